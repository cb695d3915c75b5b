// SPDX-License-Identifier: MIT
// `vkcloth info`: what a scene file turns into, for checking a scene before running it.
#include <array>

#include <fmt/format.h>

#include "commands.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {
namespace {

std::string vec(glm::dvec3 v) {
  return fmt::format("[{:g}, {:g}, {:g}]", v.x, v.y, v.z);
}

int info_command(const SceneArgs& opt) {
  auto scene_r = opt.load();
  if (!scene_r)
    return report(scene_r.error());
  const Scene& s = *scene_r;
  const SimParams& p = s.params;

  std::size_t pinned = 0;
  double mass = 0.0;
  for (const Particle& q : s.system.particles) {
    pinned += q.pinned ? 1 : 0;
    mass += q.pinned ? 0.0 : q.mass;
  }
  std::array<std::size_t, 4> per_kind{};
  for (const Spring& sp : s.system.springs)
    ++per_kind[static_cast<std::size_t>(sp.kind)];

  fmt::print("scene       {}\n", s.name);
  fmt::print("system      {}", s.system.grid || s.system.surface ? "cloth" : "chain");
  if (s.system.grid)
    fmt::print(" ({} x {} grid, index j*nx+i)", s.system.grid->nx, s.system.grid->ny);
  if (const auto& surface = s.system.surface) {
    const std::size_t faces =
        surface->face_offsets.empty() ? surface->triangles.size() / 3 : surface->face_offsets.size() - 1;
    fmt::print(" (mesh: {} faces, {} triangles; outputs in the file's vertex order)", faces,
               surface->triangles.size() / 3);
  }
  fmt::print("\nparticles   {} ({} pinned, free mass {:g} kg)\n", s.system.size(), pinned, mass);
  fmt::print("springs     {}", s.system.springs.size());
  for (SpringKind k : {SpringKind::plain, SpringKind::structural, SpringKind::shear, SpringKind::bend})
    if (const auto n = per_kind[static_cast<std::size_t>(k)])
      fmt::print(", {} {}", n, to_string(k));
  fmt::print("\nintegrator  {}, dt {:g} s, {} steps ({:g} s)\n", to_string(p.integrator), p.dt, s.steps,
             p.dt * static_cast<double>(s.steps));
  fmt::print("gravity     {} m/s^2\ndamping     {:g} 1/s\n", vec(p.gravity), p.damping);
  fmt::print("wind        strength {:g}, direction {}\n", p.wind.strength, vec(p.wind.direction));
  fmt::print("colliders   {}\n", p.colliders.size());
  for (std::size_t k = 0; k < p.colliders.size(); ++k) {
    const Collider& c = p.colliders[k];
    if (c.type == Collider::Type::plane)
      fmt::print("  [{}] plane  normal {}, offset {:g}\n", k, vec(c.normal), c.offset);
    else
      fmt::print("  [{}] sphere center {}, radius {:g}\n", k, vec(c.center), c.radius);
  }
  fmt::print("contact_epsilon {:g} m, divergence_limit {:g} m\n", p.contact_epsilon, p.divergence_limit);
  return exit_ok;
}

} // namespace

void add_info_command(CLI::App& app, int* exit) {
  auto args = std::make_shared<SceneArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Print a parsed scene: particles, springs per kind, parameters");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, *args, false);
  cmd->callback([args, exit] { *exit = info_command(*args); });
}

} // namespace vkcloth::cli
