// SPDX-License-Identifier: MIT
// `vkcloth bench`'s timing: each scene on the CPU solver, on Vulkan and in a ClothWorld, and the
// contact and self-collision scenes timed in alternation with the same cloth without them.
#include <algorithm>
#include <array>
#include <chrono>
#include <optional>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "bench.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/layout.hpp"
#include "vkcloth/gpu/world.hpp"

namespace vkcloth::cli::bench {
namespace {

/// Mean CG iterations per solve between two snapshots of a solver's statistics.
double cg_per_step(const SolveStats& before, const SolveStats& after) {
  const std::uint64_t solves = after.solves - before.solves;
  return solves ? double(after.total_iterations - before.total_iterations) / double(solves) : 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// `reps` repetitions of `steps` steps of `run(steps)`, each after one of `partner_run(steps)`
/// when given: the medians of the wall times (the partner's -1 without one). Every timed
/// alternation of the bench goes through here (mesh rows and their grid, alternate_contact).
template <typename Run, typename PartnerRun>
Result<std::pair<double, double>> timed_reps(const BenchOptions& o, Run run, PartnerRun* partner_run) {
  std::vector<double> wall, partner_wall;
  for (unsigned r = 0; r < o.reps; ++r) {
    if (partner_run) {
      const auto t0 = Clock::now();
      VKCLOTH_TRY((*partner_run)(o.steps));
      partner_wall.push_back(ms_since(t0));
    }
    const auto t0 = Clock::now();
    VKCLOTH_TRY(run(o.steps));
    wall.push_back(ms_since(t0));
  }
  return std::pair{median(wall), partner_run ? median(partner_wall) : -1.0};
}

} // namespace

Result<Row> bench_cpu(const BenchScene& sc, std::uint32_t n, const BenchOptions& o,
                      std::optional<Partner> partner) {
  CpuSolverOptions co;
  co.threads = o.threads;
  auto s = CpuSolver<float>::create(sc.system, sc.params, co);
  if (!s)
    return s.error();
  std::optional<CpuSolver<float>> grid;
  if (partner) {
    auto g = CpuSolver<float>::create(partner->scene.system, partner->scene.params, co);
    if (!g)
      return g.error();
    grid.emplace(std::move(*g));
    VKCLOTH_TRY(grid->run(o.warmup));
  }
  VKCLOTH_TRY(s->run(o.warmup));
  const SolveStats before = s->last_solve();
  auto grid_run = [&](std::uint64_t steps) { return grid->run(steps); };
  auto times = timed_reps(
      o, [&](std::uint64_t steps) { return s->run(steps); }, grid ? &grid_run : nullptr);
  if (!times)
    return times.error();
  Row row;
  row.backend = "cpu";
  row.variant = "cpu";
  row.integrator = to_string(sc.params.integrator);
  row.cg_iterations = s->last_solve().iterations;
  row.cg_per_step = cg_per_step(before, s->last_solve());
  row.threads = s->threads();
  row.size = n;
  row.wall_ms = times->first;
  row.partner_ms = times->second;
  row.partner_size = partner ? partner->size : 0;
  return row;
}

namespace {

/// The buffer access and workgroup size a solver created with `go` runs on `ctx` (DeviceLayout).
std::pair<std::string, std::uint32_t> layout_of(gpu::Context& ctx, const gpu::GpuSolverOptions& go,
                                                bool implicit) {
  const gpu::DeviceLayout d = gpu::device_layout(ctx);
  const gpu::BufferAccess a = go.buffer_access == gpu::BufferAccess::automatic ? d.access : go.buffer_access;
  if (implicit) // implicit.comp reads storage buffers in workgroups of 64 on every device
    return {gpu::to_string(gpu::BufferAccess::storage_buffers), 64u};
  return {gpu::to_string(a), go.workgroup_size ? go.workgroup_size : d.workgroup_size};
}

} // namespace

Result<Row> bench_vulkan(gpu::Context& ctx, const BenchScene& sc, std::uint32_t n, bool fused,
                         gpu::BufferAccess access, const BenchOptions& o,
                         gpu::GpuSolverOptions::CgDispatch cg, std::optional<Partner> partner) {
  gpu::GpuSolverOptions go;
  go.fused = fused;
  go.buffer_access = access;
  go.workgroup_size = o.workgroup;
  go.cg_dispatch = cg;
  auto s = gpu::GpuSolver::create(ctx, sc.system, sc.params, go);
  if (!s)
    return s.error();
  std::optional<gpu::GpuSolver> grid;
  if (partner) {
    auto g = gpu::GpuSolver::create(ctx, partner->scene.system, partner->scene.params, go);
    if (!g)
      return g.error();
    grid.emplace(std::move(*g));
    VKCLOTH_TRY(grid->simulate(o.warmup, o.steps_per_submit));
  }
  VKCLOTH_TRY(s->simulate(o.warmup, o.steps_per_submit));
  const SolveStats before = s->last_solve();
  std::vector<double> gpu_ms;
  auto grid_run = [&](std::uint64_t steps) { return grid->simulate(steps, o.steps_per_submit); };
  auto times = timed_reps(
      o,
      [&](std::uint64_t steps) -> Result<void> {
        VKCLOTH_TRY(s->simulate(steps, o.steps_per_submit));
        gpu_ms.push_back(s->last_gpu_ms());
        return {};
      },
      grid ? &grid_run : nullptr);
  if (!times)
    return times.error();
  Row row;
  row.backend = "vulkan";
  row.variant = sc.params.integrator == Integrator::implicit_euler ? "implicit"
                : sc.params.integrator == Integrator::vbd          ? "vbd"
                : fused && sc.params.integrator != Integrator::rk4 ? "fused"
                                                                   : "two_pass";
  row.integrator = to_string(sc.params.integrator);
  row.cg_iterations = s->last_solve().iterations;
  row.cg_per_step = cg_per_step(before, s->last_solve());
  if (sc.params.integrator == Integrator::implicit_euler)
    row.cg_dispatch = s->implicit_one_workgroup() ? "one_workgroup" : "per_iteration";
  row.size = n;
  row.wall_ms = times->first;
  row.partner_ms = times->second;
  row.partner_size = partner ? partner->size : 0;
  row.gpu_ms = median(gpu_ms);
  std::tie(row.layout, row.workgroup) =
      layout_of(ctx, go, sc.params.integrator == Integrator::implicit_euler);
  return row;
}

/// `instances` cloths of the scene in one ClothWorld, one submission per `steps_per_submit` steps:
/// batched (one shared topology: one dispatch per pass for all) or not (a topology prepared for
/// each: every cloth its own dispatches, as separate solvers recorded into one command buffer).
Result<Row> bench_world(gpu::Context& ctx, const BenchScene& sc, std::uint32_t n, bool batched,
                        gpu::BufferAccess access, const BenchOptions& o) {
  gpu::WorldOptions wo;
  wo.solver.buffer_access = access;
  wo.solver.workgroup_size = o.workgroup;
  auto w = gpu::ClothWorld::create(ctx, wo);
  if (!w)
    return w.error();
  auto shared = ClothTopology::create(sc.system);
  if (!shared)
    return shared.error();
  for (std::uint32_t k = 0; k < o.instances; ++k) {
    auto own = batched ? shared : ClothTopology::create(sc.system);
    if (!own)
      return own.error();
    VKCLOTH_TRY(w->add(*own, sc.params));
  }
  VKCLOTH_TRY(w->simulate(o.warmup, o.steps_per_submit));
  std::vector<double> wall;
  for (unsigned r = 0; r < o.reps; ++r) {
    const auto t0 = Clock::now();
    VKCLOTH_TRY(w->simulate(o.steps, o.steps_per_submit));
    wall.push_back(ms_since(t0));
  }
  Row row;
  row.backend = "vulkan";
  row.variant = batched ? "batched" : "unbatched";
  row.integrator = to_string(sc.params.integrator);
  row.size = n;
  row.instances = o.instances;
  row.wall_ms = median(wall);
  std::tie(row.layout, row.workgroup) =
      layout_of(ctx, wo.solver, sc.params.integrator == Integrator::implicit_euler);
  return row;
}

namespace {

/// The particles of `positions` (in float) in double, for particles_in_contact.
std::vector<glm::dvec3> to_double(std::span<const glm::vec3> positions) {
  return {positions.begin(), positions.end()};
}

/// Times a contact scene (k = 1) and the same cloth without colliders (k = 0), in alternation: both
/// warm up, then repetition r runs `steps` steps of the bare cloth, then `steps` of the cloth on
/// its colliders, so that a machine whose speed drifts (other jobs on its cores) slows both alike.
/// `run(k, steps)` advances solver k; `gpu_ms(k)` is its last GPU time (-1: none); `count()` the
/// particles in contact on solver 1 now. Returns the two rows (bare, then with colliders) with
/// their medians, their scenes named `scenes` (row 0, row 1).
template <typename Run, typename GpuMs, typename Count>
Result<std::array<Row, 2>> alternate_contact(const BenchOptions& o, Run run, GpuMs gpu_ms, Count count,
                                             std::array<const char*, 2> scenes = {"contact_free",
                                                                                  "contact"}) {
  for (int k = 0; k < 2; ++k)
    VKCLOTH_TRY(run(k, o.warmup));
  std::array<Row, 2> rows;
  auto start = count();
  if (!start)
    return start.error();
  std::array<std::vector<double>, 2> gpu;
  auto stepper = [&](int k) {
    return [&, k](std::uint64_t steps) -> Result<void> {
      VKCLOTH_TRY(run(k, steps));
      gpu[k].push_back(gpu_ms(k));
      return {};
    };
  };
  auto bare = stepper(0);
  auto times = timed_reps(o, stepper(1), &bare);
  if (!times)
    return times.error();
  auto end = count();
  if (!end)
    return end.error();
  rows[0].wall_ms = times->second;
  rows[1].wall_ms = times->first;
  for (int k = 0; k < 2; ++k) {
    rows[k].gpu_ms = median(gpu[k]);
    rows[k].scene = scenes[k];
  }
  rows[1].in_contact_start = *start;
  rows[1].in_contact_end = *end;
  return rows;
}

/// Times `system` with `bare` (row 0) and `full` (row 1) on the CPU, in alternation
/// (alternate_contact); `count(positions)` counts on the `full` solver.
template <typename Count>
Result<std::array<Row, 2>> bench_cpu_pair(const ParticleSystem& system, const SimParams& bare,
                                          const SimParams& full, const BenchOptions& o,
                                          std::array<const char*, 2> scenes, Count count) {
  CpuSolverOptions co;
  co.threads = o.threads;
  auto s0 = CpuSolver<float>::create(system, bare, co);
  if (!s0)
    return s0.error();
  auto s1 = CpuSolver<float>::create(system, full, co);
  if (!s1)
    return s1.error();
  std::array<CpuSolver<float>*, 2> s = {&*s0, &*s1};
  auto rows = alternate_contact(
      o, [&](int k, std::uint64_t steps) { return s[k]->run(steps); }, [](int) { return -1.0; },
      [&] { return count(s1->positions()); }, scenes);
  if (!rows)
    return rows.error();
  for (Row& r : *rows) {
    r.backend = "cpu";
    r.variant = "cpu";
    r.threads = s1->threads();
  }
  return rows;
}

/// The same on Vulkan (one solver per parameter set, `fused` or two-pass, buffer access `access`).
template <typename Count>
Result<std::array<Row, 2>> bench_vulkan_pair(gpu::Context& ctx, const ParticleSystem& system,
                                             const SimParams& bare, const SimParams& full, bool fused,
                                             gpu::BufferAccess access, const BenchOptions& o,
                                             std::array<const char*, 2> scenes, Count count) {
  gpu::GpuSolverOptions go;
  go.fused = fused;
  go.buffer_access = access;
  go.workgroup_size = o.workgroup;
  auto s0 = gpu::GpuSolver::create(ctx, system, bare, go);
  if (!s0)
    return s0.error();
  auto s1 = gpu::GpuSolver::create(ctx, system, full, go);
  if (!s1)
    return s1.error();
  std::array<gpu::GpuSolver*, 2> s = {&*s0, &*s1};
  auto rows = alternate_contact(
      o, [&](int k, std::uint64_t steps) { return s[k]->simulate(steps, o.steps_per_submit); },
      [&](int k) { return s[k]->last_gpu_ms(); },
      [&]() -> Result<std::size_t> {
        auto x = s1->positions();
        if (!x)
          return x.error();
        return count(std::span<const glm::vec3>(*x));
      },
      scenes);
  if (!rows)
    return rows.error();
  const Integrator integrator = full.integrator;
  for (Row& r : *rows) {
    r.backend = "vulkan";
    r.variant = integrator == Integrator::implicit_euler ? "implicit"
                : integrator == Integrator::vbd          ? "vbd"
                : fused && integrator != Integrator::rk4 ? "fused"
                                                         : "two_pass";
    std::tie(r.layout, r.workgroup) = layout_of(ctx, go, integrator == Integrator::implicit_euler);
  }
  return rows;
}

} // namespace

Result<std::array<Row, 2>> bench_cpu_contact(const ContactScene& sc, const BenchOptions& o) {
  SimParams bare = sc.params;
  bare.colliders.clear();
  return bench_cpu_pair(sc.system, bare, sc.params, o, {"contact_free", "contact"},
                        [&](std::span<const glm::vec3> x) { return particles_in_contact(sc, to_double(x)); });
}

Result<std::array<Row, 2>> bench_vulkan_contact(gpu::Context& ctx, const ContactScene& sc, bool fused,
                                                gpu::BufferAccess access, const BenchOptions& o) {
  SimParams bare = sc.params;
  bare.colliders.clear();
  return bench_vulkan_pair(
      ctx, sc.system, bare, sc.params, fused, access, o, {"contact_free", "contact"},
      [&](std::span<const glm::vec3> x) { return particles_in_contact(sc, to_double(x)); });
}

namespace {

/// The folded cloth with self-collision off (row 0, scene "self_collision_free") and on (row 1,
/// "self_collision"), alternated by `time_pair(off, on, count)` (bench_cpu_pair or
/// bench_vulkan_pair); the particles in self-contact counted on the second, and its pairs after the
/// timed steps (the last count taken).
template <typename TimePair> Result<std::array<Row, 2>> self_rows(const SelfScene& sc, TimePair&& time_pair) {
  SimParams off = sc.params;
  off.self_collision.enabled = false;
  SelfContact last;
  auto rows = time_pair(off, [&](std::span<const glm::vec3> x) -> Result<std::size_t> {
    last = self_contact(sc, x);
    return last.particles;
  });
  if (rows)
    (*rows)[1].self_pairs_end = last.pairs;
  return rows;
}

} // namespace

Result<std::array<Row, 2>> bench_cpu_self(const SelfScene& sc, const BenchOptions& o) {
  return self_rows(sc, [&](const SimParams& off, const auto& count) {
    return bench_cpu_pair(sc.system, off, sc.params, o, {"self_collision_free", "self_collision"}, count);
  });
}

Result<std::array<Row, 2>> bench_vulkan_self(gpu::Context& ctx, const SelfScene& sc, bool fused,
                                             gpu::BufferAccess access, const BenchOptions& o) {
  return self_rows(sc, [&](const SimParams& off, const auto& count) {
    return bench_vulkan_pair(ctx, sc.system, off, sc.params, fused, access, o,
                             {"self_collision_free", "self_collision"}, count);
  });
}

} // namespace vkcloth::cli::bench
