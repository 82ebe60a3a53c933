// gs_muscle.c: Hill-type muscle-tendon unit, De Groote et al. 2016 curves, elastic (fT_norm state)
// and rigid tendon, analytic partials. Equations, sources and guards are documented in
// gs_muscle.h.
#include "callbacks/gs_muscle.h"

#include <math.h>
#include <stdio.h>

#include "callbacks/gs_model_layout.h"

// exponent limit against overflow (exp(700) ~ 1e304)
#define GS_MUSCLE_EXP_MAX 700.0
// sinh argument limit of the fV inverse (-)
#define GS_MUSCLE_SINH_MAX 30.0
// smallest Gaussian width of fL (-), smallest vmax lopt (m/s), smallest lts (m)
#define GS_MUSCLE_MIN_WIDTH 1e-6
#define GS_MUSCLE_MIN_SPEED 1e-12
#define GS_MUSCLE_MIN_LENGTH 1e-12
// smallest a fL used by the undamped forward solve (-)
#define GS_MUSCLE_MIN_AFL 1e-12
// iteration limits of the safeguarded Newton solves
#define GS_MUSCLE_MAX_ITER 200
#define GS_MUSCLE_MAX_EXPAND 60
// pi / 2 (rad)
#define GS_MUSCLE_HALF_PI 1.5707963267948966

static double exp_clamped(double x) {
  return exp(x < GS_MUSCLE_EXP_MAX ? x : GS_MUSCLE_EXP_MAX);
}

int gs_muscle_params_from_user(const double* user, gsMuscleParams* p, char* err, int errlen) {
  const char* reason = NULL;

  // copy in gsActUser order
  p->fmax = user[GS_ACT_FMAX];
  p->lopt = user[GS_ACT_LOPT];
  p->lts = user[GS_ACT_LTS];
  p->pennation = user[GS_ACT_PENNATION];
  p->vmax = user[GS_ACT_VMAX];
  p->kT = user[GS_ACT_TENDON_KT] > 0.0 ? user[GS_ACT_TENDON_KT] : GS_MUSCLE_KT_DEFAULT;
  p->damping = GS_MUSCLE_DAMPING_DEFAULT;
  p->elastic = user[GS_ACT_ELASTIC_TENDON] != 0.0;

  // range checks (negated comparisons also reject NaN)
  if (!(p->fmax > 0.0) || !isfinite(p->fmax)) {
    reason = "Fmax must be > 0 N";
  } else if (!(p->lopt > 0.0) || !isfinite(p->lopt)) {
    reason = "optimal fibre length must be > 0 m";
  } else if (!(p->lts >= 0.0) || !isfinite(p->lts)) {
    reason = "tendon slack length must be >= 0 m";
  } else if (!(p->pennation >= 0.0 && p->pennation < GS_MUSCLE_HALF_PI)) {
    reason = "pennation angle must be in [0, pi/2) rad";
  } else if (!(p->vmax > 0.0) || !isfinite(p->vmax)) {
    reason = "maximum contraction velocity must be > 0 lopt/s";
  } else if (!isfinite(p->kT) || isnan(user[GS_ACT_ELASTIC_TENDON])) {
    reason = "tendon stiffness and elastic flag must be finite";
  } else if (p->elastic && !(p->lts > 0.0)) {
    reason = "an elastic tendon needs a tendon slack length > 0 m";
  }
  if (reason) {
    if (err && errlen > 0) {
      snprintf(err, (size_t)errlen, "muscle: %s", reason);
    }
    return -1;
  }
  return 0;
}

// one Gaussian of fL: b1 exp(-0.5 z^2), z = (l - b2) / (b3 + b4 l); derivative added to *d
static double gaussian(double l, double b1, double b2, double b3, double b4, double* d) {
  double w = b3 + b4 * l;
  double z, g;
  if (w < GS_MUSCLE_MIN_WIDTH) {
    w = GS_MUSCLE_MIN_WIDTH;
    b4 = 0.0;
  }
  z = (l - b2) / w;
  g = b1 * exp(-0.5 * z * z);
  // dz/dl = (w - (l - b2) b4) / w^2 = (1 - z b4) / w
  *d += -g * z * (1.0 - z * b4) / w;
  return g;
}

double gs_muscle_fl_active(double lM_norm, double* deriv) {
  double d = 0.0;
  double f = gaussian(lM_norm, GS_MUSCLE_B11, GS_MUSCLE_B21, GS_MUSCLE_B31, GS_MUSCLE_B41, &d) +
             gaussian(lM_norm, GS_MUSCLE_B12, GS_MUSCLE_B22, GS_MUSCLE_B32, GS_MUSCLE_B42, &d) +
             gaussian(lM_norm, GS_MUSCLE_B13, GS_MUSCLE_B23, GS_MUSCLE_B33, GS_MUSCLE_B43, &d);
  if (deriv) {
    *deriv = d;
  }
  return f;
}

double gs_muscle_fv(double vM_norm, double* deriv) {
  double s = GS_MUSCLE_D2 * vM_norm + GS_MUSCLE_D3;
  if (deriv) {
    *deriv = GS_MUSCLE_D1 * GS_MUSCLE_D2 / sqrt(s * s + 1.0);
  }
  // log(s + sqrt(s^2 + 1)) = asinh(s), accurate also for s << 0
  return GS_MUSCLE_D1 * asinh(s) + GS_MUSCLE_D4;
}

double gs_muscle_fv_inverse(double fV, double* deriv) {
  double x = (fV - GS_MUSCLE_D4) / GS_MUSCLE_D1;
  int clamped = 0;
  if (x > GS_MUSCLE_SINH_MAX) {
    x = GS_MUSCLE_SINH_MAX;
    clamped = 1;
  } else if (x < -GS_MUSCLE_SINH_MAX) {
    x = -GS_MUSCLE_SINH_MAX;
    clamped = 1;
  }
  if (deriv) {
    *deriv = clamped ? 0.0 : cosh(x) / (GS_MUSCLE_D1 * GS_MUSCLE_D2);
  }
  return (sinh(x) - GS_MUSCLE_D3) / GS_MUSCLE_D2;
}

// smooth max(p, 0) = (p + sqrt(p^2 + w^2)) / 2 and its derivative d/dp (w GS_MUSCLE_PASSIVE_WIDTH)
static double passive_floor(double p, double* dp) {
  const double w = GS_MUSCLE_PASSIVE_WIDTH;
  double r = sqrt(p * p + w * w);
  if (dp) {
    *dp = 0.5 * (1.0 + p / r);
  }
  return 0.5 * (p + r);
}

double gs_muscle_fl_passive(double lM_norm, double* deriv) {
  const double k = GS_MUSCLE_KPE / GS_MUSCLE_E0;
  const double den = exp(GS_MUSCLE_KPE) - 1.0;
  double x = k * (lM_norm - 1.0);
  double e = exp_clamped(x), dfloor;
  double f = passive_floor((e - 1.0) / den, &dfloor);
  if (deriv) {
    *deriv = x < GS_MUSCLE_EXP_MAX ? dfloor * k * e / den : 0.0;
  }
  return f;
}

double gs_muscle_fl_passive_min(void) {
  return passive_floor(-(1.0 - exp(-GS_MUSCLE_KPE / GS_MUSCLE_E0)) / (exp(GS_MUSCLE_KPE) - 1.0),
                       NULL);
}

double gs_muscle_ft(double lT_norm, double kT, double* deriv) {
  double x = kT * (lT_norm - GS_MUSCLE_C2);
  double e = GS_MUSCLE_C1 * exp_clamped(x);
  if (deriv) {
    *deriv = x < GS_MUSCLE_EXP_MAX ? kT * e : 0.0;
  }
  return e - GS_MUSCLE_C3;
}

double gs_muscle_ft_inverse(double fT_norm, double kT, double* deriv) {
  double s = fT_norm + GS_MUSCLE_C3;
  int floored = 0;
  if (s < GS_MUSCLE_MIN_FT_SHIFT) {
    s = GS_MUSCLE_MIN_FT_SHIFT;
    floored = 1;
  }
  if (deriv) {
    *deriv = floored ? 0.0 : 1.0 / (kT * s);
  }
  return GS_MUSCLE_C2 + log(s / GS_MUSCLE_C1) / kT;
}

// fibre thickness h = lopt sin(alpha0) with the floor of gs_muscle.h (m)
static double thickness(const gsMuscleParams* p) {
  double h = p->lopt * sin(p->pennation);
  double h0 = GS_MUSCLE_MIN_THICKNESS * p->lopt;
  return sqrt(h * h + h0 * h0);
}

double gs_muscle_fibre_length(const gsMuscleParams* p, double lMT, double lT, double* cos_alpha,
                              double* dcos_alpha) {
  double h = thickness(p);
  double x = lMT - lT;
  double lM = sqrt(x * x + h * h);
  if (lM < GS_MUSCLE_MIN_LENGTH) {
    lM = GS_MUSCLE_MIN_LENGTH;  // only when lopt itself is ~0: rejected by params_from_user
  }
  if (cos_alpha) {
    *cos_alpha = x / lM;
  }
  // d(x / lM)/dx = (lM - x^2 / lM) / lM^2 = h^2 / lM^3
  if (dcos_alpha) {
    *dcos_alpha = h * h / (lM * lM * lM);
  }
  return lM;
}

// normalising speed vmax lopt (m/s), guarded
static double speed_scale(const gsMuscleParams* p) {
  double v = p->vmax * p->lopt;
  return v > GS_MUSCLE_MIN_SPEED ? v : GS_MUSCLE_MIN_SPEED;
}

// curve values at (lM_norm, vM_norm) and the fibre force multiplier
//   M = a fL fV + fPE + beta v,  dM/dl = a fL' fV + fPE',  dM/dv = a fL fV' + beta
typedef struct fibreEval_ {
  double fL, dfL, fV, dfV, fPE, dfPE;
  double M, dM_dl, dM_dv;
} fibreEval;

static void fibre_eval(const gsMuscleParams* p, double a, double l, double v, fibreEval* e) {
  e->fL = gs_muscle_fl_active(l, &e->dfL);
  e->fV = gs_muscle_fv(v, &e->dfV);
  e->fPE = gs_muscle_fl_passive(l, &e->dfPE);
  e->M = a * e->fL * e->fV + e->fPE + p->damping * v;
  e->dM_dl = a * e->dfL * e->fV + e->dfPE;
  e->dM_dv = a * e->fL * e->dfV + p->damping;
}

static void fill_out(const gsMuscleParams* p, double a, double lT, double vT, double lM,
                     double vM, double c, const fibreEval* e, double force, gsMuscleOut* out) {
  double V = speed_scale(p);
  if (!out) {
    return;
  }
  out->lT = lT;
  out->lT_norm = p->lts > GS_MUSCLE_MIN_LENGTH ? lT / p->lts : 1.0;
  out->vT = vT;
  out->lM = lM;
  out->lM_norm = lM / p->lopt;
  out->vM = vM;
  out->vM_norm = vM / V;
  out->cos_alpha = c;
  // sin(alpha) = h / lM with the floored h; atan2 is exact for any sign of cos
  out->alpha = atan2(thickness(p) / lM, c);
  out->fL = e->fL;
  out->fV = e->fV;
  out->fPE = e->fPE;
  out->f_active = p->fmax * a * e->fL * e->fV;
  out->f_passive = p->fmax * e->fPE;
  out->f_damping = p->fmax * p->damping * vM / V;
  out->force = force;
}

double gs_muscle_equilibrium_residual(const gsMuscleParams* p, double a, double lMT, double vMT,
                                      double fT, double fT_dot, gsMuscleGrad* grad,
                                      gsMuscleOut* out) {
  double V = speed_scale(p);
  double dlTn, lTn, lT, vT, dvT_dfT, dvT_dfdot, g, dg;
  double c, dc, lM, l, vrel, v, r;
  fibreEval e;

  // tendon: lT_norm = fT^-1(fT), vT = lts g fT_dot with g = dlT_norm/dfT = 1 / (kT (fT + c3))
  lTn = gs_muscle_ft_inverse(fT, p->kT, &dlTn);
  g = dlTn;
  // dg/dfT = -kT g^2 (0 where the inverse is floored, consistent with g)
  dg = -p->kT * g * g;
  lT = p->lts * lTn;
  vT = p->lts * g * fT_dot;
  dvT_dfT = p->lts * dg * fT_dot;
  dvT_dfdot = p->lts * g;

  // fibre: x = lMT - lT, lM = sqrt(x^2 + h^2), c = cos(alpha), vM = (vMT - vT) c
  lM = gs_muscle_fibre_length(p, lMT, lT, &c, &dc);
  l = lM / p->lopt;
  vrel = vMT - vT;
  v = vrel * c / V;

  // r = M c - fT
  fibre_eval(p, a, l, v, &e);
  r = e.M * c - fT;

  if (grad) {
    // through x (dx/dlMT = 1, dx/dfT = -lts g): dl/dx = c / lopt, dv/dx = vrel dc / V
    double dr_dx = (e.dM_dl * c / p->lopt + e.dM_dv * vrel * dc / V) * c + e.M * dc;
    // through vT: dv/dvT = -c / V
    double dr_dvT = -e.dM_dv * c * c / V;
    grad->a = e.fL * e.fV * c;
    grad->lMT = dr_dx;
    grad->vMT = e.dM_dv * c * c / V;
    grad->fT = dr_dx * (-p->lts * g) + dr_dvT * dvT_dfT - 1.0;
    grad->fT_dot = dr_dvT * dvT_dfdot;
  }
  fill_out(p, a, lT, vT, lM, vrel * c, c, &e, p->fmax * fT, out);
  return r;
}

// g(v) = A fV(v) + beta v - target and dg/dv
static double velocity_eq(double A, double beta, double target, double v, double* dg) {
  double dfv;
  double fv = gs_muscle_fv(v, &dfv);
  *dg = A * dfv + beta;
  return A * fv + beta * v - target;
}

// root of the increasing function g(v) = A fV(v) + beta v - target (A >= 0, beta > 0), from the
// guess v0: bracket by doubling, then Newton steps kept inside the bracket, else bisection.
// Returns 0, or 1 when the root lies beyond +-GS_MUSCLE_VNORM_LIMIT (then *v is the limit).
static int solve_velocity(double A, double beta, double target, double v0, double* v) {
  double lo = -1.0, hi = 1.0, glo, ghi, gv, dg, x;
  int k;

  // bracket: g(lo) <= 0 <= g(hi)
  glo = velocity_eq(A, beta, target, lo, &dg);
  for (k = 0; glo > 0.0 && k < GS_MUSCLE_MAX_EXPAND; k++) {
    hi = lo;
    lo = 2.0 * lo;
    if (lo < -GS_MUSCLE_VNORM_LIMIT) {
      *v = -GS_MUSCLE_VNORM_LIMIT;
      return 1;
    }
    glo = velocity_eq(A, beta, target, lo, &dg);
  }
  ghi = velocity_eq(A, beta, target, hi, &dg);
  for (k = 0; ghi < 0.0 && k < GS_MUSCLE_MAX_EXPAND; k++) {
    lo = hi;
    hi = 2.0 * hi;
    if (hi > GS_MUSCLE_VNORM_LIMIT) {
      *v = GS_MUSCLE_VNORM_LIMIT;
      return 1;
    }
    ghi = velocity_eq(A, beta, target, hi, &dg);
  }
  if (v0 > lo && v0 < hi) {
    x = v0;
  } else {
    x = 0.5 * (lo + hi);
  }

  // safeguarded Newton
  for (k = 0; k < GS_MUSCLE_MAX_ITER; k++) {
    double xn;
    gv = velocity_eq(A, beta, target, x, &dg);
    if (gv == 0.0) {
      break;
    }
    if (gv < 0.0) {
      lo = x;
    } else {
      hi = x;
    }
    xn = dg > 0.0 ? x - gv / dg : 0.5 * (lo + hi);
    if (!(xn > lo && xn < hi)) {
      xn = 0.5 * (lo + hi);
    }
    if (fabs(xn - x) <= 1e-15 * (1.0 + fabs(x))) {
      x = xn;
      break;
    }
    x = xn;
  }
  *v = x;
  return 0;
}

int gs_muscle_elastic_fT_dot(const gsMuscleParams* p, double a, double lMT, double vMT, double fT,
                             double* fT_dot, gsMuscleOut* out) {
  double V = speed_scale(p);
  double lts = p->lts > GS_MUSCLE_MIN_LENGTH ? p->lts : GS_MUSCLE_MIN_LENGTH;
  double g, lT, c, lM, l, A, target, v, vM, vT, fdot;
  int status = 0;
  fibreEval e;

  // lengths do not depend on fT_dot
  lT = p->lts * gs_muscle_ft_inverse(fT, p->kT, &g);
  lM = gs_muscle_fibre_length(p, lMT, lT, &c, NULL);
  l = lM / p->lopt;
  fibre_eval(p, a, l, 0.0, &e);
  if (c < GS_MUSCLE_MIN_COS) {
    c = GS_MUSCLE_MIN_COS;
    status = 2;
  }

  // a fL fV(v) + beta v = fT / cos(alpha) - fPE
  A = a * e.fL;
  target = fT / c - e.fPE;
  if (p->damping > 0.0) {
    double guess = A > GS_MUSCLE_MIN_AFL ? gs_muscle_fv_inverse(target / A, NULL) : 0.0;
    if (solve_velocity(A, p->damping, target, guess, &v) && status == 0) {
      status = 1;
    }
  } else {
    v = gs_muscle_fv_inverse(target / (A > GS_MUSCLE_MIN_AFL ? A : GS_MUSCLE_MIN_AFL), NULL);
    if (fabs(v) > GS_MUSCLE_VNORM_LIMIT) {
      v = v > 0.0 ? GS_MUSCLE_VNORM_LIMIT : -GS_MUSCLE_VNORM_LIMIT;
      if (status == 0) {
        status = 1;
      }
    }
  }

  // vM = (vMT - vT) cos(alpha)  =>  vT = vMT - vM / cos(alpha);  fT_dot = vT / (lts g)
  vM = v * V;
  vT = vMT - vM / c;
  g = g > 0.0 ? g : 1.0 / (p->kT * GS_MUSCLE_MIN_FT_SHIFT);
  fdot = vT / (lts * g);
  *fT_dot = fdot;

  if (out) {
    fibre_eval(p, a, l, v, &e);
    fill_out(p, a, lT, vT, lM, vM, c, &e, p->fmax * fT, out);
  }
  return status;
}

// static residual r(fT) at vMT = 0, fT_dot = 0 and its derivative
static double static_residual(const gsMuscleParams* p, double a, double lMT, double fT,
                              double* dr) {
  gsMuscleGrad gr;
  double r = gs_muscle_equilibrium_residual(p, a, lMT, 0.0, fT, 0.0, &gr, NULL);
  *dr = gr.fT;
  return r;
}

int gs_muscle_equilibrium_fT(const gsMuscleParams* p, double a, double lMT, double* fT,
                             gsMuscleOut* out) {
  double lo = gs_muscle_fl_passive_min() - 1e-3, hi = 1.0, rlo, rhi, r, dr, x;
  int k, found = 1;

  // lower end: r(lo) >= 0 whenever cos(alpha) >= 0 there (M >= fPE >= fPE_min > lo);
  // otherwise move towards -c3, where the fibre becomes arbitrarily long
  rlo = static_residual(p, a, lMT, lo, &dr);
  for (k = 0; !(rlo >= 0.0) && k < GS_MUSCLE_MAX_EXPAND; k++) {
    lo = -GS_MUSCLE_C3 + 0.5 * (lo + GS_MUSCLE_C3);
    rlo = static_residual(p, a, lMT, lo, &dr);
  }
  // upper end: double until the tendon force exceeds the fibre force
  rhi = static_residual(p, a, lMT, hi, &dr);
  for (k = 0; !(rhi <= 0.0) && k < GS_MUSCLE_MAX_EXPAND; k++) {
    hi *= 2.0;
    rhi = static_residual(p, a, lMT, hi, &dr);
  }
  if (!(rlo >= 0.0) || !(rhi <= 0.0)) {
    found = 0;
  }

  // safeguarded Newton on the bracket (r(lo) >= 0 >= r(hi))
  x = fabs(rlo) < fabs(rhi) ? lo : hi;
  if (found) {
    // start at the isometric guess a (fT ~ a fL at lM ~ lopt)
    x = a;
    if (!(x > lo && x < hi)) {
      x = 0.5 * (lo + hi);
    }
    for (k = 0; k < GS_MUSCLE_MAX_ITER; k++) {
      double xn;
      r = static_residual(p, a, lMT, x, &dr);
      if (r == 0.0) {
        break;
      }
      if (r > 0.0) {
        lo = x;
      } else {
        hi = x;
      }
      xn = (dr < 0.0 && isfinite(dr)) ? x - r / dr : 0.5 * (lo + hi);
      if (!(xn > lo && xn < hi)) {
        xn = 0.5 * (lo + hi);
      }
      if (fabs(xn - x) <= 1e-15 * (1.0 + fabs(x))) {
        x = xn;
        break;
      }
      x = xn;
    }
  }
  *fT = x;
  if (out) {
    gs_muscle_equilibrium_residual(p, a, lMT, 0.0, x, 0.0, NULL, out);
  }
  return found ? 0 : -1;
}

double gs_muscle_rigid_force(const gsMuscleParams* p, double a, double lMT, double vMT,
                             gsMuscleGrad* grad, gsMuscleOut* out) {
  double V = speed_scale(p);
  double c, dc, lM, l, v, F;
  fibreEval e;

  // lT = lts, vT = 0: x = lMT - lts, vM = vMT c
  lM = gs_muscle_fibre_length(p, lMT, p->lts, &c, &dc);
  l = lM / p->lopt;
  v = vMT * c / V;
  fibre_eval(p, a, l, v, &e);
  F = p->fmax * e.M * c;

  if (grad) {
    grad->a = p->fmax * e.fL * e.fV * c;
    grad->lMT = p->fmax * ((e.dM_dl * c / p->lopt + e.dM_dv * vMT * dc / V) * c + e.M * dc);
    grad->vMT = p->fmax * e.dM_dv * c * c / V;
    grad->fT = 0.0;
    grad->fT_dot = 0.0;
  }
  fill_out(p, a, p->lts, 0.0, lM, vMT * c, c, &e, F, out);
  return F;
}
