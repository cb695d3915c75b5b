// SPDX-License-Identifier: MIT
// Scene files that must be refused, each with a message naming the key and the value (the
// colliders': test_scene_errors_colliders.cpp).
#include <doctest/doctest.h>

#include <string>

#include "scene_errors_util.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

TEST_CASE("a key twice in one object, or a NUL byte, is an error naming where (not the last key winning)") {
  // nlohmann lets the last of two keys win and stops reading at a NUL byte: both silently dropped
  // part of the scene.
  const Error twice = expect_error(R"({"system": "chain", "colliders": [{"type": "sphere", "radius": 1, )"
                                   R"("center": [0, 0, 0], "radius": 2}]})",
                                   {"invalid JSON at colliders[0]", "the key \"radius\" appears twice"});
  CHECK(twice.code == ErrorCode::parse);
  expect_error(R"({"system": "cloth", "system": "chain"})", {"the key \"system\" appears twice"});
  // The same key in two objects is fine.
  CHECK(parse_scene(
            R"({"system": "chain", "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}, )"
            R"({"type": "sphere", "center": [1, 0, 0], "radius": 1}]})",
            "ok.json")
            .ok());
  const Error nul =
      expect_error(std::string("{\"system\": \"chain\"}\0{\"more\": 1}", 31), {"bad.json:1:20", "NUL byte"});
  CHECK(nul.code == ErrorCode::parse);
}

TEST_CASE("malformed JSON: parse error with line and column") {
  const Error e = expect_error("{\"system\": \"chain\",\n  \"physics\": {\"damping\": 0.5,}\n}",
                               {"bad.json:2:", "invalid JSON"});
  CHECK(e.code == ErrorCode::parse);
  expect_error("", {"bad.json:1:1", "invalid JSON"});
  expect_error("[1, 2]", {"JSON object"});
}

TEST_CASE("unknown keys are refused at every level, naming the full path") {
  expect_error(R"({"system": "chain", "dampin": 1})", {"unknown key dampin"});
  expect_error(cloth(R"({"stifness": {"bend": 1}})"), {"unknown key cloth.stifness"});
  expect_error(cloth(R"({"stiffness": {"bent": 1}})"), {"unknown key cloth.stiffness.bent"});
  expect_error(R"({"system": "chain", "integrator": {"dt": 0.02, "step": 5}})",
               {"unknown key integrator.step"});
  expect_error(R"({"system": "chain", "physics": {"g": 1}})", {"unknown key physics.g"});
  expect_error(R"({"system": "chain", "wind": {"speed": 1}})", {"unknown key wind.speed"});
  expect_error(R"({"system": "chain", "chain": {"mass": [1]}})", {"unknown key chain.mass"});
  expect_error(
      R"({"system": "chain", "colliders": [{"type": "sphere", "center": [0,0,0], "radius": 1, "r": 2}]})",
      {"unknown key colliders[0].r"});
  expect_error(R"({"system": "chain", "colliders": [{"type": "plane", "radius": 2}]})",
               {"unknown key colliders[0].radius"});
}

TEST_CASE("wrong types name the key, the expected type and the value") {
  const Error e = expect_error(R"({"system": "chain", "integrator": {"dt": "fast"}})",
                               {"integrator.dt", "must be a number", "\"fast\""});
  CHECK(e.code == ErrorCode::parse);
  expect_error(R"({"system": "chain", "physics": {"gravity": [0, -9.81]}})",
               {"physics.gravity", "3 numbers", "[0,-9.81]"});
  expect_error(R"({"system": "chain", "physics": {"gravity": [0, 0, "down"]}})",
               {"physics.gravity[2]", "\"down\""});
  expect_error(R"({"system": "chain", "physics": 3})", {"physics", "an object", "3"});
  expect_error(cloth(R"({"resolution": [10.5, 10]})"), {"cloth.resolution[0]", "integer", "10.5"});
  expect_error(cloth(R"({"resolution": 10})"), {"cloth.resolution", "2 integers", "10"});
  expect_error(cloth(R"({"orientation": "diagonal"})"), {"cloth.orientation", "diagonal"});
  expect_error(cloth(R"({"pins": [[1]]})"), {"cloth.pins[0]", "[1]"});
  expect_error(R"({"system": "chain", "integrator": {"steps": -5}})", {"integrator.steps", "-5"});
  expect_error(R"({"system": "chain", "integrator": {"steps": 2e9}})", {"integrator.steps", "1000000000"});
  expect_error(R"({"system": "chain", "chain": {"positions": [[0, 0]]}})",
               {"chain.positions[0]", "3 numbers"});
  expect_error(R"({"system": "chain", "colliders": {"type": "plane"}})", {"colliders", "an array"});
  expect_error(R"({"system": "chain", "colliders": [{"type": "cube"}]})", {"colliders[0].type", "cube"});
  expect_error(R"({"system": "chain", "colliders": [{"type": "sphere", "center": [0, 0, 0]}]})",
               {"colliders[0].radius", "required"});
}

TEST_CASE("values out of range name the key and the value") {
  expect_error(R"({"system": "chain", "integrator": {"dt": 0}})", {"integrator.dt", "> 0", "got 0"});
  expect_error(R"({"system": "chain", "integrator": {"dt": -1}})", {"integrator.dt", "got -1"});
  expect_error(R"({"system": "chain", "physics": {"damping": -1}})", {"physics.damping", "got -1"});
  expect_error(R"({"system": "chain", "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0}]})",
               {"colliders[0].radius", "got 0"});
  expect_error(R"({"system": "chain", "contact_epsilon": -0.1})", {"contact_epsilon", "-0.1"});
  expect_error(cloth(R"({"particle_mass": 0})"), {"cloth.particle_mass", "got 0"});
  expect_error(cloth(R"({"resolution": [0, 5]})"), {"cloth.resolution", "[0, 5]"});
  // Refused before anything is allocated (10^10 particles would not fit).
  const Error big =
      expect_error(cloth(R"({"resolution": [100000, 100000]})"), {"cloth.resolution", "[100000, 100000]"});
  CHECK(big.code == ErrorCode::invalid_argument);
  expect_error(cloth(R"({"resolution": [8000, 8000]})"), {"cloth.resolution", "particles"});
  expect_error(cloth(R"({"resolution": [1e12, 5]})"), {"cloth.resolution[0]", "integer"});
  expect_error(cloth(R"({"resolution": [4, 4], "pins": [[4, 0]]})"), {"cloth.pins[0]", "[4, 0]", "outside"});
  expect_error(cloth(R"({"stiffness": {"bend": -2}})"), {"cloth.stiffness.bend", "-2"});
  expect_error(cloth(R"({"size": [0, 1]})"), {"cloth.size", "[0, 1]"});
  expect_error(R"({"system": "chain", "chain": {"masses": [1, 1], "stiffness": [20, 20, 20]}})",
               {"chain.stiffness", "3"});
  expect_error(R"({"system": "chain", "chain": {"masses": [1, 1], "positions": [[0, 0, -1]]}})",
               {"chain.positions"});
  expect_error(R"({"system": "chain", "chain": {"masses": [1, -1]}})", {"chain.masses[1]", "-1"});
  expect_error(R"({"system": "chain", "chain": {"masses": []}})", {"chain.masses"});
}

TEST_CASE("numbers that overflow a double (1e999) are refused, naming the key") {
  const Error e =
      expect_error(R"({"system": "chain", "physics": {"damping": 1e999}})", {"physics.damping", "1e999"});
  CHECK(e.code == ErrorCode::parse);
  expect_error(cloth(R"({"pins": [[0, 1], [2, 1e999]]})"), {"cloth.pins[1][1]", "1e999"});
  expect_error(R"({"system": "chain"})", {"integrator.dt", "1e999"}, {"integrator.dt=1e999"});
  expect_error(R"({"system": "chain"})", {"integrator.dt", "finite"}, {"integrator.dt=-1e999"});
}

TEST_CASE("system: required, known, and only its own section") {
  expect_error(R"({"integrator": {"dt": 0.02}})", {"system", "required"});
  expect_error(R"({"system": "rope"})", {"system", "rope"});
  expect_error(R"({"system": 1})", {"system", "string"});
  expect_error(R"({"system": "chain", "cloth": {}})", {"cloth", "chain"});
  expect_error(R"({"system": "cloth", "chain": {}})", {"chain", "cloth"});
}

TEST_CASE("unknown integrator names the key and the value") {
  expect_error(R"({"system": "chain", "integrator": {"method": "verlet"}})",
               {"integrator.method", "verlet", "rk4", "implicit_euler"});
}

TEST_CASE("substeps and the CG keys are range-checked") {
  // The range a message quotes is the one the key takes (it said 0..1000000 and then refused 0).
  for (const char* n : {"0", "1e7"}) {
    CAPTURE(n);
    expect_error(R"({"system": "chain", "integrator": {"substeps": )" + std::string(n) + "}}",
                 {"integrator.substeps must be an integer in 1..1000000, got"});
  }
  expect_error(R"({"system": "chain", "integrator": {"iterations": 1001}})",
               {"integrator.iterations must be an integer in 1..1000, got 1001"});

  expect_error(R"({"system": "chain", "integrator": {"cg_tolerance": 2}})", {"integrator.cg_tolerance", "2"});
  expect_error(R"({"system": "chain", "integrator": {"cg_max_iterations": 0}})",
               {"integrator.cg_max_iterations", "0"});
}

TEST_CASE("bad overrides name the override and the path") {
  expect_error(R"({"system": "chain", "integrator": {"dt": 0.02}})", {"integrator.dt.x", "not an object"},
               {"integrator.dt.x=1"});
  expect_error(R"({"system": "chain"})", {"key.path=value"}, {"no_equals_sign"});
  expect_error(R"({"system": "chain"})", {"empty part"}, {"integrator..dt=1"});
  expect_error(R"({"system": "cloth"})", {"unknown key cloth.stifness"}, {"cloth.stifness.bend=3"});
  expect_error(R"({"system": "chain"})", {"unknown key nosuch"}, {"nosuch=3"});
  expect_error(R"({"system": "chain", "colliders": []})", {"index 3", "colliders"}, {"colliders.3.radius=1"});
  expect_error(R"({"system": "chain", "colliders": []})", {"colliders", "not an index"}, {"colliders.x=1"});
  expect_error(R"({"system": "chain"})", {"integrator.dt", "\"fast\""}, {"integrator.dt=fast"});
  expect_error(R"({"system": "chain"})", {"physics.damping", "got -1"}, {"physics.damping=-1"});
}

TEST_CASE("load_scene_file: a missing file is an i/o error naming it") {
  auto s = load_scene_file("/nonexistent/dir/scene.json");
  REQUIRE(!s.ok());
  CHECK(s.error().code == ErrorCode::io);
  CHECK(s.error().message.find("/nonexistent/dir/scene.json") != std::string::npos);
}

TEST_CASE("stretch_limit: bad input names the key and the value") {
  const std::string base = R"({"system": "cloth", "stretch_limit": )";
  expect_error(base + R"({"method": "both", "max_strain": 0}})",
               {"stretch_limit.max_strain", "> 0", "got 0"});
  expect_error(base + R"({"method": "both", "max_strain": -0.1}})", {"stretch_limit.max_strain", "-0.1"});
  expect_error(base + R"({"method": "both", "iterations": 0}})",
               {"stretch_limit.iterations", "1..100", "got 0"});
  expect_error(base + R"({"method": "both", "iterations": 101}})", {"stretch_limit.iterations", "got 101"});
  expect_error(base + R"({"method": "both", "iterations": 2.5}})", {"stretch_limit.iterations"});
  expect_error(base + R"({"method": "hard"}})", {"stretch_limit.method", "\"hard\"", "provot", "projection"});
  expect_error(base + R"({"max_strain": 0.1}})", {"stretch_limit.method is required"});
  expect_error(base + R"({"method": "both", "tether_distance": "manhattan"}})",
               {"stretch_limit.tether_distance", "\"manhattan\""});
  expect_error(base + R"({"method": "both", "sweeps": 4}})", {"unknown key stretch_limit.sweeps"});
  expect_error(base + R"({"method": "provot", "order": "chain"}})",
               {"stretch_limit.order", "\"colours\" or \"chains\"", "\"chain\""});
  expect_error(base + R"({"method": "provot", "order": 1}})", {"stretch_limit.order"});
  // --set reaches every key, and turns the limit on in a scene without one.
  expect_error(R"({"system": "cloth"})", {"stretch_limit.max_strain", "got 0"},
               {"stretch_limit.method=both", "stretch_limit.max_strain=0"});
  auto on = parse_scene(R"({"system": "cloth"})", "ok.json",
                        std::vector<std::string>{"stretch_limit.method=provot"});
  REQUIRE(on.ok());
  CHECK(on->params.stretch_limit.method == StretchLimit::Method::provot);
  CHECK(on->params.stretch_limit.iterations == 4);
  CHECK(on->params.stretch_limit.order == StretchLimit::SweepOrder::colours); // the default
  auto chains = parse_scene(base + R"({"method": "both", "order": "chains"}})", "ok.json");
  REQUIRE(chains.ok());
  CHECK(chains->params.stretch_limit.chains());
  auto projection = parse_scene(R"({"system": "cloth"})", "ok.json",
                                std::vector<std::string>{"stretch_limit.method=projection"});
  REQUIRE(projection.ok());
  CHECK(projection->params.stretch_limit.projection());
  CHECK(projection->params.stretch_limit.tethers()); // the tethers first
  auto off = parse_scene(R"({"system": "cloth"})", "ok.json");
  REQUIRE(off.ok());
  CHECK(!off->params.stretch_limit.enabled()); // off by default: the report's model
}

// ---- Capsule, box and mesh colliders, friction, moving colliders ----

TEST_CASE("self_collision: bad input names the key and the value") {
  const std::string base = R"({"system": "cloth", "self_collision": )";
  const auto expect = [&](const std::string& body, ErrorCode code, std::initializer_list<std::string> needles,
                          std::vector<std::string> overrides = {}) {
    CAPTURE(body);
    CHECK(expect_error(base + body + "}", needles, std::move(overrides)).code == code);
  };
  // Ranges (SimParams::validate): invalid_argument.
  expect(R"({"thickness": 0})", ErrorCode::invalid_argument, {"self_collision.thickness", "> 0", "got 0"});
  expect(R"({"thickness": -0.01})", ErrorCode::invalid_argument, {"self_collision.thickness", "got -0.01"});
  expect(R"({"iterations": 0})", ErrorCode::invalid_argument,
         {"self_collision.iterations", "1..16", "got 0"});
  expect(R"({"iterations": 17})", ErrorCode::invalid_argument,
         {"self_collision.iterations", "1..16", "got 17"});
  expect(R"({"friction": -0.1})", ErrorCode::invalid_argument,
         {"self_collision.friction", ">= 0", "got -0.1"});
  expect(R"({"skin": -0.001})", ErrorCode::invalid_argument, {"self_collision.skin", ">= 0", "got -0.001"});
  expect(R"({"thickness": 0.01, "skin": 0.2})", ErrorCode::invalid_argument,
         {"self_collision.skin", "10 x the thickness", "got 0.2"});
  expect(R"({"stiffness": -1})", ErrorCode::invalid_argument, {"self_collision.stiffness", ">= 0", "got -1"});
  expect(R"({"stiffness": 100})", ErrorCode::invalid_argument,
         {"self_collision.stiffness 100", "self_collision.skin > 0", "got skin 0"});
  // Off, the values are still checked (a later --set self_collision.enabled=true must not meet them).
  expect(R"({"enabled": false, "thickness": -1})", ErrorCode::invalid_argument,
         {"self_collision.thickness", "got -1"});
  // Shapes: parse.
  expect(R"({"thickness": 1e999})", ErrorCode::parse, {"self_collision.thickness", "1e999"});
  expect(R"({"thickness": "nan"})", ErrorCode::parse, {"self_collision.thickness", "a number", "\"nan\""});
  expect(R"({"thickness": "0.01"})", ErrorCode::parse, {"self_collision.thickness", "a number", "\"0.01\""});
  expect(R"({"friction": null})", ErrorCode::parse, {"self_collision.friction", "a number", "null"});
  expect(R"({"iterations": 2.5})", ErrorCode::parse, {"self_collision.iterations", "integer", "2.5"});
  expect(R"({"iterations": -1})", ErrorCode::parse, {"self_collision.iterations", "integer", "-1"});
  expect(R"({"iterations": "2"})", ErrorCode::parse, {"self_collision.iterations", "integer", "\"2\""});
  expect(R"({"enabled": 1})", ErrorCode::parse, {"self_collision.enabled", "true or false", "got 1"});
  expect(R"({"enabled": "yes"})", ErrorCode::parse, {"self_collision.enabled", "true or false", "\"yes\""});
  expect(R"({"radius": 0.01})", ErrorCode::parse,
         {"unknown key self_collision.radius", "enabled, thickness, friction, iterations"});
  expect(R"(true)", ErrorCode::parse, {"self_collision", "an object", "got true"});
  // The thickness against the cloth (check_self_collision): the default 10 x 10 grid over 1 m has
  // structural springs of 1/9 m, so more than 1.111 m is refused.
  expect(R"({"thickness": 2})", ErrorCode::invalid_argument,
         {"self_collision.thickness 2 m", "more than 10 x the mean rest length", "(0.1111 m)"});
  // ... on a chain (its springs have no kind: all of them count; the default spring is 0.4 m) ...
  CHECK(expect_error(R"({"system": "chain", "self_collision": {"thickness": 5}})",
                     {"self_collision.thickness 5 m", "10 x the mean rest length", "(0.4 m)"})
            .code == ErrorCode::invalid_argument);
  // ... and on a mesh cloth (a 3 x 1 strip of unit quads).
  const auto dir = mesh_dir("self_collision", "strip.obj",
                            "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 0 1\nv 1 0 1\nv 2 0 1\nv 3 0 1\n"
                            "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n");
  expect_error_in(
      dir, R"({"system": "cloth", "cloth": {"mesh": "strip.obj"}, "self_collision": {"thickness": 11}})",
      {"self_collision.thickness 11 m", "10 x the mean rest length", "(1 m)"});
  // Off, a thickness far above the spacing is not compared with it.
  CHECK(parse_scene(base + R"({"enabled": false, "thickness": 2}})", "ok.json").ok());

  // --set reaches every key, and turns self-collision on in a scene without it.
  expect_error(R"({"system": "cloth"})", {"self_collision.thickness", "got -1"},
               {"self_collision.thickness=-1"});
  expect_error(R"({"system": "cloth"})", {"self_collision.thickness", "\"nan\""},
               {"self_collision.thickness=nan"});
  expect_error(R"({"system": "cloth"})", {"self_collision.thickness", "1e999"},
               {"self_collision.thickness=1e999"});
  expect_error(R"({"system": "cloth"})", {"self_collision.iterations", "got 17"},
               {"self_collision.enabled=true", "self_collision.iterations=17"});
  expect_error(R"({"system": "cloth"})", {"self_collision.enabled", "\"maybe\""},
               {"self_collision.enabled=maybe"});
  expect_error(R"({"system": "cloth"})", {"unknown key self_collision.thicknes"},
               {"self_collision.thicknes=0.1"});
  expect_error(R"({"system": "cloth", "self_collision": {"enabled": false, "thickness": 2}})",
               {"self_collision.thickness 2 m", "10 x"}, {"self_collision.enabled=true"});
}

namespace {
/// A 4 x 4 cloth with a sphere (collider 0) and a plane (collider 1), and `attach` in its cloth.
std::string attached(const std::string& attach) {
  return R"({"system": "cloth", "cloth": {"resolution": [4, 4], )" + attach +
         R"(}, "colliders": [{"type": "sphere", "center": [0, 0, 2], "radius": 0.1}, )"
         R"({"type": "plane", "normal": [0, 0, 1], "offset": -1}]})";
}
} // namespace

TEST_CASE("cloth.attach and cloth.max_distance: bad entries name the key and the value") {
  expect_error(attached(R"("attach": [{"collider": 7, "vertices": [[0, 3]]}])"),
               {"cloth.attach[0].collider is 7", "2 colliders"});
  expect_error(attached(R"("attach": [{"collider": 1, "vertices": [[0, 3]]}])"),
               {"cloth.attach[0]", "collider 1 is a plane"});
  expect_error(attached(R"("attach": [{"collider": 0, "region": {"min": [5, 5, 5], "max": [6, 6, 6]}}])"),
               {"cloth.attach[0].region", "selects no particle"});
  expect_error(attached(R"("attach": [{"collider": 0, "vertices": []}])"),
               {"cloth.attach[0].vertices is empty", "no particle"});
  expect_error(attached(R"("attach": [{"collider": 0, "vertices": [[4, 0]]}])"),
               {"cloth.attach[0].vertices[0] = [4, 0]", "outside the 4 x 4 grid"});
  expect_error(attached(R"("attach": [{"collider": 0, "vertices": [3]}])"),
               {"cloth.attach[0].vertices[0]", "[i, j]"});
  expect_error(attached(R"("attach": [{"collider": 0}])"), {"cloth.attach[0]", "\"region\" or \"vertices\""});
  expect_error(attached(R"("attach": [{"vertices": [[0, 0]]}])"), {"cloth.attach[0]", "collider"});
  expect_error(attached(R"("attach": [{"collider": 0, "vertices": [[0, 0]], "bone": 2}])"),
               {"cloth.attach[0]", "bone"});
  expect_error(
      attached(R"("attach": [{"collider": 0, "vertices": [[0, 0]]}, {"collider": 0, "vertices": [[0, 0]]}])"),
      {"attachments[1].particles[0] is particle 0", "attachments[0].particles[0]"});
  expect_error(
      attached(
          R"("attach": [{"collider": 0, "vertices": [[0, 0]]}], "max_distance": {"attach": 1, "distance": 0.1})"),
      {"cloth.max_distance.attach is 1", "1 entries"});
  expect_error(
      attached(
          R"("attach": [{"collider": 0, "vertices": [[0, 0]]}], "max_distance": [{"attach": 0, "distance": -0.1}])"),
      {"cloth.max_distance[0].distance", ">= 0", "got -0.1"});
  expect_error(attached(R"("max_distance": {"attach": 0, "distance": 0.1})"),
               {"cloth.max_distance needs cloth.attach"});
}

TEST_CASE("cloth.attach: a region pins the particles it selects, max_distance leaves them free, offsets from "
          "t = 0") {
  auto s = parse_scene(
      attached(
          R"("size": [1, 1], "origin": [0, 0, 0], "attach": [{"collider": 0, "region": {"min": [-1, -1, 0.9], "max": [2, 2, 2]}}, )"
          R"({"collider": 0, "vertices": [[1, 0]]}], "max_distance": {"attach": 1, "distance": 0.05})"),
      "attach.json");
  REQUIRE_MESSAGE(s.ok(), (s.ok() ? "" : s.error().message));
  REQUIRE(s->params.attachments.size() == 2);
  const Attachment& top = s->params.attachments[0];
  CHECK(top.particles == std::vector<std::uint32_t>{12, 13, 14, 15}); // the vertical grid's top row, z = 1
  CHECK(top.max_distance == 0.0);
  for (std::uint32_t p : top.particles)
    CHECK(s->system.particles[p].pinned);
  CHECK(top.offsets[0].z == doctest::Approx(1.0 - 2.0)); // z = 1 against the sphere's centre at 2
  CHECK(s->params.attachments[1].particles == std::vector<std::uint32_t>{1});
  CHECK(s->params.attachments[1].max_distance == 0.05);
  CHECK_FALSE(s->system.particles[1].pinned);
  CHECK_FALSE(s->params.inertia.enabled());
  // The frame and a teleport key.
  auto framed = parse_scene(
      R"({"system": "cloth", "inertia": {"collider": 0, "linear": 0.25}, "colliders": [{"type": "capsule", )"
      R"("a": [0, 0, 0], "b": [0, 0, 1], "radius": 0.1, "keyframes": [{"t": 0}, {"t": 1, "translate": [5, 0, 0], )"
      R"("teleport": true}]}]})",
      "framed.json");
  REQUIRE_MESSAGE(framed.ok(), (framed.ok() ? "" : framed.error().message));
  CHECK(framed->params.inertia.collider == 0u);
  CHECK(framed->params.inertia.linear == 0.25);
  CHECK(framed->params.inertia.angular == 1.0);
  CHECK(framed->params.colliders[0].path->keys[1].teleport);
}

TEST_CASE("inertia and keyframes' teleport: bad entries name the key and the value") {
  const std::string sphere_json = R"({"type": "sphere", "center": [0, 0, 2], "radius": 0.1})";
  const auto scene = [&](const std::string& inertia) {
    return R"({"system": "cloth", "colliders": [)" + sphere_json + R"(, {"type": "plane"}], "inertia": )" +
           inertia + "}";
  };
  expect_error(scene(R"({"collider": 3})"), {"inertia.collider is 3, but there are 2 colliders"});
  expect_error(scene(R"({"collider": 1})"), {"inertia.collider 1 is a plane"});
  expect_error(scene(R"({"collider": 0, "linear": 1.5})"), {"inertia.linear must be in [0, 1], got 1.5"});
  expect_error(scene(R"({"collider": 0, "angular": -1})"), {"inertia.angular must be in [0, 1], got -1"});
  expect_error(scene(R"({"linear": 0.5})"), {"inertia", "collider"});
  expect_error(scene(R"({"collider": 0, "spin": 0.5})"), {"inertia", "spin"});
  expect_error(
      colliders(
          R"({"type": "box", "center": [0,0,0], "half_extents": [1,1,1], "keyframes": [{"t": 0, "teleport": true}]})"),
      {"colliders[0].keyframes[0].teleport", "first key"});
  expect_error(
      colliders(
          R"({"type": "box", "center": [0,0,0], "half_extents": [1,1,1], "keyframes": [{"t": 0}, {"t": 1, "teleport": 1}]})"),
      {"colliders[0].keyframes[1].teleport"});
}
