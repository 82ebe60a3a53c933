#!/usr/bin/env bash
# Run every fuzz target (tests/fuzz.cmake: fuzz_storage, fuzz_solution, fuzz_options; libFuzzer
# with AddressSanitizer and UndefinedBehaviorSanitizer, clang) for SECONDS each, one after the
# other on one core, each continuing its corpus in build-fuzz/tests/<target>_work/corpus from
# the seeds in tests/fuzz/. Prints each target's final statistics (its whole output in
# build-fuzz/tests/<target>_work/log.txt); exits non-zero when one finds a crash (the input is
# saved in build-fuzz/tests/<target>_work/artifacts/).
#   scripts/fuzz.sh SECONDS            e.g. scripts/fuzz.sh 600
# scripts/test.sh runs the same targets for 30 s each (ctest -L fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-}
if ! [[ $seconds =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: scripts/fuzz.sh SECONDS (a whole number > 0)" >&2
  exit 2
fi
export OPENBLAS_NUM_THREADS=1
CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Debug -DGAITSIM_FUZZ=ON >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_storage fuzz_solution fuzz_options
status=0
for target in fuzz_storage fuzz_solution fuzz_options; do
  work=build-fuzz/tests/${target}_work
  seeds=tests/fuzz/corpus_${target}
  extra=(-close_fd_mask=2)
  if [ "$target" = fuzz_storage ]; then seeds=tests/fuzz/corpus_storage extra=(-dict=tests/fuzz/storage.dict); fi
  mkdir -p "$work/corpus" "$work/artifacts"
  echo "== $target, $seconds s (log: $work/log.txt)"
  set +e
  LSAN_OPTIONS=suppressions="$PWD/tests/lsan.supp" "build-fuzz/tests/$target" \
    -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=8192 \
    -print_final_stats=1 "${extra[@]}" -artifact_prefix="$work/artifacts/" \
    "$work/corpus" "$seeds" >"$work/log.txt" 2>&1
  rc=$?
  set -e
  grep -E '^(stat::|SUMMARY|==[0-9]+==ERROR)' "$work/log.txt" || true
  if [ "$rc" -ne 0 ]; then
    echo "$target: FAILED, exit $rc (input in $work/artifacts/)" >&2
    status=1
  fi
done
exit $status
