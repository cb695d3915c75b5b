// SPDX-License-Identifier: MIT
#include "view_input.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

namespace vkcloth::cli {
namespace {

Input& input_of(GLFWwindow* w) {
  return *static_cast<Input*>(host::Window::host_pointer(w));
}

/// The cursor's ray in world space.
struct Ray {
  glm::vec3 origin, dir;
};
Ray cursor_ray(const render::Camera& cam, double x, double y, VkExtent2D e) {
  const glm::mat4 inv = glm::inverse(cam.view_projection(float(e.width) / float(e.height)));
  const float nx = float(x) / float(e.width) * 2.0f - 1.0f, ny = float(y) / float(e.height) * 2.0f - 1.0f;
  glm::vec4 a = inv * glm::vec4(nx, ny, 0.0f, 1.0f), b = inv * glm::vec4(nx, ny, 1.0f, 1.0f);
  const glm::vec3 p0 = glm::vec3(a) / a.w, p1 = glm::vec3(b) / b.w;
  return {p0, glm::normalize(p1 - p0)};
}

} // namespace

void install_input_callbacks(host::Window& window, Input& input) {
  window.set_host_pointer(&input);
  glfwSetKeyCallback(window.glfw(), [](GLFWwindow* w, int key, int, int action, int) {
    Input& in = input_of(w);
    if (action != GLFW_PRESS && !(action == GLFW_REPEAT && (key == GLFW_KEY_S || key == GLFW_KEY_RIGHT)))
      return;
    switch (key) {
    case GLFW_KEY_ESCAPE:
      glfwSetWindowShouldClose(w, GLFW_TRUE);
      break;
    case GLFW_KEY_SPACE:
      in.paused = !in.paused;
      break;
    case GLFW_KEY_S:
    case GLFW_KEY_RIGHT:
      in.paused = true;
      in.step_once = true;
      break;
    case GLFW_KEY_R:
      in.reset = true;
      break;
    case GLFW_KEY_W:
      in.toggle_wind = true;
      break;
    default:
      break;
    }
  });
  glfwSetMouseButtonCallback(window.glfw(), [](GLFWwindow* w, int button, int action, int) {
    Input& in = input_of(w);
    if (button != GLFW_MOUSE_BUTTON_LEFT)
      return;
    in.left_down = action == GLFW_PRESS;
    (action == GLFW_PRESS ? in.left_pressed : in.left_released) = true;
  });
  glfwSetCursorPosCallback(window.glfw(), [](GLFWwindow* w, double x, double y) {
    Input& in = input_of(w);
    in.x = x;
    in.y = y;
  });
  glfwSetScrollCallback(window.glfw(), [](GLFWwindow* w, double, double y) { input_of(w).scroll += y; });
}

Orbit Orbit::framing(const render::Bounds& bounds, float aspect) {
  const render::Camera start = render::Camera::frame(bounds, aspect);
  const glm::vec3 off = start.eye - start.target;
  Orbit o;
  o.target = start.target;
  o.distance = glm::length(off);
  o.yaw = std::atan2(off.y, off.x);
  o.pitch = std::asin(off.z / o.distance);
  o.fov = start.fov_y_degrees;
  o.scene_radius = std::max(bounds.radius(), 0.05f);
  return o;
}

render::Camera Orbit::camera() const {
  render::Camera c;
  c.target = target;
  c.eye = target + distance * glm::vec3(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                        std::sin(pitch));
  c.fov_y_degrees = fov;
  c.near_plane = std::max(distance * 0.01f, distance - 4.0f * scene_radius);
  c.far_plane = distance + 30.0f * scene_radius + 10.0f;
  return c;
}

void apply_mouse(Input& input, Orbit& orbit, Hold& hold, host::DrawnCloth& solver, host::Window& window) {
  const render::Camera cam = orbit.camera();
  const VkExtent2D extent = window.extent(); // 0 x 0 while minimised: nothing to pick in
  if (input.scroll != 0.0) {
    orbit.distance *= std::pow(0.9f, float(input.scroll));
    orbit.distance =
        std::clamp(orbit.distance, 0.05f * orbit.scene_radius, 50.0f * orbit.scene_radius + 1.0f);
    input.scroll = 0.0;
  }
  if (input.left_pressed && extent.width) {
    input.left_pressed = false;
    // Pick the particle nearest to the cursor's ray (within 3% of the camera distance).
    const Ray ray = cursor_ray(cam, input.x, input.y, extent);
    window.wait_idle();
    if (auto pos = solver.positions()) {
      float best = 0.03f * orbit.distance;
      for (std::uint32_t i = 0; i < pos->size(); ++i) {
        const glm::vec3 d = (*pos)[i] - ray.origin;
        const float along = glm::dot(d, ray.dir);
        if (along <= 0.0f)
          continue;
        const float off = glm::length(d - along * ray.dir);
        if (off < best) {
          best = off;
          hold.particle = i;
          hold.position = (*pos)[i];
        }
      }
      hold.drag_normal = glm::normalize(cam.target - cam.eye);
    }
  }
  if (input.left_released) {
    input.left_released = false;
    hold.particle.reset();
  }
  const double dx = input.x - input.last_x, dy = input.y - input.last_y;
  input.last_x = input.x;
  input.last_y = input.y;
  if (input.left_down && hold.particle && extent.width) {
    // Move the held particle in the plane through it facing the camera.
    const Ray ray = cursor_ray(cam, input.x, input.y, extent);
    const float denom = glm::dot(ray.dir, hold.drag_normal);
    if (std::abs(denom) > 1e-6f) {
      const float t = glm::dot(hold.position - ray.origin, hold.drag_normal) / denom;
      if (t > 0.0f)
        hold.position = ray.origin + t * ray.dir;
    }
  } else if (input.left_down) {
    orbit.yaw -= float(dx) * 0.008f;
    orbit.pitch = std::clamp(orbit.pitch + float(dy) * 0.008f, -1.5f, 1.5f);
  }
}

} // namespace vkcloth::cli
