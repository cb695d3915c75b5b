// SPDX-License-Identifier: MIT
// The solver behind `vkcloth run` and `compare`, behind a small interface so that each backend
// (backend.cpp: CPU, backend_vulkan.cpp: Vulkan) lives in its own file.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/measure.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {

/// Arithmetic the solver runs in (`--precision float|double`).
enum class Precision { float32, float64 };
std::optional<Precision> parse_precision(std::string_view name); ///< "float" | "double"
const char* to_string(Precision p);                              ///< "float" | "double"

class SimBackend {
public:
  virtual ~SimBackend() = default;
  /// Advances `n` steps, stopping at the first error. A blow-up is ErrorCode::diverged with a
  /// message naming the step and the time.
  virtual Result<void> step(std::uint64_t n) = 0;
  /// Copies the current state out (the vectors are resized to the particle count).
  virtual Result<void> read_state(std::vector<glm::dvec3>& positions,
                                  std::vector<glm::dvec3>& velocities) = 0;
  /// structural_strain() of the current positions, read in the solver's precision (the Vulkan
  /// backend reads back the positions only).
  virtual Result<StrainStats> strain(const ParticleSystem& system) = 0;
  /// Steps taken so far, and the simulated time step_index() * dt.
  virtual std::uint64_t step_index() const = 0;
  virtual double time() const = 0;
  /// The colliders where they are now (moving ones advance with every substep).
  virtual std::vector<Collider> colliders() const = 0;
  /// implicit_euler: the last substep's CG iterations and relative residual.
  virtual SolveStats last_solve() const { return {}; }
  /// Self-collision's passes and neighbour-list builds (the CPU solver counts them; Vulkan: none).
  virtual std::optional<SelfCollisionStats> self_collision_stats() const { return std::nullopt; }
};

/// "cpu" or "vulkan". Unknown name: ErrorCode::invalid_argument; no Vulkan device: ErrorCode::no_device.
Result<std::unique_ptr<SimBackend>> make_backend(std::string_view name, const Scene& scene,
                                                 Precision precision);

/// The GpuSolver on a Context of its own (backend_vulkan.cpp).
Result<std::unique_ptr<SimBackend>> make_vulkan_backend(const Scene& scene, Precision precision);

} // namespace vkcloth::cli
