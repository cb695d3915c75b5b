#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the glTF validator pinned by package-lock.json beside this script into build/npm (npm ci:
# exactly the locked version). Idempotent; prints nothing when that version is already there.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
prefix=$(cd "$here/../.." && pwd)/build/npm
want=$(node -e 'console.log(require(process.argv[1]).packages["node_modules/gltf-validator"].version)' \
  "$here/package-lock.json")
have=$(node -e 'try { console.log(require(process.argv[1]).version) } catch { }' \
  "$prefix/node_modules/gltf-validator/package.json")
[[ $have == "$want" ]] && exit 0
echo "setup: installing gltf-validator $want into $prefix" >&2
mkdir -p "$prefix"
cp "$here/package.json" "$here/package-lock.json" "$prefix/"
npm ci --prefix "$prefix" --no-audit --no-fund --loglevel=error >/dev/null
