#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# For a user with a real GPU: builds vkcloth (release preset), runs the GPU test suite under the
# Khronos validation layer with synchronization validation (CI=true: no device is a failure, not a
# skip), then times the Vulkan solver with `vkcloth bench`: explicit fused Euler up to 4096 x 4096
# with both buffer accesses (texel views, storage buffers; alternated, each result's `layout` key)
# implicit Euler at 256 x 256, and vbd (one dispatch per colour per sweep) at 256, 1024 and 4096 with
# CG beside it at 256. Writes ONE JSON file: the device, the CPU, the test outcome and the three
# bench results (their keys: docs/bench-json.md).
#
#   tools/gpu-bench.sh [OUT.json] [--quick] [--skip-tests]
#     OUT.json      default gpu-bench.json
#     --quick       sizes up to 256 and fewer steps: a smoke run (e.g. on lavapipe)
#     --skip-tests  only the benchmarks
# Exit: 0 when every test passed and both benches ran; 1 otherwise (the JSON says which part).
set -euo pipefail
cd "$(dirname "$0")/.."
out=gpu-bench.json
quick=0
tests=1
for arg in "$@"; do
  case $arg in
  --quick) quick=1 ;;
  --skip-tests) tests=0 ;;
  -h | --help)
    sed -n '2,15p' "$0"
    exit 0
    ;;
  -*)
    echo "gpu-bench: unknown option $arg" >&2
    exit 2
    ;;
  *) out=$arg ;;
  esac
done

tools/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release
cli=build/release/tools/vkcloth/vkcloth
device=$("$cli" devices | sed -n 's/^selected: //p' | sed 's/ (set VKCLOTH_DEVICE.*//')
cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -n 1)
json_string() { printf '"%s"' "$(printf '%s' "$1" | sed 's/\\/\\\\/g; s/"/\\"/g')"; }

status=0
test_result='"skipped"'
if ((tests)); then
  log=$(mktemp)
  if CI=true ctest --preset release -R '^(gpu|samples?|render|quickstart):' -j "$(nproc)" >"$log" 2>&1; then
    test_result='"passed"'
  else
    test_result='"failed"'
    status=1
    grep -E '\(Failed\)|\(Timeout\)' "$log" >&2 || true
  fi
  tail -n 3 "$log" >&2
  rm -f "$log"
fi

if ((quick)); then
  sizes=64,128,256 steps=50 reps=2 implicit_size=64 vbd_sizes=64,128
else
  sizes=256,512,1024,2048,4096 steps=200 reps=3 implicit_size=256 vbd_sizes=256,1024,4096
fi
explicit=$(mktemp)
implicit=$(mktemp)
vbd=$(mktemp)
trap 'rm -f "$explicit" "$implicit" "$vbd"' EXIT
"$cli" bench --backend vulkan --sizes "$sizes" --steps "$steps" --reps "$reps" --variants fused --layout texel,storage \
  --json "$explicit" || status=1
"$cli" bench --backend vulkan --sizes "$implicit_size" --steps "$steps" --reps "$reps" \
  --integrator implicit_euler --json "$implicit" || status=1
# vbd on a cotton-like cloth (500 / 50 N/m, 0.15 kg) at a stiff step (1/300 s): 5 sweeps of 5 colours.
"$cli" bench --backend vulkan --sizes "$vbd_sizes" --steps "$steps" --reps "$reps" --integrator vbd \
  --dt 0.0033333 --stiffness 500,50,0.02 --cloth-mass 0.15 --json "$vbd" || status=1
[[ -s $explicit ]] || echo null >"$explicit"
[[ -s $implicit ]] || echo null >"$implicit"
[[ -s $vbd ]] || echo null >"$vbd"

{
  printf '{\n  "schema": "vkcloth-gpu-bench/1",\n'
  printf '  "device": %s,\n  "cpu": %s,\n' "$(json_string "$device")" "$(json_string "$cpu")"
  printf '  "quick": %s,\n  "gpu_tests": %s,\n' "$( ((quick)) && echo true || echo false)" "$test_result"
  printf '  "explicit_fused_euler": '
  cat "$explicit"
  printf ',\n  "implicit_euler": '
  cat "$implicit"
  printf ',\n  "vbd": '
  cat "$vbd"
  printf '\n}\n'
} >"$out"
echo "gpu-bench: wrote $out (device: $device; tests: $test_result)" >&2
exit $status
