// SPDX-License-Identifier: MIT
// AnimationRecorder and write_obj_frame: every frame read back (tinygltf, a plain OBJ parser)
// equals the recorded positions in the file's vertex order, for a grid cloth from the CPU solver
// and for a mesh cloth whose particles are a permutation of its file's vertices.
#include <doctest/doctest.h>

#include "gltf_readback.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "vkcloth/builders.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/export.hpp"
#include "vkcloth/topology.hpp"

using namespace vkcloth;
using namespace vkcloth::test;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path tmp(const std::string& name) {
  const fs::path dir(VKCLOTH_TEST_TMP);
  fs::create_directories(dir);
  return dir / name;
}

/// A 2 x 2 RGB PNG (red, green / blue, white).
const std::vector<std::uint8_t> tiny_png = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
    0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x02, 0x00, 0x00, 0x00, 0xfd,
    0xd4, 0x9a, 0x73, 0x00, 0x00, 0x00, 0x12, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8,
    0xcf, 0xc0, 0xc0, 0x00, 0xc2, 0x0c, 0xff, 0x81, 0x00, 0x00, 0x1f, 0xee, 0x05, 0xfb, 0x0b,
    0xd9, 0x68, 0x8b, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

struct Recorded {
  std::vector<double> times;
  std::vector<std::vector<glm::dvec3>> frames; ///< solver order
};

/// A 5 x 4 grid cloth falling under gravity: frames at steps 0, 3, 6, 9.
Recorded simulate_grid(const ParticleSystem& system) {
  SimParams params;
  REQUIRE(params.validate());
  auto solver = CpuSolver<float>::create(system, params);
  REQUIRE(solver);
  Recorded r;
  for (int f = 0; f < 4; ++f) {
    if (f > 0)
      REQUIRE(solver->run(3));
    r.times.push_back(0.06 * f);
    r.frames.emplace_back(solver->positions().begin(), solver->positions().end());
  }
  return r;
}

ParticleSystem grid_cloth() {
  ClothDesc desc;
  desc.nx = 5;
  desc.ny = 4;
  auto s = make_cloth(desc);
  REQUIRE(s);
  return *s;
}

/// A 3 x 2 vertex strip (file vertices v = 3 j + i, 4 triangles) whose particles are the file's
/// vertices shuffled: particle p is file vertex source[p].
constexpr std::array<std::uint32_t, 6> source = {3, 0, 5, 1, 4, 2};
constexpr std::array<std::uint32_t, 12> file_triangles = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};

glm::dvec3 file_position(std::uint32_t v, int frame) {
  return {0.1 * (v % 3) + 0.001 * frame, 0.25 * frame * frame, 0.1 * (v / 3) - 0.003 * v * frame};
}
glm::vec2 file_uv(std::uint32_t v) {
  return {0.5f * float(v % 3), float(v / 3)};
}

ParticleSystem shuffled_mesh_cloth() {
  ParticleSystem s;
  std::array<std::uint32_t, 6> particle_of{};
  for (std::uint32_t p = 0; p < 6; ++p)
    particle_of[source[p]] = p;
  Surface surface;
  surface.source_vertex.assign(source.begin(), source.end());
  for (std::uint32_t p = 0; p < 6; ++p) {
    s.particles.push_back(Particle{file_position(source[p], 0), {}, 0.1, source[p] >= 3});
    surface.uvs.push_back(file_uv(source[p]));
  }
  for (const std::uint32_t v : file_triangles)
    surface.triangles.push_back(particle_of[v]);
  for (std::size_t t = 0; t < file_triangles.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = particle_of[file_triangles[t + e]],
                          b = particle_of[file_triangles[t + (e + 1) % 3]];
      s.springs.push_back(Spring{a, b, glm::length(s.particles[a].position - s.particles[b].position), 40.0,
                                 SpringKind::structural});
    }
  s.surface = std::move(surface);
  s.finalize();
  REQUIRE(s.validate());
  return s;
}

Recorded mesh_frames(const ParticleSystem& system) {
  Recorded r;
  for (int f = 0; f < 3; ++f) {
    r.times.push_back(0.5 * f);
    std::vector<glm::dvec3> frame;
    for (std::size_t p = 0; p < system.size(); ++p)
      frame.push_back(file_position(file_vertex(system, std::uint32_t(p)), f));
    r.frames.push_back(std::move(frame));
  }
  return r;
}

AnimationRecorder record(const ParticleSystem& system, const Recorded& r,
                         std::optional<MeshTexture> texture = std::nullopt) {
  auto rec = AnimationRecorder::create(system, std::move(texture));
  REQUIRE_MESSAGE(rec, rec.error().message);
  for (std::size_t f = 0; f < r.frames.size(); ++f)
    REQUIRE(rec->add_frame(r.times[f], r.frames[f]));
  CHECK(rec->frame_count() == r.frames.size());
  return std::move(*rec);
}

/// Every frame read back equals the recorded one, vertex k being particle file_order(system)[k].
void check_frames(const GltfAnimation& g, const ParticleSystem& system, const Recorded& r) {
  const auto order = file_order(system);
  REQUIRE(g.frames.size() == r.frames.size());
  for (std::size_t f = 0; f < r.frames.size(); ++f) {
    CAPTURE(f);
    CHECK(g.times[f] == float(r.times[f]));
    REQUIRE(g.frames[f].size() == order.size());
    for (std::size_t k = 0; k < order.size(); ++k)
      for (int c = 0; c < 3; ++c)
        CHECK_MESSAGE(close(g.frames[f][k][c], r.frames[f][order[k]][c]), "vertex ", k, " axis ", c);
  }
}

} // namespace

TEST_CASE("export: a grid cloth's frames read back from .glb and .gltf") {
  const ParticleSystem system = grid_cloth();
  const Recorded r = simulate_grid(system);
  const AnimationRecorder rec = record(system, r);
  auto topology = ClothTopology::create(system);
  REQUIRE(topology);
  for (const char* name : {"grid.glb", "grid.gltf"}) {
    CAPTURE(name);
    REQUIRE(rec.write_gltf(tmp(name)));
    const GltfAnimation g = read_gltf_animation(tmp(name));
    check_frames(g, system, r);
    // A grid is in particle order: the topology's triangles and uvs as they are.
    CHECK(g.indices == std::vector<std::uint32_t>(topology.value()->triangles().begin(),
                                                  topology.value()->triangles().end()));
    REQUIRE(g.uvs.size() == system.size());
    for (std::size_t p = 0; p < system.size(); ++p)
      CHECK(g.uvs[p] == topology.value()->uvs()[p]);
    // The node turns vkcloth's z up into glTF's y up.
    const auto& rot = g.model.nodes.at(0).rotation;
    REQUIRE(rot.size() == 4);
    CHECK(rot[0] == doctest::Approx(-std::sqrt(0.5)));
    CHECK(rot[3] == doctest::Approx(std::sqrt(0.5)));
    // No texture: a plain material, no image.
    CHECK(g.model.images.empty());
    CHECK(g.model.materials.size() == 1);
  }
  // The .gltf embeds its buffer.
  CHECK(slurp(tmp("grid.gltf")).find("data:application/octet-stream;base64,") != std::string::npos);
}

TEST_CASE("export: a shuffled mesh cloth is written in its file's vertex order") {
  const ParticleSystem system = shuffled_mesh_cloth();
  CHECK(file_order(system) == std::vector<std::uint32_t>{1, 3, 5, 0, 4, 2});
  CHECK(file_vertex(system, 0) == 3);
  const Recorded r = mesh_frames(system);
  const AnimationRecorder rec = record(system, r);
  for (const char* name : {"mesh.glb", "mesh.gltf"}) {
    CAPTURE(name);
    REQUIRE(rec.write_gltf(tmp(name)));
    const GltfAnimation g = read_gltf_animation(tmp(name));
    check_frames(g, system, r);
    // In file order, vertex v is the file's vertex v: its position, uv and triangles.
    for (std::uint32_t v = 0; v < 6; ++v)
      for (int c = 0; c < 3; ++c)
        CHECK(close(g.frames[2][v][c], file_position(v, 2)[c]));
    CHECK(g.indices == std::vector<std::uint32_t>(file_triangles.begin(), file_triangles.end()));
    for (std::uint32_t v = 0; v < 6; ++v)
      CHECK(g.uvs[v] == file_uv(v));
    // Normals follow the vertices into the file's order.
    const auto topology = ClothTopology::create(system).value();
    const auto order = file_order(system);
    for (std::size_t f = 0; f < r.frames.size(); ++f) {
      const std::vector<glm::vec3> x(r.frames[f].begin(), r.frames[f].end());
      const std::vector<glm::vec3> n = topology->vertex_normals(x).value();
      for (std::size_t k = 0; k < order.size(); ++k)
        CHECK(glm::length(g.normals[f][k] - n[order[k]]) <= 1e-6f);
    }
  }
}

TEST_CASE("export: NORMAL and its morph deltas are the renderer's smooth normals of each frame, unit "
          "length, the positions are unchanged") {
  // The renderer draws the solver's normals buffer; CpuSolver<float>::normals() is what the GPU
  // tests compare it with. A step's normals are those of the positions it starts from (the force
  // pass), so frame f's reference normals are read after the step that starts at frame f.
  ClothDesc desc;
  desc.nx = 9;
  desc.ny = 7;
  SimParams params;
  params.wind.strength = 0.05; // a curved, twisted cloth: normals far from one another
  params.wind.direction = {0.3, 1.0, 0.2};
  const ParticleSystem system = make_cloth(desc).value();
  auto solver = CpuSolver<float>::create(system, params);
  REQUIRE(solver);
  Recorded r;
  std::vector<std::vector<glm::vec3>> renderer;
  for (int f = 0; f < 5; ++f) {
    REQUIRE(solver->run(f == 0 ? 0 : 7));
    r.times.push_back(0.14 * f);
    r.frames.emplace_back(solver->positions().begin(), solver->positions().end());
    REQUIRE(solver->step());
    renderer.emplace_back(solver->normals().begin(), solver->normals().end());
  }
  const AnimationRecorder rec = record(system, r);
  for (const char* name : {"normals.glb", "normals.gltf"}) {
    CAPTURE(name);
    REQUIRE(rec.write_gltf(tmp(name)));
    const GltfAnimation g = read_gltf_animation(tmp(name));
    check_frames(g, system, r); // positions exactly as before
    REQUIRE(g.normals.size() == r.frames.size());
    double worst = 0.0, worst_length = 0.0, spread = 0.0;
    for (std::size_t f = 0; f < g.normals.size(); ++f)
      for (std::size_t k = 0; k < system.size(); ++k) { // a grid: file order = particle order
        const glm::vec3 n = g.normals[f][k];
        worst = std::max(worst, double(glm::length(n - renderer[f][k])));
        worst_length = std::max(worst_length, std::abs(double(glm::length(n)) - 1.0));
        spread = std::max(spread, double(glm::length(n - g.normals[0][0])));
      }
    MESSAGE("normals vs the renderer's: max |dn| = " << worst << ", max ||n| - 1| = " << worst_length);
    CHECK(worst <= 1e-3);
    CHECK(worst_length <= 1e-5);
    CHECK(spread > 0.1); // not one flat normal
    // The base NORMAL itself is unit (the validator checks it).
    const tinygltf::Primitive& prim = g.model.meshes.at(0).primitives.at(0);
    for (const glm::vec3 n : as_vec3(accessor_values<float>(g.model, prim.attributes.at("NORMAL"))))
      CHECK(std::abs(glm::length(n) - 1.0f) <= 1e-6f);
  }
}

TEST_CASE("export: OBJ frames read back in the file's order, with round-trip precision") {
  SUBCASE("grid from the float solver") {
    const ParticleSystem system = grid_cloth();
    const Recorded r = simulate_grid(system);
    REQUIRE(write_obj_frame(tmp("grid.obj"), system, r.frames.back()));
    const ObjFrame o = read_obj_frame(tmp("grid.obj"));
    REQUIRE(o.positions.size() == system.size());
    for (std::size_t p = 0; p < system.size(); ++p)
      for (int c = 0; c < 3; ++c)
        CHECK(float(o.positions[p][c]) == float(r.frames.back()[p][c])); // float data: exact as float
    auto topology = ClothTopology::create(system);
    REQUIRE(topology);
    CHECK(o.indices == std::vector<std::uint32_t>(topology.value()->triangles().begin(),
                                                  topology.value()->triangles().end()));
  }
  SUBCASE("shuffled mesh with double positions") {
    const ParticleSystem system = shuffled_mesh_cloth();
    const Recorded r = mesh_frames(system);
    REQUIRE(write_obj_frame(tmp("mesh.obj"), system, r.frames[1]));
    const ObjFrame o = read_obj_frame(tmp("mesh.obj"));
    REQUIRE(o.positions.size() == 6);
    for (std::uint32_t v = 0; v < 6; ++v) {
      CHECK(o.positions[v] == file_position(v, 1)); // doubles: exact
      CHECK(float(o.uvs[v].x) == file_uv(v).x);
      CHECK(float(1.0 - o.uvs[v].y) == doctest::Approx(file_uv(v).y)); // OBJ's v runs up
    }
    CHECK(o.indices == std::vector<std::uint32_t>(file_triangles.begin(), file_triangles.end()));
  }
}

TEST_CASE("export: one frame is a still mesh, and a texture is embedded with its MIME type") {
  const ParticleSystem system = shuffled_mesh_cloth();
  Recorded one = mesh_frames(system);
  one.frames.resize(1);
  one.times.resize(1);
  // Also kept for the glTF validator test (tests/scene/validate_export.sh).
  for (const char* name : {"textured.glb", "textured.gltf"}) {
    CAPTURE(name);
    const AnimationRecorder rec = record(system, mesh_frames(system), MeshTexture{"tiny.png", tiny_png});
    REQUIRE(rec.write_gltf(tmp(name)));
    const GltfAnimation g = read_gltf_animation(tmp(name));
    REQUIRE(g.model.images.size() == 1);
    const tinygltf::Image& image = g.model.images[0];
    CHECK(image.mimeType == "image/png");
    REQUIRE(image.bufferView >= 0);
    const tinygltf::BufferView& view = g.model.bufferViews[std::size_t(image.bufferView)];
    const auto& data = g.model.buffers[0].data;
    CHECK(std::vector<std::uint8_t>(data.begin() + long(view.byteOffset),
                                    data.begin() + long(view.byteOffset + view.byteLength)) == tiny_png);
    CHECK(g.model.materials.at(0).pbrMetallicRoughness.baseColorTexture.index == 0);
    CHECK(g.model.textures.at(0).source == 0);
  }
  const std::vector<std::uint8_t> jpeg_magic = {0xFF, 0xD8, 0xFF, 0xE0, 0, 0};
  const AnimationRecorder jpeg = record(system, one, MeshTexture{"fabric.jpg", jpeg_magic});
  REQUIRE(jpeg.write_gltf(tmp("still.glb")));
  const GltfAnimation g = read_gltf_animation(tmp("still.glb"));
  CHECK(g.model.images.at(0).mimeType == "image/jpeg");
  CHECK(g.model.animations.empty());
  CHECK(g.model.meshes[0].primitives[0].targets.empty());
  check_frames(g, system, one);
}

TEST_CASE("export: errors name the problem and the value") {
  const ParticleSystem grid = grid_cloth();
  const auto message_has = [](const auto& result, const std::string& needle) {
    REQUIRE_FALSE(result);
    CHECK_MESSAGE(result.error().message.find(needle) != std::string::npos, result.error().message);
    return result.error().code;
  };
  ChainDesc chain_desc;
  auto chain = make_chain(chain_desc);
  REQUIRE(chain);
  CHECK(message_has(AnimationRecorder::create(*chain), "chain") == ErrorCode::invalid_argument);
  CHECK(message_has(write_obj_frame(tmp("chain.obj"), *chain, std::vector<glm::dvec3>(chain->size())),
                    "chain") == ErrorCode::invalid_argument);
  message_has(AnimationRecorder::create(grid, MeshTexture{"notes.txt", {'h', 'i'}}), "notes.txt");

  auto rec = AnimationRecorder::create(grid);
  REQUIRE(rec);
  message_has(rec->write_gltf(tmp("empty.glb")), "no frames");
  std::vector<glm::dvec3> frame(grid.size(), glm::dvec3(0.0));
  message_has(rec->add_frame(0.0, std::vector<glm::dvec3>(3)), "3 positions for 20 particles");
  frame[7].y = std::numeric_limits<double>::quiet_NaN();
  message_has(rec->add_frame(0.0, frame), "particle 7");
  frame[7].y = 1e39; // finite in double, not in float
  message_has(rec->add_frame(0.0, frame), "particle 7");
  frame[7].y = 0.0;
  message_has(rec->add_frame(-1.0, frame), "-1");
  message_has(rec->add_frame(1e39, frame), "finite"); // beyond float's range
  REQUIRE(rec->add_frame(0.5, frame));
  message_has(rec->add_frame(0.5, frame), "not after");
  CHECK(rec->frame_count() == 1);
  CHECK(message_has(rec->write_gltf(tmp("cloth.obj")), "\".obj\"") == ErrorCode::invalid_argument);
  CHECK(message_has(rec->write_gltf("/nonexistent/dir/cloth.glb"), "/nonexistent/dir/cloth.glb") ==
        ErrorCode::io);
  CHECK(check_gltf_path("A.GLB"));
  CHECK_FALSE(check_gltf_path("a.glb.bak"));
}
