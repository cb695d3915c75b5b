// SPDX-License-Identifier: MIT
// Scenes whose cloth is a mesh file (cloth.mesh): the keys, their errors and warnings, the mesh
// samples on both backends, and the vertex order of every CLI output.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "cli_util.hpp"
#include "vkcloth/mesh.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth;
using vkcloth::test::run_cli;
using vkcloth::test::tmp_dir;

namespace {

const std::string scenes = VKCLOTH_SCENES_DIR;

/// A 3 x 2 quad strip (vertices 0..7, two rows of four) written next to the scenes that use it.
std::string write_strip(const std::string& name) {
  const auto path = tmp_dir() / name;
  std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 0 1\nv 1 0 1\nv 2 0 1\nv 3 0 1\n"
                         "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n";
  return path.string();
}

/// Parses a scene text as if it were the file tmp/<name>.json (mesh paths relative to tmp/).
Result<Scene> parse_in_tmp(const std::string& cloth_body) {
  const std::string text = R"({"system": "cloth", "cloth": )" + cloth_body + "}";
  return parse_scene(text, (tmp_dir() / "mesh_scene.json").string());
}

std::string error_of(const std::string& cloth_body) {
  auto s = parse_in_tmp(cloth_body);
  REQUIRE_MESSAGE(!s.ok(), "expected an error for " << cloth_body);
  return s.error().message;
}

} // namespace

TEST_CASE("cloth.mesh: the path is relative to the scene file, and transform, density and pins apply") {
  write_strip("strip.obj");
  auto s = parse_in_tmp(R"({"mesh": "strip.obj", "mesh_transform": {"translate": [0, 0, 2], "scale": 0.5},
                            "density": 0.4, "pin_vertices": [4], "pin_region": {"min": [1.4, -1, 0], "max": [2, 1, 9]}})");
  REQUIRE_MESSAGE(s.ok(), s.error().message);
  const ParticleSystem& sys = s->system;
  REQUIRE(sys.surface);
  CHECK_FALSE(sys.grid);
  CHECK(sys.size() == 8);
  CHECK(s->warnings.empty());
  double mass = 0.0;
  int pinned = 0;
  for (std::size_t p = 0; p < sys.size(); ++p) {
    mass += sys.particles[p].mass;
    pinned += sys.particles[p].pinned;
    CHECK(sys.particles[p].position.z >= 2.0);
  }
  CHECK(mass == doctest::Approx(0.4 * 1.5 * 0.5)); // 1.5 m x 0.5 m after the scale
  CHECK(pinned == 3);                              // vertex 4, and 3 and 7 at x = 1.5
}

TEST_CASE("cloth.attach on a mesh cloth: vertices are the file's, a region its rest positions") {
  write_strip("attach_strip.obj");
  const std::string sphere = R"(, "colliders": [{"type": "sphere", "center": [0, 0, 3], "radius": 0.2}])";
  const auto parse = [&](const std::string& attach) {
    const std::string text = R"({"system": "cloth", "cloth": {"mesh": "attach_strip.obj", "attach": )" +
                             attach + "}" + sphere + "}";
    return parse_scene(text, (tmp_dir() / "attach_scene.json").string());
  };
  auto s = parse(R"([{"collider": 0, "vertices": [4, 7]}])");
  REQUIRE_MESSAGE(s.ok(), s.error().message);
  const ParticleSystem& sys = s->system;
  const Attachment& a = s->params.attachments.at(0);
  REQUIRE(a.particles.size() == 2);
  // The solver's particles are renumbered (meshoptimizer): each is the file's vertex 4 and 7.
  CHECK(sys.surface->source_vertex[a.particles[0]] == 4u);
  CHECK(sys.surface->source_vertex[a.particles[1]] == 7u);
  CHECK(sys.particles[a.particles[0]].position == glm::dvec3(0, 0, 1));
  CHECK(sys.particles[a.particles[0]].pinned);
  CHECK(a.offsets[0] == glm::dvec3(0, 0, -2)); // the vertex against the sphere's centre
  auto region = parse(R"([{"collider": 0, "region": {"min": [-1, -1, 0.5], "max": [9, 1, 2]}}])");
  REQUIRE_MESSAGE(region.ok(), region.error().message);
  CHECK(region->params.attachments.at(0).particles.size() == 4); // the top row
  auto bad = parse(R"([{"collider": 0, "vertices": [8]}])");
  REQUIRE_FALSE(bad.ok());
  CHECK_MESSAGE(bad.error().message.find("cloth.attach[0].vertices[0] = 8 is not a vertex of the cloth") !=
                    std::string::npos,
                bad.error().message);
}

TEST_CASE("cloth.mesh errors name the key, the file and the element") {
  write_strip("strip.obj");
  CHECK(error_of(R"({"mesh": "strip.obj", "resolution": [4, 4]})").find("cloth.resolution is a grid key") !=
        std::string::npos);
  CHECK(error_of(R"({"mesh": "strip.obj", "pins": []})").find("cloth.pins is a grid key") !=
        std::string::npos);
  CHECK(error_of(R"({"mesh": "strip.obj", "density": 1, "particle_mass": 1})")
            .find("cloth.density (kg/m^2) or cloth.particle_mass") != std::string::npos);
  CHECK(error_of(R"({"mesh": "no_such.obj"})").find("no_such.obj") != std::string::npos);
  CHECK(error_of(R"({"mesh": "strip.obj", "pin_vertices": [8]})")
            .find("cloth.pin_vertices[0] = 8 is outside the mesh (8 vertices)") != std::string::npos);
  CHECK(error_of(R"({"mesh": "strip.obj", "pin_region": {"min": [0, 0, 0]}})").find("cloth.pin_region.max") !=
        std::string::npos);
  CHECK(error_of(R"({"mesh": "strip.obj", "mesh_transform": {"scale": 0}})")
            .find("cloth.mesh_transform.scale") != std::string::npos);
  CHECK(error_of(R"({"mesh": "strip.obj", "mesh_transform": {"rotate": [0, 0, 1]}})")
            .find("unknown key cloth.mesh_transform.rotate") != std::string::npos);
  CHECK(error_of(R"({"mesh": "strip.stl"})").find(".stl") != std::string::npos);
}

TEST_CASE("the CLI prints a mesh scene's warnings and exits 2 on a bad mesh, naming the file and line") {
  write_strip("strip.obj");
  std::ofstream(tmp_dir() / "warn.json") << R"({"system": "cloth", "integrator": {"steps": 2},
             "cloth": {"mesh": "strip.obj", "pin_region": {"min": [5, 5, 5], "max": [6, 6, 6]}}})";
  auto ok = run_cli("mesh_warn", "run " + (tmp_dir() / "warn.json").string());
  CHECK(ok.code == 0);
  CHECK(ok.err.find("warning: cloth.pin_region [5, 5, 5] .. [6, 6, 6] pins no vertex") != std::string::npos);

  std::ofstream(tmp_dir() / "broken.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n";
  std::ofstream(tmp_dir() / "broken.json") << R"({"system": "cloth", "cloth": {"mesh": "broken.obj"}})";
  auto bad = run_cli("mesh_bad", "run " + (tmp_dir() / "broken.json").string());
  CHECK(bad.code == 2);
  CHECK(bad.err.find("broken.obj:4: face index 9 is out of range") != std::string::npos);
}

TEST_CASE("--trace and --positions list a mesh's vertices in the file's order") {
  // The tablecloth's particles are renumbered (meshoptimizer); the CSV rows must not be.
  const std::string csv = (tmp_dir() / "tablecloth_positions.csv").string();
  auto r =
      run_cli("mesh_positions", "run " + scenes + "/tablecloth_on_sphere.json --steps 1 --positions " + csv);
  REQUIRE(r.code == 0);
  auto mesh = read_obj(scenes + "/../meshes/tablecloth.obj");
  REQUIRE(mesh.ok());
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  CHECK(line == "particle,x,y,z");
  std::size_t row = 0;
  while (std::getline(in, line)) {
    CAPTURE(line);
    std::uint32_t id = 0;
    double x = 0, y = 0, z = 0;
    REQUIRE(std::sscanf(line.c_str(), "%u,%lf,%lf,%lf", &id, &x, &y, &z) == 4);
    CHECK(id == row);
    // One step of 2 ms: every vertex is still within 0.1 mm of the file's position (z + 0.62).
    CHECK(std::abs(x - mesh->positions[row].x) < 1e-4);
    CHECK(std::abs(y - mesh->positions[row].y) < 1e-4);
    CHECK(std::abs(z - (mesh->positions[row].z + 0.62)) < 1e-4);
    ++row;
  }
  CHECK(row == mesh->positions.size());
}

TEST_CASE("every mesh sample: GPU = CPU within 1e-5 m after 100 steps (vkcloth compare)") {
  for (const char* name : {"tablecloth_on_sphere", "flag_with_hole", "skirt"}) {
    CAPTURE(name);
    auto r = run_cli(std::string("mesh_compare_") + name,
                     "compare " + scenes + "/" + name + ".json --steps 100 --tolerance 1e-5");
    if (r.code == 4 && std::getenv("CI") == nullptr) {
      MESSAGE("no Vulkan device: ", r.err);
      continue;
    }
    CHECK_MESSAGE(r.code == 0, r.err);
    CHECK(r.out.find("PASS") != std::string::npos);
  }
}
