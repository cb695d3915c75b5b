# SPDX-License-Identifier: MIT
# cmake -DSPV=in.spv -DOUT=out.hpp -DNAME=symbol -P embed_spirv.cmake
# Writes a C++ header holding the SPIR-V words as `inline constexpr std::uint32_t NAME[]`.
file(READ "${SPV}" hex HEX)
string(LENGTH "${hex}" len)
math(EXPR rem "${len} % 8")
if(len EQUAL 0 OR NOT rem EQUAL 0)
  message(FATAL_ERROR "${SPV}: not a SPIR-V word stream (${len} hex digits)")
endif()
# Little-endian bytes -> 32-bit words.
string(REGEX REPLACE "([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])"
       "0x\\4\\3\\2\\1u,\n" words "${hex}")
file(WRITE "${OUT}.tmp"
"// Generated from ${SPV} by shaders/embed_spirv.cmake. Do not edit.\n#pragma once\n#include <cstdint>\n\n"
"namespace vkcloth::gpu::spirv {\ninline constexpr std::uint32_t ${NAME}[] = {\n${words}};\n} // namespace vkcloth::gpu::spirv\n")
file(RENAME "${OUT}.tmp" "${OUT}")
