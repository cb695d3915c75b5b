// SPDX-License-Identifier: MIT
// read_mesh (dispatch by extension) and the file read both readers share.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

#include "mesh_io.hpp"

namespace vkcloth {

namespace mesh_detail {

Result<void> check_mesh_size(std::size_t size, std::string_view source_name) {
  if (size > max_mesh_bytes)
    return make_error(ErrorCode::parse,
                      fmt::format("{}: the mesh is {} bytes, more than the limit {} ({} MiB)", source_name,
                                  size, max_mesh_bytes, max_mesh_bytes >> 20));
  return {};
}

Result<std::vector<std::uint8_t>> read_mesh_file(const std::filesystem::path& path) {
  try {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (status.type() == std::filesystem::file_type::not_found)
      return make_error(ErrorCode::io, fmt::format("{}: no such mesh file", path.string()));
    if (status.type() == std::filesystem::file_type::directory)
      return make_error(ErrorCode::io, fmt::format("{}: is a directory, not a mesh file", path.string()));
    if (const auto size = std::filesystem::file_size(path, ec); !ec && size > max_mesh_bytes)
      return make_error(ErrorCode::io,
                        fmt::format("{}: the file is {} bytes, more than the mesh size limit {} ({} MiB)",
                                    path.string(), size, max_mesh_bytes, max_mesh_bytes >> 20));
    std::ifstream in(path, std::ios::binary);
    if (!in)
      return make_error(ErrorCode::io, fmt::format("{}: cannot open the mesh file ({})", path.string(),
                                                   std::strerror(errno)));
    // Bounded read: a device or pipe (/dev/zero, a FIFO) has no size to check up front.
    std::vector<std::uint8_t> bytes;
    char chunk[1 << 16];
    while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
      bytes.insert(bytes.end(), chunk, chunk + in.gcount());
      if (bytes.size() > max_mesh_bytes)
        return make_error(ErrorCode::io, fmt::format("{}: more than the mesh size limit {} bytes ({} MiB)",
                                                     path.string(), max_mesh_bytes, max_mesh_bytes >> 20));
    }
    if (in.bad())
      return make_error(ErrorCode::io, fmt::format("{}: read error", path.string()));
    return bytes;
  } catch (const std::bad_alloc&) {
    return make_error(ErrorCode::out_of_memory,
                      fmt::format("{}: out of memory while reading", path.string()));
  } catch (const std::exception& e) {
    return make_error(ErrorCode::io, fmt::format("{}: {}", path.string(), e.what()));
  }
}

} // namespace mesh_detail

Result<Mesh> read_mesh(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".obj")
    return read_obj(path);
  if (ext == ".gltf" || ext == ".glb")
    return read_gltf(path);
  return make_error(ErrorCode::invalid_argument,
                    fmt::format("{}: unknown mesh file extension '{}' (expected .obj, .gltf or .glb)",
                                path.string(), path.extension().string()));
}

} // namespace vkcloth
