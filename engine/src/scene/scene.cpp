// SPDX-License-Identifier: MIT
// Scene JSON -> Scene. Shape checks (keys, types, finiteness) happen here; range checks are left to
// SimParams::validate(), make_chain() and make_cloth(), whose messages use the same key names.
#include "vkcloth/scene.hpp"

#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <sstream>

#include <fmt/format.h>

#include "json_parse.hpp"
#include "json_read.hpp"
#include "overrides.hpp"
#include "vkcloth/builders.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/material.hpp"

namespace vkcloth {
namespace sd = scene_detail;
using sd::json;

namespace {

#define SCENE_TRY_ASSIGN(var, expr)                                                                          \
  auto var##_r = (expr);                                                                                     \
  if (!var##_r)                                                                                              \
    return var##_r.error();                                                                                  \
  auto& var = *var##_r

Result<void> read_integrator(const json& doc, SimParams& params, std::uint64_t& steps) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "integrator"));
  if (!obj)
    return {};
  VKCLOTH_TRY(sd::check_keys(*obj, "integrator",
                             {"method", "dt", "steps", "substeps", "cg_tolerance", "cg_max_iterations"}));
  std::string method = to_string(params.integrator);
  VKCLOTH_TRY(sd::read(*obj, "integrator", "method", method));
  const auto integ = parse_integrator(method);
  if (!integ)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("integrator.method: unknown integrator \"{}\" (known: explicit_euler, "
                                  "semi_implicit_euler, rk4, implicit_euler)",
                                  method));
  params.integrator = *integ;
  VKCLOTH_TRY(sd::read(*obj, "integrator", "dt", params.dt));
  if (auto it = obj->find("substeps"); it != obj->end()) {
    SCENE_TRY_ASSIGN(n, sd::as_integer(*it, "integrator.substeps", 1000000));
    params.substeps = static_cast<std::uint32_t>(n);
  }
  VKCLOTH_TRY(sd::read(*obj, "integrator", "cg_tolerance", params.cg_tolerance));
  if (auto it = obj->find("cg_max_iterations"); it != obj->end()) {
    SCENE_TRY_ASSIGN(n, sd::as_integer(*it, "integrator.cg_max_iterations", 100000));
    params.cg_max_iterations = static_cast<std::uint32_t>(n);
  }
  if (auto it = obj->find("steps"); it != obj->end()) {
    SCENE_TRY_ASSIGN(n, sd::as_integer(*it, "integrator.steps", max_scene_steps));
    steps = n;
  }
  return {};
}

Result<void> read_physics(const json& doc, SimParams& params) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "physics"));
  if (!obj)
    return {};
  VKCLOTH_TRY(sd::check_keys(*obj, "physics", {"gravity", "damping"}));
  VKCLOTH_TRY(sd::read(*obj, "physics", "gravity", params.gravity));
  return sd::read(*obj, "physics", "damping", params.damping);
}

Result<void> read_wind(const json& doc, SimParams& params) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "wind"));
  if (!obj)
    return {};
  VKCLOTH_TRY(sd::check_keys(*obj, "wind", {"strength", "direction"}));
  VKCLOTH_TRY(sd::read(*obj, "wind", "strength", params.wind.strength));
  return sd::read(*obj, "wind", "direction", params.wind.direction);
}

// obj[key], a string, through `parse` into `out` (absent: `out` stays); a name `parse` refuses is
// an error listing the `choices`.
template <typename T, typename Parse>
Result<void> read_choice(const json& obj, const char* path, const char* key, Parse parse, const char* choices,
                         T& out) {
  if (!obj.contains(key))
    return {};
  std::string name;
  VKCLOTH_TRY(sd::read(obj, path, key, name));
  const std::optional<T> value = parse(name);
  if (!value)
    return sd::shape_error(fmt::format("{}.{} must be {}, got \"{}\"", path, key, choices, name));
  out = *value;
  return {};
}

// Absent: off (the report's model). Present: "method" is required, the rest have defaults.
Result<void> read_stretch_limit(const json& doc, SimParams& params) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "stretch_limit"));
  if (!obj)
    return {};
  const char* path = "stretch_limit";
  VKCLOTH_TRY(sd::check_keys(*obj, path, {"method", "max_strain", "iterations", "tether_distance"}));
  StretchLimit& sl = params.stretch_limit;
  const char* methods = "\"tethers\", \"provot\", \"both\", \"projection\" or \"off\"";
  if (!obj->contains("method"))
    return sd::shape_error(fmt::format("stretch_limit.method is required: {}", methods));
  VKCLOTH_TRY(read_choice(*obj, path, "method", parse_stretch_method, methods, sl.method));
  VKCLOTH_TRY(sd::read(*obj, path, "max_strain", sl.max_strain));
  if (obj->contains("iterations")) {
    SCENE_TRY_ASSIGN(it, sd::as_integer((*obj)["iterations"], "stretch_limit.iterations", 1000000));
    sl.iterations = static_cast<std::uint32_t>(it); // the range (1..100) is validate()'s
  }
  return read_choice(*obj, path, "tether_distance", parse_tether_distance, "\"euclidean\" or \"geodesic\"",
                     sl.tether_distance);
}

// Absent: off (the report's model). Present: on unless "enabled" is false; every other key has the
// SelfCollision default. The ranges are validate()'s; the thickness against the cloth's spacing is
// check_self_collision()'s, once the system is built.
Result<void> read_self_collision(const json& doc, SimParams& params) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "self_collision"));
  if (!obj)
    return {};
  const char* path = "self_collision";
  VKCLOTH_TRY(sd::check_keys(*obj, path, {"enabled", "thickness", "friction", "iterations"}));
  SelfCollision& sc = params.self_collision;
  sc.enabled = true;
  VKCLOTH_TRY(sd::read(*obj, path, "enabled", sc.enabled));
  VKCLOTH_TRY(sd::read(*obj, path, "thickness", sc.thickness));
  VKCLOTH_TRY(sd::read(*obj, path, "friction", sc.friction));
  if (obj->contains("iterations")) {
    SCENE_TRY_ASSIGN(it, sd::as_integer((*obj)["iterations"], "self_collision.iterations", 1000000));
    sc.iterations = static_cast<std::uint32_t>(it); // the range (1..16) is validate()'s
  }
  return {};
}

/// self_collision.thickness against the built system's spring lengths: an error, or warnings added
/// to the scene's.
Result<void> check_scene_self_collision(Scene& scene) {
  SCENE_TRY_ASSIGN(warnings, check_self_collision(scene.params.self_collision, scene.system));
  scene.warnings.insert(scene.warnings.end(), warnings.begin(), warnings.end());
  return {};
}

/// A file a scene names ("cloth.mesh", "colliders[k].path"): relative to the scene file's directory,
/// or absolute.
std::filesystem::path scene_relative(const std::string& file, const std::filesystem::path& scene_dir) {
  const std::filesystem::path p(file);
  return p.is_absolute() ? p : scene_dir / p;
}

constexpr const char* collider_types = R"("plane", "sphere", "capsule", "box" or "mesh")";

/// The keys every collider takes besides its shape's: friction and motion.
#define VKCLOTH_COLLIDER_COMMON_KEYS                                                                         \
  "type", "friction", "static_friction", "linear_velocity", "angular_velocity"

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
      col = Collider::plane({0.0, 0.0, 1.0}, 0.0);
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
    scene.params.colliders.push_back(std::move(col));
  }
  return {};
}

#undef VKCLOTH_COLLIDER_COMMON_KEYS

Result<ParticleSystem> read_chain(const json& doc) {
  ChainDesc d;
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "chain"));
  if (obj) {
    VKCLOTH_TRY(
        sd::check_keys(*obj, "chain", {"anchor", "masses", "stiffness", "rest_lengths", "positions"}));
    VKCLOTH_TRY(sd::read(*obj, "chain", "anchor", d.anchor));
    VKCLOTH_TRY(sd::read(*obj, "chain", "masses", d.masses));
    VKCLOTH_TRY(sd::read(*obj, "chain", "stiffness", d.stiffness));
    VKCLOTH_TRY(sd::read(*obj, "chain", "rest_lengths", d.rest_lengths));
    SCENE_TRY_ASSIGN(pos, sd::read_array(*obj, "chain", "positions"));
    if (pos) {
      d.positions.clear();
      for (std::size_t k = 0; k < pos->size(); ++k) {
        SCENE_TRY_ASSIGN(p, sd::as_vec3((*pos)[k], fmt::format("chain.positions[{}]", k)));
        d.positions.push_back(p);
      }
    } else {
      d.positions.clear(); // default: hanging straight down from the anchor, each spring at rest length
    }
  }
  return make_chain(d);
}

Result<void> read_stiffness(const json& cloth, ClothStiffness& k) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(cloth, "cloth", "stiffness"));
  if (!obj)
    return {};
  VKCLOTH_TRY(sd::check_keys(*obj, "cloth.stiffness", {"structural", "shear", "bend"}));
  VKCLOTH_TRY(sd::read(*obj, "cloth.stiffness", "structural", k.structural));
  VKCLOTH_TRY(sd::read(*obj, "cloth.stiffness", "shear", k.shear));
  return sd::read(*obj, "cloth.stiffness", "bend", k.bend);
}

/// "cloth.material": a preset name or an object with all five values (docs/scene-format.md
/// "Materials"); exclusive with the per-particle keys. Absent: nothing.
Result<std::optional<Material>> read_material(const json& cloth) {
  auto it = cloth.find("material");
  if (it == cloth.end())
    return std::optional<Material>{};
  for (const char* key : {"particle_mass", "stiffness", "density"})
    if (cloth.contains(key) && (std::string_view(key) != "density" || cloth.contains("mesh")))
      return sd::shape_error(
          fmt::format("cloth.material and cloth.{} exclude each other: give a material (it "
                      "sets the masses and stiffnesses) or the per-particle keys",
                      key));
  if (it->is_string()) {
    const std::string name = it->get<std::string>();
    if (auto m = material_preset(name))
      return std::optional<Material>(*m);
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("cloth.material: unknown preset \"{}\" (presets: {})", name, material_preset_list()));
  }
  if (!it->is_object())
    return sd::shape_error(fmt::format(
        "cloth.material must be a preset name (\"cotton\", ...) or an object, got {}", sd::show(*it)));
  VKCLOTH_TRY(sd::check_keys(*it, "cloth.material", {"density", "stretch", "shear", "bend", "damping"}));
  Material m;
  const std::pair<const char*, double*> fields[] = {{"density", &m.density},
                                                    {"stretch", &m.stretch},
                                                    {"shear", &m.shear},
                                                    {"bend", &m.bend},
                                                    {"damping", &m.damping}};
  for (auto [key, out] : fields) {
    if (!it->contains(key))
      return sd::shape_error(fmt::format(
          "cloth.material.{} is required (a material object gives density, stretch, shear, bend and damping)",
          key));
    VKCLOTH_TRY(sd::read(*it, "cloth.material", key, *out));
  }
  VKCLOTH_TRY(check_material(m));
  return std::optional<Material>(m);
}

Result<void> read_mesh_transform(const json& cloth, MeshTransform& t) {
  return sd::read_transform(cloth, "cloth", "mesh_transform", t.translate, t.rotate_deg, t.scale);
}

Result<void> read_mesh_pins(const json& cloth, MeshClothDesc& d) {
  SCENE_TRY_ASSIGN(pins, sd::read_array(cloth, "cloth", "pin_vertices"));
  if (pins) {
    if (pins->size() > max_particles)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("cloth.pin_vertices holds {} entries, more than the limit {}",
                                    pins->size(), max_particles));
    for (std::size_t k = 0; k < pins->size(); ++k) {
      SCENE_TRY_ASSIGN(v, sd::as_integer((*pins)[k], fmt::format("cloth.pin_vertices[{}]", k),
                                         std::numeric_limits<std::uint32_t>::max()));
      d.pin_vertices.push_back(static_cast<std::uint32_t>(v));
    }
  }
  SCENE_TRY_ASSIGN(region, sd::read_object(cloth, "cloth", "pin_region"));
  if (region) {
    VKCLOTH_TRY(sd::check_keys(*region, "cloth.pin_region", {"min", "max"}));
    for (const char* key : {"min", "max"})
      if (!region->contains(key))
        return sd::shape_error(fmt::format("cloth.pin_region.{} is required", key));
    PinRegion r;
    VKCLOTH_TRY(sd::read(*region, "cloth.pin_region", "min", r.min));
    VKCLOTH_TRY(sd::read(*region, "cloth.pin_region", "max", r.max));
    d.pin_region = r;
  }
  return {};
}

/// A cloth made from a mesh file ("cloth": {"mesh": ...}), the path relative to the scene file.
Result<void> read_mesh_cloth(const json& cloth, const std::filesystem::path& scene_dir,
                             const std::optional<Material>& material, Scene& scene) {
  for (const char* grid_key : {"resolution", "size", "origin", "orientation", "pins"})
    if (cloth.contains(grid_key))
      return sd::shape_error(fmt::format(
          "cloth.{} is a grid key, not allowed with cloth.mesh (the mesh gives the vertices; pin with "
          "cloth.pin_vertices or cloth.pin_region)",
          grid_key));
  VKCLOTH_TRY(sd::check_keys(cloth, "cloth",
                             {"mesh", "mesh_transform", "density", "particle_mass", "stiffness", "material",
                              "pin_vertices", "pin_region"}));
  std::string file;
  VKCLOTH_TRY(sd::read(cloth, "cloth", "mesh", file));
  MeshClothDesc d;
  d.material = material;
  VKCLOTH_TRY(read_mesh_transform(cloth, d.transform));
  if (cloth.contains("density") && cloth.contains("particle_mass"))
    return sd::shape_error("give cloth.density (kg/m^2) or cloth.particle_mass (kg per vertex), not both");
  if (cloth.contains("density")) {
    double density = 0.0;
    VKCLOTH_TRY(sd::read(cloth, "cloth", "density", density));
    d.density = density;
  }
  VKCLOTH_TRY(sd::read(cloth, "cloth", "particle_mass", d.particle_mass));
  VKCLOTH_TRY(read_stiffness(cloth, d.stiffness));
  VKCLOTH_TRY(read_mesh_pins(cloth, d));

  const std::filesystem::path path = scene_relative(file, scene_dir);
  auto mesh = read_mesh(path);
  if (!mesh)
    return mesh.error();
  auto made = make_mesh_cloth(*mesh, d);
  if (!made)
    return Error{made.error().code, fmt::format("{}: {}", path.string(), made.error().message), 0};
  scene.system = std::move(made->system);
  scene.warnings.insert(scene.warnings.end(), made->warnings.begin(), made->warnings.end());
  scene.texture = std::move(mesh->texture);
  return {};
}

Result<ParticleSystem> read_cloth(const json& doc, const std::optional<Material>& material) {
  ClothDesc d;
  d.material = material;
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "cloth"));
  if (obj) {
    VKCLOTH_TRY(sd::check_keys(
        *obj, "cloth",
        {"resolution", "size", "origin", "orientation", "particle_mass", "stiffness", "material", "pins"}));
    if (auto it = obj->find("resolution"); it != obj->end()) {
      if (!it->is_array() || it->size() != 2)
        return sd::shape_error(
            fmt::format("cloth.resolution must be an array of 2 integers [nx, ny], got {}", sd::show(*it)));
      // Sizes beyond uint32 are refused here; make_cloth() checks the real limits before allocating.
      SCENE_TRY_ASSIGN(
          nx, sd::as_integer((*it)[0], "cloth.resolution[0]", std::numeric_limits<std::uint32_t>::max()));
      SCENE_TRY_ASSIGN(
          ny, sd::as_integer((*it)[1], "cloth.resolution[1]", std::numeric_limits<std::uint32_t>::max()));
      d.nx = static_cast<std::uint32_t>(nx);
      d.ny = static_cast<std::uint32_t>(ny);
    }
    VKCLOTH_TRY(sd::read(*obj, "cloth", "size", d.size));
    VKCLOTH_TRY(sd::read(*obj, "cloth", "origin", d.origin));
    std::string orientation = "vertical";
    VKCLOTH_TRY(sd::read(*obj, "cloth", "orientation", orientation));
    if (orientation == "vertical")
      d.orientation = ClothOrientation::vertical;
    else if (orientation == "horizontal")
      d.orientation = ClothOrientation::horizontal;
    else
      return sd::shape_error(
          fmt::format("cloth.orientation must be \"vertical\" or \"horizontal\", got \"{}\"", orientation));
    VKCLOTH_TRY(sd::read(*obj, "cloth", "particle_mass", d.particle_mass));
    VKCLOTH_TRY(read_stiffness(*obj, d.stiffness));
    SCENE_TRY_ASSIGN(pins, sd::read_array(*obj, "cloth", "pins"));
    if (pins) {
      d.pin_default_corners = false; // "pins": [] means nothing pinned
      if (const std::uint64_t cells = std::uint64_t(d.nx) * d.ny; pins->size() > cells)
        return make_error(
            ErrorCode::invalid_argument,
            fmt::format("cloth.pins holds {} entries, more than the {} x {} grid's {} particles",
                        pins->size(), d.nx, d.ny, cells));
      for (std::size_t n = 0; n < pins->size(); ++n) {
        const json& p = (*pins)[n];
        const std::string path = fmt::format("cloth.pins[{}]", n);
        if (!p.is_array() || p.size() != 2)
          return sd::shape_error(
              fmt::format("{} must be an array of 2 integers [i, j], got {}", path, sd::show(p)));
        const auto lim = std::numeric_limits<std::uint32_t>::max();
        SCENE_TRY_ASSIGN(i, sd::as_integer(p[0], path + "[0]", lim));
        SCENE_TRY_ASSIGN(j, sd::as_integer(p[1], path + "[1]", lim));
        d.pins.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j)});
      }
    }
  }
  return make_cloth(d);
}

Result<Scene> build_scene(const json& doc, std::string_view source_name) {
  if (!doc.is_object())
    return sd::shape_error(fmt::format("the scene must be a JSON object, got {}", doc.type_name()));
  VKCLOTH_TRY(sd::check_keys(doc, "",
                             {"name", "system", "integrator", "physics", "chain", "cloth", "wind",
                              "colliders", "contact_epsilon", "contact_inward_only", "divergence_limit",
                              "stretch_limit", "self_collision"}));
  Scene scene;
  if (!doc.contains("system"))
    return sd::shape_error("missing required key system (\"chain\" or \"cloth\")");
  std::string kind;
  VKCLOTH_TRY(sd::read(doc, "", "system", kind));
  if (kind != "chain" && kind != "cloth")
    return sd::shape_error(fmt::format("system must be \"chain\" or \"cloth\", got \"{}\"", kind));
  const char* other = kind == "chain" ? "cloth" : "chain";
  if (doc.contains(other))
    return sd::shape_error(
        fmt::format("a \"{}\" section is not allowed in a scene whose system is \"{}\"", other, kind));

  scene.name = std::filesystem::path(source_name).stem().string();
  VKCLOTH_TRY(sd::read(doc, "", "name", scene.name));
  VKCLOTH_TRY(read_integrator(doc, scene.params, scene.steps));
  VKCLOTH_TRY(read_physics(doc, scene.params));
  std::optional<Material> material; // cloth.material: its damping is mu, so it is read before validate()
  if (const json* cloth = kind == "cloth" && doc.contains("cloth") ? &doc["cloth"] : nullptr;
      cloth && cloth->is_object()) {
    SCENE_TRY_ASSIGN(m, read_material(*cloth));
    material = m;
  }
  if (material) {
    if (const auto it = doc.find("physics"); it != doc.end() && it->contains("damping"))
      return sd::shape_error(fmt::format("physics.damping and cloth.material exclude each other: the "
                                         "material's damping ({} 1/s) is mu",
                                         material->damping));
    scene.params.damping = material->damping;
  }
  VKCLOTH_TRY(read_wind(doc, scene.params));
  const std::filesystem::path scene_dir = std::filesystem::path(source_name).parent_path();
  VKCLOTH_TRY(read_colliders(doc, scene_dir, scene));
  VKCLOTH_TRY(read_stretch_limit(doc, scene.params));
  VKCLOTH_TRY(read_self_collision(doc, scene.params));
  VKCLOTH_TRY(sd::read(doc, "", "contact_epsilon", scene.params.contact_epsilon));
  VKCLOTH_TRY(sd::read(doc, "", "divergence_limit", scene.params.divergence_limit));
  VKCLOTH_TRY(sd::read(doc, "", "contact_inward_only", scene.params.contact_inward_only));
  VKCLOTH_TRY(scene.params.validate()); // ranges, before any large allocation below

  if (const json* cloth = kind == "cloth" && doc.contains("cloth") ? &doc["cloth"] : nullptr;
      cloth && cloth->is_object() && cloth->contains("mesh")) {
    VKCLOTH_TRY(read_mesh_cloth(*cloth, scene_dir, material, scene));
  } else {
    auto system = kind == "chain" ? read_chain(doc) : read_cloth(doc, material);
    if (!system)
      return system.error();
    scene.system = std::move(*system);
  }
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
    if (sd::JsonParseFailure f; !sd::parse_json(json_text, doc, f)) {
      const auto [line, col] = sd::line_col(json_text, f.byte);
      const std::string where = f.path.empty() ? "" : fmt::format(" at {}", f.path);
      return make_error(ErrorCode::parse, fmt::format("{}:{}:{}: invalid JSON{} (byte {}): {}", source_name,
                                                      line, col, where, f.byte, f.message));
    }
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
