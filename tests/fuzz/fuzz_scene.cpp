// SPDX-License-Identifier: MIT
// libFuzzer target: the scene parser and validator on arbitrary bytes plus overrides.
// Build and run: tools/fuzz.sh [seconds]   (clang, -DVKCLOTH_FUZZ=ON; see docs/errors.md)
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vkcloth::fuzz::run_scene_input(data, size);
  return 0;
}
