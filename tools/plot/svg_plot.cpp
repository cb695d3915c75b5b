// SPDX-License-Identifier: MIT
#include "vkcloth_plot/svg_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace vkcloth::plot {
namespace {

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

/// About `target` round tick values covering [lo, hi].
std::vector<double> ticks(double lo, double hi, int target = 6) {
  const double span = hi - lo;
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> t;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step)
    t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  return t;
}

} // namespace

const char* palette(std::size_t index) {
  static const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b"};
  return colors[index % (sizeof colors / sizeof *colors)];
}

std::string to_svg(const Plot& plot) {
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  for (const Series& s : plot.series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]))
        break;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i]);
      y_hi = std::max(y_hi, s.y[i]);
    }
  if (plot.y_lo < plot.y_hi) {
    y_lo = plot.y_lo;
    y_hi = plot.y_hi;
  }
  if (!(x_lo < x_hi)) {
    x_lo = 0;
    x_hi = 1;
  }
  if (!(y_lo < y_hi)) {
    y_lo -= 0.5;
    y_hi += 0.5;
  }
  const double pad = 0.05 * (y_hi - y_lo);
  if (!(plot.y_lo < plot.y_hi)) {
    y_lo -= pad;
    y_hi += pad;
  }

  const double left = 70, right = 20, top = 58, bottom = 50; // the legend sits between title and plot
  const double w = plot.width - left - right, h = plot.height - top - bottom;
  auto px = [&](double x) { return left + (x - x_lo) / (x_hi - x_lo) * w; };
  auto py = [&](double y) { return top + (1.0 - (std::clamp(y, y_lo, y_hi) - y_lo) / (y_hi - y_lo)) * h; };

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" font-family=\"sans-serif\" "
      "font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      plot.width, plot.height);
  svg += fmt::format("<text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">{}</text>\n",
                     plot.width / 2, escape(plot.title));
  for (double t : ticks(x_lo, x_hi))
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#ddd\"/>"
                       "<text x=\"{0:.1f}\" y=\"{3:.1f}\" text-anchor=\"middle\">{4:g}</text>\n",
                       px(t), top, top + h, top + h + 16, t);
  for (double t : ticks(y_lo, y_hi))
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#ddd\"/>"
                       "<text x=\"{3:.1f}\" y=\"{4:.1f}\" text-anchor=\"end\">{5:g}</text>\n",
                       left, py(t), left + w, left - 6, py(t) + 4, t);
  svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\"/>\n",
                     left, top, w, h);
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", left + w / 2,
                     plot.height - 10, escape(plot.x_label));
  svg += fmt::format("<text transform=\"translate(16,{}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
                     top + h / 2, escape(plot.y_label));

  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const Series& s = plot.series[k];
    std::string points;
    double lx = 0, ly = 0;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]))
        break;
      lx = px(s.x[i]);
      ly = py(s.y[i]);
      points += fmt::format("{:.1f},{:.1f} ", lx, ly);
    }
    svg += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.6\"{} points=\"{}\"/>\n",
                       s.color, s.dashed ? " stroke-dasharray=\"6,4\"" : "", points);
    if (!s.note.empty())
      svg += fmt::format(
          "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4\" fill=\"{}\"/><text x=\"{:.1f}\" y=\"{:.1f}\" "
          "fill=\"{}\" text-anchor=\"end\">{}</text>\n",
          lx, ly, s.color, std::min(lx, left + w - 4), std::max(ly - 8, top + 14), s.color, escape(s.note));
    // Legend: one row above the plot area.
    const double lx0 = left + 150.0 * double(k), ly0 = top - 12;
    svg += fmt::format(
        "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" stroke-width=\"2\"{}/>"
        "<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n",
        lx0, ly0, lx0 + 22, ly0, s.color, s.dashed ? " stroke-dasharray=\"6,4\"" : "", lx0 + 27, ly0 + 4,
        escape(s.label));
  }
  svg += "</svg>\n";
  return svg;
}

} // namespace vkcloth::plot
