// SPDX-License-Identifier: MIT
#include "vkcloth/render/host_buffers.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include <fmt/format.h>
#include <glm/vec4.hpp>

#include "render_internal.hpp"

namespace vkcloth::render {

using gpu::Buffer;

struct HostClothBuffers::Impl {
  std::shared_ptr<gpu::Context::Impl> ctx; // first: outlives the buffers below
  std::uint32_t count = 0;
  std::vector<Buffer> positions, normals; // one per slot
  Buffer uvs, indices;
  std::uint32_t index_count = 0;

  Result<Buffer> mapped(VkDeviceSize bytes, VkBufferUsageFlags usage, const char* what) {
    // Host-visible and host-coherent (MemoryUse::host_upload), mapped for the buffer's lifetime.
    auto b = gpu::create_buffer(*ctx, std::max<VkDeviceSize>(bytes, 16), usage, gpu::MemoryUse::host_upload,
                                true, what);
    if (!b)
      return b.error();
    std::memset(b->mapped, 0, b->size);
    return b;
  }
};

Result<HostClothBuffers> HostClothBuffers::create(gpu::Context& context, const ClothTopology& topology,
                                                  std::uint32_t slots) {
  if (slots < 1 || slots > 8)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("HostClothBuffers: {} slots; use 1..8 (one per frame in flight)", slots));
  auto impl = std::make_unique<Impl>();
  impl->ctx = gpu::context_impl(context);
  impl->count = static_cast<std::uint32_t>(topology.size());
  const VkDeviceSize bytes = VkDeviceSize(impl->count) * gpu::GpuSolver::stride;
  for (std::uint32_t k = 0; k < slots; ++k) {
    auto p = impl->mapped(bytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "host positions");
    if (!p)
      return p.error();
    impl->positions.push_back(std::move(*p));
    auto n = impl->mapped(bytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "host normals");
    if (!n)
      return n.error();
    impl->normals.push_back(std::move(*n));
  }
  auto uv = impl->mapped(bytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "host uvs");
  if (!uv)
    return uv.error();
  impl->uvs = std::move(*uv);
  auto* uv4 = static_cast<glm::vec4*>(impl->uvs.mapped);
  const auto topo_uvs = topology.uvs();
  for (std::size_t i = 0; i < topo_uvs.size() && i < impl->count; ++i)
    uv4[i] = glm::vec4(topo_uvs[i], 0.0f, 0.0f); // the GPU solver's layout: u, v, 0, 0
  const auto tris = topology.triangles();
  impl->index_count = static_cast<std::uint32_t>(tris.size());
  auto ix = impl->mapped(tris.size_bytes(), VK_BUFFER_USAGE_INDEX_BUFFER_BIT, "host indices");
  if (!ix)
    return ix.error();
  impl->indices = std::move(*ix);
  if (!tris.empty())
    std::memcpy(impl->indices.mapped, tris.data(), tris.size_bytes());
  return HostClothBuffers(std::move(impl));
}

Result<gpu::InstanceBuffers> HostClothBuffers::upload(std::uint32_t slot,
                                                      std::span<const glm::vec3> positions,
                                                      std::span<const glm::vec3> normals) {
  Impl& s = *impl_;
  if (positions.size() != s.count || normals.size() != s.count)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("HostClothBuffers::upload: {} positions and {} normals for {} particles",
                                  positions.size(), normals.size(), s.count));
  const std::uint32_t k = slot % slots();
  auto* p = static_cast<glm::vec4*>(s.positions[k].mapped);
  auto* n = static_cast<glm::vec4*>(s.normals[k].mapped);
  for (std::uint32_t i = 0; i < s.count; ++i) {
    p[i] = glm::vec4(positions[i], 1.0f);
    n[i] = glm::vec4(normals[i], 0.0f);
  }
  gpu::InstanceBuffers b;
  b.positions = s.positions[k].buffer;
  b.normals = s.normals[k].buffer;
  b.uvs = s.uvs.buffer;
  b.count = s.count;
  b.indices = s.index_count ? s.indices.buffer : VK_NULL_HANDLE;
  b.index_count = s.index_count;
  return b;
}

HostClothBuffers::HostClothBuffers(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HostClothBuffers::HostClothBuffers(HostClothBuffers&&) noexcept = default;
HostClothBuffers& HostClothBuffers::operator=(HostClothBuffers&&) noexcept = default;
HostClothBuffers::~HostClothBuffers() = default;
std::uint32_t HostClothBuffers::slots() const {
  return static_cast<std::uint32_t>(impl_->positions.size());
}
std::uint32_t HostClothBuffers::particle_count() const {
  return impl_->count;
}

} // namespace vkcloth::render
