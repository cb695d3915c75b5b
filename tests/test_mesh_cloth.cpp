// SPDX-License-Identifier: MIT
// Cloth from a mesh (docs/model.md "Mesh springs"): a grid handed over as a quad mesh (or as the
// triangles a quad mesh exports to) gives the grid builder's springs and trajectory; triangle
// meshes get bend springs across edges; masses, pins, cleaning and reordering.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <tuple>

#include <glm/geometric.hpp>

#include "sim_backends.hpp"
#include "vkcloth/mesh.hpp"
#include "vkcloth/vkcloth.hpp"
#include "rest_positions.hpp"

using namespace vkcloth;
using vkcloth::test::rest_positions;

namespace {

ClothDesc report_grid(std::uint32_t nx, std::uint32_t ny) {
  ClothDesc d;
  d.nx = nx;
  d.ny = ny;
  d.size = {1.2, 0.8};
  d.origin = {-0.6, 0.0, 0.2};
  d.stiffness = {40.0, 8.0, 8.0};
  return d;
}

ParticleSystem grid_system(const ClothDesc& d) {
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  return std::move(*s);
}

/// The grid's quads split into the two triangles a quad exporter writes.
Mesh triangulated(const Mesh& quads) {
  Mesh m = quads;
  m.indices.clear();
  m.face_offsets = {0};
  for (std::size_t f = 0; f < quads.face_count(); ++f) {
    const std::uint32_t* q = quads.indices.data() + quads.face_offsets[f];
    for (std::uint32_t t : {q[0], q[1], q[2], q[0], q[2], q[3]})
      m.indices.push_back(t);
    m.face_offsets.push_back(static_cast<std::uint32_t>(m.indices.size()) - 3);
    m.face_offsets.push_back(static_cast<std::uint32_t>(m.indices.size()));
  }
  return m;
}

MeshCloth mesh_cloth(const Mesh& m, const MeshClothDesc& d) {
  auto c = make_mesh_cloth(m, d);
  REQUIRE_MESSAGE(c.ok(), (c.ok() ? "" : c.error().message));
  return std::move(*c);
}

MeshClothDesc like_grid(const ClothDesc& g) {
  MeshClothDesc d;
  d.particle_mass = g.particle_mass;
  d.stiffness = g.stiffness;
  d.pin_vertices = {(g.ny - 1) * g.nx, g.ny * g.nx - 1}; // the grid's two top corners
  return d;
}

/// Springs keyed by their file-vertex pair: (kind, rest length, stiffness).
using SpringSet = std::map<std::pair<std::uint32_t, std::uint32_t>, std::tuple<SpringKind, double, double>>;

SpringSet spring_set(const ParticleSystem& s) {
  SpringSet set;
  const bool mapped = s.surface && !s.surface->source_vertex.empty();
  for (const Spring& sp : s.springs) {
    std::uint32_t a = mapped ? s.surface->source_vertex[sp.a] : sp.a;
    std::uint32_t b = mapped ? s.surface->source_vertex[sp.b] : sp.b;
    const std::pair<std::uint32_t, std::uint32_t> key{std::min(a, b), std::max(a, b)};
    CHECK_MESSAGE(set.count(key) == 0, "spring ", key.first, "-", key.second, " appears twice");
    set[key] = {sp.kind, sp.rest_length, sp.stiffness};
  }
  return set;
}

void check_same_springs(const ParticleSystem& grid, const ParticleSystem& mesh) {
  const SpringSet g = spring_set(grid), m = spring_set(mesh);
  REQUIRE(g.size() == m.size());
  for (const auto& [pair, value] : g) {
    const auto it = m.find(pair);
    REQUIRE_MESSAGE(it != m.end(), "the mesh lacks the grid's spring ", pair.first, "-", pair.second);
    CHECK(std::get<0>(it->second) == std::get<0>(value));
    CHECK(std::get<1>(it->second) == doctest::Approx(std::get<1>(value)).epsilon(1e-12));
    CHECK(std::get<2>(it->second) == std::get<2>(value));
  }
}

/// Positions of a mesh cloth's particles in file order.
std::vector<glm::dvec3> in_file_order(const ParticleSystem& s, const std::vector<glm::dvec3>& x) {
  std::vector<glm::dvec3> out(x.size());
  for (std::size_t p = 0; p < x.size(); ++p)
    out[s.surface->source_vertex[p]] = x[p];
  return out;
}

double max_distance(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  REQUIRE(a.size() == b.size());
  double d = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
    d = std::max(d, glm::length(a[k] - b[k]));
  return d;
}

/// A unit square as one quad or two triangles.
Mesh square(bool as_triangles) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  if (as_triangles) {
    m.indices = {0, 1, 2, 0, 2, 3};
    m.face_offsets = {0, 3, 6};
  } else {
    m.indices = {0, 1, 2, 3};
    m.face_offsets = {0, 4};
  }
  return m;
}

std::size_t count_kind(const ParticleSystem& s, SpringKind k) {
  return std::size_t(
      std::count_if(s.springs.begin(), s.springs.end(), [k](const Spring& sp) { return sp.kind == k; }));
}

bool has_warning(const MeshCloth& c, const std::string& part) {
  return std::any_of(c.warnings.begin(), c.warnings.end(),
                     [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

std::string error_of(const Mesh& m, const MeshClothDesc& d) {
  auto c = make_mesh_cloth(m, d);
  REQUIRE_FALSE(c.ok());
  CHECK(c.error().code == ErrorCode::invalid_argument);
  return c.error().message;
}

} // namespace

TEST_CASE("a grid as a quad mesh, or as its triangle pairs, gives the grid builder's springs") {
  const ClothDesc g = report_grid(9, 6);
  const ParticleSystem grid = grid_system(g);
  const Mesh quads = surface_mesh(grid, rest_positions(grid));
  REQUIRE(quads.face_count() == 8 * 5);
  for (bool reorder : {false, true}) {
    CAPTURE(reorder);
    MeshClothDesc d = like_grid(g);
    d.reorder = reorder;
    check_same_springs(grid, mesh_cloth(quads, d).system);
    check_same_springs(grid, mesh_cloth(triangulated(quads), d).system);
  }
}

TEST_CASE("a grid written as a quad OBJ and read back gives the grid's springs") {
  const ClothDesc g = report_grid(7, 5);
  const ParticleSystem grid = grid_system(g);
  auto read = parse_obj(format_obj(surface_mesh(grid, rest_positions(grid))), "grid.obj");
  REQUIRE_MESSAGE(read.ok(), (read.ok() ? "" : read.error().message));
  CHECK(read->face_offsets.size() == 6 * 4 + 1);
  check_same_springs(grid, mesh_cloth(*read, like_grid(g)).system);
}

TEST_CASE("a quad mesh of a grid gives each particle the grid's normal fan terms") {
  const ParticleSystem grid = grid_system(report_grid(6, 5));
  MeshClothDesc d;
  d.reorder = false; // particle p = grid particle p
  const MeshCloth mesh = mesh_cloth(surface_mesh(grid, rest_positions(grid)), d);
  auto tg = ClothTopology::create(grid), tm = ClothTopology::create(mesh.system);
  REQUIRE(tg.ok());
  REQUIRE(tm.ok());
  for (std::size_t p = 0; p < grid.size(); ++p) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> a, b;
    for (auto k = (*tg)->fan_offsets()[p]; k < (*tg)->fan_offsets()[p + 1]; ++k)
      a.emplace_back((*tg)->fans()[k].a, (*tg)->fans()[k].b);
    for (auto k = (*tm)->fan_offsets()[p]; k < (*tm)->fan_offsets()[p + 1]; ++k)
      b.emplace_back((*tm)->fans()[k].a, (*tm)->fans()[k].b);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    CHECK_MESSAGE(a == b, "particle ", p);
  }
}

TEST_CASE("a grid scene and its quad mesh follow the same trajectory for 200 steps (1e-5 m), every backend") {
  vkcloth::test::ValidationScope validation;
  const ClothDesc g = report_grid(12, 9);
  const ParticleSystem grid = grid_system(g);
  const MeshCloth mesh = mesh_cloth(surface_mesh(grid, rest_positions(grid)), like_grid(g));
  SimParams params;
  params.dt = 0.005;
  params.wind.strength = 0.05; // the report's strongest wind (Figure 13): normals matter
  params.wind.direction = {0.3, 1.0, 0.0};
  REQUIRE(params.validate().ok());
  for (auto b : vkcloth::test::backends()) {
    const std::string backend = vkcloth::test::to_string(b);
    CAPTURE(backend);
    auto a = vkcloth::test::make_sim(b, grid, params);
    auto m = vkcloth::test::make_sim(b, mesh.system, params);
    REQUIRE(a->run(200).ok());
    REQUIRE(m->run(200).ok());
    const double d = max_distance(a->positions(), in_file_order(mesh.system, m->positions()));
    MESSAGE(backend, ": grid vs quad mesh after 200 steps: ", d, " m");
    CHECK(d < 1e-5);
    CHECK(max_distance(a->positions(), rest_positions(grid)) > 0.01); // it did move
  }
}

TEST_CASE("triangles get bend springs across each shared edge and no shear, and quads get both diagonals") {
  MeshClothDesc d;
  const MeshCloth tris = mesh_cloth(square(true), d);
  // A right-triangle pair is merged back into its quad only when the file is quad-dominant: two
  // triangles of a square are, so check a non-right pair instead.
  Mesh kite = square(true);
  kite.positions[2] = {1.3, 1.1, 0.0};
  const MeshCloth k = mesh_cloth(kite, d);
  CHECK(count_kind(k.system, SpringKind::structural) == 5);
  CHECK(count_kind(k.system, SpringKind::shear) == 0);
  REQUIRE(count_kind(k.system, SpringKind::bend) == 1);
  for (const Spring& s : k.system.springs)
    if (s.kind == SpringKind::bend) {
      const std::uint32_t a = k.system.surface->source_vertex[s.a], b = k.system.surface->source_vertex[s.b];
      CHECK(std::min(a, b) == 1); // the vertices opposite edge 0-2
      CHECK(std::max(a, b) == 3);
      CHECK(s.rest_length == doctest::Approx(glm::length(kite.positions[1] - kite.positions[3])));
    }
  const MeshCloth quad = mesh_cloth(square(false), d);
  CHECK(count_kind(quad.system, SpringKind::structural) == 4);
  CHECK(count_kind(quad.system, SpringKind::shear) == 2);
  CHECK(count_kind(quad.system, SpringKind::bend) == 0);
  CHECK(count_kind(tris.system, SpringKind::shear) == 2); // the square's triangles: merged to a quad
}

TEST_CASE("density gives lumped masses: each face's area shared by its corners") {
  MeshClothDesc d;
  d.density = 0.2;
  d.transform.scale = 2.0; // a 2 m x 2 m square
  d.reorder = false;
  const MeshCloth quad = mesh_cloth(square(false), d);
  for (const Particle& p : quad.system.particles)
    CHECK(p.mass == doctest::Approx(0.2 * 4.0 / 4.0));
  Mesh kite = square(true);
  kite.positions[2] = {1.3, 1.1, 0.0};
  const MeshCloth k = mesh_cloth(kite, d);
  double total = 0.0;
  for (const Particle& p : k.system.particles)
    total += p.mass;
  const double area = 0.5 * glm::length(glm::cross(kite.positions[1], kite.positions[2])) +
                      0.5 * glm::length(glm::cross(kite.positions[2], kite.positions[3]));
  CHECK(total == doctest::Approx(0.2 * 4.0 * area));
}

TEST_CASE("mesh_transform scales, rotates (z last) and translates, and pins by index and by region") {
  MeshClothDesc d;
  d.transform = {{10.0, 0.0, 1.0}, {0.0, 0.0, 90.0}, 2.0};
  d.reorder = false;
  d.pin_vertices = {0};
  d.pin_region = PinRegion{{9.5, 1.5, 0.5}, {10.5, 2.5, 1.5}}; // holds vertex 1, moved to (10, 2, 1)
  const MeshCloth c = mesh_cloth(square(false), d);
  CHECK(c.warnings.empty());
  const auto& p = c.system.particles;
  CHECK(p[1].position.x == doctest::Approx(10.0));
  CHECK(p[1].position.y == doctest::Approx(2.0));
  CHECK(p[1].position.z == doctest::Approx(1.0));
  CHECK(p[0].pinned);
  CHECK(p[1].pinned);
  CHECK_FALSE(p[2].pinned);
  CHECK_FALSE(p[3].pinned);
}

TEST_CASE("reordering renumbers particles but every output keeps the file's vertex order") {
  const ParticleSystem grid = grid_system(report_grid(10, 7));
  const Mesh quads = surface_mesh(grid, rest_positions(grid));
  // The file's vertices shuffled: a stride-11 permutation of the 70 vertices.
  Mesh shuffled = quads;
  std::vector<std::uint32_t> new_index(quads.positions.size());
  for (std::uint32_t v = 0; v < new_index.size(); ++v)
    new_index[v] = (v * 11) % 70;
  for (std::uint32_t v = 0; v < new_index.size(); ++v) {
    shuffled.positions[new_index[v]] = quads.positions[v];
    shuffled.uvs[new_index[v]] = quads.uvs[v];
  }
  for (std::uint32_t& i : shuffled.indices)
    i = new_index[i];
  const MeshCloth c = mesh_cloth(shuffled, MeshClothDesc{});
  const auto& sv = c.system.surface->source_vertex;
  CHECK_FALSE(std::is_sorted(sv.begin(), sv.end())); // the particles were renumbered
  const Mesh back = surface_mesh(c.system, rest_positions(c.system));
  CHECK(back.positions == shuffled.positions);
  CHECK(back.indices.size() == shuffled.indices.size());
  CHECK(back.uvs.size() == shuffled.uvs.size());
  for (std::size_t k = 0; k < back.uvs.size(); ++k)
    CHECK(back.uvs[k].x == doctest::Approx(shuffled.uvs[k].x).epsilon(1e-6));
}

TEST_CASE("reordering groups each run of 64 particles by valence: the SIMD lanes' lists line up") {
  // The irregular sample tablecloth (valences 3 to 8). Within each run of 64 particles of the
  // spatial order the valence (mesh edges = structural springs of a triangle mesh) never falls;
  // over the whole order it does (the runs keep their places: locality). What it buys: the lists a
  // vector of 16 lanes walks together, padded to its longest (CpuSolver's list kernel; llvmpipe
  // runs a loop as long as its longest lane too), hold few slots more than the lists themselves.
  auto mesh = read_mesh(std::filesystem::path(VKCLOTH_SCENES_DIR) / "../meshes" / "tablecloth.obj");
  REQUIRE(mesh.ok());
  auto padding = [](const ParticleSystem& sys, std::size_t width) {
    auto topology = ClothTopology::create(sys);
    REQUIRE(topology.ok());
    const std::span<const std::uint32_t> off = (*topology)->edge_offsets();
    std::size_t slots = 0, entries = 0;
    for (std::size_t b = 0; b + width <= sys.size(); b += width) {
      std::uint32_t longest = 0;
      for (std::size_t p = b; p < b + width; ++p) {
        longest = std::max(longest, off[p + 1] - off[p]);
        entries += off[p + 1] - off[p];
      }
      slots += longest * width;
    }
    return double(slots) / double(entries) - 1.0;
  };
  MeshClothDesc desc;
  desc.reorder = false;
  const MeshCloth file_order = mesh_cloth(*mesh, desc);
  desc.reorder = true;
  const MeshCloth c = mesh_cloth(*mesh, desc);
  std::vector<int> valence(c.system.size(), 0);
  for (const Spring& s : c.system.springs)
    if (s.kind == SpringKind::structural) {
      ++valence[s.a];
      ++valence[s.b];
    }
  CHECK(*std::max_element(valence.begin(), valence.end()) -
            *std::min_element(valence.begin(), valence.end()) >=
        3);
  for (std::size_t run = 0; run < valence.size(); run += 64) {
    CAPTURE(run);
    const auto end = valence.begin() + std::ptrdiff_t(std::min(valence.size(), run + 64));
    CHECK(std::is_sorted(valence.begin() + std::ptrdiff_t(run), end));
  }
  CHECK_FALSE(std::is_sorted(valence.begin(), valence.end()));
  const double grouped = padding(c.system, 16), plain = padding(file_order.system, 16);
  CAPTURE(grouped);
  CAPTURE(plain);
  CHECK(grouped < plain); // here 13 % against 19 % in the file's ring-by-ring order (docs/performance.md)
}

TEST_CASE("uvs: the file's when present, else a planar projection on the widest axes") {
  MeshClothDesc d;
  d.reorder = false;
  Mesh m = square(false);
  m.positions = {{0, 0, 0}, {2, 0, 0}, {2, 0, 1}, {0, 0, 1}}; // in the x-z plane
  const MeshCloth c = mesh_cloth(m, d);
  CHECK(c.system.surface->uvs[2] == glm::vec2(1.0f, 1.0f));
  CHECK(c.system.surface->uvs[1] == glm::vec2(1.0f, 0.0f));
  m.uvs = {{0.5, 0.5}, {0.25, 0.5}, {0.25, 0.75}, {0.5, 0.75}};
  CHECK(mesh_cloth(m, d).system.surface->uvs[1] == glm::vec2(0.25f, 0.5f));
}

TEST_CASE("degenerate faces and isolated vertices are dropped with a warning that counts them") {
  Mesh m = square(false);
  m.positions.push_back({5, 5, 5});                   // vertex 4: isolated
  m.positions.push_back({1, 0, 0});                   // vertex 5: same place as vertex 1
  m.indices.insert(m.indices.end(), {0, 1, 5});       // zero-length edge 1-5
  m.indices.insert(m.indices.end(), {0, 1, 1});       // repeated vertex
  m.indices.insert(m.indices.end(), {0, 1, 2, 3, 0}); // a pentagon with a repeated corner
  m.face_offsets = {0, 4, 7, 10, 15};
  const MeshCloth c = mesh_cloth(m, MeshClothDesc{});
  CHECK(has_warning(c, "dropped 3 degenerate faces"));
  CHECK(has_warning(c, "the first is face 1"));
  CHECK(has_warning(c, "dropped 2 isolated vertices"));
  CHECK(c.system.size() == 4);
}

TEST_CASE("bad meshes and pins are errors naming the element") {
  MeshClothDesc d;
  Mesh nonmanifold = square(true);
  nonmanifold.positions.push_back({0.5, 0.5, 1.0});
  nonmanifold.indices.insert(nonmanifold.indices.end(), {0, 2, 4}); // a third face on edge 0-2
  nonmanifold.face_offsets.push_back(9);
  CHECK(error_of(nonmanifold, d).find("between vertices 0 and 2 is shared by more than two faces") !=
        std::string::npos);

  Mesh huge = square(false);
  huge.positions[3].y = 1e39;
  CHECK(error_of(huge, d).find("vertex 3") != std::string::npos);
  Mesh nan = square(false);
  nan.positions[2].x = std::nan("");
  CHECK(error_of(nan, d).find("vertex 2") != std::string::npos);
  Mesh out_of_range = square(false);
  out_of_range.indices[2] = 9;
  CHECK(error_of(out_of_range, d).find("face 0 refers to vertex 9") != std::string::npos);
  Mesh all_degenerate = square(false);
  all_degenerate.positions = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  CHECK(error_of(all_degenerate, d).find("every one of the mesh's 1 faces is degenerate") !=
        std::string::npos);

  MeshClothDesc pin = d;
  pin.pin_vertices = {1, 4};
  CHECK(error_of(square(false), pin).find("cloth.pin_vertices[1] = 4 is outside the mesh (4 vertices)") !=
        std::string::npos);
  Mesh stray = square(false);
  stray.positions.push_back({3, 3, 3});
  pin.pin_vertices = {4};
  CHECK(error_of(stray, pin).find("cloth.pin_vertices[0] = 4 is an isolated vertex") != std::string::npos);
  MeshClothDesc scaled = d;
  scaled.transform.scale = -1.0;
  CHECK(error_of(square(false), scaled).find("cloth.mesh_transform.scale") != std::string::npos);
  MeshClothDesc dense = d;
  dense.density = 0.0;
  CHECK(error_of(square(false), dense).find("cloth.density") != std::string::npos);

  MeshClothDesc region = d;
  region.pin_region = PinRegion{{5, 5, 5}, {6, 6, 6}};
  CHECK(has_warning(mesh_cloth(square(false), region),
                    "cloth.pin_region [5, 5, 5] .. [6, 6, 6] pins no vertex"));
}
