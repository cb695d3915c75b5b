// SPDX-License-Identifier: MIT
#include "vkcloth/cpu_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <thread>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "internal/argument_checks.hpp"
#include "cpu_solver_impl.hpp"
#include "internal/stretch_topology.hpp"
#include "implicit_euler.hpp"
#include "internal/kernel.hpp"
#include "row_kernel.hpp"
#include "internal/self_collision.hpp"
#include "strain_projection.hpp"
#include "thread_pool.hpp"

// Every per-particle formula comes from engine/kernel/cloth_kernel.h (kernel.hpp), the source
// the compute shaders include too; this file gathers the inputs, loops and schedules. The engine
// is built with -ffp-contract=off, so the compiler does not fuse the kernel's expressions.

namespace vkcloth {

using detail::bad_components;

namespace {

/// Row kernel ISA: 2 = AVX-512F, 1 = AVX2, 0 = scalar; the widest the CPU has, capped by the
/// environment variable VKCLOTH_CPU_SIMD = scalar | avx2 | avx512 (tests compare them bitwise).
int detect_simd() {
  int best = 0;
#if VKCLOTH_ROW_SIMD
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2"))
    best = 1;
#if VKCLOTH_ROW_AVX512
  if (__builtin_cpu_supports("avx512f"))
    best = 2;
#endif
#endif
  if (const char* env = std::getenv("VKCLOTH_CPU_SIMD")) {
    if (std::strcmp(env, "scalar") == 0)
      best = 0;
    else if (std::strcmp(env, "avx2") == 0)
      best = std::min(best, 1);
  }
  return best;
}

} // namespace

template <typename Real> CpuSolver<Real>::Impl::Impl() = default;
template <typename Real> CpuSolver<Real>::Impl::~Impl() = default;

template <typename Real>
Result<CpuSolver<Real>> CpuSolver<Real>::create(const ParticleSystem& system, SimParams params,
                                                CpuSolverOptions options) {
  VKCLOTH_TRY(params.validate());
  auto topology = ClothTopology::create(system);
  if (!topology)
    return topology.error();
  return create(std::move(*topology), std::move(params), options);
}

template <typename Real>
Result<CpuSolver<Real>> CpuSolver<Real>::create(std::shared_ptr<const ClothTopology> topology,
                                                SimParams params, CpuSolverOptions options) {
  if (!topology)
    return make_error(ErrorCode::invalid_argument, "CpuSolver::create: the topology is null");
  VKCLOTH_TRY(params.validate());
  if (options.threads > 256)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("threads must be at most 256, got {}", options.threads));
  const ParticleSystem& system = topology->system();
  const std::size_t n = system.size();

  VKCLOTH_TRY(detail::PinTargets::check(params, {}, n));
  VKCLOTH_TRY(detail::check_sweep_order(params.stretch_limit, *topology));
  if constexpr (std::is_same_v<Real, float>)
    VKCLOTH_TRY(detail::check_float_masses(system));

  auto impl = std::make_unique<Impl>();
  Impl& s = *impl;
  s.topology_ = std::move(topology);
  s.params_ = params;
  s.edge_offsets_ = s.topology_->edge_offsets();
  s.edges_.reserve(s.topology_->edges().size());
  for (const GatherEdge& e : s.topology_->edges())
    s.edges_.push_back(typename Impl::Edge{e.other, Real(e.rest_length), Real(e.stiffness), e.ring});
  s.mass_.resize(n);
  s.pinned_.resize(n);
  s.pos_.resize(n);
  s.vel_.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    const Particle& q = system.particles[p];
    s.mass_[p] = Real(q.mass);
    s.pinned_[p] = q.pinned;
    s.pos_[p] = Vec3(q.position);
    s.vel_[p] = q.pinned ? Vec3(0) : Vec3(q.velocity);
  }
  s.force_.assign(n, Vec3(0));
  s.normal_.assign(n, Vec3(0));
  s.pos_next_ = s.pos_;
  if ((s.stencil_ = s.topology_->stencil())) {
    for (std::size_t k = 0; k < 12; ++k) {
      s.stencil_offset_[k] = s.stencil_->offset[k];
      s.stencil_rest_[k] = Real(s.stencil_->rest_length[k]);
      s.stencil_stiff_[k] = Real(s.stencil_->stiffness[k]);
    }
    s.soa_pad_ = s.stencil_->reach;
  }
  // Below ~1000 particles per thread the fork-join costs more than it saves.
  const unsigned wanted = options.threads ? options.threads : detail::ThreadPool::available_cores();
  const auto useful = static_cast<unsigned>(std::max<std::size_t>(1, n / 1024));
  s.pool_ = std::make_unique<detail::ThreadPool>(std::min(wanted, useful));
  s.simd_ = detect_simd();
  return CpuSolver(std::move(impl));
}

template <typename Real> Result<void> CpuSolver<Real>::Impl::set_params(SimParams params) {
  VKCLOTH_TRY(params.validate());
  VKCLOTH_TRY(targets_.check_params(params, pos_.size()));
  VKCLOTH_TRY(detail::check_sweep_order(params.stretch_limit, *topology_));
  if (!detail::same_frame(params.inertia, params_.inertia))
    frame_last_.reset();
  params_ = params;
  return {};
}

template <typename Real>
Result<void> CpuSolver<Real>::Impl::set_particle(std::uint32_t index, Vec3 position, Vec3 velocity) {
  if (index >= pos_.size())
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("set_particle: index {} is out of range (the system has {} particles)",
                                  index, pos_.size()));
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(position[k]) || !std::isfinite(velocity[k]))
      return make_error(
          ErrorCode::invalid_argument,
          fmt::format(
              "set_particle: particle {} position ({}, {}, {}) and velocity ({}, {}, {}) must be finite",
              index, position.x, position.y, position.z, velocity.x, velocity.y, velocity.z));
  pos_[index] = position;
  vel_[index] = pinned_[index] ? Vec3(0) : velocity;
  soa_valid_ = false;
  return {};
}

template <typename Real>
typename CpuSolver<Real>::Vec3
CpuSolver<Real>::Impl::normal_force_at(std::span<const Vec3> pos, std::span<const Vec3> vel, std::size_t p) {
  const Vec3 x = pos[p];
  Vec3 f(0);
  Vec3 fan(0); // an area-weighted vertex normal (zero without a surface)
  bool interior = false;
  if (stencil_) {
    const std::size_t nx = topology_->grid()->nx, ny = topology_->grid()->ny;
    const std::size_t i = p % nx, j = p / nx;
    interior = i >= 2 && i + 2 < nx && j >= 2 && j + 2 < ny;
  }
  if (!topology_->ring_normals())
    fan = fan_sum(pos, p);
  if (interior) {
    // Same terms, same order as the CSR loop below (the topology's stencil detection checked it).
    for (std::size_t k = 0; k < 12; ++k)
      kernel::add_spring(f, x, pos[std::size_t(std::int64_t(p) + stencil_offset_[k])], stencil_rest_[k],
                         stencil_stiff_[k]);
  } else {
    Vec3 prev(0), first(0);
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e) {
      const Edge& s = edges_[e];
      const Vec3 u = pos[s.other] - x;
      kernel::add_spring_edge(f, u, s.rest_length, s.stiffness);
      kernel::add_ring_term(fan, prev, first, u, s.ring);
    }
  }
  normal_[p] = kernel::unit_or_zero(fan);
  const Real kw = Real(params_.wind.strength);
  return kernel::add_body_forces(f, mass_[p], vel[p], Vec3{params_.gravity}, Real(params_.damping),
                                 kw != Real(0), normal_[p], Vec3{params_.wind.direction}, kw);
}

template <typename Real>
typename CpuSolver<Real>::Impl::Vec3 CpuSolver<Real>::Impl::fan_sum(std::span<const Vec3> pos,
                                                                    std::size_t p) const {
  const Vec3 x = pos[p];
  Vec3 fan(0);
  const std::span<const std::uint32_t> fan_offsets = topology_->fan_offsets();
  const std::span<const FanTriangle> fans = topology_->fans();
  for (std::uint32_t t = fan_offsets[p]; t < fan_offsets[p + 1]; ++t)
    kernel::add_fan_triangle(fan, pos[fans[t].a] - x, pos[fans[t].b] - x);
  return fan;
}

template <typename Real> void CpuSolver<Real>::Impl::normal_at(std::span<const Vec3> pos, std::size_t p) {
  if (!topology_->ring_normals()) {
    normal_[p] = kernel::unit_or_zero(fan_sum(pos, p));
    return;
  }
  const Vec3 x = pos[p];
  Vec3 fan(0), prev(0), first(0);
  for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e)
    kernel::add_ring_term(fan, prev, first, pos[edges_[e].other] - x, edges_[e].ring);
  normal_[p] = kernel::unit_or_zero(fan);
}

// The colliders at their pose for this substep, as the kernel takes them (kernel_shape: the
// conversion the GPU solver uses too); a mesh collider's hierarchy is walked in place.
template <typename Real> void CpuSolver<Real>::Impl::prepare_colliders() {
  if (!contacts_)
    contacts_ = std::make_unique<detail::ContactShapes<Real>>();
  auto& shapes = contacts_->shapes;
  auto& meshes = contacts_->meshes;
  auto& finish = contacts_->finish;
  shapes.clear();
  meshes.clear();
  finish.clear();
  std::vector<const ColliderMesh*> mesh_list;
  for (const Collider& c : params_.colliders)
    if (c.type == Collider::Type::mesh)
      mesh_list.push_back(c.mesh.get());
  if (mesh_list != mesh_cache_meshes_) { // other meshes: their entries start empty
    mesh_cache_.assign(8 * mesh_list.size() * pos_.size(), Real(0));
    mesh_cache_meshes_ = mesh_list;
  }
  std::uint32_t mesh_ordinal = 0;
  for (const Collider& c : params_.colliders) {
    kernel::MeshData m;
    std::uint32_t cache = 0;
    if (c.mesh && c.type == Collider::Type::mesh) {
      m.nodes = c.mesh->nodes().data();
      m.triangles = c.mesh->triangles().data();
      m.cache = mesh_cache_.data();
      m.neighbours = c.mesh->neighbours().data();
      if (!c.mesh->triangle_velocities().empty())
        m.velocities = c.mesh->triangle_velocities().data();
      cache = mesh_ordinal++ * std::uint32_t(pos_.size());
    }
    shapes.push_back(kernel::kernel_shape<Real>(c, 0, 0, cache));
    meshes.push_back(m);
  }
  // The SIMD finish (row_kernel.hpp FinishShape): at most finish_max_shapes colliders.
  const bool simd = shapes.size() <= detail::finish_max_shapes;
  for (std::size_t k = 0; simd && k < shapes.size(); ++k) {
    const kernel::ColliderShape<Real>& s = shapes[k];
    auto put = [](Real* out, glm::vec<3, Real> v) {
      out[0] = v.x;
      out[1] = v.y;
      out[2] = v.z;
    };
    detail::FinishShape<Real> f{};
    f.type = s.type;
    f.moving = s.moving;
    put(f.a, s.a);
    f.b = s.b;
    put(f.c, s.c);
    put(f.ax, s.ax);
    put(f.ay, s.ay);
    put(f.az, s.az);
    put(f.velocity, s.velocity);
    put(f.spin, s.spin);
    put(f.pivot, s.pivot);
    f.mu_k = s.mu_k;
    f.mu_s = s.mu_s;
    f.mesh = s.type == VKCLOTH_COLLIDER_MESH ? &meshes[k] : nullptr;
    f.scalar = &s;
    finish.push_back(f);
  }
}

// Moving colliders advance by the substep h (in double, as the GPU solver's host side does).
template <typename Real> void CpuSolver<Real>::Impl::advance_colliders(double h) {
  for (Collider& c : params_.colliders)
    if (c.moving())
      c = c.posed_at(h);
}

template <typename Real>
void CpuSolver<Real>::Impl::contact_at(std::size_t p, Vec3 pos, Vec3& vel, Vec3& force, Real h_over_m,
                                       bool friction) const {
  const Real band = Real(2) * Real(params_.contact_epsilon);
  const bool both = !params_.contact_inward_only; // Figure 12's variant: outward parts go too
  const auto& shapes = contacts_->shapes;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    const kernel::ColliderShape<Real> s = friction ? shapes[k] : kernel::without_friction(shapes[k]);
    Real distance;
    Vec3 normal, deform;
    kernel::collider_contact(mesh_of(k, p), s, pos, pos, band, distance, normal, deform);
    kernel::contact_response(vel, force, s, pos, normal, distance, band, both, h_over_m, deform);
  }
}

template <typename Real>
void CpuSolver<Real>::Impl::project_at(std::size_t p, Vec3 side, Vec3& pos, Vec3& vel) const {
  const Real eps = Real(params_.contact_epsilon);
  for (std::size_t k = 0; k < contacts_->shapes.size(); ++k)
    kernel::project_out(mesh_of(k, p), contacts_->shapes[k], eps, side, pos, vel);
}

template <typename Real> Result<void> CpuSolver<Real>::Impl::check_finite() const {
  const Real limit = Real(params_.divergence_limit);
  // bad_components first (no early exit, vectorised); only when something is bad does the loop
  // below look for the first particle (kernel::diverged), for the message.
  if (pos_.empty() || !bad_components(&pos_[0].x, &vel_[0].x, 3 * pos_.size(), limit))
    return {};
  for (std::size_t p = 0; p < pos_.size(); ++p) {
    const Vec3 x = pos_[p], v = vel_[p];
    if (kernel::diverged(x, v, limit))
      return make_error(
          ErrorCode::diverged,
          fmt::format("simulation diverged at step {} (t = {:.4g} s): particle {} is at ({:.4g}, {:.4g}, "
                      "{:.4g}) with velocity ({:.4g}, {:.4g}, {:.4g}) (limit {:g}); {}",
                      step_, time(), p, double(x.x), double(x.y), double(x.z), double(v.x), double(v.y),
                      double(v.z), params_.divergence_limit, detail::divergence_advice(params_.dt)));
  }
  return {};
}

template <typename Real> Result<void> CpuSolver<Real>::Impl::step() {
  // integrator.substeps = k: k substeps of dt / k (bit-identical to k steps with dt / k).
  const std::uint32_t k = params_.substeps;
  const double h = k == 1 ? params_.dt : params_.dt / double(k);
  const bool targets = !targets_.empty(params_);
  for (std::uint32_t s = 0; s < k; ++s) {
    const Collider frame_before = frame_last_ ? *frame_last_ : detail::frame_collider(params_);
    advance_colliders(h); // a substep meets the colliders (and the host's frame) where they are at its end
    detail::advance_host_frame(params_, h);
    prepare_colliders();
    const detail::FrameStep f = detail::frame_step(params_, frame_before, detail::frame_collider(params_),
                                                   s == 0 ? host_jump_ : std::nullopt);
    if (params_.inertia.enabled())
      frame_last_ = detail::frame_collider(params_);
    if (f.jump)
      jump_cloth(*f.jump);
    if (targets)
      drive_targets(s);
    if (f.carry)
      frame_x0_ = pos_;
    substep(Real(h));
    if (targets)
      hold_targets();
    if (f.carry)
      carry_cloth(f);
  }
  host_jump_.reset();
  targets_.end_step();
  ++step_;
  time_ += params_.dt;
  if (swept_finite_)
    return {}; // the last substep's row sweep already checked every particle
  return check_finite();
}

template <typename Real> void CpuSolver<Real>::Impl::drive_targets(const std::uint32_t k) {
  targets_.at_substep(params_, k, params_.substeps, targets_now_);
  for (const detail::TargetEntry& t : targets_now_)
    if (pinned_[t.particle])
      kernel::drive_pinned(Vec3(t.position), Vec3(t.velocity), pos_[t.particle], vel_[t.particle]);
  soa_valid_ = false; // the row sweep transposes the moved pins
}

template <typename Real> void CpuSolver<Real>::Impl::hold_targets() {
  for (const detail::TargetEntry& t : targets_now_)
    if (!pinned_[t.particle])
      kernel::hold_within(Vec3(t.position), Vec3(t.velocity), Real(t.reach), pos_[t.particle],
                          vel_[t.particle]);
  soa_valid_ = false;
}

template <typename Real> void CpuSolver<Real>::Impl::jump_cloth(const RigidJump& jump) {
  const detail::JumpRows rows = detail::jump_rows(jump);
  const Vec3 r0(rows.r0), r1(rows.r1), r2(rows.r2), t(rows.shift);
  for (std::size_t p = 0; p < pos_.size(); ++p)
    kernel::rigid_jump(r0, r1, r2, t, pos_[p], vel_[p]);
  targets_.teleport(jump);
  soa_valid_ = false;
}

template <typename Real> void CpuSolver<Real>::Impl::carry_cloth(const detail::FrameStep& f) {
  const Vec3 dv(f.dv), omega0(f.omega0), omega1(f.omega1), c0(f.c0), c1(f.c1);
  const Real lin = Real(f.carry_linear), ang = Real(f.carry_angular);
  for (std::size_t p = 0; p < pos_.size(); ++p)
    if (!pinned_[p])
      vel_[p] =
          vel_[p] + kernel::carried_velocity(frame_x0_[p], pos_[p], dv, omega0, omega1, c0, c1, lin, ang);
}

template <typename Real> void CpuSolver<Real>::Impl::substep(const Real h) {
  swept_finite_ = false;
  switch (params_.integrator) {
  case Integrator::explicit_euler:
    euler_substep(h, false);
    break;
  case Integrator::semi_implicit_euler:
    euler_substep(h, true);
    break;
  case Integrator::rk4:
    soa_valid_ = false;
    rk4_substep(h);
    break;
  case Integrator::implicit_euler:
    soa_valid_ = false;
    implicit_substep(h);
    break;
  case Integrator::vbd:
    soa_valid_ = false;
    vbd_substep(h);
    break;
  }
  if (params_.stretch_limit.enabled())
    limit_stretch(h);
  if (detail::self_collision_passes<Real>(params_)) // vbd's energy acts in its sweeps instead
    self_collide();
}

template <typename Real>
void CpuSolver<Real>::Impl::euler_finish(std::size_t p, Vec3 f, const Real h, const bool semi) {
  if (pinned_[p]) {
    force_[p] = f;
    pos_next_[p] = pos_[p];
    return;
  }
  Vec3 v = vel_[p];
  contact_at(p, pos_[p], v, f, h / mass_[p]);
  force_[p] = f;
  Vec3 x = pos_[p];
  kernel::euler_update(semi, x, v, f, mass_[p], h);
  project_at(p, pos_[p], x, v);
  pos_next_[p] = x;
  vel_[p] = v; // only particle p reads its own velocity: updating in place is safe
}

template <typename Real> void CpuSolver<Real>::Impl::euler_substep(const Real h, const bool semi) {
  if (stencil_) {
    row_sweep(h, semi);
    return;
  }
#if VKCLOTH_ROW_SIMD
  if (simd_ != 0 && (topology_->ring_normals() || !topology_->has_surface())) {
    list_sweep(h, semi); // meshes and chains (a grid without a stencil takes the reference)
    return;
  }
#endif
  // One sweep: p's normal and force read positions only (read-only here) and p's own velocity.
  pool_->for_each(pos_.size(),
                  [&](std::size_t p) { euler_finish(p, normal_force_at(pos_, vel_, p), h, semi); });
  std::swap(pos_, pos_next_);
}

// Stage s evaluates (v, F/m) at y_s = y0 + c_s k_{s-1}; contacts filter each stage.
template <typename Real> void CpuSolver<Real>::Impl::rk4_substep(const Real h) {
  const std::size_t n = pos_.size();
  if (stage_pos_.size() != n) {
    for (auto& k : k_pos_)
      k.resize(n);
    for (auto& k : k_vel_)
      k.resize(n);
    stage_pos_.resize(n);
    stage_vel_.resize(n);
  }
  for (std::uint32_t st = 0; st < 4; ++st) {
    if (st == 0) {
      stage_pos_ = pos_;
      stage_vel_ = vel_;
    } else {
      const Real c = kernel::rk4_c(st, h);
      pool_->for_each(pos_.size(), [&](std::size_t p) {
        stage_pos_[p] = kernel::rk4_stage_point(pos_[p], k_pos_[st - 1][p], c);
        stage_vel_[p] = kernel::rk4_stage_point(vel_[p], k_vel_[st - 1][p], c);
      });
    }
    pool_->for_each(pos_.size(), [&](std::size_t p) {
      Vec3 f = normal_force_at(stage_pos_, stage_vel_, p);
      if (!pinned_[p])
        contact_at(p, stage_pos_[p], stage_vel_[p], f, h / mass_[p]);
      if (st == 0)
        force_[p] = f;
      kernel::rk4_derivative(pinned_[p] != 0, stage_vel_[p], f, mass_[p], k_pos_[st][p], k_vel_[st][p]);
    });
  }
  const Real w = h / Real(6);
  pool_->for_each(pos_.size(), [&](std::size_t p) {
    if (pinned_[p])
      return;
    Vec3 dp(0), dv(0);
    for (std::uint32_t st = 0; st < 4; ++st) {
      dp = kernel::rk4_accumulate(st, dp, k_pos_[st][p]);
      dv = kernel::rk4_accumulate(st, dv, k_vel_[st][p]);
    }
    const Vec3 start = pos_[p];
    pos_[p] = kernel::rk4_finish(pos_[p], dp, w);
    vel_[p] = kernel::rk4_finish(vel_[p], dv, w);
    project_at(p, start, pos_[p], vel_[p]);
  });
}

template <typename Real> typename CpuSolver<Real>::Energy CpuSolver<Real>::Impl::energy() const {
  Energy e;
  for (std::size_t p = 0; p < pos_.size(); ++p) {
    const glm::dvec3 v{vel_[p]}, x{pos_[p]};
    if (!pinned_[p]) {
      e.kinetic += 0.5 * double(mass_[p]) * glm::dot(v, v);
      e.gravity -= double(mass_[p]) * glm::dot(params_.gravity, x);
    }
  }
  for (const Spring& s : system().springs) {
    const double stretch = glm::length(glm::dvec3{pos_[s.b]} - glm::dvec3{pos_[s.a]}) - s.rest_length;
    e.spring += 0.5 * s.stiffness * stretch * stretch;
  }
  return e;
}

// The API: each call forwards to the Impl.
template <typename Real> CpuSolver<Real>::CpuSolver(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
template <typename Real> CpuSolver<Real>::CpuSolver(CpuSolver&&) noexcept = default;
template <typename Real> CpuSolver<Real>& CpuSolver<Real>::operator=(CpuSolver&&) noexcept = default;
template <typename Real> CpuSolver<Real>::~CpuSolver() = default;
template <typename Real> unsigned CpuSolver<Real>::threads() const {
  return impl_->pool_->size();
}
// A step swaps pos_ with pos_next_ (its scratch) an odd or even number of times; the public calls
// copy the result back into the buffer positions() showed before, so its address never changes.
template <typename Real> void CpuSolver<Real>::Impl::keep_positions_at(const Vec3* home) {
  if (pos_.data() == home || pos_next_.data() != home)
    return;
  std::copy(pos_.begin(), pos_.end(), pos_next_.begin());
  std::swap(pos_, pos_next_); // both now hold the result; soa_ (a copy of pos_'s values) stays valid
}
template <typename Real> Result<void> CpuSolver<Real>::step() {
  const Vec3* home = impl_->pos_.data();
  auto r = impl_->step();
  impl_->keep_positions_at(home);
  return r;
}
template <typename Real> Result<void> CpuSolver<Real>::run(std::uint64_t steps) {
  const Vec3* home = impl_->pos_.data();
  Result<void> r;
  for (std::uint64_t s = 0; s < steps && r; ++s)
    r = impl_->step();
  impl_->keep_positions_at(home);
  return r;
}
template <typename Real> Result<void> CpuSolver<Real>::set_params(SimParams params) {
  return impl_->set_params(std::move(params));
}
template <typename Real> const SimParams& CpuSolver<Real>::params() const {
  return impl_->params_;
}
template <typename Real> auto CpuSolver<Real>::positions() const -> std::span<const Vec3> {
  return impl_->pos_;
}
template <typename Real> auto CpuSolver<Real>::velocities() const -> std::span<const Vec3> {
  return impl_->vel_;
}
template <typename Real> auto CpuSolver<Real>::forces() const -> std::span<const Vec3> {
  return impl_->force_;
}
template <typename Real> auto CpuSolver<Real>::normals() const -> std::span<const Vec3> {
  return impl_->normal_;
}
template <typename Real> SelfCollisionStats CpuSolver<Real>::self_collision_stats() const {
  return impl_->self_ ? impl_->self_->stats : SelfCollisionStats{};
}

template <typename Real> const SolveStats& CpuSolver<Real>::last_solve() const {
  return impl_->solve_;
}
template <typename Real> std::uint64_t CpuSolver<Real>::step_index() const {
  return impl_->step_;
}
template <typename Real> double CpuSolver<Real>::time() const {
  return impl_->time_;
}
template <typename Real> const ParticleSystem& CpuSolver<Real>::system() const {
  return impl_->system();
}
template <typename Real> const std::shared_ptr<const ClothTopology>& CpuSolver<Real>::topology() const {
  return impl_->topology_;
}
template <typename Real> Result<void> CpuSolver<Real>::teleport(const RigidJump& jump) {
  VKCLOTH_TRY(jump.validate());
  impl_->host_jump_ = impl_->host_jump_ ? detail::then(*impl_->host_jump_, jump) : jump;
  return {};
}
template <typename Real> Result<void> CpuSolver<Real>::set_pin_targets(std::span<const PinTarget> targets) {
  return impl_->targets_.set_host(impl_->params_, targets, impl_->pos_.size());
}
template <typename Real>
Result<void> CpuSolver<Real>::set_particle(std::uint32_t index, Vec3 position, Vec3 velocity) {
  return impl_->set_particle(index, position, velocity);
}
template <typename Real> auto CpuSolver<Real>::energy() const -> Energy {
  return impl_->energy();
}

// Instantiating the class instantiates its nested Impl too (a second explicit instantiation of
// Impl is an error under clang).
template class CpuSolver<float>;
template class CpuSolver<double>;

} // namespace vkcloth
