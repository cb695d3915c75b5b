// SPDX-License-Identifier: MIT
// glTF 2.0 reader (tinygltf): the public parse_gltf / read_gltf and the Mesh they make, every
// TRIANGLES primitive of the first mesh (mode 4, or no mode), merged in order, with its POSITION,
// TEXCOORD_0 and indices as stored. Nothing else is applied: no node transform, skin or morph
// target; the mesh comes out in its own space. The base-colour texture of the first primitive whose
// material has one is kept as the image file's encoded bytes. The input is checked before tinygltf
// reads it (gltf_input.cpp), and every accessor, buffer view and buffer before a byte of it is read
// (gltf_accessors.cpp); gltf_detail.hpp declares what the three share.
#include <algorithm>
#include <cctype>
#include <cstring>
#include <optional>
#include <string>

#include "gltf_detail.hpp"

namespace vkcloth {
namespace {

namespace fs = std::filesystem;
using namespace gltf_detail; // the checked pieces: container, JSON, buffers, accessors, tinygltf

// ---- mesh ----------------------------------------------------------------------------------------

const AccessorSpec position_spec{
    "POSITION", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false, std::size_t(max_particles)};
const AccessorSpec texcoord_spec{"TEXCOORD_0",
                                 TINYGLTF_TYPE_VEC2,
                                 {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                 true};
const AccessorSpec index_spec{"indices",
                              TINYGLTF_TYPE_SCALAR,
                              {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}};

std::optional<int> attribute(const tinygltf::Primitive& p, const std::string& name) {
  const auto it = p.attributes.find(name);
  return it == p.attributes.end() ? std::nullopt : std::optional<int>(it->second);
}

/// Appends one TRIANGLES primitive (`where`: "meshes[0].primitives[1]") to `mesh`.
Result<void> append_primitive(const tinygltf::Model& model, const tinygltf::Primitive& p,
                              const std::string& where, std::string_view source, Mesh& mesh) {
  const auto position = attribute(p, "POSITION");
  if (!position)
    return gltf_error(source, fmt::format("{} has no POSITION attribute", where));
  auto positions = accessor_view(model, *position, position_spec, where + ".attributes.POSITION", source);
  if (!positions)
    return positions.error();
  const std::size_t base = mesh.positions.size();
  if (base + positions->count > max_particles)
    return gltf_error(source,
                      fmt::format("meshes[0] has more than max_particles ({}) vertices", max_particles));
  VKCLOTH_TRY(append_positions(*positions, source, mesh.positions));

  if (const auto texcoord = attribute(p, "TEXCOORD_0")) {
    auto uvs = accessor_view(model, *texcoord, texcoord_spec, where + ".attributes.TEXCOORD_0", source);
    if (!uvs)
      return uvs.error();
    if (uvs->count != positions->count)
      return gltf_error(source, fmt::format("{} has {} elements, but {} has {}", uvs->label, uvs->count,
                                            positions->label, positions->count));
    VKCLOTH_TRY(append_texcoords(*uvs, source, mesh.uvs));
  }

  if (p.indices >= 0) {
    auto indices = accessor_view(model, p.indices, index_spec, where + ".indices", source);
    if (!indices)
      return indices.error();
    if (indices->count % 3 != 0)
      return gltf_error(source, fmt::format("{} has {} indices, not a multiple of 3 (TRIANGLES)",
                                            indices->label, indices->count));
    VKCLOTH_TRY(append_indices(*indices, positions->count, base, source, mesh.indices));
  } else {
    if (positions->count % 3 != 0)
      return gltf_error(source,
                        fmt::format("{} has no indices and {} vertices, not a multiple of 3 (TRIANGLES)",
                                    where, positions->count));
    for (std::size_t i = 0; i < positions->count; ++i)
      mesh.indices.push_back(static_cast<std::uint32_t>(base + i));
  }
  for (std::size_t f = mesh.face_offsets.back() + 3; f <= mesh.indices.size(); f += 3)
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(f));
  return {};
}

bool is_png_or_jpeg(std::span<const std::uint8_t> b) {
  static constexpr std::uint8_t png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static constexpr std::uint8_t jpeg[] = {0xff, 0xd8, 0xff};
  return (b.size() >= sizeof png && std::equal(png, png + sizeof png, b.begin())) ||
         (b.size() >= sizeof jpeg && std::equal(jpeg, jpeg + sizeof jpeg, b.begin()));
}

/// The encoded bytes of images[index].
Result<std::vector<std::uint8_t>> image_bytes(const tinygltf::Model& model, int index,
                                              const FileAccess& files, std::string_view source) {
  const tinygltf::Image& image = model.images[std::size_t(index)];
  const std::string label = fmt::format("images[{}]", index);
  std::vector<std::uint8_t> bytes;
  if (image.bufferView >= 0) {
    auto view = buffer_view_bytes(model, image.bufferView, label, source);
    if (!view)
      return view.error();
    bytes.assign(view->begin(), view->end());
  } else if (!image.image.empty()) {
    bytes = image.image;
  } else if (!image.uri.empty() && !is_data_uri(image.uri)) {
    return gltf_error(source,
                      fmt::format("{}: cannot read the file {}{}", label, mesh_detail::in_quotes(image.uri),
                                  files.base_dir.empty()
                                      ? " (the glTF was read from memory without a base directory)"
                                      : " in " + files.base_dir),
                      ErrorCode::io);
  }
  if (!is_png_or_jpeg(bytes))
    return gltf_error(source, fmt::format("{} is not a PNG or JPEG image (mimeType {}, {} bytes)", label,
                                          mesh_detail::in_quotes(image.mimeType), bytes.size()));
  return bytes;
}

/// The base-colour texture of a primitive's material, if it has one.
Result<std::optional<MeshTexture>> base_color_texture(const tinygltf::Model& model,
                                                      const tinygltf::Primitive& p, const std::string& where,
                                                      const FileAccess& files, std::string_view source) {
  if (p.material < 0)
    return std::optional<MeshTexture>();
  if (std::size_t(p.material) >= model.materials.size())
    return gltf_error(source, fmt::format("{}.material is {}, but {}", where, p.material,
                                          has_count(model.materials.size(), "material", "materials")));
  const int texture = model.materials[std::size_t(p.material)].pbrMetallicRoughness.baseColorTexture.index;
  if (texture < 0)
    return std::optional<MeshTexture>();
  if (std::size_t(texture) >= model.textures.size())
    return gltf_error(
        source, fmt::format("materials[{}].pbrMetallicRoughness.baseColorTexture.index is {}, but {}",
                            p.material, texture, has_count(model.textures.size(), "texture", "textures")));
  const int image = model.textures[std::size_t(texture)].source;
  if (image < 0) // an image only an extension knows (KHR_texture_basisu, EXT_texture_webp): none we can use
    return std::optional<MeshTexture>();
  if (std::size_t(image) >= model.images.size())
    return gltf_error(source, fmt::format("textures[{}].source is {}, but {}", texture, image,
                                          has_count(model.images.size(), "image", "images")));
  auto bytes = image_bytes(model, image, files, source);
  if (!bytes)
    return bytes.error();
  return std::optional<MeshTexture>(
      MeshTexture{fmt::format("{} images[{}]", source, image), std::move(*bytes)});
}

Result<Mesh> mesh_of(const tinygltf::Model& model, const FileAccess& files, std::string_view source) {
  if (model.meshes.empty())
    return gltf_error(source, "the file has no meshes");
  Mesh mesh;
  std::optional<std::size_t> first; // the first triangle primitive: it decides whether there are uvs
  std::string other_modes;
  const auto& primitives = model.meshes[0].primitives;
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    const tinygltf::Primitive& p = primitives[i];
    const std::string where = fmt::format("meshes[0].primitives[{}]", i);
    if (p.mode != TINYGLTF_MODE_TRIANGLES && p.mode != -1) {
      other_modes += fmt::format("{}{}", other_modes.empty() ? "" : ", ", p.mode);
      continue;
    }
    const bool has_uvs = attribute(p, "TEXCOORD_0").has_value();
    if (first && has_uvs != attribute(primitives[*first], "TEXCOORD_0").has_value())
      return gltf_error(source,
                        fmt::format("{} {} TEXCOORD_0, but meshes[0].primitives[{}] {}", where,
                                    has_uvs ? "has" : "has no", *first, has_uvs ? "has none" : "has"));
    first = first.value_or(i);
    VKCLOTH_TRY(append_primitive(model, p, where, source, mesh));
    if (!mesh.texture) {
      auto texture = base_color_texture(model, p, where, files, source);
      if (!texture)
        return texture.error();
      mesh.texture = std::move(*texture);
    }
  }
  if (!first)
    return gltf_error(source, fmt::format("meshes[0] has no TRIANGLES primitive (modes found: {})",
                                          other_modes.empty() ? "none" : other_modes));
  if (mesh.face_count() == 0)
    return gltf_error(source, "meshes[0] has no triangles");
  return mesh;
}

} // namespace

Result<Mesh> parse_gltf(std::span<const std::uint8_t> bytes, bool binary, std::string_view source_name,
                        const std::filesystem::path& base_dir) {
  return mesh_detail::guarded_parse(source_name, [&]() -> Result<Mesh> {
    VKCLOTH_TRY(mesh_detail::check_mesh_size(bytes.size(), source_name));
    std::string_view json_text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    std::string json_where(source_name);
    std::optional<std::size_t> bin_chunk;
    if (binary) {
      auto glb = check_glb(bytes, source_name);
      if (!glb)
        return glb.error();
      bytes = bytes.first(glb->length);
      json_text = glb->json;
      json_where += " (JSON chunk)";
      bin_chunk = glb->bin.value_or(0);
    }
    auto doc = parse_json_text(json_text, json_where);
    if (!doc)
      return doc.error();
    VKCLOTH_TRY(check_buffers(*doc, base_dir, bin_chunk, source_name));
    FileAccess files{base_dir.string()};
    auto model = load_model(bytes, binary, source_name, files);
    if (!model)
      return model.error();
    return mesh_of(*model, files, source_name);
  });
}

Result<Mesh> read_gltf(const std::filesystem::path& path) {
  auto bytes = mesh_detail::read_mesh_file(path);
  if (!bytes)
    return bytes.error();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  const bool binary = ext == ".glb" || (bytes->size() >= 4 && std::memcmp(bytes->data(), "glTF", 4) == 0);
  // A file in the working directory has no parent path; its buffers are looked up in ".".
  const fs::path base_dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  return parse_gltf(*bytes, binary, path.string(), base_dir);
}

} // namespace vkcloth
