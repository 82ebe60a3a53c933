// test_activation.c: activation dynamics (callbacks/gs_activation.h): analytic partials against
// central finite differences, zero rate at u = a, time constants, invariance of the bounds.
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "callbacks/gs_activation.h"
#include "callbacks/gs_model_layout.h"
#include "tests/gs_test.h"

// derivative checks: |analytic - fd| <= max(RTOL |fd|, RTOL FLOOR) = max(1e-6 |fd|, 1e-8)
#define RTOL 1e-6
#define FLOOR 1e-2

// central-difference step cbrt(eps) max(1, |x|)
static double fd_step(double x) {
  return cbrt(DBL_EPSILON) * (fabs(x) > 1.0 ? fabs(x) : 1.0);
}

// every analytic partial on a dense (u, a) grid including the switch line u = a, and the point
// u = a + tiny on both sides, with default and user time constants
static void partials_should_match_central_differences(void) {
  gsActivationParams p;
  const int n = 101;
  int bad = 0;
  gs_activation_params_default(&p);
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < n; j++) {
      double u = (double)i / (n - 1), a = (double)j / (n - 1);
      double du, da, hu = fd_step(u), ha = fd_step(a);
      double fu, fa;
      gs_activation_dot(&p, u, a, &du, &da);
      fu = (gs_activation_dot(&p, u + hu, a, NULL, NULL) -
            gs_activation_dot(&p, u - hu, a, NULL, NULL)) / (2.0 * hu);
      fa = (gs_activation_dot(&p, u, a + ha, NULL, NULL) -
            gs_activation_dot(&p, u, a - ha, NULL, NULL)) / (2.0 * ha);
      // FD error here ~ h^2/6 |d3/dx3| + eps |da/dt| / h; the tanh switch (b = 10) and 1/(0.5+1.5a)
      // keep the third derivative below ~1e6 1/s, i.e. an error ~4e-6 on values ~1e2..1e3 1/s
      if (fabs(du - fu) > RTOL * fmax(fabs(fu), FLOOR) ||
          fabs(da - fa) > RTOL * fmax(fabs(fa), FLOOR)) {
        if (bad < 5) {
          fprintf(stderr, "  (u, a) = (%g, %g): d/du %.12g vs fd %.12g, d/da %.12g vs fd %.12g\n",
                  u, a, du, fu, da, fa);
        }
        bad++;
      }
    }
  }
  EXPECT_EQ_INT(0, bad);

  // on the switch line: u = a exactly, where f = 1/2 and df/du is largest
  for (int j = 0; j < n; j++) {
    double a = GS_ACTIVATION_MIN + (GS_ACTIVATION_MAX - GS_ACTIVATION_MIN) * j / (n - 1);
    double du, da, h = fd_step(a);
    double fu = (gs_activation_dot(&p, a + h, a, NULL, NULL) -
                 gs_activation_dot(&p, a - h, a, NULL, NULL)) / (2.0 * h);
    double fa = (gs_activation_dot(&p, a, a + h, NULL, NULL) -
                 gs_activation_dot(&p, a, a - h, NULL, NULL)) / (2.0 * h);
    gs_activation_dot(&p, a, a, &du, &da);
    EXPECT_REL(fu, du, RTOL, FLOOR);
    EXPECT_REL(fa, da, RTOL, FLOOR);
    // at u = a: d/du = K = -d/da
    EXPECT_REL(du, -da, 1e-14, 1.0);
  }
}

// da/dt = 0 at u = a, positive above, negative below
static void rate_should_vanish_at_u_equal_a(void) {
  gsActivationParams p;
  gs_activation_params_default(&p);
  for (int j = 0; j <= 100; j++) {
    double a = GS_ACTIVATION_MIN + (GS_ACTIVATION_MAX - GS_ACTIVATION_MIN) * j / 100.0;
    EXPECT_NEAR(0.0, gs_activation_dot(&p, a, a, NULL, NULL), 0.0);
    if (a < GS_ACTIVATION_MAX) {
      EXPECT_TRUE(gs_activation_dot(&p, fmin(a + 1e-3, 1.0), a, NULL, NULL) > 0.0);
    }
    if (a > GS_ACTIVATION_MIN) {
      EXPECT_TRUE(gs_activation_dot(&p, a - 1e-4, a, NULL, NULL) < 0.0);
    }
  }
}

// initial slopes: rise from a = 0.001 with u = 1 is (1 - a) / (tau_a (0.5 + 1.5 a)) (f = 1 - 2e-9);
// decay from a = 1 (and from a = 0.5) with u = 0 is -a (0.5 + 1.5 a) / tau_d
static void time_constants_should_be_tau_a_and_tau_d(void) {
  gsActivationParams p;
  double a, expect;
  gs_activation_params_default(&p);
  EXPECT_NEAR(0.010, p.tau_act, 0.0);
  EXPECT_NEAR(0.040, p.tau_deact, 0.0);

  a = GS_ACTIVATION_MIN;
  expect = (1.0 - a) / (p.tau_act * (0.5 + 1.5 * a));
  EXPECT_REL(expect, gs_activation_dot(&p, 1.0, a, NULL, NULL), 1e-7, 1.0);
  // effective time constant at a -> 0 is 0.5 tau_a = 5 ms: slope 0.999 / 5.015 ms = 199.2 1/s
  EXPECT_NEAR(199.2, gs_activation_dot(&p, 1.0, a, NULL, NULL), 0.1);

  a = 1.0;
  expect = -a * (0.5 + 1.5 * a) / p.tau_deact;
  EXPECT_REL(expect, gs_activation_dot(&p, 0.0, a, NULL, NULL), 1e-7, 1.0);
  // at a = 0.5 the switch is not complete: f = 0.5 + 0.5 tanh(-5) = 4.5e-5 mixes in the
  // activation rate, a relative change of f (ka/kd - 1) = 7.1e-5
  a = 0.5;
  expect = -a * (0.5 + 1.5 * a) / p.tau_deact;
  EXPECT_REL(expect, gs_activation_dot(&p, 0.0, a, NULL, NULL), 1e-4, 1.0);

  // integrated: explicit Euler, 0.01 ms steps; a step up from a = 0.001 passes 63 % of the way in
  // between 0.5 tau_a and 2 tau_a, a step down from 1 falls to 37 % between 0.5 tau_d and 2 tau_d
  {
    double dt = 1e-5, t = 0.0;
    a = GS_ACTIVATION_MIN;
    while (a < GS_ACTIVATION_MIN + 0.632 * (1.0 - GS_ACTIVATION_MIN) && t < 1.0) {
      a += dt * gs_activation_dot(&p, 1.0, a, NULL, NULL);
      t += dt;
    }
    printf("rise to 63%%: %.2f ms (tau_a = %.0f ms)\n", 1e3 * t, 1e3 * p.tau_act);
    EXPECT_TRUE(t > 0.5 * p.tau_act && t < 2.0 * p.tau_act);
    t = 0.0;
    a = 1.0;
    while (a > 0.368 && t < 1.0) {
      a += dt * gs_activation_dot(&p, 0.0, a, NULL, NULL);
      t += dt;
    }
    printf("decay to 37%%: %.2f ms (tau_d = %.0f ms)\n", 1e3 * t, 1e3 * p.tau_deact);
    EXPECT_TRUE(t > 0.5 * p.tau_deact && t < 2.0 * p.tau_deact);
  }
}

// [MIN, MAX] is invariant: at a = MIN the rate is >= 0 and at a = MAX <= 0 for u in the bounds
static void bounds_should_be_invariant(void) {
  gsActivationParams p;
  gs_activation_params_default(&p);
  EXPECT_NEAR(0.001, GS_ACTIVATION_MIN, 0.0);
  EXPECT_NEAR(1.0, GS_ACTIVATION_MAX, 0.0);
  for (int i = 0; i <= 100; i++) {
    double u = GS_ACTIVATION_MIN + (GS_ACTIVATION_MAX - GS_ACTIVATION_MIN) * i / 100.0;
    EXPECT_TRUE(gs_activation_dot(&p, u, GS_ACTIVATION_MIN, NULL, NULL) >= 0.0);
    EXPECT_TRUE(gs_activation_dot(&p, u, GS_ACTIVATION_MAX, NULL, NULL) <= 0.0);
  }
}

// user row: time constants read from their slots; non-positive ones rejected with a reason
static void params_should_come_from_the_user_row(void) {
  double user[GS_ACT_NUSER] = {0};
  gsActivationParams p;
  char err[128] = "";
  user[GS_ACT_TAU_ACT] = 0.015;
  user[GS_ACT_TAU_DEACT] = 0.060;
  EXPECT_EQ_INT(0, gs_activation_params_from_user(user, &p, err, sizeof err));
  EXPECT_NEAR(0.015, p.tau_act, 0.0);
  EXPECT_NEAR(0.060, p.tau_deact, 0.0);
  EXPECT_NEAR(GS_ACTIVATION_SMOOTHING, p.b, 0.0);
  user[GS_ACT_TAU_DEACT] = 0.0;
  EXPECT_EQ_INT(-1, gs_activation_params_from_user(user, &p, err, sizeof err));
  EXPECT_TRUE(err[0] != '\0');
  user[GS_ACT_TAU_DEACT] = NAN;
  EXPECT_EQ_INT(-1, gs_activation_params_from_user(user, &p, NULL, 0));
}

int main(void) {
  partials_should_match_central_differences();
  rate_should_vanish_at_u_equal_a();
  time_constants_should_be_tau_a_and_tau_d();
  bounds_should_be_invariant();
  params_should_come_from_the_user_row();
  return GS_TEST_RESULT();
}
