// SPDX-License-Identifier: MIT
// A polygon mesh as a file holds it: the type the core (mesh colliders) and the readers and
// writers (vkcloth/mesh.hpp) share; no reader here.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace vkcloth {

/// A base-colour texture as the file holds it (PNG or JPEG bytes); the renderer decodes it.
struct MeshTexture {
  std::string source;                ///< where it came from, for messages ("flag.glb images[0]")
  std::vector<std::uint8_t> encoded; ///< the PNG or JPEG file's bytes
};

/// A polygon mesh in the file's vertex order. Face f is indices[face_offsets[f] ..
/// face_offsets[f+1]), counter-clockwise seen from the front; faces have 3 or more vertices.
struct Mesh {
  std::vector<glm::dvec3> positions;
  /// Empty, or one per vertex, glTF's convention: (0, 0) is the image's top-left corner, v grows
  /// downwards (the OBJ reader and writers flip OBJ's upward v).
  std::vector<glm::dvec2> uvs;
  std::vector<std::uint32_t> face_offsets{0};
  std::vector<std::uint32_t> indices;
  std::optional<MeshTexture> texture; ///< a glTF material's base-colour texture

  std::size_t face_count() const { return face_offsets.empty() ? 0 : face_offsets.size() - 1; }
};

} // namespace vkcloth
