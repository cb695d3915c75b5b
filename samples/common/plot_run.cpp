// SPDX-License-Identifier: MIT
#include "plot_run.hpp"

#include <fstream>

#include <fmt/format.h>

#include "vkcloth/cpu_solver.hpp"
#include "vkcloth_plot/svg_plot.hpp"

namespace samples {

bool plot_chain(const vkcloth::Scene& scene, double seconds, const std::filesystem::path& out) {
  using namespace vkcloth;
  auto solver = CpuSolver<double>::create(scene.system, scene.params);
  if (!solver) {
    fmt::print(stderr, "error: {}\n", solver.error().message);
    return false;
  }
  plot::Plot pos{fmt::format("{}: height of the masses", scene.name), "t (s)", "z (m)", {}, 0, 0, 640, 400};
  plot::Plot energy{fmt::format("{}: energy", scene.name), "t (s)", "E (J)", {}, 0, 0, 640, 400};
  const char* names[] = {"kinetic", "gravity", "spring", "total"};
  for (int k = 0; k < 4; ++k)
    energy.series.push_back({names[k], plot::palette(std::size_t(k)), {}, {}, k == 3, {}});
  for (std::size_t p = 0; p < scene.system.size(); ++p)
    if (!scene.system.particles[p].pinned)
      pos.series.push_back({fmt::format("mass {}", p), plot::palette(pos.series.size()), {}, {}, false, {}});
  const auto steps = std::uint64_t(seconds / scene.params.dt);
  for (std::uint64_t s = 0; s <= steps; ++s) {
    if (s > 0)
      if (auto r = solver->step(); !r) { // a blow-up ends the lines here; the plot says so
        pos.series[0].note = r.error().message;
        break;
      }
    const double t = solver->time();
    std::size_t k = 0;
    for (std::size_t p = 0; p < scene.system.size(); ++p)
      if (!scene.system.particles[p].pinned) {
        pos.series[k].x.push_back(t);
        pos.series[k++].y.push_back(solver->positions()[p].z);
      }
    const auto e = solver->energy();
    const double values[] = {e.kinetic, e.gravity, e.spring, e.total()};
    for (int i = 0; i < 4; ++i) {
      energy.series[std::size_t(i)].x.push_back(t);
      energy.series[std::size_t(i)].y.push_back(values[i]);
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  for (const auto& [plot, suffix] : {std::pair{&pos, "position"}, std::pair{&energy, "energy"}}) {
    const auto path = out / fmt::format("{}_{}.svg", scene.name, suffix);
    std::ofstream(path) << plot::to_svg(*plot);
    fmt::print("plot written to {}\n", path.string());
  }
  return true;
}

} // namespace samples
