// SPDX-License-Identifier: MIT
// The section readers of a scene document, which build_scene() (scene.cpp) calls in turn: the
// simulation parameters (scene_params.cpp), the colliders (scene_colliders.cpp) and the system, a
// chain or a grid or mesh cloth (scene_systems.cpp). Each checks its section's shape (keys, types,
// finiteness) and leaves the ranges to SimParams::validate(), make_chain() and make_cloth(), whose
// messages use the same key names.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "json_read.hpp"
#include "vkcloth/material.hpp"
#include "vkcloth/scene.hpp"

/// `auto& var = *(expr)` for a Result `expr`, or return its error.
#define SCENE_TRY_ASSIGN(var, expr)                                                                          \
  auto var##_r = (expr);                                                                                     \
  if (!var##_r)                                                                                              \
    return var##_r.error();                                                                                  \
  auto& var = *var##_r

namespace vkcloth::scene_detail {

/// "integrator": method, dt, substeps, CG settings into `params`; "steps" into `steps`.
Result<void> read_integrator(const json& doc, SimParams& params, std::uint64_t& steps);
/// "physics": gravity and damping.
Result<void> read_physics(const json& doc, SimParams& params);
/// "wind": strength and direction.
Result<void> read_wind(const json& doc, SimParams& params);
/// "stretch_limit" (absent: off).
Result<void> read_stretch_limit(const json& doc, SimParams& params);
/// "self_collision" (absent: off).
Result<void> read_self_collision(const json& doc, SimParams& params);

/// "colliders": each a shape (docs/scene-format.md "colliders") with friction and motion, appended
/// to scene.params.colliders; mesh colliders read their files relative to `scene_dir`.
Result<void> read_colliders(const json& doc, const std::filesystem::path& scene_dir, Scene& scene);

/// "cloth.material": a preset name or an object with all five values; absent: nothing.
Result<std::optional<Material>> read_material(const json& cloth);
/// "chain" -> make_chain().
Result<ParticleSystem> read_chain(const json& doc, UpAxis up);
/// A grid cloth: "cloth" -> make_cloth().
Result<ParticleSystem> read_cloth(const json& doc, const std::optional<Material>& material, UpAxis up);
/// A cloth made from a mesh file ("cloth": {"mesh": ...}) into scene.system, its warnings and texture.
Result<void> read_mesh_cloth(const json& cloth, const std::filesystem::path& scene_dir,
                             const std::optional<Material>& material, Scene& scene);

/// "cloths": the entries' materials' damping mu (they must agree), or nothing.
Result<std::optional<double>> read_cloths_damping(const json& doc);
/// "cloths": each entry a "cloth" section, joined into scene.system (particles cloth by cloth, one
/// surface), their attachments into scene.params (scene_cloths.cpp).
Result<void> read_cloths(const json& doc, const std::filesystem::path& scene_dir, Scene& scene);

/// "inertia": the collider whose frame the cloth is simulated in, and its scales.
Result<void> read_inertia(const json& doc, SimParams& params);
/// "cloth.attach" and "cloth.max_distance" into scene.params.attachments (the system and the
/// colliders built; pins the attached particles that have no max_distance).
Result<void> read_attachments(const json& cloth, Scene& scene);

/// A teleport key on a collider the cloth is attached to: the cloth jumps with it, unfelt. Without
/// an "inertia" that collider becomes the cloth's frame at full inertia (linear = angular = 1: the
/// motion of world space); another inertia collider, or several cloths, are refused naming both keys.
Result<void> carry_attached_teleports(Scene& scene, bool several_cloths);

/// A file a scene names ("cloth.mesh", "colliders[k].path"): relative to the scene file's directory,
/// or absolute.
inline std::filesystem::path scene_relative(const std::string& file, const std::filesystem::path& scene_dir) {
  const std::filesystem::path p(file);
  return p.is_absolute() ? p : scene_dir / p;
}

} // namespace vkcloth::scene_detail

namespace vkcloth {
namespace sd = scene_detail;
} // namespace vkcloth
