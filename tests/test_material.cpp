// SPDX-License-Identifier: MIT
// Materials (docs/model.md "Materials"): the conversion to springs and masses in closed form, and
// the same material hanging the same at three resolutions. CPU solver in double.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "vkcloth/mesh.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;

namespace {

ParticleSystem cloth(const ClothDesc& d) {
  auto sys = make_cloth(d);
  if (!sys.ok())
    FAIL(sys.error().message);
  return *sys;
}

double total_mass(const ParticleSystem& s) {
  double m = 0.0;
  for (const Particle& p : s.particles)
    m += p.mass;
  return m;
}

/// The stiffness of the spring joining grid points (i0, j0) and (i1, j1).
double k_between(const ParticleSystem& s, std::uint32_t nx, std::uint32_t i0, std::uint32_t j0,
                 std::uint32_t i1, std::uint32_t j1) {
  const std::uint32_t a = j0 * nx + i0, b = j1 * nx + i1;
  for (const Spring& sp : s.springs)
    if ((sp.a == a && sp.b == b) || (sp.a == b && sp.b == a))
      return sp.stiffness;
  FAIL("no spring between (" << i0 << ", " << j0 << ") and (" << i1 << ", " << j1 << ")");
  return 0.0;
}

/// Runs `sys` to rest with implicit Euler; the lowest z of any particle.
double settled_lowest_z(const ParticleSystem& sys, double damping, double dt, std::uint64_t steps) {
  SimParams p;
  p.integrator = Integrator::implicit_euler;
  p.dt = dt;
  p.damping = damping;
  p.cg_max_iterations = 2000;
  auto s = CpuSolver<double>::create(sys, p);
  REQUIRE(s.ok());
  auto r = s->run(steps);
  if (!r.ok())
    FAIL(r.error().message);
  double lowest = INFINITY;
  for (const auto& x : s->positions())
    lowest = std::min(lowest, x.z);
  return lowest;
}

} // namespace

TEST_CASE("material: the report preset gives the report's 40 / 8 / 8 and 0.05 kg per interior point on its "
          "10 x 10 grid") {
  ClothDesc d;
  d.material = *material_preset("report");
  const auto s = cloth(d);
  CHECK(k_between(s, 10, 4, 4, 5, 4) == doctest::Approx(40.0).epsilon(1e-12));
  CHECK(k_between(s, 10, 4, 4, 4, 5) == doctest::Approx(40.0).epsilon(1e-12));
  CHECK(k_between(s, 10, 4, 4, 5, 5) == doctest::Approx(8.0).epsilon(1e-12));
  CHECK(k_between(s, 10, 4, 4, 6, 4) == doctest::Approx(8.0).epsilon(1e-12));
  // Along the border a spring stands for half a cell, like the border's masses: 20 and 4.
  CHECK(k_between(s, 10, 4, 0, 5, 0) == doctest::Approx(20.0).epsilon(1e-12));
  CHECK(k_between(s, 10, 9, 4, 9, 5) == doctest::Approx(20.0).epsilon(1e-12));
  CHECK(k_between(s, 10, 0, 4, 0, 6) == doctest::Approx(4.0).epsilon(1e-12));
  CHECK(k_between(s, 10, 0, 0, 1, 1) == doctest::Approx(8.0).epsilon(1e-12));  // shear: never on the border
  CHECK(s.particles[4 * 10 + 4].mass == doctest::Approx(0.05).epsilon(1e-12)); // interior: a full cell
  CHECK(s.particles[4].mass == doctest::Approx(0.025).epsilon(1e-12));         // edge: half
  CHECK(s.particles[0].mass == doctest::Approx(0.0125).epsilon(1e-12));        // corner: a quarter
  CHECK(total_mass(s) == doctest::Approx(0.05 * 81).epsilon(1e-12));
}

TEST_CASE("material: square-grid stiffnesses K_b = 8 B / (kappa^2 h^4), K_d = G, K_s = C - G - 4 K_b") {
  const Material m{0.15, 500.0, 50.0, 1e-5, 0.5};
  const double c = 0.5 * (500.0 + std::sqrt(500.0 * 500.0 + 4 * 50.0 * 50.0)); // 504.95
  CHECK(c - 50.0 * 50.0 / c == doctest::Approx(500.0).epsilon(1e-12));         // E = C - G^2 / C
  for (const std::uint32_t n : {16u, 64u}) {
    CAPTURE(n);
    ClothDesc d;
    d.nx = d.ny = n;
    d.material = m;
    const auto s = cloth(d);
    const double h = 1.0 / (n - 1);
    const double kb = 8.0 * 1e-5 / (400.0 * std::pow(h, 4));
    CHECK(k_between(s, n, 2, 2, 4, 2) == doctest::Approx(kb).epsilon(1e-12));
    CHECK(k_between(s, n, 2, 2, 3, 3) == doctest::Approx(50.0).epsilon(1e-12));
    CHECK(k_between(s, n, 2, 2, 3, 2) == doctest::Approx(c - 50.0 - 4 * kb).epsilon(1e-12));
  }
  // 16 x 16: K_b = 0.0099 N/m, K_s = 454.91; 64 x 64: K_b = 12.6 N/m, K_s = 404.5 (the bend springs
  // carry more of the membrane as h shrinks: 4 K_b grows as h^-4).
}

TEST_CASE(
    "material: masses are density x area, lumped (a corner a quarter cell, an edge half), on any grid") {
  const Material m{0.4, 2000.0, 150.0, 1e-4, 0.5};
  for (auto [nx, ny, w, h] :
       {std::tuple{7u, 5u, 1.3, 0.7}, std::tuple{16u, 16u, 1.0, 1.0}, std::tuple{33u, 9u, 2.0, 0.5}}) {
    CAPTURE(nx);
    ClothDesc d;
    d.nx = nx;
    d.ny = ny;
    d.size = {w, h};
    d.material = m;
    const auto s = cloth(d);
    const double cell = w / (nx - 1) * (h / (ny - 1));
    CHECK(total_mass(s) == doctest::Approx(0.4 * w * h).epsilon(1e-12));
    CHECK(s.particles[0].mass == doctest::Approx(0.4 * cell / 4).epsilon(1e-12));
    CHECK(s.particles[1].mass == doctest::Approx(0.4 * cell / 2).epsilon(1e-12));
    CHECK(s.particles[nx + 1].mass == doctest::Approx(0.4 * cell).epsilon(1e-12));
  }
}

TEST_CASE("material: a rectangular grid keeps the membrane isotropic (per-direction structural and bend)") {
  // dx = 0.1, dy = 0.05: K_d = G (dx^2 + dy^2) / (2 dx dy) = 1.25 G; the lattice's
  // C11 = (K_sx + 4 K_bx) dx/dy + 2 K_d dx^3 / (d^2 dy) and C22 (the same with dx <-> dy) both equal C.
  const Material m{0.15, 500.0, 50.0, 1e-5, 0.5};
  ClothDesc d;
  d.nx = 11;
  d.ny = 21;
  d.size = {1.0, 1.0};
  d.material = m;
  const auto s = cloth(d);
  const double dx = 0.1, dy = 0.05, d2 = dx * dx + dy * dy;
  const double kd = k_between(s, 11, 3, 3, 4, 4);
  CHECK(kd == doctest::Approx(62.5).epsilon(1e-12));
  const double ksx = k_between(s, 11, 3, 3, 4, 3), ksy = k_between(s, 11, 3, 3, 3, 4);
  const double kbx = k_between(s, 11, 3, 3, 5, 3), kby = k_between(s, 11, 3, 3, 3, 5);
  const double c11 = (ksx + 4 * kbx) * dx / dy + 2 * kd * dx * dx * dx / (d2 * dy);
  const double c22 = (ksy + 4 * kby) * dy / dx + 2 * kd * dy * dy * dy / (d2 * dx);
  const double c66 = 2 * kd * dx * dy / d2;
  const double c = 0.5 * (500.0 + std::sqrt(500.0 * 500.0 + 4 * 50.0 * 50.0));
  CHECK(c11 == doctest::Approx(c).epsilon(1e-12));
  CHECK(c22 == doctest::Approx(c).epsilon(1e-12));
  CHECK(c66 == doctest::Approx(50.0).epsilon(1e-12));
  CHECK(ksx != doctest::Approx(ksy)); // the directions really differ
}

TEST_CASE("material: a strip hanging from its top row stretches rho g L^2 / (2 E) at two resolutions") {
  // A soft material so that the extension is measurable: E = 50 N/m, rho g L^2 / (2 E) = 14.7 mm.
  const Material m{0.15, 50.0, 5.0, 1e-7, 5.0};
  const double expected = 0.15 * 9.81 * 1.0 / (2 * 50.0);
  double ext[2];
  int k = 0;
  for (const std::uint32_t ny : {21u, 41u}) {
    ClothDesc d;
    d.nx = (ny - 1) / 5 + 1; // 0.2 m wide: the same aspect at both resolutions
    d.ny = ny;
    d.size = {0.2, 1.0};
    d.material = m;
    d.pin_default_corners = false;
    for (std::uint32_t i = 0; i < d.nx; ++i)
      d.pins.push_back({i, ny - 1});
    const auto sys = cloth(d);
    const double lowest = settled_lowest_z(sys, m.damping, 0.02, 400);
    ext[k++] = -lowest; // the bottom row started at z = 0
    MESSAGE(fmt::format("{} x {}: bottom moved {:.7f} m (closed form {:.5f})", d.nx, ny, -lowest, expected));
  }
  // Measured: 14.688 mm (5 x 21) and 14.690 mm (9 x 41) against 14.715 mm: the strip's top row is
  // held from contracting sideways (Poisson ratio G / C = 0.1), a little stiffer than the closed form.
  CHECK(ext[0] == doctest::Approx(ext[1]).epsilon(0.002));
  CHECK(ext[1] == doctest::Approx(expected).epsilon(0.01));
}

TEST_CASE("material: cotton hangs the same at 16 x 16, 32 x 32 and 64 x 64 (lowest point within 5 % of its "
          "size), per-particle values do not") {
  const auto t0 = std::chrono::steady_clock::now();
  // 1 m x 1 m, vertical, the two top corners pinned, the bottom edge starting at z = 0; implicit
  // Euler, dt = 0.1, 30 steps (3 s: 150 steps of 0.02 give the same lowest point to 0.1 mm).
  auto hang = [](std::uint32_t n, std::optional<Material> material) {
    ClothDesc d;
    d.nx = d.ny = n;
    d.origin = {-0.5, 0.0, 0.0};
    d.material = material;
    return settled_lowest_z(cloth(d), material ? material->damping : 0.5, 0.1, 30);
  };
  // Measured: cotton sags 11.1 / 13.2 / 14.8 mm, 3.7 mm apart (0.4 % of the size); a soft material
  // (E = 20, G = 2 N/m) 189.6 / 210.2 / 230.0 mm, 40 mm apart (4.0 %; 90 steps change the last by
  // 0.1 mm). The sag grows by about the same amount at each doubling: the pins are points, where a
  // membrane's displacement grows as log(1/h), so a soft cloth pinned at two points leaves the 5 %
  // band near 128 x 128; the spread comes from the pins, not from the conversion.
  const Material soft{0.15, 20.0, 2.0, 1e-6, 0.5};
  for (const auto& [name, material, sag_min, sag_max] :
       {std::tuple{"cotton", *material_preset("cotton"), 0.008, 0.02}, std::tuple{"soft", soft, 0.15, 0.3}}) {
    double z[3];
    int k = 0;
    for (const std::uint32_t n : {16u, 32u, 64u}) {
      z[k] = hang(n, material);
      MESSAGE(fmt::format("{0} {1} x {1}: lowest z = {2:.4f} m", name, n, z[k]));
      CHECK(-z[k] > sag_min); // it does sag: the test can tell a cloth that does not move
      CHECK(-z[k] < sag_max);
      ++k;
    }
    const auto [lo, hi] = std::minmax({z[0], z[1], z[2]});
    CHECK(hi - lo < 0.05 * 1.0);
  }
  // The report's per-particle values (0.05 kg per point, 40 / 8 / 8) at 16 and 32: the heavier
  // finer cloth on the same springs falls far further (measured -1.71 m and -10.78 m after 3 s; it
  // has not settled: -1.82 m and -8.04 m after 9 s).
  const double p16 = hang(16, std::nullopt), p32 = hang(32, std::nullopt);
  MESSAGE(fmt::format("per-particle 0.05 kg, 40 / 8 / 8: lowest z = {:.4f} (16), {:.4f} (32)", p16, p32));
  CHECK(std::abs(p16 - p32) > 0.05);
  MESSAGE(
      fmt::format("{:.1f} s", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
}

TEST_CASE(
    "material: refused where the bend springs alone would be stiffer than the membrane, naming the spacing") {
  ClothDesc d;
  d.nx = d.ny = 64;
  d.material = *material_preset("report"); // B = 0.061 N m: fine at 10 x 10, not at 64 x 64
  auto s = make_cloth(d);
  REQUIRE(!s.ok());
  CHECK(s.error().code == ErrorCode::invalid_argument);
  const std::string& msg = s.error().message;
  CHECK_MESSAGE(msg.find("cloth.material") != std::string::npos, msg);
  CHECK_MESSAGE(msg.find("spacing 0.01587") != std::string::npos, msg);
  CHECK_MESSAGE(msg.find("at least 0.0") != std::string::npos, msg);
  d.nx = d.ny = 10;
  CHECK(make_cloth(d).ok());
}

TEST_CASE("material: a quad mesh of a grid gets the grid builder's springs and masses") {
  ClothDesc g;
  g.nx = 9;
  g.ny = 7;
  g.size = {1.0, 0.75}; // square cells, h = 0.125
  g.pin_default_corners = false;
  g.material = *material_preset("denim");
  const auto grid = cloth(g);
  Mesh mesh;
  mesh.positions.reserve(grid.size());
  for (const Particle& p : grid.particles)
    mesh.positions.push_back(p.position);
  for (std::uint32_t j = 0; j + 1 < g.ny; ++j)
    for (std::uint32_t i = 0; i + 1 < g.nx; ++i) {
      const std::uint32_t a = j * g.nx + i;
      mesh.indices.insert(mesh.indices.end(), {a, a + 1, a + 1 + g.nx, a + g.nx});
      mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.indices.size()));
    }
  MeshClothDesc md;
  md.material = g.material;
  md.reorder = false;
  auto made = make_mesh_cloth(mesh, md);
  if (!made.ok())
    FAIL(made.error().message);
  const ParticleSystem& ms = made->system;
  REQUIRE(ms.springs.size() == grid.springs.size());
  for (std::size_t p = 0; p < grid.size(); ++p)
    CHECK(ms.particles[p].mass == doctest::Approx(grid.particles[p].mass).epsilon(1e-12));
  for (const Spring& gs : grid.springs) {
    const auto it = std::find_if(ms.springs.begin(), ms.springs.end(), [&](const Spring& s) {
      return (s.a == gs.a && s.b == gs.b) || (s.a == gs.b && s.b == gs.a);
    });
    REQUIRE(it != ms.springs.end());
    CHECK(it->kind == gs.kind);
    CHECK(it->stiffness == doctest::Approx(gs.stiffness).epsilon(1e-9));
  }
  CHECK(total_mass(ms) == doctest::Approx(0.4 * 0.75).epsilon(1e-12));
}

TEST_CASE("material: every value must be finite and > 0, the message naming the field and the value") {
  Material m{0.15, 500.0, 50.0, 1e-5, 0.5};
  CHECK(check_material(m).ok());
  m.shear = -1.0;
  auto r = check_material(m);
  REQUIRE(!r.ok());
  CHECK(r.error().message == "cloth.material.shear must be finite and > 0, got -1");
  m.shear = 50.0;
  m.density = 0.0;
  CHECK(check_material(m).error().message == "cloth.material.density must be finite and > 0, got 0");
  CHECK(material_preset_list() == "cotton, silk, denim, leather, rubber, report");
  CHECK(!material_preset("wool").has_value());
  for (std::string_view name : material_preset_names())
    CHECK(check_material(*material_preset(name)).ok());
}

TEST_CASE("material: a clamped strip droops under its own weight by the same amount at 9 and 17 points "
          "(bending)") {
  // A cantilever (Peirce's bending test): 0.2 m x 0.1 m horizontal, the part at x <= 0.05 m clamped
  // (pinned), 0.15 m overhang, about 1.1 bending lengths (B / (rho g))^(1/3) = 13.7 cm. Without
  // bending stiffness it hangs straight down (droop 0.150 m, measured); bending holds it up.
  auto droop = [](std::uint32_t n, double bend) {
    const Material m{0.2, 5e4, 5e3, bend, 2.0}; // h_min = 9.7 mm
    ClothDesc d;
    d.nx = n;
    d.ny = (n - 1) / 2 + 1;
    d.size = {0.2, 0.1};
    d.orientation = ClothOrientation::horizontal;
    d.material = m;
    d.pin_default_corners = false;
    for (std::uint32_t j = 0; j < d.ny; ++j)
      for (std::uint32_t i = 0; i <= (n - 1) / 4; ++i) // x <= 0.05
        d.pins.push_back({i, j});
    const double z = -settled_lowest_z(cloth(d), m.damping, 0.05, 200);
    MESSAGE(fmt::format("bend {} N m, {} x {}: droop {:.4f} m", bend, d.nx, d.ny, z));
    return z;
  };
  // Measured: 0.1114 (5 x 3, h = 5 cm: 3 cells of overhang), 0.0986 (9 x 5), 0.0978 m (17 x 9).
  const double d5 = droop(5, 5e-3), d9 = droop(9, 5e-3), d17 = droop(17, 5e-3);
  CHECK(d9 == doctest::Approx(d17).epsilon(0.02));
  CHECK(d5 == doctest::Approx(d17).epsilon(0.15));
  CHECK(d17 < 0.11);                                             // bending holds it up ...
  CHECK(droop(17, 1e-8) == doctest::Approx(0.15).epsilon(0.01)); // ... without it, it hangs down
}

TEST_CASE("material: a triangle mesh gets positive stiffnesses, half on its border, and density x area") {
  // A regular hexagon of side 0.1 m around its centre: 6 equilateral triangles (none pair into quads).
  Mesh mesh;
  mesh.positions.push_back({0, 0, 0});
  for (int k = 0; k < 6; ++k)
    mesh.positions.push_back({0.1 * std::cos(k * M_PI / 3), 0.1 * std::sin(k * M_PI / 3), 0.0});
  for (std::uint32_t k = 0; k < 6; ++k) {
    mesh.indices.insert(mesh.indices.end(), {0u, 1 + k, 1 + (k + 1) % 6});
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.indices.size()));
  }
  MeshClothDesc md;
  md.material = *material_preset("cotton");
  md.reorder = false;
  auto made = make_mesh_cloth(mesh, md);
  if (!made.ok())
    FAIL(made.error().message);
  const double area = 6 * std::sqrt(3.0) / 4 * 0.01;
  CHECK(total_mass(made->system) == doctest::Approx(0.15 * area).epsilon(1e-12));
  CHECK(made->system.particles[0].mass == doctest::Approx(0.15 * area / 3).epsilon(1e-12)); // 6 thirds
  const double ks = *spring_stiffness(*md.material, SpringKind::structural, 0.1, 0.1);
  int spokes = 0, rim = 0, bends = 0;
  for (const Spring& sp : made->system.springs) {
    CHECK(sp.stiffness > 0.0);
    if (sp.kind == SpringKind::structural)
      (sp.a == 0 || sp.b == 0 ? spokes : rim) +=
          sp.stiffness == doctest::Approx((sp.a == 0 || sp.b == 0) ? ks : ks / 2).epsilon(1e-12);
    if (sp.kind == SpringKind::bend) // across each spoke: rim vertices sqrt 3 * 0.1 apart, h = rest / 2
      bends +=
          sp.stiffness == doctest::Approx(*spring_stiffness(*md.material, SpringKind::bend,
                                                            std::sqrt(3.0) * 0.05, std::sqrt(3.0) * 0.05))
                              .epsilon(1e-12);
  }
  CHECK(spokes == 6);
  CHECK(rim == 6);
  CHECK(bends == 6);
}
