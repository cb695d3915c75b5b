// SPDX-License-Identifier: MIT
// `vkcloth bench`: throughput of the solvers on the report's hanging cloth (structural, shear and
// bend springs, two pinned corners, wind) at several grid sizes, against this machine's memory
// and compute ceilings. Bytes and flops per particle-step are counted from the kernels (the
// counting is documented in docs/performance.md). A table for people, --json for tools.
// This file: the flags, their checks and the order of the rows; the rest is named in bench.hpp.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "../commands.hpp"
#include "bench.hpp"
#include "vkcloth/gpu/layout.hpp"
#include "vkcloth/mesh.hpp"
#include "vkcloth/topology.hpp"

namespace vkcloth::cli {
namespace bench {
namespace {

Result<std::vector<std::uint32_t>> parse_sizes(const std::string& text) {
  std::vector<std::uint32_t> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    unsigned long v = 0;
    try {
      v = std::stoul(item, &used);
    } catch (...) {
      used = 0;
    }
    if (used != item.size() || v < 2 || v > max_cloth_side)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("--sizes: '{}' is not a grid side in 2..{}", item, max_cloth_side));
    out.push_back(static_cast<std::uint32_t>(v));
  }
  if (out.empty())
    return make_error(ErrorCode::invalid_argument, "--sizes: give at least one size, e.g. 64,256");
  return out;
}

/// Checks the options that CLI11 cannot and parses --integrator and --sizes into `run`.
int check_options(BenchRun& run) {
  const BenchOptions& o = run.o;
  if (o.backend != "cpu" && o.backend != "vulkan" && o.backend != "all")
    return report(make_error(ErrorCode::invalid_argument,
                             fmt::format("--backend must be cpu, vulkan or all, got '{}'", o.backend)));
  const auto integrator = parse_integrator(o.integrator);
  if (!integrator)
    return report(make_error(
        ErrorCode::invalid_argument,
        fmt::format(
            "--integrator must be explicit_euler, semi_implicit_euler, rk4, implicit_euler or vbd, got '{}'",
            o.integrator)));
  run.integrator = *integrator;
  auto sizes = parse_sizes(o.sizes);
  if (!sizes)
    return report(sizes.error());
  run.sizes = std::move(*sizes);
  if (o.steps == 0 || o.reps == 0 || o.steps_per_submit == 0)
    return report(
        make_error(ErrorCode::invalid_argument, "--steps, --reps and --steps-per-submit must be > 0"));
  if (o.instances == 0 || o.instances > 4096)
    return report(make_error(ErrorCode::invalid_argument,
                             fmt::format("--instances must be in 1..4096, got {}", o.instances)));
  if (!(o.memory_gbps > 0) || !(o.compute_gflops > 0))
    return report(make_error(ErrorCode::invalid_argument, "--memory-gbps and --compute-gflops must be > 0"));
  run.dt = o.dt.value_or(5e-4);
  return exit_ok;
}

/// Opens the Vulkan device (unless --backend cpu; with all, a missing one is a note) and parses
/// --layout.
int open_vulkan(BenchRun& run) {
  const BenchOptions& o = run.o;
  if (o.backend != "cpu") {
    auto c = gpu::Context::create();
    if (c)
      run.ctx.emplace(std::move(*c));
    else if (o.backend == "vulkan")
      return report(c.error());
    else
      run.vulkan_note = c.error().message;
  }

  std::stringstream ss(o.layout);
  std::string item;
  while (std::getline(ss, item, ','))
    if (auto a = gpu::parse_buffer_access(item))
      run.layouts.push_back(*a);
    else
      return report(make_error(ErrorCode::invalid_argument,
                               fmt::format("--layout: '{}' is not auto, texel or storage", item)));
  if (run.layouts.empty())
    return report(make_error(ErrorCode::invalid_argument, "--layout: give auto, texel, storage or a list"));
  if (run.ctx)
    run.device_layout = gpu::device_layout(*run.ctx);
  return exit_ok;
}

/// time_scene's Vulkan rows: each variant asked for on each --layout, then the ClothWorld batches;
/// `add(row)` adds a row (or a note).
template <typename Add>
int time_scene_vulkan(BenchRun& run, const BenchScene& sc, std::uint32_t n, const std::string& scene,
                      std::optional<Partner> partner, Add add) {
  const BenchOptions& o = run.o;
  gpu::Context& ctx = *run.ctx;
  const bool fused = o.variants.find("fused") != std::string::npos;
  const bool two_pass = o.variants.find("two_pass") != std::string::npos;
  const bool rk4 = sc.params.integrator == Integrator::rk4;
  const bool imp = sc.params.integrator == Integrator::implicit_euler;
  const bool vbd = sc.params.integrator == Integrator::vbd; // one variant: the vbd pass
  // Each variant once per --layout entry, back to back (alternated: a machine whose speed drifts
  // during the run affects both layouts alike). Implicit with --cg-dispatch other than auto: the
  // CG loop's two dispatch layouts, forced.
  using D = gpu::GpuSolverOptions::CgDispatch;
  if (fused || rk4 || imp || vbd)
    for (gpu::BufferAccess access : run.layouts) {
      if (imp && o.cg_dispatch != "auto") {
        for (const char* name : {"one_workgroup", "per_iteration"})
          if (o.cg_dispatch == name || o.cg_dispatch == "both")
            if (int e = add(
                    bench_vulkan(ctx, sc, n, true, access, o,
                                 std::string(name) == "one_workgroup" ? D::one_workgroup : D::per_iteration)))
              return e;
        continue;
      }
      if (int e = add(bench_vulkan(ctx, sc, n, true, access, o, D::automatic, partner)))
        return e;
    }
  if (two_pass && !rk4 && !imp && !vbd)
    for (gpu::BufferAccess access : run.layouts)
      if (int e = add(bench_vulkan(ctx, sc, n, false, access, o, D::automatic, partner)))
        return e;
  if (o.instances > 1 && scene == "grid") { // many cloths: one batch vs one dispatch chain per cloth
    for (gpu::BufferAccess access : run.layouts) {
      if (int e = add(bench_world(ctx, sc, n, true, access, o)))
        return e;
      if (int e = add(bench_world(ctx, sc, n, false, access, o)))
        return e;
    }
  }
  return exit_ok;
}

/// Times one scene on the chosen backends (CPU; Vulkan fused / two-pass; ClothWorld batches).
int time_scene(BenchRun& run, const BenchScene& sc, std::uint32_t n, const std::string& scene,
               const std::string& order, std::optional<Partner> partner = std::nullopt) {
  const BenchOptions& o = run.o;
  const bool implicit = run.integrator == Integrator::implicit_euler;
  const double s = double(sc.system.adjacency.refs.size()) / double(sc.system.size());
  double fans = 0.0;
  if (sc.system.surface) {
    auto t = ClothTopology::create(sc.system);
    if (!t)
      return report(t.error());
    fans = double((*t)->fans().size()) / double(sc.system.size());
  }
  auto add = [&](Result<Row> r) -> int {
    const bool baseline = implicit && sc.params.integrator != Integrator::implicit_euler;
    if (!r && (r.error().code == ErrorCode::unsupported || // too large for this device: note it, go on
               (baseline && r.error().code == ErrorCode::diverged))) { // the explicit baseline at a stiff dt
      fmt::print("note: {} n = {} ({}): {}\n", scene, n, to_string(sc.params.integrator), r.error().message);
      return exit_ok;
    }
    if (!r)
      return report(r.error());
    r->particles = sc.system.size() * r->instances;
    r->springs = sc.system.springs.size();
    r->steps = o.steps;
    r->reps = o.reps;
    r->scene = scene;
    r->order = order;
    if (sc.params.integrator == Integrator::vbd)
      r->vbd_sweeps = sc.params.vbd_iterations * sc.params.substeps;
    r->cost = cost_of(r->variant, sc.params.integrator, s, scene != "mesh", fans, true, o.steps_per_submit,
                      r->vbd_sweeps);
    run.rows.push_back(*r);
    return exit_ok;
  };
  if (o.backend != "vulkan")
    if (int e = add(bench_cpu(sc, n, o, partner)))
      return e;
  if (!run.ctx)
    return exit_ok;
  return time_scene_vulkan(run, sc, n, scene, partner, add);
}

/// Each --sizes grid; with --stretch, the same grid with stretch control; with implicit_euler, the
/// explicit baseline.
int grid_rows(BenchRun& run) {
  const BenchOptions& o = run.o;
  const bool implicit = run.integrator == Integrator::implicit_euler;
  for (std::uint32_t n : run.sizes) {
    auto sc = bench_scene(n, run.integrator, run.dt, o);
    if (!sc)
      return report(sc.error());
    if (int e = time_scene(run, *sc, n, "grid", ""))
      return e;
    if (!o.stretch.empty()) { // the same grid with stretch control, for its cost ratio
      auto limited = bench_scene(n, run.integrator, run.dt, o);
      if (!limited)
        return report(limited.error());
      const bool chains = o.stretch == "chains"; // Provot's sweeps in chain order
      limited->params.stretch_limit.method =
          chains ? StretchLimit::Method::provot : *parse_stretch_method(o.stretch);
      limited->params.stretch_limit.order =
          chains ? StretchLimit::SweepOrder::chains : StretchLimit::SweepOrder::colours;
      if (int e = time_scene(run, *limited, n, "stretch", o.stretch))
        return e;
    }
    if (implicit) { // the explicit baseline at the same size and dt, for the cost ratio
      auto base = bench_scene(n, Integrator::semi_implicit_euler, run.dt, o);
      if (!base)
        return report(base.error());
      if (int e = time_scene(run, *base, n, "grid", ""))
        return e;
    }
    // Implicit Euler by CG beside vbd at the same size and dt, up to 256 x 256 (beyond, CG's hundreds
    // of iterations per step would take the bench's whole time).
    if (run.integrator == Integrator::vbd && n <= 256) {
      auto cg = bench_scene(n, Integrator::implicit_euler, run.dt, o);
      if (!cg)
        return report(cg.error());
      if (int e = time_scene(run, *cg, n, "grid", ""))
        return e;
    }
  }
  return exit_ok;
}

/// --mesh: the mesh's cloth in each particle order.
int mesh_rows(BenchRun& run) {
  const BenchOptions& o = run.o;
  if (o.mesh.empty())
    return exit_ok;
  auto mesh = read_mesh(o.mesh);
  if (!mesh)
    return report(mesh.error());
  // Each order timed in alternation with the grid of --sizes nearest its particle count.
  std::optional<BenchScene> grid;
  std::uint32_t side = 0;
  for (const char* order : {"meshopt", "file", "shuffled"}) {
    auto sc = mesh_bench_scene(*mesh, order, run.integrator, run.dt);
    if (!sc)
      return report(sc.error());
    if (!grid) {
      const double root = std::sqrt(double(sc->system.size()));
      side = *std::min_element(run.sizes.begin(), run.sizes.end(), [&](std::uint32_t a, std::uint32_t b) {
        return std::abs(double(a) - root) < std::abs(double(b) - root);
      });
      auto g = bench_scene(side, run.integrator, run.dt, o);
      if (!g)
        return report(g.error());
      grid.emplace(std::move(*g));
    }
    if (int e = time_scene(run, *sc, 0, "mesh", order, Partner{*grid, side}))
      return e;
  }
  return exit_ok;
}

/// A scene timed on against off in pairs (cpu(): the CPU; vulkan(fused, access): each Vulkan
/// variant and layout asked for); tag(row) adds the scene's own fields. A device too small for it
/// is a note naming `what`.
template <typename Cpu, typename Vulkan, typename Tag>
int time_pairs(BenchRun& run, const std::string& what, const ParticleSystem& system, const SimParams& params,
               std::uint32_t size, Cpu cpu, Vulkan vulkan, Tag tag) {
  const BenchOptions& o = run.o;
  const double s = double(system.adjacency.refs.size()) / double(system.size());
  auto add = [&](Result<std::array<Row, 2>> pair) -> int {
    if (!pair && pair.error().code == ErrorCode::unsupported) { // too large for this device
      fmt::print("note: {} ({}): {}\n", what, to_string(params.integrator), pair.error().message);
      return exit_ok;
    }
    if (!pair)
      return report(pair.error());
    for (Row& r : *pair) {
      r.integrator = to_string(params.integrator);
      r.size = size;
      r.particles = system.size();
      r.springs = system.springs.size();
      r.steps = o.steps;
      r.reps = o.reps;
      tag(r);
      r.cost = cost_of(r.variant, params.integrator, s, true, 0.0, false, o.steps_per_submit);
      run.rows.push_back(r);
    }
    return exit_ok;
  };
  if (o.backend != "vulkan")
    if (int e = add(cpu()))
      return e;
  if (!run.ctx)
    return exit_ok;
  const bool rk4 = run.integrator == Integrator::rk4;
  const bool imp = run.integrator == Integrator::implicit_euler;
  if (o.variants.find("fused") != std::string::npos || rk4 || imp)
    for (gpu::BufferAccess access : run.layouts)
      if (int e = add(vulkan(true, access)))
        return e;
  if (o.variants.find("two_pass") != std::string::npos && !rk4 && !imp)
    for (gpu::BufferAccess access : run.layouts)
      if (int e = add(vulkan(false, access)))
        return e;
  return exit_ok;
}

/// --contact: the contact scenes, each timed against the same cloth without colliders.
int contact_rows(BenchRun& run) {
  const BenchOptions& o = run.o;
  if (o.contact.empty())
    return exit_ok;
  for (const std::string name : {"table", "mesh", "sphere"}) {
    const std::string group = name == "sphere" ? "mesh" : name; // the mesh row's yardstick comes with it
    if (o.contact != group && o.contact != "both")
      continue;
    auto sc = name == "table" ? table_scene(run.integrator, run.dt, o)
                              : mesh_scene(run.integrator, run.dt, o, name == "sphere");
    if (!sc)
      return report(sc.error());
    if (int e = time_pairs(
            run, "contact " + name, sc->system, sc->params, sc->n, [&] { return bench_cpu_contact(*sc, o); },
            [&](bool fused, gpu::BufferAccess access) {
              return bench_vulkan_contact(*run.ctx, *sc, fused, access, o);
            },
            [&](Row& r) {
              r.contact = name;
              if (r.scene == "contact") {
                r.colliders = sc->kinds;
                r.collider_triangles = sc->triangles;
              }
            }))
      return e;
  }
  return exit_ok;
}

/// --self-collision: each size folded on the floor, self-collision on vs off.
int self_collision_rows(BenchRun& run) {
  const BenchOptions& o = run.o;
  if (!o.self_collision)
    return exit_ok;
  for (std::uint32_t n : run.sizes) {
    if (n < self_min_size) {
      fmt::print("note: self_collision n = {}: the folded cloth needs n >= {}; left out\n", n, self_min_size);
      continue;
    }
    auto sc = folded_scene(n, run.integrator, run.dt, o);
    if (!sc)
      return report(sc.error());
    if (int e = time_pairs(
            run, fmt::format("self_collision n = {}", n), sc->system, sc->params, n,
            [&] { return bench_cpu_self(*sc, o); },
            [&](bool fused, gpu::BufferAccess access) {
              return bench_vulkan_self(*run.ctx, *sc, fused, access, o);
            },
            [&](Row& r) {
              r.self_thickness = sc->params.self_collision.thickness;
              r.self_skin = sc->params.self_collision.skin;
              r.self_stiffness = sc->params.self_collision.stiffness;
              if (sc->params.integrator == Integrator::vbd) // the per-sweep figures (print_ratios, JSON)
                r.vbd_sweeps = sc->params.vbd_iterations * sc->params.substeps;
            }))
      return e;
  }
  return exit_ok;
}

int bench_command(const BenchOptions& o) {
  BenchRun run(o);
  if (int e = check_options(run))
    return e;
  if (int e = open_vulkan(run))
    return e;
  if (int e = grid_rows(run))
    return e;
  if (int e = mesh_rows(run))
    return e;
  if (int e = contact_rows(run))
    return e;
  if (int e = self_collision_rows(run))
    return e;
  return print_report(run);
}

} // namespace
} // namespace bench

void add_bench_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<bench::BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Throughput of the solvers on the hanging cloth at several sizes, against the memory and compute "
      "ceilings (docs/performance.md)");
  cmd->add_option("--backend", opt->backend,
                  "cpu | vulkan | all (all: Vulkan is skipped with a note if no device)")
      ->capture_default_str();
  cmd->add_option("--sizes", opt->sizes, "Comma-separated grid sides n (n x n particles)")
      ->capture_default_str();
  cmd->add_option("--steps", opt->steps, "Timed steps per repetition")->capture_default_str();
  cmd->add_option("--warmup", opt->warmup, "Untimed steps before the first repetition")
      ->capture_default_str();
  cmd->add_option("--reps", opt->reps, "Repetitions; the median is reported")->capture_default_str();
  cmd->add_option("--integrator", opt->integrator,
                  "explicit_euler | semi_implicit_euler | rk4 | implicit_euler (adds a semi-implicit "
                  "baseline row and the cost ratio) | vbd (adds implicit Euler by CG beside it; ns per "
                  "particle-sweep)")
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads, "CPU solver threads (0: the host's hardware threads)")
      ->capture_default_str();
  cmd->add_option("--steps-per-submit", opt->steps_per_submit, "Vulkan: steps recorded per command buffer")
      ->capture_default_str();
  cmd->add_option("--instances", opt->instances,
                  "Vulkan: also time this many cloths in one ClothWorld, batched (one dispatch per pass) and "
                  "unbatched (one per cloth)")
      ->capture_default_str();
  cmd->add_option("--dt", opt->dt, "Time step in seconds (default 5e-4, stable at every size)");
  cmd->add_option("--memory-gbps", opt->memory_gbps, "Memory bandwidth ceiling in GB/s")
      ->capture_default_str();
  cmd->add_option("--compute-gflops", opt->compute_gflops, "Compute ceiling in GFLOP/s")
      ->capture_default_str();
  cmd->add_option("--variants", opt->variants,
                  "Vulkan: fused | two_pass | fused,two_pass (semi-implicit and explicit Euler)")
      ->capture_default_str()
      ->check([](const std::string& v) {
        return v == "fused" || v == "two_pass" || v == "fused,two_pass" || v == "two_pass,fused"
                   ? std::string()
                   : std::string("expected fused, two_pass or fused,two_pass");
      });
  cmd->add_option(
         "--layout", opt->layout,
         "Vulkan: how the shaders read their buffers: auto (the device's choice), texel, storage, or "
         "a list (texel,storage: each Vulkan row once per entry, alternated)")
      ->capture_default_str();
  cmd->add_option("--workgroup", opt->workgroup,
                  "Vulkan: invocations per workgroup (0: the device's choice; implicit Euler: always 64)")
      ->capture_default_str();
  cmd->add_option("--mesh", opt->mesh,
                  "Also time the cloth made from this OBJ / glTF mesh, with its particles renumbered by "
                  "meshoptimizer, in the file's order and shuffled, against the grid of nearest size")
      ->check(CLI::ExistingFile);
  cmd->add_option(
         "--stretch", opt->stretch,
         "Also time each grid with stretch control (tethers, provot, both, projection, or chains: provot's "
         "sweeps in chain order; max_strain 0.1, 4 sweeps or Newton iterations) against the plain step")
      ->check(CLI::IsMember({"tethers", "provot", "both", "projection", "chains"}));
  cmd->add_option(
         "--contact", opt->contact,
         "Also time the contact scenes: a 256 x 256 cloth on a table (box on a floor plane), "
         "a 64 x 64 cloth on a ~10 000-triangle mesh sphere (and on a sphere collider of the same size, the "
         "mesh query's yardstick), or both; each against the same cloth without colliders, alternated")
      ->check(CLI::IsMember({"table", "mesh", "both"}));
  cmd->add_flag(
      "--self-collision", opt->self_collision,
      "Also time each size's cloth folded into 4 layers on the floor with self-collision on ("
      "thickness 1.5 x the grid spacing, friction 0.2, 1 iteration) against the same cloth with it off, "
      "alternated (n >= 16)");
  cmd->add_option("--self-skin", opt->self_skin,
                  "With --self-collision: keep neighbour lists with a skin of this many thicknesses, rebuilt "
                  "when a particle has moved half the skin (self_collision.skin; default 0: every pass walks "
                  "the cells)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option(
         "--self-stiffness", opt->self_stiffness,
         "With --self-collision, --integrator vbd and --self-skin: self-contact as an energy of this "
         "stiffness in the vertex steps (self_collision.stiffness, N/m; default 0: the passes after the "
         "step)")
      ->check(non_negative_number);
  cmd->add_option(
      "--stiffness", opt->stiffness,
      "Structural, shear and bend stiffness of the grid in N/m, e.g. 10000,2000,2000 (default 40,8,8)");
  cmd->add_option("--wind", opt->wind,
                  "Grid rows: the wind's acceleration of a particle facing it, in m/s^2 (0: no wind)")
      ->capture_default_str()
      ->check(non_negative_number);
  cmd->add_option("--cloth-mass", opt->cloth_mass,
                  "Mass of the whole grid in kg (default: 0.05 kg per particle of a 64 x 64 grid, 204.8 kg)")
      ->check(positive_number);
  cmd->add_option(
         "--cg-dispatch", opt->cg_dispatch,
         "implicit_euler on Vulkan: where the CG iterations run (auto: GpuSolverOptions' default; both: "
         "one row each)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "one_workgroup", "per_iteration", "both"}));
  cmd->add_option("--json", opt->json, "Also write the results as JSON to FILE (keys: docs/performance.md)");
  cmd->footer(exit_codes_footer);
  cmd->callback([opt, exit] { *exit = bench::bench_command(*opt); });
}

} // namespace vkcloth::cli
