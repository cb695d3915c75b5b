// SPDX-License-Identifier: MIT
// Scene files: a JSON description of a system (chain or cloth) and its simulation parameters.
// The format is documented key by key in docs/scene-format.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <optional>
#include <vector>

#include "vkcloth/mesh.hpp"
#include "vkcloth/builders.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// A loaded, validated scene: ready to hand to a solver.
struct Scene {
  std::string name;      ///< "name" key, else the file stem (or the source name)
  ParticleSystem system; ///< finalized
  SimParams params;      ///< validated (directions normalised)
  std::uint64_t steps = 500;
  /// A mesh cloth's base-colour texture (a glTF material's), for the renderer and the exporter.
  std::optional<MeshTexture> texture;
  /// What loading dropped or ignored (degenerate faces, a pin region that pins nothing, ...):
  /// the CLI prints each as "warning: ...".
  std::vector<std::string> warnings;
  /// The file's "up" ("z" by default): the grid's plane, gravity's and a plane's default follow it.
  /// Last, so that hosts' aggregate initialisers of the fields above keep compiling.
  UpAxis up = UpAxis::z;
  /// A "cloths" scene (several cloths joined into `system`, cloth by cloth): the first particle of
  /// each cloth, then the particle count (cloth k is particles cloths[k] .. cloths[k+1]). Empty for
  /// a scene of one cloth or a chain.
  std::vector<std::uint32_t> cloths = {}; // "= {}": hosts' aggregate initialisers need not name it
  // The file's "system" key ("chain" | "cloth") is not stored: a cloth is system.grid.has_value().
};

/// Largest "integrator.steps" a scene may ask for.
inline constexpr std::uint64_t max_scene_steps = 1'000'000'000;

/// Largest scene text accepted (bytes), by parse_scene() and load_scene_file() (which checks the
/// file size before reading). The samples are under 2 KiB; a 8192 x 8192 cloth is a few lines.
inline constexpr std::size_t max_scene_bytes = std::size_t{16} << 20;

/// Parses and validates a scene. `overrides` are "key.path=value" strings (e.g.
/// "cloth.stiffness.bend=15", "colliders.0.radius=0.3", "colliders[0].radius=0.3"); each value is
/// parsed as JSON, or taken as a plain string when it is not JSON. They are applied to the document
/// before validation, so errors name the key. Errors: ErrorCode::parse (bad JSON, unknown key,
/// wrong type, bad override, text over max_scene_bytes, nesting deeper than 64 levels) or
/// ErrorCode::invalid_argument (a value out of range); ErrorCode::out_of_memory if the host runs
/// out of memory. Never throws.
Result<Scene> parse_scene(std::string_view json_text, std::string_view source_name,
                          std::span<const std::string> overrides = {});

/// Reads `path` and calls parse_scene(). A missing or unreadable file, a directory or a file larger
/// than max_scene_bytes is ErrorCode::io (checked before reading).
Result<Scene> load_scene_file(const std::filesystem::path& path, std::span<const std::string> overrides = {});

} // namespace vkcloth
