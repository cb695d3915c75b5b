#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian packages vkcloth needs. Idempotent; prints nothing when all is present.
# Usage: tools/setup.sh [fuzz] [format] [validator]   (any of them: fuzz: also clang and its
#        libFuzzer runtime, for tools/fuzz.sh; format: clang-format, for tools/format.sh; validator:
#        node and the Khronos glTF validator pinned in tools/gltf-validator/, installed into
#        build/npm, for the export tests)
# One install at a time (a lock in $TMPDIR): .ci/run installs the extras in the background while
# tools/test.sh builds, and a second setup.sh that has something to install waits for the first.
set -euo pipefail
packages=(
  cmake ninja-build g++ pkg-config
  libvulkan-dev libvulkan-volk-dev glslang-tools glslang-dev spirv-tools
  libglm-dev doctest-dev nlohmann-json3-dev libfmt-dev libcli11-dev
  mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  libglfw3-dev libstb-dev xvfb xauth
  libtinyobjloader-dev libtinygltf-dev libmeshoptimizer-dev python3
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib # the Python module, its tests and examples
)
validator=false
for extra in "$@"; do
  case $extra in
    fuzz) packages+=(clang-16 libclang-rt-16-dev llvm-16) ;; # llvm-16: the sanitizers' symbolizer
    format) packages+=(clang-format) ;;
    validator) validator=true ;;
    *) echo "setup: unknown extra '$extra' (fuzz, format, validator)" >&2; exit 2 ;;
  esac
done
missing_packages() {
  missing=()
  local all=("${packages[@]}")
  $validator && ! command -v npm >/dev/null && all+=(nodejs npm)
  for p in "${all[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
}
missing_packages
((${#missing[@]} == 0)) && ! $validator && exit 0
exec 9>"${TMPDIR:-/tmp}/vkcloth-setup.lock"
flock 9
missing_packages # again: another setup.sh may have installed them while this one waited
if ((${#missing[@]} > 0)); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""; [[ $(id -u) -ne 0 ]] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    -o DPkg::Lock::Timeout=300 "${missing[@]}" >/dev/null
fi
! $validator || "$(dirname "$0")/gltf-validator/install.sh"
