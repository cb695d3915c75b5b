// `vkcloth figures`: the gallery exists and its numbers show the report's physics.
#include <doctest/doctest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "stability_map_check.hpp"

using namespace vkcloth::test;

namespace {

void check_spring_physics(const nlohmann::json& m) {
  const auto& k = m["spring"]["stiffness"];
  // The sag mg/K: reached for K = 20 and 1000; larger for softer springs.
  CHECK(std::abs(k["20"]["final_z"].get<double>() - k["20"]["rest_z"].get<double>()) < 1e-3);
  CHECK(std::abs(k["1000"]["final_z"].get<double>() - k["1000"]["rest_z"].get<double>()) < 1e-3);
  CHECK(k["5"]["final_z"].get<double>() < k["20"]["final_z"].get<double>() - 1.0);
  const auto& mu = m["spring"]["damping"];
  CHECK(mu["0"]["late_amplitude"].get<double>() > 0.3);     // never settles
  CHECK(mu["0.5"]["late_amplitude"].get<double>() < 0.01);  // settles
  CHECK(mu["100"]["velocity_sign_flips_last_20_steps"].get<int>() == 20); // the integrator's oscillation
  const auto& dt = m["spring"]["timestep"];
  CHECK_FALSE(dt["0.02"]["diverged"].get<bool>());
  CHECK_FALSE(dt["0.2"]["diverged"].get<bool>());
  CHECK(dt["0.45"]["diverged"].get<bool>());
  const auto& integ = m["spring"]["integrators"];
  CHECK(integ["rk4"]["max_error"].get<double>() < 1e-5);
  CHECK(integ["semi_implicit_euler"]["max_error"].get<double>() < integ["explicit_euler"]["max_error"].get<double>());
  const double e0 = integ["rk4"]["energy_start"].get<double>();
  CHECK(integ["explicit_euler"]["energy_end"].get<double>() > e0 + 100.0);                 // gains energy
  CHECK(std::abs(integ["semi_implicit_euler"]["energy_end"].get<double>() - e0) < 0.05);  // bounded
  CHECK(std::abs(integ["rk4"]["energy_end"].get<double>() - e0) < 1e-3);
  const auto& start = m["spring"]["stiff_start"];
  CHECK(start["1"]["late_amplitude"].get<double>() > 10.0 * start["0.4"]["late_amplitude"].get<double>());
  CHECK(m["spring"]["double_spring"]["energy_end"].get<double>() < m["spring"]["double_spring"]["energy_start"].get<double>());
}

void check_gallery(const fs::path& dir) {
  const std::string html = slurp(dir / "index.html");
  REQUIRE_FALSE(html.empty());
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".svg" && ext != ".png") continue;
    CAPTURE(entry.path().filename().string());
    CHECK(html.find(entry.path().filename().string()) != std::string::npos); // every picture is shown
    CHECK(fs::file_size(entry.path()) > 500);
  }
}

} // namespace

TEST_CASE("vkcloth figures (cpu): the gallery and the physics behind it") {
  const fs::path out = tmp_dir() / "figures_cpu";
  fs::remove_all(out);
  const Outcome o = run_cli("figures_cpu", "figures --out " + quote(out.string()));
  REQUIRE_MESSAGE(o.code == 0, o.err);
  check_gallery(out);
  check_spring_physics(nlohmann::json::parse(slurp(out / "figures.json")));
  check_stability_map(nlohmann::json::parse(slurp(out / "figures.json")));
}

TEST_CASE("vkcloth figures --backend vulkan: the same physics on the GPU, zero validation messages") {
  if (!have_vulkan_device())
    return;
  const fs::path out = tmp_dir() / "figures_vulkan";
  fs::remove_all(out);
  const Outcome o = run_cli("figures_vulkan", "figures --backend vulkan --out " + quote(out.string()), validate);
  REQUIRE_MESSAGE(o.code == 0, o.err);
  CHECK(o.err.find("validation") == std::string::npos);
  check_gallery(out);
  check_spring_physics(nlohmann::json::parse(slurp(out / "figures.json")));
}
