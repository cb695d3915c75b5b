// SPDX-License-Identifier: MIT
// Golden images: scenes rendered at 160x120 on the offscreen target, compared with the PNGs in
// tests/render/golden/ (metric in render_test_util.hpp: < 0.5% of the pixels with a channel
// differing by more than 8). Regenerate: VKCLOTH_UPDATE_GOLDEN=1 ctest -R render:golden
#include "render_test_util.hpp"

using namespace vkcloth;
using namespace vkcloth::render;
using namespace vkcloth::render::test;

namespace {

void golden_case(const std::string& name, const std::string& file, std::uint32_t steps,
                 std::vector<std::string> sets = {}) {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  auto rig = make_rig(ctx, load(file, std::move(sets)), 160, 120);
  auto img = rig->target.render(rig->solver, rig->renderer, rig->camera, steps);
  REQUIRE_MESSAGE(img, (img ? "" : img.error().message));
  check_golden(name, *img);
}

} // namespace

TEST_CASE("golden: cloth draped on the sphere (16 steps)") {
  golden_case("cloth_on_sphere", "cloth_on_sphere.json", 16);
}
TEST_CASE("golden: hanging cloth (60 steps)") {
  golden_case("cloth_hanging", "cloth_hanging.json", 60);
}
TEST_CASE("golden: cloth on the floor plane (80 steps)") {
  golden_case("cloth_on_plane", "cloth_on_plane.json", 80);
}
TEST_CASE("golden: single spring, a chain (20 steps)") {
  golden_case("spring", "spring.json", 20);
}
