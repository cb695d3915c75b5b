// SPDX-License-Identifier: MIT
#include "internal/pin_targets.hpp"

#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "internal/argument_checks.hpp"

namespace vkcloth::detail {

namespace {
// Who targets a particle, as the messages name it: attachments[a].particles[i] or pin target i.
struct Claim {
  std::size_t attachment; // SIZE_MAX: a host target
  std::size_t index;
  std::string name() const {
    return attachment == SIZE_MAX ? fmt::format("pin target {}", index)
                                  : fmt::format("attachments[{}].particles[{}]", attachment, index);
  }
};
} // namespace

Result<void> PinTargets::check(const SimParams& params, std::span<const PinTarget> host, std::size_t count) {
  std::unordered_map<std::uint32_t, Claim> owner; // particle -> who targets it (names made on an error)
  const auto claim = [&](std::uint32_t p, Claim who) -> Result<void> {
    if (p >= count)
      return make_error(
          ErrorCode::invalid_argument,
          fmt::format("{} is particle {}, past the cloth's {} particles", who.name(), p, count));
    const auto [it, fresh] = owner.emplace(p, who);
    if (!fresh)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("{} is particle {}, which {} targets already (one target per particle)",
                                    who.name(), p, it->second.name()));
    return {};
  };
  for (std::size_t a = 0; a < params.attachments.size(); ++a)
    for (std::size_t i = 0; i < params.attachments[a].particles.size(); ++i)
      VKCLOTH_TRY(claim(params.attachments[a].particles[i], Claim{a, i}));
  for (std::size_t i = 0; i < host.size(); ++i) {
    const PinTarget& t = host[i];
    if (!finite(t.position))
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("pin target {} (particle {}): position must be finite, got {}", i,
                                    t.particle, str(t.position)));
    if (!std::isfinite(t.max_distance) || t.max_distance < 0.0)
      return make_error(
          ErrorCode::invalid_argument,
          fmt::format("pin target {} (particle {}): max_distance must be finite and >= 0, got {}", i,
                      t.particle, t.max_distance));
    VKCLOTH_TRY(claim(t.particle, Claim{SIZE_MAX, i}));
  }
  return {};
}

Result<void> PinTargets::check_params(const SimParams& params, std::size_t count) const {
  std::vector<PinTarget> host;
  host.reserve(host_.size());
  for (const Host& h : host_)
    host.push_back(h.target);
  return check(params, host, count);
}

Result<void> PinTargets::set_host(const SimParams& params, std::span<const PinTarget> targets,
                                  std::size_t count) {
  VKCLOTH_TRY(check(params, targets, count));
  std::unordered_map<std::uint32_t, glm::dvec3> previous;
  for (const Host& h : host_)
    previous.emplace(h.target.particle, h.target.position);
  std::vector<Host> next;
  next.reserve(targets.size());
  for (const PinTarget& t : targets) {
    const auto it = previous.find(t.particle);
    next.push_back(Host{t, it == previous.end() ? t.position : it->second});
  }
  host_ = std::move(next);
  return {};
}

void PinTargets::at_substep(const SimParams& params, std::uint32_t k, std::uint32_t substeps,
                            std::vector<TargetEntry>& out) const {
  out.clear();
  for (const Attachment& a : params.attachments) {
    const Collider& c = params.colliders[a.collider];
    const glm::dvec3 centre = c.centre();
    for (std::size_t i = 0; i < a.particles.size(); ++i) {
      const glm::dvec3 x = centre + c.rotation * a.offsets[i];
      out.push_back({a.particles[i], x, c.linear_velocity + glm::cross(c.angular_velocity, x - centre),
                     a.max_distance});
    }
  }
  const double s = double(k + 1) / double(substeps), dt = params.dt;
  for (const Host& h : host_) {
    const glm::dvec3 move = h.target.position - h.from;
    out.push_back({h.target.particle, h.from + move * s, move / dt, h.target.max_distance});
  }
}

std::uint32_t PinTargets::size(const SimParams& params) const {
  std::size_t n = host_.size();
  for (const Attachment& a : params.attachments)
    n += a.particles.size();
  return static_cast<std::uint32_t>(n);
}

void PinTargets::teleport(const RigidJump& jump) {
  for (Host& h : host_) {
    h.from = jump.apply(h.from);
    h.target.position = jump.apply(h.target.position);
  }
}

void PinTargets::end_step() {
  for (Host& h : host_)
    h.from = h.target.position;
}

} // namespace vkcloth::detail

namespace vkcloth {
Result<void> check_attachments(const SimParams& params, std::size_t particles) {
  return detail::PinTargets::check(params, {}, particles);
}
} // namespace vkcloth
