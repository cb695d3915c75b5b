#include "vkcloth/cpu_solver.hpp"

#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

// Floating-point expressions below are written in the exact order the GLSL passes use
// (shaders/force.comp, shaders/integrate.comp); the engine is built with -ffp-contract=off so the
// compiler does not fuse them differently. Change one side, change the other.

namespace vkcloth {
namespace {

template <typename V> auto dot3(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/// Signed distance to a collider and its outward unit normal at the closest surface point.
template <typename Real> struct Contact {
  Real distance;
  glm::vec<3, Real> normal;
};

template <typename Real> Contact<Real> collider_contact(const Collider& c, glm::vec<3, Real> p) {
  using V = glm::vec<3, Real>;
  if (c.type == Collider::Type::plane) {
    const V n{c.normal};
    return {dot3(n, p) - Real(c.offset), n};
  }
  const V r = p - V{c.center};
  const Real len = std::sqrt(dot3(r, r));
  const V n = len > Real(0) ? r / len : V{0, 0, 1}; // at the exact centre, push up
  return {len - Real(c.radius), n};
}

} // namespace

template <typename Real> Result<CpuSolver<Real>> CpuSolver<Real>::create(const ParticleSystem& system, SimParams params) {
  VKCLOTH_TRY(params.validate());
  const std::size_t n = system.size();
  if (n == 0) return make_error(ErrorCode::invalid_argument, "the particle system is empty");
  if (system.adjacency.offsets.size() != n + 1)
    return make_error(ErrorCode::invalid_argument, "the particle system was not finalized (call finalize())");
  if (system.grid && std::uint64_t(system.grid->nx) * system.grid->ny != n)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("grid {} x {} does not match the {} particles", system.grid->nx, system.grid->ny, n));
  for (std::size_t p = 0; p < n; ++p)
    if (!system.particles[p].pinned && !(system.particles[p].mass > 0.0))
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("particle {} has mass {}; free particles need a mass > 0", p, system.particles[p].mass));

  CpuSolver s;
  s.system_ = std::make_shared<const ParticleSystem>(system);
  s.params_ = params;
  s.edge_offsets_ = system.adjacency.offsets;
  s.edges_.reserve(system.adjacency.refs.size());
  for (const SpringRef& r : system.adjacency.refs) {
    const Spring& sp = system.springs[r.spring];
    s.edges_.push_back(Edge{r.other, Real(sp.rest_length), Real(sp.stiffness)});
  }
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
  return s;
}

template <typename Real> Result<void> CpuSolver<Real>::set_params(SimParams params) {
  VKCLOTH_TRY(params.validate());
  params_ = params;
  return {};
}

template <typename Real> void CpuSolver<Real>::set_particle(std::uint32_t index, Vec3 position, Vec3 velocity) {
  if (index >= pos_.size()) return;
  pos_[index] = position;
  vel_[index] = pinned_[index] ? Vec3(0) : velocity;
}

template <typename Real> void CpuSolver<Real>::compute_normals(std::span<const Vec3> pos) {
  if (!system_->grid) return;
  const std::int64_t nx = system_->grid->nx, ny = system_->grid->ny;
  for (std::int64_t j = 0; j < ny; ++j)
    for (std::int64_t i = 0; i < nx; ++i) {
      const Vec3 p = pos[j * nx + i];
      // Fan around p: right, up, left, down. Each present pair adds one triangle's
      // cross product (twice its area times its normal): an area-weighted vertex normal.
      const bool has[4] = {i + 1 < nx, j + 1 < ny, i > 0, j > 0};
      Vec3 e[4] = {};
      if (has[0]) e[0] = pos[j * nx + i + 1] - p;
      if (has[1]) e[1] = pos[(j + 1) * nx + i] - p;
      if (has[2]) e[2] = pos[j * nx + i - 1] - p;
      if (has[3]) e[3] = pos[(j - 1) * nx + i] - p;
      Vec3 sum(0);
      for (int k = 0; k < 4; ++k)
        if (has[k] && has[(k + 1) & 3]) sum += glm::cross(e[k], e[(k + 1) & 3]);
      const Real len = std::sqrt(dot3(sum, sum));
      normal_[j * nx + i] = len > Real(0) ? sum / len : Vec3(0);
    }
}

template <typename Real>
void CpuSolver<Real>::compute_forces(std::span<const Vec3> pos, std::span<const Vec3> vel, std::vector<Vec3>& out) {
  compute_normals(pos);
  const Vec3 g{params_.gravity};
  const Real mu = Real(params_.damping);
  const Real kw = Real(params_.wind.strength);
  const Vec3 uw{params_.wind.direction};
  const std::size_t n = pos.size();
  for (std::size_t p = 0; p < n; ++p) {
    const Vec3 x = pos[p];
    Vec3 f(0);
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e) {
      const Edge& s = edges_[e];
      const Vec3 u = pos[s.other] - x;
      const Real len = std::sqrt(dot3(u, u));
      if (len > Real(0)) f += u * (s.stiffness * (len - s.rest_length) / len); // report eq. 2
    }
    const Real m = mass_[p];
    f += g * m;
    f -= vel[p] * (mu * m);
    if (kw != Real(0)) {
      const Vec3 nrm = normal_[p];
      f += nrm * (kw * dot3(nrm, uw));
    }
    out[p] = f;
  }
}

template <typename Real>
void CpuSolver<Real>::apply_contacts(std::span<const Vec3> pos, std::vector<Vec3>& vel, std::vector<Vec3>& force) const {
  if (params_.colliders.empty()) return;
  const Real band = Real(2) * Real(params_.contact_epsilon);
  for (std::size_t p = 0; p < pos.size(); ++p) {
    if (pinned_[p]) continue;
    for (const Collider& c : params_.colliders) {
      const Contact<Real> ct = collider_contact<Real>(c, pos[p]);
      if (!(ct.distance < band)) continue;
      // Only the part pointing INTO the collider is removed: a hand lifting the cloth keeps
      // its outward pull (report §4, Figure 12).
      const Real vn = dot3(vel[p], ct.normal);
      if (vn < Real(0)) vel[p] -= ct.normal * vn;
      const Real fn = dot3(force[p], ct.normal);
      if (fn < Real(0)) force[p] -= ct.normal * fn;
    }
  }
}

template <typename Real> void CpuSolver<Real>::project(std::vector<Vec3>& pos, std::vector<Vec3>& vel) const {
  if (params_.colliders.empty()) return;
  const Real eps = Real(params_.contact_epsilon);
  for (std::size_t p = 0; p < pos.size(); ++p) {
    if (pinned_[p]) continue;
    for (const Collider& c : params_.colliders) {
      const Contact<Real> ct = collider_contact<Real>(c, pos[p]);
      if (!(ct.distance < Real(0))) continue;
      if (c.type == Collider::Type::plane)
        pos[p] += ct.normal * (eps - ct.distance); // report eq. 5: back to z_s + eps
      else
        pos[p] = Vec3{c.center} + ct.normal * (Real(c.radius) + eps); // report eq. 6
      const Real vn = dot3(vel[p], ct.normal);
      if (vn < Real(0)) vel[p] -= ct.normal * vn;
    }
  }
}

template <typename Real> Result<void> CpuSolver<Real>::check_finite() const {
  const Real limit = Real(params_.divergence_limit);
  for (std::size_t p = 0; p < pos_.size(); ++p) {
    const Vec3 x = pos_[p], v = vel_[p];
    const bool finite = std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z) && std::isfinite(v.x) &&
                        std::isfinite(v.y) && std::isfinite(v.z);
    if (!finite || std::abs(x.x) > limit || std::abs(x.y) > limit || std::abs(x.z) > limit)
      return make_error(ErrorCode::diverged,
                        fmt::format("simulation diverged at step {} (t = {:.4g} s): particle {} is at ({:.4g}, {:.4g}, "
                                    "{:.4g}) with velocity ({:.4g}, {:.4g}, {:.4g}) (limit {:g}); try a smaller "
                                    "integrator.dt, lower stiffness or more damping",
                                    step_, time(), p, double(x.x), double(x.y), double(x.z), double(v.x), double(v.y),
                                    double(v.z), params_.divergence_limit));
  }
  return {};
}

template <typename Real> Result<void> CpuSolver<Real>::step() {
  const std::size_t n = pos_.size();
  const Real dt = Real(params_.dt);
  switch (params_.integrator) {
  case Integrator::explicit_euler:
  case Integrator::semi_implicit_euler: {
    compute_forces(pos_, vel_, force_);
    apply_contacts(pos_, vel_, force_);
    const bool semi = params_.integrator == Integrator::semi_implicit_euler;
    for (std::size_t p = 0; p < n; ++p) {
      if (pinned_[p]) continue;
      const Vec3 a = force_[p] / mass_[p];
      if (semi) {
        vel_[p] += a * dt;
        pos_[p] += vel_[p] * dt;
      } else {
        pos_[p] += vel_[p] * dt;
        vel_[p] += a * dt;
      }
    }
    break;
  }
  case Integrator::rk4: {
    // Stage k evaluates (v, F/m) at y_k = y0 + c_k dt k_{k-1}; contacts filter each stage.
    if (stage_pos_.size() != n) {
      for (auto& k : k_pos_) k.resize(n);
      for (auto& k : k_vel_) k.resize(n);
      stage_pos_.resize(n);
      stage_vel_.resize(n);
    }
    const Real c[4] = {Real(0), dt / Real(2), dt / Real(2), dt};
    for (int s = 0; s < 4; ++s) {
      if (s == 0) {
        stage_pos_ = pos_;
        stage_vel_ = vel_;
      } else {
        for (std::size_t p = 0; p < n; ++p) {
          stage_pos_[p] = pos_[p] + k_pos_[s - 1][p] * c[s];
          stage_vel_[p] = vel_[p] + k_vel_[s - 1][p] * c[s];
        }
      }
      std::vector<Vec3>& f = s == 0 ? force_ : k_vel_[s];
      compute_forces(stage_pos_, stage_vel_, f);
      apply_contacts(stage_pos_, stage_vel_, f);
      for (std::size_t p = 0; p < n; ++p) {
        k_pos_[s][p] = pinned_[p] ? Vec3(0) : stage_vel_[p];
        k_vel_[s][p] = pinned_[p] ? Vec3(0) : f[p] / mass_[p];
      }
    }
    const Real w = dt / Real(6);
    for (std::size_t p = 0; p < n; ++p) {
      if (pinned_[p]) continue;
      Vec3 dp = k_pos_[0][p] + k_pos_[1][p] * Real(2);
      dp += k_pos_[2][p] * Real(2);
      dp += k_pos_[3][p];
      Vec3 dv = k_vel_[0][p] + k_vel_[1][p] * Real(2);
      dv += k_vel_[2][p] * Real(2);
      dv += k_vel_[3][p];
      pos_[p] += dp * w;
      vel_[p] += dv * w;
    }
    break;
  }
  }
  project(pos_, vel_);
  ++step_;
  return check_finite();
}

template <typename Real> Result<void> CpuSolver<Real>::run(std::uint64_t steps) {
  for (std::uint64_t s = 0; s < steps; ++s) VKCLOTH_TRY(step());
  return {};
}

template <typename Real> typename CpuSolver<Real>::Energy CpuSolver<Real>::energy() const {
  Energy e;
  for (std::size_t p = 0; p < pos_.size(); ++p) {
    const glm::dvec3 v{vel_[p]}, x{pos_[p]};
    if (!pinned_[p]) {
      e.kinetic += 0.5 * double(mass_[p]) * glm::dot(v, v);
      e.gravity -= double(mass_[p]) * glm::dot(params_.gravity, x);
    }
  }
  for (const Spring& s : system_->springs) {
    const double stretch = glm::length(glm::dvec3{pos_[s.b]} - glm::dvec3{pos_[s.a]}) - s.rest_length;
    e.spring += 0.5 * s.stiffness * stretch * stretch;
  }
  return e;
}

template class CpuSolver<float>;
template class CpuSolver<double>;

} // namespace vkcloth
