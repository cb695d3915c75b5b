// SPDX-License-Identifier: MIT
// Mesh surfaces in the renderer: a flat, irregularly triangulated patch with a square
// hole and particles in shuffled order, drawn from above and from below (two-sided, no culling):
// the background shows through the hole and past the outer boundary, the cloth everywhere on it;
// an encoded (PNG) texture colours it; decode_image's errors name the bytes' source.
#include "render_test_util.hpp"

#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <utility>

#include "vkcloth/mesh.hpp"

using namespace vkcloth;
using namespace vkcloth::render;
using namespace vkcloth::render::test;

namespace {

constexpr std::uint32_t W = 200, H = 150;
constexpr float plane_z = 0.5f; // the patch, flat and still (no gravity)

/// An 11 x 11 lattice over [-0.5, 0.5]^2 at z = plane_z, a random diagonal per cell, the 4 x 4
/// cells |x|, |y| < 0.2 left out (the hole), unused points dropped, the rest shuffled; springs on
/// the unique triangle edges at their rest length.
ParticleSystem holed_patch() {
  constexpr std::uint32_t m = 11;
  std::mt19937 rng(7u);
  std::vector<std::uint32_t> tris;
  for (std::uint32_t j = 0; j + 1 < m; ++j)
    for (std::uint32_t i = 0; i + 1 < m; ++i) {
      if (i >= 3 && i < 7 && j >= 3 && j < 7)
        continue;
      const std::uint32_t a = j * m + i, b = a + 1, c = a + m, d = c + 1; // counter-clockwise from +z
      if (rng() % 2)
        tris.insert(tris.end(), {a, b, d, a, d, c});
      else
        tris.insert(tris.end(), {a, b, c, b, d, c});
    }
  std::vector<bool> used(m * m, false);
  for (std::uint32_t t : tris)
    used[t] = true;
  std::vector<std::uint32_t> keep;
  for (std::uint32_t p = 0; p < m * m; ++p)
    if (used[p])
      keep.push_back(p);
  for (std::size_t k = keep.size(); k > 1; --k)
    std::swap(keep[k - 1], keep[rng() % k]);
  std::vector<std::uint32_t> new_index(m * m, 0);
  ParticleSystem s;
  Surface surface;
  for (std::uint32_t k = 0; k < keep.size(); ++k) {
    const std::uint32_t i = keep[k] % m, j = keep[k] / m;
    new_index[keep[k]] = k;
    Particle q;
    q.position = {-0.5 + 0.1 * i, -0.5 + 0.1 * j, double(plane_z)};
    q.mass = 0.05;
    s.particles.push_back(q);
    surface.uvs.push_back({float(i) / (m - 1), float(j) / (m - 1)});
  }
  for (std::uint32_t t : tris)
    surface.triangles.push_back(new_index[t]);
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::size_t t = 0; t < surface.triangles.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = surface.triangles[t + e], b = surface.triangles[t + (e + 1) % 3];
      if (edges.insert(std::minmax(a, b)).second)
        s.springs.push_back(Spring{a, b, glm::length(s.particles[a].position - s.particles[b].position), 40.0,
                                   SpringKind::structural});
    }
  s.surface = std::move(surface);
  s.finalize();
  return s;
}

SimParams still() {
  SimParams p;
  p.gravity = {0.0, 0.0, 0.0};
  return p;
}

struct MeshRig {
  gpu::GpuSolver solver;
  OffscreenTarget target;
  ClothRenderer renderer;
};

MeshRig make_mesh_rig(gpu::Context& ctx, RendererOptions ro = {}) {
  auto solver = gpu::GpuSolver::create(ctx, holed_patch(), still());
  REQUIRE_MESSAGE(solver, (solver ? "" : solver.error().message));
  auto target = OffscreenTarget::create(ctx, W, H);
  REQUIRE_MESSAGE(target, (target ? "" : target.error().message));
  ro.render_pass = target->render_pass();
  auto renderer = ClothRenderer::create(ctx, *solver, *solver->topology(), std::move(ro));
  REQUIRE_MESSAGE(renderer, (renderer ? "" : renderer.error().message));
  return {std::move(*solver), std::move(*target), std::move(*renderer)};
}

glm::vec3 pixel_at(const Image& img, const Camera& cam, glm::vec3 p) {
  const auto [x, y] = pixel_in(cam, p, W, H, 2.0f);
  return rgb(img, x, y);
}

/// A PNG file's bytes, written by write_png.
std::vector<std::uint8_t> png_bytes(const Image& img, const std::string& name) {
  const auto path = out_dir() / name;
  REQUIRE(write_png(path, img));
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Image solid(std::uint32_t w, std::uint32_t h, std::array<std::uint8_t, 3> c) {
  Image img;
  img.width = w;
  img.height = h;
  for (std::uint32_t k = 0; k < w * h; ++k)
    img.rgba.insert(img.rgba.end(), {c[0], c[1], c[2], 255});
  return img;
}

} // namespace

TEST_CASE("mesh render: the hole and the outside show the background, the cloth shows from both sides") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  MeshRig rig = make_mesh_rig(ctx);
  CHECK(rig.renderer.draws_cloth());
  const glm::vec3 background = rgb255(rig.renderer.palette().background);
  const Bounds b = scene_bounds(rig.solver.topology()->system(), still());
  const Camera views[2] = {Camera::frame(b, float(W) / float(H)),
                           Camera::frame(b, float(W) / float(H), {0.9f, -1.6f, -1.0f})};
  glm::vec3 ring_colour[2];
  for (int side = 0; side < 2; ++side) {
    CAPTURE(side); // 0: from above (the front), 1: from below
    const Camera& cam = views[side];
    auto img = rig.target.render(rig.solver, rig.renderer, cam, 1); // one step: the fan normals
    REQUIRE(img);
    REQUIRE(write_png(out_dir() / (side ? "mesh_hole_below.png" : "mesh_hole_above.png"), *img));
    // Inside the hole (0.05 m from its edges and nearer): nothing drawn.
    for (float x : {-0.15f, 0.0f, 0.15f})
      for (float y : {-0.15f, 0.0f, 0.15f}) {
        const glm::vec3 c = pixel_at(*img, cam, {x, y, plane_z});
        INFO("hole pixel at (" << x << ", " << y << "): " << c.r << ", " << c.g << ", " << c.b);
        CHECK(max_abs(c, background) <= 2.0f);
      }
    // On the cloth, between the hole and the outer boundary: the fabric on every side.
    glm::vec3 sum(0.0f);
    for (glm::vec2 at : {glm::vec2(-0.35f, 0.0f), glm::vec2(0.35f, 0.0f), glm::vec2(0.0f, -0.35f),
                         glm::vec2(0.0f, 0.35f), glm::vec2(-0.35f, -0.35f), glm::vec2(0.35f, 0.35f)}) {
      const glm::vec3 c = pixel_at(*img, cam, {at.x, at.y, plane_z});
      INFO("cloth pixel at (" << at.x << ", " << at.y << "): " << c.r << ", " << c.g << ", " << c.b);
      CHECK(max_abs(c, background) > 30.0f);
      sum += c;
    }
    ring_colour[side] = sum / 6.0f;
    // Past the outer boundary: nothing drawn.
    for (glm::vec2 at : {glm::vec2(-0.6f, 0.0f), glm::vec2(0.6f, 0.0f), glm::vec2(0.0f, 0.62f)}) {
      const glm::vec3 c = pixel_at(*img, cam, {at.x, at.y, plane_z});
      INFO("outside pixel at (" << at.x << ", " << at.y << "): " << c.r << ", " << c.g << ", " << c.b);
      CHECK(max_abs(c, background) <= 2.0f);
    }
  }
  // The back side is tinted (Palette::back_tint is bluest): bluer relative to red than the front.
  INFO("mean cloth colour above " << ring_colour[0].r << ", " << ring_colour[0].g << ", " << ring_colour[0].b
                                  << "; below " << ring_colour[1].r << ", " << ring_colour[1].g << ", "
                                  << ring_colour[1].b);
  CHECK(ring_colour[1].b / std::max(ring_colour[1].r, 1.0f) >
        1.2f * ring_colour[0].b / std::max(ring_colour[0].r, 1.0f));
}

TEST_CASE("mesh render: an encoded PNG texture (RendererOptions::encoded_texture) colours the cloth") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  RendererOptions ro;
  ro.encoded_texture = MeshTexture{"test green.png", png_bytes(solid(8, 4, {30, 200, 40}), "green.png")};
  MeshRig rig = make_mesh_rig(ctx, std::move(ro));
  const Camera cam =
      Camera::frame(scene_bounds(rig.solver.topology()->system(), still()), float(W) / float(H));
  auto img = rig.target.render(rig.solver, rig.renderer, cam, 1);
  REQUIRE(img);
  REQUIRE(write_png(out_dir() / "mesh_green.png", *img));
  for (glm::vec2 at : {glm::vec2(-0.35f, 0.0f), glm::vec2(0.35f, 0.1f), glm::vec2(0.1f, -0.35f)}) {
    const glm::vec3 c = pixel_at(*img, cam, {at.x, at.y, plane_z});
    INFO("cloth pixel " << c.r << ", " << c.g << ", " << c.b);
    CHECK(c.g > c.r + 60.0f);
    CHECK(c.g > c.b + 60.0f);
  }
}

TEST_CASE("mesh render: a corrupt encoded texture, or two textures, fail ClothRenderer::create clearly") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  auto solver = gpu::GpuSolver::create(ctx, holed_patch(), still());
  REQUIRE(solver);
  auto target = OffscreenTarget::create(ctx, 16, 16);
  REQUIRE(target);
  RendererOptions ro;
  ro.render_pass = target->render_pass();
  ro.encoded_texture = MeshTexture{"flag.glb images[0]", {0x89, 'P', 'N', 'G', 1, 2, 3, 4, 5}};
  auto bad = ClothRenderer::create(ctx, *solver, *solver->topology(), ro);
  REQUIRE_FALSE(bad);
  CHECK(bad.error().code == ErrorCode::io);
  CHECK(bad.error().message.find("flag.glb images[0]") != std::string::npos);
  ro.texture = solid(4, 4, {1, 2, 3});
  auto both = ClothRenderer::create(ctx, *solver, *solver->topology(), ro);
  REQUIRE_FALSE(both);
  CHECK(both.error().code == ErrorCode::invalid_argument);
  CHECK(both.error().message.find("flag.glb images[0]") != std::string::npos);
}

TEST_CASE("image: decode_image decodes PNG bytes, and its errors name the source") {
  Image gradient;
  gradient.width = 5;
  gradient.height = 3;
  for (std::uint32_t k = 0; k < 15; ++k)
    gradient.rgba.insert(gradient.rgba.end(), {std::uint8_t(k * 17), std::uint8_t(255 - k * 11),
                                               std::uint8_t(k * 3), std::uint8_t(255 - k)});
  const std::vector<std::uint8_t> png = png_bytes(gradient, "gradient.png");
  auto ok = decode_image(png, "gradient");
  REQUIRE_MESSAGE(ok, (ok ? "" : ok.error().message));
  CHECK(ok->width == 5);
  CHECK(ok->height == 3);
  CHECK(ok->rgba == gradient.rgba); // PNG is lossless, alpha included

  const auto fails = [](std::span<const std::uint8_t> bytes, std::uint32_t max_side, const char* expect) {
    auto r = decode_image(bytes, "scene.gltf images[2]", max_side);
    REQUIRE_FALSE(r);
    INFO(r.error().message);
    CHECK(r.error().code == ErrorCode::io);
    CHECK(r.error().message.find("scene.gltf images[2]") != std::string::npos);
    CHECK(r.error().message.find(expect) != std::string::npos);
  };
  fails({}, max_texture_size, "empty");
  const std::string text = "this is not an image at all";
  fails(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), max_texture_size,
        "not a readable PNG/JPEG image");
  // A PNG cut after its header: the size is readable, the pixels are not.
  fails(std::span(png).first(png.size() / 2), max_texture_size, "could not be decoded");
  fails(png, 4, "too large: 5 x 3");
}
