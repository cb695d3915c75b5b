// SPDX-License-Identifier: MIT
// The README's "C++ quick start", compiled and run as a test (quickstart:readme checks that the
// README shows exactly the lines between the markers), so the snippet cannot rot.
#include <cstdio>

#include <vkcloth/vkcloth.hpp>

namespace {
int fail(const vkcloth::Error& e) {
  std::fprintf(stderr, "quickstart: %s\n", e.message.c_str());
  return 1;
}
} // namespace

int main() {
  // The README shows these lines as a reader would type them: compact, not clang-formatted.
  // clang-format off
  // [quickstart]
  using namespace vkcloth;
  auto context = gpu::Context::create(); // or gpu::Context::adopt(...) on the host's VkDevice
  if (!context) return fail(context.error());
  auto cloth = make_cloth({.nx = 10, .ny = 10}); // the report's cloth: 1 m x 1 m, top corners pinned
  if (!cloth) return fail(cloth.error());
  auto topology = ClothTopology::create(*cloth); // prepared once, shared by every instance
  auto world = gpu::ClothWorld::create(*context);
  if (!topology || !world) return fail(!topology ? topology.error() : world.error());
  auto id = world->add(*topology, SimParams{}); // dt 0.02 s, gravity, damping 0.5
  if (!id) return fail(id.error());
  if (auto r = world->simulate(100); !r) return fail(r.error()); // or record_steps(cmd, n) per frame
  auto positions = world->positions(*id); // or world->buffers(*id) to draw them on the GPU
  if (!positions) return fail(positions.error());
  std::printf("lowest corner after 2 s: z = %.3f m\n", (*positions)[0].z);
  // [/quickstart]
  // clang-format on
  return (*positions)[0].z < -0.5f && (*positions)[0].z > -2.0f ? 0 : 1; // hangs below its start
}
