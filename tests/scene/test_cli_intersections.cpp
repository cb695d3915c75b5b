// SPDX-License-Identifier: MIT
// `vkcloth run --check-intersections` (issue 16): the count of intersecting triangle pairs at the
// final state, as a summary line and as --json's "intersections", for a grid, a mesh and a chain.
#include <doctest/doctest.h>

#include "cli_util.hpp"

#include <string>

#include <nlohmann/json.hpp>

using namespace vkcloth::test;

TEST_CASE("cli: run --check-intersections counts the intersecting triangle pairs (grid, mesh, chain)") {
  // A 10 x 10 grid hanging for 20 steps: 2 x 9 x 9 triangles, none intersecting.
  const fs::path json = tmp_dir() / "intersections.json";
  const Outcome o =
      run_cli("intersections", "run " + sample("cloth_hanging.json") +
                                   " --steps 20 --check-intersections --json '" + json.string() + "'");
  REQUIRE(o.code == 0);
  CHECK(o.out.find("intersections: 0 pairs of triangles intersect (of 162 triangles)\n") !=
        std::string::npos);
  const std::string text = slurp(json);
  REQUIRE(nlohmann::json::accept(text));
  const auto doc = nlohmann::json::parse(text);
  REQUIRE(doc.contains("intersections"));
  CHECK(doc["intersections"] == nlohmann::json{{"pairs", 0}, {"triangles", 162}});

  // A mesh cloth (an OBJ flag with a hole) after a few steps: none either.
  const Outcome m = run_cli("intersections_mesh",
                            "run " + sample("flag_with_hole.json") + " --steps 10 --check-intersections");
  REQUIRE(m.code == 0);
  CHECK(m.out.find("intersections: 0 pairs of triangles intersect (of ") != std::string::npos);

  // A chain has no triangles.
  const fs::path chain_json = tmp_dir() / "intersections_chain.json";
  const Outcome c = run_cli("intersections_chain", "run " + sample("double_spring.json") +
                                                       " --steps 5 --check-intersections --json '" +
                                                       chain_json.string() + "'");
  REQUIRE(c.code == 0);
  CHECK(c.out.find("intersections: no triangles (a chain), 0 pairs\n") != std::string::npos);
  CHECK(nlohmann::json::parse(slurp(chain_json))["intersections"] ==
        nlohmann::json{{"pairs", 0}, {"triangles", 0}});

  // Without the flag: no line and no key (the other outputs are unchanged).
  const fs::path plain = tmp_dir() / "intersections_plain.json";
  const Outcome p = run_cli("intersections_plain", "run " + sample("cloth_hanging.json") +
                                                       " --steps 3 --json '" + plain.string() + "'");
  REQUIRE(p.code == 0);
  CHECK(p.out.find("intersections:") == std::string::npos);
  CHECK_FALSE(nlohmann::json::parse(slurp(plain)).contains("intersections"));
}
