#!/usr/bin/env bash
# Cost of one constraint Jacobian of the tracking problem on jw_fullbody (issue #5): structured
# finite differences (the default) against the dense central-difference baseline of Lin, Walter &
# Pandy 2018, in path (model) evaluations and wall time, side by side in one run (alternating
# repeats, medians; tests/bench/bench_jacobian.c). Both modes at the small node counts; at LARGE_N
# only the structured one is run (the dense one would take ~10 min): its count is 2 n N exactly,
# its wall time is extrapolated from the dense wall per path evaluation at the largest small N.
# Last line: evals_ratio=<dense/structured at LARGE_N> wall_ratio=<same, wall, extrapolated>.
#   scripts/bench_jacobian.sh [repeats] [threads] [LARGE_N] [SMALL_N...]   default: 5 2 80 4 8
# Build folder: $GAITSIM_BUILD_DIR (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${GAITSIM_BUILD_DIR:-build}
export OPENBLAS_NUM_THREADS=1
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target bench_jacobian >/dev/null
echo "nproc=$(nproc) load=$(cut -d' ' -f1-3 /proc/loadavg)"
"$build"/bench_jacobian mjmodels/jw_fullbody.xml mjmodels/trials/jw_ngait_og5 "$@"
