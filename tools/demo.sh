#!/usr/bin/env bash
# Builds vkcloth and runs the main demo: the report's hanging cloth in the wind, on the GPU when a
# Vulkan device is there (lavapipe counts), else on the CPU reference solver.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release
bin=build/release/tools/vkcloth/vkcloth
backend=cpu
if "$bin" devices >/dev/null 2>&1; then backend=vulkan; fi
mkdir -p out
"$bin" run samples/scenes/cloth_wind.json --backend "$backend" --positions out/cloth_wind_positions.csv
echo "final positions written to out/cloth_wind_positions.csv"
