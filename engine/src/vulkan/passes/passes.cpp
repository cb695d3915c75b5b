// SPDX-License-Identifier: MIT
// The solver's passes, in the order a substep runs them: the one list. Each pass decides from the
// batch's parameters whether it runs (Pass::active), so the list is the same for every batch. A new
// pass is one factory declared and listed here (docs/architecture.md "Adding a pass").
#include <memory>
#include <vector>

#include "implicit_update.hpp"
#include "pass.hpp"

namespace vkcloth::gpu {

// Defined next to each pass (passes/*.cpp).
std::unique_ptr<Pass> make_frame_jump();
std::unique_ptr<Pass> make_frame_carry();
std::unique_ptr<Pass> make_drive_targets();
std::unique_ptr<Pass> make_hold_targets();
std::unique_ptr<Pass> make_explicit_update();
std::unique_ptr<Pass> make_vbd_update();
std::unique_ptr<Pass> make_tethers();
std::unique_ptr<Pass> make_strain_links();
std::unique_ptr<Pass> make_strain_projection();
std::unique_ptr<Pass> make_contacts_after_stretch();
std::unique_ptr<Pass> make_self_collision();
std::unique_ptr<Pass> make_contacts_after_self_collision();
std::unique_ptr<Pass> make_vertices();

std::vector<std::unique_ptr<Pass>> make_solver_passes() {
  std::vector<std::unique_ptr<Pass>> passes;
  // The cloth's frame jumps (a teleport), then pinned particles onto their targets at the
  // substep's end (attachments, the host's targets).
  passes.push_back(make_frame_jump());
  passes.push_back(make_drive_targets());
  // The update: forces, contacts and the integrator (one of the three runs).
  passes.push_back(make_explicit_update());
  passes.push_back(std::make_unique<ImplicitUpdate>());
  passes.push_back(make_vbd_update());
  // Stretch control: tethers, Provot's sweeps, the fast projection, then the colliders again.
  passes.push_back(make_tethers());
  passes.push_back(make_strain_links());
  passes.push_back(make_strain_projection());
  passes.push_back(make_contacts_after_stretch());
  // Self-collision, then the colliders again.
  passes.push_back(make_self_collision());
  passes.push_back(make_contacts_after_self_collision());
  // Free particles back within reach of their targets (motion constraints).
  passes.push_back(make_hold_targets());
  // The share of the frame's motion the cloth does not feel (inertia < 1), last.
  passes.push_back(make_frame_carry());
  // Once per recording, after the last substep.
  passes.push_back(make_vertices());
  return passes;
}

} // namespace vkcloth::gpu
