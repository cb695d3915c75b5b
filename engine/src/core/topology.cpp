// SPDX-License-Identifier: MIT
#include "vkcloth/topology.hpp"

#include "vkcloth/builders.hpp"
#include "internal/kernel.hpp" // add_fan_triangle, unit_or_zero: the solvers' normal
#include "kernel/constants.h"  // VKCLOTH_RING_*

#include "internal/stretch_topology.hpp"
#include "vertex_colouring.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <unordered_map>
#include <utility>

namespace vkcloth {

namespace {

bool same_constants(const GatherEdge& e, const GridStencil& st, int k) {
  // Compared in double: equal doubles give equal floats, so the verdict holds in every precision.
  return e.rest_length == st.rest_length[k] && e.stiffness == st.stiffness[k];
}

/// The fan of grid particle (i, j): neighbours right, up, left, down; each present adjacent pair
/// (k, k+1 mod 4) is one triangle, in that order (CpuSolver::normal_force_at, force_body.glsl
/// grid_normal, term for term).
struct GridFan {
  bool has[4];
  std::uint32_t nb[4];
  GridFan(std::uint32_t nx, std::uint32_t ny, std::uint32_t p) {
    const std::uint32_t i = p % nx, j = p / nx;
    has[0] = i + 1 < nx;
    has[1] = j + 1 < ny;
    has[2] = i > 0;
    has[3] = j > 0;
    nb[0] = p + 1;
    nb[1] = p + nx;
    nb[2] = p - 1;
    nb[3] = p - nx;
  }
  bool term(int k) const { return has[k] && has[(k + 1) & 3]; }
};

/// Per-particle masks (GridStencil::masks): every particle's list must be the stencil's, in order,
/// with some springs left out (make_cloth's border particles are); the fan bits follow the grid
/// fan. Empty when some list is irregular (border particles then take the CSR path).
std::vector<std::uint16_t> stencil_masks(const Grid& grid, std::span<const std::uint32_t> off,
                                         std::span<const GatherEdge> edges, const GridStencil& st) {
  const std::size_t n = std::size_t(grid.nx) * grid.ny;
  std::vector<std::uint16_t> masks(n, 0);
  for (std::size_t p = 0; p < n; ++p) {
    const GridFan fan(grid.nx, grid.ny, static_cast<std::uint32_t>(p));
    unsigned m = 0;
    for (int k = 0; k < 4; ++k)
      if (fan.term(k))
        m |= 1u << (12 + k);
    int k = 0;
    for (std::uint32_t e = off[p]; e < off[p + 1]; ++e, ++k) {
      const GatherEdge& ed = edges[e];
      while (k < 12 && (std::int64_t(ed.other) - std::int64_t(p) != st.offset[std::size_t(k)] ||
                        !same_constants(ed, st, k)))
        ++k;
      if (k == 12)
        return {};
      m |= 1u << k;
    }
    masks[p] = static_cast<std::uint16_t>(m);
  }
  return masks;
}

/// The GPU's SC_BORDER condition: each offset is a (di, dj) step in [-2, 2]^2, and every border
/// particle's list is exactly the stencil entries whose neighbour lies inside the grid, in stencil
/// order (the interior lists were checked by detect_stencil).
bool border_is_geometric(const Grid& grid, std::span<const std::uint32_t> off,
                         std::span<const GatherEdge> edges, const GridStencil& st) {
  const std::int64_t nx = grid.nx, ny = grid.ny;
  std::int64_t di[12], dj[12];
  for (std::size_t k = 0; k < 12; ++k) {
    const std::int64_t shifted = std::int64_t(st.offset[k]) + 2 * nx + 2;
    dj[k] = shifted / nx - 2;
    di[k] = st.offset[k] - dj[k] * nx;
    if (shifted < 0 || dj[k] < -2 || dj[k] > 2 || di[k] < -2 || di[k] > 2)
      return false;
  }
  for (std::int64_t j = 0; j < ny; ++j)
    for (std::int64_t i = 0; i < nx; ++i) {
      if (i >= 2 && i < nx - 2 && j >= 2 && j < ny - 2)
        continue;
      const std::size_t p = std::size_t(j * nx + i);
      std::size_t e = off[p];
      for (int k = 0; k < 12; ++k) {
        if (i + di[k] < 0 || i + di[k] >= nx || j + dj[k] < 0 || j + dj[k] >= ny)
          continue;
        if (e >= off[p + 1])
          return false;
        const GatherEdge& ed = edges[e++];
        if (std::int64_t(ed.other) - std::int64_t(p) != st.offset[std::size_t(k)] ||
            !same_constants(ed, st, k))
          return false;
      }
      if (e != off[p + 1])
        return false;
    }
  return true;
}

/// Each particle's fan from a list of faces (triangles or quads), in face order: the corner at p
/// of face (.., prev, p, next, ..) adds cross(x_next - x_p, x_prev - x_p), the face's
/// counter-clockwise normal there. Triangle (a, b, c) gives a (b, c), b (c, a), c (a, b); the quads
/// of a grid give the grid fan's four terms.
void fill_fans(std::span<const std::uint32_t> face_offsets, std::span<const std::uint32_t> faces,
               std::size_t n, std::vector<std::uint32_t>& offsets, std::vector<FanTriangle>& fans) {
  offsets.assign(n + 1, 0);
  for (std::uint32_t v : faces)
    ++offsets[v + 1];
  for (std::size_t p = 0; p < n; ++p)
    offsets[p + 1] += offsets[p];
  fans.assign(offsets[n], FanTriangle{});
  std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t f = 0; f + 1 < face_offsets.size(); ++f) {
    const std::uint32_t first = face_offsets[f], size = face_offsets[f + 1] - first;
    for (std::uint32_t k = 0; k < size; ++k) {
      const std::uint32_t p = faces[first + k];
      fans[fill[p]++] = FanTriangle{faces[first + (k + 1) % size], faces[first + (k + size - 1) % size]};
    }
  }
}

/// Particle p's fan as chains of neighbours: each triangle (a, b) links a to b; a chain starts
/// where no unused triangle ends (else anywhere: a closed ring), follows the first unused triangle
/// leaving its last neighbour, and closes when it comes back to its start. The terms come out in
/// chain order; those of a degenerate triangle (p a corner twice) are left out, as they add zero.
struct RingNode {
  std::uint32_t other;
  std::uint32_t ring; // ring_start | ring_prev | ring_close
};
static_assert(ring_start == VKCLOTH_RING_START && ring_prev == VKCLOTH_RING_PREV &&
                  ring_close == VKCLOTH_RING_CLOSE,
              "the shaders read GatherEdge::ring's bits");
std::vector<RingNode> fan_chains(std::uint32_t p, std::span<const FanTriangle> fan) {
  std::vector<FanTriangle> left;
  for (const FanTriangle& t : fan)
    if (t.a != p && t.b != p)
      left.push_back(t);
  // Unused triangles leaving each neighbour (in fan order) and how many unused ones end there.
  std::unordered_map<std::uint32_t, std::vector<std::size_t>> leaving;
  std::unordered_map<std::uint32_t, std::size_t> ending;
  for (std::size_t k = left.size(); k-- > 0;) {
    leaving[left[k].a].push_back(k); // reversed: back() is the first in fan order
    ++ending[left[k].b];
  }
  std::vector<bool> used(left.size(), false);
  auto take = [&](std::size_t k) {
    used[k] = true;
    --ending[left[k].b];
    std::vector<std::size_t>& out_of = leaving[left[k].a];
    out_of.erase(std::find(out_of.begin(), out_of.end(), k));
  };
  std::vector<RingNode> out;
  std::size_t open_scan = 0, any_scan = 0;
  for (std::size_t done = 0; done < left.size(); ++done) {
    while (open_scan < left.size() && (used[open_scan] || ending[left[open_scan].a] != 0))
      ++open_scan; // a start no unused triangle ends at stays one: the scan never goes back
    while (used[any_scan])
      ++any_scan;
    const std::size_t start = open_scan < left.size() ? open_scan : any_scan;
    take(start);
    const std::size_t first = out.size();
    out.push_back({left[start].a, ring_start});
    out.push_back({left[start].b, ring_prev});
    for (;;) {
      const std::vector<std::size_t>& next = leaving[out.back().other];
      if (next.empty())
        break;
      const std::size_t k = next.back();
      take(k);
      ++done;
      out.push_back({left[k].b, ring_prev});
    }
    if (out.back().other == out[first].other) { // back at the start: the last triangle closes
      out.pop_back();
      out.back().ring |= ring_close;
    }
  }
  return out;
}

/// Puts each particle's fan into its gather list (ClothTopology::ring_normals): the chains' nodes
/// first, each taking the particle's first unused entry towards that neighbour (or a new entry of
/// stiffness zero), then the other entries in their order.
void ring_order(std::span<const std::uint32_t> fan_offsets, std::span<const FanTriangle> fans,
                std::vector<std::uint32_t>& offsets, std::vector<GatherEdge>& edges) {
  std::vector<std::uint32_t> out_offsets{0};
  std::vector<GatherEdge> out;
  out.reserve(edges.size());
  for (std::size_t p = 0; p + 1 < offsets.size(); ++p) {
    const std::span<const GatherEdge> list(edges.data() + offsets[p], offsets[p + 1] - offsets[p]);
    std::vector<bool> taken(list.size(), false);
    for (const RingNode& node :
         fan_chains(std::uint32_t(p), fans.subspan(fan_offsets[p], fan_offsets[p + 1] - fan_offsets[p]))) {
      GatherEdge e{node.other, 0.0, 0.0, node.ring};
      for (std::size_t k = 0; k < list.size(); ++k)
        if (!taken[k] && list[k].other == node.other) {
          taken[k] = true;
          e = list[k];
          e.ring = node.ring;
          break;
        }
      out.push_back(e);
    }
    for (std::size_t k = 0; k < list.size(); ++k)
      if (!taken[k])
        out.push_back(list[k]);
    out_offsets.push_back(std::uint32_t(out.size()));
  }
  offsets = std::move(out_offsets);
  edges = std::move(out);
}

/// The grid stencil of `t`'s gather lists, if it applies: the one detection rule every solver
/// uses. The size limits (nx, ny >= 5; the first interior particle's list has 12 entries) are the
/// ones the CPU and GPU solvers applied before this routine replaced theirs.
std::optional<GridStencil> detect_stencil(const Grid& grid, std::span<const std::uint32_t> off,
                                          std::span<const GatherEdge> edges) {
  const std::int64_t nx = grid.nx, ny = grid.ny;
  if (nx < 5 || ny < 5)
    return std::nullopt;
  const std::int64_t first = 2 * nx + 2;
  if (off[std::size_t(first) + 1] - off[std::size_t(first)] != 12)
    return std::nullopt;
  GridStencil st;
  for (int k = 0; k < 12; ++k) {
    const GatherEdge& e = edges[off[std::size_t(first)] + std::size_t(k)];
    const std::int64_t o = std::int64_t(e.other) - first;
    if (o < std::numeric_limits<std::int32_t>::min() || o > std::numeric_limits<std::int32_t>::max())
      return std::nullopt; // a neighbour no grid stencil reaches (the shaders take int offsets)
    st.offset[std::size_t(k)] = static_cast<std::int32_t>(o);
    st.rest_length[std::size_t(k)] = e.rest_length;
    st.stiffness[std::size_t(k)] = e.stiffness;
  }
  // Every interior list equals the first one up to translation, in the same order.
  for (std::int64_t j = 2; j < ny - 2; ++j)
    for (std::int64_t i = 2; i < nx - 2; ++i) {
      const std::size_t p = std::size_t(j * nx + i);
      if (off[p + 1] - off[p] != 12)
        return std::nullopt;
      for (int k = 0; k < 12; ++k) {
        const GatherEdge& e = edges[off[p] + std::size_t(k)];
        if (std::int64_t(e.other) - std::int64_t(p) != st.offset[std::size_t(k)] || !same_constants(e, st, k))
          return std::nullopt;
      }
    }
  std::int64_t reach = nx + 1;
  for (std::int32_t o : st.offset)
    reach = std::max<std::int64_t>(reach, o < 0 ? -std::int64_t(o) : o);
  st.reach = static_cast<std::uint32_t>(reach);

  st.masks = stencil_masks(grid, off, edges, st);
  st.border_geometric = !st.masks.empty() && border_is_geometric(grid, off, edges, st);
  return st;
}

} // namespace

Result<std::shared_ptr<const ClothTopology>> ClothTopology::create(const ParticleSystem& system) {
  VKCLOTH_TRY(system.validate());
  std::shared_ptr<ClothTopology> t(new ClothTopology());
  t->system_ = system;
  const ParticleSystem& s = t->system_;
  const std::size_t n = s.size();

  t->edge_offsets_ = s.adjacency.offsets;
  t->edges_.reserve(s.adjacency.refs.size());
  for (const SpringRef& r : s.adjacency.refs) {
    const Spring& sp = s.springs[r.spring];
    t->edges_.push_back(GatherEdge{r.other, sp.rest_length, sp.stiffness});
  }

  t->fan_offsets_.assign(n + 1, 0);
  t->uvs_.assign(n, glm::vec2(0.0f));
  if (s.grid) {
    const std::uint32_t nx = s.grid->nx, ny = s.grid->ny;
    for (std::uint32_t p = 0; p < n; ++p) {
      const GridFan fan(nx, ny, p);
      for (int k = 0; k < 4; ++k)
        if (fan.term(k))
          t->fans_.push_back(FanTriangle{fan.nb[k], fan.nb[(k + 1) & 3]});
      t->fan_offsets_[p + 1] = static_cast<std::uint32_t>(t->fans_.size());
    }
    // Two counter-clockwise triangles (a, b, d), (a, d, c) per quad.
    if (nx >= 2 && ny >= 2) {
      t->triangles_.reserve(std::size_t(nx - 1) * (ny - 1) * 6);
      for (std::uint32_t j = 0; j + 1 < ny; ++j)
        for (std::uint32_t i = 0; i + 1 < nx; ++i) {
          const std::uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
          t->triangles_.insert(t->triangles_.end(), {a, b, d, a, d, c});
        }
    }
    // In float, as the GPU solver has always uploaded them (drawn images depend on these bits).
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i < nx; ++i)
        t->uvs_[std::size_t(j) * nx + i] = default_grid_uv(i, j, nx, ny);
    if (!s.grid->uvs.empty())
      t->uvs_ = s.grid->uvs; // the caller's (ClothDesc::uvs, uv_transform)
    t->stencil_ = detect_stencil(*s.grid, t->edge_offsets(), t->edges_);
  } else if (s.surface) {
    t->triangles_ = s.surface->triangles;
    t->uvs_ = s.surface->uvs;
    if (s.surface->face_offsets.empty()) {
      std::vector<std::uint32_t> offsets(t->triangles_.size() / 3 + 1);
      for (std::size_t f = 0; f < offsets.size(); ++f)
        offsets[f] = static_cast<std::uint32_t>(3 * f);
      fill_fans(offsets, t->triangles_, n, t->fan_offsets_, t->fans_);
    } else {
      fill_fans(s.surface->face_offsets, s.surface->faces, n, t->fan_offsets_, t->fans_);
    }
  }
  if (s.surface && !t->fans_.empty()) {
    ring_order(t->fan_offsets_, t->fans_, t->edge_offsets_, t->edges_);
    t->ring_normals_ = true;
  }
  t->fan_ends_.resize(n);
  for (std::size_t p = 0; p < n; ++p) { // the fan's entries are a prefix of the list (ring_order)
    std::uint32_t e = t->edge_offsets_[p];
    while (e < t->edge_offsets_[p + 1] && t->edges_[e].ring != 0)
      ++e;
    t->fan_ends_[p] = e;
  }
  detail::colour_strain_links(s, t->strain_links_, t->strain_colour_offsets_);
  detail::chain_strain_links(s, t->strain_links_, t->strain_chains_, t->strain_chain_shape_);
  detail::link_incidence(n, t->strain_links_, t->strain_incidence_offsets_, t->strain_incidence_);
  detail::colour_vertices(s, t->edge_offsets_, t->edges_, t->vertex_order_, t->vertex_colour_offsets_);
  return std::shared_ptr<const ClothTopology>(std::move(t));
}

std::span<const Tether> ClothTopology::tethers(StretchLimit::TetherDistance distance) const {
  const bool geodesic = distance == StretchLimit::TetherDistance::geodesic;
  const int k = geodesic ? 1 : 0;
  std::call_once(tethers_once_[k], [&] { tethers_[k] = detail::find_tethers(system_, geodesic); });
  return tethers_[k];
}

Result<std::vector<glm::vec3>> ClothTopology::vertex_normals(std::span<const glm::vec3> positions) const {
  if (positions.size() != size())
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("vertex_normals: {} positions for {} particles", positions.size(), size()));
  std::vector<glm::vec3> normals(positions.size(), glm::vec3(0.0f));
  for (std::size_t p = 0; p < positions.size(); ++p) {
    const glm::vec3 x = positions[p];
    glm::vec3 fan(0.0f); // the solvers' fan sum and normalisation (engine/kernel/forces.h), in float
    for (std::uint32_t t = fan_offsets_[p]; t < fan_offsets_[p + 1]; ++t)
      kernel::add_fan_triangle(fan, positions[fans_[t].a] - x, positions[fans_[t].b] - x);
    normals[p] = kernel::unit_or_zero(fan);
  }
  return normals;
}

} // namespace vkcloth
