// SPDX-License-Identifier: MIT
// What the figures share (cloth_drawing.hpp): the offscreen drawing set-up, the "display" solver that
// holds a run's final positions for the renderer (cloth.cpp explains why), the simulation of a scene on
// either backend, the camera framing and the labelled image grid drawn from the runs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "cloth_drawing.hpp"
#include "figures.hpp"
#include "image_grid.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/material.hpp"
#include "vkcloth/measure.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::figures {

Result<void> open_drawing(const Gallery& G, Drawing& d, std::string_view group) {
  if (G.quick)
    d.w = 240, d.h = 180;
  gpu::ContextOptions o;
  o.require_graphics = true;
  auto ctx = gpu::Context::create(o);
  if (ctx) {
    d.ctx.emplace(std::move(*ctx));
    auto t = render::OffscreenTarget::create(*d.ctx, d.w, d.h);
    if (!t)
      return t.error();
    d.target.emplace(std::move(*t));
  } else if (G.backend == "vulkan" || ctx.error().code != ErrorCode::no_device) {
    return ctx.error();
  } else {
    d.unavailable = ctx.error().message;
    fmt::print(stderr,
               "figures: no Vulkan device ({}): the {} numbers are computed, the {} pictures are skipped\n",
               d.unavailable, group, group);
  }
  return {};
}

Result<gpu::GpuSolver> display_solver(gpu::Context& ctx, Run& run) {
  run.drawn = run.scene.system;
  for (std::size_t i = 0; i < run.pos.size(); ++i) {
    run.drawn.particles[i].position = run.pos[i];
    run.drawn.particles[i].velocity = glm::dvec3(0.0);
    run.drawn.particles[i].pinned = true;
  }
  auto s = gpu::GpuSolver::create(ctx, run.drawn, run.scene.params);
  if (!s)
    return s.error();
  // Every particle is pinned: the step moves nothing and rebuilds the normals for the shading.
  VKCLOTH_TRY(s->simulate(1));
  return s;
}

std::vector<glm::dvec3> to_d(std::span<const glm::vec3> v) {
  return {v.begin(), v.end()};
}

Result<Run> simulate_cloth(Drawing& d, Scene scene, std::uint64_t steps, const std::string& backend) {
  Run run;
  run.scene = std::move(scene);
  for (const Particle& p : run.scene.system.particles)
    run.initial.push_back(p.position);
  if (backend == "vulkan") {
    auto s = gpu::GpuSolver::create(*d.ctx, run.scene.system, run.scene.params);
    if (!s)
      return s.error();
    if (auto r = s->simulate(steps); !r) {
      if (r.error().code != ErrorCode::diverged)
        return r.error();
      run.diverged = r.error().message;
    }
    auto p = s->positions();
    if (!p)
      return p.error();
    run.pos = to_d(*p);
  } else {
    auto s = CpuSolver<float>::create(run.scene.system, run.scene.params);
    if (!s)
      return s.error();
    if (auto r = s->run(steps); !r) {
      if (r.error().code != ErrorCode::diverged)
        return r.error();
      run.diverged = r.error().message;
    }
    run.pos = to_d(s->positions());
  }
  // Both backends are drawn the same way, from a display solver holding the final positions: the
  // simulating GpuSolver's normals are those of its last force pass, one step behind its positions.
  if (d.ctx) {
    auto g = display_solver(*d.ctx, run);
    if (!g)
      return g.error();
    run.gpu.emplace(std::move(*g));
  }
  return run;
}

/// Pulls the camera in until the 8 corners of `b` just fit the view (with a small margin):
/// Camera::frame fits the bounds' sphere, which leaves a flat cloth small in the picture.
render::Camera tighten(render::Camera c, const render::Bounds& b, float aspect) {
  const glm::vec3 fwd = glm::normalize(c.target - c.eye);
  const glm::vec3 right = glm::normalize(glm::cross(fwd, c.up));
  const glm::vec3 up = glm::cross(right, fwd);
  const float tv = std::tan(glm::radians(c.fov_y_degrees) * 0.5f), th = tv * aspect;
  float dist = 0.05f;
  for (int k = 0; k < 8; ++k) {
    const glm::vec3 p{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z};
    const glm::vec3 q = p - c.target;
    const float toward_eye = -glm::dot(q, fwd);
    dist = std::max(
        {dist, toward_eye + std::abs(glm::dot(q, right)) / th, toward_eye + std::abs(glm::dot(q, up)) / tv});
  }
  dist *= 1.06f; // margin
  const float r = std::max(b.radius(), 0.05f);
  c.eye = c.target - fwd * dist;
  c.near_plane = std::max(dist - 3.0f * r, dist * 0.01f);
  c.far_plane = dist + 20.0f * r + 1.0f;
  return c;
}

/// One camera for all panels of a figure: framed tightly on the union of their final states and
/// (with `with_spheres`) their spheres.
render::Camera frame(const std::vector<const Run*>& runs, float aspect, glm::vec3 from, bool with_spheres) {
  render::Bounds b{glm::vec3(1e30f), glm::vec3(-1e30f)};
  for (const Run* r : runs) {
    for (const glm::dvec3& p : r->pos)
      if (glm::length(p) < 50.0)
        b.lo = glm::min(b.lo, glm::vec3(p)), b.hi = glm::max(b.hi, glm::vec3(p));
    if (with_spheres)
      for (const Collider& c : r->scene.params.colliders)
        if (c.type == Collider::Type::sphere) {
          b.lo = glm::min(b.lo, glm::vec3(c.center - c.radius));
          b.hi = glm::max(b.hi, glm::vec3(c.center + c.radius));
        }
  }
  return tighten(render::Camera::frame(b, aspect, from, 35.0f), b, aspect);
}

Result<render::Image> draw(Drawing& d, Run& run, const render::Camera& cam) {
  render::RendererOptions ro;
  ro.render_pass = d.target->render_pass();
  auto rend = render::ClothRenderer::create(*d.ctx, *run.gpu, *run.gpu->topology(), std::move(ro));
  if (!rend)
    return rend.error();
  return d.target->render(*run.gpu, *rend, cam, 0);
}

Result<void> grid_figure(Gallery& G, Drawing& d, std::vector<Run>& runs,
                         const std::vector<std::string>& labels, const std::string& file,
                         const std::string& section, const std::string& title, const std::string& caption,
                         glm::vec3 from, bool with_spheres, std::size_t columns) {
  if (!d.ctx)
    return {};
  std::vector<const Run*> all;
  for (const Run& r : runs)
    all.push_back(&r);
  return grid_figure(G, d, runs, labels, file, section, title, caption,
                     frame(all, float(d.w) / float(d.h), from, with_spheres), columns);
}

Result<void> grid_figure(Gallery& G, Drawing& d, std::vector<Run>& runs,
                         const std::vector<std::string>& labels, const std::string& file,
                         const std::string& section, const std::string& title, const std::string& caption,
                         const render::Camera& cam, std::size_t columns) {
  if (!d.ctx)
    return {};
  std::vector<Panel> panels;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    auto img = draw(d, runs[i], cam);
    if (!img)
      return img.error();
    panels.push_back({std::move(*img), labels[i] + (runs[i].diverged.empty() ? "" : " (DIVERGED)")});
  }
  VKCLOTH_TRY(render::write_png(G.dir / file, compose_grid(panels, title, columns)));
  G.figures.push_back({file, section, title, caption});
  return {};
}

/// Height of the lowest particle (m).
double min_z(const Run& r) {
  double z = 1e30;
  for (const glm::dvec3& p : r.pos)
    z = std::min(z, p.z);
  return z;
}

/// Largest structural strain (|x_b - x_a| - L0) / L0 of the final state (vkcloth/measure.hpp).
double max_strain(const Run& r) {
  auto s = structural_strain(r.scene.system, r.pos);
  return s ? s->max : std::nan("");
}

void Progress::operator()(std::string_view what) const {
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  fmt::print(stderr, "figures: {} {} ({:.1f} s)\n", group_, what, s);
}

} // namespace vkcloth::figures
