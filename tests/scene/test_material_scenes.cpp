// SPDX-License-Identifier: MIT
// cloth.material in scene files (docs/scene-format.md "Materials"): a preset by name, the object
// form, the --set override, and every bad material input with the key in the message.
#include <doctest/doctest.h>

#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "cli_util.hpp"
#include "vkcloth/material.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth;
using vkcloth::test::run_cli;
using vkcloth::test::sample;
using vkcloth::test::write_scene;

namespace {

std::string cloth(const std::string& body, const std::string& extra = "") {
  return R"({"system": "cloth", )" + extra + R"("cloth": )" + body + "}";
}

Scene parse(const std::string& text, std::vector<std::string> overrides = {}) {
  auto s = parse_scene(text, "mat.json", overrides);
  if (!s.ok())
    FAIL(s.error().message);
  return std::move(*s);
}

double total_mass(const Scene& s) {
  double m = 0.0;
  for (const Particle& p : s.system.particles)
    m += p.mass;
  return m;
}

std::string error_of(const std::string& text, std::vector<std::string> overrides = {}) {
  auto s = parse_scene(text, "mat.json", overrides);
  REQUIRE_MESSAGE(!s.ok(), "expected an error for: " << text);
  return s.error().message;
}

void expect_error(const std::string& text, std::initializer_list<std::string> needles) {
  const std::string msg = error_of(text);
  for (const std::string& n : needles)
    CHECK_MESSAGE(msg.find(n) != std::string::npos, "'" << n << "' not in: " << msg);
}

} // namespace

TEST_CASE("cloth.material by preset name: lumped masses sum to density x area, mu = the material's damping") {
  const Scene s = parse(cloth(R"({"resolution": [16, 12], "size": [1.5, 1], "material": "denim"})"));
  CHECK(total_mass(s) == doctest::Approx(0.4 * 1.5).epsilon(1e-12));
  CHECK(s.params.damping == 0.5);
  // An interior structural spring along i (dx = 0.1, dy = 1/11) is the library's conversion.
  const auto k = spring_stiffness(*material_preset("denim"), SpringKind::structural, 0.1, 1.0 / 11);
  REQUIRE(k.ok());
  CHECK(s.system.springs[15 * 5 + 3].stiffness == doctest::Approx(*k).epsilon(1e-12));
}

TEST_CASE("cloth.material as an object: every value used (density, damping)") {
  const Scene s = parse(cloth(
      R"({"resolution": [8, 8], "material": {"density": 0.3, "stretch": 800, "shear": 60, "bend": 2e-5, "damping": 0.8}})"));
  CHECK(total_mass(s) == doctest::Approx(0.3).epsilon(1e-12));
  CHECK(s.params.damping == 0.8);
  const double h = 1.0 / 7;
  CHECK(s.system.springs.back().stiffness ==
        doctest::Approx(0.5 * 8 * 2e-5 / (400 * h * h * h * h)).epsilon(1e-12));
}

TEST_CASE("--set cloth.material=denim replaces the material (a bare word is a preset name)") {
  const std::string text = cloth(R"({"resolution": [10, 10], "material": "cotton"})");
  CHECK(total_mass(parse(text)) == doctest::Approx(0.15).epsilon(1e-12));
  CHECK(total_mass(parse(text, {"cloth.material=denim"})) == doctest::Approx(0.4).epsilon(1e-12));
  CHECK(total_mass(parse(text, {"cloth.material=\"silk\""})) == doctest::Approx(0.05).epsilon(1e-12));
  CHECK(total_mass(parse(cloth("{}"), {"cloth.material=rubber"})) == doctest::Approx(1.1).epsilon(1e-12));
}

TEST_CASE("vkcloth run --set cloth.material=denim runs the material sample, an unknown preset exits 2 "
          "listing them") {
  const auto ok = run_cli("material_denim",
                          "run " + sample("cloth_material.json") + " --steps 20 --set cloth.material=denim");
  CHECK_MESSAGE(ok.code == 0, ok.err);
  const auto bad =
      run_cli("material_wool", "run " + sample("cloth_material.json") + " --set cloth.material=wool");
  CHECK(bad.code == 2);
  CHECK_MESSAGE(
      bad.err.find("cloth.material: unknown preset \"wool\" (presets: cotton, silk, denim, leather, "
                   "rubber, report)") != std::string::npos,
      bad.err);
}

TEST_CASE("cloth.material: bad input names the key and the value") {
  expect_error(cloth(R"({"material": "wool"})"), {"cloth.material: unknown preset \"wool\"",
                                                  "presets: cotton, silk, denim, leather, rubber, report"});
  expect_error(cloth(R"({"material": {"density": 0.1, "stretch": 500, "shear": 50, "damping": 0.5}})"),
               {"cloth.material.bend is required"});
  expect_error(
      cloth(R"({"material": {"density": 0.1, "stretch": 500, "shear": -5, "bend": 1e-5, "damping": 0.5}})"),
      {"cloth.material.shear must be finite and > 0, got -5"});
  expect_error(
      cloth(R"({"material": {"density": 0, "stretch": 500, "shear": 5, "bend": 1e-5, "damping": 0.5}})"),
      {"cloth.material.density must be finite and > 0, got 0"});
  expect_error(
      cloth(R"({"material": {"density": 0.1, "stretch": 500, "shear": 5, "bend": 1e-5, "damping": 0}})"),
      {"cloth.material.damping must be finite and > 0, got 0"});
  expect_error(
      cloth(R"({"material": {"density": 0.1, "stretch": "stiff", "shear": 5, "bend": 1e-5, "damping": 1}})"),
      {"cloth.material.stretch must be a number", "\"stiff\""});
  expect_error(
      cloth(R"({"material": {"density": 0.1, "stretch": 5, "shear": 5, "bend": 1, "damping": 1, "wet": 1}})"),
      {"unknown key cloth.material.wet"});
  expect_error(cloth(R"({"material": 3})"), {"cloth.material must be a preset name", "got 3"});
  expect_error(cloth(R"({"material": "cotton", "particle_mass": 0.05})"),
               {"cloth.material and cloth.particle_mass exclude each other"});
  expect_error(cloth(R"({"material": "cotton", "stiffness": {"bend": 1}})"),
               {"cloth.material and cloth.stiffness exclude each other"});
  expect_error(cloth(R"({"material": "cotton"})", R"("physics": {"damping": 0.5}, )"),
               {"physics.damping and cloth.material exclude each other", "0.5 1/s"});
  expect_error(cloth(R"({"mesh": "x.obj", "material": "cotton", "density": 0.2})"),
               {"cloth.material and cloth.density exclude each other"});
  expect_error(cloth(R"({"resolution": [64, 64], "material": "report"})"),
               {"cloth.material: at spacing 0.01587 m", "use a spacing of at least"});
  expect_error(cloth(R"({"resolution": [1, 5], "material": "cotton"})"), {"at least 2 x 2", "[1, 5]"});
}

TEST_CASE("a scene file with cloth.material and its CLI error: exit 2, the file and the key named") {
  const std::string path = write_scene("material_missing.json", cloth(R"({"material": {"density": 0.1}})"));
  const auto o = run_cli("material_missing", "run " + path);
  CHECK(o.code == 2);
  CHECK_MESSAGE(o.err.find("material_missing.json: cloth.material.stretch is required") != std::string::npos,
                o.err);
}

TEST_CASE("cloth.material on a mesh scene: masses from its density, the file's edge lengths as spacings") {
  const auto obj = vkcloth::test::tmp_dir() / "material_strip.obj";
  std::ofstream(obj)
      << "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nv 0.3 0 0\nv 0 0 0.1\nv 0.1 0 0.1\nv 0.2 0 0.1\nv 0.3 0 "
         "0.1\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n";
  auto s = parse_scene(R"({"system": "cloth", "cloth": {"mesh": "material_strip.obj", "material": "silk"}})",
                       (vkcloth::test::tmp_dir() / "material_mesh.json").string());
  if (!s.ok())
    FAIL(s.error().message);
  CHECK(total_mass(*s) == doctest::Approx(0.05 * 0.03).epsilon(1e-12));
  CHECK(s->params.damping == 0.5);
  // Every structural spring is a side of 0.1 m: the inner ones (shared by two quads) the full
  // K_s = C - G - 4 K_b, the border ones half.
  const Material silk = *material_preset("silk");
  const double ks = *spring_stiffness(silk, SpringKind::structural, 0.1, 0.1);
  int inner = 0, border = 0;
  for (const Spring& sp : s->system.springs)
    if (sp.kind == SpringKind::structural) {
      if (sp.stiffness == doctest::Approx(ks).epsilon(1e-12))
        ++inner;
      else if (sp.stiffness == doctest::Approx(ks / 2).epsilon(1e-12))
        ++border;
    }
  CHECK(inner == 2);
  CHECK(border == 8);
}
