// SPDX-License-Identifier: MIT
// SolverBatch's creation: the device limits checked first (batch_limits.hpp), then the buffers and
// the upload of the topology and the initial state (the state set:
// solver_state_set.cpp; the passes: passes/; the rest of the batch: solver_batch.cpp).
#include "solver_batch.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "internal/kernel.hpp"
#include "internal/barriers.hpp"
#include "batch_limits.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

StorageLimit storage_limit(const Context::Impl& ctx, const testing::SolverKnobs& knobs) {
  const std::uint64_t device = ctx.properties.limits.maxStorageBufferRange;
  if (knobs.max_storage_buffer_bytes && knobs.max_storage_buffer_bytes < device)
    return {knobs.max_storage_buffer_bytes, "testing::SolverKnobs::max_storage_buffer_bytes"};
  return {device, "maxStorageBufferRange"};
}

Result<void> check_buffer(const Context::Impl& ctx, const StorageLimit& limit, const char* what,
                          std::uint64_t items, std::uint64_t per) {
  if (items * per <= limit.bytes)
    return {};
  return make_error(
      ErrorCode::unsupported,
      fmt::format("the system is too large for device '{}': its {} buffer needs {} bytes ({} x {} "
                  "bytes) but a storage buffer may hold at most {} bytes ({}); use fewer "
                  "particles or fewer instances of one topology",
                  ctx.name, what, items * per, items, per, limit.bytes, limit.source));
}

Result<void> check_texels(const Context::Impl& ctx, const char* what, std::uint64_t texels,
                          const char* advice) {
  const std::uint64_t max = ctx.properties.limits.maxTexelBufferElements;
  if (texels <= max)
    return {};
  return make_error(ErrorCode::unsupported,
                    fmt::format("the system is too large for device '{}': its {} need {} texels in a texel "
                                "buffer view but the device allows {} (maxTexelBufferElements); {}",
                                ctx.name, what, texels, max, advice));
}

namespace {

// Each particle's gather list as (begin, end of its fan entries, end, 0): what the texel builds read
// instead of the offsets, so that their fan loop knows where the fan ends (buffer_access.glsl
// read_list_range).
std::vector<std::uint32_t> list_ranges(const ClothTopology& topology) {
  const std::span<const std::uint32_t> off = topology.edge_offsets();
  const std::size_t n = topology.size();
  std::vector<std::uint32_t> ranges(4 * n, 0);
  for (std::size_t p = 0; p < n; ++p) {
    ranges[4 * p] = off[p];
    ranges[4 * p + 1] = topology.fan_ends()[p];
    ranges[4 * p + 2] = off[p + 1];
  }
  return ranges;
}

} // namespace

namespace {

/// Workgroups per dispatch: gx x gy (x instances in z).
struct DispatchGrid {
  std::uint32_t x = 1, y = 1;
};

/// The device limits a batch of `batch` instances of `topology` must fit, checked before any
/// allocation; errors name the buffer or dispatch and the limit. (The tethers, made when first
/// asked for, are checked then: ensure_tethers.)
Result<DispatchGrid> check_limits(const Context::Impl& ctx, const ClothTopology& topology,
                                  std::uint64_t batch, const GpuSolverOptions& options,
                                  const testing::SolverKnobs& knobs, const DeviceLayout& layout) {
  const std::uint32_t workgroup = layout.workgroup_size;
  const bool texel = layout.access == BufferAccess::texel_views; // the storage builds make no texel views
  const std::uint64_t n = topology.size();
  const VkPhysicalDeviceLimits& lim = ctx.properties.limits;
  const StorageLimit limit = storage_limit(ctx, knobs);
  const std::uint64_t edges_n = topology.edges().size();
  const std::uint64_t links_n = topology.strain_links().size();
  const struct {
    const char* what;
    std::uint64_t items;
    std::uint64_t per;
  } needs[] = {{"per-particle (vec4)", batch * n, 16},
               {"spring adjacency", edges_n, sizeof(sh::Edge)},
               {"particle constants", n, sizeof(sh::ParticleInfo)},
               {"strain links", links_n, sizeof(sh::StrainLink)},
               {"interleaved vertices", options.interleaved_vertices ? batch * n : 0, sizeof(sh::Vertex)}};
  for (const auto& need : needs)
    VKCLOTH_TRY(check_buffer(ctx, limit, need.what, need.items, need.per));
  // Positions, velocities and particle constants are also read through texel buffer views (one
  // texel per particle of every instance).
  if (texel && batch * n > lim.maxTexelBufferElements)
    return make_error(
        ErrorCode::unsupported,
        fmt::format("the system is too large for device '{}': {} particles ({} instances of {}) need "
                    "{} texels per texel buffer view but the device allows {} (maxTexelBufferElements); "
                    "use fewer particles or fewer instances of one topology",
                    ctx.name, batch * n, batch, n, batch * n, lim.maxTexelBufferElements));
  // So are the topology's lists (buffer_access.glsl read_list_range, read_edge): one range per
  // particle, one texel per spring entry.
  const struct {
    const char* what;
    std::uint64_t texels;
  } lists[] = {{"spring adjacency ranges", n},
               {"spring adjacency", edges_n},
               {"strain links", links_n * 3}}; // three R32UI texels each
  for (const auto& list : lists)
    if (texel)
      VKCLOTH_TRY(check_texels(ctx, list.what, list.texels, "use fewer springs or particles"));
  const std::uint64_t groups = (n + workgroup - 1) / workgroup;
  std::uint64_t row = lim.maxComputeWorkGroupCount[0];
  if (knobs.max_workgroups_x)
    row = std::min<std::uint64_t>(row, knobs.max_workgroups_x);
  const std::uint64_t gx = std::min<std::uint64_t>(groups, row);
  const std::uint64_t gy = (groups + gx - 1) / gx;
  if (gy > lim.maxComputeWorkGroupCount[1] || n >= std::numeric_limits<std::uint32_t>::max())
    return make_error(
        ErrorCode::unsupported,
        fmt::format("the system is too large for device '{}': {} particles need {} workgroups of {} but "
                    "the device dispatches at most {} x {}",
                    ctx.name, n, groups, workgroup, lim.maxComputeWorkGroupCount[0],
                    lim.maxComputeWorkGroupCount[1]));
  if (batch == 0 || batch > lim.maxComputeWorkGroupCount[2])
    return make_error(
        ErrorCode::unsupported,
        fmt::format("a batch of {} instances of one topology does not fit device '{}' (at most {} per "
                    "dispatch: maxComputeWorkGroupCount[2])",
                    batch, ctx.name, lim.maxComputeWorkGroupCount[2]));
  return DispatchGrid{static_cast<std::uint32_t>(gx), static_cast<std::uint32_t>(gy)};
}

} // namespace

// Buffers. Bulk ones prefer device-local + host-visible (mapped) unless staging is forced.
Result<void> SolverBatch::create_buffers() {
  const std::size_t n = count;
  // VERTEX_BUFFER: a renderer binds positions, normals and uvs as vertex buffers (render/);
  // UNIFORM_TEXEL_BUFFER: positions are read through texel views (buffer_access.glsl read_pos_in).
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                   VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                   VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  const VkDeviceSize vec4_bytes = VkDeviceSize(size()) * n * 16;
  const bool allow_map = !knobs.force_staging;
  std::vector<std::uint32_t> families;
  if (!options.sharing_queue_families.empty()) {
    families = options.sharing_queue_families;
    families.push_back(ctx->queue_family); // the solver's own queue always uses them
  }
  const std::tuple<Buffer*, VkDeviceSize, const char*> device_buffers[] = {
      {&pos[0], vec4_bytes, "positions[0]"},
      {&pos[1], vec4_bytes, "positions[1]"},
      {&vel, vec4_bytes, "velocities"},
      {&force, vec4_bytes, "forces"},
      {&force_stage, vec4_bytes, "stage forces"},
      {&vel_filt, vec4_bytes, "contact velocities"},
      {&normal, vec4_bytes, "normals"},
      {&uv, vec4_bytes, "uvs"},
      {&stage_pos, vec4_bytes, "stage positions"},
      {&stage_vel, vec4_bytes, "stage velocities"},
      {&acc_pos, vec4_bytes, "rk4 sums (positions)"},
      {&acc_vel, vec4_bytes, "rk4 sums (velocities)"},
      {&particle, std::max<VkDeviceSize>(n * sizeof(sh::ParticleInfo), 16), "particle constants"},
      {&offsets, std::max<VkDeviceSize>((n + 1) * sizeof(std::uint32_t), 16), "adjacency offsets"},
      {&ranges,
       access == BufferAccess::texel_views ? std::max<VkDeviceSize>(n * 4 * sizeof(std::uint32_t), 16) : 16,
       "adjacency ranges"}, // read by the texel builds only
      {&edges, std::max<VkDeviceSize>(edges_count * sizeof(sh::Edge), 16), "adjacency"},
      {&strain_links, std::max<VkDeviceSize>(strain_link_count() * sizeof(sh::StrainLink), 16),
       "strain links"},
      {&tethers, 16, "tethers (none yet)"},
      {&vbd_order, std::max<VkDeviceSize>(n * sizeof(std::uint32_t), 16), "vbd colour order"},
      {&targets, sizeof(sh::Target), "targets (none yet)"},
      {&frames, sizeof(sh::FrameMotion), "frames (none yet)"},
      {&mesh_cache, 2 * sizeof(sh::vec4), "mesh collider search entries (none yet)"},
      // GpuSolverOptions::interleaved_vertices: one Vertex (32 bytes) per particle; else one.
      {&vertices, options.interleaved_vertices ? VkDeviceSize(size()) * n * sizeof(sh::Vertex) : 32,
       "interleaved vertices"}};
  for (auto [b, bytes, what] : device_buffers) {
    auto r = create_buffer(*ctx, bytes, usage, MemoryUse::device, allow_map, what, families);
    if (!r)
      return r.error();
    *b = std::move(*r);
  }
  // The topology's triangle list for the host's drawing (instance-local indices; empty for chains).
  {
    auto r =
        create_buffer(*ctx, std::max<VkDeviceSize>(VkDeviceSize(index_count) * sizeof(std::uint32_t), 16),
                      VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::device,
                      allow_map, "triangle indices", families);
    if (!r)
      return r.error();
    indices = std::move(*r);
  }
  staging = pos[0].mapped == nullptr;
  // Texel views of both: fused.comp (flags), common.glsl (instance parameters).
  constexpr VkBufferUsageFlags small =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  {
    auto r = create_buffer(*ctx, size() * sizeof(sh::Flags), small, MemoryUse::host_readback, true, "flags");
    if (!r)
      return r.error();
    flags = std::move(*r);
    for (std::uint32_t k = 0; k < size(); ++k)
      static_cast<sh::Flags*>(flags.mapped)[k] = sh::Flags{0, VKCLOTH_NO_BAD_STEP, VKCLOTH_NO_BAD_STEP, 0};
  }
  {
    auto r =
        create_buffer(*ctx, size() * sizeof(sh::InstanceParams), small | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      MemoryUse::host_upload, true, "instance parameters");
    if (!r)
      return r.error();
    instances = std::move(*r);
  }
  VKCLOTH_TRY(ensure_collider_capacity());
  return ensure_mesh_buffers();
}

// Initial state of every instance, converted as CpuSolver<float>::create converts it, and the
// topology's constants; the scratch buffers zeroed.
Result<void> SolverBatch::upload_initial_state(const ClothTopology& topology,
                                               const std::vector<SlotState>& states) {
  const ParticleSystem& system = topology.system();
  const std::size_t n = count;
  const std::size_t entries = std::size_t(size()) * n;
  const VkDeviceSize vec4_bytes = entries * 16;
  std::vector<sh::vec4> x0(entries), v0(entries), uv0(entries);
  std::vector<sh::ParticleInfo> info(n);
  uvs_.assign(topology.uvs().begin(), topology.uvs().end());
  for (std::size_t k = 0; k < size(); ++k) {
    const SlotState state = k < states.size() ? states[k] : SlotState{};
    for (std::size_t p = 0; p < n; ++p) {
      const Particle& q = system.particles[p];
      const glm::dvec3 x = state.positions && !state.positions->empty() ? (*state.positions)[p] : q.position;
      const glm::dvec3 u =
          state.velocities && !state.velocities->empty() ? (*state.velocities)[p] : q.velocity;
      x0[k * n + p] = {float(x.x), float(x.y), float(x.z), 1.0f};
      v0[k * n + p] = q.pinned ? sh::vec4{0, 0, 0, 0} : sh::vec4{float(u.x), float(u.y), float(u.z), 0.0f};
      info[p] = {float(q.mass), q.pinned ? 1u : 0u};
    }
  }
  for (std::size_t k = 0; k < size(); ++k)
    for (std::size_t p = 0; p < n; ++p)
      uv0[k * n + p] = {uvs_[p].x, uvs_[p].y, 0.0f, 0.0f};
  std::vector<sh::Edge> edge_data(edges_count);
  for (std::size_t e = 0; e < edges_count; ++e) {
    const GatherEdge& g = topology.edges()[e];
    edge_data[e] = {g.other, float(g.rest_length), float(g.stiffness), g.ring};
  }
  const std::vector<std::uint32_t> range_data =
      access == BufferAccess::texel_views ? list_ranges(topology) : std::vector<std::uint32_t>{};
  std::vector<sh::StrainLink> link_data;
  for (const StrainLink& l : topology.strain_links())
    link_data.push_back({l.a, l.b, float(l.rest_length)});
  const std::span<const std::uint32_t> triangles = topology.triangles();
  const Upload uploads[] = {
      {&strain_links, link_data.empty() ? nullptr : link_data.data(),
       link_data.size() * sizeof(sh::StrainLink)},
      {&tethers, nullptr, 0},
      {&pos[0], x0.data(), vec4_bytes},
      {&pos[1], x0.data(), vec4_bytes},
      {&vel, v0.data(), vec4_bytes},
      {&uv, uv0.data(), vec4_bytes},
      {&particle, info.data(), n * sizeof(sh::ParticleInfo)},
      {&offsets, topology.edge_offsets().data(), (n + 1) * sizeof(std::uint32_t)},
      {&ranges, range_data.empty() ? nullptr : range_data.data(), range_data.size() * sizeof(std::uint32_t)},
      {&edges, edge_data.data(), edges_count * sizeof(sh::Edge)},
      {&vbd_order, topology.vertex_order().data(), n * sizeof(std::uint32_t)},
      {&indices, triangles.data(), triangles.size() * sizeof(std::uint32_t)},
      {&force, nullptr, 0},
      {&force_stage, nullptr, 0},
      {&vel_filt, nullptr, 0},
      {&normal, nullptr, 0},
      {&vertices, nullptr, 0},
      {&stage_pos, nullptr, 0},
      {&stage_vel, nullptr, 0},
      {&acc_pos, nullptr, 0},
      {&acc_vel, nullptr, 0}};
  return upload(uploads);
}

// Into mapped memory directly, or through one staging buffer (one submission, waited for).
Result<void> SolverBatch::upload(std::span<const Upload> uploads) {
  if (!staging) {
    for (const Upload& u : uploads) {
      if (u.data)
        std::memcpy(u.dst->mapped, u.data, u.bytes);
      else
        std::memset(u.dst->mapped, 0, u.dst->size);
    }
    return {};
  }
  VkDeviceSize total = 0;
  for (const Upload& u : uploads)
    total += u.data ? u.bytes : 0;
  auto st = create_buffer(*ctx, std::max<VkDeviceSize>(total, 16), VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          MemoryUse::host_upload, true, "upload staging");
  if (!st)
    return st.error();
  const Buffer& stage = *st;
  const auto& v = vk();
  VkDeviceSize at = 0;
  return commands->submit_and_wait([&](VkCommandBuffer c) {
    for (const Upload& u : uploads) {
      if (!u.data) {
        v.vkCmdFillBuffer(c, u.dst->buffer, 0, VK_WHOLE_SIZE, 0);
        continue;
      }
      if (u.bytes == 0)
        continue;
      std::memcpy(static_cast<char*>(stage.mapped) + at, u.data, u.bytes);
      const VkBufferCopy region{at, 0, u.bytes};
      v.vkCmdCopyBuffer(c, stage.buffer, u.dst->buffer, 1, &region);
      at += u.bytes;
    }
    barriers::transfer_to_compute(v, c);
  });
}

SolverBatch::Normals SolverBatch::normals_of(const ClothTopology& topology) {
  if (topology.grid())
    return Normals::grid; // every grid, even one without triangles (a strip: zero normals)
  return topology.ring_normals() ? Normals::ring : Normals::none;
}

Result<std::unique_ptr<SolverBatch>>
SolverBatch::create(const std::shared_ptr<Context::Impl>& ctx, CommandContext& commands,
                    const ClothTopology& topology, std::vector<SimParams> params,
                    const GpuSolverOptions& options, const testing::SolverKnobs& knobs,
                    const std::vector<SlotState>& states) {
  for (SimParams& p : params)
    VKCLOTH_TRY(p.validate());
  auto chosen =
      resolve_layout(*ctx, options, !params.empty() && params[0].integrator == Integrator::implicit_euler);
  if (!chosen)
    return chosen.error();
  auto grid = check_limits(*ctx, topology, params.size(), options, knobs, *chosen);
  if (!grid)
    return grid.error();

  std::unique_ptr<SolverBatch> impl(new SolverBatch());
  SolverBatch& s = *impl;
  s.ctx = ctx;
  s.commands = &commands;
  s.slots.resize(params.size());
  for (std::size_t k = 0; k < params.size(); ++k)
    s.slots[k].params = std::move(params[k]);
  s.options = options;
  s.knobs = knobs;
  s.count = s.pc.count = static_cast<std::uint32_t>(topology.size());
  s.edges_count = topology.edges().size();
  s.normals = normals_of(topology);
  s.index_count = static_cast<std::uint32_t>(topology.triangles().size());
  s.batch_topology = &topology;
  s.strain_colours.assign(topology.strain_colour_offsets().begin(), topology.strain_colour_offsets().end());
  s.groups_x = grid->x;
  s.groups_y = grid->y;
  s.access = chosen->access;
  s.workgroup = chosen->workgroup_size;
  if (const auto& g = topology.grid()) {
    s.nx = s.pc.nx = g->nx;
    s.ny = s.pc.ny = g->ny;
  }
  // On failure `impl` frees whatever the phases created so far.
  VKCLOTH_TRY(s.create_buffers());
  if (!knobs.csr_only)
    s.set_stencil(topology);
  s.passes = make_solver_passes();
  VKCLOTH_TRY(s.init_state_sets());
  VKCLOTH_TRY(s.write_sets());
  s.write_params_now();
  VKCLOTH_TRY(s.upload_initial_state(topology, states));
  VKCLOTH_TRY(s.ensure_tethers());
  VKCLOTH_TRY(s.ensure_strain_chains());
  VKCLOTH_TRY(s.ensure_targets());
  VKCLOTH_TRY(s.ensure_frames());
  VKCLOTH_TRY(s.prepare_passes());
  return impl;
}

} // namespace vkcloth::gpu
