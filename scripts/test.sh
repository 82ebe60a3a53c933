#!/usr/bin/env bash
# The whole test suite: warnings-as-errors build + every test (ctest), the unit tests again under
# AddressSanitizer/UndefinedBehaviorSanitizer, and the fuzz targets for a bounded time (clang).
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

echo "== fuzz targets (clang, libFuzzer, bounded time)"
CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Debug -DGAITSIM_FUZZ=ON >/dev/null
cmake --build build-fuzz -j"$jobs" --target fuzz_storage
(cd build-fuzz && ctest --output-on-failure -L fuzz)
