// SPDX-License-Identifier: MIT
// SolverBatch's colliders: the buffer of every instance's colliders, the mesh colliders' nodes,
// triangles and search entries, and the colliders as the kernel takes them (the rest of the batch:
// solver_batch.cpp).
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

#include "internal/kernel.hpp"
#include "batch_limits.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

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

bool SolverBatch::any_colliders() const {
  return std::any_of(slots.begin(), slots.end(), [](const Slot& s) { return !s.params.colliders.empty(); });
}

std::uint32_t SolverBatch::collider_types() const {
  std::uint32_t types = 0;
  for (const Slot& s : slots)
    for (const Collider& c : s.params.colliders)
      types |= 1u << std::uint32_t(c.type);
  return types;
}

} // namespace vkcloth::gpu
