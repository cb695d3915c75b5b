// SPDX-License-Identifier: MIT
// libFuzzer targets for the mesh readers on arbitrary bytes: this file is built three times, with
// VKCLOTH_FUZZ_MESH_FORMAT = obj (vkcloth_fuzz_obj), gltf (vkcloth_fuzz_gltf) or glb
// (vkcloth_fuzz_glb). Build and run: tools/fuzz.sh [seconds]   (clang, -DVKCLOTH_FUZZ=ON)
#include "fuzz_mesh_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vkcloth::fuzz::run_mesh_input(vkcloth::fuzz::MeshFormat::VKCLOTH_FUZZ_MESH_FORMAT, data, size);
  return 0;
}
