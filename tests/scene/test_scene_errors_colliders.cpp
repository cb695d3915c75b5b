// SPDX-License-Identifier: MIT
// Colliders in scene files that must be refused, each with a message naming the
// key and the value.
#include <doctest/doctest.h>

#include <string>

#include "scene_errors_util.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

TEST_CASE("colliders: an unknown or missing type lists all five types") {
  for (const std::string& body : {std::string(R"({"type": "cube"})"), std::string(R"({"radius": 1})")}) {
    CAPTURE(body);
    const Error e = expect_error(colliders(body),
                                 {"colliders[0].type", R"("plane", "sphere", "capsule", "box" or "mesh")"});
    CHECK(e.code == ErrorCode::parse);
  }
  expect_error(colliders(R"({"type": "cube"})"), {"got \"cube\""});
  expect_error(colliders(R"({"type": 3})"), {"colliders[0].type", "string", "3"});
}

TEST_CASE("colliders: unknown keys are refused per type, naming the key") {
  // Each type's own keys only: another type's keys are typos here.
  expect_error(
      colliders(R"({"type": "capsule", "a": [0,0,0], "b": [1,0,0], "radius": 1, "center": [0,0,0]})"),
      {"unknown key colliders[0].center"});
  expect_error(colliders(R"({"type": "box", "center": [0,0,0], "half_extents": [1,1,1], "radius": 1})"),
               {"unknown key colliders[0].radius"});
  expect_error(
      colliders(R"({"type": "box", "center": [0,0,0], "half_extents": [1,1,1], "rotate_deg": [0,0,1]})"),
      {"unknown key colliders[0].rotate_deg", "rotation_deg"});
  expect_error(colliders(R"({"type": "mesh", "path": "m.obj", "thickness": 0.01, "rotation_deg": [0,0,1]})"),
               {"unknown key colliders[0].rotation_deg", "transform"});
  expect_error(
      colliders(R"({"type": "mesh", "path": "m.obj", "thickness": 0.01, "transform": {"rotate": [0,0,1]}})"),
      {"unknown key colliders[0].transform.rotate"});
  expect_error(colliders(sphere + R"(, "half_extents": [1,1,1]})"),
               {"unknown key colliders[0].half_extents"});
  expect_error(colliders(sphere + R"(, "mu": 0.3})"),
               {"unknown key colliders[0].mu", "friction", "static_friction"});
  expect_error(colliders(R"({"type": "plane", "velocity": [1, 0, 0]})"),
               {"unknown key colliders[0].velocity", "linear_velocity", "angular_velocity"});
}

TEST_CASE("colliders: required keys of capsule, box and mesh") {
  expect_error(colliders(R"({"type": "capsule", "a": [0,0,0], "radius": 1})"),
               {"colliders[0].b is required for a capsule"});
  expect_error(colliders(R"({"type": "capsule", "a": [0,0,0], "b": [0,0,0]})"),
               {"colliders[0].radius is required for a capsule"});
  expect_error(colliders(R"({"type": "box", "center": [0,0,0]})"),
               {"colliders[0].half_extents is required for a box"});
  expect_error(colliders(R"({"type": "box", "half_extents": [1,1,1]})"),
               {"colliders[0].center is required for a box"});
  expect_error(colliders(R"({"type": "mesh", "path": "m.obj"})"),
               {"colliders[0].thickness is required for a mesh collider"});
  expect_error(colliders(R"({"type": "mesh", "thickness": 0.01})"),
               {"colliders[0].path is required for a mesh collider"});
  expect_error(colliders(R"({"type": "mesh", "path": 5, "thickness": 0.01})"),
               {"colliders[0].path", "a string", "5"});
}

TEST_CASE("colliders: friction out of range names the key and the value") {
  const Error neg = expect_error(colliders(sphere + R"(, "friction": -0.1})"),
                                 {"colliders[0].friction", ">= 0", "got -0.1"});
  CHECK(neg.code == ErrorCode::invalid_argument);
  // static < kinetic, and a negative static (in C++ "the same as friction"; a scene omits the key).
  expect_error(colliders(sphere + R"(, "friction": 0.5, "static_friction": 0.2})"),
               {"colliders[0].static_friction", ">= friction (0.5)", "got 0.2"});
  const Error neg_static = expect_error(colliders(sphere + R"(, "static_friction": -1})"),
                                        {"colliders[0].static_friction", "got -1"});
  CHECK(neg_static.code == ErrorCode::invalid_argument);
  expect_error(colliders(sphere + R"(, "friction": 0.3, "static_friction": -0.5})"),
               {"colliders[0].static_friction", "got -0.5"});
  expect_error(colliders(sphere + R"(, "friction": "high"})"),
               {"colliders[0].friction", "a number", "\"high\""});
  // The index is the collider's.
  expect_error(colliders(R"({"type": "plane"}, )" + sphere + R"(, "friction": -2})"),
               {"colliders[1].friction", "-2"});
}

TEST_CASE("colliders: keyframes name the key, the index and the value") {
  const std::string box = R"({"type": "box", "center": [0,0,0], "half_extents": [1,1,1], "keyframes": )";
  expect_error(colliders(box + R"([{"t": 0}, {"t": 2}, {"t": 1}]})"),
               {"colliders[0].keyframes[2].t", "greater than keyframes[1].t (2)", "time order", "got 1"});
  expect_error(colliders(box + R"([{"t": 0}, {"t": 0}]})"), {"colliders[0].keyframes[1].t", "got 0"});
  expect_error(colliders(box + R"([{"t": -1}]})"), {"colliders[0].keyframes[0].t", ">= 0", "got -1"});
  expect_error(colliders(box + R"([]})"), {"colliders[0].keyframes", "at least one key"});
  expect_error(colliders(box + R"({"t": 0}})"), {"colliders[0].keyframes", "an array"});
  expect_error(colliders(box + R"([{"translate": [1,0,0]}]})"), {"colliders[0].keyframes[0]", "t"});
  expect_error(colliders(box + R"([{"t": 0, "rotate": [0,0,90]}]})"),
               {"colliders[0].keyframes[0]", "rotate"});
  expect_error(colliders(box + R"([{"t": 0, "translate": [1,0]}]})"),
               {"colliders[0].keyframes[0].translate"});
  const Error both = expect_error(
      colliders(R"({"type": "sphere", "center": [0,0,0], "radius": 1, "linear_velocity": [1,0,0], )"
                R"("keyframes": [{"t": 0}]})"),
      {"colliders[0].keyframes exclude linear_velocity"});
  CHECK(both.code == ErrorCode::invalid_argument);
}

TEST_CASE("colliders: capsule radius and box half_extents must be > 0") {
  for (const char* r : {"0", "-0.5"}) {
    CAPTURE(r);
    const Error e = expect_error(
        colliders(R"({"type": "capsule", "a": [0,0,0], "b": [1,0,0], "radius": )" + std::string(r) + "}"),
        {"colliders[0].radius", "> 0", std::string("got ") + r});
    CHECK(e.code == ErrorCode::invalid_argument);
  }
  expect_error(colliders(R"({"type": "box", "center": [0,0,0], "half_extents": [1, 0, 1]})"),
               {"colliders[0].half_extents", "> 0", "[1, 0, 1]"});
  expect_error(colliders(R"({"type": "box", "center": [0,0,0], "half_extents": [-1, 1, 1]})"),
               {"colliders[0].half_extents", "[-1, 1, 1]"});
  expect_error(colliders(R"({"type": "box", "center": [0,0,0], "half_extents": [1, 1]})"),
               {"colliders[0].half_extents", "3 numbers"});
  expect_error(colliders(R"({"type": "capsule", "a": [0,0], "b": [1,0,0], "radius": 1})"),
               {"colliders[0].a", "3 numbers"});
}

TEST_CASE("colliders: velocities must be finite, a plane takes linear_velocity only") {
  // JSON has no NaN; 1e999 is what overflows (nlohmann's parser refuses it, naming the element).
  const Error e = expect_error(colliders(sphere + R"(, "linear_velocity": [0, 1e999, 0]})"),
                               {"colliders[0].linear_velocity[1]", "1e999"});
  CHECK(e.code == ErrorCode::parse);
  expect_error(colliders(sphere + R"(, "angular_velocity": [-1e999, 0, 0]})"),
               {"colliders[0].angular_velocity[0]"});
  expect_error(colliders(sphere + "}"), {"colliders.0.angular_velocity", "finite", "1e999"},
               {"colliders.0.angular_velocity=[0,0,1e999]"});
  expect_error(colliders(sphere + "}"), {"colliders[0].linear_velocity", "3 numbers", "nan"},
               {"colliders.0.linear_velocity=[0,nan,0]"}); // not JSON: taken as a string
  expect_error(colliders(sphere + R"(, "linear_velocity": [0, 0]})"),
               {"colliders[0].linear_velocity", "3 numbers"});
  expect_error(colliders(R"({"type": "plane", "angular_velocity": [0, 0, 1]})"),
               {"colliders[0].angular_velocity", "plane", "linear_velocity only", "[0, 0, 1]"});
}

TEST_CASE("colliders and wind: vectors and lengths beyond +-1e30 (float's range) name the key and value") {
  // Each finite in double but inf (or NaN) once the solvers take it in float: the collider would
  // silently do nothing, or the wind's direction normalise to zero.
  const Error e =
      expect_error(colliders(R"({"type": "capsule", "a": [0,0,0], "b": [1e39,0,0], "radius": 0.1})"),
                   {"colliders[0].b", "within +-1e30", "[1e+39, 0, 0]"});
  CHECK(e.code == ErrorCode::invalid_argument);
  expect_error(colliders(R"({"type": "sphere", "center": [1e308, 0, 0], "radius": 1})"),
               {"colliders[0].center", "within +-1e30", "1e+308"});
  expect_error(colliders(R"({"type": "plane", "normal": [1e308, 1e308, 0]})"),
               {"colliders[0].normal", "within +-1e30", "[1e+308, 1e+308, 0]"});
  expect_error(colliders(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1e31})"),
               {"colliders[0].radius", "at most 1e30", "1e+31"});
  expect_error(colliders(sphere + R"(, "linear_velocity": [1e308, 0, 0]})"),
               {"colliders[0].linear_velocity", "within +-1e30"});
  expect_error(colliders(sphere + R"(, "angular_velocity": [0, 0, -1e31]})"),
               {"colliders[0].angular_velocity", "within +-1e30"});
  expect_error(R"({"system": "chain", "wind": {"strength": 1, "direction": [0, 1e308, 1e308]}})",
               {"wind.direction", "within +-1e30", "[0, 1e+308, 1e+308]"});
  // At the limit: accepted.
  CHECK(parse_scene(colliders(R"({"type": "sphere", "center": [1e30, 0, 0], "radius": 1e30})"), "ok.json")
            .ok());
}

TEST_CASE("colliders: a mesh collider's thickness, scale and file") {
  const auto dir = mesh_dir("mesh", "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string ok_path = R"("path": "tri.obj")";
  for (const char* t : {"0", "-0.01"}) {
    CAPTURE(t);
    const Error e =
        expect_error_in(dir, colliders(R"({"type": "mesh", )" + ok_path + R"(, "thickness": )" + t + "}"),
                        {"colliders[0].thickness", "> 0", std::string("got ") + t});
    CHECK(e.code == ErrorCode::invalid_argument);
  }
  expect_error_in(
      dir, colliders(R"({"type": "mesh", )" + ok_path + R"(, "thickness": 0.01, "transform": {"scale": 0}})"),
      {"colliders[0].transform.scale", "> 0", "got 0"});
  expect_error_in(dir,
                  colliders(R"({"type": "mesh", )" + ok_path +
                            R"(, "thickness": 0.01, "transform": {"translate": [0, 1e999, 0]}})"),
                  {"colliders[0].transform.translate[1]"});

  // A missing file: the reader's message (the file) after the key; i/o, exit 2 in the CLI.
  const Error missing =
      expect_error_in(dir, colliders(R"({"type": "mesh", "path": "meshes/none.obj", "thickness": 0.01})"),
                      {"colliders[0].path: ", "meshes/none.obj", "no such mesh file"});
  CHECK(missing.code == ErrorCode::io);
  std::filesystem::create_directories(dir / "folder.obj");
  expect_error_in(dir, colliders(R"({"type": "mesh", "path": "folder.obj", "thickness": 0.01})"),
                  {"colliders[0].path: ", "folder.obj", "directory"});
  expect_error_in(dir, colliders(R"({"type": "mesh", "path": "tri.stl", "thickness": 0.01})"),
                  {"colliders[0].path: ", ".stl"});

  // A malformed file: the reader's message names the file and the line.
  mesh_dir("mesh", "broken.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n");
  const Error broken = expect_error_in(
      dir, colliders(R"({"type": "plane"}, {"type": "mesh", "path": "broken.obj", "thickness": 0.01})"),
      {"colliders[1].path: ", "broken.obj:4: face index 9 is out of range"});
  CHECK(broken.code == ErrorCode::parse);
  mesh_dir("mesh", "broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [}");
  expect_error_in(dir, colliders(R"({"type": "mesh", "path": "broken.gltf", "thickness": 0.01})"),
                  {"colliders[0].path: ", "broken.gltf:1:", "invalid JSON"});
  // Every triangle of zero area: nothing to collide with.
  mesh_dir("mesh", "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  expect_error_in(dir, colliders(R"({"type": "mesh", "path": "flat.obj", "thickness": 0.01})"),
                  {"colliders[0].path: ", "flat.obj", "zero area"});
}

// ---- Self-collision ----
