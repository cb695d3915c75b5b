// SPDX-License-Identifier: MIT
#include "render_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>

namespace vkcloth::cli {

Result<std::pair<std::uint32_t, std::uint32_t>> parse_size(const std::string& text) {
  unsigned w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w == 0 ||
      h == 0 || w > 4096 || h > 4096)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("--size {}: expected WxH with each side in 1..4096, e.g. 800x600", text));
  return std::pair<std::uint32_t, std::uint32_t>{w, h};
}

Result<render::Camera> make_camera(const std::string& spec, float fov, const Scene& scene, float aspect) {
  const render::Bounds b = render::scene_bounds(scene.system, scene.params);
  render::Camera cam = render::Camera::frame(b, aspect, {0.9f, -1.6f, 1.0f}, fov);
  if (spec.empty())
    return cam;
  std::vector<float> v;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stof(item, &used));
      if (used != item.size())
        v.push_back(NAN);
    } catch (...) {
      v.push_back(NAN);
    }
  }
  if (v.size() != 6)
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("--camera {}: expected six numbers eye_x,eye_y,eye_z,target_x,target_y,target_z, got {}",
                    spec, v.size()));
  for (std::size_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]))
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("--camera {}: number {} is not a finite float (of the six "
                                    "eye_x,eye_y,eye_z,target_x,target_y,target_z)",
                                    spec, k + 1));
  cam.eye = {v[0], v[1], v[2]};
  cam.target = {v[3], v[4], v[5]};
  const float dist = glm::length(cam.eye - cam.target);
  if (dist <= 0.0f)
    return make_error(ErrorCode::invalid_argument, fmt::format("--camera {}: eye and target coincide", spec));
  cam.near_plane = dist * 0.01f;
  cam.far_plane = dist + 20.0f * std::max(b.radius(), 0.05f) + 10.0f;
  return cam;
}

gpu::ContextOptions render_context_options() {
  gpu::ContextOptions o;
  o.require_graphics = true;
  return o;
}

void add_draw_backend_option(CLI::App& cmd, std::string& backend) {
  cmd.add_option("--backend", backend,
                 "Where the simulation runs: auto (default: the GPU solver on a GPU, the CPU solver on a CPU "
                 "Vulkan device such as lavapipe, where it is faster; `vkcloth devices` says which and why), "
                 "cpu (CpuSolver, positions and normals uploaded for each frame) or vulkan (the GPU solver)")
      ->check(CLI::IsMember({"auto", "cpu", "vulkan"}));
}

} // namespace vkcloth::cli
