// gs_test.h: the assertions every gaitsim test program uses.
//
// A test program is a plain C main() under CTest. Each failed check prints file:line, the
// expression, expected and actual, and counts as a failure; main returns GS_TEST_RESULT(), which
// prints "N passed, N failed" and is non-zero when anything failed.
#ifndef GAITSIM_TESTS_GS_TEST_H_
#define GAITSIM_TESTS_GS_TEST_H_

#include <math.h>
#include <stdio.h>

static int gs_test_passed_ = 0;
static int gs_test_failed_ = 0;

// true, else report
#define EXPECT_TRUE(cond)                                                          \
  do {                                                                             \
    if (cond) {                                                                    \
      gs_test_passed_++;                                                           \
    } else {                                                                       \
      gs_test_failed_++;                                                           \
      fprintf(stderr, "%s:%d: FAILED: %s\n", __FILE__, __LINE__, #cond);           \
    }                                                                              \
  } while (0)

// |actual - expected| <= tol
#define EXPECT_NEAR(expected, actual, tol)                                         \
  do {                                                                             \
    double e_ = (double)(expected), a_ = (double)(actual), t_ = (double)(tol);      \
    if (fabs(a_ - e_) <= t_) {                                                     \
      gs_test_passed_++;                                                           \
    } else {                                                                       \
      gs_test_failed_++;                                                           \
      fprintf(stderr, "%s:%d: FAILED: %s: expected %.10g, actual %.10g, tol %.3g\n", \
              __FILE__, __LINE__, #actual, e_, a_, t_);                            \
    }                                                                              \
  } while (0)

// relative error |a - e| / max(|e|, floor) <= rtol, for derivative checks
#define EXPECT_REL(expected, actual, rtol, floor)                                  \
  do {                                                                             \
    double e_ = (double)(expected), a_ = (double)(actual);                         \
    double d_ = fabs(e_) > (floor) ? fabs(e_) : (floor);                           \
    if (fabs(a_ - e_) / d_ <= (rtol)) {                                            \
      gs_test_passed_++;                                                           \
    } else {                                                                       \
      gs_test_failed_++;                                                           \
      fprintf(stderr, "%s:%d: FAILED: %s: expected %.12g, actual %.12g, rel %.3g > %.3g\n", \
              __FILE__, __LINE__, #actual, e_, a_, fabs(a_ - e_) / d_, (double)(rtol)); \
    }                                                                              \
  } while (0)

#define EXPECT_EQ_INT(expected, actual)                                            \
  do {                                                                             \
    long e_ = (long)(expected), a_ = (long)(actual);                               \
    if (e_ == a_) {                                                                \
      gs_test_passed_++;                                                           \
    } else {                                                                       \
      gs_test_failed_++;                                                           \
      fprintf(stderr, "%s:%d: FAILED: %s: expected %ld, actual %ld\n", __FILE__,    \
              __LINE__, #actual, e_, a_);                                          \
    }                                                                              \
  } while (0)

// print the totals; exit status for main
#define GS_TEST_RESULT()                                                           \
  (printf("%d passed, %d failed\n", gs_test_passed_, gs_test_failed_),             \
   (gs_test_failed_ > 0 || gs_test_passed_ == 0) ? 1 : 0)

#endif  // GAITSIM_TESTS_GS_TEST_H_
