// SPDX-License-Identifier: MIT
// SolverBatch: buffers, uploads, readbacks and divergence flags of one batch (the recording of
// the steps: solver_batch_record.cpp; the colliders: solver_batch_colliders.cpp; the state set:
// solver_state_set.cpp; the passes: passes/).
#include "solver_batch.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "internal/argument_checks.hpp"
#include "internal/kernel.hpp"
#include "internal/self_collision.hpp"
#include "internal/barriers.hpp"
#include "batch_limits.hpp"
#include "passes/implicit_update.hpp"
#include "vkcloth/gpu/world.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

namespace {

std::string vec_str(glm::vec3 v) {
  return fmt::format("({:.4g}, {:.4g}, {:.4g})", double(v.x), double(v.y), double(v.z));
}

} // namespace

std::vector<sh::InstanceParams> SolverBatch::packed_instance_params() const {
  std::vector<sh::InstanceParams> out;
  std::uint32_t first_collider = 0;
  for (const Slot& slot : slots) {
    const SimParams& params = slot.params;
    // Conversions exactly as CpuSolver<float>: each double field cast to float, then float math.
    const float dt =
        float(params.substeps == 1 ? params.dt : params.dt / double(params.substeps)); // as the CPU
    sh::InstanceParams ip{};
    ip.flags = normal_flag(normals) | (float(params.wind.strength) != 0.0f ? VKCLOTH_FLAG_WIND : 0u) |
               (params.contact_inward_only ? 0u : VKCLOTH_FLAG_CONTACT_BOTH) |
               (options.flip_normals ? VKCLOTH_FLAG_FLIP_NORMALS : 0u) |
               (vkcloth::detail::self_collision_passes<float>(params)
                    ? VKCLOTH_FLAG_SELF_COLLISION // the passes after the step (and the projection after them)
                    : 0u);
    ip.integrator = static_cast<std::uint32_t>(params.integrator);
    ip.collider_first = first_collider;
    ip.collider_count = static_cast<std::uint32_t>(params.colliders.size());
    first_collider += ip.collider_count;
    ip.gravity_damping = {float(params.gravity.x), float(params.gravity.y), float(params.gravity.z),
                          float(params.damping)};
    ip.wind = {float(params.wind.direction.x), float(params.wind.direction.y), float(params.wind.direction.z),
               float(params.wind.strength)};
    ip.dt = dt;
    ip.w6 = dt / 6.0f;
    ip.eps = float(params.contact_epsilon);
    ip.band = 2.0f * ip.eps;
    ip.limit = float(params.divergence_limit);
    const StretchLimit& sl = params.stretch_limit;
    ip.max_strain = float(sl.max_strain);
    ip.stretch = (sl.provot() ? VKCLOTH_STRETCH_PROVOT : 0u) | (sl.tethers() ? VKCLOTH_STRETCH_TETHERS : 0u) |
                 (sl.projection() ? VKCLOTH_STRETCH_PROJECTION : 0u) |
                 (sl.chains() ? VKCLOTH_STRETCH_CHAINS : 0u) |
                 (sl.tethers() && sl.tether_distance == StretchLimit::TetherDistance::geodesic
                      ? VKCLOTH_STRETCH_GEODESIC
                      : 0u);
    ip.stretch_sweeps = sl.iterations;
    out.push_back(ip);
  }
  return out;
}

// At creation (no recorded work yet): straight into the mapped buffers.
void SolverBatch::write_params_now() {
  const auto ip = packed_instance_params();
  std::memcpy(instances.mapped, ip.data(), ip.size() * sizeof(sh::InstanceParams));
  const auto col = packed_colliders();
  if (!col.empty())
    std::memcpy(colliders.mapped, col.data(), col.size() * sizeof(sh::Collider));
  for (const auto& pass : passes)
    pass->write_params(*this, VK_NULL_HANDLE);
  params_dirty = false;
}

const Buffer& SolverBatch::buffer_of(Field field) const {
  switch (field) {
  case Field::positions:
    return pos[parity];
  case Field::velocities:
    return vel;
  case Field::normals:
    return normal;
  case Field::forces:
    return force;
  }
  return pos[parity];
}

// `bytes` of `b` from byte `offset`: straight from mapped memory, or through a staging copy.
Result<std::vector<float>> SolverBatch::read_floats(const Buffer& b, VkDeviceSize offset,
                                                    VkDeviceSize bytes) {
  Buffer tmp; // staging, when `b` is not mapped
  if (!b.mapped) {
    auto s = create_buffer(*ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::host_readback, true,
                           "readback staging");
    if (!s)
      return s.error();
    tmp = std::move(*s);
  }
  VKCLOTH_TRY(commands->submit_and_wait([&](VkCommandBuffer c) {
    barriers::before_readback(vk(), c);
    if (tmp.buffer) {
      const VkBufferCopy region{offset, 0, bytes};
      vk().vkCmdCopyBuffer(c, b.buffer, tmp.buffer, 1, &region);
      barriers::transfer_to_host(vk(), c);
    }
  }));
  const auto* src =
      tmp.buffer ? static_cast<const char*>(tmp.mapped) : static_cast<const char*>(b.mapped) + offset;
  std::vector<float> out(bytes / sizeof(float));
  std::memcpy(out.data(), src, out.size() * sizeof(float));
  return out;
}

Result<std::vector<glm::vec3>> SolverBatch::read(Field field, std::uint32_t slot) {
  auto f = read_floats(buffer_of(field), slot_offset(slot), slot_bytes());
  if (!f)
    return f.error();
  std::vector<glm::vec3> out(count);
  for (std::uint32_t i = 0; i < count; ++i)
    out[i] = glm::vec3((*f)[4 * i], (*f)[4 * i + 1], (*f)[4 * i + 2]);
  return out;
}

Result<std::vector<float>> SolverBatch::read_vertices(std::uint32_t slot) {
  if (!options.interleaved_vertices)
    return make_error(ErrorCode::invalid_argument, "the solver was created without interleaved_vertices");
  return read_floats(vertices, vertex_offset(slot), VkDeviceSize(count) * sizeof(sh::Vertex));
}

void SolverBatch::refresh_flags() {
  const auto* f = static_cast<const sh::Flags*>(flags.mapped);
  for (std::uint32_t k = 0; k < size(); ++k) {
    Slot& slot = slots[k];
    if (slot.diverged || !f[k].diverged)
      continue;
    slot.step = slot.epoch_step + f[k].first_bad_step; // flag steps count from the batch's creation
    const std::uint32_t p = std::min(f[k].bad_particle, count - 1);
    std::string where;
    auto x = read(Field::positions, k);
    auto v = read(Field::velocities, k);
    if (x && v)
      where = fmt::format(": particle {} is at {} with velocity {}", p, vec_str((*x)[p]), vec_str((*v)[p]));
    slot.diverged = make_error(
        ErrorCode::diverged,
        fmt::format("simulation diverged at step {} (t = {:.4g} s) on the GPU{} (limit {:g}); the "
                    "state is left as after that step; {}",
                    slot.step, double(slot.step) * slot.params.dt, where, slot.params.divergence_limit,
                    vkcloth::detail::divergence_advice(slot.params.dt)));
  }
}

Result<void> SolverBatch::carry_over(std::uint32_t slot, const Slot& old) {
  Slot& now = slots[slot];
  now.step = now.epoch_step = old.step; // flag steps count from this batch's creation
  now.time = old.time;
  now.diverged = old.diverged;
  // first_bad_step 0 is before every recorded step (1-based): frozen() holds from the first one.
  if (now.diverged)
    static_cast<sh::Flags*>(flags.mapped)[slot] = sh::Flags{1, 0, 0, 0};
  now.targets = old.targets;
  now.host_jump = old.host_jump;
  now.frame_last = old.frame_last;
  VKCLOTH_TRY(ensure_targets());
  VKCLOTH_TRY(ensure_frames());
  return prepare_passes(); // the targets' passes, when only the host's targets ask for them
}

InstanceBuffers SolverBatch::buffers(std::uint32_t slot) const {
  InstanceBuffers b;
  if (options.interleaved_vertices) {
    b.vertices = vertices.buffer;
    b.vertex_offset = vertex_offset(slot);
  }
  b.positions = pos[parity].buffer;
  b.normals = normal.buffer;
  b.uvs = uv.buffer;
  b.indices = indices.buffer;
  b.index_count = index_count;
  b.offset = slot_offset(slot);
  b.count = count;
  b.nx = nx;
  b.ny = ny;
  return b;
}

Result<void> SolverBatch::set_params(std::uint32_t slot, SimParams params) {
  std::optional<Collider> frame_last = slots[slot].frame_last;
  if (!vkcloth::detail::same_frame(params.inertia, slots[slot].params.inertia))
    slots[slot].frame_last.reset();
  SimParams previous = std::exchange(slots[slot].params, std::move(params));
  params_dirty = true;
  auto done = [&]() -> Result<void> {
    VKCLOTH_TRY(ensure_collider_capacity());
    VKCLOTH_TRY(ensure_mesh_buffers());
    VKCLOTH_TRY(ensure_targets());
    VKCLOTH_TRY(ensure_frames());
    VKCLOTH_TRY(prepare_passes());
    VKCLOTH_TRY(ensure_strain_chains());
    return ensure_tethers();
  }();
  if (!done) { // e.g. no room for the tethers: the instance keeps stepping with its old parameters
    slots[slot].params = std::move(previous);
    slots[slot].frame_last = std::move(frame_last);
  }
  return done;
}

Result<void> SolverBatch::set_pin_targets(std::uint32_t slot, std::span<const PinTarget> host) {
  vkcloth::detail::PinTargets previous = slots[slot].targets;
  VKCLOTH_TRY(slots[slot].targets.set_host(slots[slot].params, host, count));
  auto done = [&]() -> Result<void> {
    VKCLOTH_TRY(ensure_targets());
    return prepare_passes();
  }();
  if (!done)
    slots[slot].targets = std::move(previous);
  return done;
}

Result<void> SolverBatch::teleport(std::uint32_t slot, const RigidJump& jump) {
  VKCLOTH_TRY(jump.validate());
  std::optional<RigidJump> previous = slots[slot].host_jump;
  slots[slot].host_jump = previous ? vkcloth::detail::then(*previous, jump) : jump;
  auto done = [&]() -> Result<void> {
    VKCLOTH_TRY(ensure_frames());
    return prepare_passes();
  }();
  if (!done)
    slots[slot].host_jump = std::move(previous);
  return done;
}

bool SolverBatch::any_frame() const {
  return std::any_of(slots.begin(), slots.end(),
                     [](const Slot& s) { return s.params.inertia.enabled() || s.host_jump.has_value(); });
}

// The frames buffer (one FrameMotion per instance) when an instance first has a frame; as
// ensure_targets.
Result<void> SolverBatch::ensure_frames() {
  if (frames_allocated || !any_frame())
    return {};
  VKCLOTH_TRY(replace_state_buffer(frames, size(), sizeof(sh::FrameMotion), "frames"));
  frames_allocated = true;
  return {};
}

// `dst` replaced by a device buffer of `entries` x `stride` bytes, filled by vkCmdUpdateBuffer
// later; recorded work that may use the descriptor sets is waited for before they are rewritten.
Result<void> SolverBatch::replace_state_buffer(Buffer& dst, std::uint64_t entries, VkDeviceSize stride,
                                               const char* what) {
  VKCLOTH_TRY(check_buffer(*ctx, storage_limit(*ctx, knobs), what, entries, stride));
  VKCLOTH_TRY(commands->wait_for_earlier_work());
  auto b = create_buffer(*ctx, entries * stride,
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                         MemoryUse::device, false, what);
  if (!b)
    return b.error();
  dst = std::move(*b);
  if (!sets[0][0]) // creation: the sets are written once they exist
    return {};
  return write_sets();
}

bool SolverBatch::any_targets() const {
  return std::any_of(slots.begin(), slots.end(), [](const Slot& s) { return !s.targets.empty(s.params); });
}

std::uint32_t SolverBatch::targets_per_slot() const {
  std::uint32_t most = 0;
  for (const Slot& s : slots)
    most = std::max(most, s.targets.size(s.params));
  return most;
}

// The targets buffer at its full size (count entries per instance) when an instance first has
// targets; the descriptor sets are rewritten, so recorded work that may use them is waited for.
Result<void> SolverBatch::ensure_targets() {
  if (targets_allocated || !any_targets())
    return {};
  VKCLOTH_TRY(replace_state_buffer(targets, std::uint64_t(size()) * count, sizeof(sh::Target), "targets"));
  targets_allocated = true;
  return {};
}

// The tethers of both rest-length kinds (VKCLOTH_BINDING_TETHERS: euclidean, then geodesic),
// uploaded when an instance first asks for tethers; the buffer replaces the zeroed element.
Result<void> SolverBatch::ensure_tethers() {
  if (!any_tethers() || tethers_uploaded)
    return {};
  // Two kinds x tethers_per_particle slots per particle, one RG32UI texel each: within the limits?
  const std::uint64_t slots_n = 2ull * count * tethers_per_particle;
  VKCLOTH_TRY(check_buffer(*ctx, storage_limit(*ctx, knobs), "tethers", slots_n, sizeof(sh::TetherSlot)));
  if (access == BufferAccess::texel_views) // the storage builds make no texel views
    VKCLOTH_TRY(check_texels(*ctx, "tethers", slots_n, "use fewer particles or stretch_limit.method provot"));
  VKCLOTH_TRY(commands->wait_for_earlier_work()); // write_sets() below: no recorded work may use the sets
  static_assert(VKCLOTH_TETHERS_PER_PARTICLE == tethers_per_particle && VKCLOTH_NO_TETHER == no_tether);
  std::vector<sh::TetherSlot> data;
  data.reserve(slots_n);
  for (auto kind : {StretchLimit::TetherDistance::euclidean, StretchLimit::TetherDistance::geodesic})
    for (const Tether& t : batch_topology->tethers(kind))
      data.push_back({t.anchor, float(t.rest_length)});
  VKCLOTH_TRY(replace_topology_buffer(tethers, tethers_view, data.data(),
                                      data.size() * sizeof(sh::TetherSlot), "tethers"));
  tethers_uploaded = true;
  return {};
}

// The strain links in chain order (ClothTopology::strain_chains()) after the coloured ones, in one
// buffer (VKCLOTH_BINDING_STRAIN_LINKS), uploaded when an instance first asks for Provot's sweeps
// in chain order (passes/stretch.cpp); the buffer replaces the one of the coloured links alone.
Result<void> SolverBatch::ensure_strain_chains() {
  if (strain_chains_uploaded ||
      std::none_of(slots.begin(), slots.end(), [](const Slot& s) { return s.params.stretch_limit.chains(); }))
    return {};
  const auto coloured = batch_topology->strain_links();
  const auto chains = batch_topology->strain_chains();
  const std::uint64_t items = coloured.size() + chains.size();
  VKCLOTH_TRY(check_buffer(*ctx, storage_limit(*ctx, knobs), "strain links", items, sizeof(sh::StrainLink)));
  if (access == BufferAccess::texel_views) // three R32UI texels a link
    VKCLOTH_TRY(check_texels(*ctx, "strain links", 3 * items,
                             "use fewer particles or stretch_limit.order \"colours\""));
  VKCLOTH_TRY(commands->wait_for_earlier_work()); // write_sets() below: no recorded work may use the sets
  std::vector<sh::StrainLink> data;
  data.reserve(items);
  for (const auto links : {coloured, chains})
    for (const StrainLink& l : links)
      data.push_back({l.a, l.b, float(l.rest_length)});
  VKCLOTH_TRY(replace_topology_buffer(strain_links, strain_links_view, data.data(),
                                      data.size() * sizeof(sh::StrainLink), "strain links"));
  strain_chains_uploaded = true;
  return {};
}

// `dst` replaced by a device buffer holding `bytes` of `data` (read through the texel view `view`
// too): the view goes before its buffer, then the views and the descriptor sets are made again (the
// caller has waited for the recorded work that may use them).
Result<void> SolverBatch::replace_topology_buffer(Buffer& dst, BufferView& view, const void* data,
                                                  VkDeviceSize bytes, const char* what) {
  auto b = create_buffer(*ctx, std::max<VkDeviceSize>(bytes, 16),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                             VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT,
                         MemoryUse::device, !knobs.force_staging, what);
  if (!b)
    return b.error();
  view.reset();
  dst = std::move(*b);
  const Upload up[] = {{&dst, data, bytes}};
  VKCLOTH_TRY(upload(up));
  VKCLOTH_TRY(create_buffer_views());
  return write_sets();
}

Result<void> SolverBatch::prepare_passes() {
  for (const auto& pass : passes)
    VKCLOTH_TRY(pass->prepare(*this));
  return {};
}

SolveStats SolverBatch::last_solve() const {
  for (const auto& pass : passes)
    if (const auto* implicit = dynamic_cast<const ImplicitUpdate*>(pass.get()))
      return implicit->stats();
  return {};
}

bool SolverBatch::implicit_one_workgroup() const {
  for (const auto& pass : passes)
    if (const auto* implicit = dynamic_cast<const ImplicitUpdate*>(pass.get()))
      return implicit->one_workgroup();
  return false;
}

bool SolverBatch::any_stretch() const {
  return std::any_of(slots.begin(), slots.end(),
                     [](const Slot& s) { return s.params.stretch_limit.enabled(); });
}

bool SolverBatch::any_tethers() const {
  return std::any_of(slots.begin(), slots.end(),
                     [](const Slot& s) { return s.params.stretch_limit.tethers(); });
}

std::uint32_t SolverBatch::projection_iterations() const {
  std::uint32_t most = 0;
  for (const Slot& s : slots)
    if (s.params.stretch_limit.projection())
      most = std::max(most, s.params.stretch_limit.iterations);
  return most;
}

std::uint32_t SolverBatch::self_iterations() const {
  std::uint32_t most = 0;
  for (const Slot& s : slots)
    if (vkcloth::detail::self_collision_passes<float>(s.params))
      most = std::max(most, s.params.self_collision.iterations);
  return most;
}

bool SolverBatch::any_self_energy() const {
  return std::any_of(slots.begin(), slots.end(),
                     [](const Slot& s) { return vkcloth::detail::self_contact_energy<float>(s.params); });
}

} // namespace vkcloth::gpu
