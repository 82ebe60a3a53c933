#!/usr/bin/env bash
# Cost of one mj_forward with gaitsim's physics against MuJoCo's native muscles and contacts, on
# the same model, side by side in one run (medians). Last line: ratio=<gaitsim/native>.
#   scripts/bench_physics.sh [MODEL] [repeats]
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-mjmodels/jw_fullbody.xml}
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target bench_forward >/dev/null
build/bench_forward "$model" "${2:-21}"
