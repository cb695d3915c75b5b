// SPDX-License-Identifier: MIT
// `vkcloth info`: what a scene file turns into, for checking a scene before running it.
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "commands.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {
namespace {

std::string vec(glm::dvec3 v) {
  return fmt::format("[{:g}, {:g}, {:g}]", v.x, v.y, v.z);
}

// R = Rz Ry Rx (Collider::rotation_from_degrees) back to [rx, ry, rz] in degrees (ry in [-90, 90]).
glm::dvec3 rotation_degrees(const glm::dmat3& r) {
  const auto at = [&](int row, int col) { return r[col][row]; }; // glm is column-major
  const double deg = 180.0 / 3.14159265358979323846;
  const double ry = std::asin(std::clamp(-at(2, 0), -1.0, 1.0));
  glm::dvec3 d = std::abs(at(2, 0)) > 1.0 - 1e-12 // gimbal lock: rx and rz turn about one axis; all in rx
                     ? glm::dvec3(std::atan2(-at(1, 2), at(1, 1)), ry, 0.0)
                     : glm::dvec3(std::atan2(at(2, 1), at(2, 2)), ry, std::atan2(at(1, 0), at(0, 0)));
  for (int k = 0; k < 3; ++k) // rounding residue (and -0) prints as 0
    d[k] = std::abs(d[k] * deg) < 1e-9 ? 0.0 : d[k] * deg;
  return d;
}

void print_collider(std::size_t k, const Collider& c) {
  switch (c.type) {
  case Collider::Type::plane:
    fmt::print("  [{}] plane   normal {}, offset {:g}\n", k, vec(c.normal), c.offset);
    break;
  case Collider::Type::sphere:
    fmt::print("  [{}] sphere  center {}, radius {:g}\n", k, vec(c.center), c.radius);
    break;
  case Collider::Type::capsule:
    fmt::print("  [{}] capsule a {}, b {}, radius {:g}\n", k, vec(c.a), vec(c.b), c.radius);
    break;
  case Collider::Type::box:
    fmt::print("  [{}] box     center {}, half_extents {}, rotation_deg {}\n", k, vec(c.center),
               vec(c.half_extents), vec(rotation_degrees(c.rotation)));
    break;
  case Collider::Type::mesh:
    fmt::print(
        "  [{}] mesh    {}: {} triangles, hierarchy depth {}; origin {}, rotation_deg {}, thickness {:g}\n",
        k, c.mesh ? c.mesh->name() : "?", c.mesh ? c.mesh->triangles().size() : 0,
        c.mesh ? c.mesh->depth() : 0, vec(c.center), vec(rotation_degrees(c.rotation)), c.thickness);
    break;
  }
  fmt::print("      friction {:g} (static {:g})", c.friction, c.static_coefficient());
  if (c.path) {
    fmt::print(", keyframed: {} keys from t = {:g} s to {:g} s", c.path->keys.size(), c.path->keys.front().t,
               c.path->keys.back().t);
    for (const ColliderKeyframe& key : c.path->keys)
      if (key.teleport)
        fmt::print(", teleport at t = {:g} s", key.t);
    fmt::print("\n");
  } else if (c.moving())
    fmt::print(", linear_velocity {} m/s, angular_velocity {} rad/s\n", vec(c.linear_velocity),
               vec(c.angular_velocity));
  else
    fmt::print(", at rest\n");
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
  if (s.cloths.size() > 1) {
    std::string ranges;
    for (std::size_t k = 0; k + 1 < s.cloths.size(); ++k)
      ranges += fmt::format("{}{}-{}", k ? ", " : "", s.cloths[k], s.cloths[k + 1] - 1);
    fmt::print(" ({} cloths, particles {})", s.cloths.size() - 1, ranges);
  }
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
  for (std::size_t k = 0; k < p.colliders.size(); ++k)
    print_collider(k, p.colliders[k]);
  if (p.inertia.enabled())
    fmt::print("inertia     the frame of collider {}: linear {:g}, angular {:g}\n", *p.inertia.collider,
               p.inertia.linear, p.inertia.angular);
  if (!p.attachments.empty())
    fmt::print("attach      {}\n", p.attachments.size());
  for (std::size_t k = 0; k < p.attachments.size(); ++k) {
    const Attachment& a = p.attachments[k];
    fmt::print("  [{}] {} particles follow collider {}", k, a.particles.size(), a.collider);
    if (a.max_distance > 0.0 || (!a.particles.empty() && !s.system.particles[a.particles[0]].pinned))
      fmt::print(", free within {:g} m (max_distance)\n", a.max_distance);
    else
      fmt::print(", pinned\n");
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
