// SPDX-License-Identifier: MIT
// Mesh contact's per-particle search entries (docs/model.md "Mesh contact", cloth_kernel.h
// mesh_contact): an entry answers a query only where the search would find the same triangle, by
// the same formula, so a particle that keeps its entry gets the bits of one that searches every
// time; and both are the nearest triangle's distance, against a brute-force scan of every triangle.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "grid_meshes.hpp"
#include "internal/kernel.hpp"
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

/// The distance between segments p0-p1 and q0-q1 (Ericson 5.1.9, non-degenerate segments).
double segment_distance(glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 q0, glm::dvec3 q1) {
  const glm::dvec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r), c = glm::dot(d1, r),
               b = glm::dot(d1, d2), denom = a * e - b * b;
  double s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0 || t > 1.0) {
    t = std::clamp(t, 0.0, 1.0);
    s = std::clamp((t * b - c) / a, 0.0, 1.0);
  }
  return glm::length((p0 + d1 * s) - (q0 + d2 * t));
}

/// The distance between two triangles that do not cross each other: the nearest of each one's
/// corners to the other and of their edges to each other.
double triangle_distance(const ColliderMesh::Triangle& x, const ColliderMesh::Triangle& y) {
  const glm::dvec3 p[3] = {x.a, x.b, x.c}, q[3] = {y.a, y.b, y.c};
  double best = 1e300;
  for (int i = 0; i < 3; ++i) {
    best = std::min(best, glm::length(p[i] - kernel::f64::closest_on_triangle(p[i], q[0], q[1], q[2])));
    best = std::min(best, glm::length(q[i] - kernel::f64::closest_on_triangle(q[i], p[0], p[1], p[2])));
    for (int j = 0; j < 3; ++j)
      best = std::min(best, segment_distance(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3]));
  }
  return best;
}

/// One query at `world` (reach 2 mm) through the particle's entry (`cached`, whose entry is `entry`)
/// and one by the search alone: whether the entry changed, whether the answers differ in any bit,
/// and the search's distance.
struct Compared {
  bool searched = false, differs = false;
  float distance = 0.0f;
};
Compared compare_query(const kernel::MeshData& cached, const kernel::ColliderShape<float>& shape,
                       const std::shared_ptr<const ColliderMesh>& mesh, const std::vector<float>& entry,
                       glm::vec3 world) {
  const kernel::MeshData searching{mesh->nodes().data(), mesh->triangles().data()};
  const std::vector<float> before = entry;
  float d_cached, d_searched;
  glm::vec3 n_cached, n_searched, deform;
  kernel::collider_contact(cached, shape, world, world, 0.002f, d_cached, n_cached, deform);
  kernel::collider_contact(searching, shape, world, world, 0.002f, d_searched, n_searched, deform);
  return {before != entry, d_cached != d_searched || n_cached != n_searched, d_searched};
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
  kernel::MeshData cached{mesh->nodes().data(),     mesh->triangles().data(), entries.data(), 0, nullptr,
                          mesh->neighbours().data()};
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

/// 200 queries of one particle on the box (in the frame of compare_query's collider, seed `seed`),
/// at the positions place(rng, u) gives with their distance to the box: whether each leaves an entry
/// of kind `kind` (the entry's n.z: 2 an edge, 3 a corner) and answers the expected distance; the
/// searches (entries renewed) and the answers that differ from the search in any bit.
struct Kept {
  std::size_t searches = 0, differences = 0;
};
template <typename Place> Kept keep_entry_on_box(std::uint32_t seed, float kind, Place place) {
  const auto mesh = box_mesh();
  const Collider c =
      Collider::triangle_mesh(mesh, {0.1, -0.2, 0.3}, Collider::rotation_from_degrees({10, 0, 30}), 0.005);
  std::vector<float> entry(8, 0.0f);
  kernel::MeshData cached{mesh->nodes().data(),     mesh->triangles().data(), entry.data(), 0, nullptr,
                          mesh->neighbours().data()};
  const auto shape = kernel::kernel_shape<float>(c);
  std::mt19937 rng(seed);
  Kept k;
  for (int i = 0; i < 200; ++i) {
    const auto [body, distance] = place(rng);
    const Compared q = compare_query(cached, shape, mesh, entry, glm::vec3(c.center + c.rotation * body));
    k.searches += q.searched;
    k.differences += q.differs;
    CHECK(entry[2] == kind);
    CHECK(std::abs(double(q.distance) - (distance - c.thickness)) < 1e-6);
  }
  return k;
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

TEST_CASE("mesh contact: a triangle's clearances bound the distance to every triangle in front of it") {
  // Checked against every pair, the distance measured between the triangles themselves.
  for (const auto& mesh : {bumps(8), box_mesh()}) {
    CAPTURE(mesh->name());
    std::size_t bounded = 0;
    const auto& tris = mesh->triangles();
    for (std::size_t i = 0; i < tris.size(); ++i) {
      const glm::dvec3 a(tris[i].a),
          n = glm::normalize(glm::cross(glm::dvec3(tris[i].b) - a, glm::dvec3(tris[i].c) - a));
      for (int side = 0; side < 2; ++side) {
        const glm::dvec3 m = side == 0 ? n : -n;
        const double clearance = side == 0 ? tris[i].clearance_front : tris[i].clearance_back;
        CHECK(clearance >= 0.0);
        bounded += clearance > 0.0;
        for (std::size_t j = 0; j < tris.size(); ++j) {
          const double ahead =
              std::max({glm::dot(m, glm::dvec3(tris[j].a) - a), glm::dot(m, glm::dvec3(tris[j].b) - a),
                        glm::dot(m, glm::dvec3(tris[j].c) - a)});
          if (j != i && ahead > 1.0 / 262144.0)
            CHECK(triangle_distance(tris[i], tris[j]) >= clearance);
        }
      }
    }
    CHECK(bounded > 0); // not vacuous
  }
  // The box from outside: nothing reaches in front of a face; inside, its neighbours touch it.
  const auto box = box_mesh();
  for (const ColliderMesh::Triangle& t : box->triangles()) {
    CHECK(t.clearance_front > 1e30f);
    CHECK(t.clearance_back == 0.0f);
  }
  // A deformed pose knows none (its search entries search instead).
  const test::GridMesh g = test::grid_mesh(4, 1.0, [](double x, double) { return 0.1 * x * x; });
  auto mesh = ColliderMesh::create(g.positions, g.triangles, "bent");
  REQUIRE(mesh.ok());
  auto moved = (*mesh)->deformed(g.positions, 0.01);
  REQUIRE(moved.ok());
  for (const ColliderMesh::Triangle& t : (*moved)->triangles())
    CHECK((t.clearance_front == 0.0f && t.clearance_back == 0.0f));
}

TEST_CASE("mesh contact: a particle beyond a box's edge keeps its edge entry, with the search's bits") {
  // The box's top front edge (y = -0.1, z = 0.15) seen from outside, along its middle: every position
  // lies beyond the edge on both faces (the 90-degree wedge), 3 to 6 mm from it.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Kept k = keep_entry_on_box(7, 2.0f, [&](std::mt19937& rng) {
    const double angle = 0.785398 + 0.6 * u(rng), r = 0.0045 + 0.0015 * u(rng);
    return std::pair{glm::dvec3(0.1 * u(rng), -0.1 - r * std::cos(angle), 0.15 + r * std::sin(angle)), r};
  });
  CHECK(k.differences == 0);
  CHECK(k.searches == 1); // the first query's
}

TEST_CASE("mesh contact: an entry moves across faces and edges to its neighbours without a search") {
  // A particle slides 4 mm above the box's top face along y = 0 (across the diagonal shared by the
  // face's two triangles), around the top's edge at x = 0.2 (its wedge) and down the side face
  // (across its diagonal), 0.5 mm a query, off the regions' borders (where a search decides). Only
  // the first query searches the hierarchy.
  const auto mesh = box_mesh();
  REQUIRE(mesh->neighbours().size() == 3 * mesh->triangles().size());
  for (const std::uint32_t n : mesh->neighbours()) // a closed box: every edge has its neighbour
    CHECK(n < mesh->triangles().size());
  const Collider c =
      Collider::triangle_mesh(mesh, {0.1, -0.2, 0.3}, Collider::rotation_from_degrees({10, 0, 30}), 0.005);
  std::vector<float> entry(8, 0.0f);
  std::uint64_t visits = 0;
  kernel::MeshData cached{mesh->nodes().data(),
                          mesh->triangles().data(),
                          entry.data(),
                          0,
                          nullptr,
                          mesh->neighbours().data(),
                          &visits};
  const auto shape = kernel::kernel_shape<float>(c);
  const double r = 0.004, top = 0.35, arc = top + 0.5 * 3.14159265358979 * r;
  std::size_t queries = 0, differences = 0, edge_entries = 0;
  std::uint64_t first_visits = 0;
  for (double u = 0.00025; u < 0.55; u += 0.0005) { // arc length along the path
    glm::dvec3 body;
    if (u < top)
      body = {-0.15 + u, 0.0, 0.15 + r};
    else if (u < arc) {
      const double angle = (u - top) / r; // 0 .. pi/2 around the edge
      body = {0.2 + r * std::sin(angle), 0.0, 0.15 + r * std::cos(angle)};
    } else
      body = {0.2 + r, 0.0, 0.15 - (u - arc)};
    const Compared q = compare_query(cached, shape, mesh, entry, glm::vec3(c.center + c.rotation * body));
    if (queries++ == 0)
      first_visits = visits;
    differences += q.differs;
    edge_entries += entry[2] == 2.0f;
    CHECK(std::abs(double(q.distance) - (r - c.thickness)) < 1e-6);
  }
  CHECK(queries > 1000);
  CHECK(differences == 0);
  CHECK(first_visits > 0);
  CHECK(visits == first_visits); // no search after the first
  CHECK(edge_entries > 5);       // the wedge was crossed with an edge entry
}

TEST_CASE("mesh contact: a face entry answers from the triangle's back as from its front") {
  // Inside the box (its triangles face out), 3 to 5 mm under the top face's first triangle, within a
  // 1 cm square (inside the ball its search leaves: the side faces are 7 cm away), and the same
  // positions above it: one search each, the walk's bits.
  const auto mesh = box_mesh();
  const Collider c =
      Collider::triangle_mesh(mesh, {0.1, -0.2, 0.3}, Collider::rotation_from_degrees({10, 0, 30}), 0.005);
  const auto shape = kernel::kernel_shape<float>(c);
  for (const double side : {-1.0, 1.0}) {
    CAPTURE(side);
    std::vector<float> entry(8, 0.0f);
    kernel::MeshData cached{mesh->nodes().data(),     mesh->triangles().data(), entry.data(), 0, nullptr,
                            mesh->neighbours().data()};
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::size_t searches = 0, differences = 0;
    for (int k = 0; k < 200; ++k) {
      const glm::dvec3 body(0.05 + 0.005 * u(rng), -0.03 + 0.005 * u(rng),
                            0.15 + side * (0.004 + 0.001 * u(rng)));
      const Compared q = compare_query(cached, shape, mesh, entry, glm::vec3(c.center + c.rotation * body));
      searches += q.searched;
      differences += q.differs;
    }
    CHECK(differences == 0);
    CHECK(searches == 1);
  }
}

TEST_CASE("mesh contact: a particle beyond a box's corner keeps its corner entry, with the search's bits") {
  // The box's corner (0.2, -0.1, 0.15) seen from outside: every position lies in its region (beyond
  // each of the three faces' edges through it), 3 to 6 mm from it. The fan around the corner holds
  // triangles of three faces, two of them coplanar on some faces.
  std::uniform_real_distribution<double> u(0.15, 1.0);
  const Kept k = keep_entry_on_box(5, 3.0f, [&](std::mt19937& rng) {
    const glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng), -u(rng), u(rng)));
    const double r = 0.003 + 0.003 * (u(rng) - 0.15) / 0.85;
    return std::pair{glm::dvec3(0.2, -0.1, 0.15) + r * dir, r};
  });
  CHECK(k.differences == 0);
  CHECK(k.searches == 1); // the first query's
}

TEST_CASE("mesh contact: a particle resting on the border between a face and its edge keeps an edge entry") {
  // Particles that rest on a curved mesh settle where their contact normal turns, on the border
  // between a face's region and its edge's (within the guard of it, where neither a face entry nor
  // the edge's wedge answers): the box's top face's edge at x = 0.2, 1.5 um either side of it, 3 to 6
  // mm above. The edge's hinge answers there (mesh_hinge): one search, the walk's bits.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Kept k = keep_entry_on_box(3, 2.0f, [&](std::mt19937& rng) {
    const double h = 0.0045 + 0.0015 * u(rng);
    return std::pair{glm::dvec3(0.2 + 1.5e-6 * u(rng), 0.05 * u(rng), 0.15 + h), h};
  });
  CHECK(k.differences == 0);
  CHECK(k.searches == 1); // the first query's
}
