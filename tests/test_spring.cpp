// SPDX-License-Identifier: MIT
// Single and coupled springs (docs/model.md "Springs", "Integrators") against closed forms and the
// integrators' stability theory. The observations of the report run on every backend; the convergence-order
// and energy studies need double precision and run on the CPU double solver.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim_backends.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

constexpr double K = 20.0, mu = 0.5, m = 1.0, L0 = 0.4, g = 9.81;
constexpr double z_eq = -(L0 + m * g / K); // static sag mg/K below rest length

SimParams spring_params(Integrator integ, double dt, double damping = mu) {
  SimParams p;
  p.integrator = integ;
  p.dt = dt;
  p.damping = damping;
  return p;
}

/// Closed form of m z'' = -K (z - z_eq) - mu m z', started at rest at z = -L0 (rest length).
double closed_form_z(double t, double damping = mu) {
  const double w0 = std::sqrt(K / m), gam = damping / 2.0, wd = std::sqrt(w0 * w0 - gam * gam);
  const double x0 = -L0 - z_eq;
  return z_eq + std::exp(-gam * t) * (x0 * std::cos(wd * t) + gam * x0 / wd * std::sin(wd * t));
}

double run_z(Backend b, Integrator integ, double dt, double t_end) {
  auto sys = make_chain({});
  auto s = make_sim(b, *sys, spring_params(integ, dt));
  const auto steps = static_cast<std::uint64_t>(std::llround(t_end / dt));
  REQUIRE(s->run(steps).ok());
  return s->position(1).z;
}

/// Runs the single spring until it diverges or `steps` pass; returns the error (if any).
Result<void> run_spring(Backend b, Integrator integ, double dt, std::uint64_t steps) {
  auto sys = make_chain({});
  return make_sim(b, *sys, spring_params(integ, dt))->run(steps);
}

} // namespace

TEST_CASE("single spring: period and decay of the damped oscillator, static sag mg/K") {
  auto sys = make_chain({});
  auto s = CpuSolver<double>::create(*sys, spring_params(Integrator::rk4, 0.001));
  REQUIRE(s.ok());
  // Record upward zero crossings of z - z_eq and the peaks of the displacement.
  std::vector<double> crossings, peaks;
  double prev = -L0 - z_eq, prev2 = prev;
  for (int k = 1; k <= 20000; ++k) {
    REQUIRE(s->step().ok());
    const double x = s->positions()[1].z - z_eq;
    if (prev < 0 && x >= 0)
      crossings.push_back(s->time() - 0.001 * x / (x - prev));
    if (prev > prev2 && prev > x && prev > 0)
      peaks.push_back(prev);
    prev2 = prev;
    prev = x;
  }
  const double wd = std::sqrt(K / m - mu * mu / 4.0);
  REQUIRE(crossings.size() >= 5);
  for (std::size_t i = 1; i < 5; ++i)
    CHECK(crossings[i] - crossings[i - 1] == doctest::Approx(2.0 * M_PI / wd).epsilon(1e-4));
  REQUIRE(peaks.size() >= 3);
  // Successive maxima shrink by exp(-mu/2 T).
  CHECK(peaks[2] / peaks[1] == doctest::Approx(std::exp(-mu / 2.0 * 2.0 * M_PI / wd)).epsilon(1e-3));
  CHECK(s->positions()[1].z == doctest::Approx(closed_form_z(20.0)).epsilon(1e-6));
  // After 100 s (25 decay times 2/mu) the mass rests mg/K below rest length.
  REQUIRE(s->run(80000).ok());
  CHECK(s->positions()[1].z == doctest::Approx(z_eq).epsilon(1e-9));
}

TEST_CASE("convergence order: the Euler schemes are first order in dt, RK4 fourth order") {
  const double t = 2.0;
  const double exact = closed_form_z(t);
  for (Integrator integ : {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::rk4}) {
    CAPTURE(to_string(integ));
    const bool rk = integ == Integrator::rk4;
    const double dt0 = rk ? 0.02 : 0.002; // explicit Euler needs dt < mu/K = 0.025 to be stable
    const double e1 = std::abs(run_z(Backend::cpu_double, integ, dt0, t) - exact);
    const double e2 = std::abs(run_z(Backend::cpu_double, integ, dt0 / 2, t) - exact);
    const double e4 = std::abs(run_z(Backend::cpu_double, integ, dt0 / 4, t) - exact);
    const double order1 = std::log2(e1 / e2), order2 = std::log2(e2 / e4);
    MESSAGE(to_string(integ), ": errors ", e1, " ", e2, " ", e4, ", observed orders ", order1, " ", order2);
    CHECK(order2 == doctest::Approx(rk ? 4.0 : 1.0).epsilon(0.1));
    CHECK(e4 < (rk ? 1e-7 : 1e-2));
  }
}

/// |z - z_eq| after `steps` steps started `offset` from equilibrium (the linear regime);
/// infinity when the run diverged.
double excursion_after(Backend b, Integrator integ, double dt, double offset, int steps) {
  ChainDesc d;
  d.positions = {{0.0, 0.0, z_eq + offset}};
  auto sys = make_chain(d);
  auto s = make_sim(b, *sys, spring_params(integ, dt));
  if (!s->run(std::uint64_t(steps)).ok())
    return INFINITY;
  return std::abs(s->position(1).z - z_eq);
}

TEST_CASE("report §2.2 stability (K = 20, mu = 0.5, m = 1) with semi-implicit Euler: 0.02 and 0.2 settle, "
          "0.45 diverges") {
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    const double tol = is_float(b) ? 1e-6 : 1e-9; // float: the rest position itself rounds
    for (double dt : {0.02, 0.2}) {
      CAPTURE(dt);
      CHECK(std::abs(run_z(b, Integrator::semi_implicit_euler, dt, 200.0) - z_eq) < tol);
    }
    auto r = run_spring(b, Integrator::semi_implicit_euler, 0.45, 5000);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().code == ErrorCode::diverged);
    CHECK(r.error().message.find("diverged at step") != std::string::npos);
  }
}

TEST_CASE(
    "semi-implicit Euler is unstable exactly where theory says: (K/m) dt^2 + 2 (mu/m) dt > 4, dt > 0.4234") {
  // Started 1e-4 from equilibrium the motion is linear until it grows; far from it the spring can
  // fold through its anchor, where the force is discontinuous and the motion bounded but chaotic.
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    CHECK(excursion_after(b, Integrator::semi_implicit_euler, 0.41, 1e-4, 200) < 1e-6);
    CHECK(excursion_after(b, Integrator::semi_implicit_euler, 0.42, 1e-4, 200) < 1e-6);
    CHECK(excursion_after(b, Integrator::semi_implicit_euler, 0.43, 1e-4, 200) > 1e-2);
    CHECK(excursion_after(b, Integrator::semi_implicit_euler, 0.44, 1e-4, 200) > 1e-2);
  }
}

TEST_CASE(
    "explicit Euler (eq. 3 as written) is stable only while dt < mu/K = 0.025, so already unstable at 0.2") {
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    CHECK(std::abs(run_z(b, Integrator::explicit_euler, 0.02, 400.0) - z_eq) < (is_float(b) ? 1e-6 : 1e-9));
    CHECK(excursion_after(b, Integrator::explicit_euler, 0.02, 1e-4, 10000) < 1e-6);
    CHECK(excursion_after(b, Integrator::explicit_euler, 0.04, 1e-4, 2000) > 1e-2);
    auto r = run_spring(b, Integrator::explicit_euler, 0.2, 5000);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().code == ErrorCode::diverged);
  }
}

TEST_CASE("mu = 100 at dt = 0.02: the integrator, not physics, makes the mass oscillate (report §2.2)") {
  // Physically the motion is overdamped (mu/2 > sqrt(K/m)) and never crosses equilibrium. With
  // semi-implicit Euler the velocity factor (1 - dt mu) is -1: the velocity flips sign every step.
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto sys = make_chain({});
    auto s = make_sim(b, *sys, spring_params(Integrator::semi_implicit_euler, 0.02, 100.0));
    REQUIRE(s->run(10).ok());
    int flips = 0;
    double last_v = s->velocity(1).z;
    for (int k = 0; k < 20; ++k) {
      REQUIRE(s->step().ok());
      const double v = s->velocity(1).z;
      flips += (v * last_v < 0);
      last_v = v;
    }
    CHECK(flips == 20);
  }
}

TEST_CASE("every backend follows the closed-form damped oscillator (RK4, dt = 0.01, 2 s)") {
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    // RK4's own error here is ~3e-8; float rounding over 200 steps adds a few 1e-7.
    CHECK(std::abs(run_z(b, Integrator::rk4, 0.01, 2.0) - closed_form_z(2.0)) < (is_float(b) ? 2e-6 : 1e-7));
  }
}

TEST_CASE("coupled springs (report §2.3): static equilibrium and energy conservation without damping") {
  ChainDesc d;
  d.masses = {1.0, 0.5};
  d.stiffness = {20.0, 15.0};
  d.rest_lengths = {0.4, 0.3};
  d.positions.clear();
  auto sys = make_chain(d);
  REQUIRE(sys.ok());
  // Equilibrium: spring 1 carries both weights, spring 2 the lower one.
  auto s = CpuSolver<double>::create(*sys, spring_params(Integrator::semi_implicit_euler, 0.01, 2.0));
  REQUIRE(s->run(5000).ok());
  const double z1 = -(0.4 + 1.5 * g / 20.0), z2 = z1 - (0.3 + 0.5 * g / 15.0);
  CHECK(s->positions()[1].z == doctest::Approx(z1).epsilon(1e-6));
  CHECK(s->positions()[2].z == doctest::Approx(z2).epsilon(1e-6));

  // Swinging off-axis with mu = 0: RK4 keeps total energy within 1e-5 relative over 10 s.
  d.positions = {{0.3, 0.0, -0.25}, {0.65, 0.0, -0.45}};
  auto swing = make_chain(d);
  auto r = CpuSolver<double>::create(*swing, spring_params(Integrator::rk4, 0.001, 0.0));
  REQUIRE(r.ok());
  const double e0 = r->energy().total();
  REQUIRE(r->run(10000).ok());
  CHECK(r->energy().total() == doctest::Approx(e0).epsilon(1e-5));
  CHECK(std::abs(r->positions()[1].x - 0.3) > 1e-3); // and it did swing
}

TEST_CASE("float and double solvers agree on the single spring to float precision") {
  const double zf = run_z(Backend::cpu_float, Integrator::semi_implicit_euler, 0.02, 5.0);
  const double zd = run_z(Backend::cpu_double, Integrator::semi_implicit_euler, 0.02, 5.0);
  CHECK(zf == doctest::Approx(zd).epsilon(1e-5));
}
