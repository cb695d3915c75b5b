// SPDX-License-Identifier: MIT
// A host that skins a character's arm every frame and drives the cloth through the API
// (docs/embedding.md "A skinned collider"): a two-bone cylinder (upper arm and forearm, the elbow
// bending 0 -> 70 -> 0 degrees and back) skinned with linear blend skinning, handed over as a mesh
// collider each frame (ColliderMesh::deformed: the hierarchy refitted, the corners' velocities for
// friction; then set_params); a sleeve of cloth whose top row the host holds on points of the arm's
// skin (set_pin_targets, max_distance 0). It prints what it measured each second and fails (exit 1)
// when a particle ends deeper than contact_epsilon in the arm or an attached one off its target.
// Exit 4 without a Vulkan device when --backend vulkan.
//
//   skinned_host [--backend cpu|vulkan] [--frames 240] [--validate]
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "vkcloth/vkcloth.hpp"

namespace {

constexpr double radius = 0.08, upper = 0.35, fore = 0.3, height = 1.0; // metres
constexpr int rings = 26, segments = 16;
constexpr double frame_dt = 1.0 / 60.0;

/// The arm at rest: a tube along +x from the shoulder (0, 0, height), rings of `segments` vertices.
struct Arm {
  std::vector<glm::dvec3> rest;
  std::vector<std::uint32_t> triangles;
};

/// Linear blend skinning's forearm weight of a rest point at x along the arm: 0 on the upper arm, 1
/// on the forearm, a smoothstep across the 12 cm around the elbow.
double forearm_weight(double x) {
  const double w = std::clamp((x - (upper - 0.06)) / 0.12, 0.0, 1.0);
  return w * w * (3.0 - 2.0 * w);
}

Arm make_arm() {
  Arm a;
  for (int r = 0; r < rings; ++r) {
    const double x = (upper + fore) * r / (rings - 1);
    for (int s = 0; s < segments; ++s) {
      const double phi = 2.0 * M_PI * s / segments;
      a.rest.push_back({x, radius * std::cos(phi), height + radius * std::sin(phi)});
    }
  }
  for (int r = 0; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) { // counter-clockwise seen from outside
      const auto i = std::uint32_t(r * segments + s), j = std::uint32_t(r * segments + (s + 1) % segments);
      a.triangles.insert(a.triangles.end(), {i, i + segments, j, j, i + segments, j + segments});
    }
  return a;
}

/// The elbow's angle (radians) at time t: down to 70 degrees and back every 2 s.
double elbow_angle(double t) {
  return glm::radians(70.0) * 0.5 * (1.0 - std::cos(M_PI * t));
}

/// Rest point p skinned at elbow angle `a`: the forearm turns down about the elbow's y axis.
glm::dvec3 skin(glm::dvec3 p, double a) {
  const glm::dvec3 elbow{upper, 0.0, height};
  const glm::dmat3 turn = glm::dmat3(glm::rotate(glm::dmat4(1.0), a, glm::dvec3(0, 1, 0)));
  const glm::dvec3 bent = elbow + turn * (p - elbow);
  return p + forearm_weight(p.x) * (bent - p);
}

struct Sleeve {
  vkcloth::ParticleSystem system;
  std::vector<std::uint32_t> top; // the attached particles
  std::vector<glm::dvec3> anchor; // their points on the arm at rest (skinned each frame)
};

/// A 24 x 12 sheet over the arm: its last row lies along the arm's top line (0.04 .. 0.61 m along
/// it, 6 mm above the skin) and is held there; the rest starts flat beside it, over -y, and drapes.
Sleeve make_sleeve() {
  vkcloth::ClothDesc d;
  d.nx = 24;
  d.ny = 12;
  d.size = {0.57, 0.36};
  d.origin = {0.04, -0.36, height + radius + 0.006};
  d.orientation = vkcloth::ClothOrientation::horizontal;
  d.pin_default_corners = false;
  d.particle_mass = 0.004;
  Sleeve s{vkcloth::make_cloth(d).value(), {}, {}};
  for (std::uint32_t i = 0; i < d.nx; ++i) {
    const std::uint32_t p = (d.ny - 1) * d.nx + i; // the row at y = 0
    s.top.push_back(p);
    s.anchor.push_back(s.system.particles[p].position);
  }
  return s;
}

// The two backends' step and readback.
vkcloth::Result<void> step(vkcloth::CpuSolver<float>& s) {
  return s.run(1);
}
vkcloth::Result<void> step(vkcloth::gpu::GpuSolver& s) {
  return s.simulate(1);
}
std::vector<glm::dvec3> positions(vkcloth::CpuSolver<float>& s) {
  return {s.positions().begin(), s.positions().end()};
}
std::vector<glm::dvec3> positions(vkcloth::gpu::GpuSolver& s) {
  auto x = s.positions();
  return x ? std::vector<glm::dvec3>(x->begin(), x->end()) : std::vector<glm::dvec3>{};
}

template <typename Solver>
int run(Solver& solver, vkcloth::SimParams params, const Arm& arm, const Sleeve& sleeve,
        std::shared_ptr<const vkcloth::ColliderMesh> mesh, int frames) {
  double deepest = -1.0, off_target = 0.0;
  std::vector<glm::dvec3> skinned(arm.rest.size());
  std::vector<vkcloth::PinTarget> targets(sleeve.top.size());
  for (int frame = 1; frame <= frames; ++frame) {
    const double a = elbow_angle(frame * frame_dt);
    for (std::size_t v = 0; v < arm.rest.size(); ++v)
      skinned[v] = skin(arm.rest[v], a);
    auto next = mesh->deformed(skinned, frame_dt); // refitted, with the corners' velocities
    if (!next)
      return std::printf("skinned_host: %s\n", next.error().message.c_str()), 1;
    mesh = *next;
    params.colliders[0].mesh = mesh;
    for (std::size_t k = 0; k < targets.size(); ++k)
      targets[k] = {sleeve.top[k], skin(sleeve.anchor[k], a), 0.0};
    if (auto r = solver.set_params(params); !r)
      return std::printf("skinned_host: %s\n", r.error().message.c_str()), 1;
    if (auto r = solver.set_pin_targets(targets); !r)
      return std::printf("skinned_host: %s\n", r.error().message.c_str()), 1;
    if (auto r = step(solver); !r)
      return std::printf("skinned_host: %s\n", r.error().message.c_str()), 1;
    const std::vector<glm::dvec3> x = positions(solver);
    auto depth = vkcloth::penetration(sleeve.system, params.colliders, x);
    if (!depth)
      return std::printf("skinned_host: %s\n", depth.error().message.c_str()), 1;
    deepest = std::max(deepest, depth->depth);
    for (const vkcloth::PinTarget& t : targets)
      off_target = std::max(off_target, glm::length(x[t.particle] - t.position));
    if (frame % 60 == 0)
      std::printf("t = %.2f s: elbow %.0f degrees, deepest in the arm %.2g m, attached off target %.2g m\n",
                  frame * frame_dt, glm::degrees(a), deepest, off_target);
  }
  const bool ok = deepest <= params.contact_epsilon && off_target <= 1e-5;
  std::printf("%s: deepest %.3g m (allowed %g), off target %.3g m (allowed 1e-05)\n", ok ? "ok" : "FAILED",
              deepest, params.contact_epsilon, off_target);
  return ok ? 0 : 1;
}

} // namespace

int main(int argc, char** argv) {
  std::string backend = "vulkan";
  int frames = 240;
  bool validate = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--backend" && i + 1 < argc)
      backend = argv[++i];
    else if (a == "--frames" && i + 1 < argc)
      frames = std::atoi(argv[++i]);
    else if (a == "--validate")
      validate = true;
    else
      return std::printf("usage: skinned_host [--backend cpu|vulkan] [--frames N] [--validate]\n"), 2;
  }
  if ((backend != "cpu" && backend != "vulkan") || frames < 1)
    return std::printf("skinned_host: --backend is cpu or vulkan, --frames >= 1\n"), 2;
  const Arm arm = make_arm();
  auto mesh = vkcloth::ColliderMesh::create(arm.rest, arm.triangles, "two-bone arm");
  if (!mesh)
    return std::printf("skinned_host: %s\n", mesh.error().message.c_str()), 1;
  const Sleeve sleeve = make_sleeve();
  vkcloth::SimParams params;
  params.dt = frame_dt;
  params.substeps = 10;
  params.integrator = vkcloth::Integrator::vbd;
  vkcloth::Collider collider = vkcloth::Collider::triangle_mesh(*mesh, {0, 0, 0}, glm::dmat3(1.0), 0.005);
  collider.friction = 0.4;
  params.colliders = {collider};
  if (backend == "cpu") {
    auto solver = vkcloth::CpuSolver<float>::create(sleeve.system, params);
    if (!solver)
      return std::printf("skinned_host: %s\n", solver.error().message.c_str()), 1;
    return run(*solver, params, arm, sleeve, *mesh, frames);
  }
  vkcloth::gpu::ContextOptions options;
  options.validation = validate;
  auto context = vkcloth::gpu::Context::create(options);
  if (!context)
    return std::printf("skinned_host: %s\n", context.error().message.c_str()), 4;
  int status = 1;
  {
    auto solver = vkcloth::gpu::GpuSolver::create(*context, sleeve.system, params);
    if (!solver)
      return std::printf("skinned_host: %s\n", solver.error().message.c_str()), 1;
    status = run(*solver, params, arm, sleeve, *mesh, frames);
  }
  if (validate && context->validation_message_count() > 0)
    return std::printf("skinned_host: %llu validation messages\n",
                       static_cast<unsigned long long>(context->validation_message_count())),
           1;
  return status;
}
