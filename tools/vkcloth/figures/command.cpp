// SPDX-License-Identifier: MIT
// Registers `vkcloth figures`.
#include <chrono>
#include <cstdint>
#include <filesystem>

#include <fmt/format.h>

#include "../commands.hpp"
#include "figures.hpp"

namespace vkcloth::cli {
namespace {

struct FiguresOptions {
  std::string out = "out/figures";
  std::string backend = "cpu";
  bool quick = false;
  std::string samples = VKCLOTH_SAMPLES_DIR;
  std::uint64_t self_collision_steps = 0;
};

int figures_command(const FiguresOptions& opt) {
  if (opt.backend != "cpu" && opt.backend != "vulkan")
    return report(make_error(ErrorCode::invalid_argument,
                             fmt::format("unknown backend \"{}\" (known: cpu, vulkan)", opt.backend)));
  std::error_code ec;
  std::filesystem::create_directories(opt.out, ec);
  if (ec)
    return report(make_error(
        ErrorCode::io, fmt::format("cannot create the output directory {}: {}", opt.out, ec.message())));
  figures::Gallery gallery{opt.out, opt.backend, {}, nlohmann::json::object(), opt.quick, opt.samples};
  gallery.self_collision_steps = opt.self_collision_steps;
  const auto t0 = std::chrono::steady_clock::now();
  fmt::print(stderr, "figures: springs...\n");
  if (auto r = figures::spring_figures(gallery); !r)
    return report(r.error());
  fmt::print(stderr, "figures: springs done ({:.1f} s)\n",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (auto r = figures::cloth_figures(gallery); !r)
    return report(r.error());
  if (auto r = figures::contact_figures(gallery); !r)
    return report(r.error());
  if (auto r = figures::self_collision_figures(gallery); !r)
    return report(r.error());
  if (auto r = figures::stability_figures(gallery); !r)
    return report(r.error());
  if (auto r = figures::stiff_figures(gallery); !r)
    return report(r.error());
  if (auto r = figures::character_figures(gallery); !r)
    return report(r.error());
  if (auto r = gallery.write_index(); !r)
    return report(r.error());
  fmt::print("{} figures in {}/index.html ({:.1f} s)\n", gallery.figures.size(), opt.out,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return exit_ok;
}

} // namespace

void add_figures_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<FiguresOptions>();
  CLI::App* cmd = app.add_subcommand(
      "figures", "Regenerate the report's figures (SVG plots, images) and an index.html gallery");
  cmd->footer(exit_codes_footer);
  cmd->add_option("--out", opt->out, "Output directory (default out/figures)");
  cmd->add_option(
      "--backend", opt->backend,
      "Solver backend: cpu | vulkan (default cpu). The cloth pictures are drawn by the Vulkan "
      "renderer either way (the CPU result is uploaded for drawing); Figure 14 is always the GPU solver, "
      "the material figures (three resolutions, presets over the sphere) always the CPU solver");
  cmd->add_flag("--quick", opt->quick,
                "Smaller cloth pictures (240x180 panels instead of 400x300); same numbers");
  cmd->add_option("--samples", opt->samples,
                  "The samples directory holding scenes/ and meshes/ for the mesh and contact figures "
                  "(default: the source "
                  "tree's)")
      ->capture_default_str();
  cmd->add_option("--self-collision-steps", opt->self_collision_steps,
                  "Run the self-collision samples for at most N steps (default 0: the scenes' own steps; "
                  "for quick checks, the full runs take about a minute)");
  cmd->callback([opt, exit] { *exit = figures_command(*opt); });
}

} // namespace vkcloth::cli
