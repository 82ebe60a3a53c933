#!/usr/bin/env bash
# Cost of one surrogate knee-contact evaluation against one elastic-foundation evaluation on JW's
# refined implant surfaces, side by side in one run (medians over repeats).
# Last line: surrogate_us=... elastic_foundation_us=... speedup=...
#   scripts/bench_knee.sh [repeats] [build dir, default build]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${2:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target bench_knee >/dev/null
"$build"/bench_knee tests/fixtures/knee6.xml mjmodels/knee/jw_knee_heldout.csv \
  mjmodels/knee/jw_knee_ef_mesh.txt "${1:-21}"
