// SPDX-License-Identifier: MIT
// Helpers shared by `vkcloth render` and `vkcloth view`: image size and camera options, --backend, the
// Context options for drawing.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/render/camera.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {

/// "WxH" with both in 1..4096.
Result<std::pair<std::uint32_t, std::uint32_t>> parse_size(const std::string& text);
/// `spec` empty: framed from the scene's bounds; else "ex,ey,ez,tx,ty,tz".
Result<render::Camera> make_camera(const std::string& spec, float fov, const Scene& scene, float aspect);
/// A Context whose queue also does graphics (VKCLOTH_VALIDATION / VKCLOTH_DEVICE apply).
gpu::ContextOptions render_context_options();
/// --backend auto | cpu | vulkan of the drawing commands (render, view), default auto.
void add_draw_backend_option(CLI::App& cmd, std::string& backend);

} // namespace vkcloth::cli
