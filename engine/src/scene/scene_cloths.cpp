// SPDX-License-Identifier: MIT
// "cloths": several cloths in one scene (docs/scene-format.md "Several cloths"). Each entry is read as
// a "cloth" section (a grid or a mesh, its material, pins and attachments) and the cloths become
// one system whose particles run on cloth by cloth, with one surface of all their faces. So
// self_collision covers the contact between the cloths as within each, and every output (positions,
// trace, export, render, --check-intersections) lists the cloths in the order of the list.
#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "scene_sections.hpp"

namespace vkcloth::scene_detail {
namespace {

/// The keys of a cloth section, a grid's and a mesh's (read_cloth and read_mesh_cloth refuse the
/// other kind's).
const std::initializer_list<std::string_view> cloth_keys = {
    "resolution", "size",           "origin",  "orientation",  "particle_mass",
    "stiffness",  "material",       "pins",    "attach",       "max_distance",
    "mesh",       "mesh_transform", "density", "pin_vertices", "pin_region"};

/// `text` about entry k of "cloths": each key path "cloth.<key>" (the section readers' and the
/// builders' names, a key of the cloth section) becomes "cloths[k].<key>"; a file name such as
/// "cloth.obj" stays.
std::string in_entry(std::string_view text, std::size_t k) {
  const auto identifier = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  const std::string entry = fmt::format("cloths[{}].", k);
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    bool key = false;
    if (text.substr(i, 6) == "cloth." && (i == 0 || !identifier(text[i - 1]))) {
      std::size_t end = i + 6;
      while (end < text.size() && identifier(text[end]))
        ++end;
      key = std::find(cloth_keys.begin(), cloth_keys.end(), text.substr(i + 6, end - i - 6)) !=
            cloth_keys.end();
    }
    out += key ? entry : std::string(1, text[i]);
    i += key ? 6 : 1;
  }
  return out;
}

Error in_entry(Error e, std::size_t k) {
  e.message = in_entry(e.message, k);
  return e;
}

/// One entry built as a scene of its own: its system (attached particles pinned), attachments,
/// texture and warnings.
Result<Scene> read_entry(const json& entry, std::size_t k, const std::filesystem::path& scene_dir,
                         const Scene& scene) {
  if (!entry.is_object())
    return shape_error(
        fmt::format("cloths[{}] must be an object (the keys of \"cloth\"), got {}", k, show(entry)));
  // Unknown keys named here (the readers below name their keys cloth.<key>, renamed by in_entry).
  VKCLOTH_TRY(check_keys(entry, fmt::format("cloths[{}]", k), cloth_keys));
  Scene part;
  part.params = scene.params; // the colliders the attachments name
  part.params.attachments.clear();
  part.up = scene.up;
  auto material = read_material(entry);
  if (!material)
    return in_entry(material.error(), k);
  if (entry.contains("mesh")) {
    if (auto r = read_mesh_cloth(entry, scene_dir, *material, part); !r)
      return in_entry(r.error(), k);
  } else {
    auto system = read_cloth(json{{"cloth", entry}}, *material, scene.up);
    if (!system)
      return in_entry(system.error(), k);
    part.system = std::move(*system);
  }
  if (auto r = read_attachments(entry, part); !r)
    return in_entry(r.error(), k);
  for (std::string& w : part.warnings)
    w = in_entry(w, k);
  return part;
}

/// The damping mu of the cloths' materials (one per scene): the materials must agree.
Result<std::optional<double>> material_damping(const json& list) {
  std::optional<double> damping;
  std::size_t first = 0;
  for (std::size_t k = 0; k < list.size(); ++k) {
    if (!list[k].is_object())
      continue; // read_entry names it
    auto m = read_material(list[k]);
    if (!m)
      return in_entry(m.error(), k);
    if (!*m)
      continue;
    if (damping && (*m)->damping != *damping)
      return shape_error(
          fmt::format("cloths[{}].material's damping ({} 1/s) differs from cloths[{}].material's "
                      "({} 1/s): a scene has one damping mu",
                      k, (*m)->damping, first, *damping));
    if (!damping) {
      damping = (*m)->damping;
      first = k;
    }
  }
  return damping;
}

/// Appends `part`'s system to `into` (particles from `base` on), its faces to `surface`.
void append(const ParticleSystem& part, std::uint32_t base, std::uint32_t file_base, ParticleSystem& into,
            Surface& surface) {
  const auto n = static_cast<std::uint32_t>(part.size());
  into.particles.insert(into.particles.end(), part.particles.begin(), part.particles.end());
  for (Spring s : part.springs) {
    s.a += base;
    s.b += base;
    into.springs.push_back(s);
  }
  const auto face = [&](std::initializer_list<std::uint32_t> corners) {
    for (const std::uint32_t c : corners)
      surface.faces.push_back(base + c);
    surface.face_offsets.push_back(static_cast<std::uint32_t>(surface.faces.size()));
  };
  if (part.grid) { // as ClothTopology makes a grid's: quads (a, b, d, c), triangles (a, b, d), (a, d, c)
    const std::uint32_t nx = part.grid->nx, ny = part.grid->ny;
    for (std::uint32_t j = 0; j + 1 < ny; ++j)
      for (std::uint32_t i = 0; i + 1 < nx; ++i) {
        const std::uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
        face({a, b, d, c});
        for (const std::uint32_t t : {a, b, d, a, d, c})
          surface.triangles.push_back(base + t);
      }
    for (std::uint32_t p = 0; p < n; ++p)
      surface.uvs.push_back(part.grid->uvs.empty() ? default_grid_uv(p % nx, p / nx, nx, ny)
                                                   : part.grid->uvs[p]);
    for (std::uint32_t p = 0; p < n; ++p)
      surface.source_vertex.push_back(file_base + p);
    return;
  }
  const Surface& s = *part.surface;
  for (const std::uint32_t t : s.triangles)
    surface.triangles.push_back(base + t);
  if (s.face_offsets.empty()) {
    for (std::size_t t = 0; t + 2 < s.triangles.size(); t += 3)
      face({s.triangles[t], s.triangles[t + 1], s.triangles[t + 2]});
  } else {
    for (std::size_t f = 0; f + 1 < s.face_offsets.size(); ++f) {
      for (std::uint32_t c = s.face_offsets[f]; c < s.face_offsets[f + 1]; ++c)
        surface.faces.push_back(base + s.faces[c]);
      surface.face_offsets.push_back(static_cast<std::uint32_t>(surface.faces.size()));
    }
  }
  surface.uvs.insert(surface.uvs.end(), s.uvs.begin(), s.uvs.end());
  for (std::uint32_t p = 0; p < n; ++p)
    surface.source_vertex.push_back(file_base + (s.source_vertex.empty() ? p : s.source_vertex[p]));
}

/// How many vertex numbers a part's outputs take: a grid's particles, a mesh file's vertices up to
/// the last one it kept.
std::uint32_t file_vertices(const ParticleSystem& part) {
  if (part.surface && !part.surface->source_vertex.empty())
    return *std::max_element(part.surface->source_vertex.begin(), part.surface->source_vertex.end()) + 1;
  return static_cast<std::uint32_t>(part.size());
}

} // namespace

Result<std::optional<double>> read_cloths_damping(const json& doc) {
  SCENE_TRY_ASSIGN(list, read_array(doc, "", "cloths"));
  if (!list)
    return std::optional<double>{};
  return material_damping(*list);
}

Result<void> read_cloths(const json& doc, const std::filesystem::path& scene_dir, Scene& scene) {
  SCENE_TRY_ASSIGN(list, read_array(doc, "", "cloths"));
  if (!list || list->empty())
    return shape_error("cloths is empty: give at least one cloth (or use \"cloth\" for one)");
  ParticleSystem merged;
  Surface surface;
  surface.face_offsets.push_back(0);
  std::uint32_t base = 0, file_base = 0;
  for (std::size_t k = 0; k < list->size(); ++k) {
    SCENE_TRY_ASSIGN(part, read_entry((*list)[k], k, scene_dir, scene));
    const ParticleSystem& s = part.system;
    if (std::uint64_t(base) + s.size() > max_particles)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("cloths: {} particles up to cloths[{}], more than the limit {}",
                                    std::uint64_t(base) + s.size(), k, max_particles));
    scene.cloths.push_back(base);
    append(s, base, file_base, merged, surface);
    for (Attachment a : part.params.attachments) {
      for (std::uint32_t& p : a.particles)
        p += base;
      scene.params.attachments.push_back(std::move(a));
    }
    if (part.texture && !scene.texture)
      scene.texture = std::move(part.texture);
    else if (part.texture)
      scene.warnings.push_back(fmt::format("cloths[{}]: only the first cloth's texture is drawn", k));
    scene.warnings.insert(scene.warnings.end(), part.warnings.begin(), part.warnings.end());
    base += static_cast<std::uint32_t>(s.size());
    file_base += file_vertices(s);
  }
  scene.cloths.push_back(base);
  merged.surface = std::move(surface);
  merged.finalize();
  scene.system = std::move(merged);
  return check_attachments(scene.params, scene.system.size());
}

} // namespace vkcloth::scene_detail
