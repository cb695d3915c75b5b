// SPDX-License-Identifier: MIT
// `vkcloth view`: an interactive window (GLFW + a Vulkan swapchain) drawing the simulation live,
// on the backend --backend names (auto: the GPU solver on a GPU, the CPU solver on lavapipe).
// Mouse: left-drag orbits, or drags the particle under the cursor (the report's hand lifting the
// cloth); wheel zooms. Keys: space pause, S / right arrow single step, R reset, W wind on/off,
// Esc quit. --frames N quits by itself after N frames; --screenshot FILE saves the last frame.
//
// The window, swapchain and present render pass are vkcloth_host_window's (shared with the
// samples); the mouse and keys are view_input's. This file sets them up and records each frame:
// the held particle, the solver's steps, the barrier to the draw (or, on the CPU backend, the steps
// and the upload of positions and normals: host::DrawnCloth), the draw.
#include "view_input.hpp" // first: brings volk (through vkcloth_host_window) before other Vulkan headers

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "commands.hpp"
#include "render_common.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {
namespace {

struct ViewOptions {
  SceneArgs args;
  std::string size = "1024x768";
  std::string texture;
  std::uint64_t frames = 0; ///< 0: until closed
  std::string screenshot;
  std::uint32_t steps_per_frame = 0; ///< 0: about real time at 60 frames per second
  std::string backend = "auto";
};

class Viewer {
public:
  ~Viewer();
  int run(const ViewOptions& opt);

private:
  Result<void> open_window(std::uint32_t width, std::uint32_t height);
  Result<void> reset_solver();
  Result<void> draw_frame();
  Result<void> save_screenshot(const std::string& path, std::uint64_t frame, VkExtent2D fallback);

  host::Window window_; // first: destroyed last (it owns the Context the rest was created on)
  std::optional<Scene> scene_;
  gpu::Backend backend_ = gpu::Backend::vulkan;
  std::optional<host::DrawnCloth> solver_;
  std::optional<render::ClothRenderer> renderer_;
  render::Image texture_;
  Input input_;
  Orbit orbit_;
  Hold hold_;
  bool wind_on_ = false;
  Wind base_wind_;
  std::uint32_t steps_per_frame_ = 1;
  std::uint32_t upload_slot_ = 0; // the CPU backend's HostClothBuffers slot, one per frame
};

Viewer::~Viewer() {
  window_.wait_idle();
  renderer_.reset();
  solver_.reset();
}

/// The window, the Context that presents to it, and its render pass; the messages are the view's.
Result<void> Viewer::open_window(std::uint32_t width, std::uint32_t height) {
  if (auto failure = window_.open(width, height, fmt::format("vkcloth: {}", scene_->name))) {
    switch (*failure) {
    case host::Window::OpenFailure::no_display:
      return make_error(ErrorCode::no_device,
                        "cannot open a window: GLFW found no display (set DISPLAY, or run "
                        "under xvfb-run; `vkcloth render` needs no display)");
    case host::Window::OpenFailure::no_vulkan:
      return make_error(ErrorCode::no_device, "GLFW found no Vulkan loader with window-system support");
    case host::Window::OpenFailure::no_window:
      return make_error(ErrorCode::no_device, "glfwCreateWindow failed");
    }
  }
  install_input_callbacks(window_, input_);
  gpu::ContextOptions co = render_context_options();
  if (!window_.add_presentation(co))
    return make_error(ErrorCode::no_device, "GLFW reports no Vulkan surface extensions for this display");
  VKCLOTH_TRY(window_.create_context(co));
  return window_.create_render_pass();
}

Result<void> Viewer::reset_solver() {
  window_.wait_idle();
  solver_.reset();
  SimParams p = scene_->params;
  p.wind = wind_on_ ? base_wind_ : Wind{0.0, base_wind_.direction};
  auto s = host::DrawnCloth::create(backend_, window_.context(), scene_->system, p);
  if (!s)
    return s.error();
  solver_.emplace(std::move(*s));
  hold_.particle.reset();
  return {};
}

Result<void> Viewer::draw_frame() {
  window_.wait_last_frame();
  if (input_.reset) {
    input_.reset = false;
    VKCLOTH_TRY(reset_solver());
  }
  if (input_.toggle_wind) {
    input_.toggle_wind = false;
    wind_on_ = !wind_on_;
    SimParams p = solver_->params();
    p.wind = wind_on_ ? base_wind_ : Wind{0.0, base_wind_.direction};
    VKCLOTH_TRY(solver_->set_params(p)); // nothing pending: the wait above was for the last submission
    fmt::print("wind {}\n", wind_on_ ? "on" : "off");
  }
  apply_mouse(input_, orbit_, hold_, *solver_, window_);
  auto ready = window_.ensure_swapchain();
  if (!ready)
    return ready.error();
  if (!*ready)
    return {}; // minimised
  auto next = window_.begin_frame();
  if (!next)
    return next.error();
  if (!*next)
    return {}; // out of date: recreated next frame
  const host::Frame& f = **next;
  const std::uint32_t steps = !input_.paused ? steps_per_frame_ : input_.step_once ? 1u : 0u;
  input_.step_once = false;
  std::optional<host::HeldParticle> held;
  if (hold_.particle)
    held = host::HeldParticle{*hold_.particle, hold_.position};
  // The held particle, the steps and THE compute -> graphics barrier (GPU), or the steps and the
  // upload of positions and normals (CPU; wait_last_frame above freed every slot).
  auto buffers = solver_->record_frame(f.cmd, steps, upload_slot_++, held);
  if (!buffers)
    return buffers.error();
  VKCLOTH_TRY(renderer_->set_colliders(solver_->params().colliders)); // where the steps left them
  window_.begin_render_pass(f, renderer_->palette().background);
  renderer_->record_draw(f.cmd, *buffers, orbit_.camera(), f.extent);
  VKCLOTH_TRY(window_.end_render_pass_and_submit(f));
  return window_.present(f);
}

/// The last frame, drawn again offscreen at the window's size (`fallback` while minimised) with the
/// same camera.
Result<void> Viewer::save_screenshot(const std::string& path, std::uint64_t frame, VkExtent2D fallback) {
  const VkExtent2D e = window_.extent().width ? window_.extent() : fallback;
  auto target = render::OffscreenTarget::create(window_.context(), e.width, e.height);
  if (!target)
    return target.error();
  render::RendererOptions so;
  so.render_pass = target->render_pass();
  so.texture = texture_;
  auto shot_renderer =
      render::ClothRenderer::create(window_.context(), solver_->params(), *solver_->topology(), so);
  if (!shot_renderer)
    return shot_renderer.error();
  auto img = solver_->render(*target, *shot_renderer, orbit_.camera(), 0);
  if (!img)
    return img.error();
  VKCLOTH_TRY(render::write_png(path, *img));
  fmt::print("screenshot of frame {} written to {}\n", frame, path);
  return {};
}

int Viewer::run(const ViewOptions& opt) {
  auto size = parse_size(opt.size);
  if (!size)
    return report(size.error());
  auto requested = host::parse_backend(opt.backend);
  if (!requested)
    return report(requested.error());
  auto scene = opt.args.load();
  if (!scene)
    return report(scene.error());
  scene_.emplace(std::move(*scene));
  if (!opt.texture.empty()) {
    auto tex = render::load_image(opt.texture);
    if (!tex)
      return report(tex.error());
    texture_ = std::move(*tex);
  } else if (scene_->texture) { // a glTF mesh's base-colour texture
    auto tex = render::decode_image(scene_->texture->encoded, scene_->texture->source);
    if (!tex)
      return report(tex.error());
    texture_ = std::move(*tex);
  }
  if (auto r = open_window(size->first, size->second); !r)
    return report(r.error());
  const gpu::BackendChoice choice = host::resolve_backend(*requested, window_.context());
  backend_ = choice.backend;
  const Wind& w = scene_->params.wind;
  wind_on_ = w.strength != 0.0;
  base_wind_ = wind_on_ ? w : Wind{0.05, glm::dvec3(1.0, 0.0, 0.0)};
  if (auto r = reset_solver(); !r)
    return report(r.error());
  render::RendererOptions ro;
  ro.render_pass = window_.render_pass();
  ro.texture = texture_;
  auto rend = render::ClothRenderer::create(window_.context(), solver_->params(), *solver_->topology(), ro);
  if (!rend)
    return report(rend.error());
  renderer_.emplace(std::move(*rend));
  if (!renderer_->draws_cloth())
    fmt::print(stderr, "vkcloth: {} is a chain: masses drawn as spheres, springs as lines\n", scene_->name);
  if (auto r = window_.create_frame_resources(); !r)
    return report(r.error());

  orbit_ = Orbit::framing(render::scene_bounds(scene_->system, scene_->params),
                          float(size->first) / float(size->second));
  steps_per_frame_ = opt.steps_per_frame
                         ? opt.steps_per_frame
                         : std::uint32_t(std::max(1.0, std::round((1.0 / 60.0) / scene_->params.dt)));
  fmt::print(
      "vkcloth view: {} on {} — drag: orbit / move a particle, wheel: zoom, space: pause, S: step, R: reset, "
      "W: wind, Esc: quit\n",
      scene_->name, window_.context().device_name());
  fmt::print("backend: {} ({})\n", gpu::to_string(choice.backend), choice.reason);

  std::uint64_t frame = 0;
  while (!glfwWindowShouldClose(window_.glfw())) {
    glfwPollEvents();
    if (auto r = draw_frame(); !r)
      return report(r.error());
    ++frame;
    if (frame % 30 == 0 || (opt.frames && frame >= opt.frames)) {
      window_.wait_last_frame();
      if (auto r = solver_->check_divergence(); !r)
        return report(r.error());
    }
    if (opt.frames && frame >= opt.frames)
      break;
  }
  window_.wait_idle();
  if (!opt.screenshot.empty())
    if (auto r = save_screenshot(opt.screenshot, frame, VkExtent2D{size->first, size->second}); !r)
      return report(r.error());
  fmt::print("vkcloth view: {} frames, step {}\n", frame, solver_->step_index());
  return exit_ok;
}

} // namespace

void add_view_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<ViewOptions>();
  CLI::App* cmd =
      app.add_subcommand("view", "Open a window and watch the simulation live (orbit, pause, step, "
                                 "reset, wind, drag a particle)");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, opt->args);
  cmd->add_option("--size", opt->size, "Window size WxH (default 1024x768)");
  cmd->add_option(
      "--texture", opt->texture,
      "Cloth texture (PNG or JPEG; default: a glTF mesh's own texture, else the built-in fabric)");
  cmd->add_option("--frames", opt->frames, "Quit by itself after N frames (0: run until closed)");
  cmd->add_option("--screenshot", opt->screenshot, "Save the last frame as a PNG on exit");
  cmd->add_option("--steps-per-frame", opt->steps_per_frame,
                  "Solver steps per frame (default: about real time at 60 fps)");
  add_draw_backend_option(*cmd, opt->backend);
  cmd->callback([opt, exit] {
    Viewer viewer;
    *exit = viewer.run(*opt);
  });
}

} // namespace vkcloth::cli
