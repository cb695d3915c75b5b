// SPDX-License-Identifier: MIT
#include "vkcloth/render/camera.hpp"

#include <algorithm>
#include <cmath>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "vkcloth/collider_mesh.hpp"

namespace vkcloth::render {

float Bounds::radius() const {
  return 0.5f * glm::length(hi - lo);
}

Bounds scene_bounds(const ParticleSystem& system, const SimParams& params) {
  Bounds b{glm::vec3(INFINITY), glm::vec3(-INFINITY)};
  auto add = [&](glm::vec3 p) {
    b.lo = glm::min(b.lo, p);
    b.hi = glm::max(b.hi, p);
  };
  for (const Particle& p : system.particles)
    add(glm::vec3(p.position));
  if (system.particles.empty())
    add(glm::vec3(0.0f));
  const glm::vec3 c = b.center();
  // A box [center - e, center + e] around a point with half extents e.
  const auto add_box = [&](glm::dvec3 center, glm::dvec3 e) {
    add(glm::vec3(center - e));
    add(glm::vec3(center + e));
  };
  for (const Collider& k : params.colliders) {
    switch (k.type) {
    case Collider::Type::plane: {
      const glm::vec3 n = glm::normalize(glm::vec3(k.normal));
      add(c - (glm::dot(n, c) - float(k.offset)) * n);
      break;
    }
    case Collider::Type::sphere:
      add_box(k.center, glm::dvec3(k.radius));
      break;
    case Collider::Type::capsule:
      add_box(k.a, glm::dvec3(k.radius));
      add_box(k.b, glm::dvec3(k.radius));
      break;
    case Collider::Type::box: {
      // The rotated box's extent along world axis i: sum over its axes j of |R_ij| h_j.
      glm::dmat3 abs_r;
      for (int j = 0; j < 3; ++j)
        abs_r[j] = glm::abs(k.rotation[j]);
      add_box(k.center, abs_r * k.half_extents);
      break;
    }
    case Collider::Type::mesh:
      if (k.mesh)
        for (const ColliderMesh::Triangle& t : k.mesh->triangles())
          for (const glm::vec3& p : {t.a, t.b, t.c})
            add(glm::vec3(k.center + k.rotation * glm::dvec3(p)));
      break;
    }
  }
  return b;
}

glm::mat4 Camera::view() const {
  return glm::lookAtRH(eye, target, up);
}

glm::mat4 Camera::projection(float aspect) const {
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(fov_y_degrees), aspect, near_plane, far_plane);
  p[1][1] *= -1.0f; // Vulkan: y points down in framebuffer space
  return p;
}

std::optional<glm::vec3> Camera::project(glm::vec3 p, std::uint32_t width, std::uint32_t height) const {
  const glm::vec4 clip = view_projection(float(width) / float(height)) * glm::vec4(p, 1.0f);
  if (clip.w <= 0.0f)
    return std::nullopt;
  const glm::vec3 ndc = glm::vec3(clip) / clip.w;
  return glm::vec3((ndc.x * 0.5f + 0.5f) * float(width), (ndc.y * 0.5f + 0.5f) * float(height), ndc.z);
}

Camera Camera::frame(const Bounds& b, float aspect, glm::vec3 from, float fov_y_degrees) {
  Camera c;
  c.fov_y_degrees = fov_y_degrees;
  c.target = b.center();
  const float r = std::max(b.radius(), 0.05f);
  const float half_v = glm::radians(fov_y_degrees) * 0.5f;
  const float half_h = std::atan(std::tan(half_v) * aspect);
  const float dist = r / std::sin(std::min(half_v, half_h)) * 1.02f;
  c.eye = c.target + glm::normalize(from) * dist;
  c.near_plane = std::max(dist - 3.0f * r, dist * 0.01f);
  c.far_plane = dist + 20.0f * r + 1.0f;
  return c;
}

} // namespace vkcloth::render
