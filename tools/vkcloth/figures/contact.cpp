// SPDX-License-Identifier: MIT
// Contact that holds: the sample scenes with friction, moving colliders, capsules, boxes
// and meshes, each drawn and measured as `vkcloth run` measures it (the deepest penetration after
// any step, the largest speed over the last second), with what each picture is about in numbers:
// the tablecloth with and without friction, the cloth on the sphere with and without, the cloth
// carried round by a spinning sphere, the flag around its pole and the cloth on the mesh colliders.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "cloth_drawing.hpp"
#include "figures.hpp"
#include "image_grid.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/measure.hpp"

namespace vkcloth::figures {
namespace {

const char* const sec_contact = "Contact that holds (friction, moving colliders, capsule, box, mesh)";

/// A sample scene run to its end, with the contact measured after every step.
struct ContactRun {
  Run run;                    ///< the final state; drawn with the colliders where they ended
  std::string scene_file;     ///< samples/scenes/NAME.json
  double time = 0.0;          ///< simulated seconds
  double max_penetration = 0; ///< max over every step of measure.hpp's penetration (<= eps: held)
  double calm_speed = 0.0;    ///< the largest free-particle speed over the last second
  /// The mean turn of the particles about the vertical axis through collider 0's centre (rad,
  /// counter-clockwise seen from above), summed step by step (with `track_turn`).
  double turn = 0.0;
};

/// Turn of each particle about the vertical axis through `c` from `a` to `b`, averaged over the
/// particles at least 5 cm off the axis (near it the angle means nothing); per step it is small, so
/// wrapping each difference into (-pi, pi] loses nothing.
double mean_turn(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b, glm::dvec3 c) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const glm::dvec2 p(a[i].x - c.x, a[i].y - c.y), q(b[i].x - c.x, b[i].y - c.y);
    if (glm::length(p) < 0.05 || glm::length(q) < 0.05)
      continue;
    sum += std::remainder(std::atan2(q.y, q.x) - std::atan2(p.y, p.x), 2.0 * M_PI);
    ++n;
  }
  return n ? sum / n : 0.0;
}

/// Loads samples/scenes/NAME.json with `overrides` and runs its own steps on G.backend, one step at
/// a time, measuring the contact after each (the Vulkan solver's state is read back every step).
Result<ContactRun> simulate_sample(const Gallery& G, Drawing& d, const std::string& name,
                                   std::span<const std::string> overrides = {}, bool track_turn = false) {
  ContactRun c;
  c.scene_file = "samples/scenes/" + name + ".json";
  auto scene = load_scene_file(G.samples / "scenes" / (name + ".json"), overrides);
  if (!scene)
    return Error{scene.error().code, scene.error().message + " (the contact figures: --samples DIR)", 0};
  Run& run = c.run;
  run.scene = std::move(*scene);
  for (const Particle& p : run.scene.system.particles)
    run.initial.push_back(p.position);
  const std::uint64_t steps = run.scene.steps;
  const SimParams& params = run.scene.params;
  const auto last_second = static_cast<std::uint64_t>(std::ceil(1.0 / params.dt - 1e-9));
  const std::uint64_t calm_from = steps > last_second ? steps - last_second : 0;
  const glm::dvec3 axis_point = params.colliders.empty() ? glm::dvec3(0.0) : params.colliders[0].centre();

  std::optional<CpuSolver<float>> cpu;
  std::optional<gpu::GpuSolver> gpu;
  if (G.backend == "vulkan") {
    auto s = gpu::GpuSolver::create(*d.ctx, run.scene.system, params);
    if (!s)
      return s.error();
    gpu.emplace(std::move(*s));
  } else {
    auto s = CpuSolver<float>::create(run.scene.system, params);
    if (!s)
      return s.error();
    cpu.emplace(std::move(*s));
  }
  std::vector<glm::dvec3> pos = run.initial, vel;
  std::vector<Collider> colliders = params.colliders;
  c.max_penetration = -std::numeric_limits<double>::infinity();
  std::uint64_t done = 0;
  for (; done < steps; ++done) {
    auto r = cpu ? cpu->step() : gpu->simulate(1);
    if (!r) {
      if (r.error().code != ErrorCode::diverged)
        return r.error();
      run.diverged = r.error().message;
      break;
    }
    const bool calm = done + 1 > calm_from; // in the last second: the speeds are wanted too
    std::vector<glm::dvec3> next;
    if (cpu) {
      next = to_d(cpu->positions());
      if (calm)
        vel = to_d(cpu->velocities());
      colliders = cpu->params().colliders;
    } else {
      auto p = gpu->positions();
      if (!p)
        return p.error();
      next = to_d(*p);
      if (calm) {
        auto v = gpu->velocities();
        if (!v)
          return v.error();
        vel = to_d(*v);
      }
      colliders = gpu->params().colliders;
    }
    auto depth = penetration(run.scene.system, colliders, next);
    if (!depth)
      return depth.error();
    c.max_penetration = std::max(c.max_penetration, depth->depth);
    if (calm)
      c.calm_speed = std::max(c.calm_speed, max_free_speed(run.scene.system, vel));
    if (track_turn)
      c.turn += mean_turn(pos, next, axis_point);
    pos = std::move(next);
  }
  c.time = double(done) * params.dt;
  run.pos = std::move(pos);
  // Drawn with the colliders where the solver has them now (a moving collider has moved).
  run.scene.params.colliders = colliders;
  if (d.ctx) {
    auto g = display_solver(*d.ctx, run);
    if (!g)
      return g.error();
    run.gpu.emplace(std::move(*g));
  }
  return c;
}

/// What every contact run reports.
nlohmann::json common_metrics(const ContactRun& c) {
  double max_z = -1e30;
  for (const glm::dvec3& p : c.run.pos)
    max_z = std::max(max_z, p.z);
  return {{"scene", c.scene_file},
          {"time", c.time},
          {"max_penetration", c.max_penetration},
          {"contact_epsilon", c.run.scene.params.contact_epsilon},
          {"max_speed_last_second", c.calm_speed},
          {"min_z", min_z(c.run)},
          {"max_z", max_z},
          {"diverged", !c.run.diverged.empty()}};
}

/// Distance of p from a sphere's or a capsule's surface (negative inside).
double surface_distance(const Collider& s, glm::dvec3 p) {
  if (s.type == Collider::Type::sphere)
    return glm::length(p - s.center) - s.radius;
  const glm::dvec3 ab = s.b - s.a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(p - s.a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (s.a + t * ab)) - s.radius;
}

/// The fraction of the particles within `band` of collider `k`'s surface (a sphere or a capsule).
double touching_fraction(const Run& r, std::size_t k, double band) {
  const Collider& s = r.scene.params.colliders.at(k);
  std::size_t n = 0;
  for (const glm::dvec3& p : r.pos)
    n += surface_distance(s, p) < band;
  return double(n) / double(r.pos.size());
}

/// A camera on the final cloths of `runs`, their colliders (render::scene_bounds) and the floor
/// under them, seen from `from`.
render::Camera frame_runs(const Drawing& d, std::span<const ContactRun* const> runs, glm::vec3 from) {
  render::Bounds b{glm::vec3(1e30f), glm::vec3(-1e30f)};
  for (const ContactRun* c : runs) {
    const render::Bounds rb = render::scene_bounds(c->run.drawn, c->run.scene.params);
    b.lo = glm::min(b.lo, rb.lo);
    b.hi = glm::max(b.hi, rb.hi);
  }
  const float aspect = float(d.w) / float(d.h);
  return tighten(render::Camera::frame(b, aspect, from, 35.0f), b, aspect);
}

/// The runs as one labelled grid (when a device is there), added to the gallery: one camera for
/// all panels (a comparison: the same scene, the same view), or with `own_camera` each panel framed
/// on its own scene.
Result<void> contact_grid(Gallery& G, Drawing& d, std::vector<ContactRun>& runs,
                          const std::vector<std::string>& labels, const std::string& file,
                          const std::string& title, const std::string& caption, bool own_camera = false,
                          glm::vec3 from = {0.9f, -1.6f, 1.0f}) {
  if (!d.ctx)
    return {};
  std::vector<const ContactRun*> all;
  for (const ContactRun& c : runs)
    all.push_back(&c);
  const render::Camera shared = frame_runs(d, all, from);
  std::vector<Panel> panels;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const render::Camera cam = own_camera ? frame_runs(d, std::span(&all[i], 1), from) : shared;
    auto img = draw(d, runs[i].run, cam);
    if (!img)
      return img.error();
    panels.push_back({std::move(*img), labels[i] + (runs[i].run.diverged.empty() ? "" : " (DIVERGED)")});
  }
  VKCLOTH_TRY(render::write_png(G.dir / file, compose_grid(panels, title)));
  G.figures.push_back({file, sec_contact, title, caption});
  return {};
}

/// The tablecloth on the table (samples/scenes/tablecloth_on_table.json) with friction 0.6 and 0.
Result<void> tablecloth_figure(Gallery& G, Drawing& d, nlohmann::json& M) {
  std::vector<ContactRun> runs;
  std::vector<std::string> labels;
  for (const char* friction : {"0.6", "0"}) {
    const std::vector<std::string> overrides = {std::string("colliders.0.friction=") + friction};
    auto c = simulate_sample(G, d, "tablecloth_on_table", overrides);
    if (!c)
      return c.error();
    const Collider& table = c->run.scene.params.colliders.at(0);
    const double top = table.center.z + table.half_extents.z;
    const Grid grid = *c->run.scene.system.grid;
    const std::size_t centre = std::size_t(grid.ny / 2) * grid.nx + grid.nx / 2;
    std::size_t on_top = 0, held = 0;
    for (const glm::dvec3& p : c->run.pos) {
      on_top += p.z > top - 0.01; // lying on the top (nothing else is that high once it has fallen)
      held += p.z > 0.1;          // on the table or hanging from it: off the floor
    }
    const double n = double(c->run.pos.size());
    const glm::dvec3 slide = c->run.pos[centre] - c->run.initial[centre];
    nlohmann::json m = common_metrics(*c);
    m["friction"] = std::stod(friction);
    m["table_top_z"] = top;
    m["on_top_fraction"] = double(on_top) / n;
    m["held_fraction"] = double(held) / n;
    m["centre_slide"] = std::hypot(slide.x, slide.y);
    M["tablecloth"][friction] = m;
    labels.push_back(fmt::format("mu = {}: {:.0f}% held", friction, 100.0 * double(held) / n));
    runs.push_back(std::move(*c));
  }
  return contact_grid(
      G, d, runs, labels, "contact_tablecloth.png", "A tablecloth on a table: friction 0.6 / 0 (share held)",
      "samples/scenes/tablecloth_on_table.json: a 1.3 x 1 m cloth (27 x 21 points, 2 g each, K = 40 / 8 / 2, "
      "damping 2) dropped 3 cm onto a table (a box collider, top 0.9 x 0.6 m at z = 0.75 m) with 0.41 m "
      "hanging over one end and none over the other, dt = 0.02 s in 4 substeps, after 10 s. Left: "
      "Coulomb friction 0.6 on the table (the scene as it is): the tablecloth drapes and stays, at rest "
      "(largest speed over the last second in contact.tablecloth.0.6.max_speed_last_second). Right: "
      "--set colliders.0.friction=0: nothing holds the overhang and the cloth slides off onto the floor. "
      "Labels: the share of the cloth off the floor (held_fraction: z > 0.1 m); on_top_fraction: lying on "
      "the top; centre_slide: how far the cloth's centre moved; max_penetration: the deepest any particle "
      "was inside a collider after any step (at most contact_epsilon = 1 mm).");
}

/// The report's cloth on the sphere (samples/scenes/cloth_on_sphere.json) and the same with friction
/// 0.6 (cloth_on_sphere_friction.json).
Result<void> sphere_figure(Gallery& G, Drawing& d, nlohmann::json& M) {
  std::vector<ContactRun> runs;
  std::vector<std::string> labels;
  for (const auto& [name, key] :
       {std::pair{"cloth_on_sphere", "0"}, std::pair{"cloth_on_sphere_friction", "0.6"}}) {
    auto c = simulate_sample(G, d, name);
    if (!c)
      return c.error();
    nlohmann::json m = common_metrics(*c);
    const double eps = c->run.scene.params.contact_epsilon;
    m["friction"] = c->run.scene.params.colliders.at(0).friction;
    m["on_sphere_fraction"] = touching_fraction(c->run, 0, 2.0 * eps);
    M["sphere"][key] = m;
    labels.push_back(fmt::format("mu = {}: top {:.2f} m", key, m["max_z"].get<double>()));
    runs.push_back(std::move(*c));
  }
  return contact_grid(
      G, d, runs, labels, "contact_sphere.png", "The report's cloth on the sphere: friction 0 / 0.6 (top)",
      "samples/scenes/cloth_on_sphere.json (the report's model: a frictionless sphere, r = 0.3 m on the "
      "floor) and cloth_on_sphere_friction.json (the same with friction 0.6 on the sphere), 10 x 10, "
      "dt = 0.02 s, after 10 s. Without friction the draped cloth is balanced on the top of the sphere "
      "like a ball on a hill: it slides off onto the floor. With friction it stays on the sphere "
      "(contact.sphere.*: max_z, the highest point; on_sphere_fraction, the points within 2 eps of the "
      "sphere).");
}

/// The cloth on the spinning sphere (samples/scenes/cloth_on_rotating_sphere.json), with its
/// friction and without.
Result<void> spinning_figure(Gallery& G, Drawing& d, nlohmann::json& M) {
  std::vector<ContactRun> runs;
  std::vector<std::string> labels;
  for (const char* friction : {"0.8", "0"}) {
    const std::vector<std::string> overrides = {std::string("colliders.0.friction=") + friction};
    auto c = simulate_sample(G, d, "cloth_on_rotating_sphere", overrides, /*track_turn=*/true);
    if (!c)
      return c.error();
    const Collider& sphere = c->run.scene.params.colliders.at(0);
    nlohmann::json m = common_metrics(*c);
    m["friction"] = std::stod(friction);
    m["angular_velocity_z"] = sphere.angular_velocity.z;
    m["sphere_turn"] = sphere.angular_velocity.z * c->time; // rad, counter-clockwise seen from above
    m["carried_turn"] = c->turn;
    m["on_sphere_fraction"] = touching_fraction(c->run, 0, 2.0 * c->run.scene.params.contact_epsilon);
    M["spinning"][friction] = m;
    labels.push_back(fmt::format("mu = {}: {:.1f} rad", friction, c->turn));
    runs.push_back(std::move(*c));
  }
  return contact_grid(
      G, d, runs, labels, "contact_spinning.png",
      "A spinning sphere carries the cloth: friction 0.8 / 0 (turn)",
      "samples/scenes/cloth_on_rotating_sphere.json: a 1 x 1 m cloth (20 x 20, 2.5 g per point) dropped "
      "onto a sphere (r = 0.3 m, centre z = 0.5 m) spinning at 3 rad/s about the vertical "
      "(angular_velocity [0, 0, 3]), dt = 0.01 s in 2 substeps, after 4 s. Friction acts on the velocity "
      "relative to the sphere's surface: with friction 0.8 (left, the scene as it is) the cloth lands and "
      "turns with the sphere; without (right) the sphere turns under it, carries nothing, and the cloth "
      "slides off. carried_turn: the particles' mean turn about the sphere's axis over the run, "
      "sphere_turn: the sphere's (contact.spinning.*).");
}

/// The flag around its pole (capsule), the cloth on the chair and on the torus knot (meshes).
Result<void> shapes_figure(Gallery& G, Drawing& d, nlohmann::json& M) {
  std::vector<ContactRun> runs;
  std::vector<std::string> labels;
  {
    auto c = simulate_sample(G, d, "flag_on_pole");
    if (!c)
      return c.error();
    const SimParams& p = c->run.scene.params;
    double along_wind = 0.0, pin_drift = 0.0;
    for (std::size_t i = 0; i < c->run.pos.size(); ++i) {
      along_wind += glm::dot(c->run.pos[i] - c->run.initial[i], p.wind.direction);
      if (c->run.scene.system.particles[i].pinned)
        pin_drift = std::max(pin_drift, glm::length(c->run.pos[i] - c->run.initial[i]));
    }
    nlohmann::json m = common_metrics(*c);
    m["on_pole_fraction"] = touching_fraction(c->run, 0, 0.005); // within 5 mm of the pole
    m["mean_displacement_along_wind"] = along_wind / double(c->run.pos.size());
    m["pin_drift"] = pin_drift;
    M["flag_on_pole"] = m;
    labels.push_back("flag and pole");
    runs.push_back(std::move(*c));
  }
  // The chair of cloth_on_mesh.json, then the same cloth on the torus knot (a scene override).
  const std::vector<std::string> knot = {R"(colliders.0.path="../meshes/torus_knot.obj")",
                                         R"(colliders.0.transform={"translate": [0, 0, 0.5]})"};
  for (const auto& [key, overrides] :
       {std::pair{"cloth_on_mesh", std::vector<std::string>{}}, std::pair{"cloth_on_torus_knot", knot}}) {
    auto c = simulate_sample(G, d, "cloth_on_mesh", overrides);
    if (!c)
      return c.error();
    const Collider& mesh = c->run.scene.params.colliders.at(0);
    nlohmann::json m = common_metrics(*c);
    m["mesh"] = mesh.mesh ? std::filesystem::path(mesh.mesh->name()).filename().string() : "";
    m["triangles"] = mesh.mesh ? mesh.mesh->triangles().size() : 0;
    m["overrides"] = overrides;
    M[key] = m;
    labels.push_back(fmt::format("{}, {} tri.", key == std::string("cloth_on_mesh") ? "chair" : "knot",
                                 m["triangles"].get<std::size_t>()));
    runs.push_back(std::move(*c));
  }
  return contact_grid(
      G, d, runs, labels, "contact_shapes.png", "Capsule and mesh colliders: a flag, a chair, a torus knot",
      "Left: samples/scenes/flag_on_pole.json, a 0.6 x 0.4 m flag (16 x 11) pinned along its edge 1 cm "
      "from a pole (a capsule, r = 3 cm, friction 0.5), blown against it by the wind (K_w = 0.01 along -y), "
      "dt = 0.01 s in 4 substeps, after 4 s: it wraps round the pole (on_pole_fraction: the points "
      "within 5 mm of its surface; none at the start). Middle: cloth_on_mesh.json, a 1 x 1 m cloth (20 x 20) "
      "dropped onto the chair "
      "of samples/meshes/chair.obj (a mesh collider: six closed boxes, 72 triangles, thickness 5 mm, "
      "friction 0.5), dt = 0.01 s in 4 substeps, after 4 s. Right: the same cloth on the (2, 3) torus knot "
      "of samples/meshes/torus_knot.obj (1 920 triangles; --set colliders.0.path=../meshes/torus_knot.obj "
      "--set 'colliders.0.transform={\"translate\": [0, 0, 0.5]}'). Meshes by tools/make_meshes.py. "
      "max_penetration (contact.flag_on_pole, contact.cloth_on_mesh, contact.cloth_on_torus_knot): never "
      "deeper than contact_epsilon (a mesh: inside its thickness shell).",
      /*own_camera=*/true);
}

} // namespace

Result<void> contact_figures(Gallery& G) {
  Drawing d;
  VKCLOTH_TRY(open_drawing(G, d, "contact"));
  auto& M = G.metrics["contact"];
  const Progress progress("contact");
  progress("tablecloth on the table, friction 0.6 / 0");
  VKCLOTH_TRY(tablecloth_figure(G, d, M));
  progress("cloth on the sphere, friction 0 / 0.6");
  VKCLOTH_TRY(sphere_figure(G, d, M));
  progress("spinning sphere, friction 0.8 / 0");
  VKCLOTH_TRY(spinning_figure(G, d, M));
  progress("flag on the pole, cloth on the chair and the torus knot");
  VKCLOTH_TRY(shapes_figure(G, d, M));
  progress("done");
  return {};
}

} // namespace vkcloth::figures
