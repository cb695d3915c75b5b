// SPDX-License-Identifier: MIT
// Sample: the report's cloth (§3-4) in its configurations: a 10 x 10 grid over 1 x 1 m, 0.05 kg
// per point, built with make_cloth(), with the colliders and wind set in SimParams.
//   cloth --preset NAME [--offscreen]     (cloth --help lists the presets)
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "common/sample_app.hpp"
#include "vkcloth/builders.hpp"

namespace {

struct Preset {
  const char* name;
  const char* what;
  void (*apply)(vkcloth::ClothDesc&, vkcloth::SimParams&);
};

using vkcloth::Collider;

/// Horizontal at z, nothing pinned: the cloth falls.
void falling(vkcloth::ClothDesc& d, double z) {
  d.orientation = vkcloth::ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, z};
  d.pin_default_corners = false;
}

const Preset presets[] = {
    {"structural", "hanging from two corners, structural springs only (K = 40; Figure 6)",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams&) {
       d.stiffness = {40, 0, 0};
     }},
    {"shear", "hanging, structural + shear springs (40 / 8)",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams&) {
       d.stiffness = {40, 8, 0};
     }},
    {"bend", "hanging, structural + shear + bend springs (40 / 8 / 8, the report's choice)",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams&) {
       d.stiffness = {40, 8, 8};
     }},
    {"plane", "falls flat onto the floor plane z = 0 (Figure 11, left)",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams& p) {
       falling(d, 0.8);
       p.colliders = {Collider::plane({0, 0, 1}, 0.0)};
     }},
    {"sphere", "falls onto a sphere (centre (0, 0, 0.3), r = 0.3), no floor",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams& p) {
       falling(d, 0.8);
       p.colliders = {Collider::sphere({0, 0, 0.3}, 0.3)};
     }},
    {"plane_sphere", "falls onto the sphere and the floor (Figure 11, right)",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams& p) {
       falling(d, 0.8);
       p.colliders = {Collider::sphere({0, 0, 0.3}, 0.3), Collider::plane({0, 0, 1}, 0.0)};
     }},
    {"wind", "hanging, 40 / 8 / 8, wind K_w = 0.05 towards +y (Figures 13-15)",
     [](vkcloth::ClothDesc&, vkcloth::SimParams& p) {
       p.wind = {0.05, {0, 1, 0}};
     }},
    {"no_structural", "no structural springs (shear + bend 8) onto the sphere: holes open (Figure 5)",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams& p) {
       falling(d, 0.8);
       d.stiffness = {0, 8, 8};
       p.colliders = {Collider::sphere({0, 0, 0.3}, 0.3), Collider::plane({0, 0, 1}, 0.0)};
     }},
    {"sticky", "started inside a sphere with contact_inward_only = false: it sticks (Figure 12, right)",
     [](vkcloth::ClothDesc& d, vkcloth::SimParams& p) {
       falling(d, 0.4);
       p.colliders = {Collider::sphere({0, 0, 0.5}, 0.3)};
       p.contact_inward_only = false;
     }},
};

} // namespace

int main(int argc, char** argv) {
  std::string list;
  for (const Preset& p : presets)
    list += fmt::format("                         {:<14} {}\n", p.name, p.what);
  samples::Options opt = samples::parse_args(
      argc, argv, "The report's cloth: 10 x 10 points over 1 x 1 m, 0.05 kg each, dt = 0.02, mu = 0.5.",
      list);
  if (opt.preset.empty())
    opt.preset = "bend";
  const Preset* chosen = nullptr;
  for (const Preset& p : presets)
    if (opt.preset == p.name)
      chosen = &p;
  if (!chosen) {
    fmt::print(stderr, "error: unknown preset \"{}\"; known:\n{}", opt.preset, list);
    return 2;
  }

  vkcloth::ClothDesc desc; // 10 x 10, vertical, pinned at its two top corners, 0.05 kg per point
  desc.origin = {-0.5, 0.0, 0.5};
  desc.stiffness = {40, 8, 8};
  vkcloth::SimParams params; // semi-implicit Euler, dt = 0.02, mu = 0.5, gravity -9.81 z
  chosen->apply(desc, params);
  if (auto v = params.validate(); !v) {
    fmt::print(stderr, "error: {}\n", v.error().message);
    return 2;
  }
  auto system = vkcloth::make_cloth(desc);
  if (!system) {
    fmt::print(stderr, "error: {}\n", system.error().message);
    return 2;
  }
  vkcloth::Scene scene{"cloth_" + opt.preset, std::move(*system), params, 500, std::nullopt, {}};
  return samples::run(scene, opt);
}
