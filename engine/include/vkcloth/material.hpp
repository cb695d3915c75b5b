// SPDX-License-Identifier: MIT
// Physical cloth materials (docs/model.md "Materials"): areal density, membrane and bending
// stiffness and damping, independent of the resolution, turned into per-particle masses and
// per-spring stiffnesses for a grid's or a mesh's spacing.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// A cloth material in SI units. Every value must be finite and > 0 (check_material).
struct Material {
  double density = 0.0; ///< kg/m^2, areal density
  double stretch = 0.0; ///< N/m, membrane tensile stiffness (uniaxial stress: a strip free at its sides)
  double shear = 0.0;   ///< N/m, membrane in-plane shear stiffness
  double bend = 0.0;    ///< N m, bending stiffness (moment per unit width per unit curvature)
  double damping = 0.0; ///< 1/s, fluid damping mu (the force -mu m v); sets SimParams::damping
};

/// The curvature (1/m) at which the bend springs' moment equals `bend` times the curvature: a bend
/// spring's force is quadratic in the hinge angle, so it can match the continuum at one curvature
/// only. 20 1/m is a fold of radius 5 cm (docs/model.md "Materials").
inline constexpr double bend_reference_curvature = 20.0;

/// The preset names: cotton, silk, denim, leather, rubber, report (docs/scene-format.md "Materials").
std::span<const std::string_view> material_preset_names();
/// The preset called `name`, or nothing.
std::optional<Material> material_preset(std::string_view name);
/// "cotton, silk, ..." for messages.
std::string material_preset_list();

/// Every value finite and > 0; the message names `key`.<field> and the value.
Result<void> check_material(const Material& material, std::string_view key = "cloth.material");

/// The stiffness (N/m) of one spring of `kind` (structural, shear or bend) in a lattice of spacing
/// `along` (the spring's own direction: for a structural or bend spring its axis, for a shear
/// spring either side) and `across` (the other side), so that the lattice has the material's
/// membrane stiffness and bending stiffness at bend_reference_curvature:
///   bend        K_b = 8 B across / (kappa_ref^2 along^5)
///   shear       K_d = G (along^2 + across^2) / (2 along across)
///   structural  K_s = C across / along - G along / across - 4 K_b,   C = (E + sqrt(E^2 + 4 G^2)) / 2
/// A square grid of spacing h: K_b = 8 B / (kappa_ref^2 h^4), K_d = G, K_s = C - G - 4 K_b. A
/// negative K_s (the bend springs alone stiffer than the membrane, on fine grids) is an
/// ErrorCode::invalid_argument naming `key`, the values and the smallest spacing that works.
Result<double> spring_stiffness(const Material& material, SpringKind kind, double along, double across,
                                std::string_view key = "cloth.material");

} // namespace vkcloth
