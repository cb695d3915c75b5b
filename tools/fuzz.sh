#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fuzzes the scene parser and validator (tests/fuzz/fuzz_scene.cpp) and the mesh readers
# (tests/fuzz/fuzz_mesh.cpp: parse_obj, parse_gltf text and binary) with libFuzzer, clang, ASan and
# UBSan, for a bounded time. Usage: tools/fuzz.sh [seconds=60]
# The fuzzers are built in the asan preset's tree (build/asan, which tools/test.sh asan builds too:
# the library there carries libFuzzer's coverage instrumentation). The scene fuzzer runs `seconds`;
# the three mesh fuzzers share another `seconds` (a third each), beside it when there are two cores.
# Seed corpus: samples/scenes/ and tests/fuzz/regressions/ (scene); tests/fuzz/seeds/mesh/ and
# tests/fuzz/regressions/mesh/ (mesh, by extension). A crash leaves its input in
# build/asan/fuzz/artifacts/ and fails the script: commit it under tests/fuzz/regressions/ (scene)
# or tests/fuzz/regressions/mesh/ with the format's extension (the test suites replay those folders)
# and fix the bug.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
mesh_seconds=$(((seconds + 2) / 3))
tools/setup.sh fuzz
start=$SECONDS
cmake --preset asan >/dev/null
cmake --build --preset asan --target vkcloth_fuzz_scene vkcloth_fuzz_obj vkcloth_fuzz_gltf vkcloth_fuzz_glb
echo "fuzz: build done in $((SECONDS - start)) s" >&2
bin=build/asan/tests/fuzz
work=build/asan/fuzz
mkdir -p "$work/artifacts" "$work/logs"
rm -f "$work"/logs/*.log

# run_fuzzer NAME CORPUS DICT SECONDS: one libFuzzer run, its output in $work/logs/NAME.log; fails
# on a crash, leak or hang.
run_fuzzer() {
  echo "fuzz: $1 for ${4}s (corpus $2)" >&2
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "$bin/vkcloth_fuzz_$1" "$2" -dict="$3" \
    -max_total_time="$4" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$work/artifacts/$1-" -print_final_stats=1 >"$work/logs/$1.log" 2>&1
}

scene() {
  local corpus="$work/corpus"
  mkdir -p "$corpus"
  cp samples/scenes/*.json "$corpus/"
  find tests/fuzz/regressions -maxdepth 1 -type f ! -name '*.md' -exec cp {} "$corpus/" \;
  run_fuzzer scene "$corpus" tests/fuzz/scene.dict "$seconds"
}

meshes() {
  local format corpus dict
  for format in obj gltf glb; do
    corpus="$work/corpus_$format"
    mkdir -p "$corpus"
    find tests/fuzz/seeds/mesh tests/fuzz/regressions/mesh -type f -name "*.$format" -exec cp {} "$corpus/" \;
    dict=tests/fuzz/gltf.dict
    [[ $format == obj ]] && dict=tests/fuzz/obj.dict
    run_fuzzer "$format" "$corpus" "$dict" "$mesh_seconds" || return 1
  done
}

# Each libFuzzer run is one thread: with two cores the scene fuzzer and the mesh fuzzers run side by side.
status=0
if (($(nproc) >= 2)); then
  scene &
  scene_pid=$!
  meshes || status=1
  wait "$scene_pid" || status=1
else
  scene || status=1
  meshes || status=1
fi
for name in scene obj gltf glb; do
  [[ -f $work/logs/$name.log ]] || continue
  echo "fuzz: $name:" >&2
  tail -n 25 "$work/logs/$name.log" >&2
done
exit "$status"
