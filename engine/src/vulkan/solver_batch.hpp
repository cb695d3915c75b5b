// SPDX-License-Identifier: MIT
// SolverBatch: the Vulkan solver's engine, a BATCH of instances (cloths) that share one topology
// and one integrator family, stepped together: one dispatch per pass serves every instance
// (instance = gl_WorkGroupID.z, vkcloth_shared.h). ClothWorld owns its batches and groups its
// instances into them (world.cpp); a GpuSolver is a world of one instance (gpu_solver.cpp).
// The batch owns the state (per-particle buffers, the shared topology, colliders, parameters,
// flags) and the state set that binds it; each feature of the step is a pass (passes/pass.hpp) that
// owns its pipelines and its own buffers, and the batch records its passes in list order
// (passes/passes.cpp). Layouts and pipelines are the Context's (pipelines.hpp). Internal to
// engine/src/vulkan.
//
// Topology: create() reads a prepared ClothTopology (gather lists, grid stencil, normal fans,
// triangles, uvs, particles); the world keys batches by the shared topology object.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "internal/cloth_frame.hpp"
#include "internal/pin_targets.hpp"
#include "passes/implicit_gpu.hpp"
#include "passes/pass.hpp"
#include "internal/pipelines.hpp"
#include "internal/resources.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/testing.hpp"
#include "vkcloth/topology.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

class SelfCollisionGpu;

/// Optional initial state of one instance (empty vectors: the topology's).
struct SlotState {
  const std::vector<glm::dvec3>* positions = nullptr;
  const std::vector<glm::dvec3>* velocities = nullptr;
};

class SolverBatch {
public:
  /// Host-side state of one instance of the batch.
  struct Slot {
    SimParams params;
    std::uint64_t step = 0;       // completed steps (the bad one when diverged)
    std::uint64_t epoch_step = 0; // `step` when this batch's flag epoch began (its creation)
    double time = 0.0;            // simulated time: the sum of the recorded steps' dt
    std::optional<Error> diverged;
    // Attachments and the host's pin targets (docs/model.md "Attachments and motion constraints").
    vkcloth::detail::PinTargets targets;
    std::optional<RigidJump> host_jump; // the host's teleport, for the next recorded step
    std::optional<Collider> frame_last; // its frame as the last recorded substep left it
  };
  /// The per-particle buffers a readback can copy.
  enum class Field { positions, velocities, normals, forces };

  /// A batch of `params.size()` instances of `topology` (all of one integrator family and one
  /// substep count: Euler (explicit and semi-implicit mix), RK4, or implicit Euler (one
  /// instance)); `states[k]` is instance k's initial state (missing entries: the topology's).
  /// `commands` (the owner's) serves the uploads and readbacks and must outlive the batch.
  static Result<std::unique_ptr<SolverBatch>>
  create(const std::shared_ptr<Context::Impl>& ctx, CommandContext& commands, const ClothTopology& topology,
         std::vector<SimParams> params, const GpuSolverOptions& options, const testing::SolverKnobs& knobs,
         const std::vector<SlotState>& states = {});
  SolverBatch(const SolverBatch&) = delete;
  SolverBatch& operator=(const SolverBatch&) = delete;

  std::uint32_t size() const { return static_cast<std::uint32_t>(slots.size()); }
  std::uint32_t particle_count() const { return count; }
  const Slot& slot(std::uint32_t k) const { return slots[k]; }
  /// A collider of some instance moves: the record advances it after every substep.
  bool any_moving_colliders() const;
  /// New parameters for one instance (validated by the caller; same family and substeps), recorded
  /// into the next record() (race-free with recorded work pending); looks up (never re-creates)
  /// the pipelines they need. More colliders than the batch has room for, or the first tethers,
  /// need new buffers: those wait for the earlier work on the Context's queue first.
  Result<void> set_params(std::uint32_t slot, SimParams params);
  /// The host's targets of one instance for the next recorded step (PinTargets::set_host's checks).
  Result<void> set_pin_targets(std::uint32_t slot, std::span<const PinTarget> host);
  /// Whether some instance has targets (targets.comp's passes run), and the most any has.
  bool any_targets() const;
  std::uint32_t targets_per_slot() const;
  /// The host's teleport of one instance, at the start of the next recorded step (checked).
  Result<void> teleport(std::uint32_t slot, const RigidJump& jump);
  /// Whether some instance has a frame (inertia) or a teleport pending (the frame passes' pipelines),
  /// and whether the substep being recorded jumps or carries some instance (they run).
  bool any_frame() const;
  bool frame_jumps_now() const { return frame_jump_now; }
  bool frame_carries_now() const { return frame_carry_now; }

  /// Records `steps` steps of every instance; advances the host-side counters now.
  void record(VkCommandBuffer cmd, std::uint32_t steps);
  std::uint64_t dispatches() const { return dispatches_; }
  /// Copies instance `from_slot` of `from` (current positions, velocities, normals, forces) into
  /// instance `to_slot` of this batch (positions[0]: current at creation); the caller records the
  /// barriers.
  void record_copy_slot(VkCommandBuffer cmd, const SolverBatch& from, std::uint32_t from_slot,
                        std::uint32_t to_slot) const;
  /// Instance `slot` continues `old` (an instance of an older batch): its step count and
  /// divergence (a diverged instance stays frozen) and its host's pin targets.
  Result<void> carry_over(std::uint32_t slot, const Slot& old);

  /// Reads the flags of every instance (their work complete and visible to the host); marks the
  /// newly diverged ones (their step, the error).
  void refresh_flags();
  /// One instance's entries of a per-particle buffer (submits, waits, copies).
  Result<std::vector<glm::vec3>> read(Field field, std::uint32_t slot);
  /// One instance's interleaved vertices, 8 floats each (GpuSolverOptions::interleaved_vertices).
  Result<std::vector<float>> read_vertices(std::uint32_t slot);
  /// Instance `slot`'s buffers for drawing (the current positions: query after recording).
  InstanceBuffers buffers(std::uint32_t slot) const;
  std::uint32_t current_position_index() const { return parity; }
  /// The buffers a host draws from: current positions, normals, uvs (queue-family transfers).
  std::array<VkBuffer, 3> drawn_buffers() const { return {pos[parity].buffer, normal.buffer, uv.buffer}; }
  VkBuffer position_buffer(std::uint32_t index) const { return pos[index & 1u].buffer; }
  VkBuffer velocity_buffer() const { return vel.buffer; }
  const std::vector<glm::vec2>& uvs() const { return uvs_; }
  SolveStats last_solve() const;
  bool implicit_one_workgroup() const;
  /// The buffer access and workgroup size this batch's shaders use (resolve_layout).
  BufferAccess buffer_access() const { return access; }
  std::uint32_t workgroup_size() const { return workgroup; }
  /// GpuSolverOptions::buffer_access and workgroup_size, or the device's choice (device_layout)
  /// where they are left to it; implicit Euler batches keep the compiled workgroup size (its
  /// reductions' shared arrays). ErrorCode::unsupported for a workgroup size the device refuses.
  static Result<DeviceLayout> resolve_layout(const Context::Impl& ctx, const GpuSolverOptions& options,
                                             bool implicit);
  bool uses_staging() const { return staging; }

  /// Where the force pass takes the vertex normals from (one choice per batch: its topology's).
  enum class Normals : std::uint32_t {
    none, ///< a chain: zero normals, no wind
    grid, ///< the unrolled grid fan (force_body.glsl grid_normal, VKCLOTH_FLAG_HAS_GRID)
    ring  ///< the gather lists' ring terms (ClothTopology::ring_normals, VKCLOTH_FLAG_RING_NORMALS): meshes
  };
  /// The instance flag of a normal path (VKCLOTH_FLAG_HAS_GRID, VKCLOTH_FLAG_RING_NORMALS or 0): what
  /// InstanceParams::flags carries and what SC_NORMAL_FLAGS keeps compiled in (force_body.glsl).
  static std::uint32_t normal_flag(Normals n) {
    return n == Normals::grid ? VKCLOTH_FLAG_HAS_GRID : n == Normals::ring ? VKCLOTH_FLAG_RING_NORMALS : 0u;
  }
  /// The normal path of `topology`'s batches: a grid's own fast path; the ring terms for any other
  /// topology with a surface.
  static Normals normals_of(const ClothTopology& topology);

  /// Grid stencil (force_body.glsl's specialisation constants 0..39): constant_id order.
  struct Stencil {
    std::uint32_t enabled = 0; // VkBool32
    std::uint32_t nx = 1, ny = 1;
    std::int32_t offset[12] = {};
    float rest[12] = {}, stiffness[12] = {};
    std::uint32_t border = 0; // VkBool32: border particles use the stencil too (SC_BORDER)
  };

  // What the passes read (passes/pass.hpp).
  Context::Impl& context() const { return *ctx; }
  const std::shared_ptr<Context::Impl>& shared_context() const { return ctx; }
  const DeviceFns& vk() const { return ctx->vk; }
  const GpuSolverOptions& solver_options() const { return options; }
  const testing::SolverKnobs& solver_knobs() const { return knobs; }
  /// The topology the batch was made from: alive as long as the batch (every instance holds it).
  const ClothTopology& topology() const { return *batch_topology; }
  std::span<const Slot> instance_slots() const { return slots; }
  const SimParams& family() const { return slots.front().params; } // integrator family, substeps
  bool any_stretch() const;
  bool any_tethers() const;
  bool any_colliders() const;
  /// The most Newton iterations of the fast projection an instance asks for (0: none uses it).
  std::uint32_t projection_iterations() const;
  /// The most self-collision passes an instance asks for (0: none has it on).
  /// The most self-collision passes after the step any instance asks for (0: none does; an
  /// instance whose vbd takes self-contact as an energy has none).
  std::uint32_t self_iterations() const;
  /// Whether some instance's vbd takes self-contact as an energy in its sweeps (SelfCollision::stiffness).
  bool any_self_energy() const;
  /// The self-collision pass's hash and lists (null before that pass makes them): vbd's sweeps
  /// record its list build and contact passes when an instance takes self-contact as an energy.
  SelfCollisionGpu* self_collision() const { return self_collision_; }
  void set_self_collision(SelfCollisionGpu* s) { self_collision_ = s; }
  /// Bit t (VKCLOTH_COLLIDER_*) for each collider type some instance has; 0 without colliders.
  std::uint32_t collider_types() const;
  /// The batch's shader build and workgroup size, the pass fixed to `stage` (VKCLOTH_ANY_STAGE:
  /// the push constants' stage).
  ShaderVariant variant(std::uint32_t stage = VKCLOTH_ANY_STAGE) const { return {access, workgroup, stage}; }
  /// `slot` := the Context's pipeline of `shader` with `constants` in this batch's variant (`stage`
  /// fixed, as variant()), looked up once: nothing to do when `slot` is set already.
  Result<void> ensure_pipeline(VkPipeline& slot, const ShaderSource& shader,
                               std::span<const std::uint32_t> constants = {},
                               std::uint32_t stage = VKCLOTH_ANY_STAGE) const;
  /// The specialisation constants of force, integrate and fused.comp (solver_state_set.cpp): the
  /// grid stencil, SC_WRITE_AUX, SC_COLLIDER_TYPES = `types` and SC_NORMAL_FLAGS; `csr` the
  /// defaults instead of the stencil and every normal path (the implicit passes' gather).
  std::array<std::uint32_t, 43> state_constants(bool write_aux, std::uint32_t types, bool csr = false) const;
  static constexpr std::uint32_t no_texel_set = ~0u;
  /// Binds the state sets for a state pass: set 0 of position parity `read` (`stage_input`: the
  /// RK4 stage set), set 1 the texel views of `texel` (0, 1: positions[k]; 2: the stage positions;
  /// no_texel_set: set 0 only).
  void bind_state(VkCommandBuffer cmd, std::uint32_t read, bool stage_input, std::uint32_t texel) const;
  /// The state layout's push constants (32 bytes: PushConstants or a pass's own struct).
  void push_state(VkCommandBuffer cmd, const void* push) const;
  /// One invocation per particle of every instance (the grid of workgroups x the instances).
  void dispatch_particles(VkCommandBuffer cmd) const;
  /// One invocation per item of a range (a colour's links or particles) of every instance: as many
  /// workgroups as the items need, in rows no wider than the particles' (nothing for no items).
  void dispatch_items(VkCommandBuffer cmd, std::uint32_t items) const;
  std::uint32_t dispatch_x() const { return groups_x; }
  std::uint32_t dispatch_y() const { return groups_y; }
  std::uint64_t edge_count() const { return edges_count; }
  /// The strain links' colour offsets (colours + 1 entries; empty without links).
  std::span<const std::uint32_t> strain_colour_offsets() const { return strain_colours; }
  std::size_t strain_link_count() const { return strain_colours.empty() ? 0 : strain_colours.back(); }
  /// The state buffers the one-set passes (self-collision, projection) bind at the same numbers.
  OneSetInputs one_set_inputs() const {
    return {{pos[0].buffer, pos[1].buffer},
            vel.buffer,
            particle.buffer,
            flags.buffer,
            instances.buffer,
            strain_links.buffer,
            acc_pos.buffer,
            acc_vel.buffer,
            stage_vel.buffer};
  }
  /// The state buffers the implicit passes bind.
  ImplicitInputs implicit_inputs() const;
  struct Upload {
    Buffer* dst;
    const void* data; // null: zero fill
    VkDeviceSize bytes;
  };
  /// Into mapped memory, or through one staging submission (waited for).
  Result<void> upload(std::span<const Upload> uploads);
  /// vkCmdUpdateBuffer of `bytes` at `offset` of `dst`, in pieces of at most 64 KiB (its limit).
  void record_buffer_update(VkCommandBuffer cmd, const Buffer& dst, const void* data, std::size_t bytes,
                            VkDeviceSize offset = 0) const;

private:
  SolverBatch() = default;

  std::shared_ptr<Context::Impl> ctx;
  GpuSolverOptions options;
  testing::SolverKnobs knobs;
  std::vector<Slot> slots; // one per instance; slot k's particles are at k * count in the buffers
  std::uint32_t count = 0; // particles per instance
  std::uint32_t nx = 0, ny = 0;
  Normals normals = Normals::none;
  bool staging = false;
  BufferAccess access = BufferAccess::texel_views;  // which build of the shaders (never automatic)
  std::uint32_t workgroup = VKCLOTH_WORKGROUP_SIZE; // invocations per workgroup (specialised)

  // Per-particle vec4 buffers (slots() x count entries), then the shared topology, then the small
  // host-visible ones (per instance). Every object below is owned (resources.hpp): a new buffer
  // is one member here plus its creation.
  Buffer pos[2], vel, force, force_stage, vel_filt, normal, uv, stage_pos, stage_vel, acc_pos, acc_vel;
  Buffer vertices; // GpuSolverOptions::interleaved_vertices (else one zeroed element)
  // The shared topology: particle constants, gather lists, triangles (`indices`, for drawing).
  Buffer particle, offsets, ranges, edges, indices;
  // Stretch control: the strain links in colour order, and the tethers (one zeroed element until
  // an instance asks for tethers: ensure_tethers()).
  Buffer strain_links, tethers;
  std::vector<std::uint32_t> strain_colours; // the topology's colour offsets (colours + 1)
  Buffer vbd_order;                          // VKCLOTH_BINDING_VBD_ORDER: ClothTopology::vertex_order
  // VKCLOTH_BINDING_TARGETS: count entries per instance, each substep's targets recorded into it
  // (record_targets); one zeroed element until an instance first has targets (ensure_targets).
  Buffer targets;
  bool targets_allocated = false;
  // VKCLOTH_BINDING_FRAMES: one FrameMotion per instance, recorded before each substep while some
  // instance has a frame (record_frames); one zeroed element until then (ensure_frames).
  Buffer frames;
  bool frames_allocated = false;
  bool frame_jump_now = false, frame_carry_now = false;
  bool tethers_uploaded = false;
  bool strain_chains_uploaded = false; // ensure_strain_chains()
  // The batch's topology, for what is uploaded when first needed (the tethers): alive as long as
  // the batch, since every instance of the batch holds it (ClothWorld::Impl::Instance).
  const ClothTopology* batch_topology = nullptr;
  std::uint32_t index_count = 0;
  // Host-visible: the divergence flags (read by the host); the colliders and the instance
  // parameters (written by the host at creation, then by vkCmdUpdateBuffer in record()).
  Buffer colliders, flags, instances;
  std::uint32_t collider_capacity = 0;
  // Mesh colliders: every distinct ColliderMesh of the batch's colliders, their hierarchies and
  // triangles one after the other (one zeroed element of each when there is none); `meshes` holds
  // them alive, `mesh_starts` their first node, first triangle, for a skinned mesh first corner
  // velocities (after every mesh's triangles, in MESH_TRIS; VKCLOTH_MESH_NONE: rigid) and first
  // neighbours' record (after those) (Collider::mesh_root, mesh_tri0, end_b.w, axis_x.w).
  Buffer mesh_nodes, mesh_tris;
  std::vector<std::shared_ptr<const ColliderMesh>> meshes;
  std::vector<std::array<std::uint32_t, 4>> mesh_starts;
  // A skinned mesh's new pose (ColliderMesh::deformed: the same counts) is written into the same
  // buffers by vkCmdUpdateBuffer at the next record(), no wait: these hold it until then.
  std::vector<ColliderMesh::Node> mesh_nodes_pending;
  std::vector<ColliderMesh::Triangle> mesh_tris_pending;
  std::size_t mesh_node_count = 0, mesh_tri_count = 0;
  // VKCLOTH_BINDING_MESH_CACHE: each particle's search entry (2 vec4) per mesh collider of its
  // instance, the k-th mesh collider's entries for every particle of the batch at k x size() x count
  // (Collider::pivot.w); one element while no instance has a mesh collider. `mesh_cache_key`: each
  // instance's mesh colliders' meshes, for which the entries were found (other meshes: emptied, by
  // a fill record() records first while `mesh_cache_clear`).
  Buffer mesh_cache;
  std::uint64_t mesh_cache_entries = 0;
  std::vector<std::vector<const ColliderMesh*>> mesh_cache_key;
  bool mesh_cache_clear = false;
  bool params_dirty = false; // set_params() since the last record(): record_params_update() due

  // Layouts and pipelines: the Context's (PipelineRegistry, pipelines.hpp), shared by every batch.
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE, texel_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  DescriptorPool pool;
  VkDescriptorSet sets[2][2] = {}; // [positions read index][0: state input, 1: RK4 stage input]
  // Set 1 of force.comp / fused.comp: POS_IN as an RGBA32F uniform texel buffer (buffer_access.glsl
  // read_pos_in), the particle constants as an RG32UI one, velocities, flags, instance parameters.
  // pos_views [0], [1]: positions[0], positions[1]; [2]: RK4 stage positions. The topology's
  // spring lists too (buffer_access.glsl read_list_range, read_edge: RANGES, which only these views
  // read, and EDGES).
  BufferView pos_views[3];
  BufferView particle_view, vel_view, flags_view, instances_view;
  BufferView ranges_view, edges_view, strain_links_view, tethers_view;
  // The collider buffer and the mesh buffers (replaced when they grow: create_buffer_views again).
  BufferView colliders_view, mesh_nodes_view, mesh_tris_view;
  VkDescriptorSet texel_sets[3] = {};
  CommandContext* commands = nullptr; // the owner's (ClothWorld): uploads, readbacks
  std::uint32_t groups_x = 1, groups_y = 1;
  Stencil stencil;
  std::uint64_t edges_count = 0;

  shared::PushConstants pc{}; // per dispatch (count, grid, stage, step)
  std::uint64_t recorded = 0; // recorded steps since the flag epoch: flag step numbers
  std::uint32_t parity = 0;   // positions[parity] is current; flipped by every recorded substep
  std::vector<std::unique_ptr<Pass>> passes;   // make_solver_passes(): in the order they record
  SelfCollisionGpu* self_collision_ = nullptr; // self_collision()
  std::vector<glm::vec2> uvs_;                 // per particle of one instance (as uploaded)
  std::uint64_t dispatches_ = 0;               // recorded so far (ClothWorld::dispatches_recorded)

  VkDeviceSize slot_offset(std::uint32_t slot) const {
    return VkDeviceSize(slot) * count * GpuSolver::stride;
  }
  VkDeviceSize slot_bytes() const { return VkDeviceSize(count) * GpuSolver::stride; }
  VkDeviceSize vertex_offset(std::uint32_t slot) const {
    return VkDeviceSize(slot) * count * sizeof(shared::Vertex);
  }
  const Buffer& buffer_of(Field field) const;
  Result<std::vector<float>> read_floats(const Buffer& b, VkDeviceSize offset, VkDeviceSize bytes);

  // Creation phases (create()), in order.
  Result<void> create_buffers();
  void set_stencil(const ClothTopology& topology);
  Result<void> init_state_sets();
  Result<void> create_descriptor_sets();
  Result<void> create_texel_views();
  Result<void> create_buffer_views();
  Result<void> write_sets();
  /// Every pass's prepare() (creation, set_params).
  Result<void> prepare_passes();
  Result<void> ensure_tethers();
  Result<void> ensure_strain_chains();
  Result<void> replace_topology_buffer(Buffer& dst, BufferView& view, const void* data, VkDeviceSize bytes,
                                       const char* what);
  Result<void> ensure_collider_capacity();
  Result<void> ensure_mesh_buffers();
  Result<void> ensure_targets();
  /// Before substep k of a step: every instance's targets at the substep's end (colliders posed)
  /// into TARGETS, VKCLOTH_NO_TARGET after each instance's last.
  void record_targets(VkCommandBuffer cmd, std::uint32_t k);
  Result<void> ensure_frames();
  /// ensure_targets' and ensure_frames' replacement of a zeroed element by the real buffer.
  Result<void> ensure_mesh_cache();
  Result<void> replace_state_buffer(Buffer& dst, std::uint64_t entries, VkDeviceSize stride,
                                    const char* what);
  /// Before substep k: each instance's frame step (`before`: its frame collider at the substep's
  /// start; the colliders already posed at its end) into FRAMES; sets frame_jump_now / _carry_now.
  void record_frames(VkCommandBuffer cmd, std::uint32_t k, const std::vector<Collider>& before);
  std::vector<shared::Collider> packed_colliders() const;
  /// Before a substep of `h` seconds: moving colliders advance to where they are at its end
  /// (Collider::posed_at, as CpuSolver does) and the new poses are recorded into the collider buffer.
  void record_collider_motion(VkCommandBuffer cmd, double h);
  std::vector<shared::InstanceParams> packed_instance_params() const;
  void write_params_now();
  void record_params_update(VkCommandBuffer cmd);
  Result<void> upload_initial_state(const ClothTopology& topology, const std::vector<SlotState>& states);
  /// The passes of `when`, each active one after the other.
  void record_passes(VkCommandBuffer cmd, Pass::When when, bool first, bool last);
};

} // namespace vkcloth::gpu
