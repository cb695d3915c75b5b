// SPDX-License-Identifier: MIT
// The particle-spring system description that every solver consumes (CPU and Vulkan).
// Topology (springs, rest lengths, the per-particle gather lists, the grid shape for normals) is
// built once here; solvers copy the initial state and own their runtime state.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "vkcloth/glm_abi.hpp" // the host's GLM must match the library's (a compile error otherwise)
#include "vkcloth/result.hpp"

namespace vkcloth {

/// The report's spring families (docs/model.md "Springs"); `plain` is a chain spring.
enum class SpringKind : std::uint32_t { plain = 0, structural = 1, shear = 2, bend = 3 };

const char* to_string(SpringKind kind);

/// Hooke spring between particles a and b (docs/model.md "Springs"): F_a = K (|u| - L0) u/|u|, u = p_b - p_a.
struct Spring {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  double rest_length = 0.0;
  double stiffness = 0.0;
  SpringKind kind = SpringKind::plain;
};

/// Initial state of one particle. A pinned particle never moves (its velocity stays zero).
struct Particle {
  glm::dvec3 position{0.0};
  glm::dvec3 velocity{0.0};
  double mass = 1.0;
  bool pinned = false;
};

/// Shape of a cloth grid: particle (i, j) has index j * nx + i. Used for normals (wind, drawing).
struct Grid {
  std::uint32_t nx = 0;
  std::uint32_t ny = 0;
  /// Texture coordinates, one per particle; empty: (i / (nx-1), j / (ny-1)) (ClothTopology::uvs).
  std::vector<glm::vec2> uvs;
};

/// The triangle surface of a cloth that is not a grid (a mesh, vkcloth/mesh.hpp): normals come
/// from each particle's triangle fan, drawing and export use these triangles and uvs.
struct Surface {
  std::vector<std::uint32_t> triangles; ///< 3 particle indices per counter-clockwise triangle
  /// The faces normals are summed over (triangles and quads, counter-clockwise): face f is
  /// faces[face_offsets[f] .. face_offsets[f+1]); each corner p adds cross(x_next - x_p,
  /// x_prev - x_p), so a quad mesh of a grid gets the grid's normals. Empty: the triangles.
  std::vector<std::uint32_t> face_offsets;
  std::vector<std::uint32_t> faces;
  std::vector<glm::vec2> uvs; ///< one per particle
  /// The file's vertex index of each particle (a mesh's particles are renumbered for locality and
  /// its isolated vertices dropped); outputs list particles in this order. Empty: identity.
  std::vector<std::uint32_t> source_vertex;
};

/// One entry of a particle's gather list: the spring's other end and its constants.
struct SpringRef {
  std::uint32_t other = 0;
  std::uint32_t spring = 0; ///< index into ParticleSystem::springs
};

/// Per-particle incident springs in compressed-row form. Particle p's springs are
/// refs[offsets[p] .. offsets[p+1]), in increasing spring index: this is THE force summation
/// order, shared by the CPU reference and the GPU gather pass.
struct SpringAdjacency {
  std::vector<std::uint32_t> offsets;
  std::vector<SpringRef> refs;
};

/// A complete particle-spring system: state, topology and (for cloth) its grid.
struct ParticleSystem {
  std::vector<Particle> particles;
  std::vector<Spring> springs;
  std::optional<Grid> grid;       ///< set for a grid cloth
  std::optional<Surface> surface; ///< set for a mesh cloth; chains have neither (no normals, no wind)
  SpringAdjacency adjacency;      ///< filled by finalize()

  std::size_t size() const { return particles.size(); }

  /// Builds `adjacency` from `springs`. Builders call it; call it again after editing springs.
  void finalize();

  /// What every solver checks before it starts: not empty, finalized, grid size = particle
  /// count, not both a grid and a surface, surface indices in range and one uv per particle, springs and
  /// gather lists within range, free particles with a mass > 0.
  Result<void> validate() const;
};

} // namespace vkcloth
