// SPDX-License-Identifier: MIT
// `vkcloth run --check-intersections`: the count of intersecting triangle pairs at the final state,
// as a summary line and as --json's "intersections", for a grid, a mesh and a chain; and
// --check-intersections-every N, the most pairs over the run.
#include <doctest/doctest.h>

#include "cli_util.hpp"

#include <string>

#include <fmt/format.h>

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

TEST_CASE("cli: run --check-intersections-every N gives the most pairs over the run and its step") {
  // The twist without self-collision: its two edges turn against each other and the cloth passes
  // through itself by t = 1.5 s (450 steps). The most pairs, sampled at step 0, every 10th and the
  // last step, must be what a run that stops at that step counts at its end.
  const fs::path json = tmp_dir() / "intersections_every.json";
  const Outcome o = run_cli("intersections_every", "run " + sample("twist.json") +
                                                       " --steps 450 --set self_collision.enabled=false "
                                                       "--check-intersections-every 10 --json '" +
                                                       json.string() + "'");
  REQUIRE(o.code == 0);
  const auto doc = nlohmann::json::parse(slurp(json));
  const auto& x = doc["intersections"];
  CHECK(x["every"] == 10);
  CHECK(x["run_samples"] == 46); // steps 0, 10, ..., 450
  const auto most = x["run_max_pairs"].get<std::size_t>();
  const auto step = x["run_max_step"].get<std::uint64_t>();
  CHECK(most > 100);
  CHECK(most >= x["pairs"].get<std::size_t>());
  CHECK(step % 10 == 0);
  CHECK(o.out.find(
            fmt::format("intersections over the run: at most {} pairs (step {}), sampled every 10 steps\n",
                        most, step)) != std::string::npos);
  const Outcome at =
      run_cli("intersections_every_at", "run " + sample("twist.json") + fmt::format(" --steps {}", step) +
                                            " --set self_collision.enabled=false --check-intersections");
  REQUIRE(at.code == 0);
  CHECK(at.out.find(fmt::format("intersections: {} pairs of triangles intersect", most)) !=
        std::string::npos);

  // A hanging cloth: 0 pairs at each of steps 0, 7, 14 and 20 (the last).
  const fs::path flat = tmp_dir() / "intersections_every_flat.json";
  const Outcome f = run_cli("intersections_every_flat",
                            "run " + sample("cloth_hanging.json") +
                                " --steps 20 --check-intersections-every 7 --json '" + flat.string() + "'");
  REQUIRE(f.code == 0);
  CHECK(f.out.find("intersections over the run: at most 0 pairs (step 0), sampled every 7 steps\n") !=
        std::string::npos);
  CHECK(nlohmann::json::parse(slurp(flat))["intersections"]["run_samples"] == 4);
  CHECK(run_cli("intersections_every_zero",
                "run " + sample("cloth_hanging.json") + " --steps 2 --check-intersections-every 0")
            .code == 2);
}
