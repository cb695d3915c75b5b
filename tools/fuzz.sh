#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fuzzes the scene parser and validator (tests/fuzz/fuzz_scene.cpp) and the mesh readers
# (tests/fuzz/fuzz_mesh.cpp: parse_obj, parse_gltf text and binary) with libFuzzer, clang, ASan and
# UBSan, for a bounded time. Usage: tools/fuzz.sh [seconds=60]
# The scene fuzzer runs `seconds`; the three mesh fuzzers share another `seconds` (a third each).
# Seed corpus: samples/scenes/ and tests/fuzz/regressions/ (scene); tests/fuzz/seeds/mesh/ and
# tests/fuzz/regressions/mesh/ (mesh, by extension). A crash leaves its input in
# build/fuzz/artifacts/ and fails the script: commit it under tests/fuzz/regressions/ (scene) or
# tests/fuzz/regressions/mesh/ with the format's extension (the test suites replay those folders)
# and fix the bug.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
mesh_seconds=$(((seconds + 2) / 3))
tools/setup.sh fuzz
build=build/fuzz
san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DVKCLOTH_FUZZ=ON -DVKCLOTH_BUILD_TESTS=OFF -DVKCLOTH_BUILD_TOOLS=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link $san" -DCMAKE_C_FLAGS="$san" \
  -DCMAKE_EXE_LINKER_FLAGS="$san" >/dev/null
cmake --build "$build" --target vkcloth_fuzz_scene vkcloth_fuzz_obj vkcloth_fuzz_gltf vkcloth_fuzz_glb
mkdir -p "$build/artifacts"

# run_fuzzer NAME CORPUS DICT SECONDS: one libFuzzer run; fails the script on a crash, leak or hang.
run_fuzzer() {
  echo "fuzz: $1 for ${4}s (corpus $2)" >&2
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "$build/tests/fuzz/vkcloth_fuzz_$1" "$2" -dict="$3" \
    -max_total_time="$4" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$build/artifacts/$1-" -print_final_stats=1 2>&1 | tail -n 25
}

corpus="$build/corpus"
mkdir -p "$corpus"
cp samples/scenes/*.json "$corpus/"
find tests/fuzz/regressions -maxdepth 1 -type f ! -name '*.md' -exec cp {} "$corpus/" \;
run_fuzzer scene "$corpus" tests/fuzz/scene.dict "$seconds"

for format in obj gltf glb; do
  corpus="$build/corpus_$format"
  mkdir -p "$corpus"
  find tests/fuzz/seeds/mesh tests/fuzz/regressions/mesh -type f -name "*.$format" -exec cp {} "$corpus/" \;
  dict=tests/fuzz/gltf.dict
  [[ $format == obj ]] && dict=tests/fuzz/obj.dict
  run_fuzzer "$format" "$corpus" "$dict" "$mesh_seconds"
done
