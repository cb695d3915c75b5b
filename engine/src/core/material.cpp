// SPDX-License-Identifier: MIT
// Materials -> springs (docs/model.md "Materials"; the preset sources are in
// docs/scene-format.md "Materials").
#include "vkcloth/material.hpp"

#include <array>
#include <cmath>

#include <fmt/format.h>

#include "internal/argument_checks.hpp"

namespace vkcloth {
using detail::bad_argument;
namespace {

struct Preset {
  std::string_view name;
  Material material;
};

// density kg/m^2, stretch N/m, shear N/m, bend N m, damping 1/s.
// report: the report's 40 / 8 / 8 and 0.05 kg per interior point on its 10 x 10 grid over 1 m
// (h = 1/9): G = 8; B = K_b kappa_ref^2 h^4 / 8 with K_b = 8; C = 40 + 8 + 4 * 8 = 80, E = C - G^2 / C.
constexpr std::array presets{
    Preset{"cotton", {0.15, 500.0, 50.0, 1e-5, 0.5}},
    Preset{"silk", {0.05, 300.0, 20.0, 3e-6, 0.5}},
    Preset{"denim", {0.40, 2000.0, 150.0, 1e-4, 0.5}},
    Preset{"leather", {0.80, 10000.0, 3000.0, 1e-3, 0.5}},
    Preset{"rubber", {1.10, 1500.0, 500.0, 1.7e-4, 0.5}},
    Preset{"report",
           {0.05 * 81.0, 80.0 - 64.0 / 80.0, 8.0,
            8.0 * bend_reference_curvature* bend_reference_curvature / (81.0 * 81.0 * 8.0), 0.5}},
};

constexpr std::array<std::string_view, presets.size()> names = [] {
  std::array<std::string_view, presets.size()> n{};
  for (std::size_t k = 0; k < presets.size(); ++k)
    n[k] = presets[k].name;
  return n;
}();

/// C11 of the lattice for the uniaxial-stress modulus E: C - C12^2 / C = E with C12 = G.
double membrane_c11(const Material& m) {
  return 0.5 * (m.stretch + std::sqrt(m.stretch * m.stretch + 4.0 * m.shear * m.shear));
}

double bend_spring(const Material& m, double along, double across) {
  const double k2 = bend_reference_curvature * bend_reference_curvature;
  return 8.0 * m.bend * across / (k2 * std::pow(along, 5.0));
}

} // namespace

std::span<const std::string_view> material_preset_names() {
  return names;
}

std::optional<Material> material_preset(std::string_view name) {
  for (const Preset& p : presets)
    if (p.name == name)
      return p.material;
  return std::nullopt;
}

std::string material_preset_list() {
  std::string s;
  for (std::string_view n : names)
    s += fmt::format("{}{}", s.empty() ? "" : ", ", n);
  return s;
}

Result<void> check_material(const Material& m, std::string_view key) {
  const std::pair<const char*, double> fields[] = {{"density", m.density},
                                                   {"stretch", m.stretch},
                                                   {"shear", m.shear},
                                                   {"bend", m.bend},
                                                   {"damping", m.damping}};
  for (auto [name, v] : fields)
    if (!std::isfinite(v) || v <= 0.0)
      return bad_argument(fmt::format("{}.{} must be finite and > 0, got {}", key, name, v));
  return {};
}

Result<double> spring_stiffness(const Material& m, SpringKind kind, double along, double across,
                                std::string_view key) {
  if (!(along > 0.0) || !(across > 0.0) || !std::isfinite(along) || !std::isfinite(across))
    return bad_argument(
        fmt::format("{}: spring spacing must be finite and > 0, got {} and {}", key, along, across));
  switch (kind) {
  case SpringKind::bend:
    return bend_spring(m, along, across);
  case SpringKind::shear:
    return m.shear * (along * along + across * across) / (2.0 * along * across);
  case SpringKind::structural: {
    const double c = membrane_c11(m);
    const double kb = bend_spring(m, along, across);
    const double ks = c * across / along - m.shear * along / across - 4.0 * kb;
    if (ks >= 0.0)
      return ks;
    // Square grid: 4 K_b(h) = C - G at h_min = (32 B / (kappa_ref^2 (C - G)))^(1/4).
    const double h_min =
        std::pow(32.0 * m.bend / (bend_reference_curvature * bend_reference_curvature * (c - m.shear)), 0.25);
    return bad_argument(fmt::format(
        "{}: at spacing {:.4g} m the bend springs (K = {:.4g} N/m each, from bend = {} N m) are stiffer "
        "in-plane than the membrane (stretch = {} N/m, shear = {} N/m) allows: the structural springs "
        "would need K = {:.4g} N/m < 0; use a spacing of at least {:.3g} m (a coarser grid) or a smaller "
        "bend",
        key, along, kb, m.bend, m.stretch, m.shear, ks, h_min));
  }
  case SpringKind::plain:
    break;
  }
  return bad_argument(fmt::format("{}: no material stiffness for a {} spring", key, to_string(kind)));
}

} // namespace vkcloth
