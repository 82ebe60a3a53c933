// gs_metabolics.c: Umberger 2010 muscle energetics, exact (OpenSim 3.3 probe) and smooth.
// Equations and sources are listed in gs_metabolics.h.
#include "callbacks/gs_metabolics.h"

#include <math.h>
#include <stdio.h>

#include "callbacks/gs_model_layout.h"

// guards for divisions: smallest mass (kg), length (m) and velocity (lopt/s) used as divisors
#define GS_MET_MIN_MASS 1e-9
#define GS_MET_MIN_LENGTH 1e-9
#define GS_MET_MIN_VMAX 1e-9

// Umberger et al. 2003 constants
#define GS_UMB_AM_FT 128.0        // activation-maintenance heat per unit fFT  (W/kg)
#define GS_UMB_AM_BASE 25.0       // activation-maintenance heat, fibre-type independent (W/kg)
#define GS_UMB_AM_LEN_BASE 0.4    // share of AM independent of overlap when lM~ > 1 (-)
#define GS_UMB_A_EXP_AM 0.6       // exponent of A on AM (-)
#define GS_UMB_ALPHA_ST 100.0     // aST * vmaxST                               (W/kg)
#define GS_UMB_ALPHA_FT 153.0     // aFT * vmaxFT                               (W/kg)
#define GS_UMB_VMAX_ST_RATIO 2.5  // vmaxFT / vmaxST                            (-)
#define GS_UMB_ST_CAP 100.0       // upper limit of the slow-twitch shortening heat (W/kg)
#define GS_UMB_LENGTHENING 0.3    // Umberger 2010 lengthening coefficient (2003: 4.0) (-)

// default widths of the smooth variant (see gsUmbergerSmoothing)
#define GS_UMB_W_EXCITATION 0.01
#define GS_UMB_W_LENGTH 0.01
#define GS_UMB_W_VELOCITY 0.01
#define GS_UMB_W_CAP 1.0
#define GS_UMB_W_HEAT 0.1
#define GS_UMB_W_FORCE 1e-3
#define GS_UMB_EPS_A 1e-6

// guarded divisor: x if x > lo, else lo
static double at_least(double x, double lo) {
  return x > lo ? x : lo;
}

// smooth step H(x) = (1 + tanh(x / w)) / 2, 0 for x << -w, 1 for x >> w
static double smooth_step(double x, double w) {
  return 0.5 + 0.5 * tanh(x / w);
}

// smooth max(x, y) = (x + y + sqrt((x - y)^2 + w^2)) / 2, error w^2 / (4 |x - y|)
static double smooth_max(double x, double y, double w) {
  double d = x - y;
  return 0.5 * (x + y + sqrt(d * d + w * w));
}

// smooth min(x, y) = (x + y - sqrt((x - y)^2 + w^2)) / 2
static double smooth_min(double x, double y, double w) {
  double d = x - y;
  return 0.5 * (x + y - sqrt(d * d + w * w));
}

// fibre-type dependent constants of one muscle
typedef struct umbConst_ {
  double f_st;       // slow-twitch fraction                        (-)
  double f_ft;       // fast-twitch fraction                        (-)
  double h_am;       // unscaled activation-maintenance heat rate   (W/kg)
  double alpha_st;   // slow-twitch shortening heat coefficient     (W/kg per lopt/s)
  double alpha_ft;   // fast-twitch shortening heat coefficient     (W/kg per lopt/s)
  double mass;       // guarded muscle mass                         (kg)
  double lopt;       // guarded optimal fibre length                (m)
} umbConst;

static void umb_const(const gsUmbergerMuscle* mus, umbConst* c) {
  double vmax_ft = at_least(mus->vmax, GS_MET_MIN_VMAX);
  double vmax_st = vmax_ft / GS_UMB_VMAX_ST_RATIO;

  // h_AM = 1.28 %FT + 25 (Umberger 2003), aST = 4*25/vmaxST, aFT = 153/vmaxFT
  c->f_st = mus->slow_twitch;
  c->f_ft = 1.0 - mus->slow_twitch;
  c->h_am = GS_UMB_AM_FT * c->f_ft + GS_UMB_AM_BASE;
  c->alpha_st = GS_UMB_ALPHA_ST / vmax_st;
  c->alpha_ft = GS_UMB_ALPHA_FT / vmax_ft;
  c->mass = at_least(mus->mass, GS_MET_MIN_MASS);
  c->lopt = at_least(mus->lopt, GS_MET_MIN_LENGTH);
}

static double finish(const umbConst* c, double scale_a, double am, double sl, double heat,
                     double work, gsUmbergerTerms* terms) {
  double rate = heat + work;
  if (terms) {
    terms->scale_a = scale_a;
    terms->heat_am = am;
    terms->heat_sl = sl;
    terms->heat = heat;
    terms->work = work;
    terms->rate = rate;
    terms->power = rate * c->mass;
    terms->work_power = work * c->mass;
  }
  return rate * c->mass;
}

void gs_umberger_smoothing_default(gsUmbergerSmoothing* s) {
  s->w_excitation = GS_UMB_W_EXCITATION;
  s->w_length = GS_UMB_W_LENGTH;
  s->w_velocity = GS_UMB_W_VELOCITY;
  s->w_cap = GS_UMB_W_CAP;
  s->w_heat = GS_UMB_W_HEAT;
  s->w_force = GS_UMB_W_FORCE;
  s->eps_a = GS_UMB_EPS_A;
}

double gs_muscle_mass(double fmax, double specific_tension, double lopt) {
  double sigma = specific_tension > 0.0 ? specific_tension : GS_SPECIFIC_TENSION_DEFAULT;

  // m = PCSA rho lopt, PCSA = Fmax / sigma (OpenSim MetabolicMuscleParameter::setMuscleMass)
  return fmax / sigma * GS_MUSCLE_DENSITY * lopt;
}

int gs_umberger_muscle_from_user(const double* user, gsUmbergerMuscle* mus, char* err,
                                 int errlen) {
  const char* reason = NULL;

  // parameters in gsActUser order; mass from the row or from Fmax, sigma and lopt
  mus->lopt = user[GS_ACT_LOPT];
  mus->vmax = user[GS_ACT_VMAX];
  mus->slow_twitch = user[GS_ACT_SLOW_TWITCH];
  mus->mass = user[GS_ACT_MASS];
  if (!(mus->mass > 0.0)) {
    mus->mass = gs_muscle_mass(user[GS_ACT_FMAX], user[GS_ACT_SPECIFIC_TENSION], mus->lopt);
  }

  // range checks (negated comparisons also reject NaN)
  if (!(mus->lopt > 0.0)) {
    reason = "optimal fibre length must be > 0 m";
  } else if (!(mus->vmax > 0.0)) {
    reason = "maximum contraction velocity must be > 0 lopt/s";
  } else if (!(mus->slow_twitch >= 0.0 && mus->slow_twitch <= 1.0)) {
    reason = "slow-twitch fraction must lie in [0, 1]";
  } else if (!(mus->mass > 0.0)) {
    reason = "muscle mass must be > 0 kg (check Fmax and specific tension)";
  }
  if (reason) {
    if (err && errlen > 0) {
      snprintf(err, (size_t)errlen, "metabolics: %s", reason);
    }
    return -1;
  }
  return 0;
}

double gs_basal_metabolic_rate(double body_mass) {
  // OpenSim Umberger2010 probe: basal_coefficient * mass^basal_exponent, 1.2 W/kg, exponent 1
  return GS_BASAL_COEFFICIENT * body_mass;
}

double gs_metabolic_rate_total(int n, const double* muscle_power, double body_mass) {
  double total = gs_basal_metabolic_rate(body_mass);
  for (int i = 0; i < n; i++) {
    total += muscle_power[i];
  }
  return total;
}

double gs_umberger2010(const gsUmbergerMuscle* mus, const gsUmbergerInput* in,
                       gsUmbergerTerms* terms) {
  umbConst c;
  double u = in->excitation, a = in->activation;
  double scale_a, am, sl, heat, work, vnorm, st, force;

  umb_const(mus, &c);

  // activation scaling A = u if u > a else (u + a)/2 (Umberger 2003)
  scale_a = u > a ? u : 0.5 * (u + a);

  // activation-maintenance heat S A^0.6 h_AM, reduced by overlap beyond lopt (W/kg)
  am = GS_UMBERGER_AEROBIC_FACTOR * pow(scale_a > 0.0 ? scale_a : 0.0, GS_UMB_A_EXP_AM) * c.h_am;
  if (in->fiber_length > 1.0) {
    am *= GS_UMB_AM_LEN_BASE + (1.0 - GS_UMB_AM_LEN_BASE) * in->force_length;
  }

  // shortening heat S A^2 (fST min(-aST v~, 100) - fFT aFT v~), lengthening S A 0.3 aST v~ (W/kg)
  vnorm = in->fiber_velocity / c.lopt;
  if (vnorm <= 0.0) {
    st = -c.alpha_st * vnorm;
    if (st > GS_UMB_ST_CAP) {
      st = GS_UMB_ST_CAP;
    }
    sl = GS_UMBERGER_AEROBIC_FACTOR * scale_a * scale_a *
         (c.f_st * st - c.f_ft * c.alpha_ft * vnorm);
  } else {
    sl = GS_UMBERGER_AEROBIC_FACTOR * scale_a * GS_UMB_LENGTHENING * c.alpha_st * vnorm;
  }
  if (in->fiber_length > 1.0) {
    sl *= in->force_length;
  }

  // positive contractile work only (Umberger 2010): -F_CE vM / m when shortening (W/kg)
  force = in->active_force > 0.0 ? in->active_force : 0.0;
  work = in->fiber_velocity <= 0.0 ? -force * in->fiber_velocity / c.mass : 0.0;

  // total heat rate not below 1 W/kg (Umberger 2003, p104)
  heat = am + sl;
  if (heat < GS_UMBERGER_MIN_HEAT) {
    heat = GS_UMBERGER_MIN_HEAT;
  }
  return finish(&c, scale_a, am, sl, heat, work, terms);
}

double gs_umberger2010_smooth(const gsUmbergerMuscle* mus, const gsUmbergerInput* in,
                              const gsUmbergerSmoothing* sm, gsUmbergerTerms* terms) {
  gsUmbergerSmoothing def;
  umbConst c;
  double u = in->excitation, a = in->activation, fl = in->force_length;
  double scale_a, a06, h_len, h_lengthening, am, sl, sl_short, sl_long, st, vnorm, heat, work;
  double force;

  if (!sm) {
    gs_umberger_smoothing_default(&def);
    sm = &def;
  }
  umb_const(mus, &c);

  // A = (u + a)/2 + (u - a)/2 H(u - a): exact u for u >> a, (u + a)/2 for u << a
  scale_a = 0.5 * (u + a) + 0.5 * (u - a) * smooth_step(u - a, sm->w_excitation);

  // AM = S (A^2 + eps^2)^0.3 h_AM (1 - H(lM~ - 1) 0.6 (1 - fL))
  a06 = pow(scale_a * scale_a + sm->eps_a * sm->eps_a, 0.5 * GS_UMB_A_EXP_AM);
  h_len = smooth_step(in->fiber_length - 1.0, sm->w_length);
  am = GS_UMBERGER_AEROBIC_FACTOR * a06 * c.h_am *
       (1.0 - h_len * (1.0 - GS_UMB_AM_LEN_BASE) * (1.0 - fl));

  // SL = (1 - H(v~)) shortening branch + H(v~) lengthening branch, times (1 + H(lM~ - 1)(fL - 1))
  vnorm = in->fiber_velocity / c.lopt;
  h_lengthening = smooth_step(vnorm, sm->w_velocity);
  st = smooth_min(-c.alpha_st * vnorm, GS_UMB_ST_CAP, sm->w_cap);
  sl_short = GS_UMBERGER_AEROBIC_FACTOR * scale_a * scale_a *
             (c.f_st * st - c.f_ft * c.alpha_ft * vnorm);
  sl_long = GS_UMBERGER_AEROBIC_FACTOR * scale_a * GS_UMB_LENGTHENING * c.alpha_st * vnorm;
  sl = ((1.0 - h_lengthening) * sl_short + h_lengthening * sl_long) * (1.0 + h_len * (fl - 1.0));

  // W = -max(F_CE, 0) vM (1 - H(v~)) / m: positive work only
  force = smooth_max(in->active_force, 0.0, sm->w_force);
  work = -force * in->fiber_velocity * (1.0 - h_lengthening) / c.mass;

  // heat = smooth max(AM + SL, 1)
  heat = smooth_max(am + sl, GS_UMBERGER_MIN_HEAT, sm->w_heat);
  return finish(&c, scale_a, am, sl, heat, work, terms);
}
