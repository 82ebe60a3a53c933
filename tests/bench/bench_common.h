// bench_common.h: the clock and the median every benchmark program (tests/bench/*.c, run by
// scripts/bench_*.sh) reports its timings with.
#ifndef GAITSIM_TESTS_BENCH_BENCH_COMMON_H_
#define GAITSIM_TESTS_BENCH_BENCH_COMMON_H_

#include <stdlib.h>
#include <time.h>

// monotonic wall clock (s)
static inline double bench_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline int bench_cmp_double(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

// median of v (n >= 1; sorts v): the middle value, or the mean of the two middle ones
static inline double bench_median(double* v, int n) {
  qsort(v, (size_t)n, sizeof(double), bench_cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

#endif  // GAITSIM_TESTS_BENCH_BENCH_COMMON_H_
