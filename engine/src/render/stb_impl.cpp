// SPDX-License-Identifier: MIT
// The stb_image / stb_image_write implementations (compiled once, without the project's warnings).
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb/stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
