// SPDX-License-Identifier: MIT
// The scene's "colliders" array: the analytic shapes (plane, sphere, capsule, box) and mesh
// colliders, each with the friction and motion keys every collider takes. A mesh collider's file is
// read with read_mesh() relative to the scene file and built once per file and scale. Shapes and
// required keys are checked here, ranges by SimParams::validate().
#include <map>
#include <memory>

#include <fmt/format.h>

#include "scene_sections.hpp"
#include "vkcloth/collider_mesh.hpp"

namespace vkcloth::scene_detail {
namespace {

constexpr const char* collider_types = R"("plane", "sphere", "capsule", "box" or "mesh")";

/// The keys every collider takes besides its shape's: friction and motion.
#define VKCLOTH_COLLIDER_COMMON_KEYS                                                                         \
  "type", "friction", "static_friction", "linear_velocity", "angular_velocity", "keyframes"

/// "keyframes": [{"t": T, "translate": [x, y, z], "rotate_deg": [a, b, c]}, ...] (Collider::with_keyframes).
Result<void> read_keyframes(const json& keys, const std::string& path, Collider& col) {
  if (!keys.is_array())
    return sd::shape_error(
        fmt::format("{}.keyframes must be an array of keys, got {}", path, sd::show(keys)));
  std::vector<ColliderKeyframe> frames;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const json& key = keys[k];
    const std::string at = fmt::format("{}.keyframes[{}]", path, k);
    if (!key.is_object())
      return sd::shape_error(fmt::format("{} must be an object, got {}", at, sd::show(key)));
    VKCLOTH_TRY(sd::check_keys(key, at, {"t", "translate", "rotate_deg", "teleport"}));
    VKCLOTH_TRY(sd::require_keys(key, at, {"t"}, "a keyframe"));
    ColliderKeyframe f;
    VKCLOTH_TRY(sd::read(key, at, "t", f.t));
    VKCLOTH_TRY(sd::read(key, at, "translate", f.translate));
    VKCLOTH_TRY(sd::read(key, at, "rotate_deg", f.rotate_deg));
    VKCLOTH_TRY(sd::read(key, at, "teleport", f.teleport));
    frames.push_back(f);
  }
  auto moved = col.with_keyframes(std::move(frames));
  if (!moved)
    return make_error(ErrorCode::invalid_argument, fmt::format("{}.{}", path, moved.error().message));
  col = std::move(*moved);
  return {};
}

Result<void> read_collider_common(const json& c, const std::string& path, Collider& col) {
  VKCLOTH_TRY(sd::read(c, path, "friction", col.friction));
  if (c.contains("static_friction")) {
    double mu_s = 0.0;
    VKCLOTH_TRY(sd::read(c, path, "static_friction", mu_s));
    // Collider::static_friction < 0 means "the same as friction"; a scene says that by omitting the
    // key, so a negative value here is a mistake. >= friction is validate()'s check.
    if (mu_s < 0.0)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("{}.static_friction must be >= 0 and >= friction (omit it to use "
                                    "friction), got {}",
                                    path, mu_s));
    col.static_friction = mu_s;
  }
  VKCLOTH_TRY(sd::read(c, path, "linear_velocity", col.linear_velocity));
  return sd::read(c, path, "angular_velocity", col.angular_velocity);
}

/// Mesh files already read for this scene, by resolved path and scale (a mesh used twice is built once).
using ColliderMeshCache = std::map<std::pair<std::string, double>, std::shared_ptr<const ColliderMesh>>;

/// {"type": "mesh", "path": ..., "transform": {...}, "thickness": t}: the file read with read_mesh(),
/// scaled into a ColliderMesh; translate is where its origin goes, rotate_deg its rotation. Sets the
/// shape's fields of `col` (its friction and motion are left as they are).
Result<void> read_mesh_collider(const json& c, const std::string& path,
                                const std::filesystem::path& scene_dir, ColliderMeshCache& cache,
                                std::vector<std::string>& warnings, Collider& col) {
  VKCLOTH_TRY(sd::require_keys(c, path, {"path", "thickness"}, "a mesh collider"));
  std::string file;
  VKCLOTH_TRY(sd::read(c, path, "path", file));
  glm::dvec3 translate{0.0}, rotate_deg{0.0};
  double scale = 1.0, thickness = 0.0;
  VKCLOTH_TRY(sd::read_transform(c, path, "transform", translate, rotate_deg, scale));
  VKCLOTH_TRY(sd::read(c, path, "thickness", thickness));
  // Checked before the file is read (validate() would say the same after).
  if (!(scale > 0.0))
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("{}.transform.scale must be finite and > 0, got {}", path, scale));
  if (!(thickness > 0.0))
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("{}.thickness must be finite and > 0, got {}", path, thickness));
  const std::filesystem::path where = scene_relative(file, scene_dir);
  std::shared_ptr<const ColliderMesh>& shape = cache[{where.string(), scale}];
  if (!shape) {
    // The reader's message names the file and the line (or the glTF element); the key goes first.
    const auto wrap = [&](const Error& e) {
      return Error{e.code, fmt::format("{}.path: {}", path, e.message), e.vk_result};
    };
    auto mesh = read_mesh(where);
    if (!mesh)
      return wrap(mesh.error());
    auto built = ColliderMesh::from_mesh(*mesh, scale, file);
    if (!built)
      return wrap(built.error());
    shape = std::move(*built);
    if (const std::uint32_t dropped = shape->dropped_triangles())
      warnings.push_back(fmt::format("{}: dropped {} zero-area triangle{} of {}", path, dropped,
                                     dropped == 1 ? "" : "s", file));
  }
  col.type = Collider::Type::mesh;
  col.mesh = shape;
  col.center = translate;
  col.rotation = Collider::rotation_from_degrees(rotate_deg);
  col.thickness = thickness;
  return {};
}

} // namespace

/// "colliders": each a shape (docs/scene-format.md "colliders") with friction and motion. Shapes and
/// required keys are checked here, ranges by SimParams::validate().
Result<void> read_colliders(const json& doc, const std::filesystem::path& scene_dir, Scene& scene) {
  SCENE_TRY_ASSIGN(arr, sd::read_array(doc, "", "colliders"));
  if (!arr)
    return {};
  ColliderMeshCache meshes;
  for (std::size_t k = 0; k < arr->size(); ++k) {
    const json& c = (*arr)[k];
    const std::string path = fmt::format("colliders[{}]", k);
    if (!c.is_object())
      return sd::shape_error(fmt::format("{} must be an object, got {}", path, sd::show(c)));
    if (!c.contains("type"))
      return sd::shape_error(fmt::format("{}.type is required ({})", path, collider_types));
    std::string type;
    VKCLOTH_TRY(sd::read(c, path, "type", type));
    Collider col;
    if (type == "plane") {
      VKCLOTH_TRY(sd::check_keys(c, path, {VKCLOTH_COLLIDER_COMMON_KEYS, "normal", "offset"}));
      col = Collider::plane(up_vector(scene.up), 0.0); // default: the ground, facing up
      VKCLOTH_TRY(sd::read(c, path, "normal", col.normal));
      VKCLOTH_TRY(sd::read(c, path, "offset", col.offset));
    } else if (type == "sphere") {
      VKCLOTH_TRY(sd::check_keys(c, path, {VKCLOTH_COLLIDER_COMMON_KEYS, "center", "radius"}));
      VKCLOTH_TRY(sd::require_keys(c, path, {"center", "radius"}, "a sphere"));
      col = Collider::sphere({}, 0.0);
      VKCLOTH_TRY(sd::read(c, path, "center", col.center));
      VKCLOTH_TRY(sd::read(c, path, "radius", col.radius));
    } else if (type == "capsule") {
      VKCLOTH_TRY(sd::check_keys(c, path, {VKCLOTH_COLLIDER_COMMON_KEYS, "a", "b", "radius"}));
      VKCLOTH_TRY(sd::require_keys(c, path, {"a", "b", "radius"}, "a capsule"));
      col = Collider::capsule({}, {}, 0.0);
      VKCLOTH_TRY(sd::read(c, path, "a", col.a));
      VKCLOTH_TRY(sd::read(c, path, "b", col.b));
      VKCLOTH_TRY(sd::read(c, path, "radius", col.radius));
    } else if (type == "box") {
      VKCLOTH_TRY(
          sd::check_keys(c, path, {VKCLOTH_COLLIDER_COMMON_KEYS, "center", "half_extents", "rotation_deg"}));
      VKCLOTH_TRY(sd::require_keys(c, path, {"center", "half_extents"}, "a box"));
      glm::dvec3 center{0.0}, half_extents{0.0}, rotation_deg{0.0};
      VKCLOTH_TRY(sd::read(c, path, "center", center));
      VKCLOTH_TRY(sd::read(c, path, "half_extents", half_extents));
      VKCLOTH_TRY(sd::read(c, path, "rotation_deg", rotation_deg));
      col = Collider::box(center, half_extents, Collider::rotation_from_degrees(rotation_deg));
    } else if (type == "mesh") {
      VKCLOTH_TRY(sd::check_keys(c, path, {VKCLOTH_COLLIDER_COMMON_KEYS, "path", "transform", "thickness"}));
    } else {
      return sd::shape_error(
          fmt::format("{}.type must be {}, got {}", path, collider_types, sd::show(c["type"])));
    }
    VKCLOTH_TRY(read_collider_common(c, path, col));
    if (type == "mesh") // the file last, once every other key of this collider is known to be well formed
      VKCLOTH_TRY(read_mesh_collider(c, path, scene_dir, meshes, scene.warnings, col));
    if (c.contains("keyframes")) // the shape complete: the keys move it
      VKCLOTH_TRY(read_keyframes(c["keyframes"], path, col));
    scene.params.colliders.push_back(std::move(col));
  }
  return {};
}

#undef VKCLOTH_COLLIDER_COMMON_KEYS

} // namespace vkcloth::scene_detail
