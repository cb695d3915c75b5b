// SPDX-License-Identifier: MIT
// Consumer smoke test: builds a cloth through the public API only, steps it on the CPU and, when a
// Vulkan device is there, on the GPU, and checks both agree. Exit 0 on success. The host also
// calls Vulkan its own way (its own volk, or the loader directly), next to vkcloth, and has its
// own stb_image (host_images.cpp): a PNG goes through vkcloth::render and the host's stbi_* both ways.
// Usage: consumer [DIR]  (DIR: where the PNG files go, default the current directory)
#if defined(HOST_USES_VOLK)
#include <volk.h> // before any other Vulkan header, as volk requires
#else
#include <vulkan/vulkan.h>
#endif

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <vkcloth/render/image.hpp>
#include <vkcloth/vkcloth.hpp>

int host_image_width(const char* path); // host_images.cpp

namespace {

/// vkcloth writes a PNG the host's stb_image reads, and the host's stb_image_write writes one
/// vkcloth reads: both copies of stb in one program, each working.
bool images_round_trip(const std::filesystem::path& dir) {
  const vkcloth::render::Image fabric = vkcloth::render::default_fabric_texture(16);
  const std::string ours = (dir / "consumer_vkcloth.png").string();
  if (!vkcloth::render::write_png(ours, fabric)) {
    std::fprintf(stderr, "render::write_png failed\n");
    return false;
  }
  if (host_image_width(ours.c_str()) != 16) {
    std::fprintf(stderr, "the host's image code does not read vkcloth's PNG\n");
    return false;
  }
  int w = 0, h = 0, comp = 0;
  stbi_uc* pixels = stbi_load(ours.c_str(), &w, &h, &comp, 4);
  const bool same =
      pixels && w == 16 && h == 16 && std::memcmp(pixels, fabric.rgba.data(), fabric.rgba.size()) == 0;
  stbi_image_free(pixels);
  if (!same) {
    std::fprintf(stderr, "the host's stbi_load does not read back vkcloth's PNG (%s)\n",
                 pixels ? "pixels differ" : stbi_failure_reason());
    return false;
  }
  const std::string theirs = (dir / "consumer_host.png").string();
  if (!stbi_write_png(theirs.c_str(), 16, 16, 4, fabric.rgba.data(), 16 * 4)) {
    std::fprintf(stderr, "the host's stbi_write_png failed\n");
    return false;
  }
  auto back = vkcloth::render::load_image(theirs);
  if (!back || back->rgba != fabric.rgba) {
    std::fprintf(stderr, "render::load_image does not read back the host's PNG\n");
    return false;
  }
  std::printf("images: vkcloth's stb and the host's stb_image side by side\n");
  return true;
}

} // namespace

int main(int argc, char** argv) {
  if (!images_round_trip(argc > 1 ? argv[1] : "."))
    return 1;
  std::uint32_t host_version = 0;
#if defined(HOST_USES_VOLK)
  if (volkInitialize() == VK_SUCCESS)
    host_version = volkGetInstanceVersion();
  std::printf("host: its own volk, instance version %u.%u\n", VK_API_VERSION_MAJOR(host_version),
              VK_API_VERSION_MINOR(host_version));
#else
  if (vkEnumerateInstanceVersion(&host_version) != VK_SUCCESS)
    return 1;
  std::printf("host: loader linked directly, instance version %u.%u\n", VK_API_VERSION_MAJOR(host_version),
              VK_API_VERSION_MINOR(host_version));
#endif
  vkcloth::ClothDesc desc;
  desc.nx = 17;
  desc.ny = 11;
  desc.origin = {-0.5, 0.0, 0.5};
  auto system = vkcloth::make_cloth(desc);
  if (!system) {
    std::fprintf(stderr, "make_cloth: %s\n", system.error().message.c_str());
    return 1;
  }
  vkcloth::SimParams params;
  params.wind = {0.05, {0.0, 1.0, 0.0}};
  auto cpu = vkcloth::CpuSolver<float>::create(*system, params);
  if (!cpu || !cpu->run(100)) {
    std::fprintf(stderr, "cpu solver failed\n");
    return 1;
  }
  auto context = vkcloth::gpu::Context::create();
  if (!context) {
    const char* ci = std::getenv("CI");
    std::printf("no Vulkan device (%s): CPU only\n", context.error().message.c_str());
    return ci && std::strcmp(ci, "true") == 0 ? 1 : 0;
  }
  auto gpu = vkcloth::gpu::GpuSolver::create(*context, *system, params);
  if (!gpu || !gpu->simulate(100)) {
    std::fprintf(stderr, "gpu solver failed\n");
    return 1;
  }
  auto positions = gpu->positions();
  if (!positions)
    return 1;
  double worst = 0.0;
  for (std::size_t i = 0; i < positions->size(); ++i)
    for (int k = 0; k < 3; ++k)
      worst = std::fmax(worst, std::fabs((*positions)[i][k] - cpu->positions()[i][k]));
  std::printf("consumer: %zu particles on %s, max |gpu - cpu| = %g\n", positions->size(),
              context->device_name().c_str(), worst);
  return worst <= 1e-5 ? 0 : 1;
}
