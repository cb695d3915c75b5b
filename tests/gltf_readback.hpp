// SPDX-License-Identifier: MIT
// Test helpers: read an exported glTF back with tinygltf and rebuild every frame from the encoding
// docs/scene-format.md "Export" describes (base POSITION + morph targets weighted by a STEP
// "weights" animation), and read an OBJ frame back.
#pragma once

#include <doctest/doctest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace vkcloth::test {

/// An exported animation as the file holds it: vertices in the file's order.
struct GltfAnimation {
  tinygltf::Model model;
  std::vector<float> times;                    ///< one per frame
  std::vector<std::vector<glm::vec3>> frames;  ///< positions per frame, rebuilt from the encoding
  std::vector<std::vector<glm::vec3>> normals; ///< NORMAL per frame, rebuilt the same way
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
};

/// The accessor's elements as `count * components` values of type T (tightly packed data).
template <typename T> std::vector<T> accessor_values(const tinygltf::Model& m, int index) {
  REQUIRE(index >= 0);
  REQUIRE(std::size_t(index) < m.accessors.size());
  const tinygltf::Accessor& a = m.accessors[std::size_t(index)];
  const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
  const std::size_t n = a.count * std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(a.type)));
  REQUIRE(std::size_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType))) == sizeof(T));
  REQUIRE(a.byteOffset + n * sizeof(T) <= v.byteLength);
  std::vector<T> out(n);
  std::memcpy(out.data(), m.buffers[std::size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset,
              n * sizeof(T));
  return out;
}

inline std::vector<glm::vec3> as_vec3(const std::vector<float>& xyz) {
  std::vector<glm::vec3> out(xyz.size() / 3);
  for (std::size_t k = 0; k < out.size(); ++k)
    out[k] = {xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
  return out;
}

inline std::vector<std::uint32_t> read_indices(const tinygltf::Model& m, int index) {
  const int type = m.accessors[std::size_t(index)].componentType;
  if (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
    const auto narrow = accessor_values<std::uint16_t>(m, index);
    return {narrow.begin(), narrow.end()};
  }
  REQUIRE(type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  return accessor_values<std::uint32_t>(m, index);
}

/// Frame f = base + sum_i w_f[i] target_i, with w_f the weights animation's output at key f:
/// `attribute` ("POSITION" or "NORMAL") of every frame.
inline std::vector<std::vector<glm::vec3>>
rebuild_attribute(const GltfAnimation& g, const std::string& attribute, const std::vector<float>& weights) {
  const tinygltf::Primitive& prim = g.model.meshes.at(0).primitives.at(0);
  const auto base = as_vec3(accessor_values<float>(g.model, prim.attributes.at(attribute)));
  const std::size_t targets = prim.targets.size();
  std::vector<std::vector<glm::vec3>> deltas;
  for (const auto& t : prim.targets)
    deltas.push_back(as_vec3(accessor_values<float>(g.model, t.at(attribute))));
  std::vector<std::vector<glm::vec3>> out;
  for (std::size_t f = 0; f < g.times.size(); ++f) {
    std::vector<glm::vec3> frame = base;
    for (std::size_t i = 0; i < targets; ++i)
      for (std::size_t k = 0; k < frame.size(); ++k)
        frame[k] += weights[f * targets + i] * deltas[i][k];
    out.push_back(std::move(frame));
  }
  return out;
}

inline void rebuild_frames(GltfAnimation& g) {
  const tinygltf::Primitive& prim = g.model.meshes.at(0).primitives.at(0);
  if (g.model.animations.empty()) {
    REQUIRE(prim.targets.empty());
    g.times = {0.0f};
    g.frames = rebuild_attribute(g, "POSITION", {});
    g.normals = rebuild_attribute(g, "NORMAL", {});
    return;
  }
  const tinygltf::Animation& anim = g.model.animations.at(0);
  REQUIRE(anim.channels.size() == 1);
  CHECK(anim.channels[0].target_path == "weights");
  CHECK(anim.channels[0].target_node == 0);
  const tinygltf::AnimationSampler& s = anim.samplers.at(std::size_t(anim.channels[0].sampler));
  CHECK(s.interpolation == "STEP");
  g.times = accessor_values<float>(g.model, s.input);
  const auto weights = accessor_values<float>(g.model, s.output);
  const std::size_t targets = prim.targets.size();
  REQUIRE(weights.size() == g.times.size() * targets);
  g.frames = rebuild_attribute(g, "POSITION", weights);
  g.normals = rebuild_attribute(g, "NORMAL", weights);
}

/// Images are not decoded: the tests compare the embedded bytes.
inline bool keep_image_bytes(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                             const unsigned char*, int, void*) {
  return true;
}

inline GltfAnimation read_gltf_animation(const std::filesystem::path& path) {
  GltfAnimation g;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_image_bytes, nullptr);
  std::string err, warn;
  const bool ok = path.extension() == ".glb" ? loader.LoadBinaryFromFile(&g.model, &err, &warn, path.string())
                                             : loader.LoadASCIIFromFile(&g.model, &err, &warn, path.string());
  REQUIRE_MESSAGE(ok, path.string(), ": ", err);
  CHECK_MESSAGE(warn.empty(), warn);
  REQUIRE(g.model.meshes.size() == 1);
  const tinygltf::Primitive& prim = g.model.meshes[0].primitives.at(0);
  CHECK(prim.mode == TINYGLTF_MODE_TRIANGLES);
  const auto uv = accessor_values<float>(g.model, prim.attributes.at("TEXCOORD_0"));
  for (std::size_t k = 0; k + 1 < uv.size(); k += 2)
    g.uvs.emplace_back(uv[k], uv[k + 1]);
  g.indices = read_indices(g.model, prim.indices);
  rebuild_frames(g);
  return g;
}

/// An OBJ frame as written: v (double), vt, and f a/a b/b c/c triangles (0-based here).
struct ObjFrame {
  std::vector<glm::dvec3> positions;
  std::vector<glm::dvec2> uvs;
  std::vector<std::uint32_t> indices;
};

inline ObjFrame read_obj_frame(const std::filesystem::path& path) {
  ObjFrame o;
  std::ifstream in(path);
  REQUIRE_MESSAGE(in.good(), path.string());
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      std::string x, y, z;
      s >> x >> y >> z;
      o.positions.emplace_back(std::stod(x), std::stod(y), std::stod(z));
    } else if (tag == "vt") {
      std::string u, v;
      s >> u >> v;
      o.uvs.emplace_back(std::stod(u), std::stod(v));
    } else if (tag == "f") {
      for (std::string corner; s >> corner;) {
        const auto slash = corner.find('/');
        REQUIRE(slash != std::string::npos);
        CHECK(corner.substr(0, slash) == corner.substr(slash + 1)); // v and vt share the index
        o.indices.push_back(std::uint32_t(std::stoul(corner.substr(0, slash)) - 1));
      }
    }
  }
  return o;
}

/// Float data: 1e-6 relative to the coordinate (and 1e-6 absolute near zero).
inline bool close(double a, double b) {
  return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b));
}

} // namespace vkcloth::test
