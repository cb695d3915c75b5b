// SPDX-License-Identifier: MIT
// `vkcloth bench`'s report: the table for people, the ratios quoted from its rows (implicit over
// explicit, mesh over grid, stretch, contact and self-collision costs) and --json for tools.
#include <cmath>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../commands.hpp"
#include "bench.hpp"

namespace vkcloth::cli::bench {
namespace {

double per_particle_step(const Row& r) {
  return r.wall_ms / (double(r.particles) * double(r.steps));
}

/// A mesh row's cost per particle-step over that of the grid timed in alternation with it.
double mesh_over_grid(const Row& r) {
  const double grid_particles = double(r.partner_size) * double(r.partner_size);
  return per_particle_step(r) / (r.partner_ms / (grid_particles * double(r.steps)));
}

/// The grid row of the same backend, variant and integrator whose particle count is closest to a
/// stretch row's (its own grid): that row's cost is quoted against it.
const Row* nearest_grid(const std::vector<Row>& rows, const Row& r) {
  const Row* best = nullptr;
  for (const Row& g : rows)
    if (g.scene == "grid" && g.backend == r.backend && g.variant == r.variant && g.layout == r.layout &&
        g.integrator == r.integrator && g.instances == 1 &&
        (!best || std::abs(double(g.particles) - double(r.particles)) <
                      std::abs(double(best->particles) - double(r.particles))))
      best = &g;
  return best;
}

bool is_self(const Row& r) {
  return r.scene == "self_collision" || r.scene == "self_collision_free";
}

/// The row with self-collision off timed with a self-collision row (same backend, variant, layout,
/// integrator and size).
const Row* self_free_of(const std::vector<Row>& rows, const Row& r) {
  for (const Row& e : rows)
    if (e.scene == "self_collision_free" && e.size == r.size && e.backend == r.backend &&
        e.variant == r.variant && e.layout == r.layout && e.integrator == r.integrator)
      return &e;
  return nullptr;
}

/// The bare-cloth row timed with a contact row (its colliders removed; same backend, variant,
/// layout and integrator): the contact phase is quoted against it.
const Row* contact_free_of(const std::vector<Row>& rows, const Row& r) {
  for (const Row& e : rows)
    if (e.scene == "contact_free" && e.contact == r.contact && e.backend == r.backend &&
        e.variant == r.variant && e.layout == r.layout && e.integrator == r.integrator)
      return &e;
  return nullptr;
}

/// A contact row's contact phase: its time per step over its bare row's (ms; < 0: no bare row).
double contact_phase_ms(const std::vector<Row>& rows, const Row& r) {
  const Row* f = contact_free_of(rows, r);
  return f ? (r.wall_ms - f->wall_ms) / double(r.steps) : -1.0;
}

/// The sphere row timed with a mesh contact row (same backend, variant, layout and integrator): the
/// mesh query's cost is quoted against the sphere's (at most 3x).
const Row* sphere_of(const std::vector<Row>& rows, const Row& r) {
  for (const Row& e : rows)
    if (e.scene == "contact" && e.contact == "sphere" && e.backend == r.backend && e.variant == r.variant &&
        e.layout == r.layout && e.integrator == r.integrator)
      return &e;
  return nullptr;
}

/// The lines above the table: the scene, the ceilings, the Vulkan device and each family of rows.
void print_preamble(const BenchRun& run) {
  const BenchOptions& o = run.o;
  fmt::print(
      "vkcloth bench: hanging cloth n x n (3 spring kinds, 2 pins, wind), {}, dt {:g} s, {} steps x {} reps "
      "(median), warm-up {}\n",
      o.integrator, run.dt, o.steps, o.reps, o.warmup);
  fmt::print("ceilings: memory {:g} GB/s, compute {:g} GFLOP/s (--memory-gbps, --compute-gflops)\n",
             o.memory_gbps, o.compute_gflops);
  if (run.ctx)
    fmt::print("vulkan device: {}\nvulkan layout: {} (the device's choice: {})\n", run.ctx->device_name(),
               o.layout, run.device_layout->reason);
  if (!run.vulkan_note.empty())
    fmt::print("vulkan: skipped ({})\n", run.vulkan_note);
  if (o.instances > 1)
    fmt::print("batched / unbatched rows: {} cloths of n x n in one ClothWorld (particles = all of them)\n",
               o.instances);
  if (!o.mesh.empty())
    fmt::print("mesh rows: {} (n column: the particle order: meshopt, file or shuffled)\n", o.mesh);
  if (!o.stretch.empty())
    fmt::print(
        "stretch rows: n x n with stretch_limit {{method: {}, max_strain: 0.1, iterations: 4}} (n column: "
        "n+{})\n",
        o.stretch, o.stretch);
  if (!o.contact.empty())
    fmt::print(
        "contact rows: n+table: 256 x 256 cloth draped on a box (0.5 x 1.2 x 0.2 m) on the floor plane; "
        "n+mesh: 64 x 64 cloth draped on a {}-triangle geodesic sphere (mesh collider); n+sphere: the same "
        "cloth on a sphere collider of the same size; friction "
        "{:g}; no wind; n free: the same cloth without colliders (n column)\n",
        20 * sphere_frequency * sphere_frequency, contact_friction);
  if (o.self_collision)
    fmt::print(
        "self-collision rows: n+self: the n x n cloth folded into {} layers on the floor plane "
        "(friction {:g}), "
        "self_collision {{thickness: {:g} x the spacing, friction: {:g}, iterations: {}, skin: {:g} x the "
        "thickness, stiffness: {:g} N/m}}; no wind; n-self: the same cloth with self-collision off (n "
        "column)\n",
        self_layers, contact_friction, self_thickness_over_spacing, self_friction, self_iterations,
        o.self_skin, o.self_stiffness);
}

/// What a row's median wall time comes to: ms per step, particle-steps per second, GB/s and GFLOP/s
/// by the cost model, and GPU ms per step (-1: none).
struct Rates {
  double ms_step, rate, gbps, gflops, gpu_step;
};

Rates rates_of(const Row& r) {
  const double ms_step = r.wall_ms / double(r.steps);
  const double rate = double(r.particles) * double(r.steps) / (r.wall_ms * 1e-3);
  const double gbps = rate * r.cost.bytes * 1e-9;
  const double gflops = rate * r.cost.flops * 1e-9;
  const double gpu_step = r.gpu_ms >= 0 ? r.gpu_ms / double(r.steps) : -1.0;
  return {ms_step, rate, gbps, gflops, gpu_step};
}

/// The table: its column header and a line a row.
void print_table(const std::vector<Row>& rows, const BenchOptions& o) {
  fmt::print("{:<7} {:<9} {:<11} {:>8} {:>8} {:>3} {:>9} {:>9} {:>9} {:>6} {:>7} {:>5} {:>6} {:>8} {:>5}\n",
             "backend", "variant", "layout", "n", "particles", "thr", "ms/step", "gpu ms", "M p-st/s",
             "B/p-st", "GB/s", "%mem", "fl/pst", "GFLOP/s", "%cmp");
  for (const Row& r : rows) {
    const auto [ms_step, rate, gbps, gflops, gpu_step] = rates_of(r);
    fmt::print(
        "{:<7} {:<9} {:<11} {:>8} {:>8} {:>3} {:>9.4f} {:>9} {:>9.1f} {:>6.0f} {:>7.2f} {:>4.0f}% {:>6.0f} "
        "{:>8.2f} {:>4.1f}%\n",
        r.backend, r.variant, r.layout.empty() ? "-" : fmt::format("{}/{}", r.layout, r.workgroup),
        r.scene == "grid"                  ? fmt::format("{}", r.size)
        : r.scene == "stretch"             ? fmt::format("{}+{}", r.size, r.order)
        : r.scene == "contact"             ? fmt::format("{}+{}", r.size, r.contact)
        : r.scene == "contact_free"        ? fmt::format("{} free", r.size)
        : r.scene == "self_collision"      ? fmt::format("{}+self", r.size)
        : r.scene == "self_collision_free" ? fmt::format("{}-self", r.size)
                                           : r.order,
        r.particles, r.backend == "cpu" ? fmt::format("{}", r.threads) : "-", ms_step,
        gpu_step >= 0 ? fmt::format("{:.4f}", gpu_step) : "-", rate * 1e-6, r.cost.bytes, gbps,
        100.0 * gbps / o.memory_gbps, r.cost.flops, gflops, 100.0 * gflops / o.compute_gflops);
  }
}

/// A row's JSON keys of its scene: a mesh row's, a stretch row's, a contact row's, a self-collision
/// row's (each with the ratio to the row it is quoted against).
void add_scene_keys(nlohmann::json& j, const std::vector<Row>& rows, const Row& r) {
  if (r.scene == "mesh") {
    j["order"] = r.order;
    j["mesh_over_grid"] = mesh_over_grid(r);
    j["grid_size_alternated"] = r.partner_size;
    j["grid_ms_per_step_alternated"] = r.partner_ms / double(r.steps);
  }
  if (r.scene == "stretch") {
    j["stretch_method"] = r.order;
    if (const Row* g = nearest_grid(rows, r))
      j["stretch_over_plain"] = per_particle_step(r) / per_particle_step(*g);
  }
  if (r.scene == "contact" || r.scene == "contact_free") {
    j["contact"] = r.contact;
    if (r.scene == "contact") {
      j["colliders"] = r.colliders;
      j["collider_triangles"] =
          r.collider_triangles ? nlohmann::json(r.collider_triangles) : nlohmann::json(nullptr);
      j["friction"] = contact_friction;
      j["particles_in_contact_start"] = r.in_contact_start;
      j["particles_in_contact_end"] = r.in_contact_end;
      if (const Row* f = contact_free_of(rows, r))
        j["contact_phase_fraction"] = (r.wall_ms - f->wall_ms) / f->wall_ms;
      // The mesh query against the sphere's (null where either phase did not come out positive).
      const Row* sphere = r.contact == "mesh" ? sphere_of(rows, r) : nullptr;
      if (sphere)
        j["contact_phase_over_sphere"] =
            contact_phase_ms(rows, *sphere) > 0.0 && contact_phase_ms(rows, r) >= 0.0
                ? nlohmann::json(contact_phase_ms(rows, r) / contact_phase_ms(rows, *sphere))
                : nlohmann::json(nullptr);
    }
  }
  if (is_self(r)) {
    j["self_collision_thickness"] = r.self_thickness;
    j["self_collision_friction"] = self_friction;
    j["self_collision_iterations"] = self_iterations;
    j["self_collision_skin"] = r.self_skin;
    j["self_collision_stiffness"] = r.self_stiffness;
    if (r.scene == "self_collision") {
      j["particles_in_self_contact_start"] = r.in_contact_start;
      j["particles_in_self_contact_end"] = r.in_contact_end;
      j["self_contact_pairs_end"] = r.self_pairs_end;
      if (const Row* f = self_free_of(rows, r)) {
        j["self_collision_ratio"] = r.wall_ms / f->wall_ms;
        j["self_collision_us_per_particle"] =
            1e3 * (r.wall_ms / double(r.steps) - f->wall_ms / double(f->steps)) / double(r.particles);
      }
    }
  }
}

/// A row of --json's results.
nlohmann::json row_json(const std::vector<Row>& rows, const Row& r, const BenchOptions& o) {
  const auto [ms_step, rate, gbps, gflops, gpu_step] = rates_of(r);
  nlohmann::json j;
  j["backend"] = r.backend;
  j["variant"] = r.variant;
  j["layout"] = r.layout.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.layout);
  j["workgroup_size"] = r.layout.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.workgroup);
  j["integrator"] = r.integrator;
  if (r.integrator == "implicit_euler") {
    j["cg_iterations_last_step"] = r.cg_iterations;
    j["cg_iterations_per_step"] = r.cg_per_step;
    if (!r.cg_dispatch.empty())
      j["cg_dispatch"] = r.cg_dispatch;
    for (const Row& e : rows) // the semi-implicit baseline of the same backend and size
      if (e.backend == r.backend && e.size == r.size && e.integrator == "semi_implicit_euler" &&
          r.contact.empty() && e.contact.empty() && !is_self(r) && !is_self(e))
        j["implicit_over_explicit"] = r.wall_ms / e.wall_ms;
  }
  if (r.integrator == "vbd") {
    j["vbd_sweeps_per_step"] = r.vbd_sweeps;
    j["ns_per_particle_sweep"] = 1e6 * r.wall_ms / (double(r.steps) * double(r.particles) * r.vbd_sweeps);
  }
  j["size"] = r.size;
  j["scene"] = r.scene;
  add_scene_keys(j, rows, r);
  j["instances"] = r.instances;
  j["particles"] = r.particles;
  j["springs"] = r.springs;
  j["threads"] = r.backend == "cpu" ? nlohmann::json(r.threads) : nlohmann::json(nullptr);
  j["steps"] = r.steps;
  j["reps"] = r.reps;
  j["wall_ms"] = r.wall_ms;
  j["gpu_ms"] = r.gpu_ms >= 0 ? nlohmann::json(r.gpu_ms) : nlohmann::json(nullptr);
  j["ms_per_step"] = ms_step;
  j["gpu_ms_per_step"] = gpu_step >= 0 ? nlohmann::json(gpu_step) : nlohmann::json(nullptr);
  j["particle_steps_per_s"] = rate;
  j["bytes_per_particle_step"] = r.cost.bytes;
  j["flops_per_particle_step"] = r.cost.flops;
  j["achieved_gbps"] = gbps;
  j["memory_fraction"] = gbps / o.memory_gbps;
  j["achieved_gflops"] = gflops;
  j["compute_fraction"] = gflops / o.compute_gflops;
  return j;
}

/// The lines under the table: each ratio in words (implicit over explicit, mesh over grid, stretch
/// control, the contact phase).
void print_ratios(const std::vector<Row>& rows) {
  for (const Row& r : rows)
    if (r.integrator == "implicit_euler" && r.contact.empty() && !is_self(r))
      for (const Row& e : rows)
        if (e.backend == r.backend && e.size == r.size && e.integrator == "semi_implicit_euler" &&
            e.contact.empty() && !is_self(e))
          fmt::print(
              "{}{} n = {}: implicit step {:.4f} ms vs semi-implicit {:.4f} ms: {:.1f}x the explicit cost "
              "({:.1f} CG iterations per step, {} in the last step)\n",
              r.backend, r.cg_dispatch.empty() ? "" : " (" + r.cg_dispatch + ")", r.size,
              r.wall_ms / double(r.steps), e.wall_ms / double(e.steps), r.wall_ms / e.wall_ms, r.cg_per_step,
              r.cg_iterations);
  for (const Row& r : rows)
    if (r.integrator == "vbd") {
      fmt::print("{} {} n = {}: vbd {:.4f} ms per step, {} sweeps per step: {:.1f} ns per particle-sweep",
                 r.backend, r.variant, r.size, r.wall_ms / double(r.steps), r.vbd_sweeps,
                 1e6 * r.wall_ms / (double(r.steps) * double(r.particles) * r.vbd_sweeps));
      for (const Row& e : rows)
        if (e.backend == r.backend && e.size == r.size && e.integrator == "implicit_euler" &&
            e.scene == r.scene)
          fmt::print("; CG {:.4f} ms per step ({:.1f} iterations per step): vbd {:.2f}x its cost",
                     e.wall_ms / double(e.steps), e.cg_per_step, r.wall_ms / e.wall_ms);
      fmt::print("\n");
    }
  for (const Row& r : rows)
    if (r.scene == "mesh")
      fmt::print(
          "{} {} mesh ({} order, {} particles): {:.2f}x the cost per particle-step of the {} x {} grid "
          "timed in alternation with it ({:.4f} vs {:.4f} ms per step)\n",
          r.backend, r.variant, r.order, r.particles, mesh_over_grid(r), r.partner_size, r.partner_size,
          r.wall_ms / double(r.steps), r.partner_ms / double(r.steps));
  for (const Row& r : rows)
    if (const Row* g = r.scene == "stretch" ? nearest_grid(rows, r) : nullptr)
      fmt::print(
          "{} {} n = {}: stretch control ({}, 4 sweeps) costs {:.0f} % of the plain step ({:.4f} vs {:.4f} "
          "ms)\n",
          r.backend, r.variant, r.size, r.order, 100.0 * (per_particle_step(r) / per_particle_step(*g) - 1.0),
          r.wall_ms / double(r.steps), g->wall_ms / double(g->steps));
  for (const Row& r : rows)
    if (const Row* f = r.scene == "contact" ? contact_free_of(rows, r) : nullptr)
      fmt::print(
          "{} {} {} ({} x {}): the contact phase costs {:.0f} % of the step without colliders ({:.4f} vs "
          "{:.4f} ms); {} of {} particles within 2 eps of a collider before the timed steps, {} after\n",
          r.backend, r.variant, r.contact, r.size, r.size, 100.0 * (r.wall_ms - f->wall_ms) / f->wall_ms,
          r.wall_ms / double(r.steps), f->wall_ms / double(f->steps), r.in_contact_start, r.particles,
          r.in_contact_end);
  for (const Row& r : rows)
    if (const Row* sphere = r.scene == "contact" && r.contact == "mesh" ? sphere_of(rows, r) : nullptr)
      if (contact_phase_ms(rows, *sphere) > 0.0 && contact_phase_ms(rows, r) >= 0.0)
        fmt::print("{} {} mesh (64 x 64): its contact phase is {:.2f}x the sphere's ({:.4f} vs {:.4f} ms per "
                   "step)\n",
                   r.backend, r.variant, contact_phase_ms(rows, r) / contact_phase_ms(rows, *sphere),
                   contact_phase_ms(rows, r), contact_phase_ms(rows, *sphere));
}

/// The self-collision rows on against off, a table of their own (none without them).
void print_self_table(const std::vector<Row>& rows) {
  bool self_header = false;
  for (const Row& r : rows)
    if (const Row* f = r.scene == "self_collision" ? self_free_of(rows, r) : nullptr) {
      if (!self_header) {
        fmt::print("self-collision on vs off, alternated (ms per step, wall; us/particle: (on - off) per "
                   "step / particles; in self-contact: particles after the warm-up / after the timed steps; "
                   "pairs: in self-contact after the timed steps)\n");
        fmt::print("{:<7} {:<9} {:<11} {:>5} {:>9} {:>10} {:>10} {:>8} {:>11} {:>17} {:>8}\n", "backend",
                   "variant", "layout", "n", "particles", "off ms", "on ms", "on/off", "us/particle",
                   "in self-contact", "pairs");
        self_header = true;
      }
      const double on = r.wall_ms / double(r.steps), off = f->wall_ms / double(f->steps);
      fmt::print("{:<7} {:<9} {:<11} {:>5} {:>9} {:>10.4f} {:>10.4f} {:>7.2f}x {:>11.4f} {:>17} {:>8}\n",
                 r.backend, r.variant, r.layout.empty() ? "-" : fmt::format("{}/{}", r.layout, r.workgroup),
                 r.size, r.particles, off, on, r.wall_ms / f->wall_ms, 1e3 * (on - off) / double(r.particles),
                 fmt::format("{} / {}", r.in_contact_start, r.in_contact_end), r.self_pairs_end);
    }
}

/// Writes --json: the run's parameters and the rows (keys: docs/performance.md).
int write_json(const BenchRun& run) {
  const BenchOptions& o = run.o;
  nlohmann::json results = nlohmann::json::array();
  for (const Row& r : run.rows)
    results.push_back(row_json(run.rows, r, o));
  nlohmann::json doc;
  doc["schema"] = "vkcloth-bench/1";
  doc["scene"] = "hanging_cloth";
  doc["mesh"] = o.mesh.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.mesh);
  doc["integrator"] = o.integrator;
  doc["dt"] = run.dt;
  doc["stiffness"] = o.stiffness.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.stiffness);
  doc["cloth_mass"] = o.cloth_mass ? nlohmann::json(*o.cloth_mass) : nlohmann::json(nullptr);
  doc["wind"] = o.wind;
  doc["contact"] = o.contact.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.contact);
  doc["self_collision"] = o.self_collision;
  doc["steps"] = o.steps;
  doc["warmup"] = o.warmup;
  doc["reps"] = o.reps;
  doc["steps_per_submit"] = o.steps_per_submit;
  doc["ceilings"] = {{"memory_gbps", o.memory_gbps}, {"compute_gflops", o.compute_gflops}};
  doc["host_threads"] = std::thread::hardware_concurrency();
  doc["vulkan_device"] = run.ctx ? nlohmann::json(run.ctx->device_name()) : nlohmann::json(nullptr);
  const std::optional<gpu::DeviceLayout>& device_layout = run.device_layout;
  doc["vulkan_layout"] = device_layout ? nlohmann::json{{"access", gpu::to_string(device_layout->access)},
                                                        {"workgroup_size", device_layout->workgroup_size},
                                                        {"subgroup_size", device_layout->subgroup_size},
                                                        {"reason", device_layout->reason}}
                                       : nlohmann::json(nullptr);
  doc["vulkan_skipped"] = run.vulkan_note.empty() ? nlohmann::json(nullptr) : nlohmann::json(run.vulkan_note);
  doc["results"] = std::move(results);
  std::ofstream f(o.json);
  f << doc.dump(2) << "\n";
  if (!f)
    return report(make_error(ErrorCode::io, fmt::format("--json: cannot write '{}'", o.json)));
  return exit_ok;
}

} // namespace

int print_report(const BenchRun& run) {
  // Table for people.
  print_preamble(run);
  print_table(run.rows, run.o);
  print_ratios(run.rows);
  print_self_table(run.rows);
  if (!run.o.json.empty())
    return write_json(run);
  return exit_ok;
}

} // namespace vkcloth::cli::bench
