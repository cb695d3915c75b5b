// SPDX-License-Identifier: MIT
// The mesh fuzzers' input, shared by the libFuzzer targets (fuzz_mesh.cpp, one per format) and the
// test that replays tests/fuzz/regressions/mesh/ and tests/fuzz/seeds/mesh/ in the normal suite.
//
// Input bytes: the whole file, read with parse_obj or parse_gltf (text or binary) from memory, with
// no base directory (so a URI naming a file is refused, never looked up).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "vkcloth/mesh.hpp"

namespace vkcloth::fuzz {

enum class MeshFormat { obj, gltf, glb };

/// The format a regression or seed file is in, by its extension.
inline std::optional<MeshFormat> mesh_format_of(std::string_view extension) {
  if (extension == ".obj")
    return MeshFormat::obj;
  if (extension == ".gltf")
    return MeshFormat::gltf;
  if (extension == ".glb")
    return MeshFormat::glb;
  return std::nullopt;
}

/// What every Mesh a reader returns promises (vkcloth/mesh.hpp).
inline bool mesh_keeps_its_promises(const Mesh& m) {
  if (m.face_count() == 0 || m.face_offsets.front() != 0 || m.face_offsets.back() != m.indices.size())
    return false;
  for (std::size_t f = 0; f < m.face_count(); ++f)
    if (m.face_offsets[f + 1] < m.face_offsets[f] + 3)
      return false;
  for (const std::uint32_t i : m.indices)
    if (i >= m.positions.size())
      return false;
  if (m.positions.size() > max_particles || (!m.uvs.empty() && m.uvs.size() != m.positions.size()))
    return false;
  for (const auto& p : m.positions)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(p[c]) || std::abs(p[c]) > 1e30)
        return false;
  for (const auto& uv : m.uvs)
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
      return false;
  return !m.texture || !m.texture->encoded.empty();
}

/// Returns true when the bytes read as a mesh. Must never crash, hang or leak, whatever the bytes;
/// traps when an error does not name the source or a mesh breaks its promises.
inline bool run_mesh_input(MeshFormat format, const std::uint8_t* data, std::size_t size) {
  const std::string_view name = format == MeshFormat::obj    ? "fuzz.obj"
                                : format == MeshFormat::gltf ? "fuzz.gltf"
                                                             : "fuzz.glb";
  const auto mesh =
      format == MeshFormat::obj
          ? parse_obj(std::string_view(reinterpret_cast<const char*>(data), size), name)
          : parse_gltf(std::span<const std::uint8_t>(data, size), format == MeshFormat::glb, name);
  if (!mesh.ok()) {
    if (mesh.error().message.find(name) == std::string::npos) // every message names the file
      __builtin_trap();
    return false;
  }
  if (!mesh_keeps_its_promises(*mesh))
    __builtin_trap();
  return true;
}

} // namespace vkcloth::fuzz
