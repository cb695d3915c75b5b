// SPDX-License-Identifier: MIT
// The vkcloth command line, run as a separate process: exit codes, messages, CSV outputs.
#include <doctest/doctest.h>

#include "cli_util.hpp"

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/scene.hpp"

using namespace vkcloth::test;

TEST_CASE("cli: bad scene files exit 2 and stderr names the key") {
  struct Bad {
    const char* name;
    const char* text;
    const char* needle;
  };
  const Bad cases[] = {
      {"typo.json", R"({"system": "cloth", "cloth": {"stifness": {"bend": 1}}})", "cloth.stifness"},
      {"type.json", R"({"system": "chain", "integrator": {"dt": "fast"}})", "integrator.dt"},
      {"range.json", R"({"system": "chain", "physics": {"damping": -1}})", "physics.damping"},
      {"grid.json", R"({"system": "cloth", "cloth": {"resolution": [100000, 100000]}})", "cloth.resolution"},
      {"inf.json", R"({"system": "chain", "integrator": {"dt": 1e999}})", "integrator.dt"},
      {"nosystem.json", R"({"integrator": {"dt": 0.02}})", "system"},
      {"syntax.json", "{\"system\": \"chain\",\n}", "syntax.json:2:"},
  };
  for (const Bad& b : cases) {
    CAPTURE(b.name);
    const Outcome o = run_cli(std::string("bad_") + b.name, "run " + write_scene(b.name, b.text));
    CHECK(o.code == 2);
    CHECK_MESSAGE(o.err.find(b.needle) != std::string::npos, o.err);
    CHECK(o.out.empty());
  }
  const Outcome missing = run_cli("missing", "run /nonexistent/scene.json");
  CHECK(missing.code == 2);
  CHECK(missing.err.find("/nonexistent/scene.json") != std::string::npos);
  const Outcome bad_set = run_cli("bad_set", "run " + sample("spring.json") + " --set integrator.dt.x=1");
  CHECK(bad_set.code == 2);
  CHECK(bad_set.err.find("integrator.dt.x") != std::string::npos);
}

TEST_CASE("cli: bad colliders exit 2 and stderr names the key, the file and the line") {
  const fs::path dir = tmp_dir() / "cli_colliders";
  fs::create_directories(dir);
  std::ofstream(dir / "broken.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n";
  struct Bad {
    const char* name;
    const char* colliders;
    std::vector<std::string> needles;
  };
  const Bad cases[] = {
      {"friction.json", R"({"type": "plane", "friction": -0.2})", {"colliders[0].friction", "-0.2"}},
      {"static.json",
       R"({"type": "plane", "friction": 0.5, "static_friction": 0.1})",
       {"colliders[0].static_friction", "0.1"}},
      {"box.json",
       R"({"type": "box", "center": [0, 0, 0], "half_extents": [1, 0, 1]})",
       {"colliders[0].half_extents", "[1, 0, 1]"}},
      {"capsule.json",
       R"({"type": "capsule", "a": [0, 0, 0], "b": [0, 0, 1], "radius": 0})",
       {"colliders[0].radius", "got 0"}},
      {"velocity.json",
       R"({"type": "plane", "linear_velocity": [0, 0, 1e999]})",
       {"colliders[0].linear_velocity[2]"}},
      {"thickness.json", R"({"type": "mesh", "path": "broken.obj"})", {"colliders[0].thickness is required"}},
      {"nomesh.json",
       R"({"type": "mesh", "path": "meshes/none.obj", "thickness": 0.01})",
       {"colliders[0].path", "meshes/none.obj", "no such mesh file"}},
      {"badmesh.json",
       R"({"type": "mesh", "path": "broken.obj", "thickness": 0.01})",
       {"colliders[0].path", "broken.obj:4: face index 9 is out of range"}},
  };
  for (const Bad& b : cases) {
    CAPTURE(b.name);
    std::ofstream(dir / b.name) << R"({"system": "cloth", "colliders": [)" << b.colliders << "]}";
    for (const char* command : {"run", "info"}) {
      CAPTURE(command);
      const Outcome o = run_cli(std::string("bad_collider_") + command + "_" + b.name,
                                std::string(command) + " " + quote((dir / b.name).string()));
      CHECK(o.code == 2);
      for (const std::string& n : b.needles)
        CHECK_MESSAGE(o.err.find(n) != std::string::npos, "'" << n << "' not in: " << o.err);
      CHECK(o.out.empty());
    }
  }
  // An override that makes a good scene bad.
  const Outcome set =
      run_cli("bad_collider_set", "run " + sample("cloth_on_sphere.json") + " --set colliders.0.friction=-1");
  CHECK(set.code == 2);
  CHECK(set.err.find("colliders[0].friction") != std::string::npos);
}

TEST_CASE("cli: bad self_collision exits 2 and stderr names the key and the value") {
  for (const char* command : {"run", "info"}) {
    CAPTURE(command);
    const Outcome o = run_cli(std::string("bad_self_collision_") + command,
                              std::string(command) + " " +
                                  write_scene("self_collision.json",
                                              R"({"system": "cloth", "self_collision": {"thickness": -1}})"));
    CHECK(o.code == 2);
    CHECK_MESSAGE(o.err.find("self_collision.thickness must be finite and > 0 (metres), got -1") !=
                      std::string::npos,
                  o.err);
    CHECK(o.out.empty());
  }
  // Through --set: more than 10 x the sample's 1/9 m spacing, and a word where a boolean goes.
  const Outcome thick = run_cli("bad_self_collision_set",
                                "run " + sample("cloth_hanging.json") + " --set self_collision.thickness=2");
  CHECK(thick.code == 2);
  CHECK_MESSAGE(thick.err.find("self_collision.thickness 2 m is more than 10 x") != std::string::npos,
                thick.err);
  const Outcome word = run_cli("bad_self_collision_word",
                               "info " + sample("cloth_hanging.json") + " --set self_collision.enabled=yes");
  CHECK(word.code == 2);
  CHECK_MESSAGE(word.err.find("self_collision.enabled must be true or false, got \"yes\"") !=
                    std::string::npos,
                word.err);
  // A thickness below half the spacing loads, with the warning on stderr.
  const Outcome thin = run_cli("self_collision_thin",
                               "info " + sample("cloth_hanging.json") + " --set self_collision.enabled=true");
  CHECK(thin.code == 0);
  CHECK_MESSAGE(thin.err.find("vkcloth: warning: self_collision.thickness 0.01 m is below half") !=
                    std::string::npos,
                thin.err);
}

TEST_CASE("cli: the single spring settles at the static sag L0 + mg/K below the anchor") {
  const fs::path pos = tmp_dir() / "spring_positions.csv";
  const Outcome o =
      run_cli("sag", "run " + sample("spring.json") + " --steps 3000 --positions '" + pos.string() + "'");
  REQUIRE(o.code == 0);
  CHECK(o.out.find("spring") != std::string::npos);
  CHECK(o.out.find("3000 steps") != std::string::npos);
  const auto rows = read_csv(pos);
  REQUIRE(rows.size() == 3);
  CHECK(rows[0] == std::vector<std::string>{"particle", "x", "y", "z"});
  REQUIRE(rows[2].size() == 4);
  CHECK(rows[2][0] == "1");
  CHECK(std::abs(std::stod(rows[2][3]) - (-0.4 - 0.4905)) < 1e-3);
}

TEST_CASE("cli: --trace writes step 0 and every K-th step for every particle") {
  const fs::path trace = tmp_dir() / "trace.csv";
  const Outcome o =
      run_cli("trace", "run " + sample("double_spring.json") + " --steps 10 --trace-every 3 --trace '" +
                           trace.string() + "' --precision double");
  REQUIRE(o.code == 0);
  const auto rows = read_csv(trace);
  // Steps 0, 3, 6, 9 for 3 particles (anchor included), plus the header.
  REQUIRE(rows.size() == 1 + 4 * 3);
  CHECK(rows[0] == std::vector<std::string>{"step", "time", "particle", "x", "y", "z", "vx", "vy", "vz"});
  CHECK(rows[1][0] == "0");
  CHECK(rows[1][2] == "0");
  CHECK(rows[2][3] == "0.3"); // particle 1 starts at x = 0.3
  CHECK(rows.back()[0] == "9");
  CHECK(std::stod(rows.back()[1]) == doctest::Approx(0.18));
  CHECK(rows.back()[2] == "2");
  for (const auto& r : rows)
    CHECK(r.size() == 9);

  const Outcome every =
      run_cli("trace1", "run " + sample("spring.json") + " --steps 4 --trace '" + trace.string() + "'");
  REQUIRE(every.code == 0);
  CHECK(read_csv(trace).size() == 1 + 5 * 2);
}

TEST_CASE("cli: a diverging run exits 3, names the step, and keeps the trace rows before it") {
  const fs::path trace = tmp_dir() / "diverge.csv";
  const Outcome o = run_cli("diverge", "run " + sample("spring.json") + " --dt 0.45 --steps 200 --trace '" +
                                           trace.string() + "'");
  CHECK(o.code == 3);
  CHECK(o.err.find("diverged") != std::string::npos);
  CHECK(o.err.find("step") != std::string::npos);
  const auto rows = read_csv(trace);
  CHECK(rows.size() > 3);           // some steps ran before the blow-up...
  CHECK(rows.size() < 1 + 201 * 2); // ...but not all of them
}

TEST_CASE("cli: usage errors exit 2, --help exits 0 and documents the exit codes") {
  CHECK(run_cli("nosuch", "run " + sample("spring.json") + " --backend nosuch").code == 2);
  CHECK(run_cli("noargs", "").code == 2);
  CHECK(run_cli("noscene", "run").code == 2);
  CHECK(run_cli("badflag", "run " + sample("spring.json") + " --bogus").code == 2);
  CHECK(run_cli("badsteps", "run " + sample("spring.json") + " --steps -3").code == 2);
  CHECK(run_cli("badprec", "run " + sample("spring.json") + " --precision half").code == 2);
  CHECK(run_cli("badinteg", "run " + sample("spring.json") + " --integrator leapfrog").code == 2);
  const Outcome help = run_cli("help", "--help");
  CHECK(help.code == 0);
  CHECK(help.out.find("Exit codes") != std::string::npos);
  CHECK(help.out.find("run") != std::string::npos);
  CHECK(help.out.find("info") != std::string::npos);
  const Outcome run_help = run_cli("run_help", "run --help");
  CHECK(run_help.code == 0);
  CHECK(run_help.out.find("--trace-every") != std::string::npos);
  CHECK(run_help.out.find("Exit codes") != std::string::npos);
}

TEST_CASE("cli: info prints the parsed scene") {
  const Outcome o =
      run_cli("info", "info " + sample("cloth_hanging.json") + " --set cloth.stiffness.shear=0");
  REQUIRE(o.code == 0);
  CHECK(o.out.find("100 (2 pinned") != std::string::npos);
  CHECK(o.out.find("structural") != std::string::npos);
  CHECK(o.out.find("shear") == std::string::npos); // switched off by the override
  CHECK(o.out.find("semi_implicit_euler") != std::string::npos);
}

TEST_CASE("cli: info prints each collider: shape, friction, velocities, a mesh's triangles and depth") {
  const fs::path dir = tmp_dir() / "cli_info_colliders";
  fs::create_directories(dir);
  std::ofstream(dir / "scene.json") << R"({"system": "cloth", "colliders": [
      {"type": "plane", "offset": -1, "friction": 0.4, "static_friction": 0.6, "linear_velocity": [0.5, 0, 0]},
      {"type": "sphere", "center": [0, 0, 0], "radius": 0.3},
      {"type": "capsule", "a": [0, 0, 0], "b": [1, 0, 0], "radius": 0.1, "angular_velocity": [0, 0, 2]},
      {"type": "box", "center": [0, 0, -1], "half_extents": [2, 1, 0.5], "rotation_deg": [10, -20, 30]},
      {"type": "mesh", "path": ")" << VKCLOTH_SCENES_DIR
                                    << R"(/../meshes/tablecloth.obj", "thickness": 0.005,
       "friction": 0.3, "transform": {"translate": [0, 0, 0.5], "rotate_deg": [0, 0, 90], "scale": 2}}]})";
  auto scene = vkcloth::load_scene_file(dir / "scene.json");
  REQUIRE_MESSAGE(scene.ok(), scene.error().message);
  const auto& mesh = *scene->params.colliders[4].mesh;
  const Outcome o = run_cli("info_colliders", "info " + quote((dir / "scene.json").string()));
  REQUIRE(o.code == 0);
  const std::string expected[] = {
      "colliders   5\n",
      "  [0] plane   normal [0, 0, 1], offset -1\n      friction 0.4 (static 0.6), linear_velocity [0.5, 0, "
      "0] m/s, "
      "angular_velocity [0, 0, 0] rad/s\n",
      "  [1] sphere  center [0, 0, 0], radius 0.3\n      friction 0 (static 0), at rest\n",
      "  [2] capsule a [0, 0, 0], b [1, 0, 0], radius 0.1\n      friction 0 (static 0), linear_velocity [0, "
      "0, 0] m/s, "
      "angular_velocity [0, 0, 2] rad/s\n",
      "  [3] box     center [0, 0, -1], half_extents [2, 1, 0.5], rotation_deg [10, -20, 30]\n",
      fmt::format(
          "  [4] mesh    {}/../meshes/tablecloth.obj: 384 triangles, hierarchy depth {}; origin [0, 0, 0.5], "
          "rotation_deg [0, 0, 90], thickness 0.005\n      friction 0.3 (static 0.3), at rest\n",
          VKCLOTH_SCENES_DIR, mesh.depth()),
  };
  for (const std::string& e : expected)
    CHECK_MESSAGE(o.out.find(e) != std::string::npos, "'" << e << "' not in: " << o.out);
  CHECK(mesh.depth() > 1);
}

// ---- The Vulkan backend through the CLI (lavapipe in CI, with the validation layer on) ----

TEST_CASE("vkcloth compare passes on every sample scene, with zero validation messages") {
  if (!have_vulkan_device())
    return;
  for (const auto& entry : fs::directory_iterator(VKCLOTH_SCENES_DIR)) {
    const std::string name = entry.path().filename().string();
    CAPTURE(name);
    const Outcome o = run_cli("compare_" + name, "compare " + sample(name) + " --steps 100", validate);
    CHECK(o.code == 0);
    CHECK(o.out.find("PASS: max position difference") != std::string::npos);
    CHECK(o.out.find("> tolerance") == std::string::npos);
    CHECK(o.err.find("validation") == std::string::npos);
  }
}

TEST_CASE("vkcloth run --backend vulkan writes the positions the CPU writes (within 1e-5)") {
  if (!have_vulkan_device())
    return;
  const fs::path cpu_csv = tmp_dir() / "wind_cpu.csv", gpu_csv = tmp_dir() / "wind_gpu.csv";
  const std::string scene = sample("cloth_wind.json") + " --steps 100 --integrator rk4";
  REQUIRE(run_cli("wind_cpu", "run " + scene + " --positions " + quote(cpu_csv.string())).code == 0);
  const Outcome g = run_cli(
      "wind_gpu", "run " + scene + " --backend vulkan --positions " + quote(gpu_csv.string()), validate);
  REQUIRE(g.code == 0);
  CHECK(g.err.find("validation") == std::string::npos);
  const auto a = read_csv(cpu_csv), b = read_csv(gpu_csv);
  REQUIRE(a.size() == 101); // header + 100 particles
  REQUIRE(b.size() == a.size());
  for (std::size_t r = 1; r < a.size(); ++r)
    for (std::size_t c = 1; c < 4; ++c)
      CHECK(std::abs(std::stod(a[r][c]) - std::stod(b[r][c])) <= 1e-5);
}

TEST_CASE("vkcloth on Vulkan: divergence exits 3, no device exits 4, bad compare flags exit 2") {
  if (!have_vulkan_device())
    return;
  const Outcome div =
      run_cli("gpu_div", "run " + sample("spring.json") + " --dt 0.45 --steps 200 --backend vulkan");
  CHECK(div.code == 3);
  CHECK(div.err.find("diverged") != std::string::npos);

  const Outcome none = run_cli("gpu_none", "run " + sample("spring.json") + " --backend vulkan",
                               "VKCLOTH_DEVICE=no-such-device");
  CHECK(none.code == 4);
  CHECK(none.err.find("no-such-device") != std::string::npos);
  CHECK(
      run_cli("gpu_noicd", "devices", "VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json")
          .code == 4);

  const Outcome tol = run_cli("cmp_tol", "compare " + sample("spring.json") + " --tolerance -1");
  CHECK(tol.code == 2);
  CHECK(tol.err.find("--tolerance") != std::string::npos);
  CHECK(run_cli("gpu_double", "run " + sample("spring.json") + " --backend vulkan --precision double").code ==
        2);
}

TEST_CASE("cli: hostile command-line values exit 2 and name the option or key") {
  const std::string spring = "run " + sample("spring.json");
  run_cli_refused("host_steps_huge", spring + " --steps 99999999999999999999999", "steps");
  run_cli_refused("host_steps_big", spring + " --steps 1000000000000", "integrator.steps");
  run_cli_refused("host_steps_neg", spring + " --steps -5",
                  "integrator.steps must be an integer in 0..1000000000, got -5");
  for (const char* dt : {"0", "-1", "nan", "inf", "1e999"}) {
    CAPTURE(dt);
    run_cli_refused("host_dt", spring + " --dt " + dt, "dt");
  }
  run_cli_refused("host_set", spring + " --set colliders.0.radius", "key.path=value");
  run_cli_refused("host_devzero", "run /dev/zero", "scene size limit");
  CHECK(run_cli("host_dir", "run /").code == 2);
  run_cli_refused("host_out", spring + " --steps 1 --positions /nonexistent/dir/p.csv",
                  "/nonexistent/dir/p.csv");
  // Counts and numbers name the bound and the value as typed (CLI11's wrote "Value 0 not in range
  // 0.000000 to 1797...").
  run_cli_refused("host_every", spring + " --strain-every 0",
                  "--strain-every: must be a whole number >= 1, got 0");
  run_cli_refused("host_bench_wind", "bench --wind -1", "--wind: must be a finite number >= 0, got -1");
  run_cli_refused("host_bench_integrator", "bench --integrator euler", "implicit_euler or vbd, got 'euler'");
  // Two outputs in one file (each overwrote the other's lines), however the path is spelt.
  const std::string same = (tmp_dir() / "same.csv").string();
  run_cli_refused("host_same_out",
                  spring + " --steps 1 --trace '" + same + "' --positions '" +
                      (tmp_dir() / "." / "same.csv").string() + "'",
                  "--trace and --positions name the same file");
}

TEST_CASE("cli: soak runs a short soak and reports drift and RSS") {
  const Outcome o = run_cli("soak", "soak " + sample("cloth_hanging.json") + " --steps 500 --checks 5");
  CHECK(o.code == 0);
  CHECK(o.out.find("max pinned drift 0 m") != std::string::npos);
  CHECK(o.out.find("RSS") != std::string::npos);
  CHECK(run_cli("soak_bad", "soak " + sample("spring.json") + " --steps 0").code == 2);
  const Outcome div =
      run_cli("soak_div", "soak " + sample("spring.json") + " --set integrator.dt=0.45 --steps 1000");
  CHECK(div.code == 3);
  // A run no longer than the warm-up is checked too (it reported max speed 0 m/s, checking nothing).
  const Outcome brief = run_cli("soak_brief", "soak " + sample("cloth_hanging.json") + " --steps 5");
  CHECK(brief.code == 0);
  CHECK(brief.out.find("max speed 0 m/s") == std::string::npos);
  CHECK(run_cli("soak_brief_div", "soak " + sample("spring.json") + " --set integrator.dt=1e30 --steps 3")
            .code == 3);
}

TEST_CASE("cli: --validate runs under the validation layer and passes on a clean run") {
  if (!have_vulkan_device())
    return;
  const Outcome o =
      run_cli("validate_run", "--validate run " + sample("cloth_wind.json") + " --steps 50 --backend vulkan");
  CHECK(o.code == 0);
  CHECK(o.err.find("validation") == std::string::npos);
  const Outcome c =
      run_cli("validate_cmp", "--validate compare " + sample("cloth_on_sphere.json") + " --steps 50");
  CHECK(c.code == 0);
  const Outcome s = run_cli("validate_soak", "--validate soak " + sample("cloth_hanging.json") +
                                                 " --steps 200 --backend vulkan --max-rss-growth 1000000");
  CHECK(s.code == 0);
  CHECK(s.out.find("max pinned drift 0 m") != std::string::npos);
  CHECK(run_cli("validate_help", "--help").out.find("--validate") != std::string::npos);
}
