// SPDX-License-Identifier: MIT
// `vkcloth run`'s largest structural strain (the summary line and --json's max_structural_strain),
// checked against structural_strain() on the positions the run writes.
#include <doctest/doctest.h>

#include "cli_util.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vkcloth/measure.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth::test;

namespace {

vkcloth::Scene hanging() {
  auto s = vkcloth::load_scene_file(std::string(VKCLOTH_SCENES_DIR) + "/cloth_hanging.json");
  REQUIRE(s.ok());
  return std::move(s.value());
}

/// Positions from a CSV whose rows are `particle,x,y,z` from column `first` (a grid: particle = index).
double strain_of_rows(const vkcloth::ParticleSystem& system,
                      const std::vector<std::vector<std::string>>& rows, std::size_t begin,
                      std::size_t first) {
  std::vector<glm::dvec3> p(system.size());
  for (std::size_t r = begin; r < begin + system.size(); ++r) {
    REQUIRE(rows[r].size() >= first + 4);
    p.at(std::stoul(rows[r][first])) = {std::stod(rows[r][first + 1]), std::stod(rows[r][first + 2]),
                                        std::stod(rows[r][first + 3])};
  }
  const auto s = vkcloth::structural_strain(system, std::span<const glm::dvec3>(p));
  REQUIRE(s.ok());
  return s->max;
}

nlohmann::json read_json(const fs::path& p) {
  const std::string text = slurp(p);
  REQUIRE_MESSAGE(nlohmann::json::accept(text), text);
  return nlohmann::json::parse(text);
}

} // namespace

TEST_CASE("cli: run prints the largest structural strain at the end and over every step of the run") {
  const vkcloth::Scene scene = hanging();
  const fs::path pos = tmp_dir() / "strain_positions.csv", trace = tmp_dir() / "strain_trace.csv",
                 json = tmp_dir() / "strain.json";
  const Outcome o =
      run_cli("strain", "run " + sample("cloth_hanging.json") + " --steps 40 --positions '" + pos.string() +
                            "' --trace '" + trace.string() + "' --json '" + json.string() + "'");
  REQUIRE(o.code == 0);
  const nlohmann::json doc = read_json(json);
  CHECK(doc["schema"] == "vkcloth-run/1");
  CHECK(doc["scene"] == "cloth_hanging");
  CHECK(doc["particles"] == 100);
  CHECK(doc["springs"] == scene.system.springs.size());
  CHECK(doc["steps"] == 40);
  CHECK(doc["dt"] == 0.02);
  CHECK(doc["integrator"] == "semi_implicit_euler");
  CHECK(doc["backend"] == "cpu");
  CHECK(doc["precision"] == "float");
  CHECK(std::abs(doc["simulated_time"].get<double>() - 0.8) < 1e-12);
  CHECK(doc["max_displacement"].get<double>() > 0.1); // 0.8 s of falling and swinging
  CHECK(doc["implicit_euler"].is_null());

  const nlohmann::json& st = doc["max_structural_strain"];
  REQUIRE(st.is_object());
  CHECK(st["structural_springs"] == 2 * 9 * 10);
  CHECK(st["every"] == 1);
  const double end = st["end"].get<double>(), run = st["run"].get<double>();
  const auto end_spring = st["end_spring"].get<std::uint32_t>(),
             run_spring = st["run_spring"].get<std::uint32_t>();
  const auto run_step = st["run_step"].get<std::uint64_t>();
  // The cloth hangs from two corners under gravity. At the report's K_struct = 40 the spring under
  // a pinned corner carries about half the 5 kg cloth: ~25 N / 40 N/m = 0.6 m on L0 = 1/9 m, a
  // strain of several (3.83 at step 40, measured; the report's super-elasticity).
  CHECK(end > 1.0);
  CHECK(end < 10.0);
  const vkcloth::Spring& corner = scene.system.springs[st["end_spring"].get<std::uint32_t>()];
  CHECK((corner.b == 99 || corner.b == 90)); // ends at a pinned top corner (9, 9) or (0, 9)
  CHECK(run >= end);
  CHECK(run_step <= 40);
  REQUIRE(end_spring < scene.system.springs.size());
  REQUIRE(run_spring < scene.system.springs.size());
  CHECK(scene.system.springs[end_spring].kind == vkcloth::SpringKind::structural);
  CHECK(st["end_particles"] ==
        nlohmann::json::array({scene.system.springs[end_spring].a, scene.system.springs[end_spring].b}));
  CHECK(st["run_particles"] ==
        nlohmann::json::array({scene.system.springs[run_spring].a, scene.system.springs[run_spring].b}));

  // The end strain is structural_strain() of the final positions (written with 9 digits).
  const auto final_rows = read_csv(pos);
  REQUIRE(final_rows.size() == 1 + 100);
  CHECK(std::abs(strain_of_rows(scene.system, final_rows, 1, 0) - end) < 1e-6);

  // Over the run is the largest over every step 0..40 of the trace, at the step it names.
  const auto rows = read_csv(trace);
  REQUIRE(rows.size() == 1 + 41 * 100);
  double trace_max = -1.0;
  for (std::size_t step = 0; step <= 40; ++step) {
    const double s = strain_of_rows(scene.system, rows, 1 + step * 100, 2);
    trace_max = std::max(trace_max, s);
    if (step == run_step)
      CHECK(std::abs(s - run) < 1e-6);
  }
  CHECK(std::abs(trace_max - run) < 1e-6);

  // The summary line says the same, in the JSON's numbers.
  const std::string line = fmt::format("largest structural strain: {:.6g} at the end (spring {}: particles "
                                       "{}-{}), {:.6g} over the run (step {})\n",
                                       end, end_spring, scene.system.springs[end_spring].a,
                                       scene.system.springs[end_spring].b, run, run_step);
  CHECK_MESSAGE(o.out.find(line) != std::string::npos, o.out);

  // --strain-every 7: steps 0, 7, ..., 35 and 40 only, so at most the every-step value.
  const Outcome k7 = run_cli("strain7", "run " + sample("cloth_hanging.json") +
                                            " --steps 40 --strain-every 7 "
                                            "--json '" +
                                            json.string() + "'");
  REQUIRE(k7.code == 0);
  const nlohmann::json st7 = read_json(json)["max_structural_strain"];
  CHECK(st7["every"] == 7);
  CHECK(std::abs(st7["end"].get<double>() - end) < 1e-12); // the same run, the same end state
  CHECK(st7["run"].get<double>() <= run);
  CHECK(st7["run"].get<double>() >= end);
  const auto step7 = st7["run_step"].get<std::uint64_t>();
  CHECK((step7 % 7 == 0 || step7 == 40));
  CHECK(k7.out.find(", sampled every 7 steps)") != std::string::npos);
  CHECK(run_cli("strain0", "run " + sample("cloth_hanging.json") + " --strain-every 0").code == 2);
}

TEST_CASE("cli: a chain has no structural strain: no line, and null in the JSON") {
  const fs::path json = tmp_dir() / "strain_chain.json";
  const Outcome o = run_cli("strain_chain", "run " + sample("double_spring.json") + " --steps 10 --json '" +
                                                json.string() + "'");
  REQUIRE(o.code == 0);
  CHECK(o.out.find("structural strain") == std::string::npos);
  const nlohmann::json doc = read_json(json);
  CHECK(doc["max_structural_strain"].is_null());
  CHECK(doc["steps"] == 10);
}

TEST_CASE(
    "cli: run --backend vulkan reports the CPU's structural strain (within the 1e-5 m position agreement)") {
  if (!have_vulkan_device())
    return;
  const fs::path cpu = tmp_dir() / "strain_cpu.json", gpu = tmp_dir() / "strain_vk.json";
  const std::string args = "run " + sample("cloth_hanging.json") + " --steps 60 --json ";
  REQUIRE(run_cli("strain_cpu", args + quote(cpu.string())).code == 0);
  const Outcome o = run_cli("strain_vk", args + quote(gpu.string()) + " --backend vulkan", validate);
  REQUIRE(o.code == 0);
  CHECK(o.out.find("largest structural strain: ") != std::string::npos);
  const nlohmann::json c = read_json(cpu)["max_structural_strain"],
                       g = read_json(gpu)["max_structural_strain"];
  // Positions agree to ~1e-5 m (vkcloth compare); L0 = 1/9 m.
  CHECK(std::abs(c["end"].get<double>() - g["end"].get<double>()) < 1e-3);
  CHECK(std::abs(c["run"].get<double>() - g["run"].get<double>()) < 1e-3);
  CHECK(g["run"].get<double>() >= g["end"].get<double>());
}
