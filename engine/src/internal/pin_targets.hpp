// SPDX-License-Identifier: MIT
// The targets of one cloth (docs/model.md "Attachments"): its SimParams::attachments, which follow
// their colliders, and its host's PinTargets, interpolated across a step's substeps. Both backends
// keep one per cloth (CpuSolver's Impl, the GPU batch's slots) and take each substep's targets from
// it, in double, so that they drive the same particles to the same floats.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"

namespace vkcloth::detail {

/// One particle's target at a substep's end (the kernel's drive_pinned / hold_within take it).
struct TargetEntry {
  std::uint32_t particle = 0;
  glm::dvec3 position{0.0};
  glm::dvec3 velocity{0.0};
  double reach = 0.0;
};

class PinTargets {
public:
  /// Every particle index below `count`, and each particle in one attachment or host target at
  /// most; the message names the attachment (attachments[a].particles[i]) or the target.
  static Result<void> check(const SimParams& params, std::span<const PinTarget> host, std::size_t count);
  /// The host's targets for the next step (checked with `params` first; on an error nothing changes).
  Result<void> set_host(const SimParams& params, std::span<const PinTarget> targets, std::size_t count);
  /// Whether the parameters' attachments fit the host's targets and the cloth (check).
  Result<void> check_params(const SimParams& params, std::size_t count) const;
  bool empty(const SimParams& params) const { return params.attachments.empty() && host_.empty(); }
  /// How many particles have a target (check: at most the cloth's count).
  std::uint32_t size(const SimParams& params) const;
  /// The targets at the end of substep k of `substeps` (the colliders already posed there): the
  /// attachments in order, then the host's targets.
  void at_substep(const SimParams& params, std::uint32_t k, std::uint32_t substeps,
                  std::vector<TargetEntry>& out) const;
  /// After a step: the host's targets stay where they arrived.
  void end_step();
  /// The host's targets move with the cloth's jump (a teleport), so none of them pulls it back.
  void teleport(const RigidJump& jump);

private:
  struct Host {
    PinTarget target;
    glm::dvec3 from{0.0};
  };
  std::vector<Host> host_;
};

} // namespace vkcloth::detail
