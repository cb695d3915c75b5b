// SPDX-License-Identifier: MIT
// Internal to engine/src/render: the colliders' draw geometry (unit shapes in mesh.vert's vertex
// layout, the floor square of a plane, a mesh collider's triangles) and where each is drawn now
// (pose_of). ClothRenderer builds them once at create() and poses them every draw.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/result.hpp"

namespace vkcloth::render::detail {

/// Mesh vertex: position (w: checker u, or a capsule vertex's end) and normal (w: checker v), as
/// mesh.vert reads them.
struct MeshVertex {
  glm::vec4 pos;
  glm::vec4 normal;
};

/// A shape's triangles in the shared mesh buffers (first index, index count) and how mesh.frag
/// shades them (mode, checker cell, colour).
struct MeshRange {
  std::uint32_t first = 0, count = 0;
  float mode = 0.0f, cell = 1.0f;
  glm::vec3 color{1.0f};
};

/// A collider's draw: its mesh in the shared buffers and what create() built it from.
struct ColliderDraw {
  Collider::Type type = Collider::Type::plane;
  MeshRange range;
  const ColliderMesh* mesh = nullptr; ///< mesh: the ColliderMesh whose triangles `range` holds
  glm::vec3 plane_normal{0.0f};       ///< plane: the square's normal, as built (world) ...
  glm::vec3 plane_centre{0.0f};       ///< ... and its centre
  glm::vec3 around{0.0f};             ///< plane: the point the square is centred under
};

/// A draw's rigid pose (its frame -> world) and mesh.vert's shape (vertex scale, capsule half length).
struct Pose {
  glm::dmat4 model{1.0};
  glm::vec4 shape{1.0f, 1.0f, 1.0f, 0.0f};
};

/// A sphere of radius `r` around `c`, `slices` around z and `stacks` from pole to pole.
void add_sphere(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx, glm::vec3 c, float r,
                std::uint32_t slices, std::uint32_t stacks);

/// A unit-radius capsule along z of length 0: a unit sphere cut at its equator, whose upper
/// half's vertices carry w = +1 and lower half's w = -1, the equator in both. mesh.vert moves each
/// half by +-pc.shape.w along z, which opens the strip between the two equators into the
/// cylinder (its normals, the equator's, are already horizontal).
void add_unit_capsule(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx, std::uint32_t slices,
                      std::uint32_t half_stacks);

/// The box [-1, 1]^3: 6 faces of 4 vertices with the face's normal (flat shading: each face lit
/// on its own, so the edges show), 12 triangles.
void add_unit_box(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx);

/// A mesh collider's triangles in its own frame, three vertices each with the face normal.
void add_collider_mesh(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx, const ColliderMesh& mesh);

/// Where the floor square of a plane (unit normal n, offset) is centred: the point of the plane
/// nearest to `around`, a hair below the surface (cloth resting at offset + eps never z-fights
/// with it).
glm::vec3 plane_centre(glm::vec3 n, float offset, glm::vec3 around);

/// A plane collider drawn as a square of half side `half` around `centre` (plane_centre);
/// checker coordinates in the w components (mesh.vert).
void add_plane(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx, glm::vec3 n, glm::vec3 centre,
               float half);

/// Where `k` is now, for the draw `d` built from the create()-time collider of the same type.
Pose pose_of(const ColliderDraw& d, const Collider& k);

/// The colliders' meshes in one vertex and index list (ClothRenderer's mesh buffers): each shape
/// once in its own frame (a unit sphere, capsule and box, each ColliderMesh; pose_of places them),
/// and each plane's floor square in the world.
class ShapeBuffer {
public:
  /// Collider `index`'s draw, its shape added when it is the first of its kind (or mesh). The floor
  /// square of a plane: half side `floor_half`, centred under `around`.
  Result<ColliderDraw> add(const Collider& k, std::size_t index, const Palette& palette, glm::vec3 around,
                           float floor_half);
  /// A unit sphere for the masses of a chain (instanced at the particles).
  MeshRange add_mass_sphere(glm::vec3 color);

  std::vector<MeshVertex> vertices;
  std::vector<std::uint32_t> indices;

private:
  /// Appends one shape's triangles (`append()` adds them to vertices and indices) and returns their
  /// range.
  template <typename Append> MeshRange shape(Append&& append) {
    MeshRange r;
    r.first = static_cast<std::uint32_t>(indices.size());
    append();
    r.count = static_cast<std::uint32_t>(indices.size()) - r.first;
    return r;
  }

  std::optional<MeshRange> sphere_, capsule_, box_;
  std::vector<std::pair<const ColliderMesh*, MeshRange>> meshes_;
};

} // namespace vkcloth::render::detail
