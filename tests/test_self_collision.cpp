// SPDX-License-Identifier: MIT
// Self-collision (docs/model.md "Self-collision"): particle pairs against their closed forms
// (head-on stop at the thickness with momentum kept, Coulomb friction's deceleration, the
// rest-position filter, pinned partners) on every backend, the spatial hash's determinism, and a
// cloth that folds onto itself.
#include <doctest/doctest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "kernel.hpp"
#include "sim_backends.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

/// Free particles (no springs) of mass m at `pos` with velocities `vel`; `pinned` ones fixed.
ParticleSystem particles(const std::vector<glm::dvec3>& pos, const std::vector<glm::dvec3>& vel,
                         const std::vector<bool>& pinned = {}) {
  ParticleSystem s;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    Particle p;
    p.position = pos[i];
    p.velocity = vel[i];
    p.mass = 0.01;
    p.pinned = i < pinned.size() && pinned[i];
    s.particles.push_back(p);
  }
  s.finalize();
  return s;
}

SimParams self_params(double thickness, double friction) {
  SimParams p;
  p.gravity = {0.0, 0.0, 0.0};
  p.damping = 0.0;
  p.dt = 1e-3;
  p.self_collision.enabled = true;
  p.self_collision.thickness = thickness;
  p.self_collision.friction = friction;
  return p;
}

} // namespace

TEST_CASE("self-collision: two particles meeting head-on stop at the thickness, momentum kept") {
  ValidationScope validation;
  const double t = 0.01;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    // 0.1 m apart at rest, closing at 2 m/s: they meet after 0.05 s.
    auto sim = make_sim(b, particles({{-0.05, 0.0, 0.0}, {0.05, 0.0, 0.0}}, {{1.0, 0.0, 0.0}, {-1.0, 0.0, 0.0}}),
                        self_params(t, 0.0));
    double closest = 1.0;
    for (int s = 0; s < 100; ++s) {
      REQUIRE(sim->step().ok());
      const auto x = sim->positions();
      closest = std::min(closest, glm::length(x[1] - x[0]));
    }
    const auto x = sim->positions();
    const auto v = sim->velocities();
    // Each substep's correction puts the pair back at the thickness (one iteration resolves a lone pair).
    CHECK(closest >= t * (1.0 - 1e-4));
    CHECK(glm::length(x[1] - x[0]) == doctest::Approx(t).epsilon(1e-4));
    // Perfectly inelastic: the closing velocity is gone, and equal masses keep zero momentum.
    CHECK(std::abs(v[0].x) < 1e-3);
    CHECK(std::abs(v[0].x + v[1].x) < 1e-6);
    CHECK(std::abs(x[0].x + x[1].x) < 1e-6); // the centre of mass stays at 0
  }
}
