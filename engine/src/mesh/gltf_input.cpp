// SPDX-License-Identifier: MIT
// The glTF reader's guard around tinygltf, which trusts its input more than a reader of untrusted
// files may: an image's bufferView is read without a bounds check, a GLB's BIN chunk may be read
// past the end of the data, "extras" are converted recursively, and its default file-path expansion
// runs wordexp() on URIs. So before it runs: the GLB container is checked, the JSON is parsed with
// the scene parser (line:column errors, nesting limit) and external buffers are looked up here, each
// buffer's size checked against its file, data: URI or BIN chunk. Then tinygltf gets file callbacks
// that resolve URIs only against the base directory (none when reading from memory), expand
// nothing, read regular files only and stop at max_mesh_bytes, and an image loader that keeps the
// encoded bytes (an image in a bufferView is read later, once that view is checked).
#include <cstring>

#include "internal/json_parse.hpp"
#include "gltf_detail.hpp"

namespace vkcloth::gltf_detail {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- GLB container ---------------------------------------------------------------------------------

constexpr std::uint32_t glb_magic = 0x46546C67; // "glTF"
constexpr std::uint32_t chunk_json = 0x4E4F534A;
constexpr std::uint32_t chunk_bin = 0x004E4942;

std::uint32_t read_u32(std::span<const std::uint8_t> bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4); // GLB is little-endian, as are the hosts vkcloth runs on
  return v;
}

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

} // namespace

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
  if (scene_detail::JsonParseFailure f; !scene_detail::parse_json(text, doc, f))
    return make_error(ErrorCode::parse, scene_detail::describe(f, text, where));
  if (!doc.is_object())
    return make_error(ErrorCode::parse,
                      fmt::format("{}: the glTF JSON must be an object, got {}", where, doc.type_name()));
  return doc;
}

namespace {

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

} // namespace

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

namespace {

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

} // namespace

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

} // namespace vkcloth::gltf_detail
