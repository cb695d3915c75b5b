// SPDX-License-Identifier: MIT
// `vkcloth view`'s mouse and keyboard. The GLFW callbacks only record what happened (Input); once
// per frame, apply_mouse turns it into the orbit camera's motion or a held particle's drag.
// Keys: space pause, S / right arrow single step (repeats), R reset, W wind on/off, Esc quit.
#pragma once

#include "vkcloth_host_window/window.hpp" // first of the Vulkan headers: it brings volk

#include <cstdint>
#include <optional>

#include <glm/vec3.hpp>

#include "vkcloth_host_window/drawn_cloth.hpp"
#include "vkcloth/render/camera.hpp"

namespace vkcloth::cli {

/// Mouse and keyboard state, written by the GLFW callbacks, consumed once per frame.
struct Input {
  bool paused = false, step_once = false, reset = false, toggle_wind = false;
  bool left_down = false, left_pressed = false, left_released = false;
  double x = 0, y = 0, last_x = 0, last_y = 0, scroll = 0;
};

/// Installs the key, mouse button, cursor and scroll callbacks that fill `input`.
void install_input_callbacks(host::Window& window, Input& input);

/// Orbit camera around a target (z up).
struct Orbit {
  glm::vec3 target{0.0f};
  float yaw = 0, pitch = 0, distance = 1, fov = 40, scene_radius = 1;
  /// Starts where render::Camera::frame looks at `bounds` from.
  static Orbit framing(const render::Bounds& bounds, float aspect);
  render::Camera camera() const;
};

/// The particle the left button holds, and where it is dragged to.
struct Hold {
  std::optional<std::uint32_t> particle;
  glm::vec3 position{0.0f}, drag_normal{0.0f};
};

/// Wheel: zoom. Left press: picks the particle nearest to the cursor's ray; dragging moves it in the
/// plane through it facing the camera, or orbits when nothing was picked. Release lets go.
void apply_mouse(Input& input, Orbit& orbit, Hold& hold, host::DrawnCloth& solver, host::Window& window);

} // namespace vkcloth::cli
