#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# ctest: the viewer under xvfb-run renders 30 frames, takes a screenshot and exits 0 with no
# validation message. Usage: run_viewer.sh VKCLOTH SCENE OUT_DIR [VIEW ARGS, e.g. --backend vulkan].
# Exit 77 (skip) without xvfb-run, except on CI (CI=true), where it must be installed
# (tools/setup.sh installs it).
set -u
bin=$1 scene=$2 out=$3
shift 3
if ! command -v xvfb-run >/dev/null 2>&1; then
  if [[ "${CI:-}" == "true" || "${CI:-}" == "1" ]]; then echo "CI=true but xvfb-run is not installed" >&2; exit 1; fi
  echo "skipped: xvfb-run is not installed (apt-get install xvfb xauth)"; exit 77
fi
mkdir -p "$out"
rm -f "$out/view_shot.png"
VKCLOTH_VALIDATION=1 timeout 120 xvfb-run -a "$bin" view "$scene" --frames 30 --size 320x240 \
  --screenshot "$out/view_shot.png" "$@" >"$out/view.stdout" 2>"$out/view.stderr"
rc=$?
cat "$out/view.stdout"; cat "$out/view.stderr" >&2
if [[ $rc -eq 4 && "${CI:-}" != "true" && "${CI:-}" != "1" ]]; then echo "skipped: no Vulkan device / display"; exit 77; fi
[[ $rc -eq 0 ]] || { echo "FAIL: vkcloth view exited $rc" >&2; exit 1; }
if grep -qi "validation" "$out/view.stderr"; then echo "FAIL: validation messages on stderr" >&2; exit 1; fi
[[ -s "$out/view_shot.png" ]] || { echo "FAIL: no screenshot" >&2; exit 1; }
grep -q "30 frames" "$out/view.stdout" || { echo "FAIL: did not render 30 frames" >&2; exit 1; }
echo "viewer OK: 30 frames, screenshot $out/view_shot.png"
