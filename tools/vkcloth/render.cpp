// SPDX-License-Identifier: MIT
// `vkcloth render`: simulate a scene and draw it offscreen to PNG files (one frame, or a numbered
// sequence), optionally assembled into a video with ffmpeg. No display needed. The simulation runs
// where --backend says (auto: the GPU solver on a GPU, the CPU solver on lavapipe; DrawnCloth).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "commands.hpp"
#include "render_common.hpp"
#include "vkcloth_host_window/drawn_cloth.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {
namespace {

struct RenderOptions {
  SceneArgs args;
  std::string out;
  std::string size = "800x600";
  std::string camera;
  float fov = 40.0f;
  std::string texture;
  std::string frames_dir;
  std::uint64_t every = 10;
  std::string video;
  std::string backend = "auto";
};

bool have_ffmpeg() {
  return std::system("command -v ffmpeg >/dev/null 2>&1") == 0;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s)
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

int render_command(const RenderOptions& opt) {
  if (opt.out.empty() && opt.frames_dir.empty() && opt.video.empty())
    return report(
        make_error(ErrorCode::invalid_argument, "render: give --out FILE.png, --frames DIR or --video FILE"));
  auto size = parse_size(opt.size);
  if (!size)
    return report(size.error());
  std::string video_ext;
  if (!opt.video.empty()) {
    video_ext = std::filesystem::path(opt.video).extension().string();
    if (video_ext != ".mp4" && video_ext != ".gif")
      return report(make_error(ErrorCode::invalid_argument,
                               fmt::format("--video {}: the file must end in .mp4 or .gif", opt.video)));
    if (!have_ffmpeg())
      return report(
          make_error(ErrorCode::invalid_argument,
                     fmt::format("--video {} needs ffmpeg, which is not installed (apt-get install ffmpeg); "
                                 "--frames DIR still writes the PNG sequence",
                                 opt.video)));
  }
  auto requested = host::parse_backend(opt.backend);
  if (!requested)
    return report(requested.error());
  auto scene = opt.args.load();
  if (!scene)
    return report(scene.error());
  render::RendererOptions ro;
  if (!opt.texture.empty()) {
    auto tex = render::load_image(opt.texture);
    if (!tex)
      return report(tex.error());
    ro.texture = std::move(*tex);
  } else {
    ro.encoded_texture = scene->texture; // a glTF mesh's base-colour texture, if it has one
  }
  const float aspect = float(size->first) / float(size->second);
  auto camera = make_camera(opt.camera, opt.fov, *scene, aspect);
  if (!camera)
    return report(camera.error());

  auto context = gpu::Context::create(render_context_options());
  if (!context)
    return report(context.error());
  const gpu::BackendChoice choice = host::resolve_backend(*requested, *context);
  fmt::print("backend: {} ({})\n", gpu::to_string(choice.backend), choice.reason);
  auto solver = host::DrawnCloth::create(choice.backend, *context, scene->system, scene->params);
  if (!solver)
    return report(solver.error());
  auto target = render::OffscreenTarget::create(*context, size->first, size->second);
  if (!target)
    return report(target.error());
  ro.render_pass = target->render_pass();
  auto renderer =
      render::ClothRenderer::create(*context, solver->params(), *solver->topology(), std::move(ro));
  if (!renderer)
    return report(renderer.error());
  if (!renderer->draws_cloth())
    fmt::print(stderr,
               "vkcloth: {} is a chain (no cloth grid): drawing its masses as spheres and springs as lines\n",
               scene->name);

  const std::uint64_t total = scene->steps;
  std::string frames_dir = opt.frames_dir;
  if (frames_dir.empty() && !opt.video.empty())
    frames_dir = opt.video + ".frames";
  std::uint64_t written = 0;
  if (!frames_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(frames_dir, ec);
    if (ec)
      return report(make_error(
          ErrorCode::io, fmt::format("cannot create the frames directory {}: {}", frames_dir, ec.message())));
    const std::uint64_t every = std::max<std::uint64_t>(opt.every, 1);
    for (std::uint64_t done = 0;;) {
      auto img = solver->render(*target, *renderer, *camera);
      if (!img)
        return report(img.error());
      const std::string path = fmt::format("{}/frame_{:05}.png", frames_dir, written++);
      if (auto w = render::write_png(path, *img); !w)
        return report(w.error());
      if (done >= total)
        break;
      const std::uint64_t k = std::min(every, total - done);
      // The steps and the next frame's draw share one submission in render(); here the steps go
      // alone so that frame n shows exactly step n * every.
      if (auto r = solver->simulate(k); !r)
        return report(r.error());
      done += k;
    }
    fmt::print("{}: {} frames ({} steps, every {}) written to {}/frame_NNNNN.png\n", scene->name, written,
               total, every, frames_dir);
  } else {
    // One submission: the steps, the compute -> vertex barrier, the draw, the readback.
    std::uint64_t done = 0;
    while (total - done > 4096) { // keep single submissions short (watchdogs)
      if (auto r = solver->simulate(4096); !r)
        return report(r.error());
      done += 4096;
    }
    auto img = solver->render(*target, *renderer, *camera, static_cast<std::uint32_t>(total - done));
    if (!img)
      return report(img.error());
    if (auto w = render::write_png(opt.out, *img); !w)
      return report(w.error());
    fmt::print("{}: step {} (t = {:.4g} s) rendered at {}x{} to {}\n", scene->name, solver->step_index(),
               solver->time(), size->first, size->second, opt.out);
  }
  if (!opt.out.empty() && !frames_dir.empty()) {
    auto img = solver->render(*target, *renderer, *camera);
    if (!img)
      return report(img.error());
    if (auto w = render::write_png(opt.out, *img); !w)
      return report(w.error());
  }
  if (!opt.video.empty()) {
    const std::uint64_t every = std::max<std::uint64_t>(opt.every, 1);
    const int fps = std::clamp(int(std::lround(1.0 / (scene->params.dt * double(every)))), 1, 60);
    const std::string input = shell_quote(frames_dir + "/frame_%05d.png");
    const std::string cmd =
        video_ext == ".gif"
            ? fmt::format("ffmpeg -y -loglevel error -framerate {} -i {} -vf "
                          "\"split[a][b];[a]palettegen[p];[b][p]paletteuse\" {}",
                          fps, input, shell_quote(opt.video))
            : fmt::format(
                  "ffmpeg -y -loglevel error -framerate {} -i {} -vf \"scale=trunc(iw/2)*2:trunc(ih/2)*2\" "
                  "-pix_fmt yuv420p {}",
                  fps, input, shell_quote(opt.video));
    if (std::system(cmd.c_str()) != 0)
      return report(
          make_error(ErrorCode::io, fmt::format("ffmpeg failed to write {} (command: {})", opt.video, cmd)));
    fmt::print("video written to {} ({} frames at {} fps)\n", opt.video, written, fps);
  }
  return exit_ok;
}

} // namespace

void add_render_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Simulate a scene and render it offscreen to PNG (one frame, a sequence, or a video)");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, opt->args);
  cmd->add_option("--out", opt->out, "PNG file of the state after the scene's steps");
  cmd->add_option("--size", opt->size, "Image size WxH (default 800x600)");
  cmd->add_option("--camera", opt->camera,
                  "eye_x,eye_y,eye_z,target_x,target_y,target_z (default: framed from the scene's bounds)");
  cmd->add_option("--fov", opt->fov, "Vertical field of view in degrees (default 40)")
      ->check(CLI::Range(5.0f, 150.0f));
  cmd->add_option(
      "--texture", opt->texture,
      "Cloth texture (PNG or JPEG; default: a glTF mesh's own texture, else the built-in fabric)");
  cmd->add_option("--frames", opt->frames_dir,
                  "Write a numbered PNG sequence DIR/frame_00000.png, one every K steps");
  cmd->add_option("--every", opt->every, "K for --frames / --video (default 10)")->check(CLI::PositiveNumber);
  cmd->add_option("--video", opt->video,
                  "Assemble the frames into FILE.mp4 or FILE.gif with ffmpeg (must be installed)");
  add_draw_backend_option(*cmd, opt->backend);
  cmd->callback([opt, exit] { *exit = render_command(*opt); });
}

} // namespace vkcloth::cli
