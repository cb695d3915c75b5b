// SPDX-License-Identifier: MIT
// The animated cloth out to files other tools play: glTF 2.0 (Blender's importer, web viewers)
// and one OBJ per frame. Vertices are written in the file's order (Surface::source_vertex).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/mesh.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// Collects frames of one cloth (a grid or a mesh) and writes them as one animated glTF 2.0
/// file (docs/scene-format.md "Export" says how the animation is encoded and its size per frame).
class AnimationRecorder {
public:
  /// `system` must have a surface (a grid or a mesh): chains have no triangles to export.
  /// `texture`: the base-colour texture to embed (a glTF mesh's own), else none.
  static Result<AnimationRecorder> create(const ParticleSystem& system,
                                          std::optional<MeshTexture> texture = std::nullopt);
  AnimationRecorder(AnimationRecorder&&) noexcept;
  AnimationRecorder& operator=(AnimationRecorder&&) noexcept;
  ~AnimationRecorder();

  /// One frame at `time` seconds; `positions` in solver order, one per particle, finite.
  Result<void> add_frame(double time, std::span<const glm::dvec3> positions);
  std::size_t frame_count() const;

  /// Writes every frame so far: .glb (one binary file) or .gltf (JSON with the buffer embedded
  /// as a data: URI), by extension. Errors: ErrorCode::io naming the path.
  Result<void> write_gltf(const std::filesystem::path& path) const;

private:
  struct Impl;
  explicit AnimationRecorder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Writes one OBJ of the cloth's surface at `positions` (solver order), in the file's vertex
/// order with uvs. Errors: ErrorCode::io naming the path.
Result<void> write_obj_frame(const std::filesystem::path& path, const ParticleSystem& system,
                             std::span<const glm::dvec3> positions);

} // namespace vkcloth
