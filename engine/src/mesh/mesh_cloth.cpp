// SPDX-License-Identifier: MIT
// A mesh becomes a cloth (docs/model.md "Mesh springs"): faces cleaned (degenerate ones dropped,
// right-triangle pairs of a quad-dominant file merged back into quads), particles renumbered for
// locality, then the springs of the report's grid rebuilt from the faces.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <unordered_map>
#include <unordered_set>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <meshoptimizer.h>

#include "vkcloth/export.hpp"
#include "vkcloth/mesh.hpp"

namespace vkcloth {
namespace {

Error bad(std::string message) {
  return make_error(ErrorCode::invalid_argument, std::move(message));
}

/// Coordinates past this are refused: 1e39 overflows float, and squared lengths overflow double
/// long before 1e160.
constexpr double max_coordinate = 1e30;

bool usable(glm::dvec3 p) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(p[k]) || std::abs(p[k]) > max_coordinate)
      return false;
  return true;
}

/// Faces as small vertex lists (3 or 4 corners) in one flat CSR, the builder's working form.
struct Faces {
  std::vector<std::uint32_t> offsets{0};
  std::vector<std::uint32_t> corners;
  std::size_t size() const { return offsets.size() - 1; }
  std::span<const std::uint32_t> operator[](std::size_t f) const {
    return {corners.data() + offsets[f], offsets[f + 1] - offsets[f]};
  }
  void add(std::span<const std::uint32_t> face) {
    corners.insert(corners.end(), face.begin(), face.end());
    offsets.push_back(static_cast<std::uint32_t>(corners.size()));
  }
};

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
}

Result<void> check_desc(const MeshClothDesc& d) {
  const MeshTransform& t = d.transform;
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(t.translate[k]) || !std::isfinite(t.rotate_deg[k]))
      return bad("cloth.mesh_transform.translate and rotate_deg must be finite");
  if (!std::isfinite(t.scale) || t.scale <= 0.0)
    return bad(fmt::format("cloth.mesh_transform.scale must be finite and > 0, got {}", t.scale));
  if (d.material)
    VKCLOTH_TRY(check_material(*d.material));
  else if (d.density && (!std::isfinite(*d.density) || *d.density <= 0.0))
    return bad(fmt::format("cloth.density must be finite and > 0 (kg/m^2), got {}", *d.density));
  if (!d.material)
    VKCLOTH_TRY(check_cloth_material(d.particle_mass, d.stiffness));
  if (d.pin_region) {
    const PinRegion& r = *d.pin_region;
    if (!usable(r.min) || !usable(r.max))
      return bad("cloth.pin_region.min and max must be finite");
    for (int k = 0; k < 3; ++k)
      if (r.min[k] > r.max[k])
        return bad(
            fmt::format("cloth.pin_region.min[{0}] = {1} is above max[{0}] = {2}", k, r.min[k], r.max[k]));
  }
  return {};
}

/// The mesh's own consistency (the readers guarantee it for files; the API takes any Mesh).
Result<void> check_mesh(const Mesh& m) {
  const std::size_t n = m.positions.size();
  if (n > max_particles)
    return bad(fmt::format("the mesh has {} vertices, more than the limit {}", n, max_particles));
  if (m.face_count() == 0)
    return bad("the mesh has no faces");
  if (!m.uvs.empty() && m.uvs.size() != n)
    return bad(
        fmt::format("the mesh has {} uvs for {} vertices (give one per vertex or none)", m.uvs.size(), n));
  for (std::size_t v = 0; v < n; ++v)
    if (!usable(m.positions[v]))
      return bad(fmt::format("vertex {} has a non-finite or huge coordinate ({}, {}, {}); |x| must be <= {}",
                             v, m.positions[v].x, m.positions[v].y, m.positions[v].z, max_coordinate));
  if (m.face_offsets.front() != 0 || m.face_offsets.back() != m.indices.size())
    return bad("the mesh's face_offsets do not span its index list");
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    if (m.face_offsets[f + 1] < m.face_offsets[f] + 3)
      return bad(fmt::format("face {} has fewer than 3 vertices", f));
    for (std::uint32_t k = m.face_offsets[f]; k < m.face_offsets[f + 1]; ++k)
      if (m.indices[k] >= n)
        return bad(fmt::format("face {} refers to vertex {}, but the mesh has {}", f, m.indices[k], n));
  }
  return {};
}

glm::dvec3 transformed(const MeshTransform& t, glm::dvec3 p) {
  glm::dmat4 r(1.0);
  r = glm::rotate(r, glm::radians(t.rotate_deg.z), glm::dvec3(0, 0, 1));
  r = glm::rotate(r, glm::radians(t.rotate_deg.y), glm::dvec3(0, 1, 0));
  r = glm::rotate(r, glm::radians(t.rotate_deg.x), glm::dvec3(1, 0, 0));
  return t.translate + glm::dvec3(r * glm::dvec4(t.scale * p, 1.0));
}

bool degenerate(std::span<const std::uint32_t> face, const std::vector<glm::dvec3>& x) {
  for (std::size_t k = 0; k < face.size(); ++k)
    if (x[face[k]] == x[face[(k + 1) % face.size()]])
      return true; // a repeated vertex or a zero-length edge
  return polygon_vector_area(face, x) == glm::dvec3(0.0);
}

/// The file's faces as triangles and quads (larger polygons split into a triangle fan), without
/// the degenerate ones; `dropped` counts those and `first_dropped` names one.
Faces clean_faces(const Mesh& m, const std::vector<glm::dvec3>& x, std::size_t& dropped,
                  std::size_t& first_dropped) {
  Faces out;
  dropped = 0;
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    const std::span<const std::uint32_t> face(m.indices.data() + m.face_offsets[f],
                                              m.face_offsets[f + 1] - m.face_offsets[f]);
    if (degenerate(face, x)) {
      if (dropped++ == 0)
        first_dropped = f;
      continue;
    }
    Faces parts;
    if (face.size() <= 4)
      parts.add(face);
    else
      for (std::size_t k = 1; k + 1 < face.size(); ++k)
        parts.add(std::array{face[0], face[k], face[k + 1]});
    for (std::size_t p = 0; p < parts.size(); ++p) {
      if (degenerate(parts[p], x)) {
        if (dropped++ == 0)
          first_dropped = f;
        continue;
      }
      out.add(parts[p]);
    }
  }
  return out;
}

/// The corner of triangle t where the angle is right (within 1e-6 in cosine), or -1.
int right_corner(std::span<const std::uint32_t> t, const std::vector<glm::dvec3>& x) {
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 p = x[t[std::size_t(k)]];
    const glm::dvec3 a = glm::normalize(x[t[std::size_t((k + 1) % 3)]] - p);
    const glm::dvec3 b = glm::normalize(x[t[std::size_t((k + 2) % 3)]] - p);
    if (std::abs(glm::dot(a, b)) < 1e-6)
      return k;
  }
  return -1;
}

/// A triangle-only file whose triangles (at least 90% of them) pair up into rectangles-like quads
/// across the hypotenuse of two right triangles is read as the quad mesh it was triangulated from
/// (a grid exported as triangles gets the grid's shear and bend springs back). Otherwise unchanged.
Faces merge_right_triangle_pairs(const Faces& faces, const std::vector<glm::dvec3>& x) {
  for (std::size_t f = 0; f < faces.size(); ++f)
    if (faces[f].size() != 3)
      return faces;
  // hypotenuse edge -> the triangles whose right angle faces it
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> by_hypotenuse;
  std::vector<int> right(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    right[f] = right_corner(faces[f], x);
    if (right[f] < 0)
      continue;
    const auto t = faces[f];
    by_hypotenuse[edge_key(t[std::size_t((right[f] + 1) % 3)], t[std::size_t((right[f] + 2) % 3)])].push_back(
        static_cast<std::uint32_t>(f));
  }
  std::vector<std::int64_t> partner(faces.size(), -1);
  std::size_t paired = 0;
  for (const auto& [key, tris] : by_hypotenuse)
    if (tris.size() == 2) {
      partner[tris[0]] = tris[1];
      partner[tris[1]] = tris[0];
      paired += 2;
    }
  if (paired * 10 < faces.size() * 9)
    return faces;
  Faces out;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (partner[f] < 0) {
      out.add(faces[f]);
      continue;
    }
    if (std::size_t(partner[f]) < f)
      continue; // emitted with its partner
    // (q at the right angle, then r, p): the partner holds p, r and s; the quad is (q, r, s, p),
    // written from r so that its split (0, 1, 2), (0, 2, 3) is the file's diagonal r-p again.
    const auto t = faces[f], u = faces[std::size_t(partner[f])];
    const std::uint32_t q = t[std::size_t(right[f])], r = t[std::size_t((right[f] + 1) % 3)],
                        p = t[std::size_t((right[f] + 2) % 3)];
    const std::uint32_t s = u[std::size_t(right[std::size_t(partner[f])])];
    out.add(std::array{r, s, p, q});
  }
  return out;
}

/// Undirected edge -> the faces that hold it; an edge in more than two faces is an error.
using EdgeFaces = std::unordered_map<std::uint64_t, std::array<std::int64_t, 2>>;

Result<EdgeFaces> edge_faces(const Faces& faces, std::span<const std::uint32_t> file_vertex) {
  EdgeFaces map;
  map.reserve(faces.corners.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    for (std::size_t k = 0; k < face.size(); ++k) {
      const std::uint32_t a = face[k], b = face[(k + 1) % face.size()];
      auto [it, fresh] = map.try_emplace(edge_key(a, b), std::array<std::int64_t, 2>{std::int64_t(f), -1});
      if (fresh)
        continue;
      if (it->second[1] >= 0)
        return bad(fmt::format(
            "the edge between vertices {} and {} is shared by more than two faces (non-manifold); "
            "split the mesh there",
            file_vertex[a], file_vertex[b]));
      it->second[1] = std::int64_t(f);
    }
  }
  return map;
}

/// The vertex next to `v` in `face` that is not `not_this` (quads: the other side's neighbour).
std::uint32_t other_neighbour(std::span<const std::uint32_t> face, std::uint32_t v, std::uint32_t not_this) {
  const std::size_t n = face.size();
  const std::size_t k = std::size_t(std::find(face.begin(), face.end(), v) - face.begin());
  const std::uint32_t next = face[(k + 1) % n], prev = face[(k + n - 1) % n];
  return next == not_this ? prev : next;
}

/// The vertex of triangle `face` on neither end of edge (a, b).
std::uint32_t opposite(std::span<const std::uint32_t> face, std::uint32_t a, std::uint32_t b) {
  for (std::uint32_t v : face)
    if (v != a && v != b)
      return v;
  return a;
}

/// Springs from faces, kind by kind (structural, shear, bend), each unordered pair once.
class SpringBuilder {
public:
  SpringBuilder(const std::vector<glm::dvec3>& x, const ClothStiffness& k, const std::optional<Material>& m)
      : x_(x), k_(k), material_(m) {}

  /// Fails only with a material whose structural stiffness would be negative at some spacing.
  Result<void> build(const Faces& faces, const EdgeFaces& edges) {
    for (std::size_t f = 0; f < faces.size(); ++f) // structural: the faces' sides
      for (std::size_t k = 0; k < faces[f].size(); ++k) {
        const std::uint32_t a = faces[f][k], b = faces[f][(k + 1) % faces[f].size()];
        add(a, b, k_.structural, SpringKind::structural, border(edges, a, b) ? 0.5 : 1.0);
      }
    for (std::size_t f = 0; f < faces.size(); ++f) // shear: both diagonals of each quad
      if (const auto q = faces[f]; q.size() == 4) {
        add(q[0], q[2], k_.shear, SpringKind::shear);
        add(q[1], q[3], k_.shear, SpringKind::shear);
      }
    for (std::size_t f = 0; f < faces.size(); ++f) // bend: across each interior side, in face order
      for (std::size_t k = 0; k < faces[f].size(); ++k)
        add_bend(faces, edges, f, faces[f][k], faces[f][(k + 1) % faces[f].size()]);
    return error_ ? Result<void>(*error_) : Result<void>{};
  }

  std::vector<Spring> springs;

private:
  /// A side of one face only. With a material, springs along the border get `border_scale`
  /// times the stiffness (they stand for half a cell, as on the grid).
  static bool border(const EdgeFaces& edges, std::uint32_t a, std::uint32_t b) {
    return edges.at(edge_key(a, b))[1] < 0;
  }

  void add(std::uint32_t a, std::uint32_t b, double k, SpringKind kind, double border_scale = 1.0) {
    if ((!material_ && k <= 0.0) || a == b || !seen_.insert(edge_key(a, b)).second)
      return;
    const double rest = glm::length(x_[b] - x_[a]);
    if (material_) { // the spring's local spacing h, on a square lattice (docs/model.md "Materials")
      const double h = kind == SpringKind::bend    ? 0.5 * rest
                       : kind == SpringKind::shear ? rest / std::sqrt(2.0)
                                                   : rest;
      auto km = spring_stiffness(*material_, kind, h, h);
      if (!km) {
        if (!error_)
          error_ = km.error();
        return;
      }
      k = *km * border_scale;
    }
    springs.push_back(Spring{a, b, rest, k, kind});
  }

  // Quads: the vertices two sides apart across the shared side (the grid's (i, j) - (i + 2, j));
  // triangles: the two vertices opposite the shared side. A quad next to a triangle: none.
  void add_bend(const Faces& faces, const EdgeFaces& edges, std::size_t f, std::uint32_t a, std::uint32_t b) {
    const auto& pair = edges.at(edge_key(a, b));
    const std::int64_t g = pair[0] == std::int64_t(f) ? pair[1] : pair[0];
    if (g < 0 || std::size_t(g) < f)
      return; // a boundary side, or the pair was handled from the other face
    const auto p = faces[f], q = faces[std::size_t(g)];
    if (p.size() == 4 && q.size() == 4) { // through a (its two sides on the border: along it), then b
      const std::uint32_t pa = other_neighbour(p, a, b), qa = other_neighbour(q, a, b);
      const std::uint32_t pb = other_neighbour(p, b, a), qb = other_neighbour(q, b, a);
      add(pa, qa, k_.bend, SpringKind::bend, border(edges, pa, a) && border(edges, a, qa) ? 0.5 : 1.0);
      add(pb, qb, k_.bend, SpringKind::bend, border(edges, pb, b) && border(edges, b, qb) ? 0.5 : 1.0);
    } else if (p.size() == 3 && q.size() == 3) {
      add(opposite(p, a, b), opposite(q, a, b), k_.bend, SpringKind::bend);
    }
  }

  const std::vector<glm::dvec3>& x_;
  ClothStiffness k_;
  const std::optional<Material>& material_; ///< when set, every stiffness comes from it
  std::optional<Error> error_;
  std::unordered_set<std::uint64_t> seen_;
};

/// Runs of this many particles of the spatial order are grouped by valence: the compiled GPU
/// workgroup size (VKCLOTH_WORKGROUP_SIZE; a device that picks another size still gets lanes of
/// one length, only runs that straddle its workgroups) and a multiple of every CPU vector width
/// (8 or 16 lanes).
constexpr std::size_t valence_run = 64;

/// Within each run of valence_run vertices of `order`, the vertices sorted by their number of mesh
/// edges (stable). A SIMD vector (or GPU subgroup) walks its lanes' gather lists together, as long
/// as the longest (the CPU pads every list of a vector to it), and a vertex's lists (fan, springs)
/// grow with its edges: grouping equal counts shortens that walk, while each run keeps its
/// vertices, so the memory a workgroup reads stays the same.
void group_by_valence(std::vector<std::uint32_t>& order, const Faces& faces, std::size_t n_file) {
  // Every face edge, then each once: sorted rather than hashed (a mesh may have millions).
  std::vector<std::uint64_t> edges;
  edges.reserve(faces.corners.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const std::span<const std::uint32_t> c = faces[f];
    for (std::size_t i = 0; i < c.size(); ++i)
      edges.push_back(edge_key(c[i], c[(i + 1) % c.size()]));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<std::uint32_t> valence(n_file, 0);
  for (const std::uint64_t e : edges) {
    ++valence[std::uint32_t(e >> 32)];
    ++valence[std::uint32_t(e)];
  }
  for (std::size_t begin = 0; begin < order.size(); begin += valence_run)
    std::stable_sort(order.begin() + std::ptrdiff_t(begin),
                     order.begin() + std::ptrdiff_t(std::min(order.size(), begin + valence_run)),
                     [&](std::uint32_t u, std::uint32_t v) { return valence[u] < valence[v]; });
}

/// order[p] = the file vertex that becomes particle p: the vertices some face uses, in
/// meshoptimizer's spatial order (a Morton curve: neighbours get nearby indices, so the gather reads
/// nearby memory) grouped by valence within runs (group_by_valence), or in file order.
std::vector<std::uint32_t> particle_order(const Faces& faces, const std::vector<glm::dvec3>& x,
                                          bool reorder) {
  const std::size_t n_file = x.size();
  std::vector<char> used(n_file, 0);
  for (std::uint32_t v : faces.corners)
    used[v] = 1;
  std::vector<std::uint32_t> order;
  for (std::uint32_t v = 0; v < n_file; ++v)
    if (used[v])
      order.push_back(v);
  if (!reorder)
    return order;
  std::vector<float> xyz;
  xyz.reserve(3 * order.size());
  for (std::uint32_t v : order)
    xyz.insert(xyz.end(), {float(x[v].x), float(x[v].y), float(x[v].z)});
  std::vector<std::uint32_t> remap(order.size()); // remap[k] = the new place of order[k]
  meshopt_spatialSortRemap(remap.data(), xyz.data(), order.size(), 3 * sizeof(float));
  std::vector<std::uint32_t> sorted(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    sorted[remap[k]] = order[k];
  group_by_valence(sorted, faces, n_file);
  return sorted;
}

/// Texture coordinates: the file's, else a planar projection on the two widest axes of the mesh's
/// bounding box, each mapped to [0, 1] (a grid's uvs, for a flat rectangle).
std::vector<glm::vec2> particle_uvs(const Mesh& m, std::span<const std::uint32_t> order) {
  std::vector<glm::vec2> uvs(order.size());
  if (!m.uvs.empty()) {
    for (std::size_t p = 0; p < order.size(); ++p)
      uvs[p] = glm::vec2(m.uvs[order[p]]);
    return uvs;
  }
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (std::uint32_t v : order) {
    lo = glm::min(lo, m.positions[v]);
    hi = glm::max(hi, m.positions[v]);
  }
  const glm::dvec3 extent = hi - lo;
  int axes[3] = {0, 1, 2};
  std::stable_sort(axes, axes + 3, [&](int a, int b) { return extent[a] > extent[b]; });
  const int u = std::min(axes[0], axes[1]), v = std::max(axes[0], axes[1]);
  auto unit = [&](std::uint32_t vertex, int axis) {
    return extent[axis] > 0.0 ? float((m.positions[vertex][axis] - lo[axis]) / extent[axis]) : 0.0f;
  };
  for (std::size_t p = 0; p < order.size(); ++p)
    uvs[p] = glm::vec2(unit(order[p], u), unit(order[p], v));
  return uvs;
}

Result<void> apply_pins(const MeshClothDesc& d, const std::vector<glm::dvec3>& x,
                        std::span<const std::uint32_t> particle_of, std::vector<Particle>& particles,
                        std::vector<std::string>& warnings) {
  for (std::size_t k = 0; k < d.pin_vertices.size(); ++k) {
    const std::uint32_t v = d.pin_vertices[k];
    if (v >= particle_of.size())
      return bad(fmt::format("cloth.pin_vertices[{}] = {} is outside the mesh ({} vertices)", k, v,
                             particle_of.size()));
    if (particle_of[v] == ~0u)
      return bad(fmt::format(
          "cloth.pin_vertices[{}] = {} is an isolated vertex (in no face), not part of the cloth", k, v));
    particles[particle_of[v]].pinned = true;
  }
  if (!d.pin_region)
    return {};
  const PinRegion& r = *d.pin_region;
  std::size_t pinned = 0;
  for (std::size_t p = 0; p < particles.size(); ++p)
    if (glm::all(glm::greaterThanEqual(x[p], r.min)) && glm::all(glm::lessThanEqual(x[p], r.max))) {
      particles[p].pinned = true;
      ++pinned;
    }
  if (pinned == 0)
    warnings.push_back(fmt::format("cloth.pin_region [{}, {}, {}] .. [{}, {}, {}] pins no vertex", r.min.x,
                                   r.min.y, r.min.z, r.max.x, r.max.y, r.max.z));
  return {};
}

Surface make_surface(const Mesh& mesh, const Faces& faces, std::vector<std::uint32_t> order) {
  Surface s;
  s.face_offsets = faces.offsets;
  s.faces = faces.corners;
  for (std::size_t f = 0; f < faces.size(); ++f) // quads as (0, 1, 2), (0, 2, 3)
    for (std::size_t k = 1; k + 1 < faces[f].size(); ++k)
      s.triangles.insert(s.triangles.end(), {faces[f][0], faces[f][k], faces[f][k + 1]});
  s.uvs = particle_uvs(mesh, order);
  s.source_vertex = std::move(order);
  return s;
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return fmt::format("{} {}", n, n == 1 ? one : many);
}

} // namespace

Result<MeshCloth> make_mesh_cloth(const Mesh& mesh, const MeshClothDesc& desc) {
  VKCLOTH_TRY(check_desc(desc));
  VKCLOTH_TRY(check_mesh(mesh));
  MeshCloth out;
  const std::size_t n_file = mesh.positions.size();
  std::vector<glm::dvec3> world(n_file);
  for (std::size_t v = 0; v < n_file; ++v)
    if (!usable(world[v] = transformed(desc.transform, mesh.positions[v])))
      return bad(fmt::format("vertex {} is out of range after cloth.mesh_transform (|x| must be <= {})", v,
                             max_coordinate));

  std::size_t dropped = 0, first_dropped = 0;
  Faces faces = clean_faces(mesh, world, dropped, first_dropped);
  if (faces.size() == 0)
    return bad(fmt::format("every one of the mesh's {} faces is degenerate (zero area or a zero-length edge)",
                           mesh.face_count()));
  if (dropped > 0)
    out.warnings.push_back(fmt::format("dropped {} (zero area or a zero-length edge), the first is face {}",
                                       plural(dropped, "degenerate face", "degenerate faces"),
                                       first_dropped));
  faces = merge_right_triangle_pairs(faces, world);

  std::vector<std::uint32_t> order = particle_order(faces, world, desc.reorder);
  if (const std::size_t isolated = n_file - order.size(); isolated > 0)
    out.warnings.push_back(
        fmt::format("dropped {} (in no face)", plural(isolated, "isolated vertex", "isolated vertices")));
  std::vector<std::uint32_t> particle_of(n_file, ~0u);
  for (std::uint32_t p = 0; p < order.size(); ++p)
    particle_of[order[p]] = p;
  for (std::uint32_t& c : faces.corners)
    c = particle_of[c];
  std::vector<glm::dvec3> x(order.size());
  for (std::size_t p = 0; p < order.size(); ++p)
    x[p] = world[order[p]];

  auto edges = edge_faces(faces, order);
  if (!edges)
    return edges.error();
  SpringBuilder springs(x, desc.stiffness, desc.material);
  VKCLOTH_TRY(springs.build(faces, *edges));

  ParticleSystem& sys = out.system;
  sys.particles.resize(order.size());
  for (std::size_t p = 0; p < order.size(); ++p)
    sys.particles[p] = Particle{x[p], {}, desc.particle_mass, false};
  if (desc.material || desc.density) // lumped masses (builders.hpp), shared with the grid
    lump_masses(faces.offsets, faces.corners, x, desc.material ? desc.material->density : *desc.density,
                sys.particles);
  VKCLOTH_TRY(apply_pins(desc, x, particle_of, sys.particles, out.warnings));
  sys.springs = std::move(springs.springs);
  sys.surface = make_surface(mesh, faces, std::move(order));
  sys.finalize();
  VKCLOTH_TRY(sys.validate());
  return out;
}

std::string format_obj(const Mesh& mesh) {
  std::string text = "# vkcloth mesh\n";
  for (const glm::dvec3& p : mesh.positions)
    text += fmt::format("v {:.17g} {:.17g} {:.17g}\n", p.x, p.y, p.z);
  for (const glm::dvec2& t : mesh.uvs)
    text += fmt::format("vt {:.17g} {:.17g}\n", t.x, 1.0 - t.y); // OBJ's v goes up (Mesh::uvs)
  const bool uv = !mesh.uvs.empty();
  for (std::size_t f = 0; f < mesh.face_count(); ++f) {
    text += 'f';
    for (std::uint32_t k = mesh.face_offsets[f]; k < mesh.face_offsets[f + 1]; ++k)
      text += uv ? fmt::format(" {0}/{0}", mesh.indices[k] + 1) : fmt::format(" {}", mesh.indices[k] + 1);
    text += '\n';
  }
  return text;
}

Mesh surface_mesh(const ParticleSystem& system, std::span<const glm::dvec3> positions) {
  Mesh m;
  const std::size_t n = system.size();
  if (system.grid) { // the grid's quads (a, b, d, c) and its uvs
    const std::uint32_t nx = system.grid->nx, ny = system.grid->ny;
    m.positions.assign(positions.begin(), positions.end());
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i < nx; ++i)
        m.uvs.emplace_back(nx > 1 ? double(i) / (nx - 1) : 0.0, ny > 1 ? double(j) / (ny - 1) : 0.0);
    for (std::uint32_t j = 0; j + 1 < ny; ++j)
      for (std::uint32_t i = 0; i + 1 < nx; ++i) {
        const std::uint32_t a = j * nx + i;
        m.indices.insert(m.indices.end(), {a, a + 1, a + 1 + nx, a + nx});
        m.face_offsets.push_back(static_cast<std::uint32_t>(m.indices.size()));
      }
    return m;
  }
  if (!system.surface)
    return m;
  const Surface& s = *system.surface;
  // Particles in file vertex order (isolated file vertices were dropped: indices close up).
  const std::vector<std::uint32_t> by_file = file_order(system);
  std::vector<std::uint32_t> out_index(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    out_index[by_file[k]] = k;
    m.positions.push_back(positions[by_file[k]]);
    m.uvs.emplace_back(s.uvs[by_file[k]]);
  }
  const bool faces = !s.face_offsets.empty();
  const std::span<const std::uint32_t> corners = faces ? s.faces : s.triangles;
  for (std::size_t f = 0; f + 1 < (faces ? s.face_offsets.size() : s.triangles.size() / 3 + 1); ++f) {
    const std::size_t begin = faces ? s.face_offsets[f] : 3 * f,
                      end = faces ? s.face_offsets[f + 1] : 3 * f + 3;
    for (std::size_t k = begin; k < end; ++k)
      m.indices.push_back(out_index[corners[k]]);
    m.face_offsets.push_back(static_cast<std::uint32_t>(m.indices.size()));
  }
  return m;
}

} // namespace vkcloth
