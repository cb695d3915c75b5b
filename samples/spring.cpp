// SPDX-License-Identifier: MIT
// Sample: the report's single spring (§2.1-2.2). A mass hangs from a fixed anchor (the ceiling)
// by one spring: K = 20, L0 = 0.4, m = 1, mu = 0.5, dt = 0.02, started at rest length.
//   spring               a window: the anchor, the spring (a line) and the mass (a sphere)
//   spring --offscreen   PNG frames in out/, no display needed
// Either way out/spring_position.svg and out/spring_energy.svg plot z(t) and the energies.
#include "common/plot_run.hpp"
#include "common/sample_app.hpp"
#include "vkcloth/builders.hpp"

int main(int argc, char** argv) {
  const samples::Options opt = samples::parse_args(
      argc, argv,
      "The report's single spring: K = 20, L0 = 0.4, m = 1, mu = 0.5, dt = 0.02 (semi-implicit Euler).");

  vkcloth::ChainDesc chain; // the defaults are the report's spring: anchor at the origin, mass 0.4 below
  vkcloth::Scene scene;
  scene.name = "spring";
  scene.system = *vkcloth::make_chain(chain); // a valid description: cannot fail
  scene.params.dt = 0.02;
  scene.params.damping = 0.5; // the force -mu m v; with m = 1 the report's -mu v
  if (auto v = scene.params.validate(); !v)
    return 2;

  if (!samples::plot_chain(scene, 10.0, opt.out))
    return 1;
  return samples::run(scene, opt);
}
