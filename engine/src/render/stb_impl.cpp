// SPDX-License-Identifier: MIT
// The stb_image / stb_image_write implementations (compiled once, without the project's warnings),
// with internal linkage: only the wrappers of stb.hpp leave this translation unit, so no stbi_*
// symbol clashes with, or is interposed by, a host's own copy of stb.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb/stb_image.h>
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include "stb.hpp"

namespace vkcloth::render::stb {

bool info(const char* path, int* w, int* h, int* comp) {
  return stbi_info(path, w, h, comp) != 0;
}

bool info_from_memory(const unsigned char* bytes, int len, int* w, int* h, int* comp) {
  return stbi_info_from_memory(bytes, len, w, h, comp) != 0;
}

unsigned char* load(const char* path, int* w, int* h, int* comp, int channels) {
  return stbi_load(path, w, h, comp, channels);
}

unsigned char* load_from_memory(const unsigned char* bytes, int len, int* w, int* h, int* comp,
                                int channels) {
  return stbi_load_from_memory(bytes, len, w, h, comp, channels);
}

void image_free(unsigned char* pixels) {
  stbi_image_free(pixels);
}

const char* failure_reason() {
  return stbi_failure_reason();
}

bool write_png(const char* path, int w, int h, int comp, const void* data, int stride_bytes) {
  return stbi_write_png(path, w, h, comp, data, stride_bytes) != 0;
}

} // namespace vkcloth::render::stb
