// SPDX-License-Identifier: MIT
// `vkcloth run`: load, simulate, write CSVs, summarise.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "backend.hpp"
#include "commands.hpp"
#include "vkcloth/export.hpp"
#include "vkcloth/measure.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

Result<File> open_output(const std::string& path, const char* what) {
  File f{std::fopen(path.c_str(), "w")};
  if (!f)
    return make_error(ErrorCode::io,
                      fmt::format("cannot write the {} file {}: {}", what, path, std::strerror(errno)));
  return f;
}

/// A one-line bar on stderr, redrawn when the whole percentage changes. Only on a terminal.
class Progress {
public:
  explicit Progress(std::uint64_t total) : total_(total), enabled_(total >= 100 && isatty(STDERR_FILENO)) {}
  ~Progress() {
    if (drawn_)
      fmt::print(stderr, "\r{:60}\r", "");
  }
  /// The step count at which the next redraw is due.
  std::uint64_t next_tick(std::uint64_t done) const {
    if (!enabled_)
      return total_;
    const std::uint64_t pct = done * 100 / total_;
    return std::min(total_, ((pct + 1) * total_ + 99) / 100); // first step count showing pct + 1
  }
  void update(std::uint64_t done) {
    if (!enabled_)
      return;
    const auto pct = static_cast<int>(done * 100 / total_);
    if (pct == last_)
      return;
    last_ = pct;
    drawn_ = true;
    const int bar = pct * 30 / 100;
    fmt::print(stderr, "\r[{:#<{}}{:<{}}] {:3}% step {}/{}", "", bar, "", 30 - bar, pct, done, total_);
    std::fflush(stderr);
  }

private:
  std::uint64_t total_;
  bool enabled_;
  bool drawn_ = false;
  int last_ = -1;
};

/// Rows in the file's vertex order; the particle column is the file's vertex index (a mesh's
/// Surface::source_vertex; the particle index for grids and chains).
void write_trace_rows(std::FILE* f, std::uint64_t step, double time, const std::vector<glm::dvec3>& p,
                      const std::vector<glm::dvec3>& v, const ParticleSystem& system,
                      const std::vector<std::uint32_t>& order) {
  for (const std::uint32_t k : order)
    fmt::print(f, "{},{:.9g},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", step, time,
               file_vertex(system, k), p[k].x, p[k].y, p[k].z, v[k].x, v[k].y, v[k].z);
}

/// The contact quality over a run (`vkcloth run` on a scene with colliders): the deepest penetration
/// after any sampled step, and the largest speed over the run's last second (the jitter of a cloth
/// that should be at rest).
constexpr std::uint64_t no_step = ~std::uint64_t{0};
struct ContactTrack {
  PenetrationStats deepest;     ///< the deepest sampled penetration ...
  std::uint64_t step = no_step; ///< ... and its step
  double calm_speed = 0.0;      ///< the largest free-particle speed over the last second
  std::uint64_t calm_from = 0;  ///< the first step of the last second

  ContactTrack(std::uint64_t total_steps, double dt) {
    const auto last_second_steps = static_cast<std::uint64_t>(std::ceil(1.0 / dt - 1e-9));
    calm_from = total_steps > last_second_steps ? total_steps - last_second_steps : 0;
  }
  /// The state after step `step`, with the colliders where they are then.
  Result<void> add(const ParticleSystem& system, std::span<const Collider> colliders,
                   const std::vector<glm::dvec3>& pos, const std::vector<glm::dvec3>& vel, std::uint64_t at) {
    auto depth = penetration(system, colliders, pos);
    if (!depth)
      return depth.error();
    if (depth->depth > deepest.depth || step == no_step) {
      deepest = *depth;
      step = at;
    }
    if (at > calm_from)
      calm_speed = std::max(calm_speed, max_free_speed(system, vel));
    return {};
  }
  /// Why there is no deepest penetration to report (no step ran, or every particle is pinned or
  /// attached), or null when there is one.
  const char* unmeasured() const {
    if (step == no_step)
      return "no step ran";
    return std::isfinite(deepest.depth) ? nullptr : "no free particle";
  }
};

struct RunOptions {
  SceneArgs args;
  std::string trace; ///< empty: no trace
  std::uint64_t trace_every = 1;
  std::string positions; ///< empty: no final positions file
  std::string backend = "cpu";
  std::string precision = "float";
  std::string export_path;                          ///< .glb or .gltf; empty: none
  std::string obj_frames;                           ///< a directory; empty: none
  std::optional<std::uint64_t> export_every;        ///< K for both; unset: 1
  std::uint64_t strain_every = 1;                   ///< K for "over the run" of the structural strain
  std::uint64_t contact_every = 1;                  ///< K for the contact quality (scenes with colliders)
  bool check_intersections = false;                 ///< count the intersecting triangle pairs at the end
  std::optional<std::uint64_t> intersections_every; ///< N: also count them at step 0 and every N-th step
  std::string json;                                 ///< the summary as JSON; empty: none
};

/// The largest structural strain over the run (cloths): step 0, every K-th step and the last one.
struct StrainTrack {
  StrainStats run;
  std::uint64_t run_step = 0;
  void add(const StrainStats& s, std::uint64_t step) {
    if (s.max > run.max) {
      run = s;
      run_step = step;
    }
  }
};

/// The most intersecting triangle pairs over the run (--check-intersections-every N): step 0, every
/// N-th step and the last one.
struct IntersectionTrack {
  std::uint64_t every = 1;
  std::size_t max_pairs = 0;
  std::uint64_t max_step = 0;
  std::uint64_t samples = 0;
  Result<void> add(const ParticleSystem& system, const std::vector<glm::dvec3>& pos, std::uint64_t step) {
    auto r = intersecting_triangle_pairs(system, std::span<const glm::dvec3>(pos));
    if (!r)
      return r.error();
    if (samples++ == 0 || r->pairs > max_pairs) {
      max_pairs = r->pairs;
      max_step = step;
    }
    return {};
  }
};

/// --export and --obj-frames: a frame at step 0 and every K steps (as --trace rows); OBJs are
/// written as they come, the glTF at the end (or at a blow-up, with the frames before it).
class FrameExport {
public:
  /// Checks the paths and that the scene has a surface, before anything is simulated.
  static Result<FrameExport> create(const RunOptions& opt, const Scene& scene) {
    FrameExport e(scene.system);
    if (opt.export_every && opt.export_path.empty() && opt.obj_frames.empty())
      return make_error(ErrorCode::invalid_argument, "--export-every needs --export or --obj-frames");
    e.every_ = opt.export_every.value_or(1);
    if (!opt.export_path.empty()) {
      VKCLOTH_TRY(check_gltf_path(opt.export_path));
      auto recorder = AnimationRecorder::create(scene.system, scene.texture);
      if (!recorder)
        return make_error(recorder.error().code, "--export: " + recorder.error().message);
      VKCLOTH_TRY(probe_writable(opt.export_path));
      e.gltf_path_ = opt.export_path;
      e.recorder_.emplace(std::move(*recorder));
    }
    if (!opt.obj_frames.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(opt.obj_frames, ec);
      if (ec)
        return make_error(ErrorCode::io, fmt::format("--obj-frames: cannot create the directory {}: {}",
                                                     opt.obj_frames, ec.message()));
      e.obj_dir_ = opt.obj_frames;
    }
    return e;
  }

  bool enabled() const { return recorder_ || !obj_dir_.empty(); }
  std::uint64_t every() const { return every_; }

  Result<void> add(double time, const std::vector<glm::dvec3>& positions) {
    if (recorder_)
      VKCLOTH_TRY(recorder_->add_frame(time, positions));
    if (!obj_dir_.empty()) {
      const auto path = obj_dir_ / fmt::format("frame_{:05}.obj", frames_);
      if (auto r = write_obj_frame(path, *system_, positions); !r)
        return make_error(r.error().code, "--obj-frames: " + r.error().message);
    }
    ++frames_;
    return {};
  }

  /// Writes the glTF (nothing to do for OBJs); prints what was exported.
  Result<void> finish() const {
    if (recorder_)
      VKCLOTH_TRY(recorder_->write_gltf(gltf_path_));
    if (recorder_)
      fmt::print("exported {} frames to {}\n", frames_, gltf_path_.string());
    if (!obj_dir_.empty())
      fmt::print("exported {} OBJ frames to {}\n", frames_, obj_dir_.string());
    return {};
  }

private:
  explicit FrameExport(const ParticleSystem& system) : system_(&system) {}

  /// The glTF is written at the end: fail on an unwritable path now, not after the run.
  static Result<void> probe_writable(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f)
      return make_error(ErrorCode::io,
                        fmt::format("cannot write the export file {}: {}", path, std::strerror(errno)));
    std::fclose(f);
    return {};
  }

  const ParticleSystem* system_;
  std::uint64_t every_ = 1;
  std::optional<AnimationRecorder> recorder_;
  std::filesystem::path gltf_path_;
  std::filesystem::path obj_dir_;
  std::uint64_t frames_ = 0;
};

/// No two of the run's output files are one file (each would overwrite the other's lines).
Result<void> check_distinct_outputs(const RunOptions& opt) {
  namespace fs = std::filesystem;
  const std::pair<const char*, const std::string*> outputs[] = {{"--trace", &opt.trace},
                                                                {"--positions", &opt.positions},
                                                                {"--json", &opt.json},
                                                                {"--export", &opt.export_path}};
  const auto same_file = [](const std::string& a, const std::string& b) {
    std::error_code ea, eb;
    const fs::path pa = fs::weakly_canonical(fs::absolute(a), ea),
                   pb = fs::weakly_canonical(fs::absolute(b), eb);
    return !ea && !eb ? pa == pb : a == b;
  };
  for (std::size_t i = 0; i < std::size(outputs); ++i)
    for (std::size_t j = i + 1; j < std::size(outputs); ++j)
      if (!outputs[i].second->empty() && !outputs[j].second->empty() &&
          same_file(*outputs[i].second, *outputs[j].second))
        return make_error(ErrorCode::invalid_argument,
                          fmt::format("{} and {} name the same file ({}): give each output its own",
                                      outputs[i].first, outputs[j].first, *outputs[j].second));
  return {};
}

/// The output files, opened before the run: a typo in a path should not cost a whole run.
struct Outputs {
  File trace, positions, json;
};

Result<Outputs> open_outputs(const RunOptions& opt) {
  Outputs out;
  const std::pair<const std::string*, File*> wanted[] = {
      {&opt.trace, &out.trace}, {&opt.positions, &out.positions}, {&opt.json, &out.json}};
  const char* what[] = {"trace", "positions", "JSON"};
  for (std::size_t k = 0; k < std::size(wanted); ++k) {
    if (wanted[k].first->empty())
      continue;
    auto f = open_output(*wanted[k].first, what[k]);
    if (!f)
      return f.error();
    *wanted[k].second = std::move(*f);
  }
  if (out.trace)
    fmt::print(out.trace.get(), "step,time,particle,x,y,z,vx,vy,vz\n");
  return out;
}

/// What the run measured, for the summary lines and --json.
struct RunSummary {
  double wall = 0.0;                      ///< seconds of wall time in the step loop
  double max_displacement = 0.0;          ///< m, the largest move of a particle from its start
  SolveStats cg;                          ///< implicit_euler's last solve
  std::optional<SelfCollisionStats> self; ///< self-collision's passes and list builds (CPU)
  std::optional<StrainStats> end_strain;  ///< cloths: the strain of the final state
  StrainTrack strain;                     ///< ... and the largest over the run
  std::uint64_t strain_every = 1;
  std::optional<ContactTrack> contact; ///< scenes with colliders
  std::uint64_t contact_every = 1;
  std::optional<IntersectionStats> intersections;     ///< --check-intersections (or -every): at the end
  std::optional<IntersectionTrack> intersections_run; ///< --check-intersections-every: over the run
};

void print_summary(const Scene& scene, const RunOptions& opt, const SimBackend& backend,
                   const RunSummary& r) {
  const ParticleSystem& system = scene.system;
  fmt::print(
      "{}: {} particles, {} springs, {} steps of {:g} s ({}, {} {}): simulated {:.6g} s in {:.3f} s wall, "
      "max displacement {:.6g} m\n",
      scene.name, system.size(), system.springs.size(), backend.step_index(), scene.params.dt,
      to_string(scene.params.integrator), opt.backend, opt.precision, backend.time(), r.wall,
      r.max_displacement);
  if (scene.params.integrator == Integrator::implicit_euler)
    fmt::print(
        "implicit_euler: last solve {} CG iterations, relative residual {:.3g} (tolerance {:g}, cap {}); "
        "{:.1f} CG iterations per solve over the run ({} solves)\n",
        r.cg.iterations, r.cg.residual, scene.params.cg_tolerance, scene.params.cg_max_iterations,
        r.cg.mean_iterations(), r.cg.solves);
  if (r.self && r.self->builds > 0)
    fmt::print("self-collision: {} passes, {} of them built the neighbour lists first ({} entries, {} "
               "overflowed, at the last build)\n",
               r.self->passes, r.self->builds, r.self->candidates, r.self->overflowed);
  if (r.end_strain) {
    const Spring& sp = system.springs[r.end_strain->spring];
    fmt::print(
        "largest structural strain: {:.6g} at the end (spring {}: particles {}-{}), {:.6g} over the run "
        "(step {}{})\n",
        r.end_strain->max, r.end_strain->spring, file_vertex(system, sp.a), file_vertex(system, sp.b),
        r.strain.run.max, r.strain.run_step,
        r.strain_every > 1 ? fmt::format(", sampled every {} steps", r.strain_every) : "");
  }
  if (r.contact && r.contact->unmeasured())
    fmt::print("contact: nothing to measure ({})\n", r.contact->unmeasured());
  else if (r.contact)
    fmt::print(
        "contact: deepest penetration {:.3g} m (particle {}, collider {}, step {}; contact_epsilon {:g}{}), "
        "largest speed over the last second {:.3g} m/s\n",
        r.contact->deepest.depth, file_vertex(system, r.contact->deepest.particle),
        r.contact->deepest.collider, r.contact->step, scene.params.contact_epsilon,
        r.contact_every > 1 ? fmt::format(", sampled every {} steps", r.contact_every) : "",
        r.contact->calm_speed);
  if (r.intersections) {
    if (r.intersections->triangles == 0)
      fmt::print("intersections: no triangles (a chain), 0 pairs\n");
    else
      fmt::print("intersections: {} pairs of triangles intersect (of {} triangles)\n", r.intersections->pairs,
                 r.intersections->triangles);
  }
  if (r.intersections_run)
    fmt::print("intersections over the run: at most {} pairs (step {}), sampled every {} steps\n",
               r.intersections_run->max_pairs, r.intersections_run->max_step, r.intersections_run->every);
}

/// The summary as JSON (schema "vkcloth-run/1", keys in docs/scene-format.md).
nlohmann::json summary_json(const Scene& scene, const RunOptions& opt, const SimBackend& backend,
                            const RunSummary& r) {
  const ParticleSystem& system = scene.system;
  nlohmann::json doc;
  doc["schema"] = "vkcloth-run/1";
  doc["scene"] = scene.name;
  doc["particles"] = system.size();
  doc["springs"] = system.springs.size();
  doc["steps"] = backend.step_index();
  doc["dt"] = scene.params.dt;
  doc["integrator"] = to_string(scene.params.integrator);
  doc["backend"] = opt.backend;
  doc["precision"] = opt.precision;
  doc["simulated_time"] = backend.time();
  doc["wall_s"] = r.wall;
  doc["max_displacement"] = r.max_displacement;
  doc["implicit_euler"] = scene.params.integrator == Integrator::implicit_euler
                              ? nlohmann::json{{"cg_iterations", r.cg.iterations},
                                               {"cg_residual", r.cg.residual},
                                               {"cg_iterations_mean", r.cg.mean_iterations()},
                                               {"cg_solves", r.cg.solves}}
                              : nlohmann::json(nullptr);
  if (r.self)
    doc["self_collision"] = {{"passes", r.self->passes},
                             {"list_builds", r.self->builds},
                             {"list_entries", r.self->candidates},
                             {"lists_overflowed", r.self->overflowed}};
  if (r.end_strain) {
    const auto ends = [&](std::uint32_t k) {
      const Spring& sp = system.springs[k];
      return nlohmann::json::array({file_vertex(system, sp.a), file_vertex(system, sp.b)});
    };
    doc["max_structural_strain"] = {{"end", r.end_strain->max},
                                    {"end_spring", r.end_strain->spring},
                                    {"end_particles", ends(r.end_strain->spring)},
                                    {"run", r.strain.run.max},
                                    {"run_step", r.strain.run_step},
                                    {"run_spring", r.strain.run.spring},
                                    {"run_particles", ends(r.strain.run.spring)},
                                    {"every", r.strain_every},
                                    {"structural_springs", r.end_strain->count}};
  } else {
    doc["max_structural_strain"] = nullptr;
  }
  doc["contact"] = nullptr;
  if (r.contact) {
    const ContactTrack& c = *r.contact;
    // The penetration's fields null where nothing was measured (the same keys).
    const auto measured = [&](auto value) {
      return c.unmeasured() ? nlohmann::json(nullptr) : nlohmann::json(value);
    };
    doc["contact"] = {{"max_penetration", measured(c.deepest.depth)},
                      {"penetration_particle", measured(file_vertex(system, c.deepest.particle))},
                      {"penetration_collider", measured(c.deepest.collider)},
                      {"penetration_step", measured(c.step)},
                      {"contact_epsilon", scene.params.contact_epsilon},
                      {"max_speed_last_second", c.calm_speed},
                      {"last_second_from_step", c.calm_from},
                      {"every", r.contact_every}};
  }
  if (r.intersections)
    doc["intersections"] = {{"pairs", r.intersections->pairs}, {"triangles", r.intersections->triangles}};
  if (r.intersections_run) {
    doc["intersections"]["run_max_pairs"] = r.intersections_run->max_pairs;
    doc["intersections"]["run_max_step"] = r.intersections_run->max_step;
    doc["intersections"]["run_samples"] = r.intersections_run->samples;
    doc["intersections"]["every"] = r.intersections_run->every;
  }
  return doc;
}

/// The run: the backend stepped to the next trace row, exported frame, strain or contact sample, or
/// progress redraw, whichever comes first, its state read back (into pos, vel) only when one of
/// them needs it. On a blow-up the trace rows and the frames before it are kept, and the blow-up is
/// the error.
Result<void> step_loop(const Scene& scene, SimBackend& backend, FrameExport& frames, std::FILE* trace,
                       std::uint64_t trace_every, const std::vector<std::uint32_t>& order, bool track_strain,
                       std::vector<glm::dvec3>& pos, std::vector<glm::dvec3>& vel, RunSummary& sum) {
  const std::uint64_t total = scene.steps;
  const std::uint64_t every = std::max<std::uint64_t>(trace_every, 1);
  const auto next_multiple = [](std::uint64_t done, std::uint64_t k) { return (done / k + 1) * k; };
  Progress progress(total);
  std::uint64_t done = 0;
  while (done < total) {
    std::uint64_t next = progress.next_tick(done);
    if (trace)
      next = std::min(next, next_multiple(done, every));
    if (frames.enabled())
      next = std::min(next, next_multiple(done, frames.every()));
    if (track_strain)
      next = std::min(next, next_multiple(done, sum.strain_every));
    if (sum.contact)
      next = std::min(next, next_multiple(done, sum.contact_every));
    if (sum.intersections_run)
      next = std::min(next, next_multiple(done, sum.intersections_run->every));
    next = std::min(next, total);
    if (auto r = backend.step(next - done); !r) {
      if (trace)
        std::fflush(trace);             // the rows before the blow-up stay
      if (auto w = frames.finish(); !w) // and so do the frames
        report(w.error());
      return r.error();
    }
    done = next;
    const bool trace_due = trace && done % every == 0;
    const bool frame_due = frames.enabled() && done % frames.every() == 0;
    const bool contact_due = sum.contact && (done % sum.contact_every == 0 || done == total);
    const bool intersections_due =
        sum.intersections_run && (done % sum.intersections_run->every == 0 || done == total);
    if (trace_due || frame_due || contact_due || intersections_due)
      VKCLOTH_TRY(backend.read_state(pos, vel));
    if (intersections_due)
      VKCLOTH_TRY(sum.intersections_run->add(scene.system, pos, backend.step_index()));
    if (contact_due)
      VKCLOTH_TRY(sum.contact->add(scene.system, backend.colliders(), pos, vel, backend.step_index()));
    if (track_strain && (done % sum.strain_every == 0 || done == total)) {
      // From `pos` when it was just read (exact copies of the solver's positions); else the
      // backend reads the positions only.
      auto s = trace_due || frame_due ? structural_strain(scene.system, std::span<const glm::dvec3>(pos))
                                      : backend.strain(scene.system);
      if (!s)
        return s.error();
      sum.strain.add(*s, backend.step_index());
    }
    if (trace_due)
      write_trace_rows(trace, backend.step_index(), backend.time(), pos, vel, scene.system, order);
    if (frame_due)
      VKCLOTH_TRY(frames.add(backend.time(), pos));
    progress.update(done);
  }
  return {};
}

int run_command(const RunOptions& opt) {
  const auto precision = parse_precision(opt.precision);
  if (!precision)
    return report(make_error(ErrorCode::invalid_argument, "--precision must be float or double"));
  if (auto distinct = check_distinct_outputs(opt); !distinct)
    return report(distinct.error());
  auto scene = opt.args.load();
  if (!scene)
    return report(scene.error());
  auto frames_r = FrameExport::create(opt, *scene);
  if (!frames_r)
    return report(frames_r.error());
  FrameExport& frames = *frames_r;
  auto backend_r = make_backend(opt.backend, *scene, *precision);
  if (!backend_r)
    return report(backend_r.error());
  SimBackend& backend = **backend_r;
  auto outputs = open_outputs(opt);
  if (!outputs)
    return report(outputs.error());
  File& trace = outputs->trace;

  std::vector<glm::dvec3> pos, vel;
  const auto read = [&] { return backend.read_state(pos, vel); };
  if (auto r = read(); !r)
    return report(r.error());
  const std::vector<glm::dvec3> initial = pos; // in the solver's precision, for the displacement
  // The positions are exact copies of the solver's, so the strain of `pos` is the solver's.
  const auto strain_of_pos = [&] {
    return structural_strain(scene->system, std::span<const glm::dvec3>(pos));
  };
  auto strain0 = strain_of_pos();
  if (!strain0)
    return report(strain0.error());
  RunSummary sum;
  const bool track_strain = strain0->count > 0; // chains (and K_struct = 0) have no structural spring
  sum.strain_every = std::max<std::uint64_t>(opt.strain_every, 1);
  sum.strain = StrainTrack{*strain0, 0};
  if (!scene->params.colliders.empty())
    sum.contact.emplace(scene->steps, scene->params.dt);
  sum.contact_every = std::max<std::uint64_t>(opt.contact_every, 1);
  if (opt.intersections_every) {
    sum.intersections_run.emplace();
    sum.intersections_run->every = *opt.intersections_every;
    if (auto r = sum.intersections_run->add(scene->system, pos, 0); !r)
      return report(r.error());
  }
  const std::vector<std::uint32_t> order = file_order(scene->system);
  if (trace)
    write_trace_rows(trace.get(), 0, backend.time(), pos, vel, scene->system, order);
  if (frames.enabled())
    if (auto r = frames.add(backend.time(), pos); !r)
      return report(r.error());
  const auto t0 = std::chrono::steady_clock::now();
  if (auto r = step_loop(*scene, backend, frames, trace.get(), opt.trace_every, order, track_strain, pos, vel,
                         sum);
      !r)
    return report(r.error());
  sum.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (auto r = read(); !r)
    return report(r.error());
  if (File& positions = outputs->positions) {
    fmt::print(positions.get(), "particle,x,y,z\n"); // in the file's vertex order, as --trace
    for (const std::uint32_t k : order)
      fmt::print(positions.get(), "{},{:.9g},{:.9g},{:.9g}\n", file_vertex(scene->system, k), pos[k].x,
                 pos[k].y, pos[k].z);
  }
  for (File* f : {&outputs->trace, &outputs->positions})
    if (*f && (std::fflush(f->get()) != 0 || std::ferror(f->get())))
      return report(make_error(ErrorCode::io, "writing an output file failed (disk full?)"));
  if (auto r = frames.finish(); !r)
    return report(r.error());

  for (std::size_t k = 0; k < pos.size(); ++k)
    sum.max_displacement = std::max(sum.max_displacement, glm::length(pos[k] - initial[k]));
  sum.cg = backend.last_solve();
  if (scene->params.self_collision.enabled)
    sum.self = backend.self_collision_stats();
  if (track_strain) {
    auto s = strain_of_pos();
    if (!s)
      return report(s.error());
    sum.end_strain = *s;
    sum.strain.add(*s, backend.step_index()); // already there unless the run had no steps
  }
  if (opt.check_intersections || opt.intersections_every) { // at the final state (the solver's positions)
    auto r = intersecting_triangle_pairs(scene->system, std::span<const glm::dvec3>(pos));
    if (!r)
      return report(r.error());
    sum.intersections = *r;
  }
  print_summary(*scene, opt, backend, sum);
  if (File& json = outputs->json) {
    fmt::print(json.get(), "{}\n", summary_json(*scene, opt, backend, sum).dump(2));
    if (std::fflush(json.get()) != 0 || std::ferror(json.get()))
      return report(make_error(ErrorCode::io, "writing the JSON file failed (disk full?)"));
  }
  return exit_ok;
}

} // namespace

void add_run_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Simulate a scene; optionally write CSV traces and export the animation (glTF, OBJ)");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, opt->args);
  auto* trace =
      cmd->add_option("--trace", opt->trace,
                      "Write every particle's state to a CSV file: step,time,particle,x,y,z,vx,vy,vz "
                      "(step 0 then every K steps; for a mesh cloth, particle is the file's vertex index)");
  cmd->add_option("--trace-every", opt->trace_every, "K for --trace (default 1)")
      ->check(whole_number_at_least_one)
      ->needs(trace);
  cmd->add_option(
      "--export", opt->export_path,
      "Write the animated cloth as glTF 2.0: FILE.glb (binary) or FILE.gltf (JSON, buffer embedded); "
      "frames at step 0 then every K steps (--export-every), in the mesh file's vertex order");
  cmd->add_option("--export-every", opt->export_every, "K for --export and --obj-frames (default 1)")
      ->check(whole_number_at_least_one);
  cmd->add_option(
         "--obj-frames", opt->obj_frames,
         "Write one OBJ per exported frame into DIR (created): frame_00000.obj, frame_00001.obj, ...")
      ->type_name("DIR");
  cmd->add_option("--positions", opt->positions, "Write the final positions to a CSV file: particle,x,y,z");
  cmd->add_option(
         "--contact-every", opt->contact_every,
         "Scenes with colliders: measure the penetration (and, over the last second, the largest "
         "particle speed) every K-th and the last step (default 1; on Vulkan each reads the state back)")
      ->check(whole_number_at_least_one);
  cmd->add_option("--strain-every", opt->strain_every,
                  "Cloths: take the largest structural strain over the run from step 0, every K-th and the "
                  "last step (default 1: every step; on Vulkan each one reads the positions back)")
      ->check(whole_number_at_least_one);
  cmd->add_flag(
      "--check-intersections", opt->check_intersections,
      "After the run, count the pairs of the cloth's triangles that intersect each other and share "
      "no vertex (self-intersections at the final state; grids and meshes; JSON \"intersections\")");
  cmd->add_option("--check-intersections-every", opt->intersections_every,
                  "Also count them at step 0, every N-th and the last step, and print the most over the run "
                  "(JSON \"intersections\": run_max_pairs, run_max_step, run_samples, every); implies "
                  "--check-intersections")
      ->check(whole_number_at_least_one)
      ->type_name("N");
  cmd->add_option("--json", opt->json,
                  "Also write the summary as JSON to FILE (keys: docs/scene-format.md; not written on "
                  "divergence)");
  cmd->add_option("--backend", opt->backend, "Solver backend: cpu | vulkan (default cpu)");
  cmd->add_option("--precision", opt->precision,
                  "Solver arithmetic: float | double (default float; vulkan: float)")
      ->check(CLI::IsMember({"float", "double"}));
  cmd->callback([opt, exit] { *exit = run_command(*opt); });
}

} // namespace vkcloth::cli
