// SPDX-License-Identifier: MIT
// The per-particle physics as C++: shaders/include/cloth_kernel.h, the one source the compute
// shaders include too, compiled here with GLM (which follows GLSL's syntax) once for float
// (kernel::f32, CpuSolver<float>: the GPU's bits) and once for double (kernel::f64). Both sets
// are visible in vkcloth::kernel; overloading on the vector type picks the precision.
// The GLSL side of the same bridge: shaders/include/common.glsl.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include <glm/vec3.hpp>

#include "vkcloth/params.hpp"
#include "vkcloth_shared.h"

// The shader constants the kernel compares against are the C++ enums' values.
static_assert(VKCLOTH_COLLIDER_PLANE == std::uint32_t(vkcloth::Collider::Type::plane));
static_assert(VKCLOTH_COLLIDER_SPHERE == std::uint32_t(vkcloth::Collider::Type::sphere));
static_assert(VKCLOTH_INTEGRATOR_EXPLICIT_EULER == std::uint32_t(vkcloth::Integrator::explicit_euler));
static_assert(VKCLOTH_INTEGRATOR_SEMI_IMPLICIT_EULER ==
              std::uint32_t(vkcloth::Integrator::semi_implicit_euler));
static_assert(VKCLOTH_INTEGRATOR_RK4 == std::uint32_t(vkcloth::Integrator::rk4));

#define KFN inline
#define OUT(T) T&
#define INOUT(T) T&
#define precise

namespace vkcloth::kernel {

// What cloth_kernel.h expects besides real and vec3; the nested namespaces below find these.
using uint = std::uint32_t;
using std::abs;
using std::max;
using std::sqrt;
template <typename V> bool all_finite(V v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

namespace f32 {
using real = float;
using vec3 = glm::vec3;
#include "cloth_kernel.h"
} // namespace f32

namespace f64 {
using real = double;
using vec3 = glm::dvec3;
#include "cloth_kernel.h"
} // namespace f64

using namespace f32;
using namespace f64;

/// The kernel's SpringBlock of precision Real.
template <typename Real>
using SpringBlock = std::conditional_t<std::is_same_v<Real, float>, f32::SpringBlock, f64::SpringBlock>;

} // namespace vkcloth::kernel

#undef KFN
#undef OUT
#undef INOUT
#undef precise
