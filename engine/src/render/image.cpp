// SPDX-License-Identifier: MIT
#include "vkcloth/render/image.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "stb.hpp"

namespace vkcloth::render {

namespace {

/// The checks load_image and decode_image share, after stb::info: `what` names the image
/// ("texture file 'cloth.png'", "texture 'flag.glb images[0]'").
Result<void> check_size(const std::string& what, int w, int h, std::uint32_t max_side) {
  if (w <= 0 || h <= 0)
    return make_error(ErrorCode::io, fmt::format("{} is zero-sized ({} x {})", what, w, h));
  if (std::uint32_t(w) > max_side || std::uint32_t(h) > max_side)
    return make_error(ErrorCode::io, fmt::format("{} is too large: {} x {} (at most {} pixels a side)", what,
                                                 w, h, max_side));
  return {};
}

/// Takes stb_image's RGBA pixels (freed here), or its failure reason.
Result<Image> take_pixels(const std::string& what, unsigned char* data, int w, int h) {
  if (!data) {
    const char* why = stb::failure_reason();
    return make_error(ErrorCode::io,
                      fmt::format("{} could not be decoded ({})", what, why ? why : "corrupt data"));
  }
  Image img;
  img.width = std::uint32_t(w);
  img.height = std::uint32_t(h);
  img.rgba.assign(data, data + std::size_t(w) * std::size_t(h) * 4);
  stb::image_free(data);
  return img;
}

} // namespace

Result<Image> load_image(const std::filesystem::path& path, std::uint32_t max_side) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return make_error(ErrorCode::io, fmt::format("texture file '{}' does not exist", name));
  if (std::filesystem::is_directory(path, ec))
    return make_error(ErrorCode::io, fmt::format("texture file '{}' is a directory, not an image", name));
  int w = 0, h = 0, comp = 0;
  if (!stb::info(name.c_str(), &w, &h, &comp)) {
    const char* why = stb::failure_reason();
    return make_error(ErrorCode::io, fmt::format("texture file '{}' is not a readable PNG/JPEG image ({})",
                                                 name, why ? why : "unknown format"));
  }
  const std::string what = fmt::format("texture file '{}'", name);
  VKCLOTH_TRY(check_size(what, w, h, max_side));
  return take_pixels(what, stb::load(name.c_str(), &w, &h, &comp, 4), w, h);
}

Result<Image> decode_image(std::span<const std::uint8_t> bytes, std::string_view source,
                           std::uint32_t max_side) {
  const std::string what = fmt::format("texture '{}'", source);
  if (bytes.empty())
    return make_error(ErrorCode::io, fmt::format("{} is empty (0 bytes)", what));
  if (bytes.size() > std::size_t(std::numeric_limits<int>::max()))
    return make_error(ErrorCode::io,
                      fmt::format("{} is too large to decode: {} bytes (stb_image takes at most {})", what,
                                  bytes.size(), std::numeric_limits<int>::max()));
  const int len = static_cast<int>(bytes.size());
  int w = 0, h = 0, comp = 0;
  if (!stb::info_from_memory(bytes.data(), len, &w, &h, &comp)) {
    const char* why = stb::failure_reason();
    return make_error(ErrorCode::io, fmt::format("{} ({} bytes) is not a readable PNG/JPEG image ({})", what,
                                                 bytes.size(), why ? why : "unknown format"));
  }
  VKCLOTH_TRY(check_size(what, w, h, max_side));
  return take_pixels(what, stb::load_from_memory(bytes.data(), len, &w, &h, &comp, 4), w, h);
}

Result<void> write_png(const std::filesystem::path& path, const Image& image) {
  const std::string name = path.string();
  if (image.width == 0 || image.height == 0 ||
      image.rgba.size() != std::size_t(image.width) * image.height * 4)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("cannot write '{}': the image is empty or malformed", name));
  if (!stb::write_png(name.c_str(), int(image.width), int(image.height), 4, image.rgba.data(),
                      int(image.width * 4)))
    return make_error(
        ErrorCode::io,
        fmt::format("cannot write the PNG file '{}' (directory missing or not writable?)", name));
  return {};
}

Image default_fabric_texture(std::uint32_t size) {
  size = std::max<std::uint32_t>(16, size);
  Image img;
  img.width = img.height = size;
  img.rgba.resize(std::size_t(size) * size * 4);
  const std::uint32_t thread = std::max<std::uint32_t>(2, size / 64); // pixels per thread
  const float pi = 3.14159265f;
  for (std::uint32_t y = 0; y < size; ++y)
    for (std::uint32_t x = 0; x < size; ++x) {
      const std::uint32_t cx = x / thread, cy = y / thread;
      // 2/2 twill: the warp (vertical threads) is on top where (cx + cy) mod 4 < 2.
      const bool warp_on_top = ((cx + cy) % 4) < 2;
      // Tartan: stripes every 16 threads in both directions, coloured per thread.
      const std::uint32_t along = warp_on_top ? cx : cy;
      const std::uint32_t band = along % 16;
      float r, g, b;
      if (band < 2) {
        r = 0.80f;
        g = 0.12f;
        b = 0.10f;
      } // red stripe
      else if (band < 3) {
        r = 0.95f;
        g = 0.85f;
        b = 0.35f;
      } // yellow line
      else if (band < 9) {
        r = 0.12f;
        g = 0.22f;
        b = 0.50f;
      } // navy
      else {
        r = 0.10f;
        g = 0.40f;
        b = 0.22f;
      } // green
      if (!warp_on_top) {
        r *= 0.85f;
        g *= 0.85f;
        b *= 0.85f;
      }
      // Thread relief: darker towards each thread's edges.
      const float t = (float((warp_on_top ? x : y) % thread) + 0.5f) / float(thread);
      const float relief = 0.75f + 0.25f * std::sin(t * pi);
      std::uint8_t* p = img.pixel(x, y);
      p[0] = std::uint8_t(std::lround(std::clamp(r * relief, 0.0f, 1.0f) * 255.0f));
      p[1] = std::uint8_t(std::lround(std::clamp(g * relief, 0.0f, 1.0f) * 255.0f));
      p[2] = std::uint8_t(std::lround(std::clamp(b * relief, 0.0f, 1.0f) * 255.0f));
      p[3] = 255;
    }
  return img;
}

} // namespace vkcloth::render
