// SPDX-License-Identifier: MIT
// Labelled image grids for the cloth figures: panels side by side, a title strip on top and a
// label under each panel, drawn with a tiny built-in 5 x 7 bitmap font (no font files needed).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "vkcloth/render/image.hpp"

namespace vkcloth::figures {

struct Panel {
  render::Image image;
  std::string label; ///< drawn under the panel, e.g. "K_struct = 5"
};

/// Draws `text` at (x, y) (top-left of the first glyph), each font pixel a `scale` x `scale` block.
/// Letters are drawn as capitals; characters outside the font are drawn as a blank.
void draw_text(render::Image& img, int x, int y, const std::string& text, int scale,
               const std::uint8_t rgb[3]);
/// Width in pixels of `text` drawn at `scale`.
int text_width(const std::string& text, int scale);

/// The panels (all the same size) in rows of `columns` (0: all in one row), a title strip above, each
/// label centred under its panel.
render::Image compose_grid(const std::vector<Panel>& panels, const std::string& title,
                           std::size_t columns = 0);

} // namespace vkcloth::figures
