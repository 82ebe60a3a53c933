#!/usr/bin/env bash
# Cost of one surrogate knee-contact evaluation against one elastic-foundation evaluation on JW's
# refined implant surfaces, side by side in one run (medians over repeats), then the cost of the
# whole knee hook of mjcb_passive (gs_knee_passive: surrogate contact + 68 ligament bundles) in
# the full model mjmodels/jw_fullbody_knee6.xml, with the model cached by gs_physics_prepare and
# looked up by name on every call (an unregistered copy of the model).
# Lines: passive_us=... passive_by_name_us=...; last line: surrogate_us=...
# elastic_foundation_us=... speedup=...
#   scripts/bench_knee.sh [repeats] [build dir, default build]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${2:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target bench_knee bench_knee_passive >/dev/null

"$build"/bench_knee_passive mjmodels/jw_fullbody_knee6.xml "${1:-21}"
"$build"/bench_knee tests/fixtures/knee6.xml mjmodels/knee/jw_knee_heldout.csv \
  mjmodels/knee/jw_knee_ef_mesh.txt "${1:-21}"
