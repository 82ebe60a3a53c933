#!/usr/bin/env bash
# Wall time per Ipopt iteration of the tracking problem on jw_fullbody at several node counts
# (2 threads): a few iterations each, median of the per-iteration times taken from the progress
# lines. The solve itself does not converge yet (mjmodels/README.md: right-leg tendon slack
# lengths); this measures the cost of an iteration, not of a solve.
#   scripts/bench_track_iteration.sh [iterations] [nodes...]      default: 6 iterations, 20 40 80
# Last line: per_iter_s_N20=... per_iter_s_N40=... per_iter_s_N80=...
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=1
iters=${1:-6}; shift || true
nodes=("$@"); ((${#nodes[@]})) || nodes=(20 40 80)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target gaitsim >/dev/null
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
summary=""
for n in "${nodes[@]}"; do
  build/gaitsim track mjmodels/trials/jw_ngait_og5 --out "$out/n$n" --nodes "$n" --threads 2 \
    --max-iter "$iters" 2>"$out/log$n" || [ $? -eq 3 ]
  med=$(awk '/^iter/ { for (i = 1; i <= NF; i++) if ($i == "wall") t = $(i + 1);
                       if (have) print t - prev; prev = t; have = 1 }' "$out/log$n" |
        sort -g | awk '{ d[n++] = $1 } END { print (n % 2) ? d[(n - 1) / 2] : (d[n / 2 - 1] + d[n / 2]) / 2 }')
  echo "N=$n: $(grep -m1 '^track:' "$out/log$n" | cut -d, -f1-3); median $med s per iteration over $iters iterations"
  summary+="per_iter_s_N$n=$med "
done
echo "${summary% }"
