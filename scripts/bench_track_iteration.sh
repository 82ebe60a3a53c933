#!/usr/bin/env bash
# Wall time per Ipopt iteration of the tracking problem on jw_fullbody at several node counts
# (issue #5 targets linear growth in N): `gaitsim track --max-iter I --no-polish --threads 2` at
# each N, and the per-iteration time from the progress lines' wall column, (wall of iteration I -
# wall of iteration 1) / (I - 1), so set-up (problem build, guess, Ipopt's initialisation and
# iteration 0) is left out. The solve itself does not converge yet (mjmodels/README.md: right-leg
# tendon slack lengths); this measures the cost of an iteration, not of a solve. About 25 s
# with the defaults on the 2-core machine (2026-12-01: N = 160 at ~2 s per iteration).
#   scripts/bench_track_iteration.sh [iterations] [nodes...]     default: 4 iterations, 40 80 160
# Build folder: $GAITSIM_BUILD_DIR (default build).
# Last line: per_iter_s_N40=... per_iter_s_N80=... per_iter_s_N160=...
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=1
build=${GAITSIM_BUILD_DIR:-build}
iters=${1:-4}; shift || true
((iters >= 2)) || { echo "bench_track_iteration.sh: iterations must be >= 2" >&2; exit 2; }
nodes=("$@"); ((${#nodes[@]})) || nodes=(40 80 160)
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target gaitsim >/dev/null
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
echo "nproc=$(nproc) load=$(cut -d' ' -f1-3 /proc/loadavg)"
summary=""
for n in "${nodes[@]}"; do
  t0=$(date +%s.%N)
  # exit status 3: stopped at the iteration limit (expected)
  "$build"/gaitsim track mjmodels/trials/jw_ngait_og5 --out "$out/n$n" --nodes "$n" --threads 2 \
    --max-iter "$iters" --no-polish --refine 0 >"$out/stdout$n" 2>"$out/log$n" || [ $? -eq 3 ] ||
    { echo "bench_track_iteration.sh: N=$n: gaitsim track failed:" >&2; tail -5 "$out/log$n" >&2; exit 1; }
  t1=$(date +%s.%N)
  # wall column at iteration 1 and at the last iteration printed (restoration lines: "4r")
  read -r first last it < <(awk '/^iter/ { it = $2 + 0; for (i = 1; i <= NF; i++) if ($i == "wall") t = $(i + 1);
                                    if (it == 1) w1 = t; if (it >= 1) { wl = t; il = it } }
                              END { print w1, wl, il }' "$out/log$n")
  if [ -z "${it:-}" ] || ((it < 2)); then
    echo "bench_track_iteration.sh: N=$n: fewer than 2 iterations in the progress lines" >&2; exit 1
  fi
  per=$(awk -v a="$first" -v b="$last" -v k="$it" 'BEGIN { printf "%.3f", (b - a) / (k - 1) }')
  echo "N=$n: $(grep -m1 '^track:' "$out/log$n" | cut -d, -f1-3); iterations 1-$it: wall $first -> $last s," \
       "$per s per iteration; whole command $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }') s"
  summary+="per_iter_s_N$n=$per "
done
echo "${summary% }"
