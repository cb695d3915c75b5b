// SPDX-License-Identifier: MIT
// Content checks that a blank or wrong image cannot pass: known 3D points projected with the same
// camera land on pixels of the expected colour; the texture's pattern shows; the two faces of the
// cloth are shaded differently.
#include "render_test_util.hpp"

#include <glm/geometric.hpp>

using namespace vkcloth;
using namespace vkcloth::render;
using namespace vkcloth::render::test;

namespace {

constexpr std::uint32_t W = 200, H = 150;

/// Pixel of `p`, REQUIREd inside the image with a margin.
std::pair<std::uint32_t, std::uint32_t> pixel_of(const Camera& cam, glm::vec3 p) {
  return pixel_in(cam, p, W, H);
}

/// Where the segment eye -> p crosses the flat initial cloth (z = 0.8, |x|,|y| <= 0.5).
bool hidden_by_flat_cloth(glm::vec3 eye, glm::vec3 p) {
  if ((eye.z - 0.8f) * (p.z - 0.8f) >= 0.0f)
    return false;
  const float t = (0.8f - eye.z) / (p.z - eye.z);
  const glm::vec3 x = eye + t * (p - eye);
  return std::abs(x.x) <= 0.55f && std::abs(x.y) <= 0.55f;
}

/// Luminance samples of the cloth at a 7 x 7 grid of points inside it (flat, z = z0).
std::vector<float> cloth_samples(const Image& img, const Camera& cam, float z0) {
  std::vector<float> out;
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 7; ++i) {
      const glm::vec3 p(-0.3f + 0.1f * float(i), -0.3f + 0.1f * float(j), z0);
      auto [x, y] = pixel_of(cam, p);
      const glm::vec3 c = rgb(img, x, y);
      out.push_back(0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b);
    }
  return out;
}

float mean(const std::vector<float>& v) {
  float s = 0;
  for (float x : v)
    s += x;
  return s / float(v.size());
}
float stddev(const std::vector<float>& v) {
  const float m = mean(v);
  float s = 0;
  for (float x : v)
    s += (x - m) * (x - m);
  return std::sqrt(s / float(v.size()));
}

} // namespace

TEST_CASE("content: background, cloth, sphere and floor where the camera must see them") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  auto rig = make_rig(ctx, load("cloth_on_sphere.json"), W, H);
  auto img = rig->target.render(rig->solver, rig->renderer, rig->camera, 1);
  REQUIRE(img);
  REQUIRE(write_png(out_dir() / "content_initial.png", *img));
  const Palette& pal = rig->renderer.palette();
  const Camera& cam = rig->camera;

  // Background: the top corners look over the floor's far edge into the clear colour.
  for (std::uint32_t x : {1u, W - 2})
    CHECK(max_abs(rgb(*img, x, 1), rgb255(pal.background)) <= 2.0f);

  // Cloth (flat at z = 0.8 after one step): its centre is neither background nor floor grey.
  {
    auto [x, y] = pixel_of(cam, {0.0f, 0.0f, 0.8f});
    const glm::vec3 c = rgb(*img, x, y);
    CHECK(max_abs(c, rgb255(pal.background)) > 40.0f);
    CHECK(std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b}) > 30.0f); // saturated fabric, not grey
  }

  // Sphere: its point facing the camera horizontally, 10% inside the silhouette; not behind the cloth.
  {
    const glm::vec3 centre(0.0f, 0.0f, 0.3f);
    glm::vec3 to_eye = cam.eye - centre;
    to_eye.z = 0.0f;
    const glm::vec3 p = centre + 0.3f * 0.85f * glm::normalize(to_eye);
    REQUIRE_FALSE(hidden_by_flat_cloth(cam.eye, p));
    auto [x, y] = pixel_of(cam, p);
    const glm::vec3 c = rgb(*img, x, y);
    INFO("sphere pixel " << c.r << ", " << c.g << ", " << c.b);
    CHECK(c.r > c.g + 50.0f);
    CHECK(c.r > c.b + 50.0f);
  }

  // Floor: points in front of the sphere towards the camera; grey (unsaturated), not background,
  // and both checker shades occur.
  {
    glm::vec3 dir = cam.eye - glm::vec3(0.0f);
    dir.z = 0.0f;
    dir = glm::normalize(dir);
    float lo = 1e9f, hi = -1e9f;
    int seen = 0;
    for (float d = 0.35f; d <= 1.5f; d += 0.05f) {
      const glm::vec3 p = d * dir;
      auto q = cam.project(p, W, H);
      if (!q || q->x < 2 || q->y < 2 || q->x >= W - 2 || q->y >= H - 2 || hidden_by_flat_cloth(cam.eye, p))
        continue;
      ++seen;
      const glm::vec3 c = rgb(*img, std::uint32_t(q->x), std::uint32_t(q->y));
      INFO("floor pixel at distance " << d << ": " << c.r << ", " << c.g << ", " << c.b);
      CHECK(std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b}) < 30.0f);
      CHECK(max_abs(c, rgb255(pal.background)) > 30.0f);
      lo = std::min(lo, c.g);
      hi = std::max(hi, c.g);
    }
    REQUIRE(seen >= 4);
    CHECK(hi - lo > 40.0f); // light and dark checker cells
  }
}

TEST_CASE("content: the texture's pattern is visible on the cloth") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  Image plain;
  plain.width = plain.height = 4;
  plain.rgba.assign(4 * 4 * 4, 200);
  float sd_fabric = 0, sd_plain = 0;
  for (int k = 0; k < 2; ++k) {
    auto rig = make_rig(ctx, load("cloth_on_sphere.json"), W, H, k ? plain : Image{});
    auto img = rig->target.render(rig->solver, rig->renderer, rig->camera, 1);
    REQUIRE(img);
    (k ? sd_plain : sd_fabric) = stddev(cloth_samples(*img, rig->camera, 0.8f));
  }
  INFO("luminance std-dev over 49 cloth points: fabric " << sd_fabric << ", plain " << sd_plain);
  CHECK(sd_fabric > 15.0f);
  CHECK(sd_plain < 4.0f);
}

TEST_CASE("content: the cloth's two faces are shaded differently") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  // No colliders, so nothing hides the cloth's underside; one step computes the normals.
  auto rig = make_rig(ctx, load("cloth_on_sphere.json", {"colliders=[]"}), W, H);
  Camera above, below;
  above.target = below.target = {0.0f, 0.0f, 0.8f};
  above.eye = {0.4f, -0.6f, 2.6f};
  below.eye = {0.4f, -0.6f, -1.0f};
  auto top = rig->target.render(rig->solver, rig->renderer, above, 1);
  REQUIRE(top);
  auto bottom = rig->target.render(rig->solver, rig->renderer, below, 0);
  REQUIRE(bottom);
  REQUIRE(write_png(out_dir() / "content_above.png", *top));
  REQUIRE(write_png(out_dir() / "content_below.png", *bottom));
  // The same cloth points seen from both sides (z barely moved in one step).
  const float z = 0.8f - 0.5f * 9.81f * 0.02f * 0.02f;
  const float a = mean(cloth_samples(*top, above, z)), b = mean(cloth_samples(*bottom, below, z));
  INFO("mean luminance from above " << a << ", from below " << b);
  CHECK(std::abs(a - b) > 0.2f * std::max(a, b));
}

TEST_CASE("camera: project() puts the target at the image centre") {
  Camera c;
  auto p = c.project(c.target, 160, 120);
  REQUIRE(p);
  CHECK(p->x == doctest::Approx(80.0f).epsilon(1e-4));
  CHECK(p->y == doctest::Approx(60.0f).epsilon(1e-4));
  CHECK_FALSE(c.project(c.eye + (c.eye - c.target), 160, 120)); // behind the camera
  // z is up: a point above the target is above it in the image (smaller y).
  auto up = c.project(c.target + glm::vec3(0.0f, 0.0f, 0.1f), 160, 120);
  REQUIRE(up);
  CHECK(up->y < p->y);
}

TEST_CASE("image: load_image errors name the file") {
  const auto dir = out_dir();
  auto missing = load_image(dir / "no_such_texture.png");
  REQUIRE_FALSE(missing);
  CHECK(missing.error().code == ErrorCode::io);
  CHECK(missing.error().message.find("no_such_texture.png") != std::string::npos);
  {
    std::FILE* f = std::fopen((dir / "corrupt.png").c_str(), "wb");
    REQUIRE(f);
    std::fputs("\x89PNG\r\n\x1a\n this is not a png", f);
    std::fclose(f);
  }
  auto corrupt = load_image(dir / "corrupt.png");
  REQUIRE_FALSE(corrupt);
  CHECK(corrupt.error().message.find("corrupt.png") != std::string::npos);
  {
    std::FILE* f = std::fopen((dir / "empty.png").c_str(), "wb");
    REQUIRE(f);
    std::fclose(f);
  }
  CHECK_FALSE(load_image(dir / "empty.png"));
  Image big;
  big.width = 64;
  big.height = 2;
  big.rgba.assign(64 * 2 * 4, 255);
  REQUIRE(write_png(dir / "wide.png", big));
  auto huge = load_image(dir / "wide.png", 32);
  REQUIRE_FALSE(huge);
  CHECK(huge.error().message.find("too large") != std::string::npos);
  auto ok = load_image(dir / "wide.png");
  REQUIRE(ok);
  CHECK(ok->width == 64);
  CHECK(ok->height == 2);
}

TEST_CASE("interaction: record_hold_particle moves one particle and zeroes its velocity") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  auto rig = make_rig(ctx, load("cloth_on_sphere.json"), 64, 48);
  REQUIRE(rig->solver.simulate(5));
  const std::uint32_t held = 37;
  const glm::vec3 where(0.2f, -0.1f, 1.5f);
  // Held, then 0 steps: the drawn frame and the readback see exactly the written position.
  auto img = rig->target.render(rig->solver, rig->renderer, rig->camera, 0, [&](VkCommandBuffer cmd) {
    record_hold_particle(ctx, cmd, rig->solver, held, where);
  });
  REQUIRE(img);
  auto p = rig->solver.positions();
  auto v = rig->solver.velocities();
  REQUIRE(p);
  REQUIRE(v);
  const glm::vec3 before = (*p)[held + 1] + glm::vec3(-0.1f, 0.0f, 0.0f); // its old place, about
  CHECK((*p)[held] == where);
  CHECK((*v)[held] == glm::vec3(0.0f));
  CHECK((*p)[held + 1].z < 0.9f); // the others are untouched
  // Held before 3 steps: the particle starts the steps from there; its stretched springs pull it
  // back towards the cloth, but it stays much nearer the hand than its old place.
  auto img2 = rig->target.render(rig->solver, rig->renderer, rig->camera, 3, [&](VkCommandBuffer cmd) {
    record_hold_particle(ctx, cmd, rig->solver, held, where);
  });
  REQUIRE(img2);
  p = rig->solver.positions();
  REQUIRE(p);
  CHECK(glm::length((*p)[held] - where) < 0.5f * glm::length(before - where));
}
