#!/usr/bin/env bash
# Rendering speed of `gaitsim render` at 1280x720, default (fast) quality (bone meshes, sky
# backdrop, checker floor, planar shadows with the bundled model), side camera, overlay:
# the fixture solution, 2 cycles at 60 fps (133 frames) into an H.264 mp4 through ffmpeg,
# REPEATS times. Each run's frames/s is what the command reports: frames / wall time of the
# render loop, which includes rendering (OSMesa llvmpipe), pixel read-back and the ffmpeg encode
# (ffmpeg runs alongside and is waited for); model loading and context creation (< 0.5 s) are
# excluded. Last line: fps=<median>.
#   scripts/bench_render.sh [REPEATS] [SOLUTION_DIR]
# Build folder: $GAITSIM_BUILD_DIR (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${GAITSIM_BUILD_DIR:-build}
repeats=${1:-5}
solution=${2:-tests/fixtures/solution_small}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target gaitsim >/dev/null
command -v ffmpeg >/dev/null || { echo "bench_render.sh: ffmpeg not installed" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fps=()
for i in $(seq "$repeats"); do
  out=$("$build/gaitsim" render "$solution" --out "$work/bench.mp4" --size 1280x720 --fps 60 \
    --cycles 2)
  f=$(sed -n 's/^render: .* s, \([0-9.]*\) frames\/s$/\1/p' <<<"$out")
  frames=$(sed -n 's/^render: wrote .*: \([0-9]*\) frames,.*/\1/p' <<<"$out")
  echo "run $i: $frames frames at 1280x720, $f frames/s"
  fps+=("$f")
done
median=$(printf '%s\n' "${fps[@]}" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}')
echo "nproc=$(nproc) load=$(cut -d' ' -f1-3 /proc/loadavg)"
echo "fps=$median"
