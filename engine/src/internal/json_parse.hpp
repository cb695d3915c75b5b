// SPDX-License-Identifier: MIT
// JSON text -> document, with errors a person can act on: file:line:column, and for a number that
// overflows a double (1e999) the key path it was written under.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "vkcloth/result.hpp"

namespace vkcloth::scene_detail {

struct JsonParseFailure {
  std::size_t byte = 0;  ///< 0-based offset of the offending character (npos: not known)
  std::string path;      ///< key path of the value being read ("" at top level)
  std::string message;   ///< what nlohmann reported, without its prefix
  bool overflow = false; ///< a number out of the double range
};

/// Deepest nesting of arrays and objects accepted (the scene format needs 4).
inline constexpr std::size_t max_json_depth = 64;

/// Parses `text` (refusing nesting deeper than max_json_depth and a NUL byte before more text, where
/// nlohmann would stop reading; with `unique_keys`, a key that an object repeats, which nlohmann lets the
/// last one win); on failure fills `failure` and returns false. Never throws (except bad_alloc).
bool parse_json(std::string_view text, nlohmann::json& out, JsonParseFailure& failure,
                bool unique_keys = false);

/// "WHERE:LINE:COL: invalid JSON at PATH (byte N): MESSAGE" for a failure of parse_json(text).
std::string describe(const JsonParseFailure& failure, std::string_view text, std::string_view where);

/// 1-based line and column of a byte offset.
std::pair<std::size_t, std::size_t> line_col(std::string_view text, std::size_t byte);

} // namespace vkcloth::scene_detail
