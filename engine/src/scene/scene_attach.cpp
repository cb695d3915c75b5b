// SPDX-License-Identifier: MIT
// The cloth on a moving character: "inertia" (the frame it is simulated in) and "cloth.attach" and
// "cloth.max_distance" (docs/scene-format.md "Attachments"): the cloth's particles
// that follow a collider, read once the system and the colliders are built. An attachment without
// a max_distance pins its particles (they are driven onto their targets); with one they stay free
// and are held within that distance (a motion constraint). The offsets are the particles' rest
// positions in the collider's frame at t = 0 (Attachment::at_rest).
#include <limits>
#include <map>
#include <optional>
#include <unordered_map>

#include <fmt/format.h>
#include <glm/vector_relational.hpp>

#include "scene_sections.hpp"

namespace vkcloth::scene_detail {

namespace {

Error bad(std::string message) {
  return make_error(ErrorCode::invalid_argument, std::move(message));
}

// "vertices": a grid's [i, j] pairs, or a mesh's file vertex indices (Surface::source_vertex undone).
Result<std::vector<std::uint32_t>> read_vertices(const json& list, const std::string& at,
                                                 const ParticleSystem& system) {
  if (!list.is_array())
    return shape_error(fmt::format("{} must be an array, got {}", at, show(list)));
  if (list.empty()) // as a region that selects nothing
    return bad(fmt::format("{} is empty: it attaches no particle", at));
  std::vector<std::uint32_t> particles;
  std::unordered_map<std::uint32_t, std::uint32_t> particle_of; // a mesh's file vertex -> particle
  if (system.surface && !system.surface->source_vertex.empty())
    for (std::uint32_t p = 0; p < system.surface->source_vertex.size(); ++p)
      particle_of.emplace(system.surface->source_vertex[p], p);
  const auto lim = std::numeric_limits<std::uint32_t>::max();
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string path = fmt::format("{}[{}]", at, k);
    const json& v = list[k];
    if (system.grid) {
      if (!v.is_array() || v.size() != 2)
        return shape_error(fmt::format("{} must be an array of 2 integers [i, j], got {}", path, show(v)));
      SCENE_TRY_ASSIGN(i, as_integer(v[0], path + "[0]", lim));
      SCENE_TRY_ASSIGN(j, as_integer(v[1], path + "[1]", lim));
      if (i >= system.grid->nx || j >= system.grid->ny)
        return bad(fmt::format("{} = [{}, {}] is outside the {} x {} grid", path, i, j, system.grid->nx,
                               system.grid->ny));
      particles.push_back(static_cast<std::uint32_t>(j * system.grid->nx + i));
      continue;
    }
    SCENE_TRY_ASSIGN(vertex, as_integer(v, path, lim));
    if (particle_of.empty()) { // a chain, or a mesh in its file's order
      if (vertex >= system.size())
        return bad(fmt::format("{} = {} is outside the cloth ({} particles)", path, vertex, system.size()));
      particles.push_back(static_cast<std::uint32_t>(vertex));
      continue;
    }
    const auto it = particle_of.find(static_cast<std::uint32_t>(vertex));
    if (it == particle_of.end())
      return bad(fmt::format("{} = {} is not a vertex of the cloth (outside the mesh, or in no face)", path,
                             vertex));
    particles.push_back(it->second);
  }
  return particles;
}

// "region": {"min": [...], "max": [...]}: every particle whose rest position is inside (bounds included).
Result<std::vector<std::uint32_t>> read_region(const json& region, const std::string& at,
                                               const ParticleSystem& system) {
  if (!region.is_object())
    return shape_error(fmt::format("{} must be an object {{\"min\": [x, y, z], \"max\": [x, y, z]}}, got {}",
                                   at, show(region)));
  VKCLOTH_TRY(check_keys(region, at, {"min", "max"}));
  VKCLOTH_TRY(require_keys(region, at, {"min", "max"}, "a region"));
  glm::dvec3 lo{0.0}, hi{0.0};
  VKCLOTH_TRY(read(region, at, "min", lo));
  VKCLOTH_TRY(read(region, at, "max", hi));
  std::vector<std::uint32_t> particles;
  for (std::uint32_t p = 0; p < system.size(); ++p) {
    const glm::dvec3 x = system.particles[p].position;
    if (glm::all(glm::greaterThanEqual(x, lo)) && glm::all(glm::lessThanEqual(x, hi)))
      particles.push_back(p);
  }
  if (particles.empty())
    return bad(fmt::format("{} [{}, {}, {}] .. [{}, {}, {}] selects no particle", at, lo.x, lo.y, lo.z, hi.x,
                           hi.y, hi.z));
  return particles;
}

// "max_distance": {"attach": N, "distance": D} or an array of them -> attachment N's distance.
Result<std::map<std::size_t, double>> read_max_distances(const json& cloth, std::size_t attachments) {
  std::map<std::size_t, double> out;
  const auto it = cloth.find("max_distance");
  if (it == cloth.end())
    return out;
  const json list = it->is_array() ? *it : json::array({*it});
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string at = it->is_array() ? fmt::format("cloth.max_distance[{}]", k) : "cloth.max_distance";
    const json& e = list[k];
    if (!e.is_object())
      return shape_error(
          fmt::format("{} must be an object {{\"attach\": N, \"distance\": D}}, got {}", at, show(e)));
    VKCLOTH_TRY(check_keys(e, at, {"attach", "distance"}));
    VKCLOTH_TRY(require_keys(e, at, {"attach", "distance"}, "a max_distance"));
    SCENE_TRY_ASSIGN(n, as_integer(e["attach"], at + ".attach", std::numeric_limits<std::uint32_t>::max()));
    if (n >= attachments)
      return bad(fmt::format("{}.attach is {}, but cloth.attach has {} entries", at, n, attachments));
    double d = 0.0;
    VKCLOTH_TRY(read(e, at, "distance", d));
    if (d < 0.0)
      return bad(fmt::format("{}.distance must be >= 0 (metres), got {}", at, d));
    if (!out.emplace(n, d).second)
      return bad(fmt::format("{}: cloth.attach[{}] has a max_distance already", at, n));
  }
  return out;
}

} // namespace

Result<void> read_inertia(const json& doc, SimParams& params) {
  SCENE_TRY_ASSIGN(obj, read_object(doc, "", "inertia"));
  if (!obj)
    return {};
  VKCLOTH_TRY(check_keys(*obj, "inertia", {"collider", "linear", "angular"}));
  VKCLOTH_TRY(require_keys(*obj, "inertia", {"collider"}, "inertia"));
  SCENE_TRY_ASSIGN(
      index, as_integer((*obj)["collider"], "inertia.collider", std::numeric_limits<std::uint32_t>::max()));
  params.inertia.collider = static_cast<std::uint32_t>(index);
  VKCLOTH_TRY(read(*obj, "inertia", "linear", params.inertia.linear));
  VKCLOTH_TRY(read(*obj, "inertia", "angular", params.inertia.angular));
  return {}; // the ranges and the collider: SimParams::validate
}

Result<void> read_attachments(const json& cloth, Scene& scene) {
  SCENE_TRY_ASSIGN(list, read_array(cloth, "cloth", "attach"));
  if (!list) {
    if (cloth.contains("max_distance"))
      return shape_error("cloth.max_distance needs cloth.attach (it names an attachment)");
    return {};
  }
  SCENE_TRY_ASSIGN(distances, read_max_distances(cloth, list->size()));
  std::vector<glm::dvec3> rest;
  rest.reserve(scene.system.size());
  for (const Particle& p : scene.system.particles)
    rest.push_back(p.position);
  for (std::size_t k = 0; k < list->size(); ++k) {
    const std::string at = fmt::format("cloth.attach[{}]", k);
    const json& e = (*list)[k];
    if (!e.is_object())
      return shape_error(fmt::format(
          "{} must be an object {{\"collider\": K, \"region\" or \"vertices\"}}, got {}", at, show(e)));
    VKCLOTH_TRY(check_keys(e, at, {"collider", "region", "vertices"}));
    VKCLOTH_TRY(require_keys(e, at, {"collider"}, "an attachment"));
    if (e.contains("region") == e.contains("vertices"))
      return shape_error(fmt::format("{} needs one of \"region\" or \"vertices\"", at));
    SCENE_TRY_ASSIGN(index,
                     as_integer(e["collider"], at + ".collider", std::numeric_limits<std::uint32_t>::max()));
    if (index >= scene.params.colliders.size())
      return bad(fmt::format("{}.collider is {}, but the scene has {} colliders", at, index,
                             scene.params.colliders.size()));
    SCENE_TRY_ASSIGN(particles, e.contains("region")
                                    ? read_region(e["region"], at + ".region", scene.system)
                                    : read_vertices(e["vertices"], at + ".vertices", scene.system));
    const auto distance = distances.find(k);
    auto a = Attachment::at_rest(scene.params.colliders[index], static_cast<std::uint32_t>(index), particles,
                                 rest, distance == distances.end() ? 0.0 : distance->second);
    if (!a)
      return bad(fmt::format("{}: {}", at, a.error().message));
    if (distance == distances.end()) // no max_distance: pinned, driven onto the targets
      for (const std::uint32_t p : a->particles)
        scene.system.particles[p].pinned = true;
    scene.params.attachments.push_back(std::move(*a));
  }
  return check_attachments(scene.params, scene.system.size());
}

namespace {

/// The first teleport key of collider `c`, if it has one.
std::optional<std::size_t> teleport_key(const Collider& c) {
  if (c.path)
    for (std::size_t j = 0; j < c.path->keys.size(); ++j)
      if (c.path->keys[j].teleport)
        return j;
  return std::nullopt;
}

} // namespace

Result<void> carry_attached_teleports(Scene& scene, bool several_cloths) {
  SimParams& params = scene.params;
  const bool given = params.inertia.enabled(); // the scene's "inertia", not one set below
  std::string implied;                         // the teleport key that set it
  for (std::size_t a = 0; a < params.attachments.size(); ++a) {
    const std::uint32_t k = params.attachments[a].collider;
    const auto key = teleport_key(params.colliders[k]);
    if (!key)
      continue;
    const std::string teleport = fmt::format("colliders[{}].keyframes[{}].teleport", k, *key);
    const std::string attach = several_cloths ? "an entry of cloths" : fmt::format("cloth.attach[{}]", a);
    if (params.inertia.collider == k)
      continue; // already the cloth's frame: it jumps with it
    if (!implied.empty())
      return bad(fmt::format("{} and {} both jump a collider the cloth is attached to: it can jump with one "
                             "(name it as inertia.collider) or drop a teleport",
                             implied, teleport));
    if (given)
      return bad(
          fmt::format("{} jumps collider {}, which {} attaches the cloth to, but inertia.collider is {}: a "
                      "cloth jumps with its frame only (make collider {} the inertia collider, or drop the "
                      "teleport)",
                      teleport, k, attach, *params.inertia.collider, k));
    if (several_cloths)
      return bad(fmt::format("{} jumps collider {}, which {} attaches to: with several cloths set "
                             "inertia.collider to {} (every cloth then jumps with it), or drop the teleport",
                             teleport, k, attach, k));
    // The collider the cloth hangs from becomes its frame at full inertia: the same motion as world
    // space, and its teleport carries the cloth, unfelt.
    implied = teleport;
    params.inertia.collider = k;
    params.inertia.linear = 1.0;
    params.inertia.angular = 1.0;
  }
  return {};
}

} // namespace vkcloth::scene_detail
