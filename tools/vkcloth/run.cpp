// SPDX-License-Identifier: MIT
// `vkcloth run`: load, simulate, write CSVs, summarise.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <unistd.h>

#include "backend.hpp"
#include "commands.hpp"
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

void write_trace_rows(std::FILE* f, std::uint64_t step, double time, const std::vector<glm::dvec3>& p,
                      const std::vector<glm::dvec3>& v) {
  for (std::size_t k = 0; k < p.size(); ++k)
    fmt::print(f, "{},{:.9g},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", step, time, k, p[k].x, p[k].y,
               p[k].z, v[k].x, v[k].y, v[k].z);
}

struct RunOptions {
  SceneArgs args;
  std::string trace; ///< empty: no trace
  std::uint64_t trace_every = 1;
  std::string positions; ///< empty: no final positions file
  std::string backend = "cpu";
  std::string precision = "float";
};

int run_command(const RunOptions& opt) {
  const auto precision = parse_precision(opt.precision);
  if (!precision)
    return report(make_error(ErrorCode::invalid_argument, "--precision must be float or double"));
  auto scene = load_scene_file(opt.args.scene, opt.args.overrides());
  if (!scene)
    return report(scene.error());
  auto backend_r = make_backend(opt.backend, *scene, *precision);
  if (!backend_r)
    return report(backend_r.error());
  SimBackend& backend = **backend_r;

  // Open the outputs first: a typo in a path should not cost a whole run.
  File trace, positions;
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

  std::vector<glm::dvec3> pos, vel;
  const auto read = [&] { return backend.read_state(pos, vel); };
  const std::uint64_t total = scene->steps;
  const std::uint64_t every = std::max<std::uint64_t>(opt.trace_every, 1);
  if (auto r = read(); !r)
    return report(r.error());
  const std::vector<glm::dvec3> initial = pos; // in the solver's precision, for the displacement
  if (trace) {
    write_trace_rows(trace.get(), 0, backend.time(), pos, vel);
  }

  const auto t0 = std::chrono::steady_clock::now();
  {
    Progress progress(total);
    std::uint64_t done = 0;
    while (done < total) {
      // Step to the next trace row or progress redraw, whichever comes first.
      std::uint64_t next = progress.next_tick(done);
      if (trace)
        next = std::min(next, (done / every + 1) * every);
      next = std::min(next, total);
      if (auto r = backend.step(next - done); !r) {
        if (trace)
          std::fflush(trace.get()); // the rows before the blow-up stay
        return report(r.error());
      }
      done = next;
      if (trace && done % every == 0) {
        if (auto r = read(); !r)
          return report(r.error());
        write_trace_rows(trace.get(), backend.step_index(), backend.time(), pos, vel);
      }
      progress.update(done);
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (auto r = read(); !r)
    return report(r.error());
  if (positions) {
    fmt::print(positions.get(), "particle,x,y,z\n");
    for (std::size_t k = 0; k < pos.size(); ++k)
      fmt::print(positions.get(), "{},{:.9g},{:.9g},{:.9g}\n", k, pos[k].x, pos[k].y, pos[k].z);
  }
  for (File* f : {&trace, &positions})
    if (*f && (std::fflush(f->get()) != 0 || std::ferror(f->get())))
      return report(make_error(ErrorCode::io, "writing an output file failed (disk full?)"));

  double max_disp = 0.0;
  for (std::size_t k = 0; k < pos.size(); ++k)
    max_disp = std::max(max_disp, glm::length(pos[k] - initial[k]));
  fmt::print(
      "{}: {} particles, {} springs, {} steps of {:g} s ({}, {} {}): simulated {:.6g} s in {:.3f} s wall, "
      "max displacement {:.6g} m\n",
      scene->name, scene->system.size(), scene->system.springs.size(), backend.step_index(), scene->params.dt,
      to_string(scene->params.integrator), opt.backend, opt.precision, backend.time(), wall, max_disp);
  if (scene->params.integrator == Integrator::implicit_euler) {
    const SolveStats cg = backend.last_solve();
    fmt::print(
        "implicit_euler: last solve {} CG iterations, relative residual {:.3g} (tolerance {:g}, cap {})\n",
        cg.iterations, cg.residual, scene->params.cg_tolerance, scene->params.cg_max_iterations);
  }
  return exit_ok;
}

} // namespace

void add_run_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Simulate a scene and optionally write CSV traces");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, opt->args);
  auto* trace =
      cmd->add_option("--trace", opt->trace,
                      "Write every particle's state to a CSV file: step,time,particle,x,y,z,vx,vy,vz "
                      "(step 0 then every K steps)");
  cmd->add_option("--trace-every", opt->trace_every, "K for --trace (default 1)")
      ->check(CLI::PositiveNumber)
      ->needs(trace);
  cmd->add_option("--positions", opt->positions, "Write the final positions to a CSV file: particle,x,y,z");
  cmd->add_option("--backend", opt->backend, "Solver backend: cpu | vulkan (default cpu)");
  cmd->add_option("--precision", opt->precision,
                  "Solver arithmetic: float | double (default float; vulkan: float)")
      ->check(CLI::IsMember({"float", "double"}));
  cmd->callback([opt, exit] { *exit = run_command(*opt); });
}

} // namespace vkcloth::cli
