// SPDX-License-Identifier: MIT
// Consumer smoke test: builds a cloth through the public API only, steps it on the CPU and, when a
// Vulkan device is there, on the GPU, and checks both agree. Exit 0 on success. The host also
// calls Vulkan its own way (its own volk, or the loader directly), next to vkcloth.
#if defined(HOST_USES_VOLK)
#include <volk.h> // before any other Vulkan header, as volk requires
#else
#include <vulkan/vulkan.h>
#endif

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <vkcloth/vkcloth.hpp>

int main() {
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
