// SPDX-License-Identifier: MIT
// Mesh contact's per-particle search entries (docs/model.md "Mesh contact", cloth_kernel.h
// mesh_contact): an entry answers a query only where the search would find the same triangle, by
// the same formula, so a particle that keeps its entry gets the bits of one that searches every
// time; and both are the nearest triangle's distance, against a brute-force scan of every triangle.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "grid_meshes.hpp"
#include "kernel.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/params.hpp"

using namespace vkcloth;

namespace {

/// A bumpy height field over [-0.5, 0.5]^2 (z = 0.04 sin(7x) cos(5y)), n x n quads: convex and
/// concave edges, near-coplanar neighbours.
std::shared_ptr<const ColliderMesh> bumps(int n) {
  return test::grid_collider(
      n, 1.0, [](double x, double y) { return 0.04 * std::sin(7 * x) * std::cos(5 * y); }, "bumps");
}

/// A closed box of 12 triangles (sharp 90-degree edges), faces outward.
std::shared_ptr<const ColliderMesh> box_mesh() {
  const glm::dvec3 v[] = {{-0.2, -0.1, -0.15}, {0.2, -0.1, -0.15}, {0.2, 0.1, -0.15}, {-0.2, 0.1, -0.15},
                          {-0.2, -0.1, 0.15},  {0.2, -0.1, 0.15},  {0.2, 0.1, 0.15},  {-0.2, 0.1, 0.15}};
  const std::uint32_t t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                             1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  auto m = ColliderMesh::create(v, t, "box");
  REQUIRE(m.ok());
  return *m;
}

/// The distance from q to the nearest of the mesh's triangles, by scanning them all (double).
double brute_force_distance(const ColliderMesh& mesh, glm::dvec3 q) {
  double best = 1e300;
  for (const ColliderMesh::Triangle& t : mesh.triangles()) {
    const glm::dvec3 cp =
        kernel::f64::closest_on_triangle(q, glm::dvec3(t.a), glm::dvec3(t.b), glm::dvec3(t.c));
    best = std::min(best, glm::length(q - cp));
  }
  return best;
}

struct Walked {
  std::size_t queries = 0, searches = 0, differences = 0;
  double worst_vs_brute_force = 0.0;
};

/// 48 particles each walk 300 random steps (0.05 to 4 mm, now and then a 2 cm jump) around the mesh,
/// starting within 3 cm of its surface; every position is queried twice (the contact band, then a
/// projection-like reach), once through the particle's entry and once with no entry at all.
template <typename Real>
Walked walk(const std::shared_ptr<const ColliderMesh>& mesh, glm::dvec3 centre, glm::dvec3 half,
            std::uint32_t seed) {
  using V = glm::vec<3, Real>;
  constexpr std::uint32_t particles = 48, steps = 300;
  const Collider c =
      Collider::triangle_mesh(mesh, {0.1, -0.2, 0.3}, Collider::rotation_from_degrees({10, 0, 30}), 0.005);
  std::vector<Real> entries(8 * particles, Real(0));
  kernel::MeshData cached{mesh->nodes().data(), mesh->triangles().data(), entries.data(), 0};
  const kernel::MeshData searching{mesh->nodes().data(), mesh->triangles().data()};
  const auto shape = kernel::kernel_shape<Real>(c);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), step(0.05e-3, 4e-3);
  Walked w;
  for (std::uint32_t p = 0; p < particles; ++p) {
    cached.particle = p;
    glm::dvec3 body = centre + half * glm::dvec3(u(rng), u(rng), u(rng));
    for (std::uint32_t s = 0; s < steps; ++s) {
      const glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)) + glm::dvec3(1e-9));
      body += dir * (s % 97 == 96 ? 0.02 : step(rng));
      const glm::dvec3 world = c.center + c.rotation * body;
      for (Real reach : {Real(2e-3), Real(0.012)}) {
        const std::vector<Real> before(entries.begin() + 8 * p, entries.begin() + 8 * p + 8);
        Real d_cached, d_searched;
        V n_cached, n_searched, deform;
        kernel::collider_contact(cached, shape, V(world), V(world), reach, d_cached, n_cached, deform);
        kernel::collider_contact(searching, shape, V(world), V(world), reach, d_searched, n_searched, deform);
        ++w.queries;
        w.searches += !std::equal(before.begin(), before.end(), entries.begin() + 8 * p);
        w.differences += d_cached != d_searched || n_cached != n_searched;
        if (d_searched < reach) { // in reach: the distance to the shell around the nearest triangle
          const double exact = brute_force_distance(*mesh, body) - c.thickness;
          w.worst_vs_brute_force = std::max(w.worst_vs_brute_force, std::abs(double(d_searched) - exact));
        }
      }
    }
  }
  return w;
}

} // namespace

TEST_CASE_TEMPLATE("mesh contact: a particle's search entry gives the search's bits, the nearest triangle's "
                   "distance",
                   Real, float, double) {
  struct Case {
    const char* name;
    std::shared_ptr<const ColliderMesh> mesh;
    glm::dvec3 centre, half; // where the walks start (the mesh's frame)
  };
  const Case cases[] = {{"bumps 24 x 24", bumps(24), {0, 0, 0.01}, {0.4, 0.4, 0.03}},
                        {"box", box_mesh(), {0, 0, 0}, {0.23, 0.13, 0.18}}};
  std::uint32_t seed = 1;
  for (const Case& k : cases) {
    CAPTURE(k.name);
    const Walked w = walk<Real>(k.mesh, k.centre, k.half, seed++);
    MESSAGE(std::string(k.name) << ": " << w.queries << " queries, " << w.searches
                                << " searches, worst distance vs brute "
                                << "force " << w.worst_vs_brute_force << " m");
    CHECK(w.differences == 0);
    // The entries do answer: most queries search nothing (the walks move 2 mm a step on average).
    CHECK(w.searches < w.queries / 3);
    // Float: the search in float coordinates; the faces' plane formula agrees with the closest point.
    CHECK(w.worst_vs_brute_force < (sizeof(Real) == 4 ? 2e-6 : 1e-12));
  }
}
