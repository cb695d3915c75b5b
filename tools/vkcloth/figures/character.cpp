// SPDX-License-Identifier: MIT
// Cloth on a moving character: samples/scenes/character_cape.json, a torso and two arms
// of capsules that walk, turn 180 degrees in 0.5 s and teleport 10 m, wearing a cotton cape attached
// at the shoulders in the torso's frame. Always on the CPU solver, measured after every step as
// tests/test_frame.cpp measures it; drawn at four instants, each panel centred on the torso.
#include <algorithm>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "cloth_drawing.hpp"
#include "figures.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/measure.hpp"

namespace vkcloth::figures {
namespace {

/// `run`'s cloth and colliders moved by -shift (horizontally): each panel shows the character at
/// its centre wherever it walked.
void centre_on(Run& run, glm::dvec3 shift) {
  shift.z = 0.0;
  for (glm::dvec3& x : run.pos)
    x -= shift;
  for (Collider& c : run.scene.params.colliders) {
    ColliderPose pose;
    pose.position = c.centre() - shift;
    pose.rotation = c.rotation;
    if (c.type == Collider::Type::plane)
      pose.rotation.reset(); // a plane keeps its normal
    c = c.with_pose(pose);
  }
}

} // namespace

Result<void> character_figures(Gallery& G) {
  Drawing d;
  VKCLOTH_TRY(open_drawing(G, d, "character"));
  const Progress progress("character");
  progress("the cape on the walking, turning, teleporting character");
  auto scene = load_scene_file(G.samples / "scenes" / "character_cape.json");
  if (!scene)
    return Error{scene.error().code, scene.error().message + " (the character figure: --samples DIR)", 0};
  auto solver = CpuSolver<float>::create(scene->system, scene->params);
  if (!solver)
    return solver.error();
  const double dt = scene->params.dt;
  const double instants[] = {1.0, 1.75, 2.5, 5.0}; // walking, turning, walking back, after the jump
  const char* const what[] = {"walk", "turn", "back", "jumped"};
  std::vector<Run> runs;
  std::vector<std::string> labels;
  double deepest = -1.0, strain = 0.0, fastest_after = 0.0;
  std::size_t next = 0;
  for (std::uint64_t step = 1; step <= scene->steps && next < std::size(instants); ++step) {
    if (auto r = solver->step(); !r)
      return r.error();
    const std::span<const glm::vec3> x = solver->positions();
    const std::vector<glm::dvec3> xd(x.begin(), x.end());
    const std::vector<Collider> body(solver->params().colliders.begin(),
                                     solver->params().colliders.begin() + 3);
    auto depth = penetration(scene->system, body, xd);
    if (!depth)
      return depth.error();
    deepest = std::max(deepest, depth->depth);
    strain = std::max(strain, structural_strain(scene->system, x)->max);
    if (double(step) * dt > 4.0) {
      const auto v = solver->velocities();
      fastest_after =
          std::max(fastest_after, max_free_speed(scene->system, std::vector<glm::dvec3>(v.begin(), v.end())));
    }
    if (double(step) * dt + 1e-9 < instants[next])
      continue;
    Run run;
    run.scene = *scene;
    run.scene.params.colliders = solver->params().colliders;
    run.pos = xd;
    centre_on(run, run.scene.params.colliders[0].centre());
    if (d.ctx) {
      auto g = display_solver(*d.ctx, run);
      if (!g)
        return g.error();
      run.gpu.emplace(std::move(*g));
    }
    labels.push_back(fmt::format("{:g} s {}", instants[next], what[next]));
    runs.push_back(std::move(run));
    ++next;
  }
  G.metrics["character"] = {
      {"deepest_in_body", deepest}, {"largest_strain", strain}, {"fastest_after_teleport", fastest_after}};
  return grid_figure(
      G, d, runs, labels, "character_cape.png", "Cloth on a moving character",
      "A cape on a walking, turning, teleporting character",
      fmt::format(
          "samples/scenes/character_cape.json: a torso and two arms (keyframed capsules) walk 1.5 m "
          "at 1 m/s, turn 180 degrees in 0.5 s, walk back 0.5 m and teleport 10 m at t = 4 s; a "
          "cotton cape (vbd, 6 substeps of 5 sweeps at dt = 1/300) hangs from the torso by its top row "
          "(cloth.attach) in the torso's frame (inertia). Each panel is centred on the torso. "
          "Over the run: deepest in the body {:.2g} m (contact_epsilon 0.001), largest strain "
          "{:.1f} %, fastest particle after the jump {:.2f} m/s.",
          deepest, 100.0 * strain, fastest_after),
      {1.6f, -1.4f, 0.5f}, false);
}

} // namespace vkcloth::figures
