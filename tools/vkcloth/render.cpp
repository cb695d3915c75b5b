// SPDX-License-Identifier: MIT
// `vkcloth render`: simulate a scene and draw it offscreen to PNG files (one frame, or a numbered
// sequence), optionally assembled into a video with ffmpeg. No display needed. The simulation runs
// where --backend says (auto: the GPU solver on a GPU, the CPU solver on lavapipe; DrawnCloth).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

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

/// What --size, --video and --backend come to, once checked.
struct CheckedOptions {
  std::pair<std::uint32_t, std::uint32_t> size;
  std::string video_ext;               ///< ".mp4" or ".gif" with --video, else empty
  std::optional<gpu::Backend> backend; ///< empty: auto
};

/// The checks that need no scene: an output, --size, --video (.mp4 or .gif, and ffmpeg), --backend.
Result<CheckedOptions> check_options(const RenderOptions& opt) {
  if (opt.out.empty() && opt.frames_dir.empty() && opt.video.empty())
    return make_error(ErrorCode::invalid_argument,
                      "render: give --out FILE.png, --frames DIR or --video FILE");
  if (!opt.out.empty()) {
    std::string ext = std::filesystem::path(opt.out).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".png")
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("--out {}: the picture is a PNG, so the file must end in .png", opt.out));
  }
  auto size = parse_size(opt.size);
  if (!size)
    return size.error();
  std::string video_ext;
  if (!opt.video.empty()) {
    video_ext = std::filesystem::path(opt.video).extension().string();
    if (video_ext != ".mp4" && video_ext != ".gif")
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("--video {}: the file must end in .mp4 or .gif", opt.video));
    if (!have_ffmpeg())
      return make_error(
          ErrorCode::invalid_argument,
          fmt::format("--video {} needs ffmpeg, which is not installed (apt-get install ffmpeg); "
                      "--frames DIR still writes the PNG sequence",
                      opt.video));
  }
  auto requested = host::parse_backend(opt.backend);
  if (!requested)
    return requested.error();
  return CheckedOptions{*size, video_ext, *requested};
}

/// The renderer's options but its render pass: --texture's image, else the scene's own.
Result<render::RendererOptions> texture_options(const RenderOptions& opt, const Scene& scene) {
  render::RendererOptions ro;
  if (!opt.texture.empty()) {
    auto tex = render::load_image(opt.texture);
    if (!tex)
      return tex.error();
    ro.texture = std::move(*tex);
  } else {
    ro.encoded_texture = scene.texture; // a glTF mesh's base-colour texture, if it has one
  }
  return ro;
}

/// The scene's solver, the offscreen target and the renderer that draws the solver into it.
struct Drawer {
  host::DrawnCloth solver;
  render::OffscreenTarget target;
  render::ClothRenderer renderer;
};

/// Resolves the backend (printed) and makes the Drawer on `context`, which must outlive it.
Result<Drawer> make_drawer(gpu::Context& context, std::optional<gpu::Backend> requested, const Scene& scene,
                           std::pair<std::uint32_t, std::uint32_t> size, render::RendererOptions ro) {
  const gpu::BackendChoice choice = host::resolve_backend(requested, context);
  fmt::print("backend: {} ({})\n", gpu::to_string(choice.backend), choice.reason);
  auto solver = host::DrawnCloth::create(choice.backend, context, scene.system, scene.params);
  if (!solver)
    return solver.error();
  auto target = render::OffscreenTarget::create(context, size.first, size.second);
  if (!target)
    return target.error();
  ro.render_pass = target->render_pass();
  auto renderer =
      render::ClothRenderer::create(context, solver->params(), *solver->topology(), std::move(ro));
  if (!renderer)
    return renderer.error();
  if (!renderer->draws_cloth())
    fmt::print(stderr,
               "vkcloth: {} is a chain (no cloth grid): drawing its masses as spheres and springs as lines\n",
               scene.name);
  return Drawer{std::move(*solver), std::move(*target), std::move(*renderer)};
}

/// `steps` steps, then the frame drawn (one submission on the GPU) and written to the PNG `path`.
Result<void> write_frame(Drawer& d, const render::Camera& camera, const std::string& path,
                         std::uint32_t steps = 0) {
  auto img = d.solver.render(d.target, d.renderer, camera, steps);
  if (!img)
    return img.error();
  return render::write_png(path, *img);
}

/// The frames directory: --frames, else FILE.frames next to --video, else none.
std::string frames_dir_of(const RenderOptions& opt) {
  if (opt.frames_dir.empty() && !opt.video.empty())
    return opt.video + ".frames";
  return opt.frames_dir;
}

/// --frames / --video: frame 0 and one every --every steps to DIR/frame_NNNNN.png; returns the count.
Result<std::uint64_t> write_frames(const RenderOptions& opt, const Scene& scene, Drawer& d,
                                   const render::Camera& camera, const std::string& frames_dir) {
  const std::uint64_t total = scene.steps;
  std::uint64_t written = 0;
  std::error_code ec;
  std::filesystem::create_directories(frames_dir, ec);
  if (ec)
    return make_error(ErrorCode::io,
                      fmt::format("cannot create the frames directory {}: {}", frames_dir, ec.message()));
  const std::uint64_t every = std::max<std::uint64_t>(opt.every, 1);
  for (std::uint64_t done = 0;;) {
    VKCLOTH_TRY(write_frame(d, camera, fmt::format("{}/frame_{:05}.png", frames_dir, written++)));
    if (done >= total)
      break;
    const std::uint64_t k = std::min(every, total - done);
    // The steps and the next frame's draw share one submission in render(); here the steps go
    // alone so that frame n shows exactly step n * every.
    VKCLOTH_TRY(d.solver.simulate(k));
    done += k;
  }
  fmt::print("{}: {} frames ({} steps, every {}) written to {}/frame_NNNNN.png\n", scene.name, written, total,
             every, frames_dir);
  return written;
}

/// --out alone: the scene's steps and the frame drawn after them, written to --out.
Result<void> write_last_frame(const RenderOptions& opt, const Scene& scene, Drawer& d,
                              const render::Camera& camera, std::pair<std::uint32_t, std::uint32_t> size) {
  const std::uint64_t total = scene.steps;
  // One submission: the steps, the compute -> vertex barrier, the draw, the readback.
  std::uint64_t done = 0;
  while (total - done > 4096) { // keep single submissions short (watchdogs)
    VKCLOTH_TRY(d.solver.simulate(4096));
    done += 4096;
  }
  VKCLOTH_TRY(write_frame(d, camera, opt.out, static_cast<std::uint32_t>(total - done)));
  fmt::print("{}: step {} (t = {:.4g} s) rendered at {}x{} to {}\n", scene.name, d.solver.step_index(),
             d.solver.time(), size.first, size.second, opt.out);
  return {};
}

/// --video: ffmpeg assembles the frames into the .mp4 or .gif at the simulation's rate (1 to 60 fps).
Result<void> encode_video(const RenderOptions& opt, const std::string& video_ext, const Scene& scene,
                          const std::string& frames_dir, std::uint64_t written) {
  const std::uint64_t every = std::max<std::uint64_t>(opt.every, 1);
  const int fps = std::clamp(int(std::lround(1.0 / (scene.params.dt * double(every)))), 1, 60);
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
    return make_error(ErrorCode::io, fmt::format("ffmpeg failed to write {} (command: {})", opt.video, cmd));
  fmt::print("video written to {} ({} frames at {} fps)\n", opt.video, written, fps);
  return {};
}

/// The frames, then --out drawn again and the video; or, with --out alone, the single frame.
Result<void> write_outputs(const RenderOptions& opt, const CheckedOptions& checked, const Scene& scene,
                           Drawer& d, const render::Camera& camera) {
  const std::string frames_dir = frames_dir_of(opt);
  if (frames_dir.empty()) // neither --frames nor --video
    return write_last_frame(opt, scene, d, camera, checked.size);
  auto written = write_frames(opt, scene, d, camera, frames_dir);
  if (!written)
    return written.error();
  if (!opt.out.empty())
    VKCLOTH_TRY(write_frame(d, camera, opt.out));
  if (!opt.video.empty())
    VKCLOTH_TRY(encode_video(opt, checked.video_ext, scene, frames_dir, *written));
  return {};
}

int render_command(const RenderOptions& opt) {
  auto checked = check_options(opt);
  if (!checked)
    return report(checked.error());
  auto scene = opt.args.load();
  if (!scene)
    return report(scene.error());
  auto ro = texture_options(opt, *scene);
  if (!ro)
    return report(ro.error());
  const float aspect = float(checked->size.first) / float(checked->size.second);
  auto camera = make_camera(opt.camera, opt.fov, *scene, aspect);
  if (!camera)
    return report(camera.error());

  auto context = gpu::Context::create(render_context_options());
  if (!context)
    return report(context.error());
  auto d = make_drawer(*context, checked->backend, *scene, checked->size, std::move(*ro));
  if (!d)
    return report(d.error());
  if (auto r = write_outputs(opt, *checked, *scene, *d, *camera); !r)
    return report(r.error());
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
  cmd->add_option("--every", opt->every, "K for --frames / --video (default 10)")
      ->check(whole_number_at_least_one);
  cmd->add_option("--video", opt->video,
                  "Assemble the frames into FILE.mp4 or FILE.gif with ffmpeg (must be installed)");
  add_draw_backend_option(*cmd, opt->backend);
  cmd->callback([opt, exit] { *exit = render_command(*opt); });
}

} // namespace vkcloth::cli
