// SPDX-License-Identifier: MIT
// SolverBatch: buffers, uploads, readbacks and divergence flags of one batch (the recording of
// the steps: solver_batch_record.cpp; the state set: solver_state_set.cpp; the passes: passes/).
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

#include "../core/kernel.hpp"
#include "../core/self_collision.hpp"
#include "barriers.hpp"
#include "batch_limits.hpp"
#include "passes/implicit_update.hpp"
#include "vkcloth/gpu/world.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

namespace {

std::string vec_str(glm::vec3 v) {
  return fmt::format("({:.4g}, {:.4g}, {:.4g})", double(v.x), double(v.y), double(v.z));
}

} // namespace

// The collider buffer holds every instance's colliders (InstanceParams::collider_first); more
// colliders than it has room for replace it and rewrite the descriptor sets, so recorded work that
// may still read the old one is waited for first.
Result<void> SolverBatch::ensure_collider_capacity() {
  std::uint32_t n = 0;
  for (const Slot& slot : slots)
    n += static_cast<std::uint32_t>(slot.params.colliders.size());
  if (n <= collider_capacity && colliders.buffer)
    return {};
  if (colliders.buffer)
    VKCLOTH_TRY(commands->wait_for_earlier_work());
  const std::uint32_t cap = std::max<std::uint32_t>(n, 4);
  if (access == BufferAccess::texel_views) // the *_texel builds read the colliders through a view
    VKCLOTH_TRY(
        check_texels(*ctx, "colliders", std::uint64_t(cap) * VKCLOTH_COLLIDER_TEXELS, "use fewer colliders"));
  auto b = create_buffer(*ctx, cap * sizeof(sh::Collider),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                             VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT,
                         MemoryUse::host_upload, true, "colliders");
  if (!b)
    return b.error();
  colliders_view.reset(); // before the buffer it views
  colliders = std::move(*b);
  collider_capacity = cap;
  VKCLOTH_TRY(create_buffer_views());
  if (sets[0][0])
    VKCLOTH_TRY(write_sets());
  return {};
}

// Every distinct mesh of the batch's colliders, uploaded once; a new set of meshes replaces the
// buffers and rewrites the descriptor sets (recorded work that may read the old ones is waited for).
Result<void> SolverBatch::ensure_mesh_buffers() {
  std::vector<std::shared_ptr<const ColliderMesh>> wanted;
  for (const Slot& slot : slots)
    for (const Collider& c : slot.params.colliders)
      if (c.mesh && std::find(wanted.begin(), wanted.end(), c.mesh) == wanted.end())
        wanted.push_back(c.mesh);
  if (mesh_nodes.buffer && wanted == meshes)
    return ensure_mesh_cache();
  std::vector<ColliderMesh::Node> nodes;
  std::vector<ColliderMesh::Triangle> tris;
  std::vector<std::array<std::uint32_t, 4>> starts;
  for (const auto& m : wanted) {
    starts.push_back({static_cast<std::uint32_t>(nodes.size()), static_cast<std::uint32_t>(tris.size()),
                      VKCLOTH_MESH_NONE, 0});
    nodes.insert(nodes.end(), m->nodes().begin(), m->nodes().end());
    tris.insert(tris.end(), m->triangles().begin(), m->triangles().end());
  }
  for (std::size_t k = 0; k < wanted.size(); ++k) // a skinned mesh's corner velocities, after them all
    if (!wanted[k]->triangle_velocities().empty()) {
      starts[k][2] = static_cast<std::uint32_t>(tris.size());
      tris.insert(tris.end(), wanted[k]->triangle_velocities().begin(),
                  wanted[k]->triangle_velocities().end());
    }
  for (std::size_t k = 0; k < wanted.size(); ++k) { // their neighbours, four triangles' to a record
    starts[k][3] = static_cast<std::uint32_t>(tris.size());
    const std::span<const std::uint32_t> adj = wanted[k]->neighbours();
    std::vector<float> words((adj.size() + 11) / 12 * 12, std::bit_cast<float>(VKCLOTH_MESH_NONE));
    for (std::size_t w = 0; w < adj.size(); ++w)
      words[w] = std::bit_cast<float>(adj[w]);
    for (std::size_t r = 0; r < words.size(); r += 12)
      tris.push_back({{words[r], words[r + 1], words[r + 2]},
                      words[r + 3],
                      {words[r + 4], words[r + 5], words[r + 6]},
                      words[r + 7],
                      {words[r + 8], words[r + 9], words[r + 10]},
                      words[r + 11]});
  }
  static_assert(sizeof(ColliderMesh::Node) == sizeof(sh::MeshNode) &&
                sizeof(ColliderMesh::Triangle) == sizeof(sh::MeshTriangle));
  if (mesh_nodes.buffer && nodes.size() == mesh_node_count && tris.size() == mesh_tri_count) {
    // The same counts (a skinned mesh's next pose): recorded into the buffers, no wait.
    mesh_nodes_pending = std::move(nodes);
    mesh_tris_pending = std::move(tris);
    meshes = std::move(wanted);
    mesh_starts = std::move(starts);
    params_dirty = true;
    return ensure_mesh_cache();
  }
  const StorageLimit limit = storage_limit(*ctx, knobs);
  VKCLOTH_TRY(check_buffer(*ctx, limit, "mesh collider hierarchy", nodes.size(), sizeof(sh::MeshNode)));
  VKCLOTH_TRY(check_buffer(*ctx, limit, "mesh collider triangles", tris.size(), sizeof(sh::MeshTriangle)));
  if (access == BufferAccess::texel_views) { // the *_texel builds read them through views
    VKCLOTH_TRY(
        check_texels(*ctx, "mesh collider nodes", 2ull * nodes.size(), "use a mesh of fewer triangles"));
    VKCLOTH_TRY(
        check_texels(*ctx, "mesh collider triangles", 3ull * tris.size(), "use a mesh of fewer triangles"));
  }
  if (mesh_nodes.buffer)
    VKCLOTH_TRY(commands->wait_for_earlier_work());
  Buffer new_nodes, new_tris;
  const struct {
    Buffer* dst;
    VkDeviceSize bytes;
    const char* name;
  } made[] = {
      {&new_nodes, std::max<std::size_t>(nodes.size(), 1) * sizeof(sh::MeshNode), "mesh nodes"},
      {&new_tris, std::max<std::size_t>(tris.size(), 1) * sizeof(sh::MeshTriangle), "mesh triangles"}};
  for (const auto& m : made) {
    auto b = create_buffer(*ctx, m.bytes,
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                               VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT,
                           MemoryUse::device, !knobs.force_staging, m.name);
    if (!b)
      return b.error();
    *m.dst = std::move(*b);
  }
  mesh_nodes_view.reset(); // before the buffers they view
  mesh_tris_view.reset();
  mesh_nodes = std::move(new_nodes);
  mesh_tris = std::move(new_tris);
  const Upload up[] = {
      {&mesh_nodes, nodes.empty() ? nullptr : nodes.data(), nodes.size() * sizeof(sh::MeshNode)},
      {&mesh_tris, tris.empty() ? nullptr : tris.data(), tris.size() * sizeof(sh::MeshTriangle)}};
  VKCLOTH_TRY(upload(up));
  mesh_node_count = nodes.size();
  mesh_tri_count = tris.size();
  mesh_nodes_pending.clear();
  mesh_tris_pending.clear();
  meshes = std::move(wanted);
  mesh_starts = std::move(starts);
  VKCLOTH_TRY(create_buffer_views());
  if (sets[0][0])
    VKCLOTH_TRY(write_sets());
  return ensure_mesh_cache();
}

// The particles' search entries for the instances' mesh colliders: a new, emptied buffer when the
// meshes the entries were found on change (entries only save searches: emptied, they change no result).
Result<void> SolverBatch::ensure_mesh_cache() {
  std::vector<std::vector<const ColliderMesh*>> key;
  std::size_t most = 0;
  for (const Slot& slot : slots) {
    std::vector<const ColliderMesh*> m;
    for (const Collider& c : slot.params.colliders)
      if (c.type == Collider::Type::mesh)
        m.push_back(c.mesh.get());
    most = std::max(most, m.size());
    key.push_back(std::move(m));
  }
  if (key == mesh_cache_key || most == 0) {
    mesh_cache_key = std::move(key);
    return {};
  }
  const std::uint64_t entries = std::uint64_t(most) * size() * count;
  if (entries != mesh_cache_entries) { // a new size: a new buffer (waits for recorded work)
    VKCLOTH_TRY(
        replace_state_buffer(mesh_cache, entries, 2 * sizeof(sh::vec4), "mesh collider search entries"));
    mesh_cache_entries = entries;
  }
  mesh_cache_key = std::move(key);
  mesh_cache_clear = true; // emptied by a fill at the next record(), no wait
  return {};
}

// Each collider as the kernel takes it (kernel_shape<float>: CpuSolver<float>'s conversion).
std::vector<sh::Collider> SolverBatch::packed_colliders() const {
  std::vector<sh::Collider> out;
  for (const Slot& slot : slots) {
    std::uint32_t mesh_ordinal = 0;
    for (const Collider& c : slot.params.colliders) {
      std::array<std::uint32_t, 4> start{0, 0, 0, 0};
      std::uint32_t cache = 0;
      if (c.mesh)
        start = mesh_starts[std::size_t(std::find(meshes.begin(), meshes.end(), c.mesh) - meshes.begin())];
      if (c.type == Collider::Type::mesh)
        cache = mesh_ordinal++ * size() * count;
      const auto k = kernel::kernel_shape<float>(c, start[0], start[1], cache, start[2], start[3]);
      const auto v4 = [](glm::vec3 v, float w) { return sh::vec4{v.x, v.y, v.z, w}; };
      sh::Collider g{};
      g.shape = v4(k.a, k.b);
      g.type = k.type;
      g.moving = k.moving ? 1u : 0u;
      g.mesh_root = k.mesh_root;
      g.mesh_tri0 = k.mesh_tri0;
      g.end_b = v4(k.c, std::bit_cast<float>(k.mesh_vel0));
      g.axis_x = v4(k.ax, std::bit_cast<float>(k.mesh_adj0));
      g.axis_y = v4(k.ay, 0.0f);
      g.axis_z = v4(k.az, 0.0f);
      g.velocity = v4(k.velocity, k.mu_k);
      g.spin = v4(k.spin, k.mu_s);
      g.pivot = v4(k.pivot, std::bit_cast<float>(k.mesh_cache));
      out.push_back(g);
    }
  }
  return out;
}

bool SolverBatch::any_moving_colliders() const {
  for (const Slot& s : slots)
    for (const Collider& c : s.params.colliders)
      if (c.moving())
        return true;
  return false;
}

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
                    "state is left as after that step; try a smaller integrator.dt, lower "
                    "stiffness or more damping",
                    slot.step, double(slot.step) * slot.params.dt, where, slot.params.divergence_limit));
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
  const VkDeviceSize bytes = data.size() * sizeof(sh::TetherSlot);
  auto b = create_buffer(*ctx, bytes,
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                             VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT,
                         MemoryUse::device, !knobs.force_staging, "tethers");
  if (!b)
    return b.error();
  tethers_view.reset(); // before the buffer it views
  tethers = std::move(*b);
  const Upload up[] = {{&tethers, data.data(), bytes}};
  VKCLOTH_TRY(upload(up));
  tethers_uploaded = true;
  VKCLOTH_TRY(create_buffer_views());
  return write_sets();
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
  const VkDeviceSize bytes = std::max<VkDeviceSize>(data.size() * sizeof(sh::StrainLink), 16);
  auto b = create_buffer(*ctx, bytes,
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                             VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT,
                         MemoryUse::device, !knobs.force_staging, "strain links");
  if (!b)
    return b.error();
  strain_links_view.reset(); // before the buffer it views
  strain_links = std::move(*b);
  const Upload up[] = {{&strain_links, data.data(), data.size() * sizeof(sh::StrainLink)}};
  VKCLOTH_TRY(upload(up));
  strain_chains_uploaded = true;
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

bool SolverBatch::any_colliders() const {
  return std::any_of(slots.begin(), slots.end(), [](const Slot& s) { return !s.params.colliders.empty(); });
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

std::uint32_t SolverBatch::collider_types() const {
  std::uint32_t types = 0;
  for (const Slot& s : slots)
    for (const Collider& c : s.params.colliders)
      types |= 1u << std::uint32_t(c.type);
  return types;
}

} // namespace vkcloth::gpu
