// SPDX-License-Identifier: MIT
// vkcloth's private stb_image / stb_image_write: stb is compiled with internal linkage (static) in
// stb_impl.cpp only, so the library exports no stbi_* symbol and links into a host that compiles
// its own stb (tinygltf and many engines do). The rest of the library calls these wrappers.
#pragma once

namespace vkcloth::render::stb {

/// stbi_info: the size and channel count of an image file; false if it is not one.
bool info(const char* path, int* w, int* h, int* comp);
/// stbi_info_from_memory.
bool info_from_memory(const unsigned char* bytes, int len, int* w, int* h, int* comp);
/// stbi_load / stbi_load_from_memory: pixels with `channels` components, freed with image_free.
unsigned char* load(const char* path, int* w, int* h, int* comp, int channels);
unsigned char* load_from_memory(const unsigned char* bytes, int len, int* w, int* h, int* comp, int channels);
void image_free(unsigned char* pixels);
/// stbi_failure_reason: why the last call on this thread failed (may be null).
const char* failure_reason();
/// stbi_write_png; false on failure.
bool write_png(const char* path, int w, int h, int comp, const void* data, int stride_bytes);

} // namespace vkcloth::render::stb
