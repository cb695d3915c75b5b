// SPDX-License-Identifier: MIT
// Collider shapes drawn where they are: a box, a capsule and a mesh collider appear in their
// palette colour at the projection of a point inside each (a convex shape's interior point is
// seen through its own front surface), and where set_colliders() (InstanceBuffers) or the
// solver's parameters (record_draw(cmd, solver)) move them, no longer at their old place.
// scene_bounds() frames them.
//
// The renderer alone is under test: the cloth is a small static CpuSolver cloth (or a GpuSolver's
// with a sphere) off to the side; the shapes come from the SimParams the renderer is created with.
#include "render_test_util.hpp"

#include <array>

#include <glm/geometric.hpp>

#include "vkcloth/builders.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/render/host_buffers.hpp"

using namespace vkcloth;
using namespace vkcloth::render;
using namespace vkcloth::render::test;

namespace {

constexpr std::uint32_t W = 240, H = 180;

/// A tetrahedron 0.5 m tall in its own frame (origin at the middle of its base).
std::shared_ptr<const ColliderMesh> tetrahedron() {
  const std::array<glm::dvec3, 4> p = {glm::dvec3(-0.2, -0.15, 0.0), glm::dvec3(0.2, -0.15, 0.0),
                                       glm::dvec3(0.0, 0.22, 0.0), glm::dvec3(0.0, 0.0, 0.5)};
  const std::array<std::uint32_t, 12> tri = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
  auto m = ColliderMesh::create(p, tri, "tetrahedron");
  REQUIRE_MESSAGE(m, (m ? "" : m.error().message));
  return *m;
}

/// The floor, then a box, a capsule and the tetrahedron in a row along x, each raised by `lift`.
std::vector<Collider> shapes(const std::shared_ptr<const ColliderMesh>& mesh, double lift) {
  const glm::dvec3 up(0.0, 0.0, lift);
  return {Collider::plane({0, 0, 1}, 0.0),
          Collider::box(glm::dvec3(-0.55, 0.0, 0.25) + up, {0.2, 0.12, 0.25},
                        Collider::rotation_from_degrees({0.0, 0.0, 30.0})),
          Collider::capsule(glm::dvec3(0.0, -0.22, 0.2) + up, glm::dvec3(0.05, 0.22, 0.35) + up, 0.1),
          Collider::triangle_mesh(mesh, glm::dvec3(0.55, 0.0, 0.0) + up,
                                  Collider::rotation_from_degrees({0.0, 0.0, -20.0}), 0.01)};
}

/// A point inside each shape (the floor's: none) whose pixel must show it.
glm::vec3 inside(const Collider& k) {
  switch (k.type) {
  case Collider::Type::capsule:
    return glm::vec3((k.a + k.b) * 0.5);
  case Collider::Type::mesh:
    return glm::vec3(k.center + k.rotation * glm::dvec3(0.0, -0.02, 0.125)); // the tetrahedron's centroid
  default:
    return glm::vec3(k.center);
  }
}

/// True when `c` (0..255) is a lit shade of `albedo` (0..1): c = k albedo 255 + s (1, 1, 1) within
/// 12 a channel, with k a lit fraction (ambient 0.35 .. full light) and s a little white
/// highlight. A grey, the background or another palette colour does not fit.
bool shade_of(glm::vec3 c, glm::vec3 albedo) {
  const glm::vec3 a = albedo * 255.0f, one(1.0f);
  // Least squares in (k, s): [a.a a.1; a.1 3] [k s]^T = [a.c 1.c].
  const float aa = glm::dot(a, a), a1 = glm::dot(a, one), ac = glm::dot(a, c), c1 = glm::dot(c, one);
  const float det = aa * 3.0f - a1 * a1;
  const float k = (ac * 3.0f - a1 * c1) / det, s = (aa * c1 - a1 * ac) / det;
  const float residual = max_abs(c, k * a + s * one);
  INFO("pixel " << c.r << ", " << c.g << ", " << c.b << " = " << k << " x albedo + " << s << " (residual "
                << residual << ")");
  return k > 0.3f && k < 1.1f && s > -8.0f && s < 45.0f && residual < 12.0f;
}

struct Probe {
  std::uint32_t x = 0, y = 0;
};

Probe pixel_of(const Camera& cam, glm::vec3 p) {
  const auto [x, y] = pixel_in(cam, p, W, H);
  return {x, y};
}

glm::vec3 colour_of(const Palette& pal, Collider::Type t) {
  switch (t) {
  case Collider::Type::sphere:
    return pal.sphere;
  case Collider::Type::capsule:
    return pal.capsule;
  case Collider::Type::box:
    return pal.box;
  case Collider::Type::mesh:
    return pal.mesh;
  default:
    return pal.floor;
  }
}

/// A 3 x 3 cloth, 0.2 m, lying on the floor behind the shapes.
ParticleSystem small_cloth() {
  ClothDesc d;
  d.nx = d.ny = 3;
  d.size = {0.2, 0.2};
  d.origin = {-0.1, 0.9, 0.01};
  d.orientation = ClothOrientation::horizontal;
  auto cloth = make_cloth(d);
  REQUIRE_MESSAGE(cloth, (cloth ? "" : cloth.error().message));
  return std::move(*cloth);
}

} // namespace

TEST_CASE("camera: scene_bounds holds capsules, rotated boxes and posed meshes") {
  const ParticleSystem cloth = small_cloth();
  SimParams p;
  p.colliders = {Collider::capsule({-2.0, 0.0, 0.5}, {-1.0, 0.0, 0.5}, 0.25)};
  Bounds b = scene_bounds(cloth, p);
  CHECK(b.lo.x == doctest::Approx(-2.25));
  CHECK(b.lo.z == doctest::Approx(0.01)); // the cloth is lower than the capsule's bottom, 0.25
  CHECK(b.hi.z == doctest::Approx(0.75));

  // A box turned 90 degrees about z: its x half extent lies along y.
  p.colliders = {
      Collider::box({0.0, -3.0, 0.0}, {1.0, 0.5, 0.25}, Collider::rotation_from_degrees({0, 0, 90}))};
  b = scene_bounds(cloth, p);
  CHECK(b.lo.y == doctest::Approx(-4.0));
  CHECK(b.lo.x == doctest::Approx(-0.5));
  CHECK(b.lo.z == doctest::Approx(-0.25));

  // The tetrahedron's apex (0, 0, 0.5), turned 90 degrees about x, points along -y.
  p.colliders = {Collider::triangle_mesh(tetrahedron(), {0.0, -1.0, 2.0},
                                         Collider::rotation_from_degrees({90, 0, 0}), 0.01)};
  b = scene_bounds(cloth, p);
  CHECK(b.lo.y == doctest::Approx(-1.5));
  CHECK(b.hi.z == doctest::Approx(2.22)); // the base vertex (0, 0.22, 0) turned up to z = +0.22
}

TEST_CASE(
    "content: box, capsule and mesh colliders drawn where they are, then where set_colliders moves them") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  const auto mesh = tetrahedron();
  const ParticleSystem cloth = small_cloth();
  SimParams physics; // the solver's: the floor only (the renderer alone is under test)
  physics.colliders = {Collider::plane({0, 0, 1}, 0.0)};
  auto cpu = CpuSolver<float>::create(cloth, physics);
  REQUIRE_MESSAGE(cpu, (cpu ? "" : cpu.error().message));
  auto host = HostClothBuffers::create(ctx, *cpu->topology(), 1);
  REQUIRE_MESSAGE(host, (host ? "" : host.error().message));
  auto buffers = host->upload(0, cpu->positions(), cpu->normals());
  REQUIRE(buffers);

  SimParams drawn;
  drawn.colliders = shapes(mesh, 0.0);
  const std::vector<Collider> moved = shapes(mesh, 0.6);
  auto target = OffscreenTarget::create(ctx, W, H);
  REQUIRE(target);
  RendererOptions ro;
  ro.render_pass = target->render_pass();
  auto renderer = ClothRenderer::create(ctx, drawn, *cpu->topology(), std::move(ro));
  REQUIRE_MESSAGE(renderer, (renderer ? "" : renderer.error().message));
  // Framed on both poses, so both are in view.
  SimParams both = drawn;
  both.colliders.insert(both.colliders.end(), moved.begin() + 1, moved.end());
  const Camera cam = Camera::frame(scene_bounds(cloth, both), float(W) / float(H));
  const Palette& pal = renderer->palette();

  auto before = target->render(*buffers, *renderer, cam);
  REQUIRE(before);
  REQUIRE(write_png(out_dir() / "colliders_before.png", *before));
  for (std::size_t i = 1; i < drawn.colliders.size(); ++i) {
    const Collider& k = drawn.colliders[i];
    CAPTURE(i);
    const Probe at = pixel_of(cam, inside(k));
    CHECK(shade_of(rgb(*before, at.x, at.y), colour_of(pal, k.type)));
    const Probe there = pixel_of(cam, inside(moved[i]));
    CHECK_FALSE(shade_of(rgb(*before, there.x, there.y), colour_of(pal, k.type)));
  }
  // The box's faces are lit differently (flat normals: its edges show): pixels on its top face and
  // on its front face differ clearly.
  {
    const Collider& box = drawn.colliders[1];
    const glm::vec3 top = glm::vec3(box.center) + glm::vec3(0.0f, 0.0f, 0.24f);
    const glm::vec3 toward = glm::normalize(glm::vec3(box.rotation[1]) * (cam.eye.y < 0.0f ? -1.0f : 1.0f));
    const glm::vec3 front = glm::vec3(box.center) + 0.11f * toward;
    const Probe t = pixel_of(cam, top), f = pixel_of(cam, front);
    const glm::vec3 ct = rgb(*before, t.x, t.y), cf = rgb(*before, f.x, f.y);
    CHECK(shade_of(ct, pal.box));
    CHECK(shade_of(cf, pal.box));
    CHECK(max_abs(ct, cf) > 15.0f);
  }

  // Moved up by 0.6 m: drawn at the new place, and the old place shows what is behind it.
  REQUIRE(renderer->set_colliders(moved));
  auto after = target->render(*buffers, *renderer, cam);
  REQUIRE(after);
  REQUIRE(write_png(out_dir() / "colliders_after.png", *after));
  for (std::size_t i = 1; i < moved.size(); ++i) {
    CAPTURE(i);
    const Probe now = pixel_of(cam, inside(moved[i]));
    CHECK(shade_of(rgb(*after, now.x, now.y), colour_of(pal, moved[i].type)));
    const Probe old = pixel_of(cam, inside(drawn.colliders[i]));
    CHECK_FALSE(shade_of(rgb(*after, old.x, old.y), colour_of(pal, moved[i].type)));
  }

  // A capsule whose ends meet is a sphere of its radius: its centre is capsule-coloured, a point
  // 0.15 m along its old axis (inside the long capsule) no longer is.
  std::vector<Collider> ball = drawn.colliders;
  ball[2].a = ball[2].b = glm::dvec3(0.0, 0.0, 0.28);
  REQUIRE(renderer->set_colliders(ball));
  auto sphere = target->render(*buffers, *renderer, cam);
  REQUIRE(sphere);
  {
    const Probe c = pixel_of(cam, {0.0f, 0.0f, 0.28f});
    CHECK(shade_of(rgb(*sphere, c.x, c.y), pal.capsule));
    const Probe end = pixel_of(cam, glm::vec3(drawn.colliders[2].a) + glm::vec3(0.0f, 0.03f, 0.0f));
    CHECK_FALSE(shade_of(rgb(*sphere, end.x, end.y), pal.capsule));
  }

  // Not the create()-time list: refused, nothing changed (the next frame is the last one again).
  {
    auto fewer = renderer->set_colliders(std::span(moved).first(2));
    REQUIRE_FALSE(fewer);
    CHECK(fewer.error().code == ErrorCode::invalid_argument);
    CHECK(fewer.error().message.find("2 colliders") != std::string::npos);
    std::vector<Collider> swapped = moved;
    std::swap(swapped[1], swapped[2]);
    auto types = renderer->set_colliders(swapped);
    REQUIRE_FALSE(types);
    CHECK(types.error().message.find("collider 1") != std::string::npos);
    std::vector<Collider> other = moved;
    other[3].mesh = tetrahedron(); // the same triangles, another ColliderMesh
    auto meshes = renderer->set_colliders(other);
    REQUIRE_FALSE(meshes);
    CHECK(meshes.error().message.find("collider 3") != std::string::npos);
    auto again = target->render(*buffers, *renderer, cam);
    REQUIRE(again);
    CHECK(again->rgba == sphere->rgba);
  }
}

TEST_CASE(
    "content: record_draw(cmd, solver) draws the solver's colliders where its parameters put them now") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  Scene scene;
  scene.system = small_cloth();
  scene.params.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({-0.4, 0.0, 0.2}, 0.18)};
  scene.params.gravity = glm::dvec3(0.0);
  SimParams moved = scene.params;
  moved.colliders[1].center = glm::dvec3(0.4, 0.0, 0.2);
  SimParams both = scene.params;
  both.colliders.push_back(moved.colliders[1]);
  const Camera cam = Camera::frame(scene_bounds(scene.system, both), float(W) / float(H));
  auto rig = make_rig(ctx, std::move(scene), W, H);
  const Palette& pal = rig->renderer.palette();
  const Probe old = pixel_of(cam, {-0.4f, 0.0f, 0.2f}), now = pixel_of(cam, {0.4f, 0.0f, 0.2f});

  auto first = rig->target.render(rig->solver, rig->renderer, cam, 1);
  REQUIRE(first);
  CHECK(shade_of(rgb(*first, old.x, old.y), pal.sphere));
  CHECK_FALSE(shade_of(rgb(*first, now.x, now.y), pal.sphere));

  REQUIRE(rig->solver.set_params(moved));
  auto second = rig->target.render(rig->solver, rig->renderer, cam, 1);
  REQUIRE(second);
  REQUIRE(write_png(out_dir() / "colliders_solver_moved.png", *second));
  CHECK(shade_of(rgb(*second, now.x, now.y), pal.sphere));
  CHECK_FALSE(shade_of(rgb(*second, old.x, old.y), pal.sphere));

  // A collider the solver no longer has is not drawn.
  moved.colliders.pop_back();
  REQUIRE(rig->solver.set_params(moved));
  auto third = rig->target.render(rig->solver, rig->renderer, cam, 1);
  REQUIRE(third);
  CHECK_FALSE(shade_of(rgb(*third, now.x, now.y), pal.sphere));
}
