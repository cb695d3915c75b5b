// SPDX-License-Identifier: MIT
// Compiled (-fsyntax-only) by the package:glm_abi_* tests: the public headers under a host GLM
// configuration (-DGLM_FORCE_...) or, faked here, a host GLM version other than the library's.
#include <glm/vec3.hpp>

#if defined(FAKE_GLM_VERSION_PATCH)
#undef GLM_VERSION_PATCH
#define GLM_VERSION_PATCH FAKE_GLM_VERSION_PATCH
#endif
#if defined(FAKE_GLM_VERSION_REVISION)
#undef GLM_VERSION_REVISION
#define GLM_VERSION_REVISION FAKE_GLM_VERSION_REVISION
#endif

#include <vkcloth/system.hpp>

int main() {
  return 0;
}
