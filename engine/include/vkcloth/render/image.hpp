// SPDX-License-Identifier: MIT
// RGBA8 images on the host: textures for the renderer, frames read back from it, PNG files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

#include "vkcloth/result.hpp"

namespace vkcloth::render {

/// Tightly packed RGBA, 8 bits per channel, rows top to bottom.
struct Image {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint8_t> rgba;

  const std::uint8_t* pixel(std::uint32_t x, std::uint32_t y) const {
    return &rgba[(std::size_t(y) * width + x) * 4];
  }
  std::uint8_t* pixel(std::uint32_t x, std::uint32_t y) { return &rgba[(std::size_t(y) * width + x) * 4]; }
};

/// Largest texture side load_image() accepts by default.
inline constexpr std::uint32_t max_texture_size = 8192;

/// Loads a PNG / JPEG / BMP / TGA file (stb_image) as RGBA. Errors (ErrorCode::io, the message
/// names the file): missing or unreadable, corrupt or not an image, zero-sized, a side larger
/// than `max_side`.
Result<Image> load_image(const std::filesystem::path& path, std::uint32_t max_side = max_texture_size);

/// Decodes a PNG / JPEG / BMP / TGA file's bytes held in memory (stb_image; e.g. a glTF
/// material's texture, vkcloth::MeshTexture::encoded) as RGBA. `source` names the bytes in
/// messages ("flag.glb images[0]"). Errors (ErrorCode::io, naming `source`): no bytes, not an
/// image or corrupt (stb_image's reason), zero-sized, a side larger than `max_side`.
Result<Image> decode_image(std::span<const std::uint8_t> bytes, std::string_view source,
                           std::uint32_t max_side = max_texture_size);

/// Writes a PNG (stb_image_write). ErrorCode::io naming the file on failure.
Result<void> write_png(const std::filesystem::path& path, const Image& image);

/// The built-in fabric: a woven two-colour twill with a tartan stripe, generated procedurally
/// (size x size, size a power of two >= 16).
Image default_fabric_texture(std::uint32_t size = 256);

} // namespace vkcloth::render
