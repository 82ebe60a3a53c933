// gs_activation.h: first-order muscle activation dynamics with a smooth switch between the
// activation and the deactivation time constants, and its analytic partial derivatives.
//
// Pure functions on plain doubles; nothing here knows about MuJoCo. The caller reads the time
// constants from the actuator `user` row (callbacks/gs_model_layout.h: GS_ACT_TAU_ACT,
// GS_ACT_TAU_DEACT) with gs_activation_params_from_user, the excitation u from its controls and
// the activation a from its states.
//
// Model: De Groote, Kinney, Rao & Fregly 2016, Ann Biomed Eng 44:2922, Methods, "Activation
// dynamics", a smooth form of the activation-dependent time constants (0.5 + 1.5 a) of Winters
// 1995 and Raasch et al. 1997 (J Biomech 30:595):
//   da/dt = (u - a) (f / (tau_a (0.5 + 1.5 a)) + (1 - f) (0.5 + 1.5 a) / tau_d),
//   f     = 0.5 + 0.5 tanh(b (u - a)).
// f -> 1 when u > a (activation, time constant tau_a (0.5 + 1.5 a): 5 ms at a = 0, 20 ms at a = 1
// for tau_a = 10 ms) and f -> 0 when u < a (deactivation, tau_d / (0.5 + 1.5 a): 80 ms at a = 0,
// 20 ms at a = 1 for tau_d = 40 ms). Smoothing b = 10, the default of OpenSim Moco's
// DeGrooteFregly2016Muscle (activation_dynamics_smoothing); De Groote 2016 print b = 0.1, which
// with u - a in [-1, 1] barely switches (f in [0.475, 0.525]: nearly the mean of both rates).
// With b = 10, f is within 2 % of the hard switch when |u - a| > 0.2. Time constants
// tau_a = 10 ms, tau_d = 40 ms: Lin, Walter & Pandy 2018 (ref. 47 there).
// da/dt is zero at u = a (and only there), so [GS_ACTIVATION_MIN, GS_ACTIVATION_MAX] is invariant
// for excitations in that range.
#ifndef GAITSIM_CALLBACKS_GS_ACTIVATION_H_
#define GAITSIM_CALLBACKS_GS_ACTIVATION_H_

#define GS_ACTIVATION_MIN 0.001        // lower bound of activation and excitation (-)
#define GS_ACTIVATION_MAX 1.0          // upper bound of activation and excitation (-)
#define GS_ACTIVATION_TAU_ACT 0.010    // default activation time constant tau_a   (s)
#define GS_ACTIVATION_TAU_DEACT 0.040  // default deactivation time constant tau_d (s)
#define GS_ACTIVATION_SMOOTHING 10.0   // default switch steepness b               (-)

// Parameters of the activation dynamics of one muscle.
typedef struct gsActivationParams_ {
  double tau_act;    // activation time constant tau_a                 (s)
  double tau_deact;  // deactivation time constant tau_d               (s)
  double b;          // switch steepness of f = 0.5 + 0.5 tanh(b (u-a)) (-)
} gsActivationParams;

// Fill p with tau_a = GS_ACTIVATION_TAU_ACT, tau_d = GS_ACTIVATION_TAU_DEACT,
// b = GS_ACTIVATION_SMOOTHING.
void gs_activation_params_default(gsActivationParams* p);

// Fill p from one actuator user row (GS_ACT_NUSER entries, order of gsActUser): tau_a and tau_d
// from GS_ACT_TAU_ACT and GS_ACT_TAU_DEACT, b = GS_ACTIVATION_SMOOTHING. Returns 0, or -1 with a
// reason in err (errlen bytes, may be NULL) when a time constant is not finite and > 0.
int gs_activation_params_from_user(const double* user, gsActivationParams* p, char* err,
                                   int errlen);

// Activation rate da/dt (1/s) for excitation u (-) and activation a (-), see the top of this file.
// Writes d(da/dt)/du (1/s) and d(da/dt)/da (1/s), analytic, when the pointers are not NULL.
// Guards: 0.5 + 1.5 a is floored at 1e-6 (a > -0.333; outside the bounds) and the time constants
// at 1e-9 s.
double gs_activation_dot(const gsActivationParams* p, double u, double a, double* ddot_du,
                         double* ddot_da);

#endif  // GAITSIM_CALLBACKS_GS_ACTIVATION_H_
