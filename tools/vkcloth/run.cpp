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

/// The contact quality over a run (`vkcloth run` on a scene with colliders).
constexpr std::uint64_t no_step = ~std::uint64_t{0};
struct ContactTrack {
  PenetrationStats deepest;     ///< the deepest sampled penetration ...
  std::uint64_t step = no_step; ///< ... and its step
  double calm_speed = 0.0;      ///< the largest free-particle speed over the last second
};

struct RunOptions {
  SceneArgs args;
  std::string trace; ///< empty: no trace
  std::uint64_t trace_every = 1;
  std::string positions; ///< empty: no final positions file
  std::string backend = "cpu";
  std::string precision = "float";
  std::string export_path;                   ///< .glb or .gltf; empty: none
  std::string obj_frames;                    ///< a directory; empty: none
  std::optional<std::uint64_t> export_every; ///< K for both; unset: 1
  std::uint64_t strain_every = 1;            ///< K for "over the run" of the structural strain
  std::uint64_t contact_every = 1;           ///< K for the contact quality (scenes with colliders)
  bool check_intersections = false;          ///< count the intersecting triangle pairs at the end
  std::string json;                          ///< the summary as JSON; empty: none
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

int run_command(const RunOptions& opt) {
  const auto precision = parse_precision(opt.precision);
  if (!precision)
    return report(make_error(ErrorCode::invalid_argument, "--precision must be float or double"));
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

  // Open the outputs first: a typo in a path should not cost a whole run.
  File trace, positions, json;
  if (!opt.trace.empty()) {
    auto f = open_output(opt.trace, "trace");
    if (!f)
      return report(f.error());
    trace = std::move(*f);
    fmt::print(trace.get(), "step,time,particle,x,y,z,vx,vy,vz\n");
  }
  if (!opt.positions.empty()) {
    auto f = open_output(opt.positions, "positions");
    if (!f)
      return report(f.error());
    positions = std::move(*f);
  }

  if (!opt.json.empty()) {
    auto f = open_output(opt.json, "JSON");
    if (!f)
      return report(f.error());
    json = std::move(*f);
  }

  std::vector<glm::dvec3> pos, vel;
  const auto read = [&] { return backend.read_state(pos, vel); };
  const std::uint64_t total = scene->steps;
  const std::uint64_t every = std::max<std::uint64_t>(opt.trace_every, 1);
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
  const bool track_strain = strain0->count > 0; // chains (and K_struct = 0) have no structural spring
  const std::uint64_t strain_every = std::max<std::uint64_t>(opt.strain_every, 1);
  StrainTrack strain{*strain0, 0};
  // Contact quality (scenes with colliders): the deepest penetration after any sampled step, and
  // the largest speed over the run's last second (the jitter of a cloth that should be at rest).
  const bool track_contact = !scene->params.colliders.empty();
  const std::uint64_t contact_every = std::max<std::uint64_t>(opt.contact_every, 1);
  const auto last_second_steps = static_cast<std::uint64_t>(std::ceil(1.0 / scene->params.dt - 1e-9));
  const std::uint64_t calm_from = total > last_second_steps ? total - last_second_steps : 0;
  ContactTrack contact;
  const auto sample_contact = [&]() -> Result<void> {
    const auto colliders = backend.colliders();
    auto depth = penetration(scene->system, colliders, pos);
    if (!depth)
      return depth.error();
    if (depth->depth > contact.deepest.depth || contact.step == no_step) {
      contact.deepest = *depth;
      contact.step = backend.step_index();
    }
    if (backend.step_index() > calm_from)
      contact.calm_speed = std::max(contact.calm_speed, max_free_speed(scene->system, vel));
    return {};
  };
  const std::vector<std::uint32_t> order = file_order(scene->system);
  if (trace)
    write_trace_rows(trace.get(), 0, backend.time(), pos, vel, scene->system, order);
  if (frames.enabled())
    if (auto r = frames.add(backend.time(), pos); !r)
      return report(r.error());
  const auto next_multiple = [](std::uint64_t done, std::uint64_t k) { return (done / k + 1) * k; };

  const auto t0 = std::chrono::steady_clock::now();
  {
    Progress progress(total);
    std::uint64_t done = 0;
    while (done < total) {
      // Step to the next trace row, exported frame or progress redraw, whichever comes first.
      std::uint64_t next = progress.next_tick(done);
      if (trace)
        next = std::min(next, next_multiple(done, every));
      if (frames.enabled())
        next = std::min(next, next_multiple(done, frames.every()));
      if (track_strain)
        next = std::min(next, next_multiple(done, strain_every));
      if (track_contact)
        next = std::min(next, next_multiple(done, contact_every));
      next = std::min(next, total);
      if (auto r = backend.step(next - done); !r) {
        if (trace)
          std::fflush(trace.get());       // the rows before the blow-up stay
        if (auto w = frames.finish(); !w) // and so do the frames
          report(w.error());
        return report(r.error());
      }
      done = next;
      const bool trace_due = trace && done % every == 0;
      const bool frame_due = frames.enabled() && done % frames.every() == 0;
      const bool contact_due = track_contact && (done % contact_every == 0 || done == total);
      if (trace_due || frame_due || contact_due) {
        if (auto r = read(); !r)
          return report(r.error());
      }
      if (contact_due)
        if (auto r = sample_contact(); !r)
          return report(r.error());
      if (track_strain && (done % strain_every == 0 || done == total)) {
        // From `pos` when it was just read; else the backend reads the positions only.
        auto s = trace_due || frame_due ? strain_of_pos() : backend.strain(scene->system);
        if (!s)
          return report(s.error());
        strain.add(*s, backend.step_index());
      }
      if (trace_due)
        write_trace_rows(trace.get(), backend.step_index(), backend.time(), pos, vel, scene->system, order);
      if (frame_due)
        if (auto r = frames.add(backend.time(), pos); !r)
          return report(r.error());
      progress.update(done);
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (auto r = read(); !r)
    return report(r.error());
  if (positions) {
    fmt::print(positions.get(), "particle,x,y,z\n"); // in the file's vertex order, as --trace
    for (const std::uint32_t k : order)
      fmt::print(positions.get(), "{},{:.9g},{:.9g},{:.9g}\n", file_vertex(scene->system, k), pos[k].x,
                 pos[k].y, pos[k].z);
  }
  for (File* f : {&trace, &positions})
    if (*f && (std::fflush(f->get()) != 0 || std::ferror(f->get())))
      return report(make_error(ErrorCode::io, "writing an output file failed (disk full?)"));
  if (auto r = frames.finish(); !r)
    return report(r.error());

  double max_disp = 0.0;
  for (std::size_t k = 0; k < pos.size(); ++k)
    max_disp = std::max(max_disp, glm::length(pos[k] - initial[k]));
  fmt::print(
      "{}: {} particles, {} springs, {} steps of {:g} s ({}, {} {}): simulated {:.6g} s in {:.3f} s wall, "
      "max displacement {:.6g} m\n",
      scene->name, scene->system.size(), scene->system.springs.size(), backend.step_index(), scene->params.dt,
      to_string(scene->params.integrator), opt.backend, opt.precision, backend.time(), wall, max_disp);
  const SolveStats cg = backend.last_solve();
  if (scene->params.integrator == Integrator::implicit_euler)
    fmt::print(
        "implicit_euler: last solve {} CG iterations, relative residual {:.3g} (tolerance {:g}, cap {}); "
        "{:.1f} CG iterations per solve over the run ({} solves)\n",
        cg.iterations, cg.residual, scene->params.cg_tolerance, scene->params.cg_max_iterations,
        cg.mean_iterations(), cg.solves);
  std::optional<StrainStats> end_strain;
  if (track_strain) {
    auto s = strain_of_pos();
    if (!s)
      return report(s.error());
    end_strain = *s;
    strain.add(*s, backend.step_index()); // already there unless the run had no steps
    const Spring& sp = scene->system.springs[end_strain->spring];
    fmt::print(
        "largest structural strain: {:.6g} at the end (spring {}: particles {}-{}), {:.6g} over the run "
        "(step {}{})\n",
        end_strain->max, end_strain->spring, file_vertex(scene->system, sp.a),
        file_vertex(scene->system, sp.b), strain.run.max, strain.run_step,
        strain_every > 1 ? fmt::format(", sampled every {} steps", strain_every) : "");
  }
  if (track_contact)
    fmt::print(
        "contact: deepest penetration {:.3g} m (particle {}, collider {}, step {}; contact_epsilon {:g}{}), "
        "largest speed over the last second {:.3g} m/s\n",
        contact.deepest.depth, file_vertex(scene->system, contact.deepest.particle), contact.deepest.collider,
        contact.step, scene->params.contact_epsilon,
        contact_every > 1 ? fmt::format(", sampled every {} steps", contact_every) : "", contact.calm_speed);
  // Self-intersections at the final state (the solver's positions, in particle order).
  std::optional<IntersectionStats> intersections;
  if (opt.check_intersections) {
    auto r = intersecting_triangle_pairs(scene->system, std::span<const glm::dvec3>(pos));
    if (!r)
      return report(r.error());
    intersections = *r;
    if (r->triangles == 0)
      fmt::print("intersections: no triangles (a chain), 0 pairs\n");
    else
      fmt::print("intersections: {} pairs of triangles intersect (of {} triangles)\n", r->pairs,
                 r->triangles);
  }
  if (json) {
    nlohmann::json doc;
    doc["schema"] = "vkcloth-run/1";
    doc["scene"] = scene->name;
    doc["particles"] = scene->system.size();
    doc["springs"] = scene->system.springs.size();
    doc["steps"] = backend.step_index();
    doc["dt"] = scene->params.dt;
    doc["integrator"] = to_string(scene->params.integrator);
    doc["backend"] = opt.backend;
    doc["precision"] = opt.precision;
    doc["simulated_time"] = backend.time();
    doc["wall_s"] = wall;
    doc["max_displacement"] = max_disp;
    doc["implicit_euler"] = scene->params.integrator == Integrator::implicit_euler
                                ? nlohmann::json{{"cg_iterations", cg.iterations},
                                                 {"cg_residual", cg.residual},
                                                 {"cg_iterations_mean", cg.mean_iterations()},
                                                 {"cg_solves", cg.solves}}
                                : nlohmann::json(nullptr);
    if (end_strain) {
      const auto ends = [&](std::uint32_t k) {
        const Spring& sp = scene->system.springs[k];
        return nlohmann::json::array({file_vertex(scene->system, sp.a), file_vertex(scene->system, sp.b)});
      };
      doc["max_structural_strain"] = {{"end", end_strain->max},
                                      {"end_spring", end_strain->spring},
                                      {"end_particles", ends(end_strain->spring)},
                                      {"run", strain.run.max},
                                      {"run_step", strain.run_step},
                                      {"run_spring", strain.run.spring},
                                      {"run_particles", ends(strain.run.spring)},
                                      {"every", strain_every},
                                      {"structural_springs", end_strain->count}};
    } else {
      doc["max_structural_strain"] = nullptr;
    }
    doc["contact"] =
        track_contact
            ? nlohmann::json{{"max_penetration", contact.deepest.depth},
                             {"penetration_particle", file_vertex(scene->system, contact.deepest.particle)},
                             {"penetration_collider", contact.deepest.collider},
                             {"penetration_step", contact.step},
                             {"contact_epsilon", scene->params.contact_epsilon},
                             {"max_speed_last_second", contact.calm_speed},
                             {"last_second_from_step", calm_from},
                             {"every", contact_every}}
            : nlohmann::json(nullptr);
    if (intersections)
      doc["intersections"] = {{"pairs", intersections->pairs}, {"triangles", intersections->triangles}};
    fmt::print(json.get(), "{}\n", doc.dump(2));
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
      ->check(CLI::PositiveNumber)
      ->needs(trace);
  cmd->add_option(
      "--export", opt->export_path,
      "Write the animated cloth as glTF 2.0: FILE.glb (binary) or FILE.gltf (JSON, buffer embedded); "
      "frames at step 0 then every K steps (--export-every), in the mesh file's vertex order");
  cmd->add_option("--export-every", opt->export_every, "K for --export and --obj-frames (default 1)")
      ->check(CLI::PositiveNumber);
  cmd->add_option(
         "--obj-frames", opt->obj_frames,
         "Write one OBJ per exported frame into DIR (created): frame_00000.obj, frame_00001.obj, ...")
      ->type_name("DIR");
  cmd->add_option("--positions", opt->positions, "Write the final positions to a CSV file: particle,x,y,z");
  cmd->add_option(
         "--contact-every", opt->contact_every,
         "Scenes with colliders: measure the penetration (and, over the last second, the largest "
         "particle speed) every K-th and the last step (default 1; on Vulkan each reads the state back)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--strain-every", opt->strain_every,
                  "Cloths: take the largest structural strain over the run from step 0, every K-th and the "
                  "last step (default 1: every step; on Vulkan each one reads the positions back)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag(
      "--check-intersections", opt->check_intersections,
      "After the run, count the pairs of the cloth's triangles that intersect each other and share "
      "no vertex (self-intersections at the final state; grids and meshes; JSON \"intersections\")");
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
