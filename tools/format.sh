#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Formats the C++ sources (and the header shared with GLSL) with the repository's .clang-format.
# Usage: tools/format.sh          rewrite the files in place
#        tools/format.sh --check  change nothing; list the files that differ and exit 1 if any
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh format
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.inl')
if [[ ${1:-} == --check ]]; then
  bad=()
  for f in "${files[@]}"; do
    clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
  done
  if ((${#bad[@]})); then
    echo "format: ${#bad[@]} file(s) differ from .clang-format (run tools/format.sh):" >&2
    printf '  %s\n' "${bad[@]}" >&2
    exit 1
  fi
  echo "format: ${#files[@]} files follow .clang-format" >&2
else
  clang-format -i "${files[@]}"
fi
