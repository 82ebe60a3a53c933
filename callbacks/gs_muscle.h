// gs_muscle.h: Hill-type muscle-tendon unit with the smooth curves of De Groote et al. 2016, an
// elastic tendon (normalised tendon force as state, Hill equilibrium as an implicit residual) or
// a rigid tendon, and analytic partial derivatives of everything the collocation problem needs.
//
// Pure functions on plain doubles; nothing here knows about MuJoCo. The caller reads the
// parameters from the actuator `user` row (callbacks/gs_model_layout.h, gsActUser) with
// gs_muscle_params_from_user, the muscle-tendon length lMT and lengthening velocity vMT from
// mjData (actuator_length, actuator_velocity), and the muscle states from its own storage.
//
// Source: De Groote F, Kinney AL, Rao AV, Fregly BJ 2016, "Evaluation of direct collocation
// optimal control problem formulations for solving the muscle redundancy problem", Ann Biomed Eng
// 44:2922-2936, Appendix (curves, eqs. for f_L, f_V, f_PE, f_T) and section "Muscle-tendon
// dynamics" (formulation with the normalised tendon force as state and its time derivative as
// control). Full-precision curve constants as published with the authors' implementation in
// OpenSim (DeGrooteFregly2016Muscle); the paper prints them rounded to three decimals.
//
// Conventions (all functions):
//   lengths in m, velocities in m/s, lengthening positive (vMT > 0: the unit gets longer,
//   vM < 0: the fibre shortens); forces returned in N are TENSION, >= 0 when the muscle pulls.
//   MuJoCo's actuator convention is the opposite (a muscle pulling shortens its tendon, so
//   actuator_force = -tension): negating is the caller's job.
//   Normalised quantities carry a trailing _norm (the paper's tilde):
//     lM_norm = lM / lopt,  vM_norm = vM / (vmax lopt),  lT_norm = lT / lts,  fT_norm = F / Fmax.
//
// Pennation at constant thickness (Zajac 1989, Crit Rev Biomed Eng 17:359; De Groote 2016):
//   h = lopt sin(alpha0),  lM sin(alpha) = h,  lM cos(alpha) = lMT - lT,
//   lM = sqrt((lMT - lT)^2 + h^2),  cos(alpha) = (lMT - lT) / lM,  vM = (vMT - vT) cos(alpha).
// Guard (documented): h is replaced by sqrt(h^2 + (GS_MUSCLE_MIN_THICKNESS lopt)^2) so lM >= that
// floor > 0 and every division by lM is safe even at zero pennation; for alpha0 = 0 this is a
// pennation angle of 1e-3 rad at optimal length (cos = 1 - 5e-7).
#ifndef GAITSIM_CALLBACKS_GS_MUSCLE_H_
#define GAITSIM_CALLBACKS_GS_MUSCLE_H_

// --- De Groote et al. 2016, Appendix, curve constants ----------------------------------------
// active force-length, sum of three Gaussians (-); paper: 0.815 1.055 0.162 0.063 / 0.433 0.717
// -0.030 0.200 / 0.100 1.000 0.354 0.000
#define GS_MUSCLE_B11 0.815
#define GS_MUSCLE_B21 1.055
#define GS_MUSCLE_B31 0.162
#define GS_MUSCLE_B41 0.063
#define GS_MUSCLE_B12 0.433
#define GS_MUSCLE_B22 0.717
#define GS_MUSCLE_B32 -0.030
#define GS_MUSCLE_B42 0.200
#define GS_MUSCLE_B13 0.100
#define GS_MUSCLE_B23 1.000
#define GS_MUSCLE_B33 0.354
#define GS_MUSCLE_B43 0.000
// force-velocity, fV = d1 asinh(d2 v + d3) + d4 (-); paper: d1 = -0.318, d2 = -8.149,
// d3 = -0.374, d4 = 0.886. d1 and d4 are the values that make fV(0) = 1 and fV(-1) = 0 exactly,
// d1 = 1 / (asinh(d3) - asinh(d3 - d2)), d4 = 1 - d1 asinh(d3) (OpenSim DeGrooteFregly2016Muscle
// uses the same); the paper's rounded pair gives fV(0) = 1.0023, fV(-1) = 0.012.
#define GS_MUSCLE_D1 -0.3211346127989808
#define GS_MUSCLE_D2 -8.149
#define GS_MUSCLE_D3 -0.374
#define GS_MUSCLE_D4 0.8825327733249912
// passive force-length, fPE = (exp(kPE (l - 1) / e0) - 1) / (exp(kPE) - 1) (-), joined to zero
// below optimal length by a smooth max of width GS_MUSCLE_PASSIVE_WIDTH (see gs_muscle_fl_passive)
#define GS_MUSCLE_KPE 4.0
#define GS_MUSCLE_E0 0.6
// tendon force-length, fT = c1 exp(kT (l - c2)) - c3 (-); kT per muscle (user row), 35 default.
// Note fT(1) = 0.2 exp(0.175) - 0.25 = -0.0118, not 0, and fT = 1 at lT_norm = 1.0474 (kT = 35).
#define GS_MUSCLE_C1 0.200
#define GS_MUSCLE_C2 0.995
#define GS_MUSCLE_C3 0.250
#define GS_MUSCLE_KT_DEFAULT 35.0

// --- gaitsim choices ----------------------------------------------------------------------
// fibre damping beta (-): a normalised force beta vM_norm in parallel with the fibre, as in
// OpenSim DeGrooteFregly2016Muscle (fiber_damping); keeps the equilibrium solvable for vM_norm
// when a fL -> 0 and regularises the NLP. 0.01 Fmax at vmax.
#define GS_MUSCLE_DAMPING_DEFAULT 0.01
// thickness floor as a fraction of lopt (-): see "Guard" above
#define GS_MUSCLE_MIN_THICKNESS 1e-3
// width of the smooth max that takes the passive curve to zero below optimal length (normalised
// force, -): fPE(1) = width / 2 = 5e-4, fPE = 1.3e-5 at short lengths, 2.5e-7 off at l = 1.6
#define GS_MUSCLE_PASSIVE_WIDTH 1e-3
// smallest fT_norm + c3 accepted by the tendon inverse (-): fT_norm must exceed -c3 = -0.25
#define GS_MUSCLE_MIN_FT_SHIFT 1e-9
// |vM_norm| limit of the forward solve (-); beyond it the result is clamped and flagged
#define GS_MUSCLE_VNORM_LIMIT 1e4
// smallest cos(alpha) the forward solve divides by (-)
#define GS_MUSCLE_MIN_COS 1e-6

// Parameters of one muscle-tendon unit (one actuator user row, gsActUser order).
typedef struct gsMuscleParams_ {
  double fmax;       // maximum isometric force Fmax                             (N)
  double lopt;       // optimal fibre length                                     (m)
  double lts;        // tendon slack length                                      (m)
  double pennation;  // pennation angle alpha0 at optimal fibre length          (rad)
  double vmax;       // maximum contraction velocity                             (lopt/s)
  double kT;         // tendon stiffness shape factor kT of fT                   (-)
  double damping;    // fibre damping beta, GS_MUSCLE_DAMPING_DEFAULT            (-)
  int elastic;       // 1: elastic tendon (fT_norm state), 0: rigid tendon      (flag)
} gsMuscleParams;

// Partial derivatives of one scalar output (the residual r, dimensionless, or the rigid force F,
// N) with respect to the inputs. Units are the output's per the input's.
typedef struct gsMuscleGrad_ {
  double a;          // d/d activation                                           (1/-)
  double lMT;        // d/d muscle-tendon length                                 (1/m)
  double vMT;        // d/d muscle-tendon lengthening velocity                   (s/m)
  double fT;         // d/d normalised tendon force (elastic only, else 0)       (1/-)
  double fT_dot;     // d/d time derivative of the normalised tendon force       (s)
} gsMuscleGrad;

// Everything a caller may want to output about one evaluation.
typedef struct gsMuscleOut_ {
  double lT;         // tendon length                                            (m)
  double lT_norm;    // lT / lts                                                 (-)
  double vT;         // tendon lengthening velocity                              (m/s)
  double lM;         // fibre length                                             (m)
  double lM_norm;    // lM / lopt                                                (-)
  double vM;         // fibre lengthening velocity, < 0 shortening               (m/s)
  double vM_norm;    // vM / (vmax lopt)                                         (-)
  double cos_alpha;  // cosine of the pennation angle                            (-)
  double alpha;      // pennation angle                                          (rad)
  double fL;         // active force-length multiplier                           (-)
  double fV;         // force-velocity multiplier                                (-)
  double fPE;        // passive force-length multiplier                          (-)
  double f_active;   // active fibre force Fmax a fL fV, along the fibre         (N)
  double f_passive;  // passive fibre force Fmax fPE, along the fibre            (N)
  double f_damping;  // damping fibre force Fmax beta vM_norm, along the fibre   (N)
  double force;      // tendon tension: Fmax fT_norm (elastic), fibre force
                     // projected on the tendon (rigid)                          (N)
} gsMuscleOut;

// Fill p from one actuator user row (GS_ACT_NUSER entries, order of gsActUser): Fmax, lopt, lts,
// alpha0, vmax, kT (a value <= 0 selects GS_MUSCLE_KT_DEFAULT), elastic flag (non-zero: elastic);
// damping = GS_MUSCLE_DAMPING_DEFAULT (not in the row; the caller may change it).
// Returns 0, or -1 with a reason in err (errlen bytes, may be NULL) when a parameter is out of
// range (Fmax <= 0, lopt <= 0, lts < 0, alpha0 outside [0, pi/2), vmax <= 0, a non-finite entry).
int gs_muscle_params_from_user(const double* user, gsMuscleParams* p, char* err, int errlen);

// --- curves (De Groote 2016, Appendix); each returns the value and writes the derivative to
// *deriv when deriv is not NULL ---------------------------------------------------------------

// Active force-length multiplier fL(lM_norm) (-), eq. for f_L^M:
//   fL = sum_{i=1..3} b1i exp(-0.5 (l - b2i)^2 / (b3i + b4i l)^2);  fL(1) = 0.9993.
// The second Gaussian's width b32 + b42 l vanishes at l = 0.1497 (a pole of the published curve);
// the width is floored at 1e-6 so below that length the term is exactly 0 (it already is, to
// double precision, for l < 0.25). deriv: dfL/dlM_norm (-).
double gs_muscle_fl_active(double lM_norm, double* deriv);

// Force-velocity multiplier fV(vM_norm) (-), eq. for f_V^M:
//   fV = d1 log((d2 v + d3) + sqrt((d2 v + d3)^2 + 1)) + d4 = d1 asinh(d2 v + d3) + d4;
// fV(0) = 1, fV(-1) = 0, increasing, unbounded both ways. deriv: dfV/dvM_norm (-).
double gs_muscle_fv(double vM_norm, double* deriv);

// Inverse of fV: vM_norm = (sinh((fV - d4) / d1) - d3) / d2 (-). The sinh argument is clamped to
// +-30 (|vM_norm| ~ 1e12, never physiological). deriv: dvM_norm/dfV (-).
double gs_muscle_fv_inverse(double fV, double* deriv);

// Passive force-length multiplier fPE(lM_norm) (-), the parallel elastic element:
//   p = (exp(kPE (l - 1) / e0) - 1) / (exp(kPE) - 1),  kPE = 4, e0 = 0.6 (De Groote 2016),
//   fPE = (p + sqrt(p^2 + w^2)) / 2,  w = GS_MUSCLE_PASSIVE_WIDTH = 1e-3.
// De Groote's p passes through zero at l = 1 and is NEGATIVE below, down to -0.0186 Fmax: a
// fibre that pushes. With the tendon force bounded at zero (a slack tendon cannot push either),
// an unopposed push must be cancelled by activation: a slack muscle whose fibre sits at 0.6 lopt
// needs a = 0.06 to stay in equilibrium, which Umberger's heat prices at a cost per second. The
// parallel elastic element is slack below optimal length in OpenSim's Thelen2003Muscle (zero
// below lopt) and Millard2012EquilibriumMuscle (its fibre force-length curve starts at strain 0);
// OpenSim Moco's DeGrooteFregly2016Muscle shifts De Groote's curve so that it does not go negative
// for the same reason. gaitsim keeps De Groote's curve above optimal length and takes the smooth
// max with zero: fPE(1) = w / 2, fPE >= 1.34e-5 (gs_muscle_fl_passive_min) as l -> 0, within
// w^2 / (4 p) of p above (2.5e-7 at l = 1.6), C-infinity. The exponent is clamped at 700
// (l > 106) against overflow. deriv: dfPE/dlM_norm (-).
double gs_muscle_fl_passive(double lM_norm, double* deriv);

// Lower bound of fPE over lM_norm >= 0 (-), its value as lM_norm -> 0 (p = -(1 - exp(-kPE/e0)) /
// (exp(kPE) - 1) = -0.01863 there): (p + sqrt(p^2 + w^2)) / 2 = 1.34e-5.
double gs_muscle_fl_passive_min(void);

// Tendon force-length fT(lT_norm) (-), eq. for f_T: fT = c1 exp(kT (l - c2)) - c3, kT (-) per
// muscle. deriv: dfT/dlT_norm (-).
double gs_muscle_ft(double lT_norm, double kT, double* deriv);

// Inverse of fT: lT_norm = c2 + log((fT_norm + c3) / c1) / kT (-). fT_norm + c3 is floored at
// GS_MUSCLE_MIN_FT_SHIFT (fT_norm must exceed -0.25). deriv: dlT_norm/dfT_norm = 1 / (kT (fT +
// c3)) (-).
double gs_muscle_ft_inverse(double fT_norm, double kT, double* deriv);

// Fibre length (m) from the muscle-tendon and tendon lengths (m), constant thickness (see the
// top of this file): lM = sqrt((lMT - lT)^2 + h^2). dlM/dlMT = -dlM/dlT = cos(alpha).
// Writes cos(alpha) (-) and dcos(alpha)/dlMT = -dcos(alpha)/dlT = h^2 / lM^3 (1/m) when the
// pointers are not NULL.
double gs_muscle_fibre_length(const gsMuscleParams* p, double lMT, double lT, double* cos_alpha,
                              double* dcos_alpha);

// --- elastic tendon (De Groote 2016, formulation with fT_norm as state) ---------------------

// Hill equilibrium residual (-) of an elastic-tendon unit; zero when the tendon force equals the
// fibre force projected on the tendon:
//   lT_norm = fT^-1(fT_norm),  lT = lts lT_norm,  vT = lts dlT_norm/dfT_norm fT_dot,
//   lM = sqrt((lMT - lT)^2 + h^2),  cos(alpha) = (lMT - lT) / lM,  vM = (vMT - vT) cos(alpha),
//   r = (a fL(lM_norm) fV(vM_norm) + fPE(lM_norm) + beta vM_norm) cos(alpha) - fT_norm.
//   a       activation (-), >= 0
//   lMT     muscle-tendon length (m)
//   vMT     muscle-tendon lengthening velocity (m/s)
//   fT      normalised tendon force fT_norm (-), > -0.25
//   fT_dot  its time derivative (1/s)
//   grad    partials dr/d(a, lMT, vMT, fT, fT_dot), analytic; NULL: not computed
//   out     lengths, velocities, angle, curve values, forces (force = Fmax fT); NULL: not written
double gs_muscle_equilibrium_residual(const gsMuscleParams* p, double a, double lMT, double vMT,
                                      double fT, double fT_dot, gsMuscleGrad* grad,
                                      gsMuscleOut* out);

// Forward simulation of an elastic-tendon unit: the fT_dot (1/s) that makes the equilibrium
// residual zero for given a (-, >= 0), lMT (m), vMT (m/s), fT (-). Solves
//   a fL fV(v) + beta v = fT / cos(alpha) - fPE        for v = vM_norm,
// then vT = vMT - vM / cos(alpha) and fT_dot = vT kT (fT + c3) / lts. With beta > 0 the left side
// is strictly increasing and unbounded in v, so the root is unique for any a >= 0, even a fL = 0
// (then the damping alone carries the force): safeguarded Newton-bisection started from the
// analytic inverse of fV. With beta = 0 the analytic inverse is used, with a fL floored at 1e-12.
// Writes *fT_dot and out (may be NULL). Returns 0 when solved (|r| < 1e-12 typically), 1 when
// |vM_norm| hit GS_MUSCLE_VNORM_LIMIT (result clamped, residual not zero), 2 when cos(alpha) <
// GS_MUSCLE_MIN_COS (lMT <= lT: the fibre has no positive projected length; cos floored).
int gs_muscle_elastic_fT_dot(const gsMuscleParams* p, double a, double lMT, double vMT, double fT,
                             double* fT_dot, gsMuscleOut* out);

// Static equilibrium for initialisation: the fT_norm (-) with zero residual at vMT = 0,
// fT_dot = 0, for activation a (-, >= 0) and length lMT (m). Safeguarded Newton-bisection on
// fT_norm in a bracket whose residual signs are guaranteed (lower end: fPE's minimum or closer to
// -c3; upper end: doubled until the residual is negative). Where the residual has several roots
// (fibres on the descending limb with a compliant tendon) one of them is returned. lMT must exceed
// the tendon length at fPE's minimum, lts fT^-1(-0.0186) ~ 0.999 lts (kT = 35), for the root to
// have cos(alpha) > 0; below that only a non-physical root (fibre folded back) exists. Writes *fT
// and out (may be NULL). Returns 0 when solved, -1 when no bracket was found (*fT is then the best
// iterate).
int gs_muscle_equilibrium_fT(const gsMuscleParams* p, double a, double lMT, double* fT,
                             gsMuscleOut* out);

// --- rigid tendon (lts < lopt: inextensible, Lin, Walter & Pandy 2018, Methods) ----------------

// Tendon tension (N) of a rigid-tendon unit: lT = lts, lM from lMT, vM = vMT cos(alpha),
//   F = Fmax (a fL(lM_norm) fV(vM_norm) + fPE(lM_norm) + beta vM_norm) cos(alpha).
// grad: dF/da (N), dF/dlMT (N/m), dF/dvMT (N s/m), fT and fT_dot set to 0; NULL: not computed.
double gs_muscle_rigid_force(const gsMuscleParams* p, double a, double lMT, double vMT,
                             gsMuscleGrad* grad, gsMuscleOut* out);

#endif  // GAITSIM_CALLBACKS_GS_MUSCLE_H_
