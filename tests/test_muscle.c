// test_muscle.c: Hill-type muscle-tendon unit (callbacks/gs_muscle.h): every analytic partial
// against central finite differences over each curve's range, curve properties (values at the
// anchor points, sign, continuity, monotonicity), the one-muscle isometric bench, the forward
// solve (its fT_dot zeroes the residual), the static initialisation, the user-row parser.
//
// Derivative criterion: |analytic - fd| <= RTOL max(|fd|, FLOOR), RTOL = 1e-6, FLOOR = 1e-2,
// i.e. relative error 1e-6 with an absolute floor of 1e-8 (derivative units). The reference fd
// is the central difference with step h = cbrt(eps) max(1, |x|), Richardson-extrapolated over h
// and h/2 (error O(h^4) + ~eps/h). Plain central differences carry a truncation error
// h^2/6 |f'''| that alone exceeds the 1e-8 floor where the curves are steep (fPE and fT at their
// upper ends, derivatives in lMT with lopt ~ 5 cm: h/lopt ~ 1e-4); their largest deviation is
// printed as a note, not asserted.
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "callbacks/gs_model_layout.h"
#include "callbacks/gs_muscle.h"
#include "tests/gs_test.h"

#define RTOL 1e-6
#define FLOOR 1e-2

static double fd_step(double x) {
  return cbrt(DBL_EPSILON) * (fabs(x) > 1.0 ? fabs(x) : 1.0);
}

// largest plain-central-difference deviation seen (note only)
static double plain_fd_worst = 0.0;
static const char* plain_fd_where = "";

// a scalar function of one variable with context
typedef double (*scalarFn)(const void* ctx, double x);

// Richardson-extrapolated central difference; records the plain one's deviation from it
static double fd_derivative(scalarFn f, const void* ctx, double x, const char* what) {
  double h = fd_step(x);
  double d1 = (f(ctx, x + h) - f(ctx, x - h)) / (2.0 * h);
  double d2 = (f(ctx, x + 0.5 * h) - f(ctx, x - 0.5 * h)) / h;
  double d = (4.0 * d2 - d1) / 3.0;
  double dev = fabs(d1 - d) / fmax(fabs(d), FLOOR);
  if (dev > plain_fd_worst) {
    plain_fd_worst = dev;
    plain_fd_where = what;
  }
  return d;
}

// compare; print the first few failures of a family with index, expected, actual
static int check_partial(const char* what, int index, double x, double fd, double analytic,
                         int* printed) {
  if (fabs(analytic - fd) <= RTOL * fmax(fabs(fd), FLOOR)) {
    return 0;
  }
  if ((*printed)++ < 5) {
    fprintf(stderr, "  %s[%d] at x = %.9g: fd %.12g, analytic %.12g, rel %.3g\n", what, index, x,
            fd, analytic, fabs(analytic - fd) / fmax(fabs(fd), FLOOR));
  }
  return 1;
}

// --- curves ---------------------------------------------------------------------------------
typedef double (*curveFn)(double, double*);
typedef struct curveCtx_ {
  curveFn f;
} curveCtx;
static double curve_value(const void* ctx, double x) {
  return ((const curveCtx*)ctx)->f(x, NULL);
}

typedef struct tendonCtx_ {
  double kT;
  int inverse;
} tendonCtx;
static double tendon_value(const void* ctx, double x) {
  const tendonCtx* t = ctx;
  return t->inverse ? gs_muscle_ft_inverse(x, t->kT, NULL) : gs_muscle_ft(x, t->kT, NULL);
}

static void check_curve(const char* what, curveFn f, double lo, double hi, int n) {
  curveCtx ctx = {f};
  int bad = 0, printed = 0;
  for (int i = 0; i < n; i++) {
    double x = lo + (hi - lo) * i / (n - 1), d;
    f(x, &d);
    bad += check_partial(what, i, x, fd_derivative(curve_value, &ctx, x, what), d, &printed);
  }
  if (bad) {
    fprintf(stderr, "  %s: %d of %d points failed\n", what, bad, n);
  }
  EXPECT_EQ_INT(0, bad);
}

static void curve_partials_should_match_finite_differences(void) {
  check_curve("fL", gs_muscle_fl_active, 0.2, 1.8, 3201);
  check_curve("fV", gs_muscle_fv, -1.0, 1.0, 2001);
  check_curve("fV_wide", gs_muscle_fv, -3.0, 3.0, 601);
  check_curve("fV_inverse", gs_muscle_fv_inverse, gs_muscle_fv(-1.0, NULL),
              gs_muscle_fv(1.0, NULL), 2001);
  check_curve("fPE", gs_muscle_fl_passive, 0.2, 1.8, 3201);

  // tendon, kT = 35 (default) and a compliant 20 and stiff 50
  {
    const double kts[3] = {35.0, 20.0, 50.0};
    for (int k = 0; k < 3; k++) {
      for (int inv = 0; inv < 2; inv++) {
        tendonCtx t = {kts[k], inv};
        int bad = 0, printed = 0, n = 1601;
        const char* what = inv ? "fT_inverse" : "fT";
        for (int i = 0; i < n; i++) {
          double x = inv ? 1.5 * i / (n - 1) : 0.98 + 0.08 * i / (n - 1), d;
          tendon_value(&t, x);
          if (inv) {
            gs_muscle_ft_inverse(x, t.kT, &d);
          } else {
            gs_muscle_ft(x, t.kT, &d);
          }
          bad += check_partial(what, i, x, fd_derivative(tendon_value, &t, x, what), d, &printed);
        }
        EXPECT_EQ_INT(0, bad);
      }
    }
  }
}

// --- muscles used below ---------------------------------------------------------------------
typedef struct namedMuscle_ {
  const char* name;
  gsMuscleParams p;
} namedMuscle;

// Fmax N, lopt m, lts m, alpha0 rad, vmax lopt/s, kT, damping, elastic (OpenSim gait2392-like)
static const namedMuscle kMuscles[] = {
    {"soleus", {3549.0, 0.050, 0.250, 0.4363, 10.0, 35.0, 0.01, 1}},
    {"vastus_lateralis", {1871.0, 0.084, 0.157, 0.0873, 10.0, 35.0, 0.01, 1}},
    {"unpennate", {1000.0, 0.100, 0.200, 0.0, 10.0, 35.0, 0.01, 1}},
    {"undamped", {1500.0, 0.060, 0.300, 0.2, 10.0, 20.0, 0.0, 1}},
    {"iliacus_rigid", {1073.0, 0.100, 0.090, 0.1222, 10.0, 35.0, 0.01, 0}},
};
#define NMUSCLE ((int)(sizeof kMuscles / sizeof kMuscles[0]))

static double urand(double lo, double hi) {
  return lo + (hi - lo) * ((double)rand() / RAND_MAX);
}

// lMT (m) that puts the fibre at lM_norm with the tendon at fT (elastic) or slack (rigid)
static double lmt_for(const gsMuscleParams* p, double lM_norm, double fT) {
  double h = p->lopt * sin(p->pennation);
  double lM = lM_norm * p->lopt;
  double lT = p->elastic ? p->lts * gs_muscle_ft_inverse(fT, p->kT, NULL) : p->lts;
  return lT + sqrt(fmax(lM * lM - h * h, 0.0));
}

// --- fibre geometry -------------------------------------------------------------------------
typedef struct geomCtx_ {
  const gsMuscleParams* p;
  double lT;
  int want_cos;
} geomCtx;
static double geom_value(const void* ctx, double lMT) {
  const geomCtx* g = ctx;
  double c;
  double lM = gs_muscle_fibre_length(g->p, lMT, g->lT, &c, NULL);
  return g->want_cos ? c : lM;
}

static void fibre_geometry_partials_should_match_finite_differences(void) {
  int bad = 0, printed = 0;
  for (int m = 0; m < NMUSCLE; m++) {
    const gsMuscleParams* p = &kMuscles[m].p;
    for (int i = 0; i < 400; i++) {
      double l = 0.2 + 1.6 * i / 399.0;
      double lMT = lmt_for(p, l, 0.5), c, dc;
      geomCtx g0 = {p, p->lts, 0}, g1 = {p, p->lts, 1};
      gs_muscle_fibre_length(p, lMT, p->lts, &c, &dc);
      bad += check_partial("dlM/dlMT", i, lMT, fd_derivative(geom_value, &g0, lMT, "lM"), c,
                           &printed);
      bad += check_partial("dcos/dlMT", i, lMT, fd_derivative(geom_value, &g1, lMT, "cos"), dc,
                           &printed);
      // constant thickness: lM sin(alpha) = h (floored), lM cos(alpha) = lMT - lT
      EXPECT_NEAR(lMT - p->lts, gs_muscle_fibre_length(p, lMT, p->lts, NULL, NULL) * c, 1e-15);
    }
  }
  EXPECT_EQ_INT(0, bad);
}

// --- elastic residual -----------------------------------------------------------------------
typedef struct resCtx_ {
  const gsMuscleParams* p;
  double x[5];  // a, lMT, vMT, fT, fT_dot
  int k;        // which one varies
} resCtx;
static double res_value(const void* ctx, double v) {
  const resCtx* r = ctx;
  double x[5];
  for (int j = 0; j < 5; j++) {
    x[j] = r->x[j];
  }
  x[r->k] = v;
  return gs_muscle_equilibrium_residual(r->p, x[0], x[1], x[2], x[3], x[4], NULL, NULL);
}

static double rigid_value(const void* ctx, double v) {
  const resCtx* r = ctx;
  double x[3] = {r->x[0], r->x[1], r->x[2]};
  x[r->k] = v;
  return gs_muscle_rigid_force(r->p, x[0], x[1], x[2], NULL, NULL);
}

// random elastic state: a in [0,1], lM_norm in [0.2,1.8] (above the thickness), fT in [0,1.5],
// fT_dot in [-5,5] 1/s, vMT in [-1,1] vmax lopt
static void random_state(const gsMuscleParams* p, double x[5]) {
  double lmin = fmax(0.2, 1.05 * sin(p->pennation));
  x[0] = urand(0.0, 1.0);
  x[3] = urand(0.0, 1.5);
  x[1] = lmt_for(p, urand(lmin, 1.8), x[3]);
  x[2] = urand(-1.0, 1.0) * p->vmax * p->lopt;
  x[4] = urand(-5.0, 5.0);
}

static void residual_partials_should_match_finite_differences(void) {
  static const char* names[5] = {"dr/da", "dr/dlMT", "dr/dvMT", "dr/dfT", "dr/dfT_dot"};
  int bad = 0, printed = 0, n = 0;
  srand(12345);
  for (int m = 0; m < NMUSCLE; m++) {
    const gsMuscleParams* p = &kMuscles[m].p;
    if (!p->elastic) {
      continue;
    }
    for (int i = 0; i < 1000; i++) {
      resCtx ctx = {p, {0}, 0};
      gsMuscleGrad g;
      double an[5];
      random_state(p, ctx.x);
      // include the activation bounds and the isometric, static points
      if (i % 10 == 0) {
        ctx.x[0] = (i / 10) % 2 ? 1.0 : 0.0;
      }
      if (i % 7 == 0) {
        ctx.x[2] = 0.0;
        ctx.x[4] = 0.0;
      }
      gs_muscle_equilibrium_residual(p, ctx.x[0], ctx.x[1], ctx.x[2], ctx.x[3], ctx.x[4], &g,
                                     NULL);
      an[0] = g.a;
      an[1] = g.lMT;
      an[2] = g.vMT;
      an[3] = g.fT;
      an[4] = g.fT_dot;
      for (int k = 0; k < 5; k++) {
        ctx.k = k;
        bad += check_partial(names[k], i, ctx.x[k],
                             fd_derivative(res_value, &ctx, ctx.x[k], names[k]), an[k],
                             &printed);
        n++;
      }
    }
  }
  if (bad) {
    fprintf(stderr, "  residual partials: %d of %d failed\n", bad, n);
  }
  EXPECT_EQ_INT(0, bad);
}

static void rigid_partials_should_match_finite_differences(void) {
  static const char* names[3] = {"dF/da", "dF/dlMT", "dF/dvMT"};
  int bad = 0, printed = 0;
  srand(777);
  for (int m = 0; m < NMUSCLE; m++) {
    gsMuscleParams p = kMuscles[m].p;
    p.elastic = 0;
    for (int i = 0; i < 1000; i++) {
      resCtx ctx = {&p, {0}, 0};
      gsMuscleGrad g;
      double an[3];
      double lmin = fmax(0.2, 1.05 * sin(p.pennation));
      ctx.x[0] = urand(0.0, 1.0);
      ctx.x[1] = lmt_for(&p, urand(lmin, 1.8), 0.0);
      ctx.x[2] = urand(-1.0, 1.0) * p.vmax * p.lopt;
      gs_muscle_rigid_force(&p, ctx.x[0], ctx.x[1], ctx.x[2], &g, NULL);
      an[0] = g.a;
      an[1] = g.lMT;
      an[2] = g.vMT;
      EXPECT_NEAR(0.0, g.fT + g.fT_dot, 0.0);
      for (int k = 0; k < 3; k++) {
        ctx.k = k;
        // F is in N (up to ~1e4): compare relative to Fmax, i.e. on F / Fmax
        double fd = fd_derivative(rigid_value, &ctx, ctx.x[k], names[k]) / p.fmax;
        bad += check_partial(names[k], i, ctx.x[k], fd, an[k] / p.fmax, &printed);
      }
    }
  }
  EXPECT_EQ_INT(0, bad);
}

// --- curve properties -----------------------------------------------------------------------
static void curves_should_have_their_published_properties(void) {
  double fl1 = gs_muscle_fl_active(1.0, NULL);
  double lpk = 0.0, fpk = 0.0, d;
  printf("fL(1) = %.6f, fV(0) = %.12f, fV(-1) = %.3g, fV(1) = %.4f, fPE(1.6) = %.6f, "
         "fT(1) = %.5f, fPE_min = %.5f\n",
         fl1, gs_muscle_fv(0.0, NULL), gs_muscle_fv(-1.0, NULL), gs_muscle_fv(1.0, NULL),
         gs_muscle_fl_passive(1.6, NULL), gs_muscle_ft(1.0, 35.0, NULL),
         gs_muscle_fl_passive_min());

  // fL: fL(1) = 0.99933 with the paper's three-decimal constants; peak near 1
  EXPECT_NEAR(1.0, fl1, 1e-3);
  EXPECT_NEAR(0.99933, fl1, 1e-5);
  for (int i = 0; i <= 16000; i++) {
    double l = 0.2 + 1.6 * i / 16000.0, f = gs_muscle_fl_active(l, NULL);
    if (f > fpk) {
      fpk = f;
      lpk = l;
    }
    EXPECT_TRUE(f > 0.0 && f < 1.01);
  }
  printf("fL peak %.5f at lM_norm = %.4f\n", fpk, lpk);
  EXPECT_TRUE(lpk > 0.95 && lpk < 1.05);
  // increasing on [0.45, peak], decreasing on [peak, 1.8] (the third, wide Gaussian gives a
  // shallow shoulder below 0.45, still increasing)
  for (int i = 0; i < 2000; i++) {
    double l = 0.2 + 1.6 * i / 1999.0;
    gs_muscle_fl_active(l, &d);
    if (l < lpk - 1e-3) {
      EXPECT_TRUE(d > 0.0);
    } else if (l > lpk + 1e-3) {
      EXPECT_TRUE(d < 0.0);
    }
  }

  // fV: fV(0) = 1, fV(-1) = 0 with the refitted d1, d4; increasing; d1, d4 reproduce
  EXPECT_NEAR(1.0, gs_muscle_fv(0.0, NULL), 1e-14);
  EXPECT_NEAR(0.0, gs_muscle_fv(-1.0, NULL), 1e-14);
  EXPECT_NEAR(1.0 / (asinh(GS_MUSCLE_D3) - asinh(GS_MUSCLE_D3 - GS_MUSCLE_D2)), GS_MUSCLE_D1,
              1e-14);
  EXPECT_NEAR(1.0 - GS_MUSCLE_D1 * asinh(GS_MUSCLE_D3), GS_MUSCLE_D4, 1e-14);
  // the paper's rounded pair is within 0.4 % of these
  EXPECT_NEAR(-0.318, GS_MUSCLE_D1, 0.004);
  EXPECT_NEAR(0.886, GS_MUSCLE_D4, 0.004);
  for (int i = 0; i <= 2000; i++) {
    double v = -1.5 + 3.0 * i / 2000.0, f = gs_muscle_fv(v, &d);
    EXPECT_TRUE(d > 0.0);
    // round trip through the inverse
    EXPECT_NEAR(v, gs_muscle_fv_inverse(f, NULL), 1e-12);
  }

  // fPE: De Groote's p = (exp(kPE (l - 1) / e0) - 1) / (exp(kPE) - 1) above optimal length,
  // zero below, joined by the smooth max (p + sqrt(p^2 + w^2)) / 2: w / 2 = 5e-4 at 1, 1 at
  // 1 + e0 within w^2 / 4, never negative (the published p goes down to -0.01863), within 3e-5
  // of zero below 0.9 lopt, within w^2 / (4 p) of p above 1.1; increasing
  EXPECT_NEAR(0.5 * GS_MUSCLE_PASSIVE_WIDTH, gs_muscle_fl_passive(1.0, NULL), 1e-16);
  EXPECT_NEAR(1.0, gs_muscle_fl_passive(1.0 + GS_MUSCLE_E0, NULL), 3e-7);
  EXPECT_NEAR(1.3407e-5, gs_muscle_fl_passive_min(), 1e-9);
  for (int i = 0; i <= 2000; i++) {
    double l = 1.8 * i / 2000.0, f = gs_muscle_fl_passive(l, &d);
    double p = (exp(4.0 * (l - 1.0) / 0.6) - 1.0) / (exp(4.0) - 1.0);
    EXPECT_TRUE(d > 0.0);
    EXPECT_TRUE(f > 0.0 && f >= gs_muscle_fl_passive_min());
    if (l <= 0.9) {
      EXPECT_TRUE(f < 3e-5);
    } else if (l >= 1.1) {
      EXPECT_NEAR(p, f, 1e-6 / (4.0 * p));
    }
  }

  // fT: fT(1) = c1 exp(kT (1 - c2)) - c3 = -0.0118 (not 0: De Groote's c2 = 0.995, c3 = 0.25),
  // fT = 1 at 1 + ln(6.25)/kT - 0.005 = 1.0474; increasing; inverse round trip
  EXPECT_NEAR(0.2 * exp(35.0 * 0.005) - 0.25, gs_muscle_ft(1.0, 35.0, NULL), 1e-15);
  EXPECT_NEAR(-0.01175, gs_muscle_ft(1.0, 35.0, NULL), 1e-5);
  EXPECT_NEAR(1.0474, gs_muscle_ft_inverse(1.0, 35.0, NULL), 1e-4);
  for (int i = 0; i <= 2000; i++) {
    double l = 0.98 + 0.08 * i / 2000.0, f = gs_muscle_ft(l, 35.0, &d);
    EXPECT_TRUE(d > 0.0);
    EXPECT_NEAR(l, gs_muscle_ft_inverse(f, 35.0, NULL), 1e-13);
  }

  // continuity: on a 1e-5 grid no step exceeds the largest slope times the spacing (+1 %)
  {
    const curveFn fs[4] = {gs_muscle_fl_active, gs_muscle_fv, gs_muscle_fl_passive,
                           gs_muscle_fv_inverse};
    const double lo[4] = {0.2, -1.0, 0.2, 0.0}, hi[4] = {1.8, 1.0, 1.8, 1.79};
    for (int c = 0; c < 4; c++) {
      double dmax = 0.0, jump = 0.0, step = 1e-5;
      int n = (int)((hi[c] - lo[c]) / step);
      for (int i = 0; i <= n; i++) {
        fs[c](lo[c] + step * i, &d);
        dmax = fmax(dmax, fabs(d));
      }
      for (int i = 0; i < n; i++) {
        double x = lo[c] + step * i;
        jump = fmax(jump, fabs(fs[c](x + step, NULL) - fs[c](x, NULL)));
      }
      EXPECT_TRUE(jump <= 1.01 * dmax * step + 1e-15);
    }
  }
}

// --- one-muscle bench -----------------------------------------------------------------------
static void isometric_force_at_optimum_should_be_fmax(void) {
  gsMuscleParams p = {1000.0, 0.100, 0.200, 0.0, 10.0, 35.0, 0.01, 1};
  gsMuscleOut out;
  double fT, F;

  // elastic: lMT = lopt + lts fT^-1(1); solve the static equilibrium for fT
  double lMT = p.lopt + p.lts * gs_muscle_ft_inverse(1.0, p.kT, NULL);
  EXPECT_EQ_INT(0, gs_muscle_equilibrium_fT(&p, 1.0, lMT, &fT, &out));
  printf("bench elastic: fT = %.6f, force = %.3f N, lM_norm = %.6f, alpha = %.2e rad\n", fT,
         out.force, out.lM_norm, out.alpha);
  EXPECT_NEAR(p.fmax, out.force, 0.01 * p.fmax);
  EXPECT_NEAR(1.0, out.lM_norm, 1e-3);
  EXPECT_NEAR(0.0, gs_muscle_equilibrium_residual(&p, 1.0, lMT, 0.0, fT, 0.0, NULL, NULL),
              1e-12);

  // rigid: lMT = lopt + lts, vMT = 0
  p.elastic = 0;
  p.lts = 0.05;
  F = gs_muscle_rigid_force(&p, 1.0, p.lopt + p.lts, 0.0, NULL, &out);
  printf("bench rigid: F = %.3f N, lM_norm = %.9f\n", F, out.lM_norm);
  EXPECT_NEAR(p.fmax, F, 0.01 * p.fmax);
  EXPECT_NEAR(F, out.force, 0.0);
  EXPECT_NEAR(F, (out.f_active + out.f_passive + out.f_damping) * out.cos_alpha, 1e-9);
}

// --- forward simulation ---------------------------------------------------------------------
static void forward_fT_dot_should_zero_the_residual(void) {
  int bad = 0, n = 0, n_clamped = 0;
  double worst = 0.0;
  srand(4242);
  for (int m = 0; m < NMUSCLE; m++) {
    const gsMuscleParams* p = &kMuscles[m].p;
    if (!p->elastic) {
      continue;
    }
    for (int i = 0; i < 2000; i++) {
      double x[5], fdot, r;
      gsMuscleOut out;
      int status;
      random_state(p, x);
      if (i % 10 == 0) {
        x[0] = (i / 10) % 3 == 0 ? 0.0 : GS_MUSCLE_DAMPING_DEFAULT * 1e-3;  // a fL ~ 0
      }
      status = gs_muscle_elastic_fT_dot(p, x[0], x[1], x[2], x[3], &fdot, &out);
      r = gs_muscle_equilibrium_residual(p, x[0], x[1], x[2], x[3], fdot, NULL, NULL);
      // without damping the root may lie beyond |vM_norm| = 1e4 (a fL ~ 0, or fT far from
      // a fL): then the solve must say so (status 1) and stop at the limit
      if (p->damping == 0.0 && status == 1) {
        EXPECT_NEAR(GS_MUSCLE_VNORM_LIMIT, fabs(out.vM_norm), 1e-6 * GS_MUSCLE_VNORM_LIMIT);
        n_clamped++;
        continue;
      }
      n++;
      if (status != 0 || !(fabs(r) < 1e-10)) {
        if (bad++ < 5) {
          fprintf(stderr, "  %s[%d]: status %d, r = %.3g (a %g, lMT %g, vMT %g, fT %g)\n",
                  kMuscles[m].name, i, status, r, x[0], x[1], x[2], x[3]);
        }
      }
      worst = fmax(worst, fabs(r));
    }
  }
  printf("forward: %d states solved, max |r| = %.3g; %d undamped states beyond the limit\n", n,
         worst, n_clamped);
  EXPECT_EQ_INT(0, bad);

  // the undamped (beta = 0) analytic inverse at a state with a fL > 0
  {
    gsMuscleParams p = kMuscles[3].p;
    double fdot, lMT = lmt_for(&p, 1.1, 0.6);
    EXPECT_NEAR(0.0, p.damping, 0.0);
    EXPECT_EQ_INT(0, gs_muscle_elastic_fT_dot(&p, 0.7, lMT, 0.1, 0.6, &fdot, NULL));
    EXPECT_NEAR(0.0, gs_muscle_equilibrium_residual(&p, 0.7, lMT, 0.1, 0.6, fdot, NULL, NULL),
                1e-10);
  }
}

// static initialisation: zero residual at vMT = 0, fT_dot = 0 across activations and lengths
static void static_equilibrium_should_zero_the_residual(void) {
  int bad = 0;
  srand(99);
  for (int m = 0; m < NMUSCLE; m++) {
    const gsMuscleParams* p = &kMuscles[m].p;
    if (!p->elastic) {
      continue;
    }
    for (int i = 0; i < 300; i++) {
      double a = i % 5 == 0 ? 0.0 : urand(0.0, 1.0);
      double lMT = lmt_for(p, urand(fmax(0.4, 1.05 * sin(p->pennation)), 1.6), urand(0.0, 1.0));
      double fT, r;
      int status = gs_muscle_equilibrium_fT(p, a, lMT, &fT, NULL);
      r = gs_muscle_equilibrium_residual(p, a, lMT, 0.0, fT, 0.0, NULL, NULL);
      if (status != 0 || !(fabs(r) < 1e-10)) {
        if (bad++ < 5) {
          fprintf(stderr, "  %s: status %d, r = %.3g at a %g, lMT %g\n", kMuscles[m].name,
                  status, r, a, lMT);
        }
      }
    }
  }
  EXPECT_EQ_INT(0, bad);
}

// --- user row -------------------------------------------------------------------------------
static void params_should_come_from_the_user_row(void) {
  double user[GS_ACT_NUSER] = {0};
  gsMuscleParams p;
  char err[128] = "";
  user[GS_ACT_FMAX] = 3549.0;
  user[GS_ACT_LOPT] = 0.05;
  user[GS_ACT_LTS] = 0.25;
  user[GS_ACT_PENNATION] = 0.4363;
  user[GS_ACT_VMAX] = 10.0;
  user[GS_ACT_ELASTIC_TENDON] = 1.0;
  user[GS_ACT_TENDON_KT] = 0.0;
  EXPECT_EQ_INT(0, gs_muscle_params_from_user(user, &p, err, sizeof err));
  EXPECT_NEAR(3549.0, p.fmax, 0.0);
  EXPECT_NEAR(0.05, p.lopt, 0.0);
  EXPECT_NEAR(0.25, p.lts, 0.0);
  EXPECT_NEAR(0.4363, p.pennation, 0.0);
  EXPECT_NEAR(10.0, p.vmax, 0.0);
  EXPECT_NEAR(GS_MUSCLE_KT_DEFAULT, p.kT, 0.0);
  EXPECT_NEAR(GS_MUSCLE_DAMPING_DEFAULT, p.damping, 0.0);
  EXPECT_EQ_INT(1, p.elastic);
  user[GS_ACT_TENDON_KT] = 20.0;
  user[GS_ACT_ELASTIC_TENDON] = 0.0;
  EXPECT_EQ_INT(0, gs_muscle_params_from_user(user, &p, NULL, 0));
  EXPECT_NEAR(20.0, p.kT, 0.0);
  EXPECT_EQ_INT(0, p.elastic);
  user[GS_ACT_LOPT] = 0.0;
  EXPECT_EQ_INT(-1, gs_muscle_params_from_user(user, &p, err, sizeof err));
  EXPECT_TRUE(err[0] != '\0');
  user[GS_ACT_LOPT] = 0.05;
  user[GS_ACT_PENNATION] = 2.0;
  EXPECT_EQ_INT(-1, gs_muscle_params_from_user(user, &p, NULL, 0));
  user[GS_ACT_PENNATION] = 0.1;
  user[GS_ACT_FMAX] = NAN;
  EXPECT_EQ_INT(-1, gs_muscle_params_from_user(user, &p, NULL, 0));
}

int main(void) {
  curve_partials_should_match_finite_differences();
  fibre_geometry_partials_should_match_finite_differences();
  residual_partials_should_match_finite_differences();
  rigid_partials_should_match_finite_differences();
  printf("note: plain central differences deviate from the extrapolated ones by up to %.3g "
         "(relative, floor %.0e) at %s\n",
         plain_fd_worst, FLOOR, plain_fd_where);
  curves_should_have_their_published_properties();
  isometric_force_at_optimum_should_be_fmax();
  forward_fT_dot_should_zero_the_residual();
  static_equilibrium_should_zero_the_residual();
  params_should_come_from_the_user_row();
  return GS_TEST_RESULT();
}
