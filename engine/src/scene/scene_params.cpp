// SPDX-License-Identifier: MIT
// The scene's simulation-parameter sections, read into SimParams: "integrator" (and the step
// count), "physics", "wind", "stretch_limit" and "self_collision". Shapes only; the ranges are
// SimParams::validate()'s, run by build_scene() once every section is read.
#include <fmt/format.h>

#include "scene_sections.hpp"

namespace vkcloth::scene_detail {

Result<void> read_integrator(const json& doc, SimParams& params, std::uint64_t& steps) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "integrator"));
  if (!obj)
    return {};
  VKCLOTH_TRY(sd::check_keys(
      *obj, "integrator",
      {"method", "dt", "steps", "substeps", "cg_tolerance", "cg_max_iterations", "iterations"}));
  std::string method = to_string(params.integrator);
  VKCLOTH_TRY(sd::read(*obj, "integrator", "method", method));
  const auto integ = parse_integrator(method);
  if (!integ)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("integrator.method: unknown integrator \"{}\" (known: explicit_euler, "
                                  "semi_implicit_euler, rk4, implicit_euler, vbd)",
                                  method));
  params.integrator = *integ;
  VKCLOTH_TRY(sd::read(*obj, "integrator", "dt", params.dt));
  if (auto it = obj->find("substeps"); it != obj->end()) {
    SCENE_TRY_ASSIGN(n, sd::as_integer(*it, "integrator.substeps", 1000000, 1));
    params.substeps = static_cast<std::uint32_t>(n);
  }
  VKCLOTH_TRY(sd::read(*obj, "integrator", "cg_tolerance", params.cg_tolerance));
  if (auto it = obj->find("cg_max_iterations"); it != obj->end()) {
    SCENE_TRY_ASSIGN(n, sd::as_integer(*it, "integrator.cg_max_iterations", 100000, 1));
    params.cg_max_iterations = static_cast<std::uint32_t>(n);
  }
  if (auto it = obj->find("iterations"); it != obj->end()) {
    SCENE_TRY_ASSIGN(n, sd::as_integer(*it, "integrator.iterations", 1000, 1));
    params.vbd_iterations = static_cast<std::uint32_t>(n); // validate() holds the same range
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

namespace {

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

} // namespace

// Absent: off (the report's model). Present: "method" is required, the rest have defaults.
Result<void> read_stretch_limit(const json& doc, SimParams& params) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "stretch_limit"));
  if (!obj)
    return {};
  const char* path = "stretch_limit";
  VKCLOTH_TRY(sd::check_keys(*obj, path, {"method", "max_strain", "iterations", "tether_distance", "order"}));
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
  VKCLOTH_TRY(read_choice(*obj, path, "tether_distance", parse_tether_distance,
                          "\"euclidean\" or \"geodesic\"", sl.tether_distance));
  return read_choice(*obj, path, "order", parse_sweep_order, "\"colours\" or \"chains\"", sl.order);
}

// Absent: off (the report's model). Present: on unless "enabled" is false; every other key has the
// SelfCollision default. The ranges are validate()'s; the thickness against the cloth's spacing is
// check_self_collision()'s, once the system is built.
Result<void> read_self_collision(const json& doc, SimParams& params) {
  SCENE_TRY_ASSIGN(obj, sd::read_object(doc, "", "self_collision"));
  if (!obj)
    return {};
  const char* path = "self_collision";
  VKCLOTH_TRY(
      sd::check_keys(*obj, path, {"enabled", "thickness", "friction", "iterations", "skin", "stiffness"}));
  SelfCollision& sc = params.self_collision;
  sc.enabled = true;
  VKCLOTH_TRY(sd::read(*obj, path, "enabled", sc.enabled));
  VKCLOTH_TRY(sd::read(*obj, path, "thickness", sc.thickness));
  VKCLOTH_TRY(sd::read(*obj, path, "friction", sc.friction));
  VKCLOTH_TRY(sd::read(*obj, path, "skin", sc.skin));
  VKCLOTH_TRY(sd::read(*obj, path, "stiffness", sc.stiffness));
  if (obj->contains("iterations")) {
    SCENE_TRY_ASSIGN(it, sd::as_integer((*obj)["iterations"], "self_collision.iterations", 1000000));
    sc.iterations = static_cast<std::uint32_t>(it); // the range (1..16) is validate()'s
  }
  return {};
}

} // namespace vkcloth::scene_detail
