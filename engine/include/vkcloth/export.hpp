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
/// file (docs/scene-format.md "Export"): one mesh whose POSITION is the first frame, one morph
/// target per later frame (float position deltas) and a "weights" animation with STEP
/// interpolation, one-hot per frame; TEXCOORD_0; NORMAL and each target's normal deltas, the
/// renderer's smooth normals of each frame (ClothTopology::vertex_normals); the node rotates
/// vkcloth's z up to glTF's y up. Size per frame: 24 N bytes of deltas (positions and normals) + 4 F
/// bytes of weights + ~400 bytes of JSON (N vertices, F frames). Frames are kept in memory (12 N
/// bytes each, positions; the normals are computed by write_gltf) until write_gltf.
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

/// The particles in the order every output lists them (glTF, OBJ, the CLI's --trace): a mesh's
/// by file vertex (Surface::source_vertex ascending), else particle order. Output vertex k is
/// particle file_order(system)[k].
std::vector<std::uint32_t> file_order(const ParticleSystem& system);

/// The file's vertex index of particle `p`: Surface::source_vertex[p], or `p` for grids, chains
/// and meshes kept in file order.
std::uint32_t file_vertex(const ParticleSystem& system, std::uint32_t p);

/// What write_gltf checks first: the extension is .glb or .gltf (any case), else
/// ErrorCode::invalid_argument naming it. Lets a caller refuse a path before a long run.
Result<void> check_gltf_path(const std::filesystem::path& path);

/// Writes one OBJ of the cloth's surface at `positions` (solver order), in the file's vertex
/// order with uvs. Errors: ErrorCode::io naming the path.
Result<void> write_obj_frame(const std::filesystem::path& path, const ParticleSystem& system,
                             std::span<const glm::dvec3> positions);

} // namespace vkcloth
