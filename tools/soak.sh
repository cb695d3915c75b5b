#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Opt-in soak test (not in tools/test.sh): 100 000 steps of each stable sample scene on the CPU
# (and on Vulkan with --vulkan), checking no NaN/inf, no drift of pinned particles and no RSS
# growth (vkcloth soak). Usage: tools/soak.sh [--vulkan] [steps=100000]
set -euo pipefail
cd "$(dirname "$0")/.."
backends=(cpu)
[[ ${1:-} == --vulkan ]] && { backends+=(vulkan); shift; }
steps=${1:-100000}
tools/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release --target vkcloth_cli >/dev/null
B=build/release/tools/vkcloth/vkcloth
# The stable samples (spring.json and double_spring.json use the report's dt, stable too).
for scene in samples/scenes/*.json; do
  for backend in "${backends[@]}"; do
    "$B" soak "$scene" --steps "$steps" --backend "$backend"
  done
done
