#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs one sample offscreen for 3 frames with the validation layer on; fails on any validation
# message, a non-zero exit, or missing frames / plots. Without a Vulkan device the sample exits 4:
# the test is skipped (77), except under CI=true where it fails.
# Usage: run_sample.sh SAMPLE FRAME_PREFIX OUT_DIR PLOTS(0|1) [sample args...]
set -u
sample=$1 name=$2 out=$3 plots=$4
shift 4
rm -rf "$out"
mkdir -p "$out"
VKCLOTH_VALIDATION=1 "$sample" --offscreen --frames 3 --size 160x120 --out "$out" "$@" >"$out/stdout" 2>"$out/stderr"
rc=$?
cat "$out/stdout" "$out/stderr"
if [ $rc -eq 4 ]; then
  if [ "${CI:-}" = true ]; then echo "no Vulkan device, and CI=true: the samples must run"; exit 1; fi
  echo "no Vulkan device: skipped"; exit 77
fi
[ $rc -eq 0 ] || { echo "FAIL: the sample exited with $rc"; exit 1; }
if grep -qi validation "$out/stderr"; then echo "FAIL: validation messages on stderr"; exit 1; fi
files="${name}_0000.png ${name}_0002.png"
[ "$plots" = 1 ] && files="$files ${name}_position.svg ${name}_energy.svg"
for f in $files; do
  [ -s "$out/$f" ] || { echo "FAIL: missing $out/$f"; exit 1; }
done
echo "ok"
