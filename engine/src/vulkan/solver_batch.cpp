// SPDX-License-Identifier: MIT
// SolverBatch: buffers, uploads, readbacks and divergence flags of one batch (the recording of
// the steps: solver_batch_record.cpp; the descriptor sets and pipelines: solver_pipelines.cpp).
#include "solver_batch.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "../core/kernel.hpp"
#include "barriers.hpp"
#include "implicit_gpu.hpp"
#include "vkcloth/gpu/world.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

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

std::string vec_str(glm::vec3 v) {
  return fmt::format("({:.4g}, {:.4g}, {:.4g})", double(v.x), double(v.y), double(v.z));
}

/// The largest storage buffer: the device's maxStorageBufferRange, or the testing knob below it.
struct StorageLimit {
  std::uint64_t bytes;
  const char* source;
};
StorageLimit storage_limit(const Context::Impl& ctx, const testing::SolverKnobs& knobs) {
  const std::uint64_t device = ctx.properties.limits.maxStorageBufferRange;
  if (knobs.max_storage_buffer_bytes && knobs.max_storage_buffer_bytes < device)
    return {knobs.max_storage_buffer_bytes, "testing::SolverKnobs::max_storage_buffer_bytes"};
  return {device, "maxStorageBufferRange"};
}

/// A buffer of `items` x `per` bytes within the storage limit, else the error naming both.
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

/// A texel buffer view of `texels` texels within maxTexelBufferElements, else the error naming
/// `what` and the limit, ending with `advice`.
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
    return {};
  std::vector<ColliderMesh::Node> nodes;
  std::vector<ColliderMesh::Triangle> tris;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> starts;
  for (const auto& m : wanted) {
    starts.emplace_back(static_cast<std::uint32_t>(nodes.size()), static_cast<std::uint32_t>(tris.size()));
    nodes.insert(nodes.end(), m->nodes().begin(), m->nodes().end());
    tris.insert(tris.end(), m->triangles().begin(), m->triangles().end());
  }
  static_assert(sizeof(ColliderMesh::Node) == sizeof(sh::MeshNode) &&
                sizeof(ColliderMesh::Triangle) == sizeof(sh::MeshTriangle));
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
  meshes = std::move(wanted);
  mesh_starts = std::move(starts);
  VKCLOTH_TRY(create_buffer_views());
  if (sets[0][0])
    VKCLOTH_TRY(write_sets());
  return {};
}

// Each collider as the kernel takes it (kernel_shape<float>: CpuSolver<float>'s conversion).
std::vector<sh::Collider> SolverBatch::packed_colliders() const {
  std::vector<sh::Collider> out;
  for (const Slot& slot : slots)
    for (const Collider& c : slot.params.colliders) {
      std::pair<std::uint32_t, std::uint32_t> start{0, 0};
      if (c.mesh)
        start = mesh_starts[std::size_t(std::find(meshes.begin(), meshes.end(), c.mesh) - meshes.begin())];
      const auto k = kernel::kernel_shape<float>(c, start.first, start.second);
      const auto v4 = [](glm::vec3 v, float w) { return sh::vec4{v.x, v.y, v.z, w}; };
      sh::Collider g{};
      g.shape = v4(k.a, k.b);
      g.type = k.type;
      g.moving = k.moving ? 1u : 0u;
      g.mesh_root = k.mesh_root;
      g.mesh_tri0 = k.mesh_tri0;
      g.end_b = v4(k.c, 0.0f);
      g.axis_x = v4(k.ax, 0.0f);
      g.axis_y = v4(k.ay, 0.0f);
      g.axis_z = v4(k.az, 0.0f);
      g.velocity = v4(k.velocity, k.mu_k);
      g.spin = v4(k.spin, k.mu_s);
      g.pivot = v4(k.pivot, 0.0f);
      out.push_back(g);
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
               (params.self_collision.enabled ? VKCLOTH_FLAG_SELF_COLLISION : 0u);
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
  if (self_collision) {
    const auto sp = packed_self_params();
    std::memcpy(self_collision->params().mapped, sp.data(), sp.size() * sizeof(sh::SelfParams));
  }
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

void SolverBatch::carry_over(std::uint32_t slot, const Slot& old) {
  Slot& now = slots[slot];
  now.step = now.epoch_step = old.step; // flag steps count from this batch's creation
  now.time = old.time;
  now.diverged = old.diverged;
  // first_bad_step 0 is before every recorded step (1-based): frozen() holds from the first one.
  if (now.diverged)
    static_cast<sh::Flags*>(flags.mapped)[slot] = sh::Flags{1, 0, 0, 0};
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
  SimParams previous = std::exchange(slots[slot].params, std::move(params));
  params_dirty = true;
  auto done = [&]() -> Result<void> {
    VKCLOTH_TRY(ensure_collider_capacity());
    VKCLOTH_TRY(ensure_mesh_buffers());
    VKCLOTH_TRY(ensure_implicit());
    VKCLOTH_TRY(ensure_fused());
    VKCLOTH_TRY(ensure_collider_pipelines());
    VKCLOTH_TRY(ensure_self_collision());
    VKCLOTH_TRY(ensure_projection());
    return ensure_tethers();
  }();
  if (!done) // e.g. no room for the tethers: the instance keeps stepping with its old parameters
    slots[slot].params = std::move(previous);
  return done;
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

Result<void> SolverBatch::ensure_implicit() {
  if (family().integrator != Integrator::implicit_euler || implicit)
    return {};
  using D = GpuSolverOptions::CgDispatch;
  std::uint32_t max_degree = 0;
  const auto gather = batch_topology->edge_offsets();
  for (std::size_t p = 0; p + 1 < gather.size(); ++p)
    max_degree = std::max(max_degree, gather[p + 1] - gather[p]);
  const std::uint32_t budget = ImplicitGpu::iteration_budget(count, max_degree);
  if (options.cg_dispatch == D::one_workgroup && budget == 0)
    return make_error(
        ErrorCode::unsupported,
        fmt::format("GpuSolverOptions::cg_dispatch = one_workgroup: {} particles with up to {} springs "
                    "each are too many for one workgroup; use automatic or per_iteration",
                    count, max_degree));
  // automatic: one workgroup only where it was measured to win (lavapipe, docs/performance.md);
  // a GPU runs a single workgroup on one of its many compute units.
  const bool cpu_device = ctx->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const bool one_workgroup = options.cg_dispatch == D::one_workgroup ||
                             (options.cg_dispatch == D::automatic && cpu_device && budget > 0 &&
                              count <= implicit_one_workgroup_max_particles);
  auto r = ImplicitGpu::create(ctx, count, edges_count, groups_x, groups_y, one_workgroup ? budget : 0,
                               !knobs.force_staging);
  if (!r)
    return r.error();
  implicit = std::move(*r);
  return write_sets();
}

// Made when an instance first turns self-collision on: its buffers (the rest positions uploaded,
// the counts zeroed) and descriptor sets, which nothing recorded so far uses. Its parameters are
// written straight into the mapped buffer here: no recorded work reads it yet.
Result<void> SolverBatch::ensure_self_collision() {
  if (self_collision || self_iterations() == 0)
    return {};
  // Its largest buffer holds two vec4 per particle of every instance (a move and a velocity change).
  VKCLOTH_TRY(check_buffer(*ctx, storage_limit(*ctx, knobs), "self-collision moves",
                           std::uint64_t(size()) * count, 32));
  auto r = SelfCollisionGpu::create(ctx, count, size(), ctx->properties.limits.maxComputeWorkGroupCount[0],
                                    !knobs.force_staging, access);
  if (!r)
    return r.error();
  self_collision = std::move(*r);
  std::vector<sh::vec4> rest(count);
  for (std::uint32_t p = 0; p < count; ++p) { // as CpuSolver<float>::self_collide makes them
    const Particle& q = batch_topology->system().particles[p];
    rest[p] = {float(q.position.x), float(q.position.y), float(q.position.z),
               kernel::inverse_mass(float(q.mass), q.pinned)};
  }
  const Upload up[] = {{&self_collision->rest_positions(), rest.data(), rest.size() * sizeof(sh::vec4)},
                       {&self_collision->counts(), nullptr, 0}};
  VKCLOTH_TRY(upload(up));
  const auto sp = packed_self_params();
  std::memcpy(self_collision->params().mapped, sp.data(), sp.size() * sizeof(sh::SelfParams));
  // Only its own new sets: the main ones may be in use by recorded work (set_params).
  return self_collision->write_sets(one_set_inputs());
}

// Made when an instance first asks for the fast projection: its buffers (each particle's links
// uploaded) and its own descriptor sets, which nothing recorded so far uses.
Result<void> SolverBatch::ensure_projection() {
  if (projection || projection_iterations() == 0)
    return {};
  // Its largest buffer holds two vec4 per strain link of every instance.
  VKCLOTH_TRY(check_buffer(*ctx, storage_limit(*ctx, knobs), "strain projection links",
                           std::uint64_t(size()) * strain_link_count(), 32));
  auto r = StrainProjectionGpu::create(ctx, *batch_topology, size(), !knobs.force_staging);
  if (!r)
    return r.error();
  projection = std::move(*r);
  const std::vector<std::uint32_t> incidence = StrainProjectionGpu::incidence_data(*batch_topology);
  const Upload up[] = {{&projection->incidence(), incidence.data(), incidence.size() * 4}};
  VKCLOTH_TRY(upload(up));
  return projection->write_sets(one_set_inputs());
}

std::vector<sh::SelfParams> SolverBatch::packed_self_params() const {
  std::vector<const SimParams*> params;
  for (const Slot& s : slots)
    params.push_back(&s.params);
  return SelfCollisionGpu::packed(params);
}

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
  VKCLOTH_TRY(s.init_pipelines());
  VKCLOTH_TRY(s.write_sets());
  VKCLOTH_TRY(s.ensure_implicit());
  VKCLOTH_TRY(s.ensure_fused());
  VKCLOTH_TRY(s.ensure_collider_pipelines());
  s.write_params_now();
  VKCLOTH_TRY(s.upload_initial_state(topology, states));
  VKCLOTH_TRY(s.ensure_tethers());
  VKCLOTH_TRY(s.ensure_self_collision());
  VKCLOTH_TRY(s.ensure_projection());
  return impl;
}

} // namespace vkcloth::gpu
