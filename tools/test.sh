#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds vkcloth and runs the test suite (CPU physics, scene files, CLI, GPU on lavapipe with the
# Khronos validation layer). Usage: tools/test.sh [preset | long]   (release | debug | asan | long)
# The default (release) runs every test but the long ones below; `long` builds the same release
# tree and runs only those (CI runs both, .ci/run).
# asan: clang's ASan + UBSan + LeakSanitizer (the tree also builds the libFuzzer targets of
# tools/fuzz.sh), less the tests in asan_skips below, each skipped for the reason given there.
# Prints the build's and the suite's times ("test: <preset> build done in N s").
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}

# The sanitizer run skips these tests (pairs: a ctest regex, then why; printed by the run); it runs
# every other test. The release run keeps them all. The long simulations spend their time in
# lavapipe (not instrumented) or in long CPU runs of code that shorter tests run under the
# sanitizers too (under ASan on a busy 2-core VM: 77 s for the GPU drop, 94 s for the batch, 167 s
# for compare, 268 s for the GPU implicit solver on the samples).
asan_skips=(
  '^package:'
  'they configure and build a consumer project against this build (one compiles the whole engine again); under the sanitizers that project would need the same runtime flags, and the release run covers packaging'
  'implicit Euler matches the CPU implicit solver on the sample scenes'
  'the GPU implicit solver on every sample scene: lavapipe-bound; the other GPU implicit tests run the same host code'
  'GPU vbd matches the CPU vbd on every sample scene'
  'vbd on every sample scene on lavapipe; "instances with different sweeps" and the vbd GPU = CPU tests run the same host code'
  'compare passes on every sample scene'
  'vkcloth compare on every sample scene: lavapipe-bound; "every mesh sample: GPU = CPU" runs the same compare code'
  'no intersecting triangle pairs after the drop settles'
  '3 s of GPU self-collision: lavapipe-bound; the 100-step GPU self-collision comparisons run the same host code'
  'no triangle passes through another after the drop settles'
  '3 s of CPU self-collision on the samples; the 100-step self-collision tests run the same code'
  'the cotton drop at 64 x 64 and 128 x 128 .samples/bench.'
  'three 3 s drops on the CPU (~4 s here); the 100-step vbd and chain-order tests run the same code'
  'the cotton drop at 128 x 128 ends with no intersecting pair'
  '3 s of a 128 x 128 self-colliding drop, on the CPU twice and on lavapipe; the 64 x 64 drop and the 100-step self-collision and chain-order tests run the same code'
  'the cotton drop keeps its structural strain within 10 %'
  '3 s of the cotton drop twice on the CPU; the 100-step self-collision and stretch-control tests run the same code'
  'vkcloth figures --backend vulkan'
  'every figure on lavapipe; vkcloth figures (cpu) runs the same figure code under the sanitizers'
  '^cli:run-every-sample$'
  'every sample through the CLI; "every sample scene loads and runs" runs the same solvers in-process (200 steps each there)'
  'self-collision per instance in one batch'
  'three 64 x 64 self-colliding cloths on lavapipe and the CPU; the per-instance batch tests run the same code'
  'the fast projection holds the report.s super-elastic cloth'
  'a second of 16 / 32 / 64 cloths with the fast projection; its smaller tests run the same code'
  'vkcloth figures \(cpu\)'
  "every figure of the report simulated on the CPU (~80 s there): the physics tests run the same solvers under the sanitizers and the release run keeps the figure code"
  'GPU matches CPU on the self-collision samples: 100 steps'
  'lavapipe-bound (~50 s there); "self-collision turned on between steps" and the per-instance tests run the same host code'
  'self-collision: results do not depend on the thread count'
  'the same self-collision run at four thread counts (~30 s there): the other self-collision tests run its code, and the invariance is arithmetic, which the release run checks'
  'implicit Euler: the stiff 64x64 cloth hangs stably'
  'a long CPU run of the implicit solver (~25 s there); the smaller implicit tests run the same code'
  'GPU vbd matches the CPU vbd on every sample scene'
  'vbd on every sample scene on lavapipe (~29 s there); "instances with different sweeps" runs the same host code'
  'implicit solvers on the cotton drop onto a sphere'
  'four 2 s drops of CG and vbd (~16 s there); the other vbd and implicit tests run the same code'
  'cli: soak runs a short soak'
  "its RSS-growth limit (1 MiB over 500 steps) measures the sanitizer's allocator: under clang's ASan the RSS grows 2.5 MiB there whatever the quarantine (0.2 MiB under GCC's), under both ~55 MiB over 400 000 steps; the release run keeps it"
)

# The long suite (pairs: a ctest regex, then why it is long): minutes of lavapipe or of a second
# engine build each, whose code the default suite's shorter tests run too.
long_tests=(
  '^package:add_subdirectory$'
  'configures and builds a consumer project that compiles the whole engine again, file by file'
  'GPU self-collision: the cotton drop at 128 x 128'
  '3 s of a 128 x 128 self-colliding drop on lavapipe; the 64 x 64 drop runs the same passes'
  'vkcloth figures --backend vulkan'
  'every figure of the report on lavapipe; the figures on the CPU and the GPU = CPU tests run the same code'
  'GPU matches CPU on the self-collision samples: 100 steps'
  'every self-collision sample on lavapipe; the per-instance self-collision tests run the same passes'
  'implicit Euler matches the CPU implicit solver on the sample scenes'
  'the GPU implicit solver on every sample scene; the other GPU implicit tests run the same host code'
  'implicit Euler: the stiff 64x64 cloth hangs stably'
  'a long CPU run of the implicit solver; the smaller implicit tests run the same code'
  'compare passes on every sample scene'
  'vkcloth compare on every sample scene on lavapipe; "every mesh sample: GPU = CPU" runs the same compare code'
)
long_regex=""
for ((i = 0; i < ${#long_tests[@]}; i += 2)); do long_regex+="${long_regex:+|}${long_tests[i]}"; done
suite=default
if [[ $preset == long ]]; then
  suite=long
  preset=release
fi

start=$SECONDS
if [[ $preset == asan ]]; then tools/setup.sh fuzz; else tools/setup.sh; fi # fuzz: clang, its runtimes
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset"
echo "test: $preset build done in $((SECONDS - start)) s" >&2
# Node and the glTF validator the export tests run (build/npm): after the build, so that .ci/run's
# background install overlaps it (setup.sh waits for that one).
tools/setup.sh validator
extra=()
if [[ $preset == asan ]]; then
  exclude=""
  for ((i = 0; i < ${#asan_skips[@]}; i += 2)); do
    echo "test: asan skips /${asan_skips[i]}/: ${asan_skips[i + 1]}" >&2
    exclude+="${exclude:+|}${asan_skips[i]}"
  done
  extra=(-E "$exclude")
elif [[ $suite == long ]]; then
  for ((i = 0; i < ${#long_tests[@]}; i += 2)); do echo "test: long: /${long_tests[i]}/: ${long_tests[i + 1]}" >&2; done
  extra=(-R "$long_regex")
elif [[ $preset == release ]]; then
  echo "test: the long tests run with tools/test.sh long (CI runs both)" >&2
  extra=(-E "$long_regex")
fi
start=$SECONDS
ctest --preset "$preset" -j "$(nproc)" "${extra[@]}"
# pytest's own result line (the test python:pytest, where the Python module is built), for the log.
log=build/$preset/Testing/Temporary/LastTest.log
if [[ -f $log ]] && pytest_line=$(grep -E '^=+ .*(passed|failed|error).* in [0-9.]+s' "$log"); then
  echo "test: python (pytest): $pytest_line" >&2
fi
label=$preset; [[ $suite == long ]] && label="$preset long"
echo "test: $label suite done in $((SECONDS - start)) s" >&2
