// SPDX-License-Identifier: MIT
// Internal to the glTF reader: what its three parts share. gltf_input.cpp checks the input before
// tinygltf reads it (the GLB container, the JSON, the buffers' sizes) and runs tinygltf with file
// callbacks of its own; gltf_accessors.cpp checks accessors, buffer views and buffers before
// reading their elements; gltf_reader.cpp assembles the Mesh (primitives, base-colour texture) and
// holds the public parse_gltf / read_gltf.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "mesh_io.hpp"

namespace vkcloth::gltf_detail {

/// An error naming the file (`source`): "source: what".
inline Error gltf_error(std::string_view source, std::string_view what, ErrorCode code = ErrorCode::parse) {
  return make_error(code, fmt::format("{}: {}", source, what));
}

inline bool is_data_uri(std::string_view uri) {
  return uri.starts_with("data:");
}

// ---- before tinygltf (gltf_input.cpp) ------------------------------------------------------------

/// The parts of a GLB that tinygltf reads: `length` bytes (the header's), the JSON chunk in them.
struct GlbLayout {
  std::size_t length = 0;
  std::string_view json;
  std::optional<std::size_t> bin; ///< the BIN chunk's size, if there is one
};

/// The GLB container's header and chunks, checked against the bytes there are.
Result<GlbLayout> check_glb(std::span<const std::uint8_t> bytes, std::string_view source);

/// The glTF JSON parsed with the scene parser (line:column errors, nesting limit); an object.
Result<nlohmann::json> parse_json_text(std::string_view text, std::string_view where);

/// Every buffer of `doc` holds its byteLength, in a file beside the glTF (under `base_dir`), a
/// data: URI or the GLB's BIN chunk (`bin_chunk`: its size).
Result<void> check_buffers(const nlohmann::json& doc, const std::filesystem::path& base_dir,
                           std::optional<std::size_t> bin_chunk, std::string_view source);

/// tinygltf's file callbacks' user data: URIs resolve against `base_dir` only (tinygltf also tries
/// the working directory).
struct FileAccess {
  std::string base_dir;
};

/// tinygltf run on the checked bytes, with `files`' callbacks and encoded images kept as they are.
Result<tinygltf::Model> load_model(std::span<const std::uint8_t> bytes, bool binary, std::string_view source,
                                   FileAccess& files);

// ---- accessors, buffer views, buffers (gltf_accessors.cpp) ---------------------------------------

/// "the file has 1 accessor" / "... 3 accessors"
std::string has_count(std::size_t n, std::string_view singular, std::string_view plural);

/// The bytes of bufferViews[index], checked against its buffer.
Result<std::span<const std::uint8_t>> buffer_view_bytes(const tinygltf::Model& model, int index,
                                                        std::string_view referrer, std::string_view source);

/// What an accessor must be to be read as `role`.
struct AccessorSpec {
  std::string_view role; ///< "POSITION", "TEXCOORD_0", "indices"
  int type = TINYGLTF_TYPE_SCALAR;
  std::vector<int> component_types;
  bool integers_normalized = false; ///< integer components must be normalized (texture coordinates)
  std::size_t max_count = SIZE_MAX;
};

/// A checked accessor: element i is at data + i * stride, within its buffer view.
struct AccessorView {
  std::string label; ///< "accessors[2] (POSITION)"
  const std::uint8_t* data = nullptr;
  std::size_t stride = 0;
  std::size_t count = 0;
  int component_type = 0;
};

/// accessors[index], checked (kind, buffer view, byte range) to be read as `spec.role`.
Result<AccessorView> accessor_view(const tinygltf::Model& model, int index, const AccessorSpec& spec,
                                   std::string_view referrer, std::string_view source);

/// The elements of a checked accessor appended to `out`: finite coordinates within +-1e30, indices
/// below `vertex_count` (offset by `base`).
Result<void> append_positions(const AccessorView& view, std::string_view source,
                              std::vector<glm::dvec3>& out);
Result<void> append_texcoords(const AccessorView& view, std::string_view source,
                              std::vector<glm::dvec2>& out);
Result<void> append_indices(const AccessorView& view, std::size_t vertex_count, std::size_t base,
                            std::string_view source, std::vector<std::uint32_t>& out);

} // namespace vkcloth::gltf_detail
