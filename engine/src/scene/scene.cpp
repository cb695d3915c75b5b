// SPDX-License-Identifier: MIT
// Scene JSON -> Scene: the public entry points (parse_scene, load_scene_file) with their size
// limits and error framing (source name, line:column, out of memory), and build_scene(), which
// checks the top level and calls the section readers (scene_sections.hpp) in order. Shape checks
// (keys, types, finiteness) happen in the readers; range checks are left to SimParams::validate(),
// make_chain() and make_cloth(), whose messages use the same key names.
#include "vkcloth/scene.hpp"

#include <fstream>
#include <new>

#include <fmt/format.h>

#include "internal/json_parse.hpp"
#include "overrides.hpp"
#include "scene_sections.hpp"

namespace vkcloth {
using sd::json;

namespace {

/// self_collision.thickness against the built system's spring lengths: an error, or warnings added
/// to the scene's.
Result<void> check_scene_self_collision(Scene& scene) {
  SCENE_TRY_ASSIGN(warnings, check_self_collision(scene.params.self_collision, scene.system));
  scene.warnings.insert(scene.warnings.end(), warnings.begin(), warnings.end());
  return {};
}

Result<Scene> build_scene(const json& doc, std::string_view source_name) {
  if (!doc.is_object())
    return sd::shape_error(fmt::format("the scene must be a JSON object, got {}", doc.type_name()));
  VKCLOTH_TRY(sd::check_keys(doc, "",
                             {"name", "system", "integrator", "physics", "chain", "cloth", "cloths", "wind",
                              "colliders", "contact_epsilon", "contact_inward_only", "divergence_limit",
                              "stretch_limit", "self_collision", "up", "inertia"}));
  Scene scene;
  if (!doc.contains("system"))
    return sd::shape_error("missing required key system (\"chain\" or \"cloth\")");
  std::string kind;
  VKCLOTH_TRY(sd::read(doc, "", "system", kind));
  if (kind != "chain" && kind != "cloth")
    return sd::shape_error(fmt::format("system must be \"chain\" or \"cloth\", got \"{}\"", kind));
  const std::vector<const char*> others =
      kind == "chain" ? std::vector<const char*>{"cloth", "cloths"} : std::vector<const char*>{"chain"};
  for (const char* other : others)
    if (doc.contains(other))
      return sd::shape_error(
          fmt::format("a \"{}\" section is not allowed in a scene whose system is \"{}\"", other, kind));
  const bool several = doc.contains("cloths");
  if (several && doc.contains("cloth"))
    return sd::shape_error(
        "cloth and cloths exclude each other: give one cloth as \"cloth\" or a list as \"cloths\"");

  scene.name = std::filesystem::path(source_name).stem().string();
  VKCLOTH_TRY(sd::read(doc, "", "name", scene.name));
  // "up" first: the defaults that follow it (gravity, a plane's normal, the grid's plane).
  if (doc.contains("up")) {
    std::string up;
    VKCLOTH_TRY(sd::read(doc, "", "up", up));
    const std::optional<UpAxis> axis = parse_up_axis(up);
    if (!axis)
      return sd::shape_error(fmt::format("up must be \"z\" or \"y\" (the world's up axis), got \"{}\"", up));
    scene.up = *axis;
  }
  scene.params.gravity = default_gravity(scene.up); // physics.gravity, when given, replaces it
  VKCLOTH_TRY(sd::read_integrator(doc, scene.params, scene.steps));
  VKCLOTH_TRY(sd::read_physics(doc, scene.params));
  std::optional<Material> material; // cloth.material: its damping is mu, so it is read before validate()
  if (const json* cloth = kind == "cloth" && doc.contains("cloth") ? &doc["cloth"] : nullptr;
      cloth && cloth->is_object()) {
    SCENE_TRY_ASSIGN(m, sd::read_material(*cloth));
    material = m;
  }
  SCENE_TRY_ASSIGN(cloths_damping, sd::read_cloths_damping(doc));
  if (material || cloths_damping) {
    const double damping = material ? material->damping : *cloths_damping;
    if (const auto it = doc.find("physics"); it != doc.end() && it->contains("damping"))
      return sd::shape_error(fmt::format("physics.damping and {}.material exclude each other: the "
                                         "material's damping ({} 1/s) is mu",
                                         several ? "cloths[k]" : "cloth", damping));
    scene.params.damping = damping;
  }
  VKCLOTH_TRY(sd::read_wind(doc, scene.params));
  const std::filesystem::path scene_dir = std::filesystem::path(source_name).parent_path();
  VKCLOTH_TRY(sd::read_colliders(doc, scene_dir, scene));
  VKCLOTH_TRY(sd::read_inertia(doc, scene.params));
  VKCLOTH_TRY(sd::read_stretch_limit(doc, scene.params));
  VKCLOTH_TRY(sd::read_self_collision(doc, scene.params));
  VKCLOTH_TRY(sd::read(doc, "", "contact_epsilon", scene.params.contact_epsilon));
  VKCLOTH_TRY(sd::read(doc, "", "divergence_limit", scene.params.divergence_limit));
  VKCLOTH_TRY(sd::read(doc, "", "contact_inward_only", scene.params.contact_inward_only));
  VKCLOTH_TRY(scene.params.validate()); // ranges, before any large allocation below

  if (several) {
    VKCLOTH_TRY(sd::read_cloths(doc, scene_dir, scene));
    VKCLOTH_TRY(scene.system.validate());
  } else if (const json* cloth = kind == "cloth" && doc.contains("cloth") ? &doc["cloth"] : nullptr;
             cloth && cloth->is_object() && cloth->contains("mesh")) {
    VKCLOTH_TRY(sd::read_mesh_cloth(*cloth, scene_dir, material, scene));
  } else {
    auto system = kind == "chain" ? sd::read_chain(doc, scene.up) : sd::read_cloth(doc, material, scene.up);
    if (!system)
      return system.error();
    scene.system = std::move(*system);
  }
  if (const json* cloth = kind == "cloth" && doc.contains("cloth") ? &doc["cloth"] : nullptr;
      cloth && cloth->is_object()) {
    VKCLOTH_TRY(sd::read_attachments(*cloth, scene));
    VKCLOTH_TRY(scene.system.validate());
  }
  VKCLOTH_TRY(sd::carry_attached_teleports(scene, several));
  VKCLOTH_TRY(scene.params.validate()); // the frame it may have set
  VKCLOTH_TRY(check_scene_self_collision(scene));
  return scene;
}

Error with_source(Error e, std::string_view source) {
  e.message = fmt::format("{}: {}", source, e.message);
  return e;
}

} // namespace

Result<Scene> parse_scene(std::string_view json_text, std::string_view source_name,
                          std::span<const std::string> overrides) {
  try {
    if (json_text.size() > max_scene_bytes)
      return make_error(ErrorCode::parse,
                        fmt::format("{}: the scene is {} bytes, more than the limit {} ({} MiB)", source_name,
                                    json_text.size(), max_scene_bytes, max_scene_bytes >> 20));
    json doc;
    if (sd::JsonParseFailure f; !sd::parse_json(json_text, doc, f, /*unique_keys=*/true))
      return make_error(ErrorCode::parse, sd::describe(f, json_text, source_name));
    if (!doc.is_object())
      return with_source(
          sd::shape_error(fmt::format("the scene must be a JSON object, got {}", doc.type_name())),
          source_name);
    for (const std::string& o : overrides)
      if (auto r = sd::apply_override(doc, o); !r)
        return with_source(r.error(), source_name);
    auto scene = build_scene(doc, source_name);
    if (!scene)
      return with_source(scene.error(), source_name);
    return scene;
  } catch (const std::bad_alloc&) {
    return make_error(ErrorCode::out_of_memory,
                      fmt::format("{}: out of memory while loading the scene", source_name));
  } catch (const std::exception& e) {
    return make_error(ErrorCode::parse, fmt::format("{}: {}", source_name, e.what()));
  }
}

Result<Scene> load_scene_file(const std::filesystem::path& path, std::span<const std::string> overrides) {
  try {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      return make_error(ErrorCode::io, fmt::format("{}: is a directory, not a scene file", path.string()));
    if (const auto size = std::filesystem::file_size(path, ec); !ec && size > max_scene_bytes)
      return make_error(ErrorCode::io,
                        fmt::format("{}: the file is {} bytes, more than the scene size limit {} ({} MiB)",
                                    path.string(), size, max_scene_bytes, max_scene_bytes >> 20));
    std::ifstream in(path, std::ios::binary);
    if (!in)
      return make_error(ErrorCode::io, fmt::format("{}: cannot open the scene file", path.string()));
    // Bounded read: a device or pipe (/dev/zero, a FIFO) has no size to check up front.
    std::string text;
    char chunk[1 << 16];
    while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
      text.append(chunk, static_cast<std::size_t>(in.gcount()));
      if (text.size() > max_scene_bytes)
        return make_error(ErrorCode::io, fmt::format("{}: more than the scene size limit {} bytes ({} MiB)",
                                                     path.string(), max_scene_bytes, max_scene_bytes >> 20));
    }
    if (in.bad())
      return make_error(ErrorCode::io, fmt::format("{}: read error", path.string()));
    return parse_scene(text, path.string(), overrides);
  } catch (const std::exception& e) {
    return make_error(ErrorCode::io, fmt::format("{}: {}", path.string(), e.what()));
  }
}

} // namespace vkcloth
