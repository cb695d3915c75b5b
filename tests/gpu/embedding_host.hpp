// SPDX-License-Identifier: MIT
// What the embedding tests share (test_embedding.cpp, test_embedding_frames.cpp): the test host
// (HostVulkan, skipped off CI when it cannot make its device) and its handles for Context::adopt.
#pragma once

#include <memory>
#include <string>

#include <doctest/doctest.h>

#include "gpu_test_util.hpp"
#include "host_vulkan.hpp"

namespace vkcloth::gpu::test {

inline std::unique_ptr<HostVulkan> host_or_skip(std::string& error) {
  auto h = HostVulkan::create(error);
  if (!h && vkcloth::gpu::test::on_ci())
    FAIL("CI=true but the test host could not create its device: " << error);
  if (!h)
    MESSAGE("skipped: " << error);
  return h;
}

inline HostHandles handles_of(const HostVulkan& h, const VkAllocationCallbacks* allocator) {
  HostHandles hh;
  hh.instance = h.instance;
  hh.physical_device = h.physical_device;
  hh.device = h.device;
  hh.queue_family = h.family;
  hh.queue = h.queue;
  hh.get_instance_proc_addr = h.get_instance_proc_addr;
  hh.allocator = allocator;
  return hh;
}

} // namespace vkcloth::gpu::test
