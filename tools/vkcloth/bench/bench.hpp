// SPDX-License-Identifier: MIT
// What the files of `vkcloth bench` share: its options, the scenes it times (scenes.cpp), the
// timing of each backend (timing.cpp), the cost model (cost.cpp) and the rows report.cpp prints.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/builders.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/layout.hpp"
#include "vkcloth/mesh.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth::cli::bench {

struct BenchOptions {
  std::string backend = "all";
  std::string sizes = "64,128,256,512,1024";
  std::uint64_t steps = 200;
  std::uint64_t warmup = 20;
  unsigned reps = 3;
  std::string integrator = "semi_implicit_euler";
  unsigned threads = 0;
  std::uint32_t steps_per_submit = 100;
  std::uint32_t instances = 1;
  std::optional<double> dt;
  double memory_gbps = 39.0;
  double compute_gflops = 192.0;
  std::string json;
  std::string variants = "fused,two_pass"; // Vulkan layouts to time (RK4 and implicit: always one)
  std::string layout = "auto";             // Vulkan buffer access(es): auto, texel, storage, comma-separated
  std::uint32_t workgroup = 0;             // Vulkan workgroup size (0: the device's choice)
  std::string mesh;      // also time this mesh (OBJ / glTF): reordered, in file order, and shuffled
  std::string stretch;   // also time each grid with stretch_limit {method: this, max_strain 0.1, 4 sweeps}
  std::string stiffness; // "S,H,B": the grid's structural, shear and bend stiffness (default 40,8,8)
  std::optional<double> cloth_mass; // kg, the whole grid's (default: 0.05 kg per particle at 64 x 64)
  double wind = 2.0; // m/s^2 on a particle facing the wind (the wind force scales with the mass)
  std::string cg_dispatch = "auto"; // implicit on Vulkan: auto | one_workgroup | per_iteration | both
  std::string contact;              // also time the contact scenes: table | mesh (+ sphere) | both
  bool self_collision = false;      // also time each size folded, self-collision on vs off
  double self_skin = 0.0;      // its neighbour lists' skin, in thicknesses (0: every pass walks the cells)
  double self_stiffness = 0.0; // with vbd: self-contact as an energy of this stiffness (N/m; 0: the passes)
};

/// The benchmark scene at n x n: a 1 m x 1 m vertical cloth hanging from its two top corners, in
/// the wind. The total mass stays that of a 64 x 64 cloth of 0.05 kg particles scaled to the grid
/// (m = 0.05 kg * 4096 / n^2), and the wind
/// force scales with m, so the accelerations are the same at every size; dt = 5e-4 s keeps the
/// stiffest size (1024: sqrt(k/m) ~ 450 1/s per spring) well inside the Euler stability limit.
struct BenchScene {
  ParticleSystem system;
  SimParams params;
};

// ---- Scenes (scenes.cpp) ----------------------------------------------------------------------

Result<BenchScene> bench_scene(std::uint32_t n, Integrator integrator, double dt, const BenchOptions& o);
Result<BenchScene> mesh_bench_scene(const Mesh& file, const std::string& order, Integrator integrator,
                                    double dt);

// ---- Contact scenes -----------------------------------------------------------------

/// A cloth resting on colliders, and what the contact rows report about it. `params` has the
/// colliders; the baseline row times the same system with params.colliders cleared.
struct ContactScene {
  std::string name; // "table" | "mesh" | "sphere"
  std::uint32_t n = 0;
  ParticleSystem system;
  SimParams params;
  std::vector<std::string> kinds; // the colliders' types, in order
  std::uint32_t triangles = 0;    // a mesh collider's triangles (0 for the table)
};

constexpr double contact_friction = 0.6; // kinetic = static, every collider of the contact scenes
constexpr std::uint32_t sphere_frequency =
    22; // the mesh scene's geodesic sphere: 20 x 22^2 = 9 680 triangles

Result<ContactScene> table_scene(Integrator integrator, double dt, const BenchOptions& o);
Result<ContactScene> mesh_scene(Integrator integrator, double dt, const BenchOptions& o, bool analytic);
Result<std::size_t> particles_in_contact(const ContactScene& sc, std::span<const glm::dvec3> positions);

// ---- Self-collision scene -----------------------------------------------------------

/// The self-collision rows' parameters: thickness = 1.5 x the grid spacing, the thickness that closes
/// the gaps between particles (a particle of another layer is pushed off anywhere in a grid square,
/// whose centre is 0.71 spacings from its corners; the 8 neighbours, up to 1.41 spacings away, are
/// all within it at rest and never collide), friction 0.2 and SelfCollision's default number of
/// Jacobi iterations (1).
constexpr double self_thickness_over_spacing = 1.5;
constexpr double self_friction = 0.2;
constexpr std::uint32_t self_iterations = SelfCollision{}.iterations; // the default (1)
constexpr std::uint32_t self_layers = 4;                              // the folded cloth's layers
constexpr double self_layer_gap = 1.001;    // the layers' starting distance, in thicknesses
constexpr double self_contact_band = 1.05;  // "in self-contact": within this many thicknesses
constexpr std::uint32_t self_min_size = 16; // below this the layers are ~1 spacing long

/// The n x n cloth folded on the floor, and what the self-collision rows report about it. `params`
/// has self-collision on; the baseline row times the same system with it off.
struct SelfScene {
  std::uint32_t n = 0;
  ParticleSystem system;
  SimParams params;
  std::vector<glm::dvec3> rest; // the starting positions: the solvers' rest-position filter
};

Result<SelfScene> folded_scene(std::uint32_t n, Integrator integrator, double dt, const BenchOptions& o);
/// What is in self-contact: the particles, and the pairs (each once).
struct SelfContact {
  std::size_t particles = 0;
  std::size_t pairs = 0;
};
SelfContact self_contact(const SelfScene& sc, std::span<const glm::vec3> positions);

// ---- Cost model (cost.cpp) --------------------------------------------------------------------

/// Bytes and flops per particle-step counted from the kernels (docs/performance.md, "Counting").
/// `s` is the mean number of springs per particle (gather-list entries / particles).
struct Cost {
  double bytes = 0, flops = 0;
};

Cost cost_of(const std::string& variant, Integrator integrator, double s, bool grid, double fans, bool wind,
             std::uint32_t steps_per_submit, std::uint32_t sweeps = 0);

// ---- Rows and their timing (timing.cpp) -------------------------------------------------------

/// One row of the table and of --json's results.
struct Row {
  std::string cg_dispatch;      // implicit on Vulkan: "one_workgroup" or "per_iteration"
  double cg_per_step = 0;       // implicit_euler: mean CG iterations per step over the timed steps
  std::uint32_t vbd_sweeps = 0; // vbd: sweeps per step (iterations x substeps)
  std::string backend, variant;
  std::uint32_t size = 0;
  std::size_t particles = 0, springs = 0;
  unsigned threads = 0;
  std::uint64_t steps = 0;
  unsigned reps = 0;
  double wall_ms = 0;              // median over reps of the wall time of `steps` steps
  double gpu_ms = -1;              // median GPU (timestamp) time of `steps` steps; -1 for the CPU
  std::string integrator;          // the scheme timed (implicit runs add a semi-implicit baseline row)
  std::uint32_t cg_iterations = 0; // implicit_euler: CG iterations of the last step
  std::uint32_t instances = 1;     // cloths stepped together (ClothWorld rows)
  std::string scene = "grid";      // "grid" (n x n) or "mesh" (--mesh)
  std::string order;               // mesh rows: "meshopt", "file" or "shuffled"
  std::string layout;              // Vulkan rows: the buffer access that ran ("texel" | "storage")
  std::uint32_t workgroup = 0;     // Vulkan rows: the workgroup size that ran
  std::string contact; // contact rows: "table" | "mesh" | "sphere" (scene "contact" or "contact_free")
  std::size_t in_contact_start = 0, in_contact_end = 0; // scene "contact": particles within 2 eps;
                                                        // "self_collision": in self-contact
  std::size_t self_pairs_end = 0;                       // "self_collision": pairs in self-contact
  std::vector<std::string> colliders;                   // scene "contact": their types
  std::uint32_t collider_triangles = 0;                 // scene "contact": a mesh collider's
  double self_thickness = 0; // self-collision rows: the thickness (m) of the "on" row's parameters
  double self_skin = 0;      // and its neighbour lists' skin (m; 0: none)
  double self_stiffness = 0; // and vbd's self-contact stiffness (N/m; 0: the passes after the step)
  // Mesh rows: the grid the row is quoted against, timed in alternation with it (each repetition
  // runs `steps` of the grid, then of the mesh): its side and median wall time (-1: not paired).
  std::uint32_t partner_size = 0;
  double partner_ms = -1;
  Cost cost;
};

/// A grid a mesh row is timed against in alternation (Row::partner_ms), so that a machine whose
/// speed drifts (other jobs on its cores) slows both alike.
struct Partner {
  const BenchScene& scene;
  std::uint32_t size;
};

Result<Row> bench_cpu(const BenchScene& sc, std::uint32_t n, const BenchOptions& o,
                      std::optional<Partner> partner = std::nullopt);
Result<Row> bench_vulkan(gpu::Context& ctx, const BenchScene& sc, std::uint32_t n, bool fused,
                         gpu::BufferAccess access, const BenchOptions& o,
                         gpu::GpuSolverOptions::CgDispatch cg = gpu::GpuSolverOptions::CgDispatch::automatic,
                         std::optional<Partner> partner = std::nullopt);
Result<Row> bench_world(gpu::Context& ctx, const BenchScene& sc, std::uint32_t n, bool batched,
                        gpu::BufferAccess access, const BenchOptions& o);
Result<std::array<Row, 2>> bench_cpu_contact(const ContactScene& sc, const BenchOptions& o);
Result<std::array<Row, 2>> bench_vulkan_contact(gpu::Context& ctx, const ContactScene& sc, bool fused,
                                                gpu::BufferAccess access, const BenchOptions& o);
Result<std::array<Row, 2>> bench_cpu_self(const SelfScene& sc, const BenchOptions& o);
Result<std::array<Row, 2>> bench_vulkan_self(gpu::Context& ctx, const SelfScene& sc, bool fused,
                                             gpu::BufferAccess access, const BenchOptions& o);

// ---- One run of the command (command.cpp) and its report (report.cpp) ---------------------------

/// One `vkcloth bench` run: the options, as given and as parsed; the Vulkan context (none with
/// --backend cpu, or when no device was found: vulkan_note says why) and the layouts to time on
/// it; and the rows timed so far, in the order the report prints them.
struct BenchRun {
  explicit BenchRun(const BenchOptions& options) : o(options) {}
  const BenchOptions& o;
  Integrator integrator = Integrator::semi_implicit_euler;
  std::vector<std::uint32_t> sizes;
  double dt = 5e-4;
  std::optional<gpu::Context> ctx;
  std::string vulkan_note;
  std::vector<gpu::BufferAccess> layouts; // --layout, in order
  std::optional<gpu::DeviceLayout> device_layout;
  std::vector<Row> rows;
};

/// Prints the table and the ratios quoted from it, and writes --json; returns the exit code.
int print_report(const BenchRun& run);

} // namespace vkcloth::cli::bench
