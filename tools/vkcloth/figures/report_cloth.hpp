// SPDX-License-Identifier: MIT
// The report's cloth as the cloth figures build it (cloth.cpp), and the numbers they quote, shared
// with the material figures (materials.cpp).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "cloth_drawing.hpp"
#include "figures.hpp"
#include "vkcloth/builders.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::figures {

/// A scene of one cloth `d` with parameters `p` (checked), named `name`.
Scene cloth_scene(const ClothDesc& d, SimParams p, std::string name);
/// The report's cloth: 10 x 10 points over 1 x 1, 0.05 kg per point, hanging (vertical) from its
/// two top corners, or horizontal at height z with nothing pinned.
ClothDesc hanging(double ks, double ksh, double kb);
ClothDesc horizontal(double z, double ks = 40, double ksh = 8, double kb = 8);
/// The report's integration: semi-implicit Euler at dt, fluid damping mu = 0.5.
SimParams report_params(double dt = 0.02);
/// The largest downward displacement of a particle of the run since its start (m).
double sag(const Run& r);
/// A number as figures.json's keys write it ("{:g}").
std::string key(double v);

/// The stretch-control and material figures (materials.cpp), into the cloth gallery's metrics M.
Result<void> material_figures(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note,
                              const Progress& progress);

} // namespace vkcloth::figures
