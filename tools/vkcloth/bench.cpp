// SPDX-License-Identifier: MIT
// `vkcloth bench`: throughput of the solvers on the report's hanging cloth (structural, shear and
// bend springs, two pinned corners, wind) at several grid sizes, against this machine's memory
// and compute ceilings. Bytes and flops per particle-step are counted from the kernels (the
// counting is documented in docs/performance.md). A table for people, --json for tools.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numeric>
#include <optional>
#include <sstream>
#include <thread>
#include <tuple>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "vkcloth/builders.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/layout.hpp"
#include "vkcloth/gpu/world.hpp"
#include "vkcloth/measure.hpp"
#include "vkcloth/mesh.hpp"

namespace vkcloth::cli {
namespace {

struct BenchOptions {
  std::string backend = "all";
  std::string sizes = "64,128,256,512,1024";
  std::uint64_t steps = 200;
  std::uint64_t warmup = 20;
  unsigned reps = 3;
  std::string integrator = "semi_implicit_euler";
  unsigned threads = 0;
  std::uint32_t steps_per_submit = 100;
  std::uint32_t instances = 1;
  std::optional<double> dt;
  double memory_gbps = 39.0;
  double compute_gflops = 192.0;
  std::string json;
  std::string variants = "fused,two_pass"; // Vulkan layouts to time (RK4 and implicit: always one)
  std::string layout = "auto";             // Vulkan buffer access(es): auto, texel, storage, comma-separated
  std::uint32_t workgroup = 0;             // Vulkan workgroup size (0: the device's choice)
  std::string mesh;      // also time this mesh (OBJ / glTF): reordered, in file order, and shuffled
  std::string stretch;   // also time each grid with stretch_limit {method: this, max_strain 0.1, 4 sweeps}
  std::string stiffness; // "S,H,B": the grid's structural, shear and bend stiffness (default 40,8,8)
  std::optional<double> cloth_mass; // kg, the whole grid's (default: 0.05 kg per particle at 64 x 64)
  double wind = 2.0; // m/s^2 on a particle facing the wind (the wind force scales with the mass)
  std::string cg_dispatch = "auto"; // implicit on Vulkan: auto | one_workgroup | per_iteration | both
  std::string contact;              // also time the contact scenes (issue 15): table | mesh | both
  bool self_collision = false;      // also time each size folded, self-collision on vs off (issue 16)
};

/// The benchmark scene at n x n: a 1 m x 1 m vertical cloth hanging from its two top corners, in
/// the wind. The total mass stays that of a 64 x 64 cloth of 0.05 kg particles scaled to the grid
/// (m = 0.05 kg * 4096 / n^2), and the wind
/// force scales with m, so the accelerations are the same at every size; dt = 5e-4 s keeps the
/// stiffest size (1024: sqrt(k/m) ~ 450 1/s per spring) well inside the Euler stability limit.
struct BenchScene {
  ParticleSystem system;
  SimParams params;
};

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

// ---- Contact scenes (issue 15) -----------------------------------------------------------------

/// A cloth resting on colliders, and what the contact rows report about it. `params` has the
/// colliders; the baseline row times the same system with params.colliders cleared.
struct ContactScene {
  std::string name; // "table" | "mesh"
  std::uint32_t n = 0;
  ParticleSystem system;
  SimParams params;
  std::vector<std::string> kinds; // the colliders' types, in order
  std::uint32_t triangles = 0;    // a mesh collider's triangles (0 for the table)
};

constexpr double contact_friction = 0.6; // kinetic = static, every collider of the contact scenes
constexpr std::uint32_t sphere_frequency =
    22; // the mesh scene's geodesic sphere: 20 x 22^2 = 9 680 triangles

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

/// A 64 x 64 cloth draped on a mesh collider: a geodesic sphere of radius 0.6 m (frequency 22:
/// 9 680 triangles, ~3 cm edges, a 13-level hierarchy), thickness 5 mm, friction 0.6, centred at
/// (0, 0, 0.6). The cloth starts at rest wrapped around its top at eps outside the shell: the grid
/// point at (x, y) from the cloth's centre goes to the point of the sphere of radius 0.6 +
/// thickness + eps at the arc length |(x, y)| from its top, towards (x, y) (the azimuthal
/// equidistant map: the grid lines through the centre keep their lengths, the others start
/// compressed, up to 21 % at the corners, 67 degrees from the top). Every particle starts within
/// 2 eps of the shell (the faces lie within 0.23 mm inside the sphere through their corners); as
/// the heavy cloth settles, its border slides and lifts off (particles_in_contact_end).
Result<ContactScene> mesh_scene(Integrator integrator, double dt, const BenchOptions& o) {
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
  p.colliders = {with_contact_friction(Collider::triangle_mesh(*sphere, centre, glm::dmat3(1.0), thickness))};
  VKCLOTH_TRY(p.validate());
  const double r = radius + thickness + p.contact_epsilon;
  for (Particle& q : cloth->system.particles) {
    const double x = q.position.x, y = q.position.y, d = std::sqrt(x * x + y * y), angle = d / r;
    const glm::dvec3 dir = d > 0.0
                               ? glm::dvec3(std::sin(angle) * x / d, std::sin(angle) * y / d, std::cos(angle))
                               : glm::dvec3(0, 0, 1);
    q.position = centre + r * dir;
  }
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

// ---- Self-collision scene (issue 16) -----------------------------------------------------------

/// The self-collision rows' parameters: thickness = 1.5 x the grid spacing, the thickness that closes
/// the gaps between particles (a particle of another layer is pushed off anywhere in a grid square,
/// whose centre is 0.71 spacings from its corners; the 8 neighbours, up to 1.41 spacings away, are
/// all within it at rest and never collide), friction 0.2 and 2 Jacobi iterations (SelfCollision's
/// defaults).
constexpr double self_thickness_over_spacing = 1.5;
constexpr double self_friction = 0.2;
constexpr std::uint32_t self_iterations = SelfCollision{}.iterations; // the default (1)
constexpr std::uint32_t self_layers = 4;                              // the folded cloth's layers
constexpr double self_layer_gap = 1.001;    // the layers' starting distance, in thicknesses
constexpr double self_contact_band = 1.05;  // "in self-contact": within this many thicknesses
constexpr std::uint32_t self_min_size = 16; // below this the layers are ~1 spacing long

/// The n x n cloth folded on the floor, and what the self-collision rows report about it. `params`
/// has self-collision on; the baseline row times the same system with it off.
struct SelfScene {
  std::uint32_t n = 0;
  ParticleSystem system;
  SimParams params;
  std::vector<glm::dvec3> rest; // the starting positions: the solvers' rest-position filter
};

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

/// Particles in self-contact: within 1.05 x the thickness of a particle that was not closer than the
/// thickness at rest (the solvers' rest-position filter, cloth_kernel.h self_pair), in double from
/// the float positions and rest positions; a spatial hash of cells 1.05 thickness wide, the 27 cells
/// around each particle. A band, not the solvers' "closer than the thickness", because a step ends
/// with its self-collision passes, which leave a resolved pair exactly the thickness apart, and the
/// resting layers hover 1-5 % of the thickness apart between the substeps that push them together;
/// the grid's next particles but one, 2 spacings = 1.33 thicknesses apart, stay outside it.
std::size_t particles_in_self_contact(const SelfScene& sc, std::span<const glm::vec3> positions) {
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
  std::size_t count = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const Cell c = cell(x[k]);
    bool touching = false;
    for (int dz = -1; dz <= 1 && !touching; ++dz)
      for (int dy = -1; dy <= 1 && !touching; ++dy)
        for (int dx = -1; dx <= 1 && !touching; ++dx) {
          const auto at = cells.find(key(c, dx, dy, dz));
          if (at == cells.end())
            continue;
          for (std::uint32_t q : at->second) {
            const glm::dvec3 u = x[k] - x[q], v = r[k] - r[q];
            const double d2 = glm::dot(u, u);
            if (q != k && d2 < t2 && d2 > 0.0 && !(glm::dot(v, v) < rest2)) {
              touching = true;
              break;
            }
          }
        }
    count += touching;
  }
  return count;
}

/// Bytes and flops per particle-step counted from the kernels (docs/performance.md, "Counting").
/// `s` is the mean number of springs per particle (gather-list entries / particles).
struct Cost {
  double bytes = 0, flops = 0;
};

double kernel_flops(double s, bool grid, double fans, bool wind) {
  // grid: 4 edges 12, 4 crosses 36, sum 12, length 5 + sqrt 1, divide 3; a mesh's fan: per term
  // 2 edges 6, a cross 9, sum 3, then the same normalisation 9.
  const double normal = grid ? 69.0 : fans > 0.0 ? 18.0 * fans + 9.0 : 0.0;
  const double springs = 18.0 * s; // u 3, dot 5, sqrt 1, (len - L) 1, k * 1, / len 1, u * 3, += 3
  const double external = 6.0 + 7.0 + (wind ? 12.0 : 0.0); // gravity, damping, wind
  return normal + springs + external;
}

// `grid`: the bench's regular cloth, whose springs both solvers sum from the grid stencil (no
// CSR reads since round 4); `steps_per_submit`: fused Vulkan steps store forces and normals only
// in the last step of a submission.
// `fans`: a mesh's mean normal-fan terms per particle (0 for grids and chains), read from CSR lists.
Cost cost_of(const std::string& variant, Integrator integrator, double s, bool grid, double fans, bool wind,
             std::uint32_t steps_per_submit) {
  Cost c;
  const double eval = kernel_flops(s, grid, fans, wind);
  const bool rk4 = integrator == Integrator::rk4;
  // Euler update: a = f/m 3, two axpys 12. RK4: 4 stages (eval + k sums 6 + next stage 12), final 12.
  c.flops = rk4 ? 4.0 * (eval + 18.0) + 12.0 : eval + 15.0;
  // offsets + edges (12 bytes on the CPU, whose list kernel pads them per vector, ~15 % on a
  // mesh, not counted; 16 on the GPU: one RGBA32UI texel); a mesh's fan lists: offsets + 8-byte terms
  const double edge_bytes = variant == "cpu" ? 12.0 : 16.0;
  const double csr = grid ? 0.0 : 4.0 + edge_bytes * s + (fans > 0.0 ? 4.0 + 8.0 * fans : 0.0);
  if (variant == "cpu") {
    // float vec3 (12 B): read pos, vel; write pos_next, vel, force, normal (and, on grids, the
    // next step's SoA position copy); mass 4 + pinned 1.
    const double euler = 6 * 12.0 + 5.0 + csr + (grid ? 12.0 : 0.0);
    c.bytes = rk4 ? 4.0 * (4 * 12.0 + 5.0 + csr + 6 * 12.0) + 4 * 12.0 : euler;
  } else if (variant == "fused" || variant == "batched" || variant == "unbatched") {
    // vec4 (16 B): read pos, vel, particle 8; write pos, vel; force, normal once per submission.
    c.bytes = 16.0 * 2 + 8.0 + csr + 16.0 * 2 + 16.0 * 2 / double(std::max(steps_per_submit, 1u));
  } else {
    // two-pass: force reads pos, vel, particle, CSR; writes force, vel_filt, normal.
    //           integrate reads particle, force, vel_filt, pos; writes pos, vel.
    const double force = 16.0 * 2 + 8.0 + csr + 16.0 * 3;
    const double integ = 8.0 + 16.0 * 3 + 16.0 * 2;
    // RK4 stages also read and write the running sums and write the stage state (4 x 16 B more).
    c.bytes = rk4 ? 4.0 * (force + integ + 64.0) : force + integ;
  }
  return c;
}

struct Row {
  std::string cg_dispatch; // implicit on Vulkan: "one_workgroup" or "per_iteration"
  double cg_per_step = 0;  // implicit_euler: mean CG iterations per step over the timed steps
  std::string backend, variant;
  std::uint32_t size = 0;
  std::size_t particles = 0, springs = 0;
  unsigned threads = 0;
  std::uint64_t steps = 0;
  unsigned reps = 0;
  double wall_ms = 0;              // median over reps of the wall time of `steps` steps
  double gpu_ms = -1;              // median GPU (timestamp) time of `steps` steps; -1 for the CPU
  std::string integrator;          // the scheme timed (implicit runs add a semi-implicit baseline row)
  std::uint32_t cg_iterations = 0; // implicit_euler: CG iterations of the last step
  std::uint32_t instances = 1;     // cloths stepped together (ClothWorld rows)
  std::string scene = "grid";      // "grid" (n x n) or "mesh" (--mesh)
  std::string order;               // mesh rows: "meshopt", "file" or "shuffled"
  std::string layout;              // Vulkan rows: the buffer access that ran ("texel" | "storage")
  std::uint32_t workgroup = 0;     // Vulkan rows: the workgroup size that ran
  std::string contact;             // contact rows: "table" | "mesh" (scene "contact" or "contact_free")
  std::size_t in_contact_start = 0, in_contact_end = 0; // scene "contact": particles within 2 eps;
                                                        // "self_collision": in self-contact
  std::vector<std::string> colliders;                   // scene "contact": their types
  std::uint32_t collider_triangles = 0;                 // scene "contact": a mesh collider's
  double self_thickness = 0; // self-collision rows: the thickness (m) of the "on" row's parameters
  // Mesh rows: the grid the row is quoted against, timed in alternation with it (each repetition
  // runs `steps` of the grid, then of the mesh): its side and median wall time (-1: not paired).
  std::uint32_t partner_size = 0;
  double partner_ms = -1;
  Cost cost;
};

/// Mean CG iterations per solve between two snapshots of a solver's statistics.
double cg_per_step(const SolveStats& before, const SolveStats& after) {
  const std::uint64_t solves = after.solves - before.solves;
  return solves ? double(after.total_iterations - before.total_iterations) / double(solves) : 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// A grid a mesh row is timed against in alternation (Row::partner_ms), so that a machine whose
/// speed drifts (other jobs on its cores) slows both alike.
struct Partner {
  const BenchScene& scene;
  std::uint32_t size;
};

/// `reps` repetitions of `steps` steps of `run(steps)`, each after one of `partner_run(steps)`
/// when given: the medians of the wall times (the partner's -1 without one). Every timed
/// alternation of the bench goes through here (mesh rows and their grid, alternate_contact).
template <typename Run, typename PartnerRun>
Result<std::pair<double, double>> timed_reps(const BenchOptions& o, Run run, PartnerRun* partner_run) {
  std::vector<double> wall, partner_wall;
  for (unsigned r = 0; r < o.reps; ++r) {
    if (partner_run) {
      const auto t0 = Clock::now();
      VKCLOTH_TRY((*partner_run)(o.steps));
      partner_wall.push_back(ms_since(t0));
    }
    const auto t0 = Clock::now();
    VKCLOTH_TRY(run(o.steps));
    wall.push_back(ms_since(t0));
  }
  return std::pair{median(wall), partner_run ? median(partner_wall) : -1.0};
}

Result<Row> bench_cpu(const BenchScene& sc, std::uint32_t n, const BenchOptions& o,
                      std::optional<Partner> partner = std::nullopt) {
  CpuSolverOptions co;
  co.threads = o.threads;
  auto s = CpuSolver<float>::create(sc.system, sc.params, co);
  if (!s)
    return s.error();
  std::optional<CpuSolver<float>> grid;
  if (partner) {
    auto g = CpuSolver<float>::create(partner->scene.system, partner->scene.params, co);
    if (!g)
      return g.error();
    grid.emplace(std::move(*g));
    VKCLOTH_TRY(grid->run(o.warmup));
  }
  VKCLOTH_TRY(s->run(o.warmup));
  const SolveStats before = s->last_solve();
  auto grid_run = [&](std::uint64_t steps) { return grid->run(steps); };
  auto times = timed_reps(
      o, [&](std::uint64_t steps) { return s->run(steps); }, grid ? &grid_run : nullptr);
  if (!times)
    return times.error();
  Row row;
  row.backend = "cpu";
  row.variant = "cpu";
  row.integrator = to_string(sc.params.integrator);
  row.cg_iterations = s->last_solve().iterations;
  row.cg_per_step = cg_per_step(before, s->last_solve());
  row.threads = s->threads();
  row.size = n;
  row.wall_ms = times->first;
  row.partner_ms = times->second;
  row.partner_size = partner ? partner->size : 0;
  return row;
}

/// The buffer access and workgroup size a solver created with `go` runs on `ctx` (DeviceLayout).
std::pair<std::string, std::uint32_t> layout_of(gpu::Context& ctx, const gpu::GpuSolverOptions& go,
                                                bool implicit) {
  const gpu::DeviceLayout d = gpu::device_layout(ctx);
  const gpu::BufferAccess a = go.buffer_access == gpu::BufferAccess::automatic ? d.access : go.buffer_access;
  if (implicit) // implicit.comp reads storage buffers in workgroups of 64 on every device
    return {gpu::to_string(gpu::BufferAccess::storage_buffers), 64u};
  return {gpu::to_string(a), go.workgroup_size ? go.workgroup_size : d.workgroup_size};
}

Result<Row> bench_vulkan(gpu::Context& ctx, const BenchScene& sc, std::uint32_t n, bool fused,
                         gpu::BufferAccess access, const BenchOptions& o,
                         gpu::GpuSolverOptions::CgDispatch cg = gpu::GpuSolverOptions::CgDispatch::automatic,
                         std::optional<Partner> partner = std::nullopt) {
  gpu::GpuSolverOptions go;
  go.fused = fused;
  go.buffer_access = access;
  go.workgroup_size = o.workgroup;
  go.cg_dispatch = cg;
  auto s = gpu::GpuSolver::create(ctx, sc.system, sc.params, go);
  if (!s)
    return s.error();
  std::optional<gpu::GpuSolver> grid;
  if (partner) {
    auto g = gpu::GpuSolver::create(ctx, partner->scene.system, partner->scene.params, go);
    if (!g)
      return g.error();
    grid.emplace(std::move(*g));
    VKCLOTH_TRY(grid->simulate(o.warmup, o.steps_per_submit));
  }
  VKCLOTH_TRY(s->simulate(o.warmup, o.steps_per_submit));
  const SolveStats before = s->last_solve();
  std::vector<double> gpu_ms;
  auto grid_run = [&](std::uint64_t steps) { return grid->simulate(steps, o.steps_per_submit); };
  auto times = timed_reps(
      o,
      [&](std::uint64_t steps) -> Result<void> {
        VKCLOTH_TRY(s->simulate(steps, o.steps_per_submit));
        gpu_ms.push_back(s->last_gpu_ms());
        return {};
      },
      grid ? &grid_run : nullptr);
  if (!times)
    return times.error();
  Row row;
  row.backend = "vulkan";
  row.variant = sc.params.integrator == Integrator::implicit_euler ? "implicit"
                : fused && sc.params.integrator != Integrator::rk4 ? "fused"
                                                                   : "two_pass";
  row.integrator = to_string(sc.params.integrator);
  row.cg_iterations = s->last_solve().iterations;
  row.cg_per_step = cg_per_step(before, s->last_solve());
  if (sc.params.integrator == Integrator::implicit_euler)
    row.cg_dispatch = s->implicit_one_workgroup() ? "one_workgroup" : "per_iteration";
  row.size = n;
  row.wall_ms = times->first;
  row.partner_ms = times->second;
  row.partner_size = partner ? partner->size : 0;
  row.gpu_ms = median(gpu_ms);
  std::tie(row.layout, row.workgroup) =
      layout_of(ctx, go, sc.params.integrator == Integrator::implicit_euler);
  return row;
}

/// `instances` cloths of the scene in one ClothWorld, one submission per `steps_per_submit` steps:
/// batched (one shared topology: one dispatch per pass for all) or not (a topology prepared for
/// each: every cloth its own dispatches, as separate solvers recorded into one command buffer).
Result<Row> bench_world(gpu::Context& ctx, const BenchScene& sc, std::uint32_t n, bool batched,
                        gpu::BufferAccess access, const BenchOptions& o) {
  gpu::WorldOptions wo;
  wo.solver.buffer_access = access;
  wo.solver.workgroup_size = o.workgroup;
  auto w = gpu::ClothWorld::create(ctx, wo);
  if (!w)
    return w.error();
  auto shared = ClothTopology::create(sc.system);
  if (!shared)
    return shared.error();
  for (std::uint32_t k = 0; k < o.instances; ++k) {
    auto own = batched ? shared : ClothTopology::create(sc.system);
    if (!own)
      return own.error();
    VKCLOTH_TRY(w->add(*own, sc.params));
  }
  VKCLOTH_TRY(w->simulate(o.warmup, o.steps_per_submit));
  std::vector<double> wall;
  for (unsigned r = 0; r < o.reps; ++r) {
    const auto t0 = Clock::now();
    VKCLOTH_TRY(w->simulate(o.steps, o.steps_per_submit));
    wall.push_back(ms_since(t0));
  }
  Row row;
  row.backend = "vulkan";
  row.variant = batched ? "batched" : "unbatched";
  row.integrator = to_string(sc.params.integrator);
  row.size = n;
  row.instances = o.instances;
  row.wall_ms = median(wall);
  std::tie(row.layout, row.workgroup) =
      layout_of(ctx, wo.solver, sc.params.integrator == Integrator::implicit_euler);
  return row;
}

/// The particles of `positions` (in float) in double, for particles_in_contact.
std::vector<glm::dvec3> to_double(std::span<const glm::vec3> positions) {
  return {positions.begin(), positions.end()};
}

/// Times a contact scene (k = 1) and the same cloth without colliders (k = 0), in alternation: both
/// warm up, then repetition r runs `steps` steps of the bare cloth, then `steps` of the cloth on
/// its colliders, so that a machine whose speed drifts (other jobs on its cores) slows both alike.
/// `run(k, steps)` advances solver k; `gpu_ms(k)` is its last GPU time (-1: none); `count()` the
/// particles in contact on solver 1 now. Returns the two rows (bare, then with colliders) with
/// their medians, their scenes named `scenes` (row 0, row 1).
template <typename Run, typename GpuMs, typename Count>
Result<std::array<Row, 2>> alternate_contact(const BenchOptions& o, Run run, GpuMs gpu_ms, Count count,
                                             std::array<const char*, 2> scenes = {"contact_free",
                                                                                  "contact"}) {
  for (int k = 0; k < 2; ++k)
    VKCLOTH_TRY(run(k, o.warmup));
  std::array<Row, 2> rows;
  auto start = count();
  if (!start)
    return start.error();
  std::array<std::vector<double>, 2> gpu;
  auto stepper = [&](int k) {
    return [&, k](std::uint64_t steps) -> Result<void> {
      VKCLOTH_TRY(run(k, steps));
      gpu[k].push_back(gpu_ms(k));
      return {};
    };
  };
  auto bare = stepper(0);
  auto times = timed_reps(o, stepper(1), &bare);
  if (!times)
    return times.error();
  auto end = count();
  if (!end)
    return end.error();
  rows[0].wall_ms = times->second;
  rows[1].wall_ms = times->first;
  for (int k = 0; k < 2; ++k) {
    rows[k].gpu_ms = median(gpu[k]);
    rows[k].scene = scenes[k];
  }
  rows[1].in_contact_start = *start;
  rows[1].in_contact_end = *end;
  return rows;
}

/// Times `system` with `bare` (row 0) and `full` (row 1) on the CPU, in alternation
/// (alternate_contact); `count(positions)` counts on the `full` solver.
template <typename Count>
Result<std::array<Row, 2>> bench_cpu_pair(const ParticleSystem& system, const SimParams& bare,
                                          const SimParams& full, const BenchOptions& o,
                                          std::array<const char*, 2> scenes, Count count) {
  CpuSolverOptions co;
  co.threads = o.threads;
  auto s0 = CpuSolver<float>::create(system, bare, co);
  if (!s0)
    return s0.error();
  auto s1 = CpuSolver<float>::create(system, full, co);
  if (!s1)
    return s1.error();
  std::array<CpuSolver<float>*, 2> s = {&*s0, &*s1};
  auto rows = alternate_contact(
      o, [&](int k, std::uint64_t steps) { return s[k]->run(steps); }, [](int) { return -1.0; },
      [&] { return count(s1->positions()); }, scenes);
  if (!rows)
    return rows.error();
  for (Row& r : *rows) {
    r.backend = "cpu";
    r.variant = "cpu";
    r.threads = s1->threads();
  }
  return rows;
}

/// The same on Vulkan (one solver per parameter set, `fused` or two-pass, buffer access `access`).
template <typename Count>
Result<std::array<Row, 2>> bench_vulkan_pair(gpu::Context& ctx, const ParticleSystem& system,
                                             const SimParams& bare, const SimParams& full, bool fused,
                                             gpu::BufferAccess access, const BenchOptions& o,
                                             std::array<const char*, 2> scenes, Count count) {
  gpu::GpuSolverOptions go;
  go.fused = fused;
  go.buffer_access = access;
  go.workgroup_size = o.workgroup;
  auto s0 = gpu::GpuSolver::create(ctx, system, bare, go);
  if (!s0)
    return s0.error();
  auto s1 = gpu::GpuSolver::create(ctx, system, full, go);
  if (!s1)
    return s1.error();
  std::array<gpu::GpuSolver*, 2> s = {&*s0, &*s1};
  auto rows = alternate_contact(
      o, [&](int k, std::uint64_t steps) { return s[k]->simulate(steps, o.steps_per_submit); },
      [&](int k) { return s[k]->last_gpu_ms(); },
      [&]() -> Result<std::size_t> {
        auto x = s1->positions();
        if (!x)
          return x.error();
        return count(std::span<const glm::vec3>(*x));
      },
      scenes);
  if (!rows)
    return rows.error();
  const Integrator integrator = full.integrator;
  for (Row& r : *rows) {
    r.backend = "vulkan";
    r.variant = integrator == Integrator::implicit_euler ? "implicit"
                : fused && integrator != Integrator::rk4 ? "fused"
                                                         : "two_pass";
    std::tie(r.layout, r.workgroup) = layout_of(ctx, go, integrator == Integrator::implicit_euler);
  }
  return rows;
}

Result<std::array<Row, 2>> bench_cpu_contact(const ContactScene& sc, const BenchOptions& o) {
  SimParams bare = sc.params;
  bare.colliders.clear();
  return bench_cpu_pair(sc.system, bare, sc.params, o, {"contact_free", "contact"},
                        [&](std::span<const glm::vec3> x) { return particles_in_contact(sc, to_double(x)); });
}

Result<std::array<Row, 2>> bench_vulkan_contact(gpu::Context& ctx, const ContactScene& sc, bool fused,
                                                gpu::BufferAccess access, const BenchOptions& o) {
  SimParams bare = sc.params;
  bare.colliders.clear();
  return bench_vulkan_pair(
      ctx, sc.system, bare, sc.params, fused, access, o, {"contact_free", "contact"},
      [&](std::span<const glm::vec3> x) { return particles_in_contact(sc, to_double(x)); });
}

/// The folded cloth with self-collision off (row 0, scene "self_collision_free") and on (row 1,
/// "self_collision"), alternated; the particles in self-contact counted on the second.
Result<std::array<Row, 2>> bench_cpu_self(const SelfScene& sc, const BenchOptions& o) {
  SimParams off = sc.params;
  off.self_collision.enabled = false;
  return bench_cpu_pair(
      sc.system, off, sc.params, o, {"self_collision_free", "self_collision"},
      [&](std::span<const glm::vec3> x) -> Result<std::size_t> { return particles_in_self_contact(sc, x); });
}

Result<std::array<Row, 2>> bench_vulkan_self(gpu::Context& ctx, const SelfScene& sc, bool fused,
                                             gpu::BufferAccess access, const BenchOptions& o) {
  SimParams off = sc.params;
  off.self_collision.enabled = false;
  return bench_vulkan_pair(
      ctx, sc.system, off, sc.params, fused, access, o, {"self_collision_free", "self_collision"},
      [&](std::span<const glm::vec3> x) -> Result<std::size_t> { return particles_in_self_contact(sc, x); });
}

Result<std::vector<std::uint32_t>> parse_sizes(const std::string& text) {
  std::vector<std::uint32_t> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    unsigned long v = 0;
    try {
      v = std::stoul(item, &used);
    } catch (...) {
      used = 0;
    }
    if (used != item.size() || v < 2 || v > max_cloth_side)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("--sizes: '{}' is not a grid side in 2..{}", item, max_cloth_side));
    out.push_back(static_cast<std::uint32_t>(v));
  }
  if (out.empty())
    return make_error(ErrorCode::invalid_argument, "--sizes: give at least one size, e.g. 64,256");
  return out;
}

double per_particle_step(const Row& r) {
  return r.wall_ms / (double(r.particles) * double(r.steps));
}

/// A mesh row's cost per particle-step over that of the grid timed in alternation with it.
double mesh_over_grid(const Row& r) {
  const double grid_particles = double(r.partner_size) * double(r.partner_size);
  return per_particle_step(r) / (r.partner_ms / (grid_particles * double(r.steps)));
}

/// The grid row of the same backend, variant and integrator whose particle count is closest to a
/// stretch row's (its own grid): that row's cost is quoted against it.
const Row* nearest_grid(const std::vector<Row>& rows, const Row& r) {
  const Row* best = nullptr;
  for (const Row& g : rows)
    if (g.scene == "grid" && g.backend == r.backend && g.variant == r.variant && g.layout == r.layout &&
        g.integrator == r.integrator && g.instances == 1 &&
        (!best || std::abs(double(g.particles) - double(r.particles)) <
                      std::abs(double(best->particles) - double(r.particles))))
      best = &g;
  return best;
}

bool is_self(const Row& r) {
  return r.scene == "self_collision" || r.scene == "self_collision_free";
}

/// The row with self-collision off timed with a self-collision row (same backend, variant, layout,
/// integrator and size).
const Row* self_free_of(const std::vector<Row>& rows, const Row& r) {
  for (const Row& e : rows)
    if (e.scene == "self_collision_free" && e.size == r.size && e.backend == r.backend &&
        e.variant == r.variant && e.layout == r.layout && e.integrator == r.integrator)
      return &e;
  return nullptr;
}

/// The bare-cloth row timed with a contact row (its colliders removed; same backend, variant,
/// layout and integrator): the contact phase is quoted against it.
const Row* contact_free_of(const std::vector<Row>& rows, const Row& r) {
  for (const Row& e : rows)
    if (e.scene == "contact_free" && e.contact == r.contact && e.backend == r.backend &&
        e.variant == r.variant && e.layout == r.layout && e.integrator == r.integrator)
      return &e;
  return nullptr;
}

int bench_command(const BenchOptions& o) {
  if (o.backend != "cpu" && o.backend != "vulkan" && o.backend != "all")
    return report(make_error(ErrorCode::invalid_argument,
                             fmt::format("--backend must be cpu, vulkan or all, got '{}'", o.backend)));
  const auto integrator = parse_integrator(o.integrator);
  if (!integrator)
    return report(make_error(
        ErrorCode::invalid_argument,
        fmt::format(
            "--integrator must be explicit_euler, semi_implicit_euler, rk4 or implicit_euler, got '{}'",
            o.integrator)));
  auto sizes = parse_sizes(o.sizes);
  if (!sizes)
    return report(sizes.error());
  if (o.steps == 0 || o.reps == 0 || o.steps_per_submit == 0)
    return report(
        make_error(ErrorCode::invalid_argument, "--steps, --reps and --steps-per-submit must be > 0"));
  if (o.instances == 0 || o.instances > 4096)
    return report(make_error(ErrorCode::invalid_argument,
                             fmt::format("--instances must be in 1..4096, got {}", o.instances)));
  if (!(o.memory_gbps > 0) || !(o.compute_gflops > 0))
    return report(make_error(ErrorCode::invalid_argument, "--memory-gbps and --compute-gflops must be > 0"));
  const double dt = o.dt.value_or(5e-4);

  std::optional<gpu::Context> ctx;
  std::string vulkan_note;
  if (o.backend != "cpu") {
    auto c = gpu::Context::create();
    if (c)
      ctx.emplace(std::move(*c));
    else if (o.backend == "vulkan")
      return report(c.error());
    else
      vulkan_note = c.error().message;
  }

  std::vector<gpu::BufferAccess> layouts; // --layout, in order
  {
    std::stringstream ss(o.layout);
    std::string item;
    while (std::getline(ss, item, ','))
      if (auto a = gpu::parse_buffer_access(item))
        layouts.push_back(*a);
      else
        return report(make_error(ErrorCode::invalid_argument,
                                 fmt::format("--layout: '{}' is not auto, texel or storage", item)));
    if (layouts.empty())
      return report(make_error(ErrorCode::invalid_argument, "--layout: give auto, texel, storage or a list"));
  }
  std::optional<gpu::DeviceLayout> device_layout;
  if (ctx)
    device_layout = gpu::device_layout(*ctx);

  std::vector<Row> rows;
  const bool implicit = *integrator == Integrator::implicit_euler;
  // Times one scene on the chosen backends (CPU; Vulkan fused / two-pass; ClothWorld batches).
  auto time_scene = [&](const BenchScene& sc, std::uint32_t n, const std::string& scene,
                        const std::string& order, std::optional<Partner> partner = std::nullopt) -> int {
    const double s = double(sc.system.adjacency.refs.size()) / double(sc.system.size());
    double fans = 0.0;
    if (sc.system.surface) {
      auto t = ClothTopology::create(sc.system);
      if (!t)
        return report(t.error());
      fans = double((*t)->fans().size()) / double(sc.system.size());
    }
    auto add = [&](Result<Row> r) -> int {
      const bool baseline = implicit && sc.params.integrator != Integrator::implicit_euler;
      if (!r &&
          (r.error().code == ErrorCode::unsupported || // too large for this device: note it, go on
           (baseline && r.error().code == ErrorCode::diverged))) { // the explicit baseline at a stiff dt
        fmt::print("note: {} n = {} ({}): {}\n", scene, n, to_string(sc.params.integrator),
                   r.error().message);
        return exit_ok;
      }
      if (!r)
        return report(r.error());
      r->particles = sc.system.size() * r->instances;
      r->springs = sc.system.springs.size();
      r->steps = o.steps;
      r->reps = o.reps;
      r->scene = scene;
      r->order = order;
      r->cost = cost_of(r->variant, sc.params.integrator, s, scene != "mesh", fans, true, o.steps_per_submit);
      rows.push_back(*r);
      return exit_ok;
    };
    if (o.backend != "vulkan")
      if (int e = add(bench_cpu(sc, n, o, partner)))
        return e;
    if (!ctx)
      return exit_ok;
    const bool fused = o.variants.find("fused") != std::string::npos;
    const bool two_pass = o.variants.find("two_pass") != std::string::npos;
    const bool rk4 = sc.params.integrator == Integrator::rk4;
    const bool imp = sc.params.integrator == Integrator::implicit_euler;
    // Each variant once per --layout entry, back to back (alternated: a machine whose speed drifts
    // during the run affects both layouts alike). Implicit with --cg-dispatch other than auto: the
    // CG loop's two dispatch layouts, forced.
    using D = gpu::GpuSolverOptions::CgDispatch;
    if (fused || rk4 || imp)
      for (gpu::BufferAccess access : layouts) {
        if (imp && o.cg_dispatch != "auto") {
          for (const char* name : {"one_workgroup", "per_iteration"})
            if (o.cg_dispatch == name || o.cg_dispatch == "both")
              if (int e = add(bench_vulkan(*ctx, sc, n, true, access, o,
                                           std::string(name) == "one_workgroup" ? D::one_workgroup
                                                                                : D::per_iteration)))
                return e;
          continue;
        }
        if (int e = add(bench_vulkan(*ctx, sc, n, true, access, o, D::automatic, partner)))
          return e;
      }
    if (two_pass && !rk4 && !imp)
      for (gpu::BufferAccess access : layouts)
        if (int e = add(bench_vulkan(*ctx, sc, n, false, access, o, D::automatic, partner)))
          return e;
    if (o.instances > 1 && scene == "grid") { // many cloths: one batch vs one dispatch chain per cloth
      for (gpu::BufferAccess access : layouts) {
        if (int e = add(bench_world(*ctx, sc, n, true, access, o)))
          return e;
        if (int e = add(bench_world(*ctx, sc, n, false, access, o)))
          return e;
      }
    }
    return exit_ok;
  };
  for (std::uint32_t n : *sizes) {
    auto sc = bench_scene(n, *integrator, dt, o);
    if (!sc)
      return report(sc.error());
    if (int e = time_scene(*sc, n, "grid", ""))
      return e;
    if (!o.stretch.empty()) { // the same grid with stretch control, for its cost ratio
      auto limited = bench_scene(n, *integrator, dt, o);
      if (!limited)
        return report(limited.error());
      limited->params.stretch_limit.method = *parse_stretch_method(o.stretch);
      if (int e = time_scene(*limited, n, "stretch", o.stretch))
        return e;
    }
    if (implicit) { // the explicit baseline at the same size and dt, for the cost ratio
      auto base = bench_scene(n, Integrator::semi_implicit_euler, dt, o);
      if (!base)
        return report(base.error());
      if (int e = time_scene(*base, n, "grid", ""))
        return e;
    }
  }
  if (!o.mesh.empty()) {
    auto mesh = read_mesh(o.mesh);
    if (!mesh)
      return report(mesh.error());
    // Each order timed in alternation with the grid of --sizes nearest its particle count.
    std::optional<BenchScene> grid;
    std::uint32_t side = 0;
    for (const char* order : {"meshopt", "file", "shuffled"}) {
      auto sc = mesh_bench_scene(*mesh, order, *integrator, dt);
      if (!sc)
        return report(sc.error());
      if (!grid) {
        const double root = std::sqrt(double(sc->system.size()));
        side = *std::min_element(sizes->begin(), sizes->end(), [&](std::uint32_t a, std::uint32_t b) {
          return std::abs(double(a) - root) < std::abs(double(b) - root);
        });
        auto g = bench_scene(side, *integrator, dt, o);
        if (!g)
          return report(g.error());
        grid.emplace(std::move(*g));
      }
      if (int e = time_scene(*sc, 0, "mesh", order, Partner{*grid, side}))
        return e;
    }
  }

  // A scene timed on against off in pairs (cpu(): the CPU; vulkan(fused, access): each Vulkan
  // variant and layout asked for); tag(row) adds the scene's own fields. A device too small for it
  // is a note naming `what`.
  auto time_pairs = [&](const std::string& what, const ParticleSystem& system, const SimParams& params,
                        std::uint32_t size, auto cpu, auto vulkan, auto tag) -> int {
    const double s = double(system.adjacency.refs.size()) / double(system.size());
    auto add = [&](Result<std::array<Row, 2>> pair) -> int {
      if (!pair && pair.error().code == ErrorCode::unsupported) { // too large for this device
        fmt::print("note: {} ({}): {}\n", what, to_string(params.integrator), pair.error().message);
        return exit_ok;
      }
      if (!pair)
        return report(pair.error());
      for (Row& r : *pair) {
        r.integrator = to_string(params.integrator);
        r.size = size;
        r.particles = system.size();
        r.springs = system.springs.size();
        r.steps = o.steps;
        r.reps = o.reps;
        tag(r);
        r.cost = cost_of(r.variant, params.integrator, s, true, 0.0, false, o.steps_per_submit);
        rows.push_back(r);
      }
      return exit_ok;
    };
    if (o.backend != "vulkan")
      if (int e = add(cpu()))
        return e;
    if (!ctx)
      return exit_ok;
    const bool rk4 = *integrator == Integrator::rk4;
    const bool imp = *integrator == Integrator::implicit_euler;
    if (o.variants.find("fused") != std::string::npos || rk4 || imp)
      for (gpu::BufferAccess access : layouts)
        if (int e = add(vulkan(true, access)))
          return e;
    if (o.variants.find("two_pass") != std::string::npos && !rk4 && !imp)
      for (gpu::BufferAccess access : layouts)
        if (int e = add(vulkan(false, access)))
          return e;
    return exit_ok;
  };

  if (!o.contact.empty()) { // the contact scenes, each timed against the same cloth without colliders
    for (const std::string name : {"table", "mesh"}) {
      if (o.contact != name && o.contact != "both")
        continue;
      auto sc = name == "table" ? table_scene(*integrator, dt, o) : mesh_scene(*integrator, dt, o);
      if (!sc)
        return report(sc.error());
      if (int e = time_pairs(
              "contact " + name, sc->system, sc->params, sc->n, [&] { return bench_cpu_contact(*sc, o); },
              [&](bool fused, gpu::BufferAccess access) {
                return bench_vulkan_contact(*ctx, *sc, fused, access, o);
              },
              [&](Row& r) {
                r.contact = name;
                if (r.scene == "contact") {
                  r.colliders = sc->kinds;
                  r.collider_triangles = sc->triangles;
                }
              }))
        return e;
    }
  }

  if (o.self_collision) { // each size folded on the floor, self-collision on vs off (issue 16)
    for (std::uint32_t n : *sizes) {
      if (n < self_min_size) {
        fmt::print("note: self_collision n = {}: the folded cloth needs n >= {}; left out\n", n,
                   self_min_size);
        continue;
      }
      auto sc = folded_scene(n, *integrator, dt, o);
      if (!sc)
        return report(sc.error());
      if (int e = time_pairs(
              fmt::format("self_collision n = {}", n), sc->system, sc->params, n,
              [&] { return bench_cpu_self(*sc, o); },
              [&](bool fused, gpu::BufferAccess access) {
                return bench_vulkan_self(*ctx, *sc, fused, access, o);
              },
              [&](Row& r) { r.self_thickness = sc->params.self_collision.thickness; }))
        return e;
    }
  }

  // Table for people.
  fmt::print(
      "vkcloth bench: hanging cloth n x n (3 spring kinds, 2 pins, wind), {}, dt {:g} s, {} steps x {} reps "
      "(median), warm-up {}\n",
      o.integrator, dt, o.steps, o.reps, o.warmup);
  fmt::print("ceilings: memory {:g} GB/s, compute {:g} GFLOP/s (--memory-gbps, --compute-gflops)\n",
             o.memory_gbps, o.compute_gflops);
  if (ctx)
    fmt::print("vulkan device: {}\nvulkan layout: {} (the device's choice: {})\n", ctx->device_name(),
               o.layout, device_layout->reason);
  if (!vulkan_note.empty())
    fmt::print("vulkan: skipped ({})\n", vulkan_note);
  if (o.instances > 1)
    fmt::print("batched / unbatched rows: {} cloths of n x n in one ClothWorld (particles = all of them)\n",
               o.instances);
  if (!o.mesh.empty())
    fmt::print("mesh rows: {} (n column: the particle order: meshopt, file or shuffled)\n", o.mesh);
  if (!o.stretch.empty())
    fmt::print(
        "stretch rows: n x n with stretch_limit {{method: {}, max_strain: 0.1, iterations: 4}} (n column: "
        "n+{})\n",
        o.stretch, o.stretch);
  if (!o.contact.empty())
    fmt::print(
        "contact rows: n+table: 256 x 256 cloth draped on a box (0.5 x 1.2 x 0.2 m) on the floor plane; "
        "n+mesh: 64 x 64 cloth draped on a {}-triangle geodesic sphere (mesh collider); friction "
        "{:g}; no wind; n free: the same cloth without colliders (n column)\n",
        20 * sphere_frequency * sphere_frequency, contact_friction);
  if (o.self_collision)
    fmt::print("self-collision rows: n+self: the n x n cloth folded into {} layers on the floor plane "
               "(friction {:g}), "
               "self_collision {{thickness: {:g} x the spacing, friction: {:g}, iterations: {}}}; no wind; "
               "n-self: the "
               "same cloth with self-collision off (n column)\n",
               self_layers, contact_friction, self_thickness_over_spacing, self_friction, self_iterations);
  fmt::print("{:<7} {:<9} {:<11} {:>8} {:>8} {:>3} {:>9} {:>9} {:>9} {:>6} {:>7} {:>5} {:>6} {:>8} {:>5}\n",
             "backend", "variant", "layout", "n", "particles", "thr", "ms/step", "gpu ms", "M p-st/s",
             "B/p-st", "GB/s", "%mem", "fl/pst", "GFLOP/s", "%cmp");
  nlohmann::json results = nlohmann::json::array();
  for (const Row& r : rows) {
    const double ms_step = r.wall_ms / double(r.steps);
    const double rate = double(r.particles) * double(r.steps) / (r.wall_ms * 1e-3);
    const double gbps = rate * r.cost.bytes * 1e-9;
    const double gflops = rate * r.cost.flops * 1e-9;
    const double gpu_step = r.gpu_ms >= 0 ? r.gpu_ms / double(r.steps) : -1.0;
    fmt::print(
        "{:<7} {:<9} {:<11} {:>8} {:>8} {:>3} {:>9.4f} {:>9} {:>9.1f} {:>6.0f} {:>7.2f} {:>4.0f}% {:>6.0f} "
        "{:>8.2f} {:>4.1f}%\n",
        r.backend, r.variant, r.layout.empty() ? "-" : fmt::format("{}/{}", r.layout, r.workgroup),
        r.scene == "grid"                  ? fmt::format("{}", r.size)
        : r.scene == "stretch"             ? fmt::format("{}+{}", r.size, r.order)
        : r.scene == "contact"             ? fmt::format("{}+{}", r.size, r.contact)
        : r.scene == "contact_free"        ? fmt::format("{} free", r.size)
        : r.scene == "self_collision"      ? fmt::format("{}+self", r.size)
        : r.scene == "self_collision_free" ? fmt::format("{}-self", r.size)
                                           : r.order,
        r.particles, r.backend == "cpu" ? fmt::format("{}", r.threads) : "-", ms_step,
        gpu_step >= 0 ? fmt::format("{:.4f}", gpu_step) : "-", rate * 1e-6, r.cost.bytes, gbps,
        100.0 * gbps / o.memory_gbps, r.cost.flops, gflops, 100.0 * gflops / o.compute_gflops);
    nlohmann::json j;
    j["backend"] = r.backend;
    j["variant"] = r.variant;
    j["layout"] = r.layout.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.layout);
    j["workgroup_size"] = r.layout.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.workgroup);
    j["integrator"] = r.integrator;
    if (r.integrator == "implicit_euler") {
      j["cg_iterations_last_step"] = r.cg_iterations;
      j["cg_iterations_per_step"] = r.cg_per_step;
      if (!r.cg_dispatch.empty())
        j["cg_dispatch"] = r.cg_dispatch;
      for (const Row& e : rows) // the semi-implicit baseline of the same backend and size
        if (e.backend == r.backend && e.size == r.size && e.integrator == "semi_implicit_euler" &&
            r.contact.empty() && e.contact.empty() && !is_self(r) && !is_self(e))
          j["implicit_over_explicit"] = r.wall_ms / e.wall_ms;
    }
    j["size"] = r.size;
    j["scene"] = r.scene;
    if (r.scene == "mesh") {
      j["order"] = r.order;
      j["mesh_over_grid"] = mesh_over_grid(r);
      j["grid_size_alternated"] = r.partner_size;
      j["grid_ms_per_step_alternated"] = r.partner_ms / double(r.steps);
    }
    if (r.scene == "stretch") {
      j["stretch_method"] = r.order;
      if (const Row* g = nearest_grid(rows, r))
        j["stretch_over_plain"] = per_particle_step(r) / per_particle_step(*g);
    }
    if (r.scene == "contact" || r.scene == "contact_free") {
      j["contact"] = r.contact;
      if (r.scene == "contact") {
        j["colliders"] = r.colliders;
        j["collider_triangles"] =
            r.collider_triangles ? nlohmann::json(r.collider_triangles) : nlohmann::json(nullptr);
        j["friction"] = contact_friction;
        j["particles_in_contact_start"] = r.in_contact_start;
        j["particles_in_contact_end"] = r.in_contact_end;
        if (const Row* f = contact_free_of(rows, r))
          j["contact_phase_fraction"] = (r.wall_ms - f->wall_ms) / f->wall_ms;
      }
    }
    if (is_self(r)) {
      j["self_collision_thickness"] = r.self_thickness;
      j["self_collision_friction"] = self_friction;
      j["self_collision_iterations"] = self_iterations;
      if (r.scene == "self_collision") {
        j["particles_in_self_contact_start"] = r.in_contact_start;
        j["particles_in_self_contact_end"] = r.in_contact_end;
        if (const Row* f = self_free_of(rows, r)) {
          j["self_collision_ratio"] = r.wall_ms / f->wall_ms;
          j["self_collision_us_per_particle"] =
              1e3 * (r.wall_ms / double(r.steps) - f->wall_ms / double(f->steps)) / double(r.particles);
        }
      }
    }
    j["instances"] = r.instances;
    j["particles"] = r.particles;
    j["springs"] = r.springs;
    j["threads"] = r.backend == "cpu" ? nlohmann::json(r.threads) : nlohmann::json(nullptr);
    j["steps"] = r.steps;
    j["reps"] = r.reps;
    j["wall_ms"] = r.wall_ms;
    j["gpu_ms"] = r.gpu_ms >= 0 ? nlohmann::json(r.gpu_ms) : nlohmann::json(nullptr);
    j["ms_per_step"] = ms_step;
    j["gpu_ms_per_step"] = gpu_step >= 0 ? nlohmann::json(gpu_step) : nlohmann::json(nullptr);
    j["particle_steps_per_s"] = rate;
    j["bytes_per_particle_step"] = r.cost.bytes;
    j["flops_per_particle_step"] = r.cost.flops;
    j["achieved_gbps"] = gbps;
    j["memory_fraction"] = gbps / o.memory_gbps;
    j["achieved_gflops"] = gflops;
    j["compute_fraction"] = gflops / o.compute_gflops;
    results.push_back(std::move(j));
  }
  for (const Row& r : rows)
    if (r.integrator == "implicit_euler" && r.contact.empty() && !is_self(r))
      for (const Row& e : rows)
        if (e.backend == r.backend && e.size == r.size && e.integrator == "semi_implicit_euler" &&
            e.contact.empty() && !is_self(e))
          fmt::print(
              "{}{} n = {}: implicit step {:.4f} ms vs semi-implicit {:.4f} ms: {:.1f}x the explicit cost "
              "({:.1f} CG iterations per step, {} in the last step)\n",
              r.backend, r.cg_dispatch.empty() ? "" : " (" + r.cg_dispatch + ")", r.size,
              r.wall_ms / double(r.steps), e.wall_ms / double(e.steps), r.wall_ms / e.wall_ms, r.cg_per_step,
              r.cg_iterations);
  for (const Row& r : rows)
    if (r.scene == "mesh")
      fmt::print(
          "{} {} mesh ({} order, {} particles): {:.2f}x the cost per particle-step of the {} x {} grid "
          "timed in alternation with it ({:.4f} vs {:.4f} ms per step)\n",
          r.backend, r.variant, r.order, r.particles, mesh_over_grid(r), r.partner_size, r.partner_size,
          r.wall_ms / double(r.steps), r.partner_ms / double(r.steps));
  for (const Row& r : rows)
    if (const Row* g = r.scene == "stretch" ? nearest_grid(rows, r) : nullptr)
      fmt::print(
          "{} {} n = {}: stretch control ({}, 4 sweeps) costs {:.0f} % of the plain step ({:.4f} vs {:.4f} "
          "ms)\n",
          r.backend, r.variant, r.size, r.order, 100.0 * (per_particle_step(r) / per_particle_step(*g) - 1.0),
          r.wall_ms / double(r.steps), g->wall_ms / double(g->steps));
  for (const Row& r : rows)
    if (const Row* f = r.scene == "contact" ? contact_free_of(rows, r) : nullptr)
      fmt::print(
          "{} {} {} ({} x {}): the contact phase costs {:.0f} % of the step without colliders ({:.4f} vs "
          "{:.4f} ms); {} of {} particles within 2 eps of a collider before the timed steps, {} after\n",
          r.backend, r.variant, r.contact, r.size, r.size, 100.0 * (r.wall_ms - f->wall_ms) / f->wall_ms,
          r.wall_ms / double(r.steps), f->wall_ms / double(f->steps), r.in_contact_start, r.particles,
          r.in_contact_end);
  bool self_header = false;
  for (const Row& r : rows)
    if (const Row* f = r.scene == "self_collision" ? self_free_of(rows, r) : nullptr) {
      if (!self_header) {
        fmt::print("self-collision on vs off, alternated (ms per step, wall; us/particle: (on - off) per "
                   "step / particles; in self-contact: after the warm-up / after the timed steps)\n");
        fmt::print("{:<7} {:<9} {:<11} {:>5} {:>9} {:>10} {:>10} {:>8} {:>11} {:>17}\n", "backend", "variant",
                   "layout", "n", "particles", "off ms", "on ms", "on/off", "us/particle", "in self-contact");
        self_header = true;
      }
      const double on = r.wall_ms / double(r.steps), off = f->wall_ms / double(f->steps);
      fmt::print("{:<7} {:<9} {:<11} {:>5} {:>9} {:>10.4f} {:>10.4f} {:>7.2f}x {:>11.4f} {:>17}\n", r.backend,
                 r.variant, r.layout.empty() ? "-" : fmt::format("{}/{}", r.layout, r.workgroup), r.size,
                 r.particles, off, on, r.wall_ms / f->wall_ms, 1e3 * (on - off) / double(r.particles),
                 fmt::format("{} / {}", r.in_contact_start, r.in_contact_end));
    }
  if (!o.json.empty()) {
    nlohmann::json doc;
    doc["schema"] = "vkcloth-bench/1";
    doc["scene"] = "hanging_cloth";
    doc["mesh"] = o.mesh.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.mesh);
    doc["integrator"] = o.integrator;
    doc["dt"] = dt;
    doc["stiffness"] = o.stiffness.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.stiffness);
    doc["cloth_mass"] = o.cloth_mass ? nlohmann::json(*o.cloth_mass) : nlohmann::json(nullptr);
    doc["wind"] = o.wind;
    doc["contact"] = o.contact.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.contact);
    doc["self_collision"] = o.self_collision;
    doc["steps"] = o.steps;
    doc["warmup"] = o.warmup;
    doc["reps"] = o.reps;
    doc["steps_per_submit"] = o.steps_per_submit;
    doc["ceilings"] = {{"memory_gbps", o.memory_gbps}, {"compute_gflops", o.compute_gflops}};
    doc["host_threads"] = std::thread::hardware_concurrency();
    doc["vulkan_device"] = ctx ? nlohmann::json(ctx->device_name()) : nlohmann::json(nullptr);
    doc["vulkan_layout"] = device_layout ? nlohmann::json{{"access", gpu::to_string(device_layout->access)},
                                                          {"workgroup_size", device_layout->workgroup_size},
                                                          {"subgroup_size", device_layout->subgroup_size},
                                                          {"reason", device_layout->reason}}
                                         : nlohmann::json(nullptr);
    doc["vulkan_skipped"] = vulkan_note.empty() ? nlohmann::json(nullptr) : nlohmann::json(vulkan_note);
    doc["results"] = std::move(results);
    std::ofstream f(o.json);
    f << doc.dump(2) << "\n";
    if (!f)
      return report(make_error(ErrorCode::io, fmt::format("--json: cannot write '{}'", o.json)));
  }
  return exit_ok;
}

} // namespace

void add_bench_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Throughput of the solvers on the hanging cloth at several sizes, against the memory and compute "
      "ceilings (docs/performance.md)");
  cmd->add_option("--backend", opt->backend,
                  "cpu | vulkan | all (all: Vulkan is skipped with a note if no device)")
      ->capture_default_str();
  cmd->add_option("--sizes", opt->sizes, "Comma-separated grid sides n (n x n particles)")
      ->capture_default_str();
  cmd->add_option("--steps", opt->steps, "Timed steps per repetition")->capture_default_str();
  cmd->add_option("--warmup", opt->warmup, "Untimed steps before the first repetition")
      ->capture_default_str();
  cmd->add_option("--reps", opt->reps, "Repetitions; the median is reported")->capture_default_str();
  cmd->add_option("--integrator", opt->integrator,
                  "explicit_euler | semi_implicit_euler | rk4 | implicit_euler (adds a semi-implicit "
                  "baseline row and the cost ratio)")
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads, "CPU solver threads (0: the host's hardware threads)")
      ->capture_default_str();
  cmd->add_option("--steps-per-submit", opt->steps_per_submit, "Vulkan: steps recorded per command buffer")
      ->capture_default_str();
  cmd->add_option("--instances", opt->instances,
                  "Vulkan: also time this many cloths in one ClothWorld, batched (one dispatch per pass) and "
                  "unbatched (one per cloth)")
      ->capture_default_str();
  cmd->add_option("--dt", opt->dt, "Time step in seconds (default 5e-4, stable at every size)");
  cmd->add_option("--memory-gbps", opt->memory_gbps, "Memory bandwidth ceiling in GB/s")
      ->capture_default_str();
  cmd->add_option("--compute-gflops", opt->compute_gflops, "Compute ceiling in GFLOP/s")
      ->capture_default_str();
  cmd->add_option("--variants", opt->variants,
                  "Vulkan: fused | two_pass | fused,two_pass (semi-implicit and explicit Euler)")
      ->capture_default_str()
      ->check([](const std::string& v) {
        return v == "fused" || v == "two_pass" || v == "fused,two_pass" || v == "two_pass,fused"
                   ? std::string()
                   : std::string("expected fused, two_pass or fused,two_pass");
      });
  cmd->add_option(
         "--layout", opt->layout,
         "Vulkan: how the shaders read their buffers: auto (the device's choice), texel, storage, or "
         "a list (texel,storage: each Vulkan row once per entry, alternated)")
      ->capture_default_str();
  cmd->add_option("--workgroup", opt->workgroup,
                  "Vulkan: invocations per workgroup (0: the device's choice; implicit Euler: always 64)")
      ->capture_default_str();
  cmd->add_option("--mesh", opt->mesh,
                  "Also time the cloth made from this OBJ / glTF mesh, with its particles renumbered by "
                  "meshoptimizer, in the file's order and shuffled, against the grid of nearest size")
      ->check(CLI::ExistingFile);
  cmd->add_option(
         "--stretch", opt->stretch,
         "Also time each grid with stretch control (tethers, provot or both; max_strain 0.1, 4 sweeps) "
         "against the plain step")
      ->check(CLI::IsMember({"tethers", "provot", "both"}));
  cmd->add_option(
         "--contact", opt->contact,
         "Also time the contact scenes (issue 15): a 256 x 256 cloth on a table (box on a floor plane), "
         "a 64 x 64 cloth on a ~10 000-triangle mesh sphere, or both; each against the same cloth "
         "without colliders, alternated")
      ->check(CLI::IsMember({"table", "mesh", "both"}));
  cmd->add_flag(
      "--self-collision", opt->self_collision,
      "Also time each size's cloth folded into 4 layers on the floor with self-collision on (issue 16; "
      "thickness 1.5 x the grid spacing, friction 0.2, 1 iteration) against the same cloth with it off, "
      "alternated (n >= 16)");
  cmd->add_option(
      "--stiffness", opt->stiffness,
      "Structural, shear and bend stiffness of the grid in N/m, e.g. 10000,2000,2000 (default 40,8,8)");
  cmd->add_option("--wind", opt->wind,
                  "Grid rows: the wind's acceleration of a particle facing it, in m/s^2 (0: no wind)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--cloth-mass", opt->cloth_mass,
                  "Mass of the whole grid in kg (default: 0.05 kg per particle of a 64 x 64 grid, 204.8 kg)")
      ->check(CLI::PositiveNumber);
  cmd->add_option(
         "--cg-dispatch", opt->cg_dispatch,
         "implicit_euler on Vulkan: where the CG iterations run (auto: GpuSolverOptions' default; both: "
         "one row each)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "one_workgroup", "per_iteration", "both"}));
  cmd->add_option("--json", opt->json, "Also write the results as JSON to FILE (keys: docs/performance.md)");
  cmd->footer(exit_codes_footer);
  cmd->callback([opt, exit] { *exit = bench_command(*opt); });
}

} // namespace vkcloth::cli
