// SPDX-License-Identifier: MIT
// What stretch control derives from a system's connectivity (ClothTopology, docs/model.md
// "Stretch control"): the strain links in colours, and the tethers. Internal to the engine.
#pragma once

#include <cstdint>
#include <vector>

#include "vkcloth/topology.hpp"

namespace vkcloth::detail {

/// The system's strain links (structural and chain springs) grouped by a greedy colouring in
/// spring order: `links` sorted by colour (stable), `offsets` the colours' ranges (colours + 1
/// entries; one zero entry without links).
void colour_strain_links(const ParticleSystem& system, std::vector<StrainLink>& links,
                         std::vector<std::uint32_t>& offsets);

/// A grid's strain links along its rows, then its columns (StrainChainShape; nothing without a
/// grid), from `links` (a missing one: (p, p, 0)).
void chain_strain_links(const ParticleSystem& system, const std::vector<StrainLink>& links,
                        std::vector<StrainLink>& chains, StrainChainShape& shape);

/// Whether `sl` can run on `topology`: Provot's sweeps in chain order need a grid (the error names
/// stretch_limit.order). Both solvers check it when made and when their parameters change.
Result<void> check_sweep_order(const StretchLimit& sl, const ClothTopology& topology);

/// Each of `particles` particles' links, in link order: offsets (particles + 1 entries) and
/// entries 2 l + (1 when the particle is link l's end b).
void link_incidence(std::size_t particles, const std::vector<StrainLink>& links,
                    std::vector<std::uint32_t>& offsets, std::vector<std::uint32_t>& entries);

/// tethers_per_particle slots per particle: the nearest pinned particles along the springs
/// (structural, shear, chain) with euclidean or geodesic rest distances.
std::vector<Tether> find_tethers(const ParticleSystem& system, bool geodesic);

} // namespace vkcloth::detail
