#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian packages vkcloth needs. Idempotent; prints nothing when all is present.
# Usage: tools/setup.sh [fuzz|format|validator]   (fuzz: also clang and its libFuzzer runtime, for
#        tools/fuzz.sh; format: clang-format, for tools/format.sh; validator: node and the Khronos glTF
#        validator pinned in tools/gltf-validator/, installed into build/npm, for the export tests)
set -euo pipefail
packages=(
  cmake ninja-build g++ pkg-config
  libvulkan-dev libvulkan-volk-dev glslang-tools glslang-dev spirv-tools
  libglm-dev doctest-dev nlohmann-json3-dev libfmt-dev libcli11-dev
  mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  libglfw3-dev libstb-dev xvfb xauth
  libtinyobjloader-dev libtinygltf-dev libmeshoptimizer-dev python3
)
[[ ${1:-} == fuzz ]] && packages+=(clang libclang-rt-14-dev)
[[ ${1:-} == format ]] && packages+=(clang-format)
[[ ${1:-} == validator ]] && ! command -v npm >/dev/null && packages+=(nodejs npm)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} > 0)); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""; [[ $(id -u) -ne 0 ]] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
[[ ${1:-} == validator ]] && "$(dirname "$0")/gltf-validator/install.sh"
exit 0
