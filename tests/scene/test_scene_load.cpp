// SPDX-License-Identifier: MIT
// Scene files that load: the samples, defaults for omitted keys, overrides.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;

namespace {

Scene load_ok(const std::string& text, std::vector<std::string> overrides = {}) {
  auto s = parse_scene(text, "test.json", overrides);
  if (!s)
    FAIL("unexpected error: " << s.error().message);
  return std::move(*s);
}

std::size_t count_pinned(const ParticleSystem& sys) {
  return static_cast<std::size_t>(
      std::count_if(sys.particles.begin(), sys.particles.end(), [](const Particle& p) { return p.pinned; }));
}

std::size_t count_kind(const ParticleSystem& sys, SpringKind kind) {
  return static_cast<std::size_t>(
      std::count_if(sys.springs.begin(), sys.springs.end(), [&](const Spring& s) { return s.kind == kind; }));
}

} // namespace

TEST_CASE("every sample scene loads and runs its steps on the CPU solver without diverging") {
  // Under AddressSanitizer (~10x slower; that run looks for memory errors, which every feature a
  // sample turns on shows within its first steps) at most 200 steps per scene; the release suite
  // runs each scene's whole `steps`.
#if defined(__SANITIZE_ADDRESS__)
  const std::uint64_t step_cap = 200;
#else
  const std::uint64_t step_cap = ~std::uint64_t{0};
#endif
  std::size_t n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(VKCLOTH_SCENES_DIR)) {
    if (entry.path().extension() != ".json")
      continue;
    CAPTURE(entry.path().string());
    auto scene = load_scene_file(entry.path());
    REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
    CHECK(scene->name == entry.path().stem().string());
    auto solver = CpuSolver<float>::create(scene->system, scene->params);
    REQUIRE(solver.ok());
    auto run = solver->run(std::min(scene->steps, step_cap));
    CHECK_MESSAGE(run.ok(), (run.ok() ? "" : run.error().message));
    ++n;
  }
  CHECK(n >= 6);
}

TEST_CASE("spring.json is the report's single spring (section 2.1)") {
  auto s = load_scene_file(std::filesystem::path(VKCLOTH_SCENES_DIR) / "spring.json");
  REQUIRE(s.ok());
  CHECK_FALSE(s->system.grid.has_value()); // "system": "chain"
  REQUIRE(s->system.size() == 2);
  REQUIRE(s->system.springs.size() == 1);
  CHECK(s->system.particles[0].pinned);
  CHECK(s->system.particles[1].mass == 1.0);
  CHECK(s->system.particles[1].position.z == doctest::Approx(-0.4));
  CHECK(s->system.springs[0].stiffness == 20.0);
  CHECK(s->system.springs[0].rest_length == 0.4);
  CHECK(s->params.dt == 0.02);
  CHECK(s->params.damping == 0.5);
  CHECK(s->params.gravity.z == doctest::Approx(-9.81));
  CHECK(s->params.integrator == Integrator::semi_implicit_euler);
  CHECK(s->steps == 500);
}

TEST_CASE("the cloth samples have the documented shape") {
  const std::filesystem::path dir(VKCLOTH_SCENES_DIR);
  auto hanging = load_scene_file(dir / "cloth_hanging.json");
  REQUIRE(hanging.ok());
  REQUIRE(hanging->system.grid.has_value());
  CHECK(hanging->system.grid->nx == 10);
  CHECK(hanging->system.grid->ny == 10);
  CHECK(count_pinned(hanging->system) == 2);
  CHECK(hanging->system.particles[9 * 10 + 0].pinned);
  CHECK(hanging->system.particles[9 * 10 + 9].pinned);
  CHECK(hanging->system.particles[0].position.x == doctest::Approx(-0.5));
  CHECK(hanging->system.particles[0].position.z == doctest::Approx(0.5));
  CHECK(hanging->system.particles[99].position.z == doctest::Approx(1.5)); // vertical: j goes up z

  auto plane = load_scene_file(dir / "cloth_on_plane.json");
  REQUIRE(plane.ok());
  CHECK(count_pinned(plane->system) == 0);
  REQUIRE(plane->params.colliders.size() == 1);
  CHECK(plane->params.colliders[0].type == Collider::Type::plane);

  auto sphere = load_scene_file(dir / "cloth_on_sphere.json");
  REQUIRE(sphere.ok());
  CHECK(count_pinned(sphere->system) == 0);
  REQUIRE(!sphere->params.colliders.empty());
  CHECK(sphere->params.colliders[0].type == Collider::Type::sphere);
  CHECK(sphere->params.colliders[0].radius > 0.0);

  auto wind = load_scene_file(dir / "cloth_wind.json");
  REQUIRE(wind.ok());
  CHECK(wind->params.wind.strength > 0.0);

  auto dbl = load_scene_file(dir / "double_spring.json");
  REQUIRE(dbl.ok());
  CHECK(dbl->system.size() == 3);
  CHECK(dbl->system.springs.size() == 2);
  CHECK(dbl->system.particles[1].position.x != 0.0); // started off-axis: it swings
}

TEST_CASE("omitted keys take the report's defaults") {
  const Scene chain = load_ok(R"({"system": "chain"})");
  const SimParams def;
  CHECK(chain.params.dt == def.dt);
  CHECK(chain.params.damping == def.damping);
  CHECK(chain.params.gravity == def.gravity);
  CHECK(chain.params.integrator == Integrator::semi_implicit_euler);
  CHECK(chain.params.contact_epsilon == def.contact_epsilon);
  CHECK(chain.params.divergence_limit == def.divergence_limit);
  CHECK(chain.params.wind.strength == 0.0);
  CHECK(chain.params.colliders.empty());
  CHECK(chain.steps == 500);
  CHECK(chain.name == "test");
  REQUIRE(chain.system.size() == 2);
  CHECK(chain.system.springs[0].stiffness == 20.0);
  CHECK(chain.system.particles[1].position.z == doctest::Approx(-0.4));

  const Scene cloth = load_ok(R"({"system": "cloth", "name": "c"})");
  CHECK(cloth.name == "c");
  REQUIRE(cloth.system.grid.has_value());
  CHECK(cloth.system.grid->nx == 10);
  CHECK(cloth.system.particles[0].mass == 0.05);
  CHECK(count_pinned(cloth.system) == 2); // absent "pins": the two top corners
  CHECK(count_kind(cloth.system, SpringKind::structural) == 180);
  CHECK(cloth.system.springs[0].stiffness == 40.0);
  const Spring* shear = nullptr;
  for (const Spring& s : cloth.system.springs)
    if (s.kind == SpringKind::shear)
      shear = &s;
  REQUIRE(shear != nullptr);
  CHECK(shear->stiffness == 8.0);
}

TEST_CASE("chain: anchor without positions hangs the masses below it at rest length") {
  const Scene s = load_ok(R"({"system": "chain", "chain": {"anchor": [1, 2, 3], "masses": [1, 2],
                                "stiffness": 20, "rest_lengths": [0.4, 0.5]}})");
  REQUIRE(s.system.size() == 3);
  CHECK(s.system.particles[1].position == glm::dvec3(1, 2, 2.6));
  CHECK(s.system.particles[2].position.z == doctest::Approx(2.1));
  CHECK(s.system.particles[2].mass == 2.0);
  CHECK(s.system.springs[1].stiffness == 20.0); // one stiffness for every spring
}

TEST_CASE("cloth: pins absent, empty and explicit") {
  CHECK(count_pinned(load_ok(R"({"system": "cloth", "cloth": {}})").system) == 2);
  CHECK(count_pinned(load_ok(R"({"system": "cloth", "cloth": {"pins": []}})").system) == 0);
  const Scene s = load_ok(R"({"system": "cloth", "cloth": {"resolution": [4, 3], "pins": [[1, 2]]}})");
  CHECK(count_pinned(s.system) == 1);
  CHECK(s.system.particles[2 * 4 + 1].pinned); // index j*nx+i
}

TEST_CASE("cloth: every key is read") {
  const Scene s = load_ok(R"({"system": "cloth", "cloth": {"resolution": [5, 4], "size": [2, 3],
    "origin": [1, 1, 1], "orientation": "horizontal", "particle_mass": 0.2,
    "stiffness": {"structural": 30, "shear": 0, "bend": 2}},
    "integrator": {"method": "rk4", "dt": 0.005, "steps": 1e3},
    "physics": {"gravity": [0, 0, -1], "damping": 0.1},
    "wind": {"strength": 0.02, "direction": [0, 2, 0]},
    "colliders": [{"type": "plane", "normal": [0, 0, 2], "offset": -1},
                  {"type": "sphere", "center": [0, 0, -5], "radius": 0.5}],
    "contact_epsilon": 0.002, "divergence_limit": 100})");
  CHECK(s.system.grid->nx == 5);
  CHECK(s.system.grid->ny == 4);
  CHECK(s.system.particles[19].position == glm::dvec3(3, 4, 1)); // horizontal: j goes along y
  CHECK(s.system.particles[0].mass == 0.2);
  CHECK(count_kind(s.system, SpringKind::shear) == 0);
  CHECK(count_kind(s.system, SpringKind::bend) > 0);
  CHECK(s.params.integrator == Integrator::rk4);
  CHECK(s.params.dt == 0.005);
  CHECK(s.steps == 1000);
  CHECK(s.params.damping == 0.1);
  CHECK(s.params.wind.direction == glm::dvec3(0, 1, 0)); // normalised
  REQUIRE(s.params.colliders.size() == 2);
  CHECK(s.params.colliders[0].normal == glm::dvec3(0, 0, 1));
  CHECK(s.params.colliders[0].offset == -1.0);
  CHECK(s.params.colliders[1].radius == 0.5);
  CHECK(s.params.contact_epsilon == 0.002);
  CHECK(s.params.divergence_limit == 100.0);
}

TEST_CASE("overrides set values before validation") {
  const std::string base =
      R"({"system": "cloth", "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]})";
  const Scene s = load_ok(base, {"cloth.stiffness.bend=15", "integrator.dt=0.01", "wind.direction=[0,1,0]",
                                 "wind.strength=0.05", "colliders.0.radius=0.3", "integrator.method=rk4",
                                 "integrator.steps=7", "name=renamed", "cloth.pins=[]"});
  CHECK(s.params.dt == 0.01);
  CHECK(s.params.wind.direction == glm::dvec3(0, 1, 0));
  CHECK(s.params.colliders[0].radius == 0.3);
  CHECK(s.params.integrator == Integrator::rk4);
  CHECK(s.steps == 7);
  CHECK(s.name == "renamed");
  CHECK(count_pinned(s.system) == 0);
  bool bend15 = false;
  for (const Spring& sp : s.system.springs)
    bend15 = bend15 || (sp.kind == SpringKind::bend && sp.stiffness == 15.0);
  CHECK(bend15);

  // Bracket indices, and appending a collider at index == size.
  const Scene t = load_ok(base, {"colliders[0].radius=2", R"(colliders.1={"type":"plane"})"});
  CHECK(t.params.colliders[0].radius == 2.0);
  REQUIRE(t.params.colliders.size() == 2);
  CHECK(t.params.colliders[1].type == Collider::Type::plane);

  // Later overrides win.
  CHECK(load_ok(R"({"system": "chain"})", {"integrator.dt=0.1", "integrator.dt=0.2"}).params.dt == 0.2);
}

TEST_CASE("contact_inward_only: defaults to true (report §4), reads a boolean, rejects other types") {
  CHECK(load_ok(R"({"system": "chain"})").params.contact_inward_only);
  CHECK_FALSE(load_ok(R"({"system": "chain", "contact_inward_only": false})").params.contact_inward_only);
  CHECK_FALSE(load_ok(R"({"system": "chain"})", {"contact_inward_only=false"}).params.contact_inward_only);
  auto bad = parse_scene(R"({"system": "chain", "contact_inward_only": 1})", "t.json");
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error().message.find("contact_inward_only") != std::string::npos);
}

// ---- Capsule, box and mesh colliders, friction, moving colliders ----

namespace {

/// A unit cube centred on the origin (6 quads, 12 triangles), written to tmp/<dir>/meshes/cube.obj
/// (each test its own <dir>: ctest runs them in parallel).
std::filesystem::path write_cube(const std::string& dir) {
  const std::filesystem::path d = std::filesystem::path(VKCLOTH_TEST_TMP) / dir / "meshes";
  std::filesystem::create_directories(d);
  std::ofstream(d / "cube.obj") << "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n"
                                   "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n"
                                   "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  return d / "cube.obj";
}

/// Parses `text` as if it were the file tmp/<dir>/scene.json (relative mesh paths start there).
Scene load_in_tmp(const std::string& dir, const std::string& text, std::vector<std::string> overrides = {}) {
  auto s =
      parse_scene(text, (std::filesystem::path(VKCLOTH_TEST_TMP) / dir / "scene.json").string(), overrides);
  if (!s)
    FAIL("unexpected error: " << s.error().message);
  return std::move(*s);
}

bool same(const glm::dmat3& a, const glm::dmat3& b) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (std::abs(a[c][r] - b[c][r]) > 1e-15)
        return false;
  return true;
}

} // namespace

TEST_CASE("colliders: capsule and box keys are read, rotation_deg through rotation_from_degrees") {
  const Scene s = load_ok(R"({"system": "cloth", "colliders": [
      {"type": "capsule", "a": [0, 0, 0.2], "b": [1, 0, 0.2], "radius": 0.1},
      {"type": "capsule", "a": [0.5, 0.5, 0], "b": [0.5, 0.5, 0], "radius": 0.25},
      {"type": "box", "center": [0, 0, -1], "half_extents": [2, 1, 0.5], "rotation_deg": [10, -20, 30]},
      {"type": "box", "center": [3, 0, 0], "half_extents": [0.1, 0.2, 0.3]}]})");
  REQUIRE(s.params.colliders.size() == 4);
  const Collider& cap = s.params.colliders[0];
  CHECK(cap.type == Collider::Type::capsule);
  CHECK(cap.a == glm::dvec3(0, 0, 0.2));
  CHECK(cap.b == glm::dvec3(1, 0, 0.2));
  CHECK(cap.radius == 0.1);
  CHECK(s.params.colliders[1].a == s.params.colliders[1].b); // a == b: a sphere, allowed
  const Collider& box = s.params.colliders[2];
  CHECK(box.type == Collider::Type::box);
  CHECK(box.center == glm::dvec3(0, 0, -1));
  CHECK(box.half_extents == glm::dvec3(2, 1, 0.5));
  CHECK(same(box.rotation, Collider::rotation_from_degrees({10, -20, 30})));
  CHECK(same(s.params.colliders[3].rotation, glm::dmat3(1.0))); // rotation_deg defaults to [0, 0, 0]
}

TEST_CASE("colliders: friction and velocities on every type, with their defaults") {
  const Scene s = load_ok(R"({"system": "cloth", "colliders": [
      {"type": "plane", "offset": -1, "friction": 0.4, "static_friction": 0.6, "linear_velocity": [0.5, 0, 0]},
      {"type": "sphere", "center": [0, 0, 0], "radius": 0.3, "friction": 0.2,
       "linear_velocity": [0, 0, 0.1], "angular_velocity": [0, 0, 3.14]},
      {"type": "capsule", "a": [0, 0, 0], "b": [1, 0, 0], "radius": 0.1, "friction": 0.3, "static_friction": 0.3},
      {"type": "box", "center": [0, 0, 0], "half_extents": [1, 1, 1], "angular_velocity": [1, 0, 0]}]})");
  const auto& c = s.params.colliders;
  REQUIRE(c.size() == 4);
  CHECK(c[0].friction == 0.4);
  CHECK(c[0].static_friction == 0.6);
  CHECK(c[0].linear_velocity == glm::dvec3(0.5, 0, 0));
  CHECK(c[0].angular_velocity == glm::dvec3(0.0));
  CHECK(c[1].friction == 0.2);
  CHECK(c[1].static_coefficient() == 0.2); // static_friction absent: the same as friction
  CHECK(c[1].linear_velocity == glm::dvec3(0, 0, 0.1));
  CHECK(c[1].angular_velocity == glm::dvec3(0, 0, 3.14));
  CHECK(c[1].moving());
  CHECK(c[2].static_coefficient() == 0.3); // static == kinetic is allowed
  CHECK(c[3].friction == 0.0);             // default: frictionless, the report's model
  CHECK(c[3].static_coefficient() == 0.0);
  CHECK(c[3].linear_velocity == glm::dvec3(0.0));
  CHECK(c[3].angular_velocity == glm::dvec3(1, 0, 0));
  // The colliders of the report's samples keep the report's model: no friction, at rest.
  auto sphere = load_scene_file(std::filesystem::path(VKCLOTH_SCENES_DIR) / "cloth_on_sphere.json");
  REQUIRE(sphere.ok());
  for (const Collider& k : sphere->params.colliders) {
    CHECK(k.friction == 0.0);
    CHECK_FALSE(k.moving());
  }
}

TEST_CASE("colliders: a mesh collider reads its file relative to the scene, with its transform") {
  const std::string abs = write_cube("mesh_load").string();
  const Scene s = load_in_tmp("mesh_load", R"({"system": "cloth", "colliders": [
      {"type": "mesh", "path": "meshes/cube.obj", "thickness": 0.01, "friction": 0.5,
       "transform": {"translate": [1, 2, 3], "rotate_deg": [0, 0, 90], "scale": 2}},
      {"type": "mesh", "path": "meshes/cube.obj", "thickness": 0.02}]})");
  REQUIRE(s.params.colliders.size() == 2);
  const Collider& m = s.params.colliders[0];
  CHECK(m.type == Collider::Type::mesh);
  REQUIRE(m.mesh);
  CHECK(m.mesh->name() == "meshes/cube.obj");
  CHECK(m.mesh->triangles().size() == 12); // 6 quads, fan-triangulated
  CHECK(m.mesh->depth() >= 2);             // 12 triangles, at most 4 per leaf
  // The scale is baked into the triangles (mesh frame), translate and rotate_deg are the pose.
  CHECK(m.mesh->nodes()[0].lo == glm::vec3(-1.0f));
  CHECK(m.mesh->nodes()[0].hi == glm::vec3(1.0f));
  CHECK(m.center == glm::dvec3(1, 2, 3));
  CHECK(same(m.rotation, Collider::rotation_from_degrees({0, 0, 90})));
  CHECK(m.thickness == 0.01);
  CHECK(m.friction == 0.5);
  const Collider& plain = s.params.colliders[1];
  REQUIRE(plain.mesh);
  CHECK(plain.mesh->nodes()[0].hi == glm::vec3(0.5f)); // transform absent: scale 1, ...
  CHECK(plain.center == glm::dvec3(0.0));              // ... the origin, ...
  CHECK(same(plain.rotation, glm::dmat3(1.0)));        // ... no rotation
  CHECK(plain.thickness == 0.02);
  CHECK(s.warnings.empty());

  // The same file at the same scale is built once and shared; an absolute path works too.
  const Scene t = load_in_tmp("mesh_load", R"({"system": "chain", "colliders": [
      {"type": "mesh", "path": "meshes/cube.obj", "thickness": 0.01},
      {"type": "mesh", "path": ")" + abs + R"(", "thickness": 0.01},
      {"type": "mesh", "path": "meshes/cube.obj", "thickness": 0.01, "transform": {"scale": 3}}]})");
  REQUIRE(t.params.colliders.size() == 3);
  CHECK(t.params.colliders[0].mesh == t.params.colliders[1].mesh);
  CHECK(t.params.colliders[0].mesh != t.params.colliders[2].mesh);

  // A sample mesh (OBJ) from a scene in samples/scenes/, as cloth.mesh would find it.
  auto table = parse_scene(
      R"({"system": "chain", "colliders": [{"type": "mesh", "path": "../meshes/tablecloth.obj", "thickness": 0.005}]})",
      std::string(VKCLOTH_SCENES_DIR) + "/table_collider.json");
  REQUIRE_MESSAGE(table.ok(), table.error().message);
  REQUIRE(table->params.colliders[0].mesh);
  CHECK(table->params.colliders[0].mesh->triangles().size() == 384);
}

TEST_CASE("colliders: a mesh with zero-area triangles loads with a warning that counts them") {
  const std::filesystem::path d = std::filesystem::path(VKCLOTH_TEST_TMP) / "mesh_flat" / "meshes";
  std::filesystem::create_directories(d);
  std::ofstream(d / "flat.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n";
  const Scene s = load_in_tmp(
      "mesh_flat",
      R"({"system": "chain", "colliders": [{"type": "mesh", "path": "meshes/flat.obj", "thickness": 0.01}]})");
  REQUIRE(s.params.colliders[0].mesh);
  CHECK(s.params.colliders[0].mesh->triangles().size() == 1);
  REQUIRE(s.warnings.size() == 1);
  CHECK(s.warnings[0] == "colliders[0]: dropped 1 zero-area triangle of meshes/flat.obj");
}

TEST_CASE("colliders: overrides reach the new keys and the new types") {
  write_cube("mesh_overrides");
  const std::string base = R"({"system": "cloth", "colliders": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 1},
      {"type": "mesh", "path": "meshes/cube.obj", "thickness": 0.01}]})";
  const Scene s =
      load_in_tmp("mesh_overrides", base,
                  {"colliders.0.friction=0.4", "colliders[0].static_friction=0.7",
                   "colliders.0.linear_velocity=[0,0,-0.5]", "colliders.0.angular_velocity=[0,0,2]",
                   "colliders.1.transform.scale=2", "colliders.1.transform.translate=[0,0,1]",
                   R"(colliders.2={"type":"capsule","a":[0,0,0],"b":[0,1,0],"radius":0.2})",
                   R"(colliders.3={"type":"box","center":[0,0,0],"half_extents":[1,1,1]})",
                   "colliders.3.rotation_deg=[0,0,45]", "colliders.2.radius=0.3"});
  const auto& c = s.params.colliders;
  REQUIRE(c.size() == 4);
  CHECK(c[0].friction == 0.4);
  CHECK(c[0].static_friction == 0.7);
  CHECK(c[0].linear_velocity == glm::dvec3(0, 0, -0.5));
  CHECK(c[0].angular_velocity == glm::dvec3(0, 0, 2));
  REQUIRE(c[1].mesh);
  CHECK(c[1].mesh->nodes()[0].hi == glm::vec3(1.0f)); // transform created by the override, scale 2
  CHECK(c[1].center == glm::dvec3(0, 0, 1));
  CHECK(c[2].type == Collider::Type::capsule);
  CHECK(c[2].radius == 0.3);
  CHECK(c[3].type == Collider::Type::box);
  CHECK(same(c[3].rotation, Collider::rotation_from_degrees({0, 0, 45})));
}

// ---- Self-collision ----

TEST_CASE("self_collision: absent is off with the defaults, present is read into SimParams") {
  const SelfCollision def;
  for (const char* text : {R"({"system": "cloth"})", R"({"system": "chain"})"}) {
    CAPTURE(text);
    const Scene off = load_ok(text);
    CHECK_FALSE(off.params.self_collision.enabled);
    CHECK(off.params.self_collision.thickness == def.thickness);
    CHECK(off.params.self_collision.friction == def.friction);
    CHECK(off.params.self_collision.iterations == def.iterations);
    CHECK(off.params.self_collision.skin == 0.0); // no neighbour lists unless asked for
    CHECK(off.warnings.empty());
  }
  CHECK_FALSE(def.enabled);
  CHECK(def.thickness == 0.01);
  CHECK(def.friction == 0.2);
  CHECK(def.iterations == 1);

  const Scene on = load_ok(
      R"({"system": "cloth", "self_collision": {"enabled": true, "thickness": 0.08, "friction": 0.35, "iterations": 5, "skin": 0.02}})");
  CHECK(on.params.self_collision.enabled);
  CHECK(on.params.self_collision.thickness == 0.08);
  CHECK(on.params.self_collision.friction == 0.35);
  CHECK(on.params.self_collision.iterations == 5);
  CHECK(on.params.self_collision.skin == 0.02);
  CHECK(on.warnings.empty()); // 0.08 m is above the triangles' circumradius (half the 1/9 m cells' diagonal)

  // Present without "enabled": on, the other keys at their defaults.
  const Scene bare = load_ok(R"({"system": "cloth", "self_collision": {"thickness": 0.1}})");
  CHECK(bare.params.self_collision.enabled);
  CHECK(bare.params.self_collision.thickness == 0.1);
  CHECK(bare.params.self_collision.friction == def.friction);
  CHECK(bare.params.self_collision.iterations == def.iterations);
  CHECK(load_ok(R"({"system": "cloth", "self_collision": {}})").params.self_collision.enabled);

  // "enabled": false keeps the values and turns it off.
  const Scene disabled = load_ok(
      R"({"system": "cloth", "self_collision": {"enabled": false, "thickness": 0.001, "iterations": 16}})");
  CHECK_FALSE(disabled.params.self_collision.enabled);
  CHECK(disabled.params.self_collision.thickness == 0.001);
  CHECK(disabled.params.self_collision.iterations == 16);
  CHECK(disabled.warnings.empty()); // off: not compared with the cloth

  // Limits of the ranges are accepted (friction 0, iterations 1 and 16, a thickness of 10 x the spacing).
  const Scene edge = load_ok(R"({"system": "cloth", "self_collision": {"friction": 0, "iterations": 1}})");
  CHECK(edge.params.self_collision.friction == 0.0);
  CHECK(edge.params.self_collision.iterations == 1);
  CHECK(
      load_ok(R"({"system": "chain", "self_collision": {"thickness": 4}})").params.self_collision.thickness ==
      4.0);
}

TEST_CASE("self_collision: overrides reach every key and turn it on") {
  const Scene s =
      load_ok(R"({"system": "cloth"})", {"self_collision.enabled=true", "self_collision.thickness=0.06",
                                         "self_collision.friction=0", "self_collision.iterations=3"});
  CHECK(s.params.self_collision.enabled);
  CHECK(s.params.self_collision.thickness == 0.06);
  CHECK(s.params.self_collision.friction == 0.0);
  CHECK(s.params.self_collision.iterations == 3);
  const Scene off = load_ok(R"({"system": "cloth", "self_collision": {"thickness": 0.06}})",
                            {"self_collision.enabled=false"});
  CHECK_FALSE(off.params.self_collision.enabled);
  CHECK(off.params.self_collision.thickness == 0.06);
}

TEST_CASE("self_collision: a thickness below half the smallest rest length, or below a triangle's "
          "circumradius, is a "
          "warning in scene.warnings") {
  // The default 10 x 10 grid over 1 m: structural springs of 1/9 m; half of that is 0.0556 m.
  const Scene thin = load_ok(R"({"system": "cloth", "self_collision": {"thickness": 0.01}})");
  REQUIRE(thin.warnings.size() == 1);
  CHECK(thin.warnings[0].find(
            "self_collision.thickness 0.01 m is below half the smallest rest length (0.1111 m)") == 0);
  CHECK(thin.warnings[0].find("a triangle can pass between two particles") != std::string::npos);
  // The default thickness (0.01 m) warns as well once turned on.
  CHECK(load_ok(R"({"system": "cloth"})", {"self_collision.enabled=true"}).warnings.size() == 1);
  // Above half the spacing but below a triangle's circumradius (half the cell's diagonal, 0.07857 m):
  // a particle can cross the middle of another layer's triangle unseen.
  const Scene mid = load_ok(R"({"system": "cloth", "self_collision": {"thickness": 0.06}})");
  REQUIRE(mid.warnings.size() == 1);
  CHECK(mid.warnings[0].find("self_collision.thickness 0.06 m is below the largest circumradius of the "
                             "cloth's triangles (0.07857 m)") == 0);
  CHECK(load_ok(R"({"system": "cloth", "self_collision": {"thickness": 0.08}})").warnings.empty());
  // A 2 x 1 m cloth of 3 x 11 particles: cells of 1 x 0.1 m, triangles of circumradius 0.5025 m.
  const std::string wide = R"({"system": "cloth", "cloth": {"size": [2, 1], "resolution": [3, 11]},
                               "self_collision": {"thickness": )";
  const Scene long_cells = load_ok(wide + "0.3}}");
  REQUIRE(long_cells.warnings.size() == 1);
  CHECK(long_cells.warnings[0].find("(0.5025 m)") != std::string::npos);
  CHECK(load_ok(wide + "0.51}}").warnings.empty());

  // A mesh cloth: a 3 x 1 strip of unit quads (structural springs of 1 m).
  const std::filesystem::path d = std::filesystem::path(VKCLOTH_TEST_TMP) / "self_collision_mesh";
  std::filesystem::create_directories(d);
  std::ofstream(d / "strip.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 0 1\nv 1 0 1\nv 2 0 1\nv 3 0 1\n"
                                    "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n";
  const std::string mesh = R"({"system": "cloth", "cloth": {"mesh": "strip.obj"}, "self_collision": )";
  const Scene mesh_thin = load_in_tmp("self_collision_mesh", mesh + R"({"thickness": 0.2}})");
  REQUIRE(mesh_thin.warnings.size() == 1);
  CHECK(mesh_thin.warnings[0].find(
            "self_collision.thickness 0.2 m is below half the smallest rest length (1 m)") == 0);
  const Scene mesh_mid = load_in_tmp("self_collision_mesh", mesh + R"({"thickness": 0.6}})");
  REQUIRE(mesh_mid.warnings.size() == 1);
  CHECK(mesh_mid.warnings[0].find("circumradius of the cloth's triangles (0.7071 m)") != std::string::npos);
  CHECK(load_in_tmp("self_collision_mesh", mesh + R"({"thickness": 0.75}})").warnings.empty());
}

TEST_CASE("up: \"y\" turns the grid's plane and the defaults of gravity and a plane, \"z\" is the default") {
  const std::string body = R"("system": "cloth", "cloth": {"resolution": [5, 4], "orientation": "horizontal",
                               "origin": [0, 0, 0.5]}, "colliders": [{"type": "plane"}])";
  const Scene z = load_ok("{" + body + "}");
  const Scene z_named = load_ok(R"({"up": "z", )" + body + "}");
  const Scene y = load_ok(R"({"up": "y", )" + body + "}");
  CHECK(z.up == UpAxis::z);
  CHECK(z_named.up == UpAxis::z);
  CHECK(y.up == UpAxis::y);
  CHECK(z.params.gravity == glm::dvec3(0, 0, -9.81));
  CHECK(z_named.params.gravity == z.params.gravity);
  CHECK(y.params.gravity == glm::dvec3(0, -9.81, 0));
  CHECK(z.params.colliders.at(0).normal == glm::dvec3(0, 0, 1));
  CHECK(y.params.colliders.at(0).normal == glm::dvec3(0, 1, 0));
  // The grid lies in x-z with y up, each particle the z-up one turned about the (given) origin.
  REQUIRE(y.system.size() == z.system.size());
  const glm::dvec3 o(0, 0, 0.5);
  for (std::size_t p = 0; p < z.system.size(); ++p) {
    CHECK(z_named.system.particles[p].position == z.system.particles[p].position);
    CHECK(glm::length(y.system.particles[p].position -
                      (o + z_up_to(UpAxis::y) * (z.system.particles[p].position - o))) < 1e-15);
    CHECK(y.system.particles[p].position.y == 0.0);
  }
  // An explicit gravity wins over the up axis's default; overrides set "up" too.
  CHECK(load_ok(R"({"up": "y", "physics": {"gravity": [0, 0, -1]}, )" + body + "}").params.gravity ==
        glm::dvec3(0, 0, -1));
  CHECK(load_ok("{" + body + "}", {"up=y"}).up == UpAxis::y);
  // A chain hangs along -up.
  const Scene chain =
      load_ok(R"({"up": "y", "system": "chain", "chain": {"anchor": [1, 2, 3], "masses": [1]}})");
  CHECK(chain.system.particles[1].position.x == 1.0);
  CHECK(chain.system.particles[1].position.y == doctest::Approx(1.6));
  CHECK(chain.system.particles[1].position.z == 3.0);
}

TEST_CASE("up: a value other than \"z\" or \"y\" is an error naming it") {
  for (const char* text : {R"({"up": "x", "system": "cloth"})", R"({"up": "Y", "system": "cloth"})"}) {
    auto s = parse_scene(text, "up.json");
    REQUIRE_FALSE(s.ok());
    CHECK_MESSAGE(s.error().message.find("up must be \"z\" or \"y\"") != std::string::npos,
                  s.error().message);
    CHECK_MESSAGE(s.error().message.find(std::string("got \"") + (text[8] == 'x' ? "x" : "Y") + "\"") !=
                      std::string::npos,
                  s.error().message);
  }
  auto s = parse_scene(R"({"up": 1, "system": "cloth"})", "up.json");
  REQUIRE_FALSE(s.ok());
  CHECK_MESSAGE(s.error().message.find("up") != std::string::npos, s.error().message);
}
