// SPDX-License-Identifier: MIT
// The scene's system: a "chain" (make_chain), a grid "cloth" (make_cloth) or a cloth made from a
// mesh file ("cloth.mesh", make_mesh_cloth), with what they share: "cloth.stiffness" and
// "cloth.material". Shapes are checked here; the builders check the ranges and sizes.
#include <limits>

#include <fmt/format.h>

#include "scene_sections.hpp"
#include "vkcloth/builders.hpp"

namespace vkcloth::scene_detail {

Result<ParticleSystem> read_chain(const json& doc, UpAxis up) {
  ChainDesc d;
  d.up = up;
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

namespace {

Result<void> read_stiffness(const json& cloth, ClothStiffness& k) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(cloth, "cloth", "stiffness"));
  if (!obj)
    return {};
  VKCLOTH_TRY(sd::check_keys(*obj, "cloth.stiffness", {"structural", "shear", "bend"}));
  VKCLOTH_TRY(sd::read(*obj, "cloth.stiffness", "structural", k.structural));
  VKCLOTH_TRY(sd::read(*obj, "cloth.stiffness", "shear", k.shear));
  return sd::read(*obj, "cloth.stiffness", "bend", k.bend);
}

} // namespace

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

namespace {

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

} // namespace

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
                              "pin_vertices", "pin_region", "attach", "max_distance"}));
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

Result<ParticleSystem> read_cloth(const json& doc, const std::optional<Material>& material, UpAxis up) {
  ClothDesc d;
  d.up = up;
  d.material = material;
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "cloth"));
  if (obj) {
    VKCLOTH_TRY(sd::check_keys(*obj, "cloth",
                               {"resolution", "size", "origin", "orientation", "particle_mass", "stiffness",
                                "material", "pins", "attach", "max_distance"}));
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

} // namespace vkcloth::scene_detail
