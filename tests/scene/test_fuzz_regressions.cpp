// SPDX-License-Identifier: MIT
// Replays the scene fuzzer's regression inputs (tests/fuzz/regressions/) and its seed corpus
// (samples/scenes/) through the fuzz target's own entry (tests/fuzz/fuzz_input.hpp).
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_input.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

} // namespace

TEST_CASE("fuzz regressions: every committed input is handled without a crash") {
  int n = 0;
  for (const auto& e : fs::directory_iterator(VKCLOTH_FUZZ_REGRESSIONS_DIR)) {
    if (e.path().extension() == ".md" ||
        !e.is_regular_file()) // mesh/ is the mesh fuzzers' (test_mesh_fuzz_regressions.cpp)
      continue;
    CAPTURE(e.path().filename().string());
    const auto b = bytes_of(e.path());
    CHECK(!vkcloth::fuzz::run_scene_input(b.data(), b.size())); // all of them are refused
    ++n;
  }
  CHECK(n >= 6);
}

TEST_CASE("fuzz regressions: the seed corpus (sample scenes) loads through the fuzz entry") {
  for (const auto& e : fs::directory_iterator(VKCLOTH_SCENES_DIR)) {
    CAPTURE(e.path().filename().string());
    const auto b = bytes_of(e.path());
    CHECK(vkcloth::fuzz::run_scene_input(b.data(), b.size(), e.path().c_str()));
  }
}
