// SPDX-License-Identifier: MIT
// `vkcloth run --export / --export-every / --obj-frames`: the exported frames are the states the
// --trace rows show at the same steps; bad flags, paths and chains exit 2 before simulating.
#include <doctest/doctest.h>

#include "cli_util.hpp"
#include "gltf_readback.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

using namespace vkcloth::test;

namespace {

struct TraceStep {
  double time = 0.0;
  std::vector<glm::dvec3> positions; ///< by the particle column
};

std::map<std::uint64_t, TraceStep> read_trace(const fs::path& path) {
  std::map<std::uint64_t, TraceStep> steps;
  const auto rows = read_csv(path);
  REQUIRE(rows.size() > 1);
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const auto& c = rows[r];
    REQUIRE(c.size() == 9);
    TraceStep& s = steps[std::stoull(c[0])];
    s.time = std::stod(c[1]);
    const std::size_t particle = std::stoul(c[2]);
    CHECK(particle == s.positions.size()); // rows in file order: 0, 1, 2, ...
    s.positions.emplace_back(std::stod(c[3]), std::stod(c[4]), std::stod(c[5]));
  }
  return steps;
}

/// Within 1e-6 m: the glTF holds floats, the trace 9 significant digits.
template <typename Vec> void check_close(const Vec& got, const glm::dvec3& want) {
  for (int c = 0; c < 3; ++c)
    CHECK(std::abs(double(got[c]) - want[c]) <= 1e-6);
}

} // namespace

TEST_CASE("cli: --export and --obj-frames hold the states the --trace rows show") {
  const fs::path dir = tmp_dir() / "export_run";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Outcome o =
      run_cli("export_run", "run " + sample("cloth_hanging.json") + " --steps 20 --trace " +
                                quote((dir / "t.csv").string()) + " --trace-every 5 --export " +
                                quote((dir / "out.glb").string()) + " --export-every 5 --obj-frames " +
                                quote((dir / "obj").string()));
  REQUIRE_MESSAGE(o.code == 0, o.err);
  CHECK(o.out.find("exported 5 frames") != std::string::npos);
  const auto trace = read_trace(dir / "t.csv");
  REQUIRE(trace.size() == 5); // steps 0, 5, 10, 15, 20

  const GltfAnimation g = read_gltf_animation(dir / "out.glb");
  REQUIRE(g.frames.size() == 5);
  for (std::size_t f = 0; f < 5; ++f) {
    CAPTURE(f);
    const TraceStep& row = trace.at(5 * f);
    CHECK(g.times[f] == doctest::Approx(row.time));
    REQUIRE(g.frames[f].size() == row.positions.size());
    for (std::size_t k = 0; k < row.positions.size(); ++k)
      check_close(g.frames[f][k], row.positions[k]);
    const ObjFrame obj = read_obj_frame(dir / "obj" / fmt::format("frame_{:05}.obj", f));
    REQUIRE(obj.positions.size() == row.positions.size());
    for (std::size_t k = 0; k < row.positions.size(); ++k)
      check_close(obj.positions[k], row.positions[k]);
  }
  CHECK_FALSE(fs::exists(dir / "obj" / "frame_00005.obj"));

  // .gltf, every 10 steps: frames at steps 0, 10, 20 of the same (deterministic) run.
  const Outcome o2 = run_cli("export_gltf", "run " + sample("cloth_hanging.json") + " --steps 20 --export " +
                                                quote((dir / "out.gltf").string()) + " --export-every 10");
  REQUIRE_MESSAGE(o2.code == 0, o2.err);
  const GltfAnimation g2 = read_gltf_animation(dir / "out.gltf");
  REQUIRE(g2.frames.size() == 3);
  for (std::size_t f = 0; f < 3; ++f)
    for (std::size_t k = 0; k < g2.frames[f].size(); ++k)
      check_close(g2.frames[f][k], trace.at(10 * f).positions[k]);
}

TEST_CASE("cli: bad export flags, paths and chains exit 2 before simulating") {
  const fs::path dir = tmp_dir() / "export_bad";
  fs::create_directories(dir);
  const std::string not_a_dir = (dir / "file").string();
  std::ofstream(not_a_dir) << "x";
  struct Bad {
    std::string args, needle;
  };
  const std::string cloth = sample("cloth_hanging.json"), chain = sample("spring.json");
  const Bad cases[] = {
      {cloth + " --export " + quote((dir / "out.obj").string()), "\".obj\""},
      {cloth + " --export-every 5", "--export-every needs --export or --obj-frames"},
      {cloth + " --export x.glb --export-every 0", "--export-every"},
      {cloth + " --export /nonexistent/dir/out.glb", "/nonexistent/dir/out.glb"},
      {cloth + " --obj-frames " + quote(not_a_dir + "/frames"), not_a_dir},
      {chain + " --export " + quote((dir / "chain.glb").string()), "chain"},
      {chain + " --obj-frames " + quote((dir / "chain_frames").string()), "chain"},
  };
  for (const Bad& b : cases) {
    CAPTURE(b.args);
    const Outcome o = run_cli("export_bad", "run " + b.args);
    CHECK(o.code == 2);
    CHECK_MESSAGE(o.err.find(b.needle) != std::string::npos, o.err);
    CHECK(o.out.empty()); // nothing was simulated
  }
}
