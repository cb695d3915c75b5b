#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs one sample in its window (GLFW + swapchain) under xvfb-run for 20 frames with the validation
# layer on; fails on any validation message, a non-zero exit, or fewer frames. Exit 77 (skip)
# without xvfb-run or without a Vulkan device / display, except under CI=true where it fails.
# Usage: run_sample_window.sh SAMPLE OUT_DIR [sample args...]
set -u
sample=$1 out=$2
shift 2
if ! command -v xvfb-run >/dev/null 2>&1; then
  if [ "${CI:-}" = true ]; then echo "CI=true but xvfb-run is not installed" >&2; exit 1; fi
  echo "skipped: xvfb-run is not installed (apt-get install xvfb xauth)"; exit 77
fi
rm -rf "$out"
mkdir -p "$out"
VKCLOTH_VALIDATION=1 timeout 120 xvfb-run -a "$sample" --frames 20 --size 160x120 --out "$out" "$@" \
  >"$out/stdout" 2>"$out/stderr"
rc=$?
cat "$out/stdout" "$out/stderr"
if [ $rc -eq 4 ]; then
  if [ "${CI:-}" = true ]; then echo "no Vulkan device / display, and CI=true: the samples must run"; exit 1; fi
  echo "no Vulkan device / display: skipped"; exit 77
fi
[ $rc -eq 0 ] || { echo "FAIL: the sample exited with $rc"; exit 1; }
if grep -qi validation "$out/stderr"; then echo "FAIL: validation messages on stderr"; exit 1; fi
grep -q ": 20 frames, step " "$out/stdout" || { echo "FAIL: did not draw 20 frames"; exit 1; }
echo "ok"
