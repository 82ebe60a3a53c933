// gs_activation.c: first-order activation dynamics with a smooth activation/deactivation switch
// (De Groote et al. 2016). Equations and sources are documented in gs_activation.h.
#include "callbacks/gs_activation.h"

#include <math.h>
#include <stdio.h>

#include "callbacks/gs_model_layout.h"

// floors of the time-constant scaling 0.5 + 1.5 a (-) and of the time constants (s)
#define GS_ACTIVATION_MIN_SCALE 1e-6
#define GS_ACTIVATION_MIN_TAU 1e-9

void gs_activation_params_default(gsActivationParams* p) {
  p->tau_act = GS_ACTIVATION_TAU_ACT;
  p->tau_deact = GS_ACTIVATION_TAU_DEACT;
  p->b = GS_ACTIVATION_SMOOTHING;
}

int gs_activation_params_from_user(const double* user, gsActivationParams* p, char* err,
                                   int errlen) {
  gs_activation_params_default(p);
  p->tau_act = user[GS_ACT_TAU_ACT];
  p->tau_deact = user[GS_ACT_TAU_DEACT];

  // negated comparisons also reject NaN
  if (!(p->tau_act > 0.0) || !isfinite(p->tau_act) || !(p->tau_deact > 0.0) ||
      !isfinite(p->tau_deact)) {
    if (err && errlen > 0) {
      snprintf(err, (size_t)errlen, "activation: time constants must be > 0 s");
    }
    return -1;
  }
  return 0;
}

double gs_activation_dot(const gsActivationParams* p, double u, double a, double* ddot_du,
                         double* ddot_da) {
  double ta = p->tau_act > GS_ACTIVATION_MIN_TAU ? p->tau_act : GS_ACTIVATION_MIN_TAU;
  double td = p->tau_deact > GS_ACTIVATION_MIN_TAU ? p->tau_deact : GS_ACTIVATION_MIN_TAU;
  double s = u - a;
  double t = tanh(p->b * s);
  double f = 0.5 + 0.5 * t;
  double g = 0.5 + 1.5 * a;
  double dg = 1.5;
  double ka, kd, K, df, dK_df;

  // time-constant scaling, floored below a = -1/3
  if (g < GS_ACTIVATION_MIN_SCALE) {
    g = GS_ACTIVATION_MIN_SCALE;
    dg = 0.0;
  }

  // rate constants: activation 1 / (tau_a g), deactivation g / tau_d  (1/s)
  ka = 1.0 / (ta * g);
  kd = g / td;
  K = f * ka + (1.0 - f) * kd;

  // df/du = -df/da = 0.5 b (1 - tanh^2);  dK/df = ka - kd
  df = 0.5 * p->b * (1.0 - t * t);
  dK_df = ka - kd;

  // da/dt = s K:  d/du = K + s dK/df df,  d/da = -K + s (-dK/df df + f dka/da + (1 - f) dkd/da)
  if (ddot_du) {
    *ddot_du = K + s * dK_df * df;
  }
  if (ddot_da) {
    double dka = -ka * dg / g;
    double dkd = dg / td;
    *ddot_da = -K + s * (-dK_df * df + f * dka + (1.0 - f) * dkd);
  }
  return s * K;
}
