// SPDX-License-Identifier: MIT
// Line plots written as standalone SVG files (library vkcloth_plot): used by `vkcloth figures`
// and by the samples (spring, double_spring), which write their position and energy plots with it.
#pragma once

#include <string>
#include <vector>

namespace vkcloth::plot {

struct Series {
  std::string label;
  std::string color;        ///< any SVG colour, e.g. "#1f77b4"
  std::vector<double> x, y; ///< same length; non-finite points end the line
  bool dashed = false;
  std::string note; ///< drawn at the last point, e.g. "diverged at t = 3.2 s"
};

struct Plot {
  std::string title;
  std::string x_label, y_label;
  std::vector<Series> series;
  /// Fixed y range; when lo >= hi the range is taken from the data (finite points only).
  double y_lo = 0.0, y_hi = 0.0;
  int width = 640, height = 400;
};

/// Renders the plot as an SVG document.
std::string to_svg(const Plot& plot);

/// The default palette, one colour per series index.
const char* palette(std::size_t index);

} // namespace vkcloth::plot
