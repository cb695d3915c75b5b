// SPDX-License-Identifier: MIT
// Replays the mesh fuzzers' regression inputs (tests/fuzz/regressions/mesh/) and seed corpus
// (tests/fuzz/seeds/mesh/) through the fuzz targets' own entry (tests/fuzz/fuzz_mesh_input.hpp);
// the file's extension (.obj, .gltf, .glb) picks the reader.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "fuzz_mesh_input.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Runs every .obj / .gltf / .glb file in `dir`; returns how many were read as a mesh, and counts them.
int replay(const fs::path& dir, int& files) {
  int loaded = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const auto format = vkcloth::fuzz::mesh_format_of(e.path().extension().string());
    if (!format)
      continue;
    CAPTURE(e.path().filename().string());
    const auto b = bytes_of(e.path());
    loaded += vkcloth::fuzz::run_mesh_input(*format, b.data(), b.size());
    ++files;
  }
  return loaded;
}

} // namespace

TEST_CASE("mesh fuzz regressions: every committed input is refused without a crash") {
  int files = 0;
  CHECK(replay(fs::path(VKCLOTH_FUZZ_DIR) / "regressions" / "mesh", files) == 0);
  CHECK(files >= 1);
}

TEST_CASE("mesh fuzz seeds: every seed reads as a mesh through the fuzz entry") {
  int files = 0;
  const int loaded = replay(fs::path(VKCLOTH_FUZZ_DIR) / "seeds" / "mesh", files);
  CHECK(files >= 4);
  CHECK(loaded == files);
}
