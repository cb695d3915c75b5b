// SPDX-License-Identifier: MIT
// Self-collision's neighbour lists (SelfCollision::skin; docs/model.md "Self-collision"): the
// invariant that makes them exact (after moves of at most half the skin every pair closer than the
// thickness is in both particles' lists, and a larger move can lose one), a listed and an
// overflowed particle's response against the brute-force sum over all pairs, and the solver's
// rebuild rule, counts and thread independence.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "internal/kernel.hpp"
#include "sim_backends.hpp"

using namespace vkcloth;

namespace {

constexpr float thickness = 0.01f, skin = 0.01f;
constexpr float reach = thickness + skin;
constexpr std::uint32_t capacity = VKCLOTH_SELF_LIST_CAPACITY;

/// Particles with the hash of their cells (the CPU solver's counting sort: each bucket's particles
/// in increasing index) and their neighbour lists, built with the kernel's walk.
struct Cloud {
  std::vector<glm::vec3> x, v, rest;
  std::vector<float> w;
  std::vector<std::uint32_t> start, sorted, key, list, listed;
  std::uint32_t mask = 0;

  kernel::SelfDataT<float> data() {
    return {start.data(), sorted.data(), key.data(), x.data(), v.data(), w.data(), rest.data(), list.data()};
  }
  void build() {
    const auto n = std::uint32_t(x.size());
    mask = kernel::self_table_size(n) - 1;
    start.assign(mask + 2, 0);
    key.resize(n);
    sorted.resize(n);
    for (std::uint32_t p = 0; p < n; ++p) {
      key[p] = kernel::self_key(x[p], 1.0f / (2.0f * reach));
      ++start[kernel::f32::self_bucket(key[p], mask) + 1];
    }
    for (std::uint32_t b = 0; b <= mask; ++b)
      start[b + 1] += start[b];
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::uint32_t p = 0; p < n; ++p)
      sorted[fill[kernel::f32::self_bucket(key[p], mask)]++] = p;
    list.assign(std::size_t(n) * capacity, 0);
    listed.resize(n);
    const auto d = data();
    for (std::uint32_t p = 0; p < n; ++p) {
      listed[p] = kernel::self_gather(d, p, key[p], x[p], rest[p], thickness, reach * reach,
                                      1.0f / (2.0f * reach), mask);
    }
  }
  bool lists(std::uint32_t p, std::uint32_t q) const {
    const auto first = list.begin() + std::ptrdiff_t(p) * capacity;
    return std::find(first, first + std::min(listed[p], capacity), q) !=
           first + std::min(listed[p], capacity);
  }
};

/// n particles in a cube of side `side` at random, with random velocities; rest positions far apart
/// (no pair is close at rest).
Cloud random_cloud(std::uint32_t n, float side, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, side), s(-1.0f, 1.0f);
  Cloud c;
  for (std::uint32_t p = 0; p < n; ++p) {
    c.x.push_back({u(rng), u(rng), u(rng)});
    c.v.push_back({s(rng), s(rng), s(rng)});
    c.rest.push_back({float(p), 0.0f, 0.0f});
    c.w.push_back(100.0f);
  }
  return c;
}

/// Every particle moved by `distance` in a random direction.
void move_all(Cloud& c, float distance, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  for (glm::vec3& x : c.x) {
    const glm::vec3 d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    x += d * distance;
  }
}

/// The pairs closer than the thickness now that some particle's list lacks (overflowed lists walk
/// the cells, which hold them: not counted), and how many pairs there are.
std::pair<int, int> unlisted_pairs(const Cloud& c) {
  int missing = 0, pairs = 0;
  for (std::uint32_t p = 0; p < c.x.size(); ++p)
    for (std::uint32_t q = p + 1; q < c.x.size(); ++q)
      if (kernel::self_pair(c.x[p], c.x[q], c.rest[p], c.rest[q], thickness * thickness)) {
        ++pairs;
        const bool in_p = c.listed[p] > capacity || c.lists(p, q);
        const bool in_q = c.listed[q] > capacity || c.lists(q, p);
        missing += in_p && in_q ? 0 : 1;
      }
  return {missing, pairs};
}

/// p's response summed over every other particle in index order (no table): the reference.
void brute_force(const Cloud& c, std::uint32_t p, glm::vec3& dx, glm::vec3& dv) {
  glm::vec3 sx(0), sv(0);
  std::uint32_t pairs = 0;
  for (std::uint32_t q = 0; q < c.x.size(); ++q)
    if (q != p && kernel::self_pair(c.x[p], c.x[q], c.rest[p], c.rest[q], thickness * thickness)) {
      kernel::self_contact(sx, sv, c.x[p], c.v[p], c.w[p], c.x[q], c.v[q], c.w[q], thickness, 0.2f);
      ++pairs;
    }
  kernel::self_mean(sx, sv, pairs, dx, dv);
}

} // namespace

TEST_CASE("self-collision lists: after moves of at most half the skin, every pair is listed") {
  for (unsigned seed : {1u, 2u, 3u}) {
    INFO("seed " << seed);
    Cloud c = random_cloud(400, 0.1f, seed);
    c.build();
    move_all(c, 0.499f * skin, seed + 100);
    const auto [missing, pairs] = unlisted_pairs(c);
    CHECK(pairs > 100); // the test has pairs to lose
    CHECK(missing == 0);

    // The bound is needed: moves of 1.5 skins lose pairs.
    Cloud far = random_cloud(400, 0.1f, seed);
    far.build();
    move_all(far, 1.5f * skin, seed + 100);
    CHECK(unlisted_pairs(far).first > 0);
  }
}

TEST_CASE("self-collision lists: a listed and an overflowed particle respond as the sum over all pairs") {
  // A dense clump (60 particles within 2 cm: every list overflows) and a sparse cloud.
  Cloud dense = random_cloud(60, 0.012f, 7);
  Cloud sparse = random_cloud(400, 0.1f, 8);
  for (Cloud* c : {&dense, &sparse}) {
    c->build();
    move_all(*c, 0.4f * skin, 9);
    const auto d = c->data();
    int overflowed = 0, compared = 0;
    for (std::uint32_t p = 0; p < c->x.size(); ++p) {
      glm::vec3 dx, dv, rx, rv;
      kernel::self_collide_listed(d, p, c->listed[p], c->key[p], c->x[p], c->v[p], c->w[p], c->rest[p],
                                  thickness, c->mask, 0.2f, dx, dv);
      brute_force(*c, p, rx, rv);
      overflowed += c->listed[p] > capacity ? 1 : 0;
      compared += glm::length(rx) > 0.0f ? 1 : 0;
      CHECK(glm::length(dx - rx) <= 1e-6f * thickness); // the same pairs, summed in another order
      CHECK(glm::length(dv - rv) <= 1e-6f * (1.0f + glm::length(rv)));
    }
    CHECK(compared > 20);
    if (c == &dense)
      CHECK(overflowed == int(c->x.size()));
    else
      CHECK(overflowed == 0);
  }
}

TEST_CASE("self-collision lists: built once while nothing moves, again when a particle moves half the skin") {
  // A flat 16 x 16 cloth, no gravity: it never moves, so the first pass builds and no other does.
  ClothDesc desc;
  desc.nx = desc.ny = 16;
  desc.size = {0.3, 0.3};
  desc.pin_default_corners = false;
  auto system = make_cloth(desc);
  REQUIRE(system.ok());
  SimParams params;
  params.gravity = {0.0, 0.0, 0.0};
  params.dt = 1e-3;
  params.self_collision.enabled = true;
  params.self_collision.iterations = 2;
  params.self_collision.skin = 0.01;
  auto s = CpuSolver<float>::create(*system, params);
  REQUIRE(s.ok());
  REQUIRE(s->run(20).ok());
  SelfCollisionStats st = s->self_collision_stats();
  CHECK(st.passes == 40);
  CHECK(st.builds == 1);
  CHECK(st.candidates > 0);
  CHECK(st.overflowed == 0);
  // One particle moved by 0.6 skin: the next pass builds again, and only that one.
  REQUIRE(s->set_particle(100, s->positions()[100] + glm::vec3(0.0f, 0.0f, 0.006f), glm::vec3(0)).ok());
  REQUIRE(s->run(5).ok());
  st = s->self_collision_stats();
  CHECK(st.passes == 50);
  CHECK(st.builds == 2);
  // Another skin is another reach: built again at once.
  params.self_collision.skin = 0.02;
  REQUIRE(s->set_params(params).ok());
  REQUIRE(s->run(1).ok());
  CHECK(s->self_collision_stats().builds == 3);
}

TEST_CASE(
    "self-collision lists: the drop sample builds them in fewer than half its passes, on any thread count") {
  const std::string path = std::string(VKCLOTH_SCENES_DIR) + "/cloth_drop_self_collision.json";
  auto scene = load_scene_file(path);
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  REQUIRE(scene->params.self_collision.skin > 0.0);
  std::vector<std::vector<glm::vec3>> runs;
  for (unsigned threads : {1u, 2u, 4u}) {
    auto s = CpuSolver<float>::create(scene->system, scene->params, {threads});
    REQUIRE(s.ok());
    REQUIRE(s->run(150).ok()); // into the fold: self-contacts from step ~70
    runs.emplace_back(s->positions().begin(), s->positions().end());
    const SelfCollisionStats st = s->self_collision_stats();
    MESSAGE(threads << " threads: " << st.passes << " passes, " << st.builds << " list builds");
    CHECK(st.passes == 150 * scene->params.substeps * scene->params.self_collision.iterations);
    CHECK(st.builds * 2 < st.passes); // it falls ~1 mm a substep: half the skin is 2.5 mm
  }
  CHECK(runs[0] == runs[1]);
  CHECK(runs[0] == runs[2]);
}

// ---- vbd's self-contact energy (SelfCollision::stiffness) ---------------------------------------

namespace {

/// Two free particles (no springs) of mass m flying at each other along x at +-v.
ParticleSystem head_on(double v) {
  ParticleSystem s;
  for (int i = 0; i < 2; ++i) {
    Particle p;
    p.position = {i == 0 ? -0.05 : 0.05, 0.0, 0.0};
    p.velocity = {i == 0 ? v : -v, 0.0, 0.0};
    p.mass = 0.01;
    s.particles.push_back(p);
  }
  s.finalize();
  return s;
}

SimParams vbd_contact(double stiffness) {
  SimParams p;
  p.integrator = Integrator::vbd;
  p.gravity = {0.0, 0.0, 0.0};
  p.damping = 0.0;
  p.dt = 1e-3;
  p.self_collision.enabled = true;
  p.self_collision.thickness = 0.01;
  p.self_collision.skin = 0.005;
  p.self_collision.stiffness = stiffness;
  return p;
}

} // namespace

TEST_CASE_TEMPLATE(
    "vbd self-contact energy: two particles meeting head-on stop near the thickness, momentum kept", Real,
    float, double) {
  // 1 m/s each, 10 g, k = 1000 N/m: the gap's penetration d = t - |x_1 - x_0| obeys d'' = -(2 k / m) d
  // from d' = 2 v, so an undamped contact reaches d = v sqrt(2 m / k) = 4.5 mm; implicit Euler's
  // steps (omega h = 0.45) damp it to ~3.2 mm. Deeper would mean the energy did not act in full;
  // much shallower, that it acted like the passes' projection (which leave the pair at t).
  auto s = CpuSolver<Real>::create(head_on(1.0), vbd_contact(1000.0));
  REQUIRE(s.ok());
  double closest = 1.0;
  for (int step = 0; step < 120; ++step) {
    REQUIRE(s->step().ok());
    const auto x = s->positions();
    closest = std::min(closest, double(x[1].x - x[0].x));
    const double momentum = double(s->velocities()[0].x + s->velocities()[1].x) * 0.01;
    CHECK(std::abs(momentum) < 1e-9); // equal and opposite: both read one snapshot
  }
  const double undamped = 0.01 - 1.0 * std::sqrt(2.0 * 0.01 / 1000.0);
  MESSAGE("closest approach " << closest << " m (undamped spring: " << undamped << " m)");
  CHECK(closest > undamped);
  CHECK(closest < 0.0075);
  const auto v = s->velocities();
  // They part (implicit Euler damps a contact of ~7 steps: about half the speed comes back), never
  // faster than they came.
  CHECK(double(v[0].x) < -0.3);
  CHECK(double(v[0].x) > -1.0);
  CHECK(double(v[1].x) == doctest::Approx(-double(v[0].x)));
  CHECK(s->self_collision_stats().passes == 120 * 5); // one contact evaluation per sweep
}

namespace {
/// A pinned row of particles 2 mm apart along x (a smooth rail), and one free particle (the last)
/// resting on it at height `t` with velocity (vx, 0, 0); 10 g each.
ParticleSystem rail_and_slider(double t, double vx) {
  ParticleSystem s;
  for (int i = 0; i < 160; ++i) {
    Particle q;
    q.position = {-0.05 + 0.002 * i, 0.0, 0.0};
    q.mass = 0.01;
    q.pinned = true;
    s.particles.push_back(q);
  }
  Particle slider;
  slider.position = {0.0, 0.0, t};
  slider.velocity = {vx, 0.0, 0.0};
  slider.mass = 0.01;
  s.particles.push_back(slider);
  s.finalize();
  return s;
}
} // namespace

TEST_CASE("vbd self-contact energy: Coulomb friction takes mu g per second off a slide on a pinned rail") {
  // A pinned row of particles 2 mm apart along x (a smooth rail), and one free particle resting on it
  // at the thickness, sliding along it at 0.5 m/s under gravity. The contact energy carries its
  // weight, lambda = m g summed over its pairs (nearly vertical: it sinks m g / k = 0.1 mm), so
  // friction takes mu g per second off the slide: 0.294 m/s over 0.1 s at mu 0.3.
  vkcloth::test::ValidationScope validation;
  const double t = 0.01, v0 = 0.5, k = 1000.0;
  const ParticleSystem rail = rail_and_slider(t, v0);
  const std::size_t free_p = rail.particles.size() - 1;
  for (double mu : {0.0, 0.3}) {
    for (vkcloth::test::Backend b : vkcloth::test::backends()) {
      INFO(std::string(to_string(b)) << ", mu " << mu);
      SimParams p = vbd_contact(k);
      p.gravity = {0.0, 0.0, -9.81};
      p.self_collision.friction = mu;
      auto sim = vkcloth::test::make_sim(b, rail, p);
      REQUIRE(sim->run(20).ok()); // settles onto the rail (its contact takes a few steps)
      const double vx0 = sim->velocity(free_p).x;
      REQUIRE(sim->run(100).ok());
      const glm::dvec3 xp = sim->position(free_p), vp = sim->velocity(free_p);
      CHECK(xp.z > 0.98 * t); // resting on the rail, at most its sag below the thickness
      CHECK(xp.z < 1.001 * t);
      CHECK(std::abs(vp.z) < 0.01);
      if (mu == 0.0) {
        CHECK(vp.x == doctest::Approx(vx0).epsilon(0.02)); // frictionless: it keeps sliding
      } else {
        CHECK(vx0 == doctest::Approx(v0 - mu * 9.81 * 0.02).epsilon(0.03));
        CHECK(vp.x == doctest::Approx(vx0 - mu * 9.81 * 0.1).epsilon(0.03));
      }
    }
  }
}

TEST_CASE(
    "vbd self-contact energy: static friction holds a particle on a rail tilted below its friction angle") {
  // Gravity tilted by tan(theta) = 0.2 along the rail: with mu = 0.3 the particle is held (the
  // smoothed static friction lets it creep below the slip speed: at 1 mm/s x tan(theta) / mu = 0.67
  // mm/s, 0.13 mm over the 0.2 s); with mu = 0.1 it slides with g (sin theta - mu cos theta).
  vkcloth::test::ValidationScope validation;
  const double t = 0.01, tan_theta = 0.2;
  const double cos_t = 1.0 / std::sqrt(1.0 + tan_theta * tan_theta), sin_t = tan_theta * cos_t;
  const ParticleSystem rail = rail_and_slider(t, 0.0);
  const std::size_t free_p = rail.particles.size() - 1;
  for (double mu : {0.3, 0.1}) {
    for (vkcloth::test::Backend b : vkcloth::test::backends()) {
      INFO(std::string(to_string(b)) << ", mu " << mu);
      SimParams p = vbd_contact(1000.0);
      p.gravity = {9.81 * sin_t, 0.0, -9.81 * cos_t};
      p.self_collision.friction = mu;
      auto sim = vkcloth::test::make_sim(b, rail, p);
      REQUIRE(sim->run(200).ok()); // 0.2 s
      const double vx = sim->velocity(free_p).x, x = sim->position(free_p).x;
      if (mu == 0.3) {
        CHECK(std::abs(vx) < VKCLOTH_SELF_FRICTION_SLIP_SPEED);
        CHECK(std::abs(x) < VKCLOTH_SELF_FRICTION_SLIP_SPEED * 0.2);
      } else {
        CHECK(vx == doctest::Approx(9.81 * (sin_t - mu * cos_t) * 0.2).epsilon(0.05));
      }
    }
  }
}

TEST_CASE("vbd self-contact energy: the SIMD lanes give the scalar reference's bits, on any thread count") {
  const std::string path = std::string(VKCLOTH_SCENES_DIR) + "/cloth_drop_self_collision.json";
  const std::string overrides[] = {"integrator.method=vbd", "self_collision.stiffness=100"};
  auto scene = load_scene_file(path, overrides);
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  std::vector<std::vector<glm::vec3>> runs;
  for (auto [isa, threads] : {std::pair{"scalar", 1u}, {"avx2", 2u}, {"avx512", 2u}, {"avx512", 4u}}) {
    ::setenv("VKCLOTH_CPU_SIMD", isa, 1);
    auto s = CpuSolver<float>::create(scene->system, scene->params, {threads});
    ::unsetenv("VKCLOTH_CPU_SIMD");
    REQUIRE(s.ok());
    REQUIRE(s->run(110).ok()); // into the fold: self-contacts from step ~70
    runs.emplace_back(s->positions().begin(), s->positions().end());
    runs.back().insert(runs.back().end(), s->velocities().begin(), s->velocities().end());
  }
  for (std::size_t k = 1; k < runs.size(); ++k)
    CHECK(runs[k] == runs[0]);
  // The energy acted: without it (the passes after the step instead) the cloth ends elsewhere.
  SimParams passes = scene->params;
  passes.self_collision.stiffness = 0.0;
  auto s = CpuSolver<float>::create(scene->system, passes);
  REQUIRE(s.ok());
  REQUIRE(s->run(110).ok());
  CHECK_FALSE(std::equal(s->positions().begin(), s->positions().end(), runs[0].begin()));
}
