// SPDX-License-Identifier: MIT
// A look-at perspective camera for the renderer, with automatic framing of a scene and the
// projection of world points to pixels (tests use it to know where things must appear).
#pragma once

#include <cstdint>
#include <optional>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "vkcloth/params.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth::render {

/// Axis-aligned bounds of what a scene shows.
struct Bounds {
  glm::vec3 lo{0.0f}, hi{0.0f};
  glm::vec3 center() const { return (lo + hi) * 0.5f; }
  float radius() const; ///< half the diagonal
};

/// The particles' initial positions and the colliders where `params` has them: spheres, capsules
/// (both ends' spheres), boxes (their rotated corners' axis-aligned box) and meshes (their
/// vertices, posed). Planes are unbounded: the point of each plane under the particles' centre is
/// included, so the floor is in view.
Bounds scene_bounds(const ParticleSystem& system, const SimParams& params);

struct Camera {
  glm::vec3 eye{2.0f, -2.0f, 1.5f};
  glm::vec3 target{0.0f, 0.0f, 0.3f};
  glm::vec3 up{0.0f, 0.0f, 1.0f}; ///< z is up
  float fov_y_degrees = 40.0f;
  float near_plane = 0.01f;
  float far_plane = 100.0f;

  glm::mat4 view() const;
  /// Vulkan clip space (y down, depth 0..1).
  glm::mat4 projection(float aspect) const;
  glm::mat4 view_projection(float aspect) const { return projection(aspect) * view(); }
  /// Pixel coordinates (x right, y down, pixel centres at +0.5) and depth of `p` in a
  /// width x height image; nullopt when `p` is behind the camera.
  std::optional<glm::vec3> project(glm::vec3 p, std::uint32_t width, std::uint32_t height) const;

  /// A camera looking at `b` from direction `from` (towards the eye, default: front-right, above),
  /// far enough that the bounds' sphere fits the view at this aspect ratio.
  static Camera frame(const Bounds& b, float aspect, glm::vec3 from = {0.9f, -1.6f, 1.0f},
                      float fov_y_degrees = 40.0f);
};

} // namespace vkcloth::render
