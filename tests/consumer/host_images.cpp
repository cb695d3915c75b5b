// SPDX-License-Identifier: MIT
// The host's own image code with stb_image / stb_image_write compiled in, the usual single-header
// way (tinygltf and many engines do this), as a static library linked after vkcloth. vkcloth's
// copy of stb is internal to the library: the two link together, each used by its own callers.
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

/// The host's own image function (what pulls this object into the link): the width of an image
/// file, 0 if it is not one.
int host_image_width(const char* path) {
  int w = 0, h = 0, comp = 0;
  return stbi_info(path, &w, &h, &comp) ? w : 0;
}
