// SPDX-License-Identifier: MIT
// The scene fuzzer's input format, shared by the libFuzzer target (fuzz_scene.cpp) and the
// regression test that replays tests/fuzz/regressions/ in the normal suite.
//
// Input bytes: the scene text, then optionally '\0'-separated override strings (at most 8):
//   {"system": "chain"}\0integrator.dt=0.1\0colliders[0].radius=2
// The scene is parsed and validated with parse_scene(); a scene that loads is also stepped a few
// times on the CPU solver (small systems only), so the validator's promises are checked too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::fuzz {

/// Returns true when the scene loaded. Must never crash, hang or leak, whatever the bytes.
/// `source` names the scene: a "cloth.mesh" path is relative to its directory (the seed corpus
/// passes the sample's own path, so the mesh samples load their OBJ files).
inline bool run_scene_input(const std::uint8_t* data, std::size_t size, const char* source = "fuzz.json") {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = all.find('\0');
  const std::string_view text = all.substr(0, nul);
  std::vector<std::string> overrides;
  if (nul != std::string_view::npos) {
    std::string_view rest = all.substr(nul + 1);
    while (overrides.size() < 8) {
      const std::size_t next = rest.find('\0');
      overrides.emplace_back(rest.substr(0, next));
      if (next == std::string_view::npos)
        break;
      rest = rest.substr(next + 1);
    }
  }
  auto scene = parse_scene(text, source, overrides);
  if (!scene.ok()) {
    // Every error has a message (the CLI prints it).
    if (scene.error().message.empty())
      __builtin_trap();
    return false;
  }
  // Keep each input fast: only small systems are stepped.
  if (scene->system.size() <= 4096) {
    auto solver = CpuSolver<float>::create(scene->system, scene->params, CpuSolverOptions{1});
    if (!solver.ok())
      __builtin_trap();   // a validated scene must be accepted by the solver
    (void)solver->run(3); // divergence is a valid outcome
  }
  return true;
}

} // namespace vkcloth::fuzz
