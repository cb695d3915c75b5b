// SPDX-License-Identifier: MIT
// A static triangle mesh a cloth collides with (Collider::Type::mesh): its triangles in the mesh's
// own frame and a bounding-volume hierarchy over them, built once and shared by every solver that
// uses it (the CPU reference walks it in place; the GPU solver uploads the same nodes and
// triangles, so both backends find the same triangle: docs/model.md "Collisions").
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/result.hpp"

namespace vkcloth {

struct Mesh;

class ColliderMesh {
public:
  /// A node of the hierarchy (32 bytes, the GPU's std430 MeshNode): the box [lo, hi] holds every
  /// triangle under it. count > 0: a leaf, triangles first .. first + count - 1; count == 0: an inner
  /// node, children first and first + 1. Node 0 is the root.
  struct Node {
    glm::vec3 lo;
    std::uint32_t first;
    glm::vec3 hi;
    std::uint32_t count;
  };
  /// A triangle (48 bytes, the GPU's std430 MeshTriangle), counter-clockwise seen from its front.
  /// Its clearances (create() computes them; 0: none known, as in a deformed() pose) bound from below
  /// the distance from it to any other triangle that reaches in front of its plane on its front
  /// (normal (b - a) x (c - a)) or back side: a contact entry near it then needs no search of its
  /// own (cloth_kernel.h mesh_contact).
  struct Triangle {
    glm::vec3 a;
    float clearance_front;
    glm::vec3 b;
    float clearance_back;
    glm::vec3 c;
    float pad;
  };
  /// Triangles per leaf at most.
  static constexpr std::uint32_t leaf_size = 4;
  /// The deepest hierarchy the traversal's stack holds (cloth_kernel.h VKCLOTH_MESH_STACK).
  static constexpr std::uint32_t max_depth = 30;

  /// Builds the hierarchy over `triangles` (index triples into `positions`, metres, the mesh's own
  /// frame; positions are rounded to float once, here, for both backends). Zero-area triangles are
  /// dropped. ErrorCode::invalid_argument, naming `name` and the value, for no triangles, an index
  /// out of range, or a vertex that is not finite.
  static Result<std::shared_ptr<const ColliderMesh>>
  create(std::span<const glm::dvec3> positions, std::span<const std::uint32_t> triangles, std::string name);
  /// The same from a polygon mesh (read_mesh): faces fan-triangulated, positions scaled by `scale`.
  static Result<std::shared_ptr<const ColliderMesh>> from_mesh(const Mesh& mesh, double scale,
                                                               std::string name);

  /// A skinned mesh's next pose: the same triangles over new vertex `positions` (the create() /
  /// from_mesh() vertices, in their order, metres, the mesh's own frame), the hierarchy refitted
  /// (the same nodes, their boxes recomputed; not rebuilt), and each triangle corner's velocity
  /// (new - old) / dt, which the contact's friction carries (triangle_velocities()). Hand it to the
  /// solver in the collider (Collider::mesh, then set_params) once per frame; `dt` is the time
  /// from this pose to the new one. ErrorCode::invalid_argument, naming the mesh and the value, for
  /// a vertex count other than vertex_count(), a vertex that is not finite, or dt not > 0.
  Result<std::shared_ptr<const ColliderMesh>> deformed(std::span<const glm::dvec3> positions,
                                                       double dt) const;

  std::span<const Node> nodes() const { return nodes_; }
  /// In leaf order (Node::first indexes this).
  std::span<const Triangle> triangles() const { return triangles_; }
  /// Where the mesh came from ("meshes/chair.obj"), for messages.
  const std::string& name() const { return name_; }
  /// Levels of the hierarchy (1: the root is a leaf).
  std::uint32_t depth() const { return depth_; }
  /// Zero-area triangles create() dropped.
  std::uint32_t dropped_triangles() const { return dropped_; }
  /// The vertices create() was given (deformed() takes as many).
  std::uint32_t vertex_count() const { return static_cast<std::uint32_t>(positions_.size()); }
  /// Per triangle (leaf order), its corners' velocities in Triangle's layout (a, b, c); empty for a
  /// mesh that never moved (create(), from_mesh()).
  std::span<const Triangle> triangle_velocities() const { return velocities_; }
  /// No triangle across an edge (neighbours()).
  static constexpr std::uint32_t no_neighbour = 0xffffffffu;
  /// Per triangle (leaf order), three: the triangle across its edge opposite corner a, b, c (the
  /// only other one with both of the edge's corners at the same positions; no_neighbour for a border
  /// or an edge of three or more). A contact entry moves across an edge to it without a search.
  std::span<const std::uint32_t> neighbours() const { return neighbours_; }

private:
  std::vector<Node> nodes_;
  std::vector<Triangle> triangles_;
  std::vector<Triangle> velocities_;
  std::vector<std::uint32_t> corners_; // per triangle (leaf order): its three vertices
  std::vector<std::uint32_t> neighbours_;
  std::vector<glm::vec3> positions_; // the vertices, rounded to float
  std::string name_;
  std::uint32_t depth_ = 0;
  std::uint32_t dropped_ = 0;
};

static_assert(sizeof(ColliderMesh::Node) == 32);
static_assert(sizeof(ColliderMesh::Triangle) == 48);

} // namespace vkcloth
