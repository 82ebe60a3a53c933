// test_solve.c: the solve strategy's rule for using a feasibility polish's point
// (go_solve_polish_usable, optim/go_solve.h). Expected, with GO_POLISH_MAX_RISE = 0.10 and
// GO_POLISH_GUARD_VIOL = 1e-2:
//   - the polishes measured on the 80-node solves are used: a tracking solve's (violation 3.5e-5
//     -> 1e-9, J 2.33891 -> 2.34039, +0.06 %) and a prediction's (1.2e-4 -> 1e-9, J 2.87560 ->
//     2.93386, +2.0 %);
//   - the wandered one is not: jw_bouncy7's polish that hit its iteration limit in the
//     restoration phase (8.94e-4 -> 2.6e-5, J 2.05298 -> 81.3092);
//   - the bound is inclusive at +10 % and exclusive just above (J 2 -> 2.2 used, 2.2 + 1e-9 not),
//     relative to |J| for a negative objective (-2 -> -1.8 used, -1.79 not);
//   - a point no less violated, or with a NaN objective, is not used; a lower J always is;
//   - from a point farther than 1e-2 from feasibility the objective does not decide: the
//     projections of cli_bad_inputs' planar solve stopped by SIGINT mid-way are used (violation
//     0.615 -> below, J 49.24 -> 65.99, +34 %; 0.0654, J 19.13 -> 22.51), and so is one with a
//     NaN objective; just inside the guard (1e-2) the rise decides again.
#include <math.h>

#include "optim/go_defaults.h"
#include "optim/go_solve.h"
#include "tests/gs_test.h"

static void measured_polishes_should_be_used(void) {
  EXPECT_EQ_INT(1, go_solve_polish_usable(3.5e-5, 2.33891, 1e-9, 2.34039));
  EXPECT_EQ_INT(1, go_solve_polish_usable(1.2e-4, 2.87560, 1e-9, 2.93386));
}

static void a_wandered_polish_should_not_be_used(void) {
  EXPECT_EQ_INT(0, go_solve_polish_usable(8.94e-4, 2.05298, 2.6e-5, 81.3092));
}

static void the_bound_should_be_the_relative_rise(void) {
  EXPECT_NEAR(0.10, GO_POLISH_MAX_RISE, 0.0);
  EXPECT_EQ_INT(1, go_solve_polish_usable(1e-3, 2.0, 1e-9, 2.0 * (1 + GO_POLISH_MAX_RISE)));
  EXPECT_EQ_INT(0, go_solve_polish_usable(1e-3, 2.0, 1e-9, 2.0 * (1 + GO_POLISH_MAX_RISE) + 1e-9));
  EXPECT_EQ_INT(1, go_solve_polish_usable(1e-3, -2.0, 1e-9, -1.8));
  EXPECT_EQ_INT(0, go_solve_polish_usable(1e-3, -2.0, 1e-9, -1.79));
}

static void violation_and_nan_should_decide(void) {
  EXPECT_EQ_INT(0, go_solve_polish_usable(1e-3, 2.0, 1e-3, 2.0));   // no less violated
  EXPECT_EQ_INT(0, go_solve_polish_usable(1e-3, 2.0, 2e-3, 1.0));   // more violated
  EXPECT_EQ_INT(0, go_solve_polish_usable(1e-3, 2.0, 1e-9, NAN));
  EXPECT_EQ_INT(1, go_solve_polish_usable(1e-3, 2.0, 1e-9, 0.5));   // lower J
}

static void far_points_should_be_projected_whatever_their_objective(void) {
  EXPECT_NEAR(1e-2, GO_POLISH_GUARD_VIOL, 0.0);
  EXPECT_EQ_INT(1, go_solve_polish_usable(0.615, 49.24, 1e-3, 65.99));
  EXPECT_EQ_INT(1, go_solve_polish_usable(0.0654, 19.13, 1e-3, 22.51));
  EXPECT_EQ_INT(1, go_solve_polish_usable(0.0654, 19.13, 1e-3, NAN));
  EXPECT_EQ_INT(0, go_solve_polish_usable(0.0654, 19.13, 0.07, 19.13));  // more violated
  EXPECT_EQ_INT(0, go_solve_polish_usable(1e-2, 19.13, 1e-3, 22.51));    // within the guard
}

int main(void) {
  measured_polishes_should_be_used();
  a_wandered_polish_should_not_be_used();
  the_bound_should_be_the_relative_rise();
  violation_and_nan_should_decide();
  far_points_should_be_projected_whatever_their_objective();
  return GS_TEST_RESULT();
}
