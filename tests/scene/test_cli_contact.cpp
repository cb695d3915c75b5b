// SPDX-License-Identifier: MIT
// `vkcloth run`'s contact quality (the summary line and --json's "contact"): the deepest
// penetration over the run and the largest speed over its last second, checked against
// penetration() and the velocities of the trace the same run writes.
#include <doctest/doctest.h>

#include "cli_util.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "vkcloth/measure.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth::test;

TEST_CASE("cli: run reports the deepest penetration and the last second's largest speed (trace-checked)") {
  auto scene = vkcloth::load_scene_file(std::string(VKCLOTH_SCENES_DIR) + "/cloth_on_sphere.json");
  REQUIRE(scene.ok());
  const int steps = 80; // dt = 0.02: the last second is steps 31..80
  const fs::path trace = tmp_dir() / "contact_trace.csv", json = tmp_dir() / "contact.json";
  const Outcome o =
      run_cli("contact", "run " + sample("cloth_on_sphere.json") + " --steps " + std::to_string(steps) +
                             " --trace '" + trace.string() + "' --json '" + json.string() + "'");
  REQUIRE(o.code == 0);
  CHECK(o.out.find("contact: deepest penetration") != std::string::npos);
  const std::string text = slurp(json);
  REQUIRE(nlohmann::json::accept(text));
  const auto c = nlohmann::json::parse(text)["contact"];
  REQUIRE(c.is_object());
  CHECK(c["every"] == 1);
  CHECK(c["last_second_from_step"] == steps - 50);

  // The same measures from the trace: positions and velocities of every particle at every step.
  std::map<int, std::vector<glm::dvec3>> pos, vel;
  const auto rows = read_csv(trace);
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const int step = std::stoi(rows[r][0]);
    const auto p = std::stoul(rows[r][2]);
    auto& x = pos[step];
    auto& v = vel[step];
    x.resize(scene->system.size());
    v.resize(scene->system.size());
    x.at(p) = {std::stod(rows[r][3]), std::stod(rows[r][4]), std::stod(rows[r][5])};
    v.at(p) = {std::stod(rows[r][6]), std::stod(rows[r][7]), std::stod(rows[r][8])};
  }
  REQUIRE(pos.size() == steps + 1);
  double deepest = -1e9, calm = 0.0;
  for (int s = 1; s <= steps; ++s) {
    const auto d = vkcloth::penetration(scene->system, scene->params.colliders, pos[s]);
    REQUIRE(d.ok());
    deepest = std::max(deepest, d->depth);
    if (s > steps - 50)
      calm = std::max(calm, vkcloth::max_free_speed(scene->system, vel[s]));
  }
  // The trace prints 9 significant digits.
  CHECK(c["max_penetration"].get<double>() == doctest::Approx(deepest).epsilon(1e-6).scale(1e-6));
  CHECK(c["max_speed_last_second"].get<double>() == doctest::Approx(calm).epsilon(1e-6));
  CHECK(deepest <= scene->params.contact_epsilon);     // and the run kept the report's bound
  CHECK(deepest > -2 * scene->params.contact_epsilon); // the cloth did reach the sphere

  // A scene without colliders has no contact summary.
  const fs::path none = tmp_dir() / "contact_none.json";
  const Outcome h = run_cli("contact_none", "run " + sample("cloth_hanging.json") + " --steps 3 --json '" +
                                                none.string() + "'");
  REQUIRE(h.code == 0);
  CHECK(h.out.find("contact:") == std::string::npos);
  CHECK(nlohmann::json::parse(slurp(none))["contact"].is_null());
}

TEST_CASE("cli: run with colliders says when there is nothing to measure (no step, no free particle)") {
  // Before: "deepest penetration -inf m (particle 0, collider 0, step 18446744073709551615 ...)".
  const std::string scene = sample("cloth_on_sphere.json");
  const fs::path json = tmp_dir() / "contact_unmeasured.json";
  const Outcome none =
      run_cli("contact_no_step", "run " + scene + " --steps 0 --json '" + json.string() + "'");
  REQUIRE(none.code == 0);
  CHECK(none.out.find("contact: nothing to measure (no step ran)") != std::string::npos);
  CHECK(none.out.find("inf") == std::string::npos);
  const auto c = nlohmann::json::parse(slurp(json))["contact"];
  REQUIRE(c.is_object()); // the same keys, null where nothing was measured
  for (const char* key :
       {"max_penetration", "penetration_particle", "penetration_collider", "penetration_step"})
    CHECK_MESSAGE(c[key].is_null(), key);
  CHECK(c["contact_epsilon"].is_number());
  // Every particle attached to the sphere: none free to measure.
  const Outcome held = run_cli(
      "contact_all_held",
      "run " + scene +
          R"( --steps 3 --set 'cloth.attach=[{"collider":0,"region":{"min":[-9,-9,-9],"max":[9,9,9]}}]')");
  REQUIRE_MESSAGE(held.code == 0, held.err);
  CHECK(held.out.find("contact: nothing to measure (no free particle)") != std::string::npos);
}
