// SPDX-License-Identifier: MIT
// What the OBJ and glTF readers share: the bounded file read and the guard that turns an exception
// thrown while parsing (by a reader or by tinyobjloader / tinygltf) into an Error.
#pragma once

#include <cstdint>
#include <filesystem>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "vkcloth/mesh.hpp"

namespace vkcloth::mesh_detail {

/// The bytes of a mesh file. ErrorCode::io, naming the path, for a missing or unreadable file, a
/// directory, or a file larger than max_mesh_bytes (checked before reading; a device such as
/// /dev/zero is read up to the limit and refused).
Result<std::vector<std::uint8_t>> read_mesh_file(const std::filesystem::path& path);

/// ErrorCode::parse when `size` bytes held in memory exceed max_mesh_bytes.
Result<void> check_mesh_size(std::size_t size, std::string_view source_name);

/// A word or string from a file as messages quote it: at most `max_chars` characters, unprintable
/// bytes as \xNN, in single quotes.
inline std::string in_quotes(std::string_view s, std::size_t max_chars = 48) {
  std::string out = "'";
  for (const char c : s.substr(0, max_chars)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 0x20 && u < 0x7f) ? std::string(1, c) : fmt::format("\\x{:02x}", u);
  }
  return out + (s.size() > max_chars ? "...'" : "'");
}

/// Runs `parse()`; std::bad_alloc becomes ErrorCode::out_of_memory and any other exception
/// ErrorCode::parse, both naming `source_name`, so nothing escapes the public API.
template <typename Parse> Result<Mesh> guarded_parse(std::string_view source_name, Parse&& parse) {
  try {
    return parse();
  } catch (const std::bad_alloc&) {
    return make_error(ErrorCode::out_of_memory,
                      fmt::format("{}: out of memory while reading the mesh", source_name));
  } catch (const std::exception& e) {
    return make_error(ErrorCode::parse, fmt::format("{}: {}", source_name, e.what()));
  }
}

} // namespace vkcloth::mesh_detail
