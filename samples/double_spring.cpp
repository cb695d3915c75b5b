// SPDX-License-Identifier: MIT
// Sample: two coupled springs (report §2.3): ceiling - spring - mass 1 - spring - mass 2, started
// off-axis so that it swings like a double pendulum (the lower mass kicks the middle one).
//   double_spring [--offscreen]   as `spring`; plots in out/double_spring_{position,energy}.svg
#include "common/plot_run.hpp"
#include "common/sample_app.hpp"
#include "vkcloth/builders.hpp"

int main(int argc, char** argv) {
  const samples::Options opt = samples::parse_args(
      argc, argv,
      "Two coupled springs (K = 60, L0 = 0.4, two 1 kg masses, mu = 0.1, dt = 0.02), started off-axis.");

  vkcloth::ChainDesc chain;
  chain.masses = {1.0, 1.0};
  chain.stiffness = {60.0, 60.0};
  chain.rest_lengths = {0.4, 0.4};
  chain.positions = {{0.3, 0.0, -0.25}, {0.65, 0.0, -0.45}}; // relative to the anchor at the origin
  vkcloth::Scene scene;
  scene.name = "double_spring";
  scene.system = *vkcloth::make_chain(chain);
  scene.params.dt = 0.02;
  scene.params.damping = 0.1;
  if (auto v = scene.params.validate(); !v)
    return 2;

  if (!samples::plot_chain(scene, 10.0, opt.out))
    return 1;
  return samples::run(scene, opt);
}
