// SPDX-License-Identifier: MIT
// `vkcloth render` as a separate process: texture errors (exit 2, the file named), --video
// without ffmpeg, PNG outputs, a chain scene, --backend (auto, the default, against vulkan).
#include <doctest/doctest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "vkcloth/builders.hpp"
#include "vkcloth/export.hpp"
#include "render_test_util.hpp"
#include "vkcloth/render/image.hpp"

namespace fs = std::filesystem;

namespace {

struct Outcome {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path tmp_dir() {
  fs::path d = fs::path(VKCLOTH_RENDER_OUT) / "cli";
  fs::create_directories(d);
  return d;
}

Outcome run_vkcloth(const std::string& tag, const std::string& args, const std::string& env = "") {
  const fs::path out = tmp_dir() / (tag + ".stdout"), err = tmp_dir() / (tag + ".stderr");
  const std::string cmd = env + " '" + VKCLOTH_CLI_PATH + "' " + args + " >'" + out.string() + "' 2>'" +
                          err.string() + "' </dev/null";
  const int status = std::system(cmd.c_str());
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = slurp(out);
  o.err = slurp(err);
  return o;
}

bool on_ci() {
  const char* v = std::getenv("CI");
  return v && (std::strcmp(v, "true") == 0 || std::strcmp(v, "1") == 0);
}

/// Exit 4 (no device) skips the check off CI.
bool device_missing(const Outcome& o) {
  if (o.code != 4)
    return false;
  if (on_ci())
    FAIL("CI=true but no Vulkan device: " << o.err);
  MESSAGE("skipped, no Vulkan device: " << o.err);
  return true;
}

const std::string scenes = VKCLOTH_SCENES_DIR;

} // namespace

TEST_CASE("render: a missing texture file is exit 2 naming the file") {
  const fs::path tex = tmp_dir() / "does_not_exist.png";
  const Outcome o =
      run_vkcloth("tex_missing", "render " + scenes + "/cloth_on_sphere.json --steps 1 --out " +
                                     (tmp_dir() / "x.png").string() + " --texture " + tex.string());
  CHECK(o.code == 2);
  CHECK(o.err.find("does_not_exist.png") != std::string::npos);
  CHECK(o.err.find("does not exist") != std::string::npos);
}

TEST_CASE("render: a corrupt texture file is exit 2 naming the file") {
  const fs::path tex = tmp_dir() / "corrupt_texture.jpg";
  std::ofstream(tex) << "\xff\xd8\xff garbage, not a JPEG";
  const Outcome o =
      run_vkcloth("tex_corrupt", "render " + scenes + "/cloth_on_sphere.json --steps 1 --out " +
                                     (tmp_dir() / "x.png").string() + " --texture " + tex.string());
  CHECK(o.code == 2);
  CHECK(o.err.find("corrupt_texture.jpg") != std::string::npos);
}

TEST_CASE("render: --video without ffmpeg is exit 2 with a clear message") {
  const Outcome o = run_vkcloth("video_no_ffmpeg",
                                "render " + scenes + "/cloth_on_sphere.json --steps 2 --video " +
                                    (tmp_dir() / "v.mp4").string(),
                                "PATH=/nonexistent");
  CHECK(o.code == 2);
  CHECK(o.err.find("needs ffmpeg") != std::string::npos);
}

TEST_CASE("render: --out and --frames write PNGs, a chain renders too") {
  const fs::path frames = tmp_dir() / "frames";
  fs::remove_all(frames);
  const fs::path out = tmp_dir() / "final.png";
  fs::remove(out);
  const Outcome o = run_vkcloth(
      "frames", "render " + scenes + "/cloth_on_sphere.json --steps 6 --every 3 --size 64x48 --frames " +
                    frames.string() + " --out " + out.string());
  if (device_missing(o))
    return;
  REQUIRE_MESSAGE(o.code == 0, o.err);
  CHECK(fs::file_size(frames / "frame_00000.png") > 0);
  CHECK(fs::file_size(frames / "frame_00002.png") > 0);
  CHECK_FALSE(fs::exists(frames / "frame_00003.png"));
  CHECK(fs::file_size(out) > 0);

  const Outcome c = run_vkcloth("chain", "render " + scenes + "/spring.json --steps 5 --size 64x48 --out " +
                                             (tmp_dir() / "spring.png").string());
  REQUIRE_MESSAGE(c.code == 0, c.err);
  CHECK(c.err.find("chain") != std::string::npos);
  CHECK(fs::file_size(tmp_dir() / "spring.png") > 0);
}

TEST_CASE("render: a glTF mesh scene is drawn with the file's base-colour texture") {
  // A 6 x 6 horizontal cloth written as a .glb whose material's texture is plain green.
  vkcloth::ClothDesc d;
  d.nx = d.ny = 6;
  d.orientation = vkcloth::ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, 0.5};
  auto system = vkcloth::make_cloth(d);
  REQUIRE(system.ok());
  vkcloth::render::Image green;
  green.width = green.height = 4;
  for (int k = 0; k < 16; ++k)
    green.rgba.insert(green.rgba.end(), {20, 210, 40, 255});
  REQUIRE(vkcloth::render::write_png(tmp_dir() / "green.png", green).ok());
  std::ifstream png(tmp_dir() / "green.png", std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(png)),
                                        std::istreambuf_iterator<char>());
  auto rec = vkcloth::AnimationRecorder::create(*system, vkcloth::MeshTexture{"green.png", bytes});
  REQUIRE(rec.ok());
  std::vector<glm::dvec3> x;
  for (const vkcloth::Particle& p : system->particles)
    x.push_back(p.position);
  REQUIRE(rec->add_frame(0.0, x).ok());
  REQUIRE(rec->write_gltf(tmp_dir() / "green_cloth.glb").ok());
  std::ofstream(tmp_dir() / "green_cloth.json")
      << R"({"system": "cloth", "integrator": {"steps": 1}, "cloth": {"mesh": "green_cloth.glb"}})";

  const fs::path out = tmp_dir() / "green_cloth.png";
  const Outcome o = run_vkcloth("gltf_texture", "render " + (tmp_dir() / "green_cloth.json").string() +
                                                    " --size 96x72 --out " + out.string());
  if (device_missing(o))
    return;
  REQUIRE_MESSAGE(o.code == 0, o.err);
  auto img = vkcloth::render::load_image(out);
  REQUIRE(img.ok());
  std::size_t greenish = 0;
  for (std::size_t k = 0; k + 3 < img->rgba.size(); k += 4)
    greenish += img->rgba[k + 1] > 2 * img->rgba[k] && img->rgba[k + 1] > 2 * img->rgba[k + 2];
  // The cloth fills a good part of the frame (framed on the scene); the fabric default has no such green.
  CHECK(greenish > img->rgba.size() / 4 / 10);
}

TEST_CASE(
    "render: --backend auto is the default and on lavapipe picks the CPU solver drawing the GPU's frame") {
  // `devices` names the backend auto picks on the selected device, and why.
  const Outcome dev = run_vkcloth("devices_auto", "devices");
  if (device_missing(dev))
    return;
  REQUIRE_MESSAGE(dev.code == 0, dev.err);
  const bool cpu_device = dev.out.find("(cpu, Vulkan") != std::string::npos;
  const std::string picked = cpu_device ? "cpu" : "vulkan";
  CHECK_MESSAGE(dev.out.find("auto backend there: " + picked) != std::string::npos, dev.out);
  CHECK_MESSAGE(dev.out.find("auto backend: " + picked + ": ") != std::string::npos, dev.out);
  // ... and the solver's per-device layout there (gpu::device_layout).
  CHECK_MESSAGE(dev.out.find(std::string("solver layout there: ") + (cpu_device ? "texel" : "storage")) !=
                    std::string::npos,
                dev.out);
  if (cpu_device)
    CHECK_MESSAGE(dev.out.find("CPU implementation of Vulkan") != std::string::npos, dev.out);

  const std::string args = "render " + scenes + "/cloth_on_sphere.json --steps 16 --size 160x120 --out ";
  const fs::path by_default = tmp_dir() / "backend_default.png", by_auto = tmp_dir() / "backend_auto.png",
                 by_vulkan = tmp_dir() / "backend_vulkan.png";
  const Outcome d = run_vkcloth("backend_default", args + by_default.string(), "VKCLOTH_VALIDATION=1");
  const Outcome a =
      run_vkcloth("backend_auto", args + by_auto.string() + " --backend auto", "VKCLOTH_VALIDATION=1");
  const Outcome v =
      run_vkcloth("backend_vulkan", args + by_vulkan.string() + " --backend vulkan", "VKCLOTH_VALIDATION=1");
  for (const Outcome* o : {&d, &a, &v}) {
    REQUIRE_MESSAGE(o->code == 0, o->err);
    CHECK_MESSAGE(o->err.find("alidation") == std::string::npos, o->err);
  }
  CHECK_MESSAGE(d.out.find("backend: " + picked + " (") != std::string::npos, d.out);
  CHECK_MESSAGE(a.out.find("backend: " + picked + " (") != std::string::npos, a.out);
  CHECK_MESSAGE(v.out.find("backend: vulkan (--backend vulkan on ") != std::string::npos, v.out);
  auto id = vkcloth::render::load_image(by_default), ia = vkcloth::render::load_image(by_auto),
       iv = vkcloth::render::load_image(by_vulkan);
  REQUIRE(id);
  REQUIRE(ia);
  REQUIRE(iv);
  CHECK(id->rgba == ia->rgba);
  // The same frame on both backends: bit for bit on lavapipe (the CPU solver reproduces the GPU's
  // semi-implicit Euler exactly), else within the golden-image metric.
  if (cpu_device)
    CHECK(ia->rgba == iv->rgba);
  CHECK(vkcloth::render::test::compare(*ia, *iv).fraction < vkcloth::render::test::golden_max_fraction);
}

TEST_CASE("render: an unknown --backend is exit 2 naming the accepted values") {
  const Outcome o =
      run_vkcloth("backend_bad", "render " + scenes + "/cloth_on_sphere.json --backend gpu --out " +
                                     (tmp_dir() / "never.png").string());
  CHECK(o.code == 2);
  CHECK_MESSAGE(o.err.find("auto,cpu,vulkan") != std::string::npos, o.err);
}

TEST_CASE("render: --out must end in .png and --camera names the number that is not finite (exit 2)") {
  // Both before any device work: they hold without a Vulkan device too.
  const Outcome jpg = run_vkcloth("out_jpg", "render " + scenes + "/cloth_on_sphere.json --steps 1 --out " +
                                                 (tmp_dir() / "never.jpg").string());
  CHECK(jpg.code == 2);
  CHECK_MESSAGE(jpg.err.find("the file must end in .png") != std::string::npos, jpg.err);
  CHECK_FALSE(fs::exists(tmp_dir() / "never.jpg"));
  const Outcome cam = run_vkcloth("camera_huge", "render " + scenes +
                                                     "/cloth_on_sphere.json --steps 1 --camera "
                                                     "1,1e308,0,0,0,0 --out " +
                                                     (tmp_dir() / "never.png").string());
  CHECK(cam.code == 2);
  CHECK_MESSAGE(cam.err.find("number 2 is not a finite float") != std::string::npos, cam.err);
  const Outcome five = run_vkcloth(
      "camera_five", "render " + scenes + "/cloth_on_sphere.json --steps 1 --camera 1,2,3,4,5 --out " +
                         (tmp_dir() / "never.png").string());
  CHECK(five.code == 2);
  CHECK_MESSAGE(five.err.find("expected six numbers") != std::string::npos, five.err);
  CHECK_MESSAGE(five.err.find("got 5") != std::string::npos, five.err);
}
