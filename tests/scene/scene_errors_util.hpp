// SPDX-License-Identifier: MIT
// What the scene-error tests share (test_scene_errors.cpp, test_scene_errors_colliders.cpp,
// test_hostile_inputs.cpp): parse a scene that must be refused and check its message, and the small
// scenes they refuse.
#pragma once

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "vkcloth/scene.hpp"

namespace vkcloth::test {

/// Parses `text` as the file `source`, expects an error whose message contains every one of `needles`.
inline Error expect_error_as(const std::string& source, const std::string& text,
                             std::initializer_list<std::string> needles,
                             std::vector<std::string> overrides = {}) {
  auto s = parse_scene(text, source, overrides);
  REQUIRE_MESSAGE(!s.ok(), "expected an error for: " << text.substr(0, 200));
  const std::string& msg = s.error().message;
  for (const std::string& n : needles)
    CHECK_MESSAGE(msg.find(n) != std::string::npos, "'" << n << "' not in: " << msg);
  return s.error();
}

/// The same as "bad.json", whose name every message must give.
inline Error expect_error(const std::string& text, std::initializer_list<std::string> needles,
                          std::vector<std::string> overrides = {}) {
  Error e = expect_error_as("bad.json", text, needles, std::move(overrides));
  CHECK(e.message.find("bad.json") != std::string::npos); // every message names the file
  return e;
}

/// Like expect_error, for a scene file in `dir` (its relative mesh paths start there).
inline Error expect_error_in(const std::filesystem::path& dir, const std::string& text,
                             std::initializer_list<std::string> needles) {
  return expect_error_as((dir / "bad.json").string(), text, needles);
}

inline std::string cloth(const std::string& body) {
  return R"({"system": "cloth", "cloth": )" + body + "}";
}

/// A chain scene with these colliders (the array's body).
inline std::string colliders(const std::string& body) {
  return R"({"system": "chain", "colliders": [)" + body + "]}";
}

inline const std::string sphere =
    R"({"type": "sphere", "center": [0, 0, 0], "radius": 1)"; // no closing brace

/// tmp/errors_<tag>/ with `name` holding `text`; returns the directory (scenes parsed "in" it).
inline std::filesystem::path mesh_dir(const std::string& tag, const std::string& name,
                                      const std::string& text) {
  const std::filesystem::path d = std::filesystem::path(VKCLOTH_TEST_TMP) / ("errors_" + tag);
  std::filesystem::create_directories(d);
  std::ofstream(d / name) << text;
  return d;
}

} // namespace vkcloth::test
