// SPDX-License-Identifier: MIT
// Closed-form checks of cloth_kernel.h's implicit-Euler blocks (the one source the CPU solver and
// the shaders share), compiled here through engine/src/internal/kernel.hpp in double precision.
#include <doctest/doctest.h>

#include <cmath>

#include "internal/kernel.hpp"

using namespace vkcloth;

TEST_CASE("kernel: the block-Jacobi preconditioner is the inverse of A's diagonal block") {
  // A_pp = (1 + h mu) m I + h^2 sum K_s for a particle with three springs at odd angles, one
  // compressed (no transverse term), two stretched; then P = invert_block(A_pp) and P A_pp = I.
  const double h = 0.02, mu_h = 1.0 + h * 0.5, m = 2.2e-4;
  const glm::dvec3 u[3] = {{0.03, 0.01, -0.02}, {-0.011, 0.024, 0.004}, {0.0, -0.02, 0.031}};
  const double rest[3] = {0.05, 0.02, 0.03}, k[3] = {10000.0, 2000.0, 2000.0};
  kernel::f64::SpringBlock sum{glm::dvec3(0.0), glm::dvec3(0.0)};
  for (int s = 0; s < 3; ++s)
    kernel::add_block(sum, kernel::spring_block(u[s], rest[s], k[s]));
  const auto a = kernel::implicit_diagonal_block(mu_h, m, sum, h * h);
  CHECK(a.off.x != 0.0); // the couplings a diagonal preconditioner would drop
  const auto p = kernel::invert_block(a);
  for (int c = 0; c < 3; ++c) {
    glm::dvec3 e(0.0);
    e[c] = 1.0;
    const glm::dvec3 back = kernel::apply_block(p, kernel::apply_block(a, e));
    for (int r = 0; r < 3; ++r)
      CHECK(back[r] == doctest::Approx(r == c ? 1.0 : 0.0).epsilon(1e-12).scale(1.0));
  }
  // A pinned-free particle without springs: P = 1 / ((1 + h mu) m) on the diagonal.
  const auto lone = kernel::invert_block(
      kernel::implicit_diagonal_block(mu_h, m, {glm::dvec3(0.0), glm::dvec3(0.0)}, h * h));
  CHECK(lone.diag.x == doctest::Approx(1.0 / (mu_h * m)).epsilon(1e-15));
  CHECK(lone.off.y == 0.0);
  // The tolerance's reference: |h m g|^2.
  CHECK(kernel::weight_impulse2(h, m, glm::dvec3(0.0, 0.0, -9.81)) ==
        doctest::Approx(std::pow(h * m * 9.81, 2)).epsilon(1e-14));
}
