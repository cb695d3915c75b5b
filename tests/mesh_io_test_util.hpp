// SPDX-License-Identifier: MIT
// What the mesh readers' tests share (test_obj_reader.cpp, test_gltf_reader.cpp): a scratch folder,
// file writers, the error check, and the reference quad and triangle that both formats encode.
#pragma once

#include <doctest/doctest.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vkcloth/mesh.hpp"

using namespace vkcloth;
namespace fs = std::filesystem;
using nlohmann::json;

namespace mesh_io_test {

inline fs::path temp_dir() {
  const fs::path dir = fs::path(VKCLOTH_TEST_TMP) / "mesh_io";
  fs::create_directories(dir);
  return dir;
}

inline void write_file(const fs::path& path, std::span<const std::uint8_t> bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline void write_file(const fs::path& path, std::string_view text) {
  write_file(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

inline std::span<const std::uint8_t> bytes_of(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

/// Expects an error with `code` whose message contains every one of `needles`.
inline void expect_error(const Result<Mesh>& r, ErrorCode code, std::initializer_list<std::string> needles) {
  REQUIRE_MESSAGE(!r.ok(), "expected an error containing " << *needles.begin());
  const std::string& msg = r.error().message;
  CHECK_MESSAGE(r.error().code == code, "code " << to_string(r.error().code) << " for: " << msg);
  for (const std::string& n : needles)
    CHECK_MESSAGE(msg.find(n) != std::string::npos, "'" << n << "' not in: " << msg);
}

inline void expect_obj_error(const std::string& text, std::initializer_list<std::string> needles) {
  CAPTURE(text);
  expect_error(parse_obj(text, "bad.obj"), ErrorCode::parse, needles);
}

// A quad and a triangle sharing an edge, with texture coordinates. Values are exact in float, so the
// glTF version of it reads back the same doubles.
inline const std::vector<glm::dvec3> ref_positions = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0.5}};
inline const std::vector<glm::dvec2> ref_uvs = {{0, 0}, {0.5, 0}, {0.5, 1}, {0, 1}, {1, 0.25}};

inline const char* const ref_obj = "# a quad and a triangle\n"
                                   "mtllib cloth.mtl\n"
                                   "o cloth\n"
                                   "v 0 0 0\n"
                                   "v 1 0 0\r\n"
                                   "v 1 1 0 # a comment after the values\n"
                                   "v 0 1 0\n"
                                   "v 2 0 0.5 1\n"
                                   "vt 0 1\n" // OBJ's v goes up: these are ref_uvs with v -> 1 - v
                                   "vt 0.5 1\n"
                                   "vt 0.5 0\n"
                                   "vt 0 0\n"
                                   "vt 1 0.75 0\n"
                                   "vn 0 0 1\n"
                                   "g front\n"
                                   "usemtl cotton\n"
                                   "s off\n"
                                   "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
                                   "\tf  -4/-4   -1/-1 -3/-3  \n"; // relative indices: 2 5 3

} // namespace mesh_io_test
using namespace mesh_io_test;
