// SPDX-License-Identifier: MIT
// `vkcloth bench`'s scenes: the hanging grid, a mesh file's cloth, the contact scenes (a cloth on a
// table, on a mesh sphere) and the folded cloth of the self-collision rows, and their contact counts.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "bench.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/measure.hpp"

namespace vkcloth::cli::bench {
namespace {

/// "S,H,B" -> the three stiffnesses, each finite and >= 0.
Result<void> parse_stiffness(const std::string& text, ClothStiffness& out) {
  double v[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 ||
      !(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) || v[0] < 0 || v[1] < 0 ||
      v[2] < 0)
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("--stiffness: '{}' is not three stiffnesses >= 0 (N/m), e.g. 10000,2000,2000", text));
  out.structural = v[0];
  out.shear = v[1];
  out.bend = v[2];
  return {};
}

/// The bench's n x n grid, 1 m x 1 m: m = 0.05 kg * 4096 / n^2 per particle (or --cloth-mass over the
/// whole grid) and --stiffness.
Result<ClothDesc> bench_grid(std::uint32_t n, const BenchOptions& o) {
  ClothDesc d;
  d.nx = n;
  d.ny = n;
  d.size = {1.0, 1.0};
  d.particle_mass = o.cloth_mass.value_or(0.05 * 4096.0) / (double(n) * double(n));
  if (!o.stiffness.empty())
    VKCLOTH_TRY(parse_stiffness(o.stiffness, d.stiffness));
  return d;
}

} // namespace

Result<BenchScene> bench_scene(std::uint32_t n, Integrator integrator, double dt, const BenchOptions& o) {
  auto grid = bench_grid(n, o);
  if (!grid)
    return grid.error();
  const ClothDesc& d = *grid;
  auto sys = make_cloth(d);
  if (!sys)
    return sys.error();
  SimParams p;
  p.integrator = integrator;
  p.dt = dt;
  p.wind.strength = o.wind * d.particle_mass; // ~2 m/s^2 on a cloth facing the wind
  p.wind.direction = {0.3, 1.0, 0.1};
  VKCLOTH_TRY(p.validate());
  return BenchScene{std::move(*sys), p};
}

/// The bench's cloth made from a mesh file instead of a grid: the same per-particle mass scaling
/// (the total mass of the 64 x 64 cloth), stiffnesses, wind and dt; vertex 0 pinned. `order`:
/// "meshopt" (the library's default renumbering), "file" (the file's vertex order) or "shuffled"
/// (the file's vertices in a fixed pseudo-random order: what reordering is up against when a
/// file's order has no locality).
Result<BenchScene> mesh_bench_scene(const Mesh& file, const std::string& order, Integrator integrator,
                                    double dt) {
  Mesh mesh = file;
  if (order == "shuffled") {
    const std::size_t n = mesh.positions.size();
    std::vector<std::uint32_t> to(n);
    std::iota(to.begin(), to.end(), 0u);
    std::uint64_t state = 0x9e3779b97f4a7c15ull;
    for (std::size_t k = n; k > 1; --k) { // Fisher-Yates with a fixed LCG: the same order every run
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      std::swap(to[k - 1], to[(state >> 33) % k]);
    }
    for (std::size_t v = 0; v < n; ++v)
      mesh.positions[to[v]] = file.positions[v];
    if (!mesh.uvs.empty())
      for (std::size_t v = 0; v < n; ++v)
        mesh.uvs[to[v]] = file.uvs[v];
    for (std::uint32_t& i : mesh.indices)
      i = to[i];
  }
  MeshClothDesc d;
  d.reorder = order == "meshopt";
  d.particle_mass = 0.05 * 4096.0 / double(std::max<std::size_t>(mesh.positions.size(), 1));
  d.pin_vertices = {0};
  auto cloth = make_mesh_cloth(mesh, d);
  if (!cloth)
    return cloth.error();
  SimParams p;
  p.integrator = integrator;
  p.dt = dt;
  p.wind.strength = 2.0 * d.particle_mass;
  p.wind.direction = {0.3, 1.0, 0.1};
  VKCLOTH_TRY(p.validate());
  return BenchScene{std::move(cloth->system), p};
}

// ---- Contact scenes -----------------------------------------------------------------

namespace {

/// The bench's horizontal n x n cloth (1 m x 1 m centred on the z axis, no pins, no wind), with the
/// grid rows' per-particle mass scaling (m = 0.05 kg * 4096 / n^2, or --cloth-mass) and stiffness:
/// the contact scenes move its particles onto their colliders (the springs keep the flat grid's rest
/// lengths).
Result<BenchScene> horizontal_cloth(std::uint32_t n, Integrator integrator, double dt,
                                    const BenchOptions& o) {
  auto grid = bench_grid(n, o);
  if (!grid)
    return grid.error();
  ClothDesc& d = *grid;
  d.orientation = ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, 0.0};
  d.pin_default_corners = false;
  auto sys = make_cloth(d);
  if (!sys)
    return sys.error();
  SimParams p;
  p.integrator = integrator;
  p.dt = dt;
  return BenchScene{std::move(*sys), p};
}

Collider with_contact_friction(Collider c) {
  c.friction = contact_friction;
  return c;
}

} // namespace

/// A 256 x 256 tablecloth on a table: a box 0.5 m wide (x), 1.2 m long (y) and 0.2 m high standing
/// on the floor plane z = 0, both with friction 0.6. The cloth starts draped, at rest: flat on the
/// top at eps above it over |x| <= 0.25 + eps, then down both long sides at eps from them, and its
/// last 5 cm along the floor at eps above it (each grid line across the table keeps its length; only
/// the bend springs across the two folds start compressed). Every particle starts within 2 eps of a
/// collider, so the timed steps are contact steps from the first on.
Result<ContactScene> table_scene(Integrator integrator, double dt, const BenchOptions& o) {
  constexpr std::uint32_t n = 256;
  auto cloth = horizontal_cloth(n, integrator, dt, o);
  if (!cloth)
    return cloth.error();
  SimParams p = cloth->params;
  const double eps = p.contact_epsilon, half_width = 0.25, height = 0.2;
  p.colliders = {
      with_contact_friction(Collider::box({0.0, 0.0, 0.5 * height}, {half_width, 0.6, 0.5 * height})),
      with_contact_friction(Collider::plane({0.0, 0.0, 1.0}, 0.0))};
  VKCLOTH_TRY(p.validate());
  const double side = half_width + eps, top = height + eps,
               drop = height; // the path at eps from the surfaces
  for (Particle& q : cloth->system.particles) {
    const double s = std::abs(q.position.x), sign = q.position.x < 0.0 ? -1.0 : 1.0;
    if (s <= side) {
      q.position.z = top;
    } else if (s <= side + drop) {
      q.position.x = sign * side;
      q.position.z = top - (s - side);
    } else {
      q.position.x = sign * (side + (s - side - drop));
      q.position.z = eps;
    }
  }
  return ContactScene{"table", n, std::move(cloth->system), std::move(p), {"box", "plane"}, 0};
}

namespace {

/// A geodesic sphere: the icosahedron's faces each cut into frequency^2 triangles, their corners
/// pushed onto the sphere of `radius` about the origin; 20 frequency^2 triangles, counter-clockwise
/// seen from outside. Computed in double from fixed constants: the same mesh every run.
Result<std::shared_ptr<const ColliderMesh>> geodesic_sphere(std::uint32_t frequency, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  const std::array<glm::dvec3, 12> ico = {{{-1, t, 0},
                                           {1, t, 0},
                                           {-1, -t, 0},
                                           {1, -t, 0},
                                           {0, -1, t},
                                           {0, 1, t},
                                           {0, -1, -t},
                                           {0, 1, -t},
                                           {t, 0, -1},
                                           {t, 0, 1},
                                           {-t, 0, -1},
                                           {-t, 0, 1}}};
  const std::array<std::uint32_t, 60> faces = {
      0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
      3, 9,  4, 3, 4, 2, 3, 2, 6, 3, 6, 8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};
  std::vector<glm::dvec3> positions;
  std::vector<std::uint32_t> triangles;
  const std::uint32_t f = frequency;
  for (std::size_t k = 0; k < faces.size(); k += 3) {
    glm::dvec3 a = ico[faces[k]], b = ico[faces[k + 1]], c = ico[faces[k + 2]];
    if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0.0)
      std::swap(b, c); // outward
    // Point (i, j) of the face, i + j <= f, at index base + row offset + j.
    const auto first = std::uint32_t(positions.size());
    auto at = [&](std::uint32_t i, std::uint32_t j) {
      return first + i * (f + 1) - i * (i - 1) / 2 + j; // rows i = 0.. have f + 1, f, ... points
    };
    for (std::uint32_t i = 0; i <= f; ++i)
      for (std::uint32_t j = 0; i + j <= f; ++j)
        positions.push_back(radius *
                            glm::normalize(a + (b - a) * (double(i) / f) + (c - a) * (double(j) / f)));
    for (std::uint32_t i = 0; i < f; ++i)
      for (std::uint32_t j = 0; i + j < f; ++j) {
        triangles.insert(triangles.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j + 1 < f)
          triangles.insert(triangles.end(), {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  return ColliderMesh::create(positions, triangles,
                              fmt::format("geodesic sphere ({} triangles)", 20 * f * f));
}

} // namespace

/// A 64 x 64 cloth draped on a mesh collider: a geodesic sphere of radius 0.6 m (frequency 22:
/// 9 680 triangles, ~3 cm edges, a 13-level hierarchy), thickness 5 mm, friction 0.6, centred at
/// (0, 0, 0.6). The cloth starts at rest wrapped around its top at eps outside the shell: the grid
/// point at (x, y) from the cloth's centre goes to the point of the sphere of radius 0.6 +
/// thickness + eps at the arc length |(x, y)| from its top, towards (x, y) (the azimuthal
/// equidistant map: the grid lines through the centre keep their lengths, the others start
/// compressed, up to 21 % at the corners, 67 degrees from the top). Every particle starts within
/// 2 eps of the shell (the faces lie within 0.23 mm inside the sphere through their corners); as
/// the heavy cloth settles, its border slides and lifts off (particles_in_contact_end).
/// `analytic`: the same cloth on a sphere collider of radius 0.6 + thickness instead (the "sphere"
/// row, the yardstick of the mesh query's cost).
Result<ContactScene> mesh_scene(Integrator integrator, double dt, const BenchOptions& o, bool analytic) {
  constexpr std::uint32_t n = 64;
  constexpr double radius = 0.6, thickness = 0.005;
  auto cloth = horizontal_cloth(n, integrator, dt, o);
  if (!cloth)
    return cloth.error();
  auto sphere = geodesic_sphere(sphere_frequency, radius);
  if (!sphere)
    return sphere.error();
  SimParams p = cloth->params;
  const glm::dvec3 centre{0.0, 0.0, radius};
  p.colliders = {
      with_contact_friction(analytic ? Collider::sphere(centre, radius + thickness)
                                     : Collider::triangle_mesh(*sphere, centre, glm::dmat3(1.0), thickness))};
  VKCLOTH_TRY(p.validate());
  const double r = radius + thickness + p.contact_epsilon;
  for (Particle& q : cloth->system.particles) {
    const double x = q.position.x, y = q.position.y, d = std::sqrt(x * x + y * y), angle = d / r;
    const glm::dvec3 dir = d > 0.0
                               ? glm::dvec3(std::sin(angle) * x / d, std::sin(angle) * y / d, std::cos(angle))
                               : glm::dvec3(0, 0, 1);
    q.position = centre + r * dir;
  }
  if (analytic)
    return ContactScene{"sphere", n, std::move(cloth->system), std::move(p), {"sphere"}, 0};
  const auto triangles = std::uint32_t((*sphere)->triangles().size());
  return ContactScene{"mesh", n, std::move(cloth->system), std::move(p), {"mesh"}, triangles};
}

/// Free particles within 2 contact_epsilon of a collider (signed distance below the solvers' contact
/// band), measured in double with cloth_kernel.h's distance (vkcloth::penetration, one particle at a
/// time; a mesh: from the particle's own side).
Result<std::size_t> particles_in_contact(const ContactScene& sc, std::span<const glm::dvec3> positions) {
  ClothDesc d;
  d.nx = d.ny = 1;
  d.pin_default_corners = false;
  auto one = make_cloth(d);
  if (!one)
    return one.error();
  std::size_t count = 0;
  const double band = 2.0 * sc.params.contact_epsilon;
  for (std::size_t k = 0; k < positions.size(); ++k) {
    if (sc.system.particles[k].pinned)
      continue;
    auto depth = penetration(*one, sc.params.colliders, positions.subspan(k, 1));
    if (!depth)
      return depth.error();
    count += -depth->depth < band;
  }
  return count;
}

// ---- Self-collision scene -----------------------------------------------------------

/// The bench's horizontal n x n cloth (grid rows' mass scaling and stiffness; no pins, no wind),
/// folded like an accordion into 4 layers stacked on the floor plane z = 0 (friction 0.6), with
/// self-collision on (thickness 1.5 x the spacing, friction 0.2, the default 1 iteration). Each grid line
/// along y keeps its length: the layers are joined by vertical segments at the two ends of the stack (the
/// folds; only the springs across the 90-degree kinks start compressed), the bottom layer at eps
/// above the floor, the layers 1.001 x the thickness apart. The solvers take the starting positions
/// as the rest positions of their filter (pairs closer than the thickness at rest never collide), so
/// the layers must start farther apart than the thickness; they fall the 0.1 % onto each other in
/// the first steps and rest there, every particle of a layer pressed onto the one below by gravity
/// (in every substep the update moves them into each other and the self-collision passes push them
/// back apart).
Result<SelfScene> folded_scene(std::uint32_t n, Integrator integrator, double dt, const BenchOptions& o) {
  auto cloth = horizontal_cloth(n, integrator, dt, o);
  if (!cloth)
    return cloth.error();
  SimParams p = cloth->params;
  const double spacing = 1.0 / double(n - 1);
  p.self_collision.enabled = true;
  p.self_collision.thickness = self_thickness_over_spacing * spacing;
  p.self_collision.friction = self_friction;
  p.self_collision.iterations = self_iterations;
  p.self_collision.skin = o.self_skin * p.self_collision.thickness;
  p.self_collision.stiffness = o.self_stiffness;
  p.colliders = {with_contact_friction(Collider::plane({0.0, 0.0, 1.0}, 0.0))};
  VKCLOTH_TRY(p.validate());
  auto warnings = check_self_collision(p.self_collision, cloth->system); // none at 1.5 spacings
  if (!warnings)
    return warnings.error();
  const double sep = self_layer_gap * p.self_collision.thickness;
  const double length = (1.0 - double(self_layers - 1) * sep) / double(self_layers); // of one layer
  const double y0 = -0.5 * length, y1 = 0.5 * length;
  for (Particle& q : cloth->system.particles) {
    const double t = q.position.y + 0.5; // the arc length along y from the cloth's first row
    auto k = std::uint32_t(std::min(std::floor(t / (length + sep)), double(self_layers - 1)));
    const double u = t - double(k) * (length + sep); // from the start of layer k
    const double z = p.contact_epsilon + double(k) * sep;
    if (u <= length) {
      q.position.y = k % 2 ? y1 - u : y0 + u;
      q.position.z = z;
    } else { // the fold up to layer k + 1
      q.position.y = k % 2 ? y0 : y1;
      q.position.z = z + (u - length);
    }
  }
  std::vector<glm::dvec3> rest;
  for (const Particle& q : cloth->system.particles)
    rest.push_back(q.position);
  return SelfScene{n, std::move(cloth->system), std::move(p), std::move(rest)};
}

/// Particles in self-contact, and pairs: within 1.05 x the thickness of a particle that was not closer than
/// the thickness at rest (the solvers' rest-position filter, cloth_kernel.h self_pair), in double from the
/// float positions and rest positions; a spatial hash of cells 1.05 thickness wide, the 27 cells around each
/// particle. A band, not the solvers' "closer than the thickness", because a step ends with its
/// self-collision passes, which leave a resolved pair exactly the thickness apart, and the resting layers
/// hover 1-5 % of the thickness apart between the substeps that push them together; the grid's next particles
/// but one, 2 spacings = 1.33 thicknesses apart, stay outside it.
SelfContact self_contact(const SelfScene& sc, std::span<const glm::vec3> positions) {
  const double thickness = sc.params.self_collision.thickness, rest2 = thickness * thickness;
  const double t = self_contact_band * thickness, t2 = t * t;
  using Cell = std::array<std::int64_t, 3>;
  auto cell = [&](const glm::dvec3& x) {
    return Cell{std::int64_t(std::floor(x.x / t)), std::int64_t(std::floor(x.y / t)),
                std::int64_t(std::floor(x.z / t))};
  };
  // 21 bits per axis, exact within +-2^20 cells (farther, cells share keys: more candidates only).
  auto key = [](const Cell& c, int dx, int dy, int dz) {
    return (std::uint64_t((c[0] + dx) & 0x1fffff) << 42) | (std::uint64_t((c[1] + dy) & 0x1fffff) << 21) |
           std::uint64_t((c[2] + dz) & 0x1fffff);
  };
  std::vector<glm::dvec3> x(positions.begin(), positions.end()), r(x.size());
  for (std::size_t k = 0; k < x.size(); ++k)
    r[k] = glm::dvec3(glm::vec3(sc.rest[k])); // the rest positions as the solvers hold them
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells;
  for (std::size_t k = 0; k < x.size(); ++k)
    cells[key(cell(x[k]), 0, 0, 0)].push_back(std::uint32_t(k));
  SelfContact count;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const Cell c = cell(x[k]);
    bool touching = false;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto at = cells.find(key(c, dx, dy, dz));
          if (at == cells.end())
            continue;
          for (std::uint32_t q : at->second) {
            const glm::dvec3 u = x[k] - x[q], v = r[k] - r[q];
            const double d2 = glm::dot(u, u);
            if (q != k && d2 < t2 && d2 > 0.0 && !(glm::dot(v, v) < rest2)) {
              touching = true;
              count.pairs += q > k; // each pair once
            }
          }
        }
    count.particles += touching;
  }
  return count;
}

} // namespace vkcloth::cli::bench
