// GpuSolver::Impl: the Vulkan solver's engine, a BATCH of instances (cloths) that share one
// topology and one integrator family, stepped together: one dispatch per pass serves every
// instance (instance = gl_WorkGroupID.z, vkcloth_shared.h). A GpuSolver is a batch of one;
// ClothWorld groups its instances into batches (world.cpp). Internal to engine/src/vulkan.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "implicit_gpu.hpp"
#include "resources.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/testing.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

/// Optional initial state of one instance (empty vectors: the topology's).
struct SlotState {
  const std::vector<glm::dvec3>* positions = nullptr;
  const std::vector<glm::dvec3>* velocities = nullptr;
};

struct GpuSolver::Impl {
  /// Host-side state of one instance of the batch.
  struct Slot {
    SimParams params;
    std::uint64_t step = 0;       // completed steps (the bad one when diverged)
    std::uint64_t epoch_step = 0; // `step` when this batch's flag epoch began (its creation)
    std::optional<Error> diverged;
  };

  std::shared_ptr<Context::Impl> ctx;
  GpuSolverOptions options;
  testing::SolverKnobs knobs;
  std::vector<Slot> slots; // one per instance; slot k's particles are at k * count in the buffers
  std::uint32_t count = 0; // particles per instance
  std::uint32_t nx = 0, ny = 0;
  bool staging = false;

  // Per-particle vec4 buffers (slots() x count entries), then the shared topology, then the small
  // host-visible ones (per instance). Every object below is owned (resources.hpp): a new buffer
  // is one member here plus its creation.
  Buffer pos[2], vel, force, force_stage, vel_filt, normal, uv, stage_pos, stage_vel, acc_pos, acc_vel;
  Buffer particle, offsets, edges, indices; // indices: grid_triangle_indices (drawing)
  std::uint32_t index_count = 0;
  Buffer colliders, flags, instances; // host-visible (written / read by the host)
  std::uint32_t collider_capacity = 0;

  // Layouts and pipelines: the Context's (PipelineRegistry, pipelines.hpp), shared by every batch.
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE, texel_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline force_pipeline = VK_NULL_HANDLE, integrate_pipeline = VK_NULL_HANDLE;
  // fused.comp variants, looked up when first needed (ensure_fused): [write_aux][colliders].
  // write_aux = 0 (SC_WRITE_AUX false: no force and normal stores) for every fused substep of a
  // recorded batch of steps but the last, since only the last one's forces and normals can be
  // observed; colliders = 0 (SC_COLLIDERS false: no contact loops) while no instance has colliders.
  VkPipeline fused_pipes[2][2] = {};
  DescriptorPool pool;
  VkDescriptorSet sets[2][2] = {}; // [positions read index][0: state input, 1: RK4 stage input]
  // Set 1 of force.comp / fused.comp: POS_IN as an RGBA32F uniform texel buffer (force_body.glsl
  // pos_at), the particle constants as an RG32UI one, velocities, flags, instance parameters.
  // pos_views [0], [1]: positions[0], positions[1]; [2]: RK4 stage positions.
  BufferView pos_views[3];
  BufferView particle_view, vel_view, flags_view, instances_view;
  VkDescriptorSet texel_sets[3] = {};
  CommandContext commands; // readbacks, uploads, simulate()
  QueryPool queries;       // two timestamps around each simulate() submission
  std::uint32_t groups_x = 1, groups_y = 1;
  // Grid stencil (force_body.glsl's specialisation constants 0..39): constant_id order.
  struct Stencil {
    std::uint32_t enabled = 0; // VkBool32
    std::uint32_t nx = 1, ny = 1;
    std::int32_t offset[12] = {};
    float rest[12] = {}, stiffness[12] = {};
    std::uint32_t border = 0; // VkBool32: border particles use the stencil too (SC_BORDER)
  } stencil;
  std::uint64_t edges_count = 0;

  shared::PushConstants pc{}; // per dispatch (count, grid, stage, step)
  std::uint64_t recorded = 0; // recorded steps since the flag epoch: flag step numbers
  std::uint32_t parity = 0;   // positions[parity] is current; flipped by every recorded substep
  std::unique_ptr<ImplicitGpu> implicit; // created when the integrator is implicit_euler (batch of one)
  std::vector<glm::vec2> uvs;
  double last_ms = -1.0;
  std::uint64_t dispatches = 0; // recorded so far (ClothWorld::dispatches_recorded)

  /// A batch of `params.size()` instances of `topology` (all of one integrator family and one
  /// substep count: Euler (explicit and semi-implicit mix), RK4, or implicit Euler (one
  /// instance)); `states[k]` is instance k's initial state (missing entries: the topology's).
  static Result<std::unique_ptr<Impl>> create(const std::shared_ptr<Context::Impl>& ctx, const ParticleSystem& topology,
                                              std::vector<SimParams> params, const GpuSolverOptions& options,
                                              const testing::SolverKnobs& knobs,
                                              const std::vector<SlotState>& states = {});

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  std::uint32_t batch() const { return static_cast<std::uint32_t>(slots.size()); }
  const SimParams& family() const { return slots.front().params; } // integrator family, substeps
  bool any_colliders() const {
    for (const Slot& slot : slots)
      if (!slot.params.colliders.empty()) return true;
    return false;
  }
  const DeviceFns& vk() const { return ctx->vk; }
  std::uint32_t current() const { return parity; }
  VkDeviceSize slot_offset(std::uint32_t slot) const { return VkDeviceSize(slot) * count * GpuSolver::stride; }
  VkDeviceSize slot_bytes() const { return VkDeviceSize(count) * GpuSolver::stride; }

  /// New parameters for one instance (validated by the caller; same family and substeps).
  Result<void> set_slot_params(std::uint32_t slot, SimParams params);
  Result<void> ensure_implicit();
  Result<void> ensure_fused();
  void record(VkCommandBuffer cmd, std::uint32_t steps);
  /// `last`: the last substep of this recording (the fused variant that stores forces and normals).
  void record_substep(VkCommandBuffer cmd, bool first, bool last);
  /// Copies instance `from_slot` of `from` (current positions, velocities, normals, forces) into
  /// instance `to_slot` of this batch (positions[0]: current at creation); the caller records the
  /// barriers.
  void record_copy_slot(VkCommandBuffer cmd, const Impl& from, std::uint32_t from_slot, std::uint32_t to_slot) const;
  /// Reads the flags of every instance; marks the newly diverged ones (their step, the error).
  void refresh_flags();
  /// The flags of an instance that diverged before this batch existed: frozen from step 1 on.
  void freeze_slot(std::uint32_t slot);

  // Creation phases (create()), in order.
  Result<void> create_buffers();
  Result<void> create_commands();
  void detect_stencil(const ParticleSystem& system);
  Result<void> init_pipelines();
  Result<void> create_descriptor_sets();
  Result<void> create_texel_views();
  Result<void> create_pipelines();
  Result<void> write_sets();
  Result<void> upload_colliders();
  void upload_instance_params();
  Result<void> upload_initial_state(const ParticleSystem& system, const std::vector<SlotState>& states);

  template <typename F> Result<void> submit_and_wait(F&& record_fn) {
    return commands.submit_and_wait(std::forward<F>(record_fn));
  }
  Result<std::vector<glm::vec3>> read_vec3(const Buffer& b, std::uint32_t slot);
};

} // namespace vkcloth::gpu
