// SPDX-License-Identifier: MIT
// Self-collision: the two self-collision samples run to their end without and with it, side by
// side, each labelled with the pairs of its triangles that intersect at the final state
// (measure.hpp's intersecting_triangle_pairs); and frames of the twist and of the layered drop
// (several cloths), each labelled with its pairs then.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cloth_drawing.hpp"
#include "figures.hpp"
#include "vkcloth/measure.hpp"

namespace vkcloth::figures {
namespace {

const char* const sec_self = "Self-collision";

/// samples/scenes/NAME.json without (--set self_collision.enabled=false) and with self-collision,
/// each run for the scene's own steps on the CPU solver (CpuSolver<float>; the GPU solver gives the
/// same, tests/gpu), as one two-panel grid FILE and metrics M[NAME]["off" | "on"].
Result<void> sample_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& name,
                           const std::string& file, const std::string& title, const std::string& what) {
  std::vector<Run> runs;
  std::vector<std::string> labels;
  std::string steps_text;
  for (const bool enabled : {false, true}) {
    const std::vector<std::string> overrides = {std::string("self_collision.enabled=") +
                                                (enabled ? "true" : "false")};
    auto scene = load_scene_file(G.samples / "scenes" / (name + ".json"), overrides);
    if (!scene)
      return Error{scene.error().code, scene.error().message + " (the self-collision figures: --samples DIR)",
                   0};
    const std::uint64_t steps =
        G.self_collision_steps ? std::min(G.self_collision_steps, scene->steps) : scene->steps;
    const double dt = scene->params.dt, time = double(steps) * dt;
    const auto t0 = std::chrono::steady_clock::now();
    auto run = simulate_cloth(d, std::move(*scene), steps, "cpu");
    if (!run)
      return run.error();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    auto isect = intersecting_triangle_pairs(run->scene.system, run->pos);
    if (!isect)
      return isect.error();
    M[name][enabled ? "on" : "off"] = {{"scene", "samples/scenes/" + name + ".json"},
                                       {"self_collision", enabled},
                                       {"steps", steps},
                                       {"dt", dt},
                                       {"time", time},
                                       {"particles", run->pos.size()},
                                       {"intersecting_pairs", isect->pairs},
                                       {"triangles", isect->triangles},
                                       {"min_z", min_z(*run)},
                                       {"diverged", !run->diverged.empty()},
                                       {"seconds", seconds}};
    labels.push_back(fmt::format("{}: {} pairs intersect", enabled ? "with" : "without", isect->pairs));
    steps_text = fmt::format("{} steps of dt = {:g} s ({:g} s)", steps, dt, time);
    runs.push_back(std::move(*run));
  }
  return grid_figure(G, d, runs, labels, file, sec_self, title,
                     fmt::format("samples/scenes/{}.json: {}, after {} on the CPU solver. Left: --set "
                                 "self_collision.enabled=false; right: the scene as it is (thickness "
                                 "0.01 m, friction 0.2). Labels: the pairs of triangles sharing no vertex "
                                 "that intersect at the final state (vkcloth run --check-intersections; "
                                 "self_collision.{}.*.intersecting_pairs).",
                                 name, what, steps_text, name),
                     {0.6f, -1.2f, 1.4f});
}

/// samples/scenes/NAME.json as it is, drawn at each of `times` (s; each a run from the start, at
/// most G.self_collision_steps steps when set), as one grid FILE and metrics M[NAME]["frames"].
Result<void> frames_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& name,
                           const std::string& file, const std::string& title, const std::string& what,
                           const std::vector<double>& times, glm::vec3 from) {
  std::vector<Run> runs;
  std::vector<std::string> labels;
  nlohmann::json frames = nlohmann::json::array();
  for (const double t : times) {
    auto scene = load_scene_file(G.samples / "scenes" / (name + ".json"));
    if (!scene)
      return Error{scene.error().code, scene.error().message + " (the self-collision figures: --samples DIR)",
                   0};
    std::uint64_t steps = static_cast<std::uint64_t>(std::llround(t / scene->params.dt));
    if (G.self_collision_steps)
      steps = std::min(steps, G.self_collision_steps);
    const double time = double(steps) * scene->params.dt;
    auto run = simulate_cloth(d, std::move(*scene), steps, "cpu");
    if (!run)
      return run.error();
    auto isect = intersecting_triangle_pairs(run->scene.system, run->pos);
    if (!isect)
      return isect.error();
    frames.push_back({{"steps", steps},
                      {"time", time},
                      {"intersecting_pairs", isect->pairs},
                      {"triangles", isect->triangles},
                      {"diverged", !run->diverged.empty()}});
    labels.push_back(fmt::format("{:g} s: {} pairs", time, isect->pairs));
    runs.push_back(std::move(*run));
  }
  M[name] = {{"scene", "samples/scenes/" + name + ".json"}, {"frames", frames}};
  return grid_figure(G, d, runs, labels, file, sec_self, title,
                     fmt::format("samples/scenes/{}.json: {}, on the CPU solver. Labels: the pairs of "
                                 "triangles sharing no vertex that intersect then (vkcloth run "
                                 "--check-intersections-every; self_collision.{}.frames).",
                                 name, what, name),
                     from, true, times.size());
}

} // namespace

Result<void> self_collision_figures(Gallery& G) {
  Drawing d;
  VKCLOTH_TRY(open_drawing(G, d, "self_collision"));
  auto& M = G.metrics["self_collision"];
  const Progress progress("self_collision");
  progress("cloth dropped onto a small sphere, without / with");
  VKCLOTH_TRY(sample_figure(G, d, M, "cloth_drop_self_collision", "self_collision_drop.png",
                            "A cloth folds onto itself: without / with self-collision",
                            "a 0.4 x 0.4 m cloth (64 x 64 points) dropped from 0.5 m onto a small "
                            "sphere (r = 6 cm) and the floor, where it folds"));
  progress("cloth sliding off a sphere, without / with");
  VKCLOTH_TRY(sample_figure(G, d, M, "cloth_slide_self_collision", "self_collision_slide.png",
                            "A cloth slides off a sphere: without / with self-collision",
                            "a 0.3 x 0.3 m cloth (48 x 48 points) dropped off-centre onto a sphere "
                            "(r = 15 cm, friction 0.05), off which it slides onto the floor"));
  progress("the twist, frames");
  VKCLOTH_TRY(frames_figure(G, d, M, "twist", "self_collision_twist.png",
                            "The twist: two edges turned against each other",
                            "a 1 m cotton cloth (50 x 50 points, no gravity, vbd) whose left and right "
                            "edges turn one turn each in opposite directions over 5.5 s, self-collision "
                            "thickness 15 mm (below the 20 mm spacing)",
                            {1.0, 1.5, 3.0, 5.5}, {0.0f, -1.8f, 0.6f}));
  progress("five cloths dropped onto a sphere, frames");
  VKCLOTH_TRY(frames_figure(G, d, M, "layered_drop", "self_collision_layers.png",
                            "Five cloths dropped onto a sphere (a scene's cloths)",
                            "five 0.6 m cotton cloths (20 x 20 points each, 4-5 cm apart) dropped onto a "
                            "sphere (r = 20 cm) and the floor, self-collision thickness 35 mm between and "
                            "within them",
                            {0.3, 0.8, 2.0}, {0.6f, -1.2f, 1.4f}));
  progress("done");
  return {};
}

} // namespace vkcloth::figures
