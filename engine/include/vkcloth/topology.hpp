// SPDX-License-Identifier: MIT
// ClothTopology: everything a solver or renderer derives from a ParticleSystem's connectivity,
// prepared ONCE (as Jolt's SoftBodySharedSettings::Optimize) and shared, immutable, by every
// consumer (std::shared_ptr<const ClothTopology>): the flattened gather lists, the normal fans,
// the triangle list and uvs, and the grid stencil fast path. Solvers then read, never re-derive,
// so the CPU and the GPU cannot disagree on the summation order or on when the stencil applies.
//
// Meshes and grids share one representation: fans and triangles are general lists (a grid fills
// them in its particular way); the grid stencil is an optional description of a fast path whose
// results equal the general lists' term for term.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec2.hpp>

#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// GatherEdge::ring bits (the shaders' VKCLOTH_RING_*; cloth_kernel.h add_ring_term): the fan
/// triangle (a, b) of particle p adds cross(x_a - x_p, x_b - x_p) to p's normal; a chain of fan
/// triangles (r0, r1), (r1, r2), ... is carried by consecutive entries towards r0, r1, r2, ...
inline constexpr std::uint32_t ring_start = 1; ///< the first entry of a chain: remember its edge
inline constexpr std::uint32_t ring_prev = 2;  ///< add the triangle (previous entry, this entry)
inline constexpr std::uint32_t ring_close = 4; ///< then the triangle (this entry, the chain's first)

/// One gather-list entry: the spring's other end and its constants (double, as in the system;
/// each solver converts to its own precision).
struct GatherEdge {
  std::uint32_t other = 0;
  double rest_length = 0.0;
  double stiffness = 0.0;
  /// ring_start | ring_prev | ring_close: this entry's part in the particle's normal fan, in
  /// ring-ordered lists (ClothTopology::ring_normals); zero otherwise.
  std::uint32_t ring = 0;
};

/// One triangle of particle p's normal fan: n_p += cross(x_a - x_p, x_b - x_p), an area-weighted
/// vertex normal summed in fan order.
struct FanTriangle {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
};

/// The grid stencil fast path: every interior particle (2 <= i < nx-2, 2 <= j < ny-2) has the same
/// gather list up to translation (same neighbour offsets, rest lengths and stiffnesses, same
/// order), so a solver may sum those 12 terms with constant offsets and get the CSR path's bits.
struct GridStencil {
  std::array<std::int32_t, 12> offset{}; ///< neighbour = p + offset[k]
  std::array<double, 12> rest_length{};
  std::array<double, 12> stiffness{};
  /// max(nx + 1, max |offset|): the farthest neighbour a (masked) lane may read, the CPU's SoA pad.
  std::uint32_t reach = 0;
  /// Per particle, when EVERY particle's gather list is a subsequence of the stencil in stencil
  /// order (make_cloth grids): bit k (0..11) stencil spring k present, bit 12+k (0..3) normal fan
  /// term k present (fan right/up, up/left, left/down, down/right). Empty otherwise: border
  /// particles then take the per-particle CSR path.
  std::vector<std::uint16_t> masks;
  /// `masks` is non-empty and every particle's spring bits are exactly the stencil entries whose
  /// neighbour (i + di, j + dj), |di|, |dj| <= 2, lies inside the grid: the GPU's SC_BORDER
  /// condition (border particles evaluate the stencil with a bounds test instead of the CSR list).
  bool border_geometric = false;
};

/// A spring the strain limit keeps from stretching (Provot): structural springs, and a chain's
/// springs. Rest length as in the system.
struct StrainLink {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  double rest_length = 0.0;
};

/// A grid's chains of strain links (StretchLimit::SweepOrder::chains): `rows` chains of `row_links`
/// links each (row j: particles (0, j) -> (1, j) -> ...), then `columns` chains of `column_links`.
/// A link that has no structural spring is (p, p, 0), which never moves. All zero without a grid.
struct StrainChainShape {
  std::uint32_t rows = 0;
  std::uint32_t row_links = 0;
  std::uint32_t columns = 0;
  std::uint32_t column_links = 0;
  bool empty() const { return rows == 0 && columns == 0; }
};

/// Slots per particle in ClothTopology::tethers(); a slot without a tether has anchor no_tether.
inline constexpr std::uint32_t tethers_per_particle = 4;
inline constexpr std::uint32_t no_tether = 0xffffffffu;

/// A long-range attachment of a particle to a pinned particle (its anchor) and its rest distance.
struct Tether {
  std::uint32_t anchor = no_tether;
  double rest_length = 0.0;
};

class ClothTopology {
public:
  /// Validates `system` (ParticleSystem::validate: errors name the problem) and prepares
  /// everything below from a copy of it.
  static Result<std::shared_ptr<const ClothTopology>> create(const ParticleSystem& system);

  ClothTopology(const ClothTopology&) = delete;
  ClothTopology& operator=(const ClothTopology&) = delete;

  /// The source: rest state (initial positions, velocities), masses, pins, springs.
  const ParticleSystem& system() const { return system_; }
  std::size_t size() const { return system_.size(); }

  /// CSR over particles, size() + 1 entries: particle p's gather list is
  /// edges()[edge_offsets()[p] .. edge_offsets()[p+1]), THE force summation order of every
  /// solver: SpringAdjacency's order, except with ring_normals().
  std::span<const std::uint32_t> edge_offsets() const { return edge_offsets_; }
  std::span<const GatherEdge> edges() const { return edges_; }
  /// True when the gather lists also carry the normal fans (every cloth with a surface that is not
  /// a grid; a grid keeps SpringAdjacency's order, its stencil's): each list starts with its fan's neighbours
  /// in ring order, flagged (GatherEdge::ring), then the other springs in SpringAdjacency order, so a solver
  /// builds the normal from the springs' edges (cloth_kernel.h add_ring_term) instead of fetching the fan's
  /// neighbours again. A fan neighbour that no spring reaches (a degenerate mesh) gets an entry of
  /// stiffness zero.
  bool ring_normals() const { return ring_normals_; }
  /// size() entries: where particle p's fan entries end in edges(), the first entry of its list
  /// without ring bits (its list's begin without ring_normals()). The solvers' fan loops stop there.
  std::span<const std::uint32_t> fan_ends() const { return fan_ends_; }

  const std::optional<Grid>& grid() const { return system_.grid; }
  /// Null when the grid stencil does not apply (no grid, a grid under 5 x 5, irregular interior).
  const GridStencil* stencil() const { return stencil_ ? &*stencil_ : nullptr; }

  /// 3 indices per counter-clockwise triangle; for a grid exactly gpu::grid_triangle_indices(nx,
  /// ny); empty for chains.
  std::span<const std::uint32_t> triangles() const { return triangles_; }
  /// CSR over particles, size() + 1 entries (all zero without a surface: no normals). The
  /// solvers read them for grids; other surfaces carry them in their gather lists (ring_normals).
  std::span<const std::uint32_t> fan_offsets() const { return fan_offsets_; }
  std::span<const FanTriangle> fans() const { return fans_; }
  /// The unit vertex normals the solvers write to their normals buffer (and the renderer draws),
  /// for `positions` (one per particle, solver order): each particle's fan summed in fans() order
  /// and normalised, with the kernel's own add_fan_triangle / unit_or_zero (engine/kernel/forces.h)
  /// in float; zero for a degenerate fan and without a surface. The glTF export's NORMAL.
  /// ErrorCode::invalid_argument naming both counts when the sizes differ.
  Result<std::vector<glm::vec3>> vertex_normals(std::span<const glm::vec3> positions) const;
  /// Texture coordinates per particle; a grid's (i, j) maps to (i / (nx-1), j / (ny-1)); zero for
  /// chains.
  std::span<const glm::vec2> uvs() const { return uvs_; }
  /// A surface has normals, feels wind and is drawn as triangles (else: masses and springs).
  bool has_surface() const { return !triangles_.empty(); }

  /// Stretch control (SimParams::stretch_limit; docs/model.md "Stretch control"). The strain
  /// links grouped by colour: colour c is strain_links()[strain_colour_offsets()[c] ..
  /// strain_colour_offsets()[c+1]), links of one colour share no particle (greedy colouring in
  /// spring order), so each colour is projected in parallel and the sweep is the same on every
  /// backend. Within a colour, links keep their spring order.
  std::span<const StrainLink> strain_links() const { return strain_links_; }
  std::span<const std::uint32_t> strain_colour_offsets() const { return strain_colour_offsets_; }
  /// The same links along a grid's rows, then its columns, each chain's links in order
  /// (StrainChainShape; empty without a grid): Provot's sweeps in chain order run each chain's links
  /// one after the other, forward then back, the chains of a family (the rows, the columns) in
  /// parallel, since no two share a particle.
  std::span<const StrainLink> strain_chains() const { return strain_chains_; }
  StrainChainShape strain_chain_shape() const { return strain_chain_shape_; }
  /// Each particle's strain links (the fast projection's gather, StretchLimit::Method::projection):
  /// particle p's are strain_incidence()[strain_incidence_offsets()[p] .. [p + 1]), each entry
  /// 2 l + e for link l = strain_links()[l], e = 1 when p is its end b (0: end a), in link order.
  std::span<const std::uint32_t> strain_incidence_offsets() const { return strain_incidence_offsets_; }
  std::span<const std::uint32_t> strain_incidence() const { return strain_incidence_; }
  /// Vertex block descent's colours (Integrator::vbd; docs/model.md "Vertex block descent"): colour
  /// c is vertex_order()[vertex_colour_offsets()[c] .. [c+1]), in index order, and no spring joins
  /// two particles of one colour, so each colour is solved in parallel with the same result as in
  /// order. A grid of structural, shear and bend springs: (i + 2 j) mod 5, five colours; otherwise
  /// a greedy colouring of the gather lists in index order.
  std::span<const std::uint32_t> vertex_order() const { return vertex_order_; }
  std::span<const std::uint32_t> vertex_colour_offsets() const { return vertex_colour_offsets_; }
  /// tethers_per_particle slots per particle (particle p's at [p * tethers_per_particle, ...)): the
  /// pinned particles nearest to p along the springs (structural, shear and chain springs at their
  /// rest lengths), nearest first, with rest distances measured straight (euclidean) or along
  /// those springs (geodesic) in the rest state. Pinned particles and particles no pinned
  /// particle reaches have none. Computed on the first call for each kind (thread-safe).
  std::span<const Tether> tethers(StretchLimit::TetherDistance distance) const;

private:
  ClothTopology() = default;

  ParticleSystem system_;
  std::vector<std::uint32_t> edge_offsets_;
  std::vector<GatherEdge> edges_;
  std::vector<std::uint32_t> fan_ends_;
  bool ring_normals_ = false;
  std::optional<GridStencil> stencil_;
  std::vector<std::uint32_t> triangles_;
  std::vector<std::uint32_t> fan_offsets_;
  std::vector<FanTriangle> fans_;
  std::vector<glm::vec2> uvs_;
  std::vector<StrainLink> strain_links_;
  std::vector<std::uint32_t> strain_colour_offsets_;
  std::vector<StrainLink> strain_chains_;
  StrainChainShape strain_chain_shape_;
  std::vector<std::uint32_t> strain_incidence_offsets_, strain_incidence_;
  std::vector<std::uint32_t> vertex_order_, vertex_colour_offsets_;
  // Tethers, computed on first use (tethers()): [0] euclidean, [1] geodesic.
  mutable std::once_flag tethers_once_[2];
  mutable std::vector<Tether> tethers_[2];
};

} // namespace vkcloth
