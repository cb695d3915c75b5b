// SPDX-License-Identifier: MIT
// Shared by the render tests: a validated Context whose queue does graphics, scenes, image
// metrics and the golden-image comparison.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "../gpu/gpu_test_util.hpp"
#include "vkcloth/render/camera.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/image.hpp"
#include "vkcloth/render/interaction.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::render::test {

/// One Context per process with validation + synchronization validation and a graphics queue.
inline gpu::test::SharedContext& render_context() {
  static gpu::test::SharedContext s = [] {
    gpu::test::SharedContext r;
    gpu::ContextOptions o;
    o.validation = true;
    o.require_graphics = true;
    auto c = gpu::Context::create(o);
    if (c)
      r.context.emplace(std::move(c.value()));
    else
      r.error = std::string(to_string(c.error().code)) + ": " + c.error().message;
    return r;
  }();
  return s;
}

inline Scene load(const std::string& name, std::vector<std::string> overrides = {}) {
  auto s = load_scene_file(std::filesystem::path(VKCLOTH_SCENES_DIR) / name, overrides);
  REQUIRE_MESSAGE(s, (s ? "" : s.error().message));
  return std::move(*s);
}

/// A solver, an offscreen target and a renderer for it, on the shared Context.
struct Rig {
  Scene scene;
  gpu::GpuSolver solver;
  OffscreenTarget target;
  ClothRenderer renderer;
  Camera camera;
};

inline std::optional<Rig> make_rig(gpu::Context& ctx, Scene scene, std::uint32_t w, std::uint32_t h,
                                   Image texture = {}) {
  auto solver = gpu::GpuSolver::create(ctx, scene.system, scene.params);
  REQUIRE_MESSAGE(solver, (solver ? "" : solver.error().message));
  auto target = OffscreenTarget::create(ctx, w, h);
  REQUIRE_MESSAGE(target, (target ? "" : target.error().message));
  RendererOptions ro;
  ro.render_pass = target->render_pass();
  ro.texture = std::move(texture);
  auto renderer = ClothRenderer::create(ctx, *solver, *solver->topology(), std::move(ro));
  REQUIRE_MESSAGE(renderer, (renderer ? "" : renderer.error().message));
  const Camera cam = Camera::frame(scene_bounds(scene.system, scene.params), float(w) / float(h));
  return Rig{std::move(scene), std::move(*solver), std::move(*target), std::move(*renderer), cam};
}

inline std::filesystem::path out_dir() {
  std::filesystem::path d(VKCLOTH_RENDER_OUT);
  std::filesystem::create_directories(d);
  return d;
}

/// The pixel of world point `p` in a w x h image through `cam`, REQUIREd inside with a margin.
inline std::pair<std::uint32_t, std::uint32_t> pixel_in(const Camera& cam, glm::vec3 p, std::uint32_t w,
                                                        std::uint32_t h, float margin = 3.0f) {
  auto q = cam.project(p, w, h);
  REQUIRE(q);
  INFO("point (" << p.x << ", " << p.y << ", " << p.z << ") -> pixel (" << q->x << ", " << q->y << ")");
  REQUIRE(q->x >= margin);
  REQUIRE(q->y >= margin);
  REQUIRE(q->x < float(w) - margin);
  REQUIRE(q->y < float(h) - margin);
  return {std::uint32_t(q->x), std::uint32_t(q->y)};
}

inline glm::vec3 rgb(const Image& img, std::uint32_t x, std::uint32_t y) {
  const std::uint8_t* p = img.pixel(x, y);
  return {float(p[0]), float(p[1]), float(p[2])};
}

inline glm::vec3 rgb255(glm::vec3 linear01) {
  return linear01 * 255.0f;
}

inline float max_abs(glm::vec3 a, glm::vec3 b) {
  const glm::vec3 d = glm::abs(a - b);
  return std::max(d.x, std::max(d.y, d.z));
}

/// The golden-image metric: a pixel "differs" when any channel differs by more than 8 (of 255);
/// the images match when fewer than 0.5% of the pixels differ.
inline constexpr int golden_channel_tolerance = 8;
inline constexpr double golden_max_fraction = 0.005;

struct Comparison {
  double fraction = 1.0;
  Image diff; ///< differing pixels in red over a faded copy of the golden image
};

inline Comparison compare(const Image& actual, const Image& golden) {
  Comparison c;
  if (actual.width != golden.width || actual.height != golden.height)
    return c;
  c.diff = golden;
  std::size_t bad = 0;
  for (std::uint32_t y = 0; y < actual.height; ++y)
    for (std::uint32_t x = 0; x < actual.width; ++x) {
      const std::uint8_t *a = actual.pixel(x, y), *g = golden.pixel(x, y);
      int m = 0;
      for (int k = 0; k < 3; ++k)
        m = std::max(m, std::abs(int(a[k]) - int(g[k])));
      std::uint8_t* d = c.diff.pixel(x, y);
      if (m > golden_channel_tolerance) {
        ++bad;
        d[0] = 255, d[1] = 0, d[2] = 0;
      } else {
        for (int k = 0; k < 3; ++k)
          d[k] = std::uint8_t(128 + g[k] / 4);
      }
      d[3] = 255;
    }
  c.fraction = double(bad) / double(std::size_t(actual.width) * actual.height);
  return c;
}

/// Compares `actual` with tests/render/golden/<name>.png. VKCLOTH_UPDATE_GOLDEN=1 rewrites the
/// golden file instead. On a mismatch writes <name>.actual.png and <name>.diff.png to the build's
/// tests/render/out/ directory.
inline void check_golden(const std::string& name, const Image& actual) {
  const std::filesystem::path golden_path = std::filesystem::path(VKCLOTH_GOLDEN_DIR) / (name + ".png");
  const char* update = std::getenv("VKCLOTH_UPDATE_GOLDEN");
  if (update && std::string(update) == "1") {
    REQUIRE(write_png(golden_path, actual));
    MESSAGE("golden image rewritten: " << golden_path.string());
    return;
  }
  auto golden = load_image(golden_path);
  const std::filesystem::path actual_path = out_dir() / (name + ".actual.png");
  if (!golden) {
    REQUIRE(write_png(actual_path, actual));
    FAIL("no golden image " << golden_path.string() << " (" << golden.error().message
                            << "); the actual frame is " << actual_path.string()
                            << "; run with VKCLOTH_UPDATE_GOLDEN=1 to create it");
  }
  const Comparison c = compare(actual, *golden);
  if (c.fraction >= golden_max_fraction) {
    REQUIRE(write_png(actual_path, actual));
    if (!c.diff.rgba.empty())
      REQUIRE(write_png(out_dir() / (name + ".diff.png"), c.diff));
  }
  CHECK_MESSAGE(c.fraction < golden_max_fraction,
                name << ": " << c.fraction * 100.0 << "% of the pixels differ by more than "
                     << golden_channel_tolerance << " (limit " << golden_max_fraction * 100.0
                     << "%); actual and diff images in " << out_dir().string());
}

} // namespace vkcloth::render::test

/// Starts a render test case on the shared graphics Context (VKCLOTH_TEST_WITH_CONTEXT).
#define VKCLOTH_RENDER_TEST_BEGIN(ctx)                                                                       \
  VKCLOTH_TEST_WITH_CONTEXT(ctx, ::vkcloth::render::test::render_context())
