#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fuzzes the scene parser and validator (tests/fuzz/fuzz_scene.cpp) with libFuzzer, clang, ASan and
# UBSan, for a bounded time. Usage: tools/fuzz.sh [seconds=60]
# Seed corpus: samples/scenes/ and tests/fuzz/regressions/. A crash leaves its input in
# build/fuzz/artifacts/ and fails the script: commit it under tests/fuzz/regressions/ (the scene
# test suite replays that folder) and fix the bug.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
tools/setup.sh fuzz
build=build/fuzz
san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DVKCLOTH_FUZZ=ON -DVKCLOTH_BUILD_TESTS=OFF -DVKCLOTH_BUILD_TOOLS=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link $san" -DCMAKE_C_FLAGS="$san" \
  -DCMAKE_EXE_LINKER_FLAGS="$san" >/dev/null
cmake --build "$build" --target vkcloth_fuzz_scene
corpus="$build/corpus"
mkdir -p "$corpus" "$build/artifacts"
cp samples/scenes/*.json "$corpus/"
find tests/fuzz/regressions -type f ! -name '*.md' -exec cp {} "$corpus/" \;
echo "fuzz: scene parser for ${seconds}s (corpus $corpus)" >&2
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  "$build/tests/fuzz/vkcloth_fuzz_scene" "$corpus" -dict=tests/fuzz/scene.dict \
  -max_total_time="$seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$build/artifacts/" -print_final_stats=1 2>&1 | tail -n 25
