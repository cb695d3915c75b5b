// SPDX-License-Identifier: MIT
// The samples' shared loop. The offscreen path uses only the engine's API (OffscreenTarget); the
// window path records each frame itself into the window, swapchain and present render pass of
// vkcloth_host_window, as a host application embedding vkcloth would (a condensed `vkcloth view`).
// Both simulate on the backend --backend names (host::DrawnCloth; auto: the GPU solver on a GPU,
// the CPU solver on a CPU Vulkan device such as lavapipe, gpu::choose_backend).
#include "sample_app.hpp"

#include "vkcloth_host_window/window.hpp" // first of the Vulkan headers: it brings volk

#include "vkcloth_host_window/drawn_cloth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/offscreen.hpp"

namespace samples {
namespace {

int fail(const vkcloth::Error& e) {
  fmt::print(stderr, "error: {}\n", e.message);
  switch (e.code) {
  case vkcloth::ErrorCode::diverged:
    return 3;
  case vkcloth::ErrorCode::no_device:
    return 4;
  default:
    return 1;
  }
}

std::uint32_t default_steps_per_frame(const vkcloth::Scene& s) {
  return std::uint32_t(std::max(1.0, std::round((1.0 / 60.0) / s.params.dt)));
}

int run_offscreen(const vkcloth::Scene& scene, const Options& o) {
  using namespace vkcloth;
  gpu::ContextOptions co;
  co.require_graphics = true; // the queue draws as well as computes
  auto ctx = gpu::Context::create(co);
  if (!ctx)
    return fail(ctx.error());
  auto requested = host::parse_backend(o.backend);
  if (!requested)
    return fail(requested.error());
  const gpu::BackendChoice choice = host::resolve_backend(*requested, *ctx);
  fmt::print("backend: {} ({})\n", gpu::to_string(choice.backend), choice.reason);
  auto solver = host::DrawnCloth::create(choice.backend, *ctx, scene.system, scene.params);
  if (!solver)
    return fail(solver.error());
  auto target = render::OffscreenTarget::create(*ctx, o.width, o.height);
  if (!target)
    return fail(target.error());
  render::RendererOptions ro;
  ro.render_pass = target->render_pass();
  auto renderer = render::ClothRenderer::create(*ctx, solver->params(), *solver->topology(), ro);
  if (!renderer)
    return fail(renderer.error());
  const render::Camera camera = render::Camera::frame(render::scene_bounds(scene.system, scene.params),
                                                      float(o.width) / float(o.height));
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  const std::uint32_t frames = o.frames ? o.frames : 60;
  const std::uint32_t steps = o.steps_per_frame ? o.steps_per_frame : default_steps_per_frame(scene);
  for (std::uint32_t f = 0; f < frames; ++f) {
    // Vulkan: one submission (the steps, the compute -> vertex barrier, the draw, the readback);
    // CPU: the steps, the upload of positions and normals, then the draw and readback.
    auto img = solver->render(*target, *renderer, camera, f == 0 ? 0 : steps);
    if (!img)
      return fail(img.error());
    const auto path = o.out / fmt::format("{}_{:04}.png", scene.name, f);
    if (auto w = render::write_png(path, *img); !w)
      return fail(w.error());
  }
  fmt::print("{}: {} frames ({} steps each, t = {:.3g} s) written to {}/{}_NNNN.png\n", scene.name, frames,
             steps, solver->time(), o.out.string(), scene.name);
  if (ctx->validation_message_count())
    return 1;
  return 0;
}

// ---- the window ----------------------------------------------------------------------------------

struct Input {
  bool paused = false, reset = false, dragging = false;
  double x = 0, y = 0, last_x = 0, last_y = 0, scroll = 0;
};

int run_window(const vkcloth::Scene& scene, const Options& o) {
  using namespace vkcloth;
  host::Window w;
  if (auto failure = w.open(o.width, o.height, fmt::format("vkcloth sample: {}", scene.name))) {
    switch (*failure) {
    case host::Window::OpenFailure::no_display:
      fmt::print(stderr, "error: no display for a window (set DISPLAY, use xvfb-run, or pass --offscreen)\n");
      return 4;
    case host::Window::OpenFailure::no_vulkan:
      return fail(make_error(ErrorCode::no_device, "GLFW reports no Vulkan surface support"));
    case host::Window::OpenFailure::no_window:
      return fail(make_error(ErrorCode::no_device, "glfwCreateWindow failed"));
    }
  }
  Input in;
  w.set_host_pointer(&in);
  glfwSetKeyCallback(w.glfw(), [](GLFWwindow* win, int key, int, int action, int) {
    auto* i = static_cast<Input*>(host::Window::host_pointer(win));
    if (action != GLFW_PRESS)
      return;
    if (key == GLFW_KEY_ESCAPE)
      glfwSetWindowShouldClose(win, GLFW_TRUE);
    if (key == GLFW_KEY_SPACE)
      i->paused = !i->paused;
    if (key == GLFW_KEY_R)
      i->reset = true;
  });
  glfwSetMouseButtonCallback(w.glfw(), [](GLFWwindow* win, int button, int action, int) {
    if (button == GLFW_MOUSE_BUTTON_LEFT)
      static_cast<Input*>(host::Window::host_pointer(win))->dragging = action == GLFW_PRESS;
  });
  glfwSetCursorPosCallback(w.glfw(), [](GLFWwindow* win, double x, double y) {
    auto* i = static_cast<Input*>(host::Window::host_pointer(win));
    i->x = x, i->y = y;
  });
  glfwSetScrollCallback(w.glfw(), [](GLFWwindow* win, double, double y) {
    static_cast<Input*>(host::Window::host_pointer(win))->scroll += y;
  });

  // The Context with what a window needs: GLFW's instance extensions, the swapchain, a queue that
  // presents to our surface and draws.
  gpu::ContextOptions co;
  co.require_graphics = true;
  if (!w.add_presentation(co))
    return fail(make_error(ErrorCode::no_device, "GLFW reports no Vulkan surface support"));
  if (auto r = w.create_context(co); !r)
    return fail(r.error());
  if (!w.create_render_pass())
    return fail(make_error(ErrorCode::vulkan, "vkCreateRenderPass failed"));

  auto requested = host::parse_backend(o.backend);
  if (!requested)
    return fail(requested.error());
  const gpu::BackendChoice choice = host::resolve_backend(*requested, w.context());
  auto solver = host::DrawnCloth::create(choice.backend, w.context(), scene.system, scene.params);
  if (!solver)
    return fail(solver.error());
  render::RendererOptions ro;
  ro.render_pass = w.render_pass();
  auto renderer = render::ClothRenderer::create(w.context(), solver->params(), *solver->topology(), ro);
  if (!renderer)
    return fail(renderer.error());
  if (!w.create_frame_resources())
    return fail(make_error(ErrorCode::vulkan, "swapchain creation failed"));

  // Orbit camera around the scene's bounds.
  const render::Bounds b = render::scene_bounds(scene.system, scene.params);
  render::Camera cam = render::Camera::frame(b, float(o.width) / float(o.height));
  const glm::vec3 off = cam.eye - cam.target;
  float dist = glm::length(off), yaw = std::atan2(off.y, off.x), pitch = std::asin(off.z / dist);
  const std::uint32_t steps = o.steps_per_frame ? o.steps_per_frame : default_steps_per_frame(scene);
  fmt::print("{} on {}: drag orbits, wheel zooms, space pauses, R resets, Esc quits\n", scene.name,
             w.context().device_name());
  fmt::print("backend: {} ({})\n", gpu::to_string(choice.backend), choice.reason);
  std::uint64_t frame = 0;
  while (!glfwWindowShouldClose(w.glfw()) && (!o.frames || frame < o.frames)) {
    glfwPollEvents();
    w.wait_last_frame();
    if (frame % 30 == 0)
      if (auto r = solver->check_divergence(); !r)
        return fail(r.error());
    if (in.reset) { // a fresh solver from the initial state (nothing is pending: the wait above)
      in.reset = false;
      auto s = host::DrawnCloth::create(choice.backend, w.context(), scene.system, scene.params);
      if (!s)
        return fail(s.error());
      *solver = std::move(*s);
    }
    if (in.dragging) {
      yaw -= float(in.x - in.last_x) * 0.01f;
      pitch = std::clamp(pitch + float(in.y - in.last_y) * 0.01f, -1.5f, 1.5f);
    }
    in.last_x = in.x, in.last_y = in.y;
    dist *= std::pow(0.9f, float(in.scroll));
    in.scroll = 0;
    cam.eye = cam.target + dist * glm::vec3(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                            std::sin(pitch));
    auto ready = w.ensure_swapchain();
    if (!ready)
      return fail(make_error(ErrorCode::vulkan, "swapchain creation failed"));
    if (!*ready)
      continue; // minimised
    auto next = w.begin_frame();
    if (!next)
      return fail(next.error());
    if (!*next)
      continue; // out of date: recreated next time round
    const host::Frame& f = **next;
    // Vulkan: the steps and the compute -> graphics barrier (positions and normals visible to the
    // vertex fetch). CPU: the steps, then the upload into a slot no frame still reads (the wait above).
    auto buffers = solver->record_frame(f.cmd, in.paused ? 0 : steps, std::uint32_t(frame));
    if (!buffers)
      return fail(buffers.error());
    if (auto r = renderer->set_colliders(solver->params().colliders); !r) // where the steps left them
      return fail(r.error());
    w.begin_render_pass(f, renderer->palette().background);
    renderer->record_draw(f.cmd, *buffers, cam, f.extent);
    if (!w.end_render_pass_and_submit(f))
      return fail(make_error(ErrorCode::vulkan, "vkQueueSubmit failed"));
    if (auto r = w.present(f); !r)
      return fail(r.error());
    ++frame;
  }
  w.wait_idle();
  if (auto r = solver->check_divergence(); !r)
    return fail(r.error());
  fmt::print("{}: {} frames, step {}\n", scene.name, frame, solver->step_index());
  return 0;
}

[[noreturn]] void usage_exit(const char* prog, const std::string& about, const std::string& presets,
                             int code) {
  std::FILE* f = code ? stderr : stdout;
  fmt::print(f,
             "{}\n\nUsage: {} [options]\n"
             "  --offscreen          render to PNG files instead of a window (no display needed)\n"
             "  --frames N           stop after N frames (offscreen default 60; windowed: until closed)\n"
             "  --steps-per-frame K  solver steps between frames (default: about real time at 60 fps)\n"
             "  --out DIR            where the PNG frames and plots go (default ./out)\n"
             "  --size WxH           image or window size (default 800x600)\n"
             "  --backend NAME       auto (default: the GPU solver on a GPU, the CPU solver on a CPU Vulkan\n"
             "                       device such as lavapipe, where it is faster), cpu or vulkan\n"
             "{}"
             "  --help               this text\n"
             "Environment: VKCLOTH_VALIDATION=1 enables the Vulkan validation layer, VKCLOTH_DEVICE picks a "
             "device.\n",
             about, prog, presets.empty() ? "" : "  --preset NAME        one of:\n" + presets);
  std::exit(code);
}

} // namespace

Options parse_args(int argc, char** argv, const std::string& about, const std::string& presets_help) {
  Options o;
  auto value = [&](int& i) -> std::string {
    if (i + 1 >= argc) {
      fmt::print(stderr, "error: {} needs a value\n", argv[i]);
      usage_exit(argv[0], about, presets_help, 2);
    }
    return argv[++i];
  };
  auto number = [&](const std::string& s, const char* what) -> std::uint32_t {
    char* end = nullptr;
    const unsigned long v = std::strtoul(s.c_str(), &end, 10);
    if (s.empty() || *end || v == 0 || v > 100000) {
      fmt::print(stderr, "error: {} {}: expected a positive whole number\n", what, s);
      std::exit(2);
    }
    return std::uint32_t(v);
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h")
      usage_exit(argv[0], about, presets_help, 0);
    else if (a == "--offscreen")
      o.offscreen = true;
    else if (a == "--frames")
      o.frames = number(value(i), "--frames");
    else if (a == "--steps-per-frame")
      o.steps_per_frame = number(value(i), "--steps-per-frame");
    else if (a == "--out")
      o.out = value(i);
    else if (a == "--size") {
      const std::string s = value(i);
      unsigned w = 0, h = 0;
      char x = 0, extra = 0;
      if (std::sscanf(s.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' || !w || !h || w > 4096 ||
          h > 4096) {
        fmt::print(stderr, "error: --size {}: expected WxH, e.g. 800x600\n", s);
        std::exit(2);
      }
      o.width = w, o.height = h;
    } else if (a == "--backend") {
      o.backend = value(i);
      if (auto b = vkcloth::host::parse_backend(o.backend); !b) {
        fmt::print(stderr, "error: {}\n", b.error().message);
        std::exit(2);
      }
    } else if (a == "--preset" && !presets_help.empty())
      o.preset = value(i);
    else {
      fmt::print(stderr, "error: unknown option {}\n", a);
      usage_exit(argv[0], about, presets_help, 2);
    }
  }
  return o;
}

int run(const vkcloth::Scene& scene, const Options& options) {
  return options.offscreen ? run_offscreen(scene, options) : run_window(scene, options);
}

} // namespace samples
