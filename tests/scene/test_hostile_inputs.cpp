// SPDX-License-Identifier: MIT
// Hostile inputs: each must be a clear error naming the field and the value, never a
// crash, a hang, a silent clamp or an unbounded allocation. docs/errors.md lists them in a table.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "vkcloth/cpu_solver.hpp"
#include "scene_errors_util.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth;

namespace {

Error refused(const std::string& text, std::initializer_list<std::string> needles,
              std::vector<std::string> overrides = {}) {
  Error e = vkcloth::test::expect_error_as("hostile.json", text, needles, std::move(overrides));
  CHECK(e.message.size() < 2000); // a message a person can read, not the input echoed back
  return e;
}

std::string cloth(const std::string& body) {
  return R"({"system": "cloth", "cloth": )" + body + "}";
}
std::string chain(const std::string& body) {
  return R"({"system": "chain", "chain": )" + body + "}";
}

std::string repeat(const std::string& s, std::size_t n) {
  std::string out;
  out.reserve(s.size() * n);
  for (std::size_t k = 0; k < n; ++k)
    out += s;
  return out;
}

} // namespace

TEST_CASE("hostile: deeply nested JSON is refused before parsing (no stack overflow)") {
  const std::size_t depth = 100000;
  const Error e = refused(R"({"system": "chain", "name": )" + repeat("[", depth) + repeat("]", depth) + "}",
                          {"hostile.json:1:", "nested more than 64 levels"});
  CHECK(e.code == ErrorCode::parse);
  refused(R"({"x": )" + repeat("{\"a\": ", depth) + "1" + repeat("}", depth) + "}", {"nested"});
  // Brackets inside strings do not count.
  auto ok = parse_scene(R"({"system": "chain", "name": ")" + repeat("[", 1000) + "\"}", "s.json");
  CHECK(ok.ok());
  // An override value that is not (acceptable) JSON is taken as a plain string.
  auto o =
      parse_scene(R"({"system": "chain"})", "s.json", std::vector<std::string>{"name=" + repeat("[", 1000)});
  REQUIRE(o.ok());
  CHECK(o->name.size() == 1000);
}

TEST_CASE("hostile: an override key path of thousands of parts is refused") {
  refused(R"({"system": "chain"})", {"more than 16"}, {repeat("a.", 5000) + "b=1"});
  refused(R"({"system": "chain"})", {"more than 16"}, {repeat("[0]", 5000) + "=1"});
}

TEST_CASE("hostile: scene text over max_scene_bytes is refused without parsing") {
  std::string big = R"({"system": "chain", "name": ")" + std::string(max_scene_bytes, 'x') + "\"}";
  const Error e = refused(big, {"more than the limit", "16 MiB"});
  CHECK(e.code == ErrorCode::parse);
}

TEST_CASE("hostile: a 1 GB scene file is refused by its size, without reading it") {
  const auto dir = std::filesystem::temp_directory_path() / "vkcloth_hostile";
  std::filesystem::create_directories(dir);
  const auto path = dir / "huge.json";
  {
    std::ofstream f(path, std::ios::binary);
    f << R"({"system": "chain"})";
  }
  std::filesystem::resize_file(path, std::uintmax_t{1} << 30); // sparse: no disk used
  auto s = load_scene_file(path);
  REQUIRE(!s.ok());
  CHECK(s.error().code == ErrorCode::io);
  CHECK(s.error().message.find("more than the scene size limit") != std::string::npos);
  std::filesystem::remove(path);
}

TEST_CASE("hostile: an endless device (/dev/zero) is read only up to the limit") {
  if (!std::filesystem::exists("/dev/zero"))
    return;
  auto s = load_scene_file("/dev/zero");
  REQUIRE(!s.ok());
  CHECK(s.error().code == ErrorCode::io);
  CHECK(s.error().message.find("/dev/zero") != std::string::npos);
}

TEST_CASE("hostile: absurd sizes are refused before any allocation") {
  refused(cloth(R"({"resolution": [100000, 100000]})"), {"cloth.resolution [100000, 100000]", "1..8192"});
  refused(cloth(R"({"resolution": [8192, 8192]})"), {"67108864 particles", "more than the limit"});
  refused(cloth(R"({"resolution": [0, 10]})"), {"cloth.resolution [0, 10]"});
  refused(cloth(R"({"resolution": [1e30, 10]})"), {"cloth.resolution[0]", "1e+30"});
  refused(cloth(R"({"resolution": [-3, 10]})"), {"cloth.resolution[0]", "-3"});
  refused(cloth(R"({"resolution": [10.5, 10]})"), {"cloth.resolution[0]", "10.5"});
  refused(R"({"system": "chain", "integrator": {"steps": 1e300}})", {"integrator.steps", "1e+300"});
  refused(R"({"system": "chain", "integrator": {"steps": 18446744073709551615}})",
          {"integrator.steps", "18446744073709551615"});
}

TEST_CASE("hostile: a pins list longer than the grid is refused without walking it") {
  std::string pins = std::string("[")
                         .append(repeat("[0, 0],", 200000))
                         .append("[0, 0]]"); // no g++ 12 -Wrestrict false positive
  const Error e = refused(cloth(R"({"resolution": [10, 10], "pins": )" + pins + "}"),
                          {"cloth.pins holds 200001 entries", "100 particles"});
  CHECK(e.code == ErrorCode::invalid_argument);
}

TEST_CASE("hostile: a huge chain array is bounded by the text limit and checked entry by entry") {
  // 1 million masses is accepted in principle (the limit is max_particles); one bad entry is named.
  std::string masses = std::string("[").append(repeat("1,", 999999)).append("-1]");
  refused(chain(R"({"masses": )" + masses + R"(, "stiffness": 20, "rest_lengths": 0.1})"),
          {"chain.masses[999999]", "-1"});
  refused(chain(R"({"masses": [1, 1], "stiffness": [1, 2, 3]})"), {"chain.stiffness", "got 3"});
  refused(chain(R"({"masses": []})"), {"chain.masses"});
}

TEST_CASE("hostile: zero, negative, NaN and infinite values name the key") {
  refused(R"({"system": "chain", "integrator": {"dt": 0}})", {"integrator.dt", "0"});
  refused(R"({"system": "chain", "integrator": {"dt": -0.01}})", {"integrator.dt", "-0.01"});
  refused(R"({"system": "chain", "integrator": {"dt": 1e999}})", {"integrator.dt"});
  refused(R"({"system": "chain", "integrator": {"dt": NaN}})", {"invalid JSON"});
  refused(R"({"system": "chain", "integrator": {"steps": -5}})", {"integrator.steps", "-5"});
  refused(R"({"system": "chain", "colliders": [{"type": "sphere", "center": [0,0,0], "radius": 0}]})",
          {"colliders[0].radius", "0"});
  refused(R"({"system": "chain", "colliders": [{"type": "sphere", "center": [0,0,0], "radius": -1}]})",
          {"colliders[0].radius", "-1"});
  refused(chain(R"({"masses": [0]})"), {"chain.masses[0]", "0"});
  refused(cloth(R"({"particle_mass": -0.1})"), {"cloth.particle_mass", "-0.1"});
  refused(cloth(R"({"size": [0, 1]})"), {"cloth.size"});
  refused(R"({"system": "chain", "physics": {"damping": -1}})", {"physics.damping", "-1"});
  refused(R"({"system": "chain", "divergence_limit": 0})", {"divergence_limit", "0"});
  refused(R"({"system": "chain"})", {"integrator.dt"}, {"integrator.dt=-1e-300"});
}

TEST_CASE("hostile: invalid UTF-8 and control bytes give a readable error") {
  refused("{\"system\": \"ch\xff\xfe\"}", {"invalid JSON"});
  // Trailing NUL bytes end the input for the JSON reader (a C string's terminator): accepted.
  CHECK(parse_scene(std::string("{\"system\": \"chain\"}\0\0", 21), "nul.json").ok());
  // A plain-string override keeps the raw bytes; the message must still be printable.
  const Error e = refused(R"({"system": "chain"})", {"system must be"}, {"system=\xff\xfe"});
  CHECK(e.code == ErrorCode::parse);
}

TEST_CASE("hostile: wrong top-level shapes and missing keys") {
  refused("null", {"JSON object"});
  refused("42", {"JSON object"});
  refused("\"chain\"", {"JSON object"});
  refused("{}", {"missing required key system"});
  refused(R"({"system": 1})", {"system", "a string"});
  refused(R"({"system": "chain", "bogus": 1})", {"unknown key bogus"});
  refused(R"({"system": "chain", "colliders": [{"type": "sphere"}]})", {"colliders[0].center is required"});
}

TEST_CASE("hostile: CpuSolver::set_particle with an out-of-range index or non-finite values is an error") {
  auto scene = parse_scene(R"({"system": "chain"})", "s.json");
  REQUIRE(scene.ok());
  auto solver = CpuSolver<float>::create(scene->system, scene->params);
  REQUIRE(solver.ok());
  const auto before = std::vector<glm::vec3>(solver->positions().begin(), solver->positions().end());
  auto r = solver->set_particle(2, glm::vec3(0), glm::vec3(0));
  REQUIRE(!r.ok());
  CHECK(r.error().code == ErrorCode::invalid_argument);
  CHECK(r.error().message.find("index 2") != std::string::npos);
  CHECK(r.error().message.find("2 particles") != std::string::npos);
  auto r2 = solver->set_particle(1, glm::vec3(NAN, 0, 0), glm::vec3(0));
  REQUIRE(!r2.ok());
  CHECK(r2.error().message.find("finite") != std::string::npos);
  auto r3 = solver->set_particle(1, glm::vec3(0), glm::vec3(0, INFINITY, 0));
  CHECK(!r3.ok());
  for (std::size_t k = 0; k < before.size(); ++k)
    CHECK(solver->positions()[k] == before[k]);
  CHECK(solver->set_particle(1, glm::vec3(0, 0, -0.5f), glm::vec3(0)).ok());
  CHECK(solver->positions()[1].z == -0.5f);
}
