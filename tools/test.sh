#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds vkcloth and runs the whole test suite (CPU physics, scene files, CLI, GPU on lavapipe
# with the Khronos validation layer). Usage: tools/test.sh [preset]   (release | debug | asan)
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
tools/setup.sh validator # also the glTF validator the export tests run (build/npm)
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset"
extra=()
# The package tests configure and build a consumer project against this build; under sanitizers
# that consumer would need the same runtime flags, and packaging is covered by the release run.
# The longest simulations spend their time in lavapipe (not instrumented) or in long CPU runs of
# code that smaller tests run too (implicit Euler, self-collision, the figures): the release run
# keeps them, the sanitizer run skips them (~10 min of a 2-core CI machine): among them every
# sample through the CLI (the in-process "every sample scene loads and runs" test runs the same
# solvers under the sanitizers), the batch of three 64 x 64 self-colliding cloths and the fast
# projection's second of 16 / 32 / 64 cloths (its smaller tests run the same code).
heavy='implicit Euler matches the CPU implicit solver on the sample scenes|the stiff cloth is stable at dt = 0.02'
heavy+='|compare passes on every sample scene|no intersecting triangle pairs after the drop settles'
heavy+='|the stiff 64x64 cloth hangs stably|no triangle passes through another after the drop settles'
heavy+='|vkcloth figures --backend vulkan|^cli:run-every-sample$|self-collision per instance in one batch'
heavy+='|the fast projection holds the report.s super-elastic cloth'
[[ $preset == asan ]] && extra=(-E "^package:|$heavy")
ctest --preset "$preset" -j "$(nproc)" "${extra[@]}"
