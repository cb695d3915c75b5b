// SPDX-License-Identifier: MIT
// `vkcloth figures`: the report's figures, regenerated as SVG plots and image grids, with an
// index.html gallery and a figures.json of the numbers behind them (checked by the tests).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../backend.hpp"
#include "vkcloth/builders.hpp"

namespace vkcloth::figures {

/// One picture of the gallery.
struct Figure {
  std::string file;    ///< relative to the output directory
  std::string section; ///< "Single spring (§2.2)", ...
  std::string title;
  std::string caption; ///< the parameters, in words
};

struct Gallery {
  std::filesystem::path dir;
  std::string backend; ///< "cpu" | "vulkan"
  std::vector<Figure> figures;
  nlohmann::json metrics = nlohmann::json::object(); ///< the numbers behind the pictures
  bool quick = false; ///< --quick: smaller cloth pictures (same physics, same numbers)
  std::filesystem::path samples =
      VKCLOTH_SAMPLES_DIR; ///< --samples: scenes/ and meshes/ of the mesh and contact figures
  /// --self-collision-steps: run the self-collision samples for at most this many steps (0: the
  /// scene's own steps; the tests use fewer, the full runs take a minute on the CPU solver)
  std::uint64_t self_collision_steps = 0;

  Result<void> write_text(const std::string& file, const std::string& text) const;
  Result<void> write_index() const; ///< index.html and figures.json
};

/// A run of one backend: state after each recorded step (every `every` steps).
struct Trace {
  std::vector<double> t;
  std::vector<std::vector<glm::dvec3>> positions, velocities;
  std::string diverged; ///< the error message when the run blew up
  double diverged_at = -1.0;
};
Result<Trace> simulate(const Scene& scene, const std::string& backend, std::uint64_t steps,
                       std::uint64_t every);

/// Kinetic + gravitational + spring energy of a state of `scene`'s system.
double total_energy(const Scene& scene, const std::vector<glm::dvec3>& pos,
                    const std::vector<glm::dvec3>& vel);

Result<void> spring_figures(Gallery& gallery);
/// Figures 5, 7-9, 11-14, the mesh samples (samples/scenes/{tablecloth_on_sphere, flag_with_hole,
/// skirt}.json), Figure 7 with and without the strain limit, cotton at three resolutions and the
/// material presets over the sphere: labelled image grids (rendered offscreen; skipped without a Vulkan
/// device on the CPU backend, the numbers are computed either way) and metrics["cloth"].
Result<void> cloth_figures(Gallery& gallery);
/// Contact that holds: samples/scenes/{tablecloth_on_table (friction 0.6 and 0),
/// cloth_on_sphere and cloth_on_sphere_friction, cloth_on_rotating_sphere (friction 0.8 and 0),
/// flag_on_pole, cloth_on_mesh (the chair, and the torus knot by an override)}.json, each run to its
/// end on G.backend with the contact measured after every step: image grids (contact.cpp) and
/// metrics["contact"].
Result<void> contact_figures(Gallery& gallery);
/// Self-collision: samples/scenes/{cloth_drop_self_collision, cloth_slide_self_collision}.json,
/// each run for its own steps on the CPU solver without (--set self_collision.enabled=false) and with
/// self-collision: two-panel image grids (self_collision.cpp) and metrics["self_collision"], with the
/// intersecting triangle pairs of each final state.
Result<void> self_collision_figures(Gallery& gallery);
/// The (K_struct, dt) stability map of semi-implicit Euler, RK4 and implicit Euler (stability.cpp).
Result<void> stability_figures(Gallery& gallery);
/// Cloth on a moving character: samples/scenes/character_cape.json on the CPU solver,
/// measured every step, drawn at four instants centred on the torso (character.cpp) and
/// metrics["character"].
Result<void> character_figures(Gallery& gallery);
/// Real fabric: a cotton drop onto a sphere by semi-implicit Euler with substeps, implicit
/// Euler by CG and vbd (two settings), always on the CPU solver: the largest strain and the wall time
/// over the run (SVG), the final states (an image grid) and metrics["stiff"] (stiff.cpp).
Result<void> stiff_figures(Gallery& gallery);

} // namespace vkcloth::figures
