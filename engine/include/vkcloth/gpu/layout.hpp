// SPDX-License-Identifier: MIT
// The per-device layout of the Vulkan solver's shaders (docs/architecture.md "Per-device
// layout"): how the force, update and stretch passes read their buffers, and the workgroup size.
// Chosen once per device from its properties by choose_layout(); GpuSolverOptions can force it.
//
// Both buffer accesses give the same bits (a 32-bit texel fetch is a copy of the stored word); only
// the speed differs: llvmpipe (lavapipe) vectorises texel fetches but turns every storage-buffer
// load into a per-lane loop, while a GPU reads storage buffers through its ordinary memory path
// (texel fetches go through the texture units, and their views are held to maxTexelBufferElements).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <vulkan/vulkan_core.h>

namespace vkcloth::gpu {

class Context;

/// How force.comp, fused.comp, integrate.comp and strain_*.comp read positions, velocities,
/// particle constants, instance parameters and the topology's lists.
enum class BufferAccess : std::uint8_t {
  automatic,      ///< the device's choice (choose_layout)
  texel_views,    ///< uniform texel buffer views (set 1): the *_texel builds of the shaders
  storage_buffers ///< std430 storage buffers (set 0 only): the *_storage builds; no texel views are
                  ///< made, so maxTexelBufferElements does not limit the batch
};

/// "auto", "texel" or "storage" (the CLI's spelling).
const char* to_string(BufferAccess access);
/// Parses "auto", "texel" or "storage"; nullopt otherwise.
std::optional<BufferAccess> parse_buffer_access(std::string_view text);

/// What the solver uses on one device, and why.
struct DeviceLayout {
  BufferAccess access = BufferAccess::texel_views; ///< never `automatic`
  /// Invocations per workgroup of the solver's per-particle passes (a specialisation constant;
  /// GpuSolverOptions::workgroup_size overrides it). Implicit Euler keeps its compiled size.
  std::uint32_t workgroup_size = 64;
  std::uint32_t subgroup_size = 0; ///< as reported by the device (0: unknown)
  /// One sentence naming the properties that decided, e.g. "CPU device (llvmpipe): texel views".
  std::string reason;
};

/// The choice for a device with these properties (pure: no Vulkan call, unit-tested):
/// - VK_PHYSICAL_DEVICE_TYPE_CPU (lavapipe, SwiftShader): texel views, 64 invocations;
/// - any other type: storage buffers, and the smallest multiple of `subgroup_size` that is at
///   least 64 (64 for subgroups of 8 to 64), within maxComputeWorkGroupSize[0] and
///   maxComputeWorkGroupInvocations.
/// `subgroup_size` 0 (unknown) counts as 32.
DeviceLayout choose_layout(const VkPhysicalDeviceProperties& properties, std::uint32_t subgroup_size);

/// choose_layout() for the Context's device (its VkPhysicalDeviceSubgroupProperties queried).
/// For `vkcloth devices` and diagnostics; the solver calls it for BufferAccess::automatic.
DeviceLayout device_layout(const Context& context);

} // namespace vkcloth::gpu
