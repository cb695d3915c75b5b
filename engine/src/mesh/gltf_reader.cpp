// SPDX-License-Identifier: MIT
// glTF 2.0 reader (tinygltf): every TRIANGLES primitive of the first mesh (mode 4, or no mode),
// merged in order, with its POSITION, TEXCOORD_0 and indices as stored. Nothing else is applied: no
// node transform, skin or morph target; the mesh comes out in its own space. The base-colour texture
// of the first primitive whose material has one is kept as the image file's encoded bytes.
//
// tinygltf trusts its input more than a reader of untrusted files may: an image's bufferView is
// read without a bounds check, a GLB's BIN chunk may be read past the end of the data, "extras"
// are converted recursively, and its default file-path expansion runs wordexp() on URIs. So before
// it runs: the GLB container is checked, the JSON is parsed with the scene parser (line:column
// errors, nesting limit), external buffers are looked up here, and tinygltf gets file callbacks that
// resolve URIs only against the base directory (none when reading from memory), expand nothing, read
// regular files only and stop at max_mesh_bytes. After it runs, every accessor, buffer view and
// buffer is checked before a byte of it is read.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "../scene/json_parse.hpp"
#include "mesh_io.hpp"

namespace vkcloth {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double max_abs_coordinate = 1e30;

Error gltf_error(std::string_view source, std::string_view what, ErrorCode code = ErrorCode::parse) {
  return make_error(code, fmt::format("{}: {}", source, what));
}

// ---- GLB container ---------------------------------------------------------------------------------

constexpr std::uint32_t glb_magic = 0x46546C67; // "glTF"
constexpr std::uint32_t chunk_json = 0x4E4F534A;
constexpr std::uint32_t chunk_bin = 0x004E4942;

std::uint32_t read_u32(std::span<const std::uint8_t> bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4); // GLB is little-endian, as are the hosts vkcloth runs on
  return v;
}

/// The parts of a GLB that tinygltf reads: `length` bytes (the header's), the JSON chunk in them.
struct GlbLayout {
  std::size_t length = 0;
  std::string_view json;
  std::optional<std::size_t> bin; ///< the BIN chunk's size, if there is one
};

Result<void> check_bin_chunk(std::span<const std::uint8_t> glb, std::size_t at, std::string_view source) {
  if (glb.size() - at < 8)
    return gltf_error(source,
                      fmt::format("truncated GLB: {} bytes after the JSON chunk, too few for a chunk header",
                                  glb.size() - at));
  const std::uint32_t length = read_u32(glb, at), type = read_u32(glb, at + 4);
  if (type != chunk_bin)
    return gltf_error(source, fmt::format("the second GLB chunk has type 0x{:08x}, expected BIN (0x{:08x})",
                                          type, chunk_bin));
  if (std::uint64_t(at) + 8 + length > glb.size())
    return gltf_error(source,
                      fmt::format("truncated GLB: the BIN chunk ends at byte {}, the GLB holds {} bytes",
                                  std::uint64_t(at) + 8 + length, glb.size()));
  if (length % 4 != 0)
    return gltf_error(source, fmt::format("the GLB BIN chunk's length {} is not a multiple of 4", length));
  return {};
}

Result<GlbLayout> check_glb(std::span<const std::uint8_t> bytes, std::string_view source) {
  if (bytes.size() < 12)
    return gltf_error(
        source,
        fmt::format("{} bytes is too short for a GLB (a 12-byte header, then a JSON chunk)", bytes.size()));
  if (read_u32(bytes, 0) != glb_magic)
    return gltf_error(source, "not a GLB file: it does not start with 'glTF'");
  if (const std::uint32_t version = read_u32(bytes, 4); version != 2)
    return gltf_error(source, fmt::format("GLB version {}; only glTF 2.0 is read", version));
  const std::uint32_t length = read_u32(bytes, 8);
  if (length > bytes.size())
    return gltf_error(source, fmt::format("truncated GLB: the header says {} bytes, the file holds {}",
                                          length, bytes.size()));
  const auto glb = bytes.first(length);
  if (glb.size() < 20)
    return gltf_error(source, fmt::format("truncated GLB: {} bytes hold no JSON chunk header", glb.size()));
  const std::uint32_t json_length = read_u32(glb, 12), json_type = read_u32(glb, 16);
  if (json_type != chunk_json)
    return gltf_error(source, fmt::format("the first GLB chunk has type 0x{:08x}, expected JSON (0x{:08x})",
                                          json_type, chunk_json));
  const std::uint64_t json_end = 20 + std::uint64_t(json_length);
  if (json_end > glb.size())
    return gltf_error(source,
                      fmt::format("truncated GLB: the JSON chunk ends at byte {}, the GLB holds {} bytes",
                                  json_end, glb.size()));
  GlbLayout layout{
      glb.size(), std::string_view(reinterpret_cast<const char*>(glb.data()) + 20, json_length), {}};
  if (json_end < glb.size()) {
    VKCLOTH_TRY(check_bin_chunk(glb, json_end, source));
    layout.bin = read_u32(glb, json_end);
  }
  return layout;
}

// ---- JSON and external files, before tinygltf ----------------------------------------------------

Result<json> parse_json_text(std::string_view text, std::string_view where) {
  json doc;
  if (scene_detail::JsonParseFailure f; !scene_detail::parse_json(text, doc, f)) {
    const auto [line, col] = scene_detail::line_col(text, f.byte);
    const std::string at = f.path.empty() ? "" : fmt::format(" at {}", f.path);
    return make_error(ErrorCode::parse, fmt::format("{}:{}:{}: invalid JSON{} (byte {}): {}", where, line,
                                                    col, at, f.byte, f.message));
  }
  if (!doc.is_object())
    return make_error(ErrorCode::parse,
                      fmt::format("{}: the glTF JSON must be an object, got {}", where, doc.type_name()));
  return doc;
}

/// A URI path as tinygltf decodes it (dlib::urldecode: %XX, and '+' as a space).
std::string decode_uri(std::string_view uri) {
  const auto hex = [](char c) -> unsigned {
    return c >= '0' && c <= '9'   ? unsigned(c - '0')
           : c >= 'a' && c <= 'f' ? unsigned(c - 'a' + 10)
           : c >= 'A' && c <= 'F' ? unsigned(c - 'A' + 10)
                                  : 0u;
  };
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      out += static_cast<char>((hex(uri[i + 1]) << 4) | hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

/// a + b and a * b, saturated at UINT64_MAX: byte ranges from the file, compared with buffer sizes.
std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}
std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}

bool is_data_uri(std::string_view uri) {
  return uri.starts_with("data:");
}

/// The size of a base64 data: URI's payload once decoded (padded or not).
std::size_t base64_decoded_size(std::string_view uri) {
  std::string_view payload = uri.substr(uri.find(',') + 1);
  while (payload.ends_with('='))
    payload.remove_suffix(1);
  return payload.size() / 4 * 3 + (payload.size() % 4 > 1 ? payload.size() % 4 - 1 : 0);
}

/// A buffer must hold byteLength bytes, whichever way it is stored: in a file beside the glTF, a
/// base64 data: URI or (no URI) the GLB's BIN chunk. Checked before tinygltf, whose messages for
/// these do not name the buffer.
Result<void> check_buffer(const json& buffer, std::size_t k, const fs::path& base_dir,
                          std::optional<std::size_t> bin_chunk, std::string_view source) {
  const auto byte_length = buffer.find("byteLength");
  const auto uri_value = buffer.find("uri");
  if (byte_length == buffer.end() || !byte_length->is_number_unsigned() ||
      (uri_value != buffer.end() && !uri_value->is_string()))
    return {}; // tinygltf refuses these, naming the property
  const std::uint64_t length = byte_length->get<std::uint64_t>();
  if (uri_value == buffer.end()) {
    if (bin_chunk && length > *bin_chunk)
      return gltf_error(source,
                        fmt::format("buffers[{}] has byteLength {}, but the GLB's BIN chunk holds {} bytes",
                                    k, length, *bin_chunk));
    return {};
  }
  const std::string& uri = uri_value->get_ref<const std::string&>();
  if (is_data_uri(uri)) {
    const std::size_t size = base64_decoded_size(uri);
    if (uri.find(";base64,") != std::string::npos && size != length)
      return gltf_error(source, fmt::format("buffers[{}]: its data: URI holds {} bytes, but byteLength is {}",
                                            k, size, length));
    return {};
  }
  if (base_dir.empty())
    return gltf_error(
        source,
        fmt::format("buffers[{}] is the file {}, but the glTF was read from memory without a base "
                    "directory",
                    k, mesh_detail::in_quotes(uri)),
        ErrorCode::io);
  const fs::path path = base_dir / decode_uri(uri);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return gltf_error(source,
                      fmt::format("buffers[{}]: cannot find the file {} in {}", k,
                                  mesh_detail::in_quotes(uri), base_dir.string()),
                      ErrorCode::io);
  if (const auto size = fs::file_size(path, ec); !ec && size != length)
    return gltf_error(source, fmt::format("buffers[{}]: the file {} holds {} bytes, but byteLength is {}", k,
                                          mesh_detail::in_quotes(uri), size, length));
  return {};
}

Result<void> check_buffers(const json& doc, const fs::path& base_dir, std::optional<std::size_t> bin_chunk,
                           std::string_view source) {
  const auto buffers = doc.find("buffers");
  if (buffers == doc.end() || !buffers->is_array())
    return {};
  for (std::size_t k = 0; k < buffers->size(); ++k)
    if ((*buffers)[k].is_object())
      VKCLOTH_TRY(check_buffer((*buffers)[k], k, base_dir, bin_chunk, source));
  return {};
}

// ---- tinygltf, with file access and image loading of our own -------------------------------------

/// tinygltf's file callbacks' user data: URIs resolve against `base_dir` only (tinygltf also tries
/// the working directory).
struct FileAccess {
  std::string base_dir;
};

bool file_exists(const std::string& path, void* user) {
  const std::string& base = static_cast<FileAccess*>(user)->base_dir;
  std::error_code ec;
  return !base.empty() && path.starts_with(base) && fs::is_regular_file(path, ec);
}

std::string expand_nothing(const std::string& path, void*) {
  return path;
}

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  if (!file_exists(path, user)) {
    *err = "not a regular file in the glTF's directory";
    return false;
  }
  auto bytes = mesh_detail::read_mesh_file(path);
  if (!bytes) {
    *err = bytes.error().message;
    return false;
  }
  *out = std::move(*bytes);
  return true;
}

bool write_nothing(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "vkcloth's glTF reader writes no files";
  return false;
}

/// Keeps an image's encoded bytes instead of decoding them. An image in a bufferView is skipped
/// here: tinygltf passes its bytes without checking the view against its buffer, so they are read
/// after that check (image_bytes).
bool keep_encoded_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                        const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && size > 0)
    image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

std::string first_line(const std::string& s) {
  return s.substr(0, s.find('\n'));
}

Result<tinygltf::Model> load_model(std::span<const std::uint8_t> bytes, bool binary, std::string_view source,
                                   FileAccess& files) {
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_encoded_image, nullptr);
  loader.SetFsCallbacks(
      tinygltf::FsCallbacks{&file_exists, &expand_nothing, &read_whole_file, &write_nothing, &files});
  tinygltf::Model model;
  std::string err, warn;
  const auto size = static_cast<unsigned>(bytes.size()); // <= max_mesh_bytes
  const bool loaded =
      binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), size, files.base_dir)
             : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                          size, files.base_dir);
  if (!loaded)
    return gltf_error(source,
                      fmt::format("invalid glTF (tinygltf: {})", mesh_detail::in_quotes(first_line(err))));
  return model;
}

// ---- accessors, buffer views, buffers ------------------------------------------------------------

std::string type_name(int type) {
  switch (type) {
  case TINYGLTF_TYPE_SCALAR:
    return "SCALAR";
  case TINYGLTF_TYPE_VEC2:
    return "VEC2";
  case TINYGLTF_TYPE_VEC3:
    return "VEC3";
  case TINYGLTF_TYPE_VEC4:
    return "VEC4";
  case TINYGLTF_TYPE_MAT2:
    return "MAT2";
  case TINYGLTF_TYPE_MAT3:
    return "MAT3";
  case TINYGLTF_TYPE_MAT4:
    return "MAT4";
  }
  return fmt::format("{}", type);
}

std::string component_name(int component_type) {
  switch (component_type) {
  case TINYGLTF_COMPONENT_TYPE_BYTE:
    return "5120 (byte)";
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
    return "5121 (unsigned byte)";
  case TINYGLTF_COMPONENT_TYPE_SHORT:
    return "5122 (short)";
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
    return "5123 (unsigned short)";
  case TINYGLTF_COMPONENT_TYPE_INT:
    return "5124 (int)";
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    return "5125 (unsigned int)";
  case TINYGLTF_COMPONENT_TYPE_FLOAT:
    return "5126 (float)";
  }
  return fmt::format("{}", component_type);
}

/// "the file has 1 accessor" / "... 3 accessors"
std::string has_count(std::size_t n, std::string_view singular, std::string_view plural) {
  return fmt::format("the file has {} {}", n, n == 1 ? singular : plural);
}

/// The bytes of bufferViews[index], checked against its buffer.
Result<std::span<const std::uint8_t>> buffer_view_bytes(const tinygltf::Model& model, int index,
                                                        std::string_view referrer, std::string_view source) {
  if (index < 0 || std::size_t(index) >= model.bufferViews.size())
    return gltf_error(source,
                      fmt::format("{} refers to bufferViews[{}], but {}", referrer, index,
                                  has_count(model.bufferViews.size(), "buffer view", "buffer views")));
  const tinygltf::BufferView& view = model.bufferViews[std::size_t(index)];
  if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
    return gltf_error(source, fmt::format("bufferViews[{}] refers to buffers[{}], but {}", index, view.buffer,
                                          has_count(model.buffers.size(), "buffer", "buffers")));
  const auto& data = model.buffers[std::size_t(view.buffer)].data;
  const std::uint64_t end = add_sat(view.byteOffset, view.byteLength);
  if (end > data.size())
    return gltf_error(source,
                      fmt::format("bufferViews[{}] covers bytes {}..{} of buffers[{}], which holds {} bytes",
                                  index, view.byteOffset, end, view.buffer, data.size()));
  return std::span<const std::uint8_t>(data.data() + view.byteOffset, view.byteLength);
}

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

Result<void> check_accessor_kind(const tinygltf::Accessor& a, const AccessorSpec& spec,
                                 const std::string& label, std::string_view source) {
  if (a.sparse.isSparse)
    return gltf_error(source, fmt::format("{} is sparse; sparse accessors are not supported", label));
  if (a.type != spec.type)
    return gltf_error(
        source, fmt::format("{} has type {}, expected {}", label, type_name(a.type), type_name(spec.type)));
  if (std::find(spec.component_types.begin(), spec.component_types.end(), a.componentType) ==
      spec.component_types.end()) {
    std::string expected;
    for (const int c : spec.component_types)
      expected += (expected.empty() ? "" : " or ") + component_name(c);
    return gltf_error(source, fmt::format("{} has componentType {}, expected {}", label,
                                          component_name(a.componentType), expected));
  }
  if (spec.integers_normalized && a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !a.normalized)
    return gltf_error(source, fmt::format("{} has componentType {} without \"normalized\": true", label,
                                          component_name(a.componentType)));
  if (a.count > spec.max_count)
    return gltf_error(source, fmt::format("{} has {} elements, more than max_particles ({})", label, a.count,
                                          spec.max_count));
  return {};
}

Result<AccessorView> accessor_view(const tinygltf::Model& model, int index, const AccessorSpec& spec,
                                   std::string_view referrer, std::string_view source) {
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    return gltf_error(source, fmt::format("{} refers to accessors[{}], but {}", referrer, index,
                                          has_count(model.accessors.size(), "accessor", "accessors")));
  const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
  AccessorView view{fmt::format("accessors[{}] ({})", index, spec.role), nullptr, 0, a.count,
                    a.componentType};
  VKCLOTH_TRY(check_accessor_kind(a, spec, view.label, source));
  if (a.bufferView < 0)
    return gltf_error(source, fmt::format("{} has no bufferView", view.label));
  auto bytes = buffer_view_bytes(model, a.bufferView, view.label, source);
  if (!bytes)
    return bytes.error();
  const std::size_t element = std::size_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType))) *
                              std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(a.type)));
  const std::size_t byte_stride = model.bufferViews[std::size_t(a.bufferView)].byteStride;
  if (byte_stride != 0 && byte_stride < element)
    return gltf_error(source,
                      fmt::format("bufferViews[{}] has byteStride {}, less than one element of {} ({} bytes)",
                                  a.bufferView, byte_stride, view.label, element));
  view.stride = byte_stride != 0 ? byte_stride : element;
  const std::uint64_t end = a.count == 0
                                ? a.byteOffset
                                : add_sat(add_sat(a.byteOffset, mul_sat(a.count - 1, view.stride)), element);
  if (end > bytes->size())
    return gltf_error(source, fmt::format("{} reads bytes {}..{} of bufferViews[{}], which holds {} bytes",
                                          view.label, a.byteOffset, end, a.bufferView, bytes->size()));
  view.data = bytes->data() + a.byteOffset;
  return view;
}

float read_float(const std::uint8_t* p) {
  float f = 0.0f;
  std::memcpy(&f, p, sizeof f);
  return f;
}

std::uint32_t read_unsigned(const std::uint8_t* p, int component_type) {
  switch (component_type) {
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
    return *p;
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
    std::uint16_t v = 0;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  default: {
    std::uint32_t v = 0;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  }
}

/// A float component that must be finite and within +-1e30.
Result<double> checked_component(float f, const AccessorView& view, std::size_t element,
                                 std::string_view what, std::string_view source) {
  const double v = f;
  if (!std::isfinite(v))
    return gltf_error(source, fmt::format("{} {} {}: {} is not finite", view.label, what, element, v));
  if (std::abs(v) > max_abs_coordinate)
    return gltf_error(source, fmt::format("{} {} {}: {} is out of range (|coordinate| > 1e30)", view.label,
                                          what, element, v));
  return v;
}

Result<void> append_positions(const AccessorView& view, std::string_view source,
                              std::vector<glm::dvec3>& out) {
  for (std::size_t i = 0; i < view.count; ++i) {
    const std::uint8_t* p = view.data + i * view.stride;
    glm::dvec3 x;
    for (int c = 0; c < 3; ++c) {
      auto v = checked_component(read_float(p + 4 * c), view, i, "vertex", source);
      if (!v)
        return v.error();
      x[c] = *v;
    }
    out.push_back(x);
  }
  return {};
}

Result<void> append_texcoords(const AccessorView& view, std::string_view source,
                              std::vector<glm::dvec2>& out) {
  const int size = tinygltf::GetComponentSizeInBytes(std::uint32_t(view.component_type));
  for (std::size_t i = 0; i < view.count; ++i) {
    const std::uint8_t* p = view.data + i * view.stride;
    glm::dvec2 uv;
    for (int c = 0; c < 2; ++c) {
      if (view.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
        auto v = checked_component(read_float(p + 4 * c), view, i, "element", source);
        if (!v)
          return v.error();
        uv[c] = *v;
      } else { // normalized unsigned byte / short
        const double max = view.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ? 255.0 : 65535.0;
        uv[c] = read_unsigned(p + size * c, view.component_type) / max;
      }
    }
    out.push_back(uv);
  }
  return {};
}

Result<void> append_indices(const AccessorView& view, std::size_t vertex_count, std::size_t base,
                            std::string_view source, std::vector<std::uint32_t>& out) {
  for (std::size_t i = 0; i < view.count; ++i) {
    const std::uint32_t index = read_unsigned(view.data + i * view.stride, view.component_type);
    if (index >= vertex_count)
      return gltf_error(source,
                        fmt::format("{} element {} is {}, out of range (the primitive has {} vertices)",
                                    view.label, i, index, vertex_count));
    out.push_back(static_cast<std::uint32_t>(base + index));
  }
  return {};
}

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
