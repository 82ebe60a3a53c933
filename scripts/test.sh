#!/usr/bin/env bash
# The whole test suite: warnings-as-errors build + every test (ctest), the unit tests and a subset
# of the command-line tests again under AddressSanitizer/UndefinedBehaviorSanitizer, and the fuzz
# targets for a bounded time (clang; scripts/fuzz.sh runs them longer).
#   scripts/test.sh            everything
#   scripts/test.sh --quick    the warnings-as-errors build and its tests only
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=1
jobs=$(nproc)

scripts/setup.sh --deps-only

echo "== build (warnings are errors) and all tests"
cmake -S . -B build-test -DCMAKE_BUILD_TYPE=Release -DGAITSIM_WERROR=ON >/dev/null
cmake --build build-test -j"$jobs"
(cd build-test && ctest --output-on-failure -j"$jobs" -LE fuzz)
if [ -f build-test/slurm_skipped.txt ]; then  # the Slurm test (label slurm) exits 77 when it cannot
  echo "=============================================================================="
  echo "== $(cat build-test/slurm_skipped.txt)"
  echo "== (ctest -L slurm; the rest of the suite ran)"
  echo "=============================================================================="
fi
[ "${1:-}" = "--quick" ] && exit 0

echo "== unit tests under AddressSanitizer and UndefinedBehaviorSanitizer"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DGAITSIM_WERROR=ON -DGAITSIM_SANITIZE=ON >/dev/null
cmake --build build-asan -j"$jobs"
(cd build-asan && ASAN_OPTIONS=detect_leaks=1 ctest --output-on-failure -j"$jobs" -L unit)

# the command-line tests whose commands do not solve the full-body model (the catalogue of bad
# input, signals and disk full among them): about 50 s; the others and the slow tests (full-body
# and planar solves of minutes) take too long under the sanitizers' Debug build
echo "== command-line tests under AddressSanitizer and UndefinedBehaviorSanitizer (a subset)"
(cd build-asan && LSAN_OPTIONS=suppressions="$PWD/../tests/lsan.supp" ASAN_OPTIONS=detect_leaks=1 \
  ctest --output-on-failure -j"$jobs" \
  -R '^cli_(bad_inputs|model_errors|simulate_inspect|hold_drop|render|predict_goals|work)$')

echo "== fuzz targets (clang, libFuzzer, bounded time)"
CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Debug -DGAITSIM_FUZZ=ON >/dev/null
cmake --build build-fuzz -j"$jobs" --target fuzz_storage fuzz_solution fuzz_options
(cd build-fuzz && ctest --output-on-failure -L fuzz)
