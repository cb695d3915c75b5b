// SPDX-License-Identifier: MIT
// The cloth figures of the report (§3-5): parameter studies and collisions as labelled image
// grids, rendered offscreen with the renderer, and the numbers behind them in figures.json.
//
// Both backends simulate; the picture is drawn by render::ClothRenderer, which draws a GpuSolver's
// buffers. Either backend's final positions are handed to a "display" GpuSolver: the same system with
// its particles placed at the result and all pinned, stepped once so that the force pass rebuilds the
// normals the renderer shades with (pinned particles never move). (The simulating GpuSolver's own
// normals are one step behind its positions, which shows on a moving cloth.) On lavapipe both backends
// compute the same bits, so both galleries show the same pictures (tests/scene/test_figures.cpp compares
// them).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "cloth_drawing.hpp"
#include "report_cloth.hpp"
#include "figures.hpp"
#include "image_grid.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/material.hpp"
#include "vkcloth/measure.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::figures {

// The report cloth's scenes and numbers the material figures share (report_cloth.hpp).

Scene cloth_scene(const ClothDesc& d, SimParams p, std::string name) {
  Scene s;
  s.name = std::move(name);
  s.system = *make_cloth(d); // valid by construction
  (void)p.validate();
  s.params = std::move(p);
  return s;
}

ClothDesc hanging(double ks, double ksh, double kb) {
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  d.stiffness = {ks, ksh, kb};
  return d;
}
ClothDesc horizontal(double z, double ks, double ksh, double kb) {
  ClothDesc d;
  d.orientation = ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, z};
  d.stiffness = {ks, ksh, kb};
  d.pin_default_corners = false;
  return d;
}

SimParams report_params(double dt) {
  SimParams p;
  p.dt = dt;
  p.damping = 0.5;
  return p;
}

double sag(const Run& r) {
  double s = 0.0;
  for (std::size_t i = 0; i < r.pos.size(); ++i)
    s = std::max(s, r.initial[i].z - r.pos[i].z);
  return s;
}

std::string key(double v) {
  return fmt::format("{:g}", v);
}

namespace {

// --- the numbers behind the pictures ------------------------------------------------------------

std::size_t at(const Grid& g, std::uint32_t i, std::uint32_t j) {
  return std::size_t(j) * g.nx + i;
}

/// Mean over the grid's quads of |d1 - d2| / mean(d1, d2), d1 and d2 its two diagonals: zero for a
/// quad that is only stretched or moved, growing as it is sheared into a rhombus.
double diagonal_shear(const Run& r) {
  const Grid g = *r.scene.system.grid;
  double sum = 0.0;
  int n = 0;
  for (std::uint32_t j = 0; j + 1 < g.ny; ++j)
    for (std::uint32_t i = 0; i + 1 < g.nx; ++i) {
      const double d1 = glm::length(r.pos[at(g, i + 1, j + 1)] - r.pos[at(g, i, j)]);
      const double d2 = glm::length(r.pos[at(g, i, j + 1)] - r.pos[at(g, i + 1, j)]);
      sum += std::abs(d1 - d2) / (0.5 * (d1 + d2));
      ++n;
    }
  return sum / n;
}

/// Mean angle (degrees) between consecutive segments `stride` grid steps long along the rows and
/// columns: 0 for a flat cloth. With stride 1 it sees every edge; with stride 2 it sees the cloth at
/// the scale of the bend springs (which join points 2 apart), i.e. its folds.
double bend_angle(const Run& r, std::uint32_t stride = 1) {
  const Grid g = *r.scene.system.grid;
  double sum = 0.0;
  int n = 0;
  auto add = [&](std::size_t a, std::size_t b, std::size_t c) {
    const glm::dvec3 u = r.pos[b] - r.pos[a], v = r.pos[c] - r.pos[b];
    const double cosv = glm::dot(u, v) / std::max(glm::length(u) * glm::length(v), 1e-12);
    sum += std::acos(std::clamp(cosv, -1.0, 1.0)) * 180.0 / M_PI;
    ++n;
  };
  const std::uint32_t s = stride;
  for (std::uint32_t j = 0; j < g.ny; ++j)
    for (std::uint32_t i = s; i + s < g.nx; ++i)
      add(at(g, i - s, j), at(g, i, j), at(g, i + s, j));
  for (std::uint32_t i = 0; i < g.nx; ++i)
    for (std::uint32_t j = s; j + s < g.ny; ++j)
      add(at(g, i, j - s), at(g, i, j), at(g, i, j + s));
  return sum / n;
}

/// Largest distance between grid neighbours (i, j)-(i+1, j) or (i, j)-(i, j+1), over the spacing.
double max_neighbour_ratio(const Run& r) {
  const Grid g = *r.scene.system.grid;
  const double spacing = glm::length(r.initial[at(g, 1, 0)] - r.initial[at(g, 0, 0)]);
  double m = 0.0;
  for (std::uint32_t j = 0; j < g.ny; ++j)
    for (std::uint32_t i = 0; i < g.nx; ++i) {
      if (i + 1 < g.nx)
        m = std::max(m, glm::length(r.pos[at(g, i + 1, j)] - r.pos[at(g, i, j)]));
      if (j + 1 < g.ny)
        m = std::max(m, glm::length(r.pos[at(g, i, j + 1)] - r.pos[at(g, i, j)]));
    }
  return m / spacing;
}

/// Mean displacement along the wind direction (m).
double wind_displacement(const Run& r) {
  const glm::dvec3 u = r.scene.params.wind.direction;
  double s = 0.0;
  for (std::size_t i = 0; i < r.pos.size(); ++i)
    s += glm::dot(r.pos[i] - r.initial[i], u);
  return s / double(r.pos.size());
}

/// Points within 2 eps of the sphere's surface (the contact band), heights.
nlohmann::json contact_metrics(const Run& r, const Collider& sphere, double eps) {
  int on = 0;
  double mean_z = 0.0, max_z = -1e30, max_z_on = -1e30;
  for (const glm::dvec3& p : r.pos) {
    const bool touching = std::abs(glm::length(p - sphere.center) - sphere.radius) < 2.0 * eps;
    on += touching;
    mean_z += p.z;
    max_z = std::max(max_z, p.z);
    if (touching)
      max_z_on = std::max(max_z_on, p.z);
  }
  return {{"on_sphere_fraction", double(on) / double(r.pos.size())},
          {"mean_z", mean_z / double(r.pos.size())},
          {"max_z", max_z},
          {"max_z_on_sphere", on ? nlohmann::json(max_z_on) : nlohmann::json(nullptr)},
          {"diverged", !r.diverged.empty()}};
}

const char* const sec_springs = "Cloth springs (report §3, Figures 5-9)";
const char* const sec_collisions = "Collisions and wind (report §4, Figures 11-13)";

/// Figures 7-9: one spring constant of the report's hanging cloth at three values, after 10 s.
struct StiffnessSweep {
  std::string name;                        ///< the scenes' name and the metrics' key: M[name][<k>]
  std::vector<double> values;              ///< the spring constant k of each panel
  ClothDesc (*cloth)(double k);            ///< the cloth at k
  nlohmann::json (*metrics)(const Run& r); ///< what M[name][<k>] records besides "diverged"
  std::string label;                       ///< a panel's label: "<label> = <k>"
  std::string file, title, caption;
};

/// Draws a stiffness sweep (Figures 7-9): one panel per value, 500 steps each.
Result<void> stiffness_sweep(Gallery& G, Drawing& d, nlohmann::json& M, const StiffnessSweep& s) {
  std::vector<Run> runs;
  std::vector<std::string> labels;
  for (double k : s.values) {
    auto r = simulate_cloth(d, cloth_scene(s.cloth(k), report_params(), s.name), 500, G.backend);
    if (!r)
      return r.error();
    nlohmann::json m = s.metrics(*r);
    m["diverged"] = !r->diverged.empty();
    M[s.name][key(k)] = std::move(m);
    runs.push_back(std::move(*r));
    labels.push_back(fmt::format("{} = {:g}", s.label, k));
  }
  return grid_figure(G, d, runs, labels, s.file, sec_springs, s.title, s.caption);
}

/// Figure 7: structural springs only, K_struct = 5 / 20 / 50.
Result<void> k_struct_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  return stiffness_sweep(
      G, d, M,
      {.name = "k_struct",
       .values = {5.0, 20.0, 50.0},
       .cloth = [](double k) { return hanging(k, 0, 0); },
       .metrics = [](const Run& r) -> nlohmann::json {
         return {{"sag", sag(r)}, {"max_neighbour_ratio", max_neighbour_ratio(r)}};
       },
       .label = "K_struct",
       .file = "cloth_k_struct.png",
       .title = "Figure 7: K_struct = 5 / 20 / 50",
       .caption = note + "Structural springs only, after 10 s. The softer the springs, the more the cloth "
                         "stretches under gravity (sag in figures.json: cloth.k_struct), most at the "
                         "corners."});
}

/// Figure 8: shear with K_struct = 1, K_shear = 1 / 10 / 40.
Result<void> k_shear_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  return stiffness_sweep(
      G, d, M,
      {.name = "k_shear",
       .values = {1.0, 10.0, 40.0},
       .cloth = [](double k) { return hanging(1, k, 0); },
       .metrics = [](const Run& r) -> nlohmann::json {
         return {{"diagonal_shear", diagonal_shear(r)}, {"sag", sag(r)}};
       },
       .label = "K_shear",
       .file = "cloth_k_shear.png",
       .title = "Figure 8: K_shear = 1 / 10 / 40",
       .caption = note + "K_struct = 1, no bend springs, after 10 s. Stiffer shear springs keep the "
                         "cells square: the diagonal shear (mean |d1 - d2| / d over the cells, "
                         "cloth.k_shear) decreases."});
}

/// Figure 9: bend with K_struct = 5, K_bend = 2 / 15 / 40.
Result<void> k_bend_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  return stiffness_sweep(
      G, d, M,
      {.name = "k_bend",
       .values = {2.0, 15.0, 40.0},
       .cloth = [](double k) { return hanging(5, 0, k); },
       .metrics = [](const Run& r) -> nlohmann::json {
         return {{"fold_angle_deg", bend_angle(r, 2)}, {"edge_angle_deg", bend_angle(r, 1)}, {"sag", sag(r)}};
       },
       .label = "K_bend",
       .file = "cloth_k_bend.png",
       .title = "Figure 9: K_bend = 2 / 15 / 40",
       .caption = note + "K_struct = 5, no shear springs, after 10 s. Stiffer bend springs fold the "
                         "cloth less: the fold angle, the mean angle between consecutive segments two "
                         "points long (the bend springs' span) along rows and columns, decreases "
                         "(cloth.k_bend.*.fold_angle_deg). The angle between single edges "
                         "(edge_angle_deg) does not: a bend spring joins points 2 apart, so with soft "
                         "structural springs the points in between zigzag freely."});
}

/// Figure 5: holes without structural springs (K_struct = 0 and 40).
Result<void> holes_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  // A heavy cloth (0.5 kg per point) with soft shear and bend springs (K = 4) dropped from 2 m onto
  // a small sphere (r = 0.15 m) on the floor, seen at the impact (0.8 s).
  std::vector<Run> runs;
  std::vector<std::string> labels;
  for (double ks : {0.0, 40.0}) {
    SimParams p = report_params();
    p.colliders = {Collider::sphere({0, 0, 0.15}, 0.15), Collider::plane({0, 0, 1}, 0.0)};
    ClothDesc desc = horizontal(2.0, ks, 4, 4);
    desc.particle_mass = 0.5;
    auto r = simulate_cloth(d, cloth_scene(desc, p, "holes"), 40, G.backend);
    if (!r)
      return r.error();
    M["no_structural"][ks == 0.0 ? "without_structural" : "with_structural"] = {
        {"max_neighbour_ratio", max_neighbour_ratio(*r)}, {"diverged", !r->diverged.empty()}};
    runs.push_back(std::move(*r));
    labels.push_back(ks == 0.0 ? "no structural" : "K_struct = 40");
  }
  return grid_figure(
      G, d, runs, labels, "cloth_no_structural.png", sec_springs, "Figure 5: without structural springs",
      note + "Here a heavier cloth (0.5 kg per point, shear and bend springs K = 4) dropped from "
             "z = 2 m onto a small sphere (r = 0.15 m) on the floor, at the impact (t = 0.8 s). "
             "Without structural springs the grid is two interleaved lattices (shear and bend "
             "springs join only points of the same parity of i + j) that nothing ties together: "
             "the sphere pushes between them and opens a hole (largest distance between direct "
             "neighbours over the spacing, cloth.no_structural). Left: K_struct = 0, right: 40.",
      {0.6f, -1.2f, 1.6f});
}

/// Figure 11: collisions with the plane, then the plane and the sphere.
Result<void> collisions_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  std::vector<Run> runs;
  std::vector<std::string> labels;
  for (int with_sphere = 0; with_sphere < 2; ++with_sphere) {
    SimParams p = report_params();
    p.colliders = {Collider::plane({0, 0, 1}, 0.0)};
    if (with_sphere)
      p.colliders.insert(p.colliders.begin(), Collider::sphere({0, 0, 0.3}, 0.3));
    auto r = simulate_cloth(d, cloth_scene(horizontal(0.8), p, "collisions"), 150, G.backend);
    if (!r)
      return r.error();
    double min_z = 1e30;
    for (const glm::dvec3& q : r->pos)
      min_z = std::min(min_z, q.z);
    M["collisions"][with_sphere ? "plane_sphere" : "plane"] = {{"min_z", min_z},
                                                               {"diverged", !r->diverged.empty()}};
    if (with_sphere)
      M["collisions"]["plane_sphere"].update(contact_metrics(*r, p.colliders[0], p.contact_epsilon));
    runs.push_back(std::move(*r));
    labels.push_back(with_sphere ? "plane + sphere" : "plane");
  }
  return grid_figure(G, d, runs, labels, "cloth_collisions.png", sec_collisions, "Figure 11: collisions",
                     note + "Dropped flat from z = 0.8 m, K = 40 / 8 / 8, after 3 s: on the floor (left), "
                            "on the sphere (r = 0.3 m) and the floor (right). Nothing goes through.");
}

/// Figure 12: the into-collider test (contact_inward_only true and false).
Result<void> inward_only_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  // The cloth starts INSIDE a large sphere (r = 3 m, centre z = 3.4 m, its bottom at z = 0.4 m), flat
  // at z = 0.5 m: the first projection puts every point on the sphere's bottom cap, where gravity
  // points OUT of the sphere. The inward-only rule lets it fall; cancelling the whole normal part
  // of v and F cancels gravity too and glues the cloth under the sphere.
  std::vector<Run> runs;
  std::vector<std::string> labels;
  const Collider sphere = Collider::sphere({0, 0, 3.4}, 3.0);
  for (bool inward : {true, false}) {
    SimParams p = report_params();
    p.colliders = {sphere};
    p.contact_inward_only = inward;
    auto r = simulate_cloth(d, cloth_scene(horizontal(0.5), p, "contact"), 20, G.backend);
    if (!r)
      return r.error();
    M["contact"][inward ? "inward_only" : "cancel_all"] = contact_metrics(*r, sphere, p.contact_epsilon);
    runs.push_back(std::move(*r));
    labels.push_back(inward ? "inward only (true)" : "cancel all (false)");
  }
  return grid_figure(
      G, d, runs, labels, "cloth_contact.png", sec_collisions, "Figure 12: the into-collider test",
      note + "Started flat at z = 0.5 m inside a large sphere (r = 3 m, centre z = 3.4 m): the first "
             "projection puts it on the sphere's underside, where gravity points away from the "
             "surface. After 0.4 s. Left: contact_inward_only = true, only the parts of v and F "
             "pointing into the sphere are removed, so the cloth falls. Right: false, the whole "
             "normal part is removed, gravity with it: the cloth stays glued under the sphere "
             "(on_sphere_fraction: points within 2 eps of the surface; mean_z; cloth.contact).",
      {0.9f, -1.6f, -0.25f}, /*with_spheres=*/false);
}

/// Figure 13: wind, K_w = 0.01 / 0.02 / 0.05.
Result<void> wind_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  std::vector<Run> runs;
  std::vector<std::string> labels;
  for (double kw : {0.01, 0.02, 0.05}) {
    SimParams p = report_params();
    p.wind = {kw, {0, 1, 0}};
    auto r = simulate_cloth(d, cloth_scene(hanging(40, 8, 8), p, "wind"), 250, G.backend);
    if (!r)
      return r.error();
    M["wind"][key(kw)] = {{"displacement", wind_displacement(*r)}, {"diverged", !r->diverged.empty()}};
    runs.push_back(std::move(*r));
    labels.push_back(fmt::format("K_w = {:g}", kw));
  }
  return grid_figure(G, d, runs, labels, "cloth_wind.png", sec_collisions,
                     "Figure 13: K_w = 0.01 / 0.02 / 0.05",
                     note + "K = 40 / 8 / 8, wind along +y (towards the back), after 5 s, seen from the "
                            "side. F_w = K_w <n, u_w> n per point is small against the 0.49 N weight of a "
                            "point, so the push is small, but it grows with K_w (mean displacement along "
                            "the wind, cloth.wind).",
                     {1.7f, -0.5f, 0.5f});
}

/// Figure 14: the GPU solver, three spring kinds and wind, at three instants (drawn: needs d.ctx).
Result<void> gpu_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  SimParams p = report_params();
  p.wind = {0.05, {0, 1, 0}};
  ClothDesc desc = hanging(40, 8, 8);
  Scene scene = cloth_scene(desc, p, "gpu_wind");
  auto s = gpu::GpuSolver::create(*d.ctx, scene.system, scene.params);
  if (!s)
    return s.error();
  Run ref;
  ref.scene = scene;
  ref.drawn = scene.system;
  for (const Particle& q : scene.system.particles)
    ref.pos.push_back(q.position), ref.pos.back().y += 0.25;
  const render::Camera cam = frame({&ref}, float(d.w) / float(d.h), {1.2f, -1.4f, 0.6f});
  render::RendererOptions ro;
  ro.render_pass = d.target->render_pass();
  auto rend = render::ClothRenderer::create(*d.ctx, *s, *s->topology(), std::move(ro));
  if (!rend)
    return rend.error();
  std::vector<Panel> panels;
  std::uint64_t done = 0;
  for (std::uint64_t at_step : {25u, 100u, 250u}) {
    VKCLOTH_TRY(s->simulate(at_step - done));
    done = at_step;
    auto img = d.target->render(*s, *rend, cam, 0);
    if (!img)
      return img.error();
    panels.push_back({std::move(*img), fmt::format("t = {:g} s", double(at_step) * p.dt)});
  }
  auto pos = s->positions();
  if (!pos)
    return pos.error();
  Run fin;
  fin.scene = scene;
  for (const Particle& q : scene.system.particles)
    fin.initial.push_back(q.position);
  fin.pos = to_d(*pos);
  M["gpu"] = {
      {"device", d.ctx->device_name()}, {"wind_displacement", wind_displacement(fin)}, {"sag", sag(fin)}};
  VKCLOTH_TRY(render::write_png(G.dir / "cloth_gpu.png", compose_grid(panels, "Figure 14: on the GPU")));
  G.figures.push_back({"cloth_gpu.png", "The GPU solver (report §5, Figures 14-15)", "Figure 14: on the GPU",
                       note + "Always simulated by the Vulkan solver (force and integration in compute "
                              "shaders), whatever --backend says, and drawn straight from its buffers: the "
                              "textured cloth with structural, shear and bend springs (40 / 8 / 8) and wind "
                              "K_w = 0.05 along +y, at t = 0.5, 2 and 5 s."});
  return {};
}

/// The mesh samples: a round tablecloth of irregular triangles falling onto a sphere,
/// a quad flag with a hole in the wind, a skirt pinned at its waist over a sphere; each scene file
/// as it is, its full run.
Result<void> mesh_figure(Gallery& G, Drawing& d, nlohmann::json& M) {
  fmt::print(stderr, "figures: cloth meshes (tablecloth, flag with a hole, skirt)\n");
  std::vector<Run> runs;
  std::vector<std::string> labels;
  const std::pair<const char*, const char*> samples[] = {
      {"tablecloth_on_sphere", "tablecloth"}, {"flag_with_hole", "flag"}, {"skirt", "skirt"}};
  for (const auto& [name, label] : samples) {
    auto scene = load_scene_file(G.samples / "scenes" / (std::string(name) + ".json"));
    if (!scene)
      return Error{scene.error().code, scene.error().message + " (the mesh figure: --samples DIR)", 0};
    const std::uint64_t steps = scene->steps;
    const double t = double(steps) * scene->params.dt;
    auto run = simulate_cloth(d, std::move(*scene), steps, G.backend);
    if (!run)
      return run.error();
    M["meshes"][name] = {{"particles", run->pos.size()},
                         {"springs", run->scene.system.springs.size()},
                         {"sag", sag(*run)},
                         {"time", t},
                         {"diverged", !run->diverged.empty()}};
    labels.push_back(fmt::format("{}, {} v, {:g} s", label, run->pos.size(), t));
    runs.push_back(std::move(*run));
  }
  return grid_figure(
      G, d, runs, labels, "cloth_meshes.png", "Cloth from meshes (OBJ / glTF in)", "Cloth from meshes",
      "samples/scenes/tablecloth_on_sphere.json, flag_with_hole.json and skirt.json: OBJ meshes "
      "written by tools/make_meshes.py, springs rebuilt from the faces as on the report's grid "
      "(docs/model.md, Mesh springs), density 1 kg/m^2, dt = 0.002 s, semi-implicit Euler.",
      {0.9f, -1.6f, 1.0f});
}

} // namespace

Result<void> cloth_figures(Gallery& G) {
  Drawing d;
  VKCLOTH_TRY(open_drawing(G, d, "cloth"));
  auto& M = G.metrics["cloth"];
  const Progress progress("cloth");
  const std::string note =
      "The report's cloth: 10 x 10 points over 1 x 1 m, 0.05 kg per point, dt = 0.02 s, "
      "mu = 0.5, semi-implicit Euler, hanging from its two top corners; stretchy by design "
      "(K ~ 40 for a 5 kg cloth). ";

  progress("Figure 7: K_struct = 5 / 20 / 50");
  VKCLOTH_TRY(k_struct_figure(G, d, M, note));
  progress("Figure 8: K_shear = 1 / 10 / 40");
  VKCLOTH_TRY(k_shear_figure(G, d, M, note));
  progress("Figure 9: K_bend = 2 / 15 / 40");
  VKCLOTH_TRY(k_bend_figure(G, d, M, note));
  progress("Figure 5: no structural springs");
  VKCLOTH_TRY(holes_figure(G, d, M, note));
  progress("Figure 11: plane / plane and sphere");
  VKCLOTH_TRY(collisions_figure(G, d, M, note));
  progress("Figure 12: contact_inward_only true / false");
  VKCLOTH_TRY(inward_only_figure(G, d, M, note));
  progress("Figure 13: K_w = 0.01 / 0.02 / 0.05");
  VKCLOTH_TRY(wind_figure(G, d, M, note));
  if (d.ctx) { // Figure 14: the GPU solver, three spring kinds and wind, at three instants
    progress("Figure 14: the GPU result");
    VKCLOTH_TRY(gpu_figure(G, d, M, note));
  }
  VKCLOTH_TRY(mesh_figure(G, d, M));
  VKCLOTH_TRY(material_figures(G, d, M, note, progress));
  progress("done");
  return {};
}

} // namespace vkcloth::figures
