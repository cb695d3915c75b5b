#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Frames per second of `vkcloth render --frames` (PNG sequence) and `vkcloth view` (under xvfb-run)
# with --backend vulkan (the GPU solver, drawn from its buffers) and --backend auto (on lavapipe:
# the CPU solver, uploaded each frame), alternated, on the hanging cloth at 64 x 64 and 256 x 256,
# 1 and 8 steps per frame (view's default for its dt of 0.02 s is 1), 800 x 600 (docs/performance.md
# "Backend auto"). Startup (device, pipelines, window) is left out: a frame costs
# (t(N frames) - t(1 frame)) / (N - 1); the median of REPS runs.
# Usage: tools/backend_fps.sh [REPS (default 5)] [BUILD_DIR (default build/release)]
set -euo pipefail
cd "$(dirname "$0")/.."
reps=${1:-5}
bin=${2:-build/release}/tools/vkcloth/vkcloth
scene=samples/scenes/cloth_hanging.json
command -v xvfb-run >/dev/null || { echo "needs xvfb-run (apt-get install xvfb xauth)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ms() { # milliseconds the command takes
  local t0
  t0=$(date +%s%N)
  "$@" >/dev/null 2>"$tmp/err" || { cat "$tmp/err" >&2; exit 1; }
  echo $((($(date +%s%N) - t0) / 1000000))
}
render_n=61 view_n=241
for rep in $(seq "$reps"); do
  for n in 64 256; do
    m=$((n - 1))
    sets=(--set "cloth.resolution=[$n,$n]" --set "cloth.pins=[[0,$m],[$m,$m]]" --size 800x600)
    for k in 1 8; do
      for backend in vulkan auto; do
        rm -rf "$tmp/f"
        r1=$(ms "$bin" render $scene "${sets[@]}" --steps 0 --frames "$tmp/f" --backend $backend)
        rm -rf "$tmp/f"
        rn=$(ms "$bin" render $scene "${sets[@]}" --steps $(((render_n - 1) * k)) --every $k --frames "$tmp/f" \
          --backend $backend)
        v1=$(ms xvfb-run -a "$bin" view $scene "${sets[@]}" --frames 1 --steps-per-frame $k --backend $backend)
        vn=$(ms xvfb-run -a "$bin" view $scene "${sets[@]}" --frames $view_n --steps-per-frame $k --backend $backend)
        echo "render $n $k $backend $(((rn - r1) * 1000 / (render_n - 1)))" >>"$tmp/rows"
        echo "view $n $k $backend $(((vn - v1) * 1000 / (view_n - 1)))" >>"$tmp/rows"
        echo "rep $rep: n=$n k=$k $backend: render ${r1}/${rn} ms, view ${v1}/${vn} ms (1 / N frames)" >&2
      done
    done
  done
done
# Median microseconds per frame -> frames per second.
echo "| command | n x n | steps / frame | --backend vulkan (fps) | --backend auto (fps) | auto / vulkan |"
echo "|---|---|---|---|---|---|"
for cmd in render view; do
  for n in 64 256; do
    for k in 1 8; do
      med() { awk -v c=$cmd -v n=$n -v k=$k -v b="$1" '$1 == c && $2 == n && $3 == k && $4 == b { print $5 }' \
        "$tmp/rows" | sort -n | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
      gv=$(med vulkan) ga=$(med auto)
      awk -v c=$cmd -v n=$n -v k=$k -v gv="$gv" -v ga="$ga" \
        'BEGIN { printf "| %s | %d | %d | %.1f | %.1f | %.2fx |\n", c, n, k, 1e6 / gv, 1e6 / ga, gv / ga }'
    done
  done
done
