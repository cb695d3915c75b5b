// SPDX-License-Identifier: MIT
// The animated cloth out to glTF 2.0 (built with tinygltf) and OBJ. The glTF encoding (the first
// frame as the mesh, one morph target per later frame, a STEP "weights" animation) and its size
// per frame are described in docs/scene-format.md "Export".
#include "vkcloth/export.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <tiny_gltf.h>

#include "vkcloth/topology.hpp"

namespace vkcloth {
namespace detail {

/// The cloth's surface in output (file) vertex order (AnimationRecorder::Impl holds one, hence not
/// file-local).
struct ExportSurface {
  std::shared_ptr<const ClothTopology> topology; ///< its normal fans (vertex_normals)
  std::vector<std::uint32_t> order;              ///< output vertex k is particle order[k]
  std::vector<std::uint32_t> triangles;          ///< output vertex indices, counter-clockwise
  std::vector<glm::vec2> uvs;                    ///< per output vertex, v down (glTF's and the renderer's)
};

} // namespace detail

using detail::ExportSurface;

namespace {

Error invalid(std::string message) {
  return make_error(ErrorCode::invalid_argument, std::move(message));
}

/// A mesh's particles map to distinct file vertices, else its outputs would be ambiguous.
Result<void> check_distinct_sources(const ParticleSystem& system, std::span<const std::uint32_t> order) {
  if (!system.surface || system.surface->source_vertex.empty())
    return {};
  const auto& source = system.surface->source_vertex;
  for (std::size_t k = 1; k < order.size(); ++k)
    if (source[order[k - 1]] == source[order[k]])
      return invalid(fmt::format("surface source_vertex maps particles {} and {} to the same file vertex {}",
                                 order[k - 1], order[k], source[order[k]]));
  return {};
}

Result<ExportSurface> export_surface(const ParticleSystem& system) {
  if (!system.grid && !system.surface)
    return invalid(
        fmt::format("the system ({} particles) has no surface to export: a chain has no triangles; "
                    "only cloths (a grid or a mesh) can be exported",
                    system.size()));
  auto topology = ClothTopology::create(system); // validates the system
  if (!topology)
    return topology.error();
  // The topology's lists: a mesh's own triangles and uvs, or those it makes for a grid.
  const std::span<const std::uint32_t> triangles = (*topology)->triangles();
  const std::span<const glm::vec2> uvs = (*topology)->uvs();
  if (triangles.empty())
    return invalid(fmt::format("the cloth ({} particles) has no triangles to export", system.size()));

  ExportSurface out;
  out.topology = *topology;
  out.order = file_order(system);
  VKCLOTH_TRY(check_distinct_sources(system, out.order));
  std::vector<std::uint32_t> rank(system.size());
  out.uvs.resize(system.size());
  for (std::uint32_t k = 0; k < out.order.size(); ++k) {
    rank[out.order[k]] = k;
    out.uvs[k] = uvs[out.order[k]];
  }
  out.triangles.reserve(triangles.size());
  for (const std::uint32_t p : triangles)
    out.triangles.push_back(rank[p]);
  return out;
}

/// Finite and within float's range (converting a larger double to float is undefined).
bool fits_float(double x) {
  return std::abs(x) <= double(std::numeric_limits<float>::max());
}

/// One position per particle, each one a float can hold (what a glTF float accessor stores).
Result<void> check_positions(std::span<const glm::dvec3> positions, std::size_t particles,
                             std::string_view what) {
  if (positions.size() != particles)
    return invalid(fmt::format("{}: {} positions for {} particles", what, positions.size(), particles));
  for (std::size_t p = 0; p < positions.size(); ++p) {
    const glm::dvec3 x = positions[p];
    if (!fits_float(x.x) || !fits_float(x.y) || !fits_float(x.z))
      return invalid(fmt::format("{}: particle {} has a position ({}, {}, {}) that is not finite in float",
                                 what, p, x.x, x.y, x.z));
  }
  return {};
}

/// x, y, z per output vertex, as floats.
std::vector<float> output_positions(const ExportSurface& surface, std::span<const glm::dvec3> positions) {
  std::vector<float> out;
  out.reserve(positions.size() * 3);
  for (const std::uint32_t p : surface.order)
    for (int c = 0; c < 3; ++c)
      out.push_back(static_cast<float>(positions[p][c]));
  return out;
}

/// The renderer's smooth normals of one output frame (x, y, z per output vertex, as stored):
/// ClothTopology::vertex_normals, the solvers' formula, on these float positions, in output order.
/// glTF requires unit normals: a degenerate fan's (zero) becomes +z, vkcloth's up.
std::vector<float> output_normals(const ExportSurface& surface, const std::vector<float>& frame) {
  std::vector<glm::vec3> positions(surface.order.size());
  for (std::size_t k = 0; k < surface.order.size(); ++k)
    positions[surface.order[k]] = {frame[3 * k], frame[3 * k + 1], frame[3 * k + 2]};
  const std::vector<glm::vec3> normals = surface.topology->vertex_normals(positions).value(); // sizes match
  std::vector<float> out;
  out.reserve(frame.size());
  for (const std::uint32_t p : surface.order) {
    const glm::vec3 n = normals[p] == glm::vec3(0.0f) ? glm::vec3(0.0f, 0.0f, 1.0f) : normals[p];
    out.insert(out.end(), {n.x, n.y, n.z});
  }
  return out;
}

Result<void> write_bytes(const std::filesystem::path& path, std::string_view bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f)
    return make_error(ErrorCode::io, fmt::format("cannot write {}: {}", path.string(), std::strerror(errno)));
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  const int saved_errno = errno;
  if (std::fclose(f) != 0 || !written)
    return make_error(ErrorCode::io, fmt::format("writing {} failed: {}", path.string(),
                                                 std::strerror(written ? errno : saved_errno)));
  return {};
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

/// "image/png" or "image/jpeg" from the file's first bytes, else empty.
std::string image_mime_type(std::span<const std::uint8_t> bytes) {
  static constexpr std::array<std::uint8_t, 8> png{0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  static constexpr std::array<std::uint8_t, 3> jpeg{0xFF, 0xD8, 0xFF};
  const auto starts_with = [&](std::span<const std::uint8_t> magic) {
    return bytes.size() >= magic.size() && std::equal(magic.begin(), magic.end(), bytes.begin());
  };
  if (starts_with(png))
    return "image/png";
  if (starts_with(jpeg))
    return "image/jpeg";
  return {};
}

// ---- glTF model building --------------------------------------------------------------------

/// Appends `bytes` to buffer 0 at a 4-byte boundary (every accessor here is 4-byte aligned) as a
/// new buffer view; returns its index.
int add_view(tinygltf::Model& m, const void* bytes, std::size_t size, int target = 0) {
  auto& data = m.buffers[0].data;
  data.resize((data.size() + 3) & ~std::size_t{3}, 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const auto* first = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), first, first + size);
  m.bufferViews.push_back(std::move(view));
  return int(m.bufferViews.size()) - 1;
}

int add_accessor(tinygltf::Model& m, int view, int component_type, std::size_t count, int type) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.componentType = component_type;
  a.count = count;
  a.type = type;
  m.accessors.push_back(std::move(a));
  return int(m.accessors.size()) - 1;
}

/// A float VEC3 vertex attribute with the min and max the spec requires for POSITION (morph
/// target deltas included).
int add_vec3_attribute(tinygltf::Model& m, const std::vector<float>& xyz) {
  std::vector<double> lo(3, std::numeric_limits<double>::infinity()), hi(3, -lo[0]);
  for (std::size_t k = 0; k < xyz.size(); ++k) {
    lo[k % 3] = std::min(lo[k % 3], double(xyz[k]));
    hi[k % 3] = std::max(hi[k % 3], double(xyz[k]));
  }
  const int view = add_view(m, xyz.data(), xyz.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
  const int a = add_accessor(m, view, TINYGLTF_COMPONENT_TYPE_FLOAT, xyz.size() / 3, TINYGLTF_TYPE_VEC3);
  m.accessors[a].minValues = std::move(lo);
  m.accessors[a].maxValues = std::move(hi);
  return a;
}

/// A float VEC3 vertex attribute without bounds (NORMAL and its morph deltas).
int add_vec3_values(tinygltf::Model& m, const std::vector<float>& xyz) {
  const int view = add_view(m, xyz.data(), xyz.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
  return add_accessor(m, view, TINYGLTF_COMPONENT_TYPE_FLOAT, xyz.size() / 3, TINYGLTF_TYPE_VEC3);
}

int add_uvs(tinygltf::Model& m, const std::vector<glm::vec2>& uvs) {
  static_assert(sizeof(glm::vec2) == 2 * sizeof(float));
  const int view = add_view(m, uvs.data(), uvs.size() * sizeof(glm::vec2), TINYGLTF_TARGET_ARRAY_BUFFER);
  return add_accessor(m, view, TINYGLTF_COMPONENT_TYPE_FLOAT, uvs.size(), TINYGLTF_TYPE_VEC2);
}

/// 16-bit indices when every index fits below 65535 (the spec forbids the type's largest value).
int add_indices(tinygltf::Model& m, const std::vector<std::uint32_t>& triangles, std::size_t vertex_count) {
  if (vertex_count <= 0xFFFF) {
    const std::vector<std::uint16_t> narrow(triangles.begin(), triangles.end());
    const int view = add_view(m, narrow.data(), narrow.size() * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    return add_accessor(m, view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, narrow.size(), TINYGLTF_TYPE_SCALAR);
  }
  const int view = add_view(m, triangles.data(), triangles.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  return add_accessor(m, view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, triangles.size(), TINYGLTF_TYPE_SCALAR);
}

/// A double-sided, non-metallic cloth material; with the texture as its base colour.
int add_material(tinygltf::Model& m, const std::optional<MeshTexture>& texture,
                 const std::string& mime_type) {
  tinygltf::Material mat;
  mat.name = "cloth";
  mat.doubleSided = true; // a cloth is seen from both sides
  mat.pbrMetallicRoughness.metallicFactor = 0.0;
  mat.pbrMetallicRoughness.roughnessFactor = 0.9;
  if (texture) {
    tinygltf::Image image;
    image.bufferView = add_view(m, texture->encoded.data(), texture->encoded.size());
    image.mimeType = mime_type;
    m.images.push_back(std::move(image));
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    m.samplers.push_back(sampler);
    tinygltf::Texture tex;
    tex.source = 0;
    tex.sampler = 0;
    m.textures.push_back(tex);
    mat.pbrMetallicRoughness.baseColorTexture.index = 0;
  } else {
    mat.pbrMetallicRoughness.baseColorFactor = {0.8, 0.8, 0.8, 1.0};
  }
  m.materials.push_back(std::move(mat));
  return 0;
}

/// Frame f > 0 as a morph target: its positions (or normals) minus the first frame's.
std::vector<float> frame_delta(const std::vector<float>& frame, const std::vector<float>& base) {
  std::vector<float> delta(frame.size());
  for (std::size_t k = 0; k < frame.size(); ++k)
    delta[k] = frame[k] - base[k];
  return delta;
}

/// The "weights" channel: STEP keys at the frame times; at key f only target f - 1 has weight 1
/// (key 0: all zero, the base mesh is frame 0).
void add_weights_animation(tinygltf::Model& m, const std::vector<float>& times, int node) {
  const std::size_t frames = times.size(), targets = frames - 1;
  std::vector<float> weights(frames * targets, 0.0f);
  for (std::size_t f = 1; f < frames; ++f)
    weights[f * targets + (f - 1)] = 1.0f;
  const int input = add_accessor(m, add_view(m, times.data(), frames * sizeof(float)),
                                 TINYGLTF_COMPONENT_TYPE_FLOAT, frames, TINYGLTF_TYPE_SCALAR);
  m.accessors[input].minValues = {times.front()}; // the spec requires both on animation inputs
  m.accessors[input].maxValues = {times.back()};
  const int output = add_accessor(m, add_view(m, weights.data(), weights.size() * sizeof(float)),
                                  TINYGLTF_COMPONENT_TYPE_FLOAT, weights.size(), TINYGLTF_TYPE_SCALAR);
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "STEP";
  tinygltf::AnimationChannel channel;
  channel.sampler = 0;
  channel.target_node = node;
  channel.target_path = "weights";
  tinygltf::Animation animation;
  animation.name = "simulation";
  animation.samplers.push_back(sampler);
  animation.channels.push_back(channel);
  m.animations.push_back(std::move(animation));
}

/// glTF's binary container stores its length in 32 bits; leave room for the JSON.
constexpr std::size_t max_gltf_buffer_bytes = (std::size_t{1} << 32) - (std::size_t{64} << 20);

} // namespace

// ---- public ---------------------------------------------------------------------------------

std::vector<std::uint32_t> file_order(const ParticleSystem& system) {
  std::vector<std::uint32_t> order(system.size());
  std::iota(order.begin(), order.end(), 0u);
  if (system.surface && system.surface->source_vertex.size() == system.size()) {
    const auto& source = system.surface->source_vertex;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return source[a] < source[b]; });
  }
  return order;
}

std::uint32_t file_vertex(const ParticleSystem& system, std::uint32_t p) {
  if (system.surface && p < system.surface->source_vertex.size())
    return system.surface->source_vertex[p];
  return p;
}

Result<void> check_gltf_path(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext != ".glb" && ext != ".gltf")
    return invalid(
        fmt::format("cannot export {}: the extension \"{}\" is not .glb or .gltf", path.string(), ext));
  return {};
}

struct AnimationRecorder::Impl {
  ExportSurface surface;
  std::optional<MeshTexture> texture;
  std::string texture_mime;
  std::vector<float> times;               ///< seconds, strictly increasing
  std::vector<std::vector<float>> frames; ///< x, y, z per output vertex

  tinygltf::Model model() const;

  /// Checked as frames come, before they fill the memory: `frame_total` frames must fit in a glb.
  Result<void> check_size(std::size_t frame_total) const {
    const std::size_t n = surface.order.size();
    const std::size_t bytes = frame_total * n * 24 + n * 8 + surface.triangles.size() * 4 +
                              frame_total * frame_total * 4 + (texture ? texture->encoded.size() : 0);
    if (bytes > max_gltf_buffer_bytes)
      return invalid(
          fmt::format("{} frames of {} vertices need about {} bytes, over glTF's 4 GiB limit: record "
                      "fewer frames",
                      frame_total, n, bytes));
    return {};
  }
};

/// One mesh (frame 0 as POSITION, frame f > 0 as morph target f - 1) on one node that turns
/// vkcloth's z-up world into glTF's y-up; with two frames or more, the weights animation.
tinygltf::Model AnimationRecorder::Impl::model() const {
  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = "vkcloth";
  m.buffers.emplace_back();
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.indices = add_indices(m, surface.triangles, surface.order.size());
  primitive.attributes["POSITION"] = add_vec3_attribute(m, frames.front());
  const std::vector<float> base_normals = output_normals(surface, frames.front());
  primitive.attributes["NORMAL"] = add_vec3_values(m, base_normals);
  primitive.attributes["TEXCOORD_0"] = add_uvs(m, surface.uvs);
  primitive.material = add_material(m, texture, texture_mime);
  for (std::size_t f = 1; f < frames.size(); ++f)
    primitive.targets.push_back(
        {{"POSITION", add_vec3_attribute(m, frame_delta(frames[f], frames.front()))},
         {"NORMAL", add_vec3_values(m, frame_delta(output_normals(surface, frames[f]), base_normals))}});
  tinygltf::Mesh mesh;
  mesh.name = "cloth";
  mesh.primitives.push_back(std::move(primitive));
  m.meshes.push_back(std::move(mesh));

  tinygltf::Node node;
  node.name = "cloth";
  node.mesh = 0;
  const double half = std::sqrt(0.5); // -90 degrees about x: z up becomes y up
  node.rotation = {-half, 0.0, 0.0, half};
  m.nodes.push_back(std::move(node));
  tinygltf::Scene scene;
  scene.nodes = {0};
  m.scenes.push_back(std::move(scene));
  m.defaultScene = 0;
  if (frames.size() > 1)
    add_weights_animation(m, times, 0);
  return m;
}

AnimationRecorder::AnimationRecorder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AnimationRecorder::AnimationRecorder(AnimationRecorder&&) noexcept = default;
AnimationRecorder& AnimationRecorder::operator=(AnimationRecorder&&) noexcept = default;
AnimationRecorder::~AnimationRecorder() = default;

Result<AnimationRecorder> AnimationRecorder::create(const ParticleSystem& system,
                                                    std::optional<MeshTexture> texture) {
  auto surface = export_surface(system);
  if (!surface)
    return surface.error();
  auto impl = std::make_unique<Impl>();
  impl->surface = std::move(*surface);
  if (texture) {
    impl->texture_mime = image_mime_type(texture->encoded);
    if (impl->texture_mime.empty())
      return invalid(fmt::format("the texture {} ({} bytes) is neither PNG nor JPEG", texture->source,
                                 texture->encoded.size()));
    impl->texture = std::move(texture);
  }
  return AnimationRecorder(std::move(impl));
}

Result<void> AnimationRecorder::add_frame(double time, std::span<const glm::dvec3> positions) {
  const std::string what = fmt::format("frame {} (time {} s)", impl_->frames.size(), time);
  if (!fits_float(time) || time < 0.0)
    return invalid(fmt::format("{}: the time must be finite and not negative", what));
  const auto t = static_cast<float>(time); // as the file stores it
  if (!impl_->times.empty() && t <= impl_->times.back())
    return invalid(fmt::format("{}: not after the previous frame's time {} s (compared as float seconds)",
                               what, impl_->times.back()));
  VKCLOTH_TRY(check_positions(positions, impl_->surface.order.size(), what));
  VKCLOTH_TRY(impl_->check_size(impl_->frames.size() + 1));
  impl_->times.push_back(t);
  impl_->frames.push_back(output_positions(impl_->surface, positions));
  return {};
}

std::size_t AnimationRecorder::frame_count() const {
  return impl_->frames.size();
}

Result<void> AnimationRecorder::write_gltf(const std::filesystem::path& path) const {
  VKCLOTH_TRY(check_gltf_path(path));
  if (impl_->frames.empty())
    return invalid(fmt::format("cannot export {}: no frames were recorded", path.string()));
  const bool binary = lower_extension(path) == ".glb";
  const tinygltf::Model model = impl_->model();
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  // .gltf: the buffer goes in as a base64 data: URI (the stream writer embeds it).
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary))
    return make_error(ErrorCode::io, fmt::format("cannot encode {} as glTF", path.string()));
  return write_bytes(path, out.view());
}

Result<void> write_obj_frame(const std::filesystem::path& path, const ParticleSystem& system,
                             std::span<const glm::dvec3> positions) {
  auto surface = export_surface(system);
  if (!surface)
    return surface.error();
  VKCLOTH_TRY(check_positions(positions, system.size(), fmt::format("OBJ frame {}", path.string())));
  // Float values (a float solver's) as the shortest text that reads back to the same float, others
  // as the shortest that reads back to the same double.
  const auto number = [](double x) {
    const auto f = static_cast<float>(x);
    return double(f) == x ? fmt::format("{}", f) : fmt::format("{}", x);
  };
  std::string text = fmt::format("# vkcloth: {} vertices in the file's order, {} triangles\n",
                                 surface->order.size(), surface->triangles.size() / 3);
  for (const std::uint32_t p : surface->order) {
    const glm::dvec3 x = positions[p];
    text += fmt::format("v {} {} {}\n", number(x.x), number(x.y), number(x.z));
  }
  // OBJ texture coordinates run up from the image's bottom row; glTF's and the renderer's run down.
  for (const glm::vec2 uv : surface->uvs)
    text += fmt::format("vt {} {}\n", uv.x, 1.0f - uv.y);
  const auto& tri = surface->triangles;
  for (std::size_t k = 0; k < tri.size(); k += 3)
    text += fmt::format("f {0}/{0} {1}/{1} {2}/{2}\n", tri[k] + 1, tri[k + 1] + 1, tri[k + 2] + 1);
  return write_bytes(path, text);
}

} // namespace vkcloth
