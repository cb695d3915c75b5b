// SPDX-License-Identifier: MIT
// Builders for the report's systems: a chain of springs and a cloth grid (docs/model.md "Springs").
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "vkcloth/material.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// Which world axis is up. vkcloth's own frame (the report's) is z up; a y-up host (most game
/// engines, glTF) names y. The y-up frame is the z-up one turned -90 degrees about x,
/// (x, y, z) -> (x, z, -y) (z_up_to), as glTF exporters do: a z-up scene and its y-up twin give the
/// same motion, turned. What follows the axis: a grid's plane (ClothOrientation), a chain's
/// default hanging direction, and in scene files gravity's and a plane collider's defaults
/// (default_gravity, up_vector). Positions given explicitly (origin, anchor, a mesh's vertices,
/// colliders) are the host's coordinates as they are.
enum class UpAxis : std::uint32_t { z = 0, y = 1 };

const char* to_string(UpAxis up);
/// "z" or "y"; anything else: nullopt.
std::optional<UpAxis> parse_up_axis(std::string_view name);
/// ErrorCode::invalid_argument naming `what` and the value for a value that is no UpAxis.
Result<void> check_up_axis(UpAxis up, std::string_view what);
/// The rotation from the z-up frame to `up`'s: the identity for z; for y, (x, y, z) -> (x, z, -y).
glm::dmat3 z_up_to(UpAxis up);
/// The unit up vector: (0, 0, 1) or (0, 1, 0).
glm::dvec3 up_vector(UpAxis up);
/// 9.81 m/s^2 down: (0, 0, -9.81) (SimParams' default) or (0, -9.81, 0).
glm::dvec3 default_gravity(UpAxis up);

/// A fixed anchor (particle 0, pinned) followed by masses joined in a line: spring k joins
/// particle k and k+1. Coordinates: z is up and the anchor is the ceiling; the report's
/// mass position (0, 0, 0.4) is a distance BELOW the ceiling, so here it is anchor + (0, 0, -0.4).
/// Defaults: the report's single spring K = 20, with vkcloth's L0 = 0.4, m = 1, started at rest length.
struct ChainDesc {
  glm::dvec3 anchor{0.0, 0.0, 0.0};
  std::vector<double> masses{1.0};
  std::vector<double> stiffness{20.0};
  std::vector<double> rest_lengths{0.4};
  std::vector<glm::dvec3> positions{{0.0, 0.0, -0.4}};
  /// The up axis: when `positions` is empty, the masses hang from the anchor along -up_vector(up).
  UpAxis up = UpAxis::z;
};

Result<ParticleSystem> make_chain(const ChainDesc& desc);

/// The plane of a grid, relative to the up axis (ClothDesc::up): `vertical` hangs (it contains the
/// up axis), `horizontal` lies flat. Rows run along x in both.
enum class ClothOrientation : std::uint32_t {
  vertical = 0,   ///< z up: spans x (i) and z (j); y up: x (i) and y (j). Row j = ny-1 is the top
  horizontal = 1, ///< z up: spans x (i) and y (j), at constant z; y up: x (i) and -z (j), at constant y
};

struct ClothStiffness {
  double structural = 40.0; ///< 4 direct neighbours, rest length = spacing
  double shear = 8.0;       ///< 4 diagonal neighbours, rest length = diagonal
  double bend = 8.0;        ///< neighbours 2 apart, rest length = 2 spacings
};

/// The default texture coordinate of grid point (i, j): (i / (nx-1), j / (ny-1)) in float (0 on
/// a side of one point).
glm::vec2 default_grid_uv(std::uint32_t i, std::uint32_t j, std::uint32_t nx, std::uint32_t ny);

/// A grid's texture coordinates as a map of the default ones (s, t) = (i / (nx-1), j / (ny-1)):
/// uv = offset + s u_axis + t v_axis. The identity leaves the default; {offset {0, 1}, v_axis
/// {0, -1}} flips v; {u_axis {0, 1}, v_axis {1, 0}} swaps u and v; {u_axis {4, 0}, v_axis {0, 4}}
/// repeats the texture 4 times (with a repeating sampler).
struct UvTransform {
  glm::vec2 offset{0.0f, 0.0f};
  glm::vec2 u_axis{1.0f, 0.0f};
  glm::vec2 v_axis{0.0f, 1.0f};
  bool operator==(const UvTransform&) const = default;
};

/// An nx x ny grid over a w x h rectangle; particle (i, j) sits at origin + i dx e_u + j dy e_v
/// with dx = w/(nx-1), dy = h/(ny-1). A spring kind with zero stiffness is left out.
struct ClothDesc {
  std::uint32_t nx = 10;
  std::uint32_t ny = 10;
  glm::dvec2 size{1.0, 1.0};
  glm::dvec3 origin{0.0, 0.0, 0.0};
  ClothOrientation orientation = ClothOrientation::vertical;
  /// The world's up axis, which `orientation` is relative to (UpAxis): with y, the grid is the
  /// z-up one turned by z_up_to(y) about `origin` (its normals point up, +y, when horizontal).
  UpAxis up = UpAxis::z;
  double particle_mass =
      0.05; ///< vkcloth's choice (the report gives no mass); docs/model.md "The report's observations"
  ClothStiffness stiffness;
  /// A physical material (docs/model.md "Materials"): when set it replaces `particle_mass` and
  /// `stiffness`: lumped masses (density times each cell's area shared by its 4 corners) and
  /// per-direction spring stiffnesses from spring_stiffness() for the spacings dx, dy. Needs a grid of
  /// at least 2 x 2. (The material's damping is a SimParams value: the caller sets it.)
  std::optional<Material> material;
  /// Pinned (i, j) cells; empty means the two top corners (0, ny-1) and (nx-1, ny-1).
  std::vector<std::array<std::uint32_t, 2>> pins;
  bool pin_default_corners = true; ///< when false and `pins` is empty, nothing is pinned
  /// Texture coordinates: the default ones mapped by `uv_transform`, or, when `uvs` is not empty,
  /// the caller's own, one per particle (j * nx + i), finite.
  UvTransform uv_transform;
  std::vector<glm::vec2> uvs;
};

/// Largest grid the builders accept (per side and in total): beyond this a scene is refused.
inline constexpr std::uint32_t max_cloth_side = 8192;
inline constexpr std::uint64_t max_particles = 1ull << 24;

Result<ParticleSystem> make_cloth(const ClothDesc& desc);

/// Twice the vector area of a polygon `face` (indices into `x`), as a fan from its first corner
/// (relative coordinates: no cancellation far from the origin); zero for a degenerate face.
glm::dvec3 polygon_vector_area(std::span<const std::uint32_t> face, std::span<const glm::dvec3> x);

/// Lumped masses (grid and mesh): every particle's mass is `density` times its share of the area of
/// its faces, each face's area shared equally by its corners. Faces in CSR form: face f is
/// corners[face_offsets[f] .. face_offsets[f+1]); `x` the positions, one per particle.
void lump_masses(std::span<const std::uint32_t> face_offsets, std::span<const std::uint32_t> corners,
                 std::span<const glm::dvec3> x, double density, std::span<Particle> particles);

/// The checks a grid and a mesh cloth share: particle_mass finite and > 0, each stiffness finite
/// and >= 0 (messages name cloth.particle_mass / cloth.stiffness.<kind> and the value).
Result<void> check_cloth_material(double particle_mass, const ClothStiffness& stiffness);

} // namespace vkcloth
