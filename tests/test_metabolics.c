// test_metabolics.c: Umberger 2010 muscle energetics, exact and smooth (callbacks/gs_metabolics.h).
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "callbacks/gs_metabolics.h"
#include "callbacks/gs_model_layout.h"
#include "tests/gs_test.h"

// muscle 1: m 0.5 kg, fST 0.5, lopt 0.1 m, vmax 10 lopt/s
//   h_AM = 128 * 0.5 + 25 = 89 W/kg; vmaxST = 10 / 2.5 = 4 lopt/s; aST = 100 / 4 = 25;
//   aFT = 153 / 10 = 15.3 (W/kg per lopt/s)
static const gsUmbergerMuscle kMuscle1 = {0.5, 0.5, 0.1, 10.0};
// muscle 2: m 1.2 kg, fST 0.2, lopt 0.05 m, vmax 12 lopt/s
//   h_AM = 128 * 0.8 + 25 = 127.4 W/kg; vmaxST = 12 / 2.5 = 4.8; aST = 100 / 4.8; aFT = 153 / 12
static const gsUmbergerMuscle kMuscle2 = {1.2, 0.2, 0.05, 12.0};

// one row of the hand-computed table
typedef struct row_ {
  const char* what;          // branches covered
  const gsUmbergerMuscle* mus;
  gsUmbergerInput in;        // u, a, lM~, vM (m/s), F_CE (N), fL
  double scale_a;            // expected A (-)
  double am, sl, work, heat; // expected terms (W/kg)
  double power;              // expected Edot (W)
} row;

static row table[7];

static void fill_table(void) {
  // 1: u > a, shortening below the ST cap, lM~ < 1, positive work
  //   A = u = 0.6; AM = 1.5 * 0.6^0.6 * 89 = 98.2589267
  //   v~ = -0.2 / 0.1 = -2; ST term -25 * -2 = 50 (< 100)
  //   SL = 1.5 * 0.6^2 * (0.5 * 50 + 0.5 * 15.3 * 2) = 1.5 * 0.36 * 40.3 = 21.762
  //   W = 400 * 0.2 / 0.5 = 160; heat = 120.0209267; Edot = (heat + 160) * 0.5 = 140.0104633 W
  table[0] = (row){"u>a, shortening, l<1, W>0", &kMuscle1, {0.6, 0.4, 0.9, -0.2, 400.0, 0.95},
                   0.6, 1.5 * pow(0.6, 0.6) * 89.0, 1.5 * 0.36 * 40.3, 160.0, 0.0, 0.0};
  // 2: u < a, lengthening, lM~ > 1 (fL 0.8), negative work excluded
  //   A = (0.2 + 0.5) / 2 = 0.35; AM = 1.5 * 0.35^0.6 * 89 * (0.4 + 0.6 * 0.8) = ... * 0.88
  //   v~ = 0.3 / 0.1 = 3; SL = 1.5 * 0.35 * (0.3 * 25 * 3) * 0.8 = 1.5 * 0.35 * 22.5 * 0.8 = 9.45
  //   W = 0; heat = 62.5755628 + 9.45 = 72.0255628; Edot = 36.0127814 W
  table[1] = (row){"u<a, lengthening, l>1, W excluded", &kMuscle1,
                   {0.2, 0.5, 1.2, 0.3, 400.0, 0.8},
                   0.35, 1.5 * pow(0.35, 0.6) * 89.0 * 0.88, 9.45, 0.0, 0.0, 0.0};
  // 3: minimum heat: u = a = 1e-4 -> A = 1e-4 (else branch)
  //   AM = 1.5 * 1e-4^0.6 * 89 = 0.5314731; v~ = -0.5: SL = 1.5 * 1e-8 * (0.5 * 12.5 + 0.5 * 15.3
  //   * 0.5) = 1.5e-8 * 10.075 = 1.51125e-7; AM + SL = 0.53 < 1 -> heat = 1
  //   W = 2 * 0.05 / 0.5 = 0.2; Edot = (1 + 0.2) * 0.5 = 0.6 W
  table[2] = (row){"minimum heat", &kMuscle1, {1e-4, 1e-4, 0.9, -0.05, 2.0, 0.95},
                   1e-4, 1.5 * pow(1e-4, 0.6) * 89.0, 1.5e-8 * 10.075, 0.2, 1.0, 0.0};
  // 4: u == a (else branch, A = 1), fast shortening above the ST cap, lM~ > 1 (fL 0.9)
  //   AM = 1.5 * 1 * 89 * (0.4 + 0.6 * 0.9) = 1.5 * 89 * 0.94 = 125.49
  //   v~ = -6; ST term 25 * 6 = 150 -> capped at 100
  //   SL = 1.5 * 1 * (0.5 * 100 + 0.5 * 15.3 * 6) * 0.9 = 1.5 * 95.9 * 0.9 = 129.465
  //   W = 300 * 0.6 / 0.5 = 360; heat = 254.955; Edot = (254.955 + 360) * 0.5 = 307.4775 W
  table[3] = (row){"u=a, ST cap, shortening, l>1", &kMuscle1, {1.0, 1.0, 1.1, -0.6, 300.0, 0.9},
                   1.0, 125.49, 129.465, 360.0, 254.955, 307.4775};
  // 5: u < a, shortening, lM~ < 1
  //   A = (0.1 + 0.3) / 2 = 0.2; AM = 1.5 * 0.2^0.6 * 89 = 50.8275602
  //   v~ = -1: SL = 1.5 * 0.04 * (0.5 * 25 + 0.5 * 15.3) = 1.5 * 0.04 * 20.15 = 1.209
  //   W = 150 * 0.1 / 0.5 = 30; Edot = (50.8275602 + 1.209 + 30) * 0.5 = 41.0182801 W
  table[4] = (row){"u<a, shortening, l<1", &kMuscle1, {0.1, 0.3, 0.8, -0.1, 150.0, 0.7},
                   0.2, 1.5 * pow(0.2, 0.6) * 89.0, 1.209, 30.0, 0.0, 0.0};
  // 6: u > a, lengthening, lM~ < 1, negative work excluded
  //   A = 0.8; AM = 1.5 * 0.8^0.6 * 89 = 116.7710695
  //   v~ = 1.5: SL = 1.5 * 0.8 * 0.3 * 25 * 1.5 = 1.5 * 0.8 * 11.25 = 13.5; W = 0
  //   Edot = (116.7710695 + 13.5) * 0.5 = 65.1355347 W
  table[5] = (row){"u>a, lengthening, l<1", &kMuscle1, {0.8, 0.5, 0.95, 0.15, 500.0, 0.99},
                   0.8, 1.5 * pow(0.8, 0.6) * 89.0, 13.5, 0.0, 0.0, 0.0};
  // 7: muscle 2 (fST 0.2), u == a = 0.5 -> A = 0.5, lM~ = 1 exactly (<= 1 branch), negative
  //   active force clamped to 0 -> W = 0
  //   AM = 1.5 * 0.5^0.6 * 127.4 = 126.0789809
  //   v~ = -0.1 / 0.05 = -2: ST term (100 / 4.8) * 2 = 41.6667; FT term (153 / 12) * 2 = 25.5
  //   SL = 1.5 * 0.25 * (0.2 * 41.6667 + 0.8 * 25.5) = 1.5 * 0.25 * 28.7333 = 10.775
  //   Edot = (126.0789809 + 10.775) * 1.2 = 164.2247770 W
  table[6] = (row){"fST 0.2, l=1, F<0 clamped", &kMuscle2, {0.5, 0.5, 1.0, -0.1, -5.0, 1.0},
                   0.5, 1.5 * pow(0.5, 0.6) * 127.4,
                   1.5 * 0.25 * (0.2 * (100.0 / 4.8) * 2.0 + 0.8 * (153.0 / 12.0) * 2.0), 0.0,
                   0.0, 0.0};

  // heat = max(AM + SL, 1) and Edot = (heat + W) m where not written out above
  for (int i = 0; i < 7; i++) {
    if (table[i].heat == 0.0) {
      table[i].heat = table[i].am + table[i].sl;
    }
    if (table[i].power == 0.0) {
      table[i].power = (table[i].heat + table[i].work) * table[i].mus->mass;
    }
  }
}

static void exact_model_should_match_hand_table(void) {
  for (int i = 0; i < 7; i++) {
    const row* r = &table[i];
    gsUmbergerTerms t;
    double p = gs_umberger2010(r->mus, &r->in, &t);
    printf("row %d (%s): Edot %.10g W\n", i + 1, r->what, p);
    EXPECT_REL(r->power, p, 1e-9, 1e-12);
    EXPECT_REL(r->power, t.power, 1e-9, 1e-12);
    EXPECT_REL(r->scale_a, t.scale_a, 1e-9, 1e-12);
    EXPECT_REL(r->am, t.heat_am, 1e-9, 1e-12);
    EXPECT_REL(r->sl, t.heat_sl, 1e-9, 1e-12);
    EXPECT_REL(r->work, t.work, 1e-9, 1e-12);
    EXPECT_REL(r->heat, t.heat, 1e-9, 1e-12);
    EXPECT_REL(r->heat + r->work, t.rate, 1e-9, 1e-12);
    // the positive work rate in W: F_CE |vM| when shortening (row 1: 400 N x 0.2 m/s = 80 W)
    double w_expected = r->in.fiber_velocity < 0 && r->in.active_force > 0
                            ? -r->in.active_force * r->in.fiber_velocity
                            : 0.0;
    EXPECT_REL(w_expected, t.work_power, 1e-9, 1e-12);
  }
  EXPECT_REL(80.0, table[0].work * table[0].mus->mass, 1e-12, 1e-12);
  // the hand values themselves (guards against a typo in an expression above)
  EXPECT_REL(140.0104633, table[0].power, 1e-9, 1e-12);
  EXPECT_REL(36.0127814, table[1].power, 1e-8, 1e-12);
  EXPECT_REL(0.6, table[2].power, 1e-12, 1e-12);
  EXPECT_REL(41.0182801, table[4].power, 1e-8, 1e-12);
  EXPECT_REL(65.1355347, table[5].power, 1e-8, 1e-12);
  EXPECT_REL(164.2247770, table[6].power, 1e-8, 1e-12);
}

static void smooth_model_should_match_exact_away_from_switches(void) {
  // every table row is at least 5 widths from each switch (|u - a| >= 0.05 or u == a,
  // |lM~ - 1| >= 0.05 or lM~ == 1 with fL == 1, |v~| >= 0.5 lopt/s, |-aST v~ - 100| >= 50 W/kg,
  // |AM + SL - 1| >= 0.46 W/kg), so the smooth model is within 2 % (in fact < 0.5 %)
  double worst = 0.0;
  for (int i = 0; i < 7; i++) {
    const row* r = &table[i];
    gsUmbergerTerms te, ts;
    double pe = gs_umberger2010(r->mus, &r->in, &te);
    double ps = gs_umberger2010_smooth(r->mus, &r->in, NULL, &ts);
    double rel = fabs(ps - pe) / fabs(pe);
    worst = rel > worst ? rel : worst;
    EXPECT_REL(pe, ps, 2e-2, 1e-9);
    EXPECT_REL(te.heat_am, ts.heat_am, 2e-2, 1e-3);
    EXPECT_REL(te.heat_sl, ts.heat_sl, 2e-2, 1e-3);
    EXPECT_REL(te.work, ts.work, 2e-2, 1e-3);
  }
  printf("smooth vs exact, worst relative difference over the table: %.3g\n", worst);
}

// the quantity whose slope is checked: Edot (W) as a function of one input
typedef struct probe_ {
  const gsUmbergerMuscle* mus;
  gsUmbergerInput in;
  int var;     // 0: u, 1: vM, 2: lM~, 3: u = a together
  int exact;   // 1: exact model, 0: smooth
} probe;

static double probe_fn(const probe* pr, double x) {
  gsUmbergerInput in = pr->in;
  if (pr->var == 0) {
    in.excitation = x;
  } else if (pr->var == 1) {
    in.fiber_velocity = x;
  } else if (pr->var == 2) {
    in.fiber_length = x;
  } else {
    in.excitation = x;
    in.activation = x;
  }
  return pr->exact ? gs_umberger2010(pr->mus, &in, NULL)
                   : gs_umberger2010_smooth(pr->mus, &in, NULL, NULL);
}

// left and right finite-difference slopes at x0, step h
static void one_sided(const probe* pr, double x0, double h, double* left, double* right) {
  double f0 = probe_fn(pr, x0);
  *left = (f0 - probe_fn(pr, x0 - h)) / h;
  *right = (probe_fn(pr, x0 + h) - f0) / h;
}

static void smooth_model_should_be_c1_across_switches(void) {
  probe pr;
  double l, r;
  pr.mus = &kMuscle1;
  pr.in = table[0].in;  // u 0.6, a 0.4, lM~ 0.9, vM -0.2, F 400, fL 0.95
  pr.exact = 0;

  // u = a (step width 0.01, h 1e-8)
  pr.var = 0;
  one_sided(&pr, pr.in.activation, 1e-8, &l, &r);
  EXPECT_TRUE(fabs(l) > 1.0);
  EXPECT_REL(l, r, 1e-3, 1.0);

  // v~ = 0 (width 0.01 lopt/s = 1e-3 m/s, h 1e-9 m/s)
  pr.var = 1;
  one_sided(&pr, 0.0, 1e-9, &l, &r);
  EXPECT_TRUE(fabs(l) > 1.0);
  EXPECT_REL(l, r, 1e-3, 1.0);

  // ST cap: -aST v~ = 100 at v~ = -4, vM = -0.4 m/s (width 1 W/kg = 4e-3 m/s, h 1e-8)
  one_sided(&pr, -0.4, 1e-8, &l, &r);
  EXPECT_REL(l, r, 1e-3, 1.0);

  // lM~ = 1 with fL 0.95 held fixed (width 0.01, h 1e-8)
  pr.var = 2;
  one_sided(&pr, 1.0, 1e-8, &l, &r);
  EXPECT_TRUE(fabs(l) > 1.0);
  EXPECT_REL(l, r, 1e-3, 1.0);

  // minimum heat: u = a = x, vM = 0, AM = 1.5 x^0.6 89 = 1 at x = (1 / 133.5)^(1 / 0.6)
  pr.var = 3;
  pr.in.fiber_velocity = 0.0;
  one_sided(&pr, pow(1.0 / 133.5, 1.0 / 0.6), 1e-10, &l, &r);
  EXPECT_TRUE(fabs(l) > 1.0);
  EXPECT_REL(l, r, 1e-3, 1.0);

  // the same check flags the kinks of the exact model (v~ = 0, u = a, minimum heat)
  pr.exact = 1;
  pr.in = table[0].in;
  pr.var = 1;
  one_sided(&pr, 0.0, 1e-9, &l, &r);
  EXPECT_TRUE(fabs(l - r) > 0.1 * fabs(l));
  pr.var = 0;
  one_sided(&pr, pr.in.activation, 1e-8, &l, &r);
  EXPECT_TRUE(fabs(l - r) > 0.1 * fabs(l));
}

static void helpers_should_follow_opensim_defaults(void) {
  double user[GS_ACT_NUSER];
  double powers[3] = {10.0, 20.0, 30.0};
  gsUmbergerMuscle m;
  char err[128] = "";

  // m = Fmax / sigma * rho * lopt = 1000 / 0.25e6 * 1059.7 * 0.1 = 0.42388 kg
  EXPECT_REL(0.42388, gs_muscle_mass(1000.0, 0.25e6, 0.1), 1e-12, 1e-12);
  EXPECT_REL(0.42388, gs_muscle_mass(1000.0, 0.0, 0.1), 1e-12, 1e-12);

  // basal 1.2 W/kg * 75 kg = 90 W; total = 90 + 60
  EXPECT_REL(90.0, gs_basal_metabolic_rate(75.0), 1e-12, 1e-12);
  EXPECT_REL(150.0, gs_metabolic_rate_total(3, powers, 75.0), 1e-12, 1e-12);

  // parameters from an actuator user row; mass computed when the entry is 0
  memset(user, 0, sizeof user);
  user[GS_ACT_FMAX] = 1000.0;
  user[GS_ACT_LOPT] = 0.1;
  user[GS_ACT_VMAX] = 10.0;
  user[GS_ACT_SLOW_TWITCH] = 0.5;
  user[GS_ACT_SPECIFIC_TENSION] = 0.25e6;
  EXPECT_EQ_INT(0, gs_umberger_muscle_from_user(user, &m, err, sizeof err));
  EXPECT_REL(0.42388, m.mass, 1e-12, 1e-12);
  user[GS_ACT_MASS] = 0.7;
  EXPECT_EQ_INT(0, gs_umberger_muscle_from_user(user, &m, err, sizeof err));
  EXPECT_REL(0.7, m.mass, 1e-12, 1e-12);
  user[GS_ACT_SLOW_TWITCH] = 1.5;
  EXPECT_EQ_INT(-1, gs_umberger_muscle_from_user(user, &m, err, sizeof err));
  EXPECT_TRUE(strstr(err, "slow-twitch") != NULL);
}

int main(void) {
  fill_table();
  exact_model_should_match_hand_table();
  smooth_model_should_match_exact_away_from_switches();
  smooth_model_should_be_c1_across_switches();
  helpers_should_follow_opensim_defaults();
  return GS_TEST_RESULT();
}
