// SPDX-License-Identifier: MIT
// GLM is part of vkcloth's public API (glm::vec2 / vec3 / dvec3 in Particle, Spring, meshes...),
// so a host must compile these headers with the GLM configuration the library was built with.
// This header turns a mismatch into a compile error instead of a silent ABI break (structs of a
// different size or layout on each side of the call):
// - layout: GLM's default, packed types. A host that defines GLM_FORCE_DEFAULT_ALIGNED_GENTYPES
//   with SIMD (GLM_FORCE_INTRINSICS, GLM_FORCE_AVX...), or anything else that changes a type's
//   size or alignment, gets a static_assert naming the type.
// - version: the GLM version the library was configured with (vkcloth/glm_version.hpp, generated)
//   against the host's. A different major, minor or patch version is an error: GLM has changed
//   defaults between such releases (initialisation, quaternion storage order, precision types)
//   and the layout checks cannot see every such change. A different revision only (0.9.9.8 vs
//   0.9.9.7) is bug fixes in a header-only library: a #pragma message, not an error. A host that
//   knows its GLM is compatible can define VKCLOTH_ALLOW_GLM_VERSION_MISMATCH to skip the version
//   check (the layout checks stay).
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "vkcloth/glm_version.hpp"

#define VKCLOTH_GLM_LAYOUT_MESSAGE(type)                                                                     \
  "vkcloth: " type " does not have the size and alignment vkcloth was built with (GLM's default, packed "    \
  "types): compile with the same GLM configuration as the library (no GLM_FORCE_DEFAULT_ALIGNED_GENTYPES "   \
  "with GLM_FORCE_INTRINSICS / GLM_FORCE_AVX...; docs/embedding.md, Link)"

static_assert(sizeof(glm::vec2) == 8 && alignof(glm::vec2) == 4, VKCLOTH_GLM_LAYOUT_MESSAGE("glm::vec2"));
static_assert(sizeof(glm::vec3) == 12 && alignof(glm::vec3) == 4, VKCLOTH_GLM_LAYOUT_MESSAGE("glm::vec3"));
static_assert(sizeof(glm::vec4) == 16 && alignof(glm::vec4) == 4, VKCLOTH_GLM_LAYOUT_MESSAGE("glm::vec4"));
static_assert(sizeof(glm::dvec2) == 16 && alignof(glm::dvec2) == 8, VKCLOTH_GLM_LAYOUT_MESSAGE("glm::dvec2"));
static_assert(sizeof(glm::dvec3) == 24 && alignof(glm::dvec3) == 8, VKCLOTH_GLM_LAYOUT_MESSAGE("glm::dvec3"));
static_assert(sizeof(glm::mat4) == 64 && alignof(glm::mat4) == 4, VKCLOTH_GLM_LAYOUT_MESSAGE("glm::mat4"));

#undef VKCLOTH_GLM_LAYOUT_MESSAGE

#define VKCLOTH_GLM_STR2(x) #x
#define VKCLOTH_GLM_STR(x) VKCLOTH_GLM_STR2(x)
#define VKCLOTH_GLM_HOST_VERSION                                                                             \
  VKCLOTH_GLM_STR(GLM_VERSION_MAJOR)                                                                         \
  "." VKCLOTH_GLM_STR(GLM_VERSION_MINOR) "." VKCLOTH_GLM_STR(GLM_VERSION_PATCH) "." VKCLOTH_GLM_STR(         \
      GLM_VERSION_REVISION)

#if !defined(VKCLOTH_ALLOW_GLM_VERSION_MISMATCH)
#if GLM_VERSION_MAJOR != VKCLOTH_GLM_VERSION_MAJOR || GLM_VERSION_MINOR != VKCLOTH_GLM_VERSION_MINOR ||      \
    GLM_VERSION_PATCH != VKCLOTH_GLM_VERSION_PATCH
static_assert(false, "vkcloth was built with GLM " VKCLOTH_GLM_VERSION_STRING
                     ", this code compiles with GLM " VKCLOTH_GLM_HOST_VERSION
                     ": use the library's GLM version (or define "
                     "VKCLOTH_ALLOW_GLM_VERSION_MISMATCH if you know they are compatible)");
#elif GLM_VERSION_REVISION != VKCLOTH_GLM_VERSION_REVISION
#pragma message("vkcloth was built with GLM " VKCLOTH_GLM_VERSION_STRING                                     \
                ", this code compiles with GLM " VKCLOTH_GLM_HOST_VERSION                                    \
                " (a different revision: bug fixes only, accepted)")
#endif
#endif

#undef VKCLOTH_GLM_HOST_VERSION
#undef VKCLOTH_GLM_STR
#undef VKCLOTH_GLM_STR2
