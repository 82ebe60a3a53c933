// gs_metabolics.h: muscle energetics of Umberger (2010), exact and smoothed for optimisation.
//
// Sources: Umberger, Gerritsen & Martin 2003, Comput Methods Biomech Biomed Engin 6:99 (the heat
// model); Umberger 2010, J R Soc Interface 7:1329 (lengthening heat coefficient 0.3 and no
// negative mechanical work); implemented as OpenSim 3.3's Umberger2010MuscleMetabolicsProbe (Tim
// Dorn), which Lin, Walter & Pandy 2018 used for their cost of transport. The exact variant
// reproduces that probe with its defaults (aerobic factor 1.5, minimum heat rate per muscle on,
// basal 1.2 W/kg, specific tension 0.25 MPa, density 1059.7 kg/m^3).
//
// U2003 = Umberger et al. 2003, U2010 = Umberger 2010 (equation numbers not quoted: checked against
// the OpenSim probe source, not the papers' typesetting).
// Per muscle, in W per kg of muscle (m muscle mass, fST slow-twitch fraction, fFT = 1 - fST):
//   A      = u                 if u > a,  (u + a)/2 otherwise                        (U2003)
//   h_AM   = 128 fFT + 25   (= 1.28 %FT + 25)                                         (U2003)
//   AM     = S A^0.6 h_AM                          if lM~ <= 1
//          = S A^0.6 h_AM (0.4 + 0.6 fL)           if lM~ >  1                        (U2003)
//   v~     = vM / lopt (lopt/s, shortening < 0);  vmaxFT = vmax, vmaxST = vmax / 2.5
//   aST    = 100 / vmaxST  (= 4 * 25 / vmaxST),   aFT = 153 / vmaxFT                  (U2003)
//   SL     = S A^2 (fST min(-aST v~, 100) - fFT aFT v~)   if v~ <= 0 (shortening)      (U2003)
//          = S A   0.3 aST v~                             if v~ >  0 (lengthening)     (U2010)
//   SL    *= fL                                    if lM~ >  1                        (U2003)
//   W      = -max(F_CE, 0) vM / m  if vM <= 0, else 0  (negative work excluded)        (U2010)
//   heat   = max(AM + SL, 1)  (minimum heat rate 1 W/kg, 2003 p104; OpenSim
//            enforce_minimum_heat_rate_per_muscle)
//   Edot   = (heat + W) m   (W)
// S = 1.5 (aerobic), fL is the active force-length multiplier at lM~, F_CE the active fibre force
// (contractile element; passive fibre force does no metabolic work). Whole body: sum over muscles
// plus the basal rate 1.2 W/kg x body mass (OpenSim basal_coefficient 1.2, exponent 1, Umberger
// 2003 p105; the 1.51 W/kg default belongs to the Bhargava 2004 probe).
#ifndef GAITSIM_CALLBACKS_GS_METABOLICS_H_
#define GAITSIM_CALLBACKS_GS_METABOLICS_H_

#define GS_MUSCLE_DENSITY 1059.7           // mammalian muscle density                (kg/m^3)
#define GS_SPECIFIC_TENSION_DEFAULT 0.25e6 // specific tension, OpenSim default       (Pa)
#define GS_UMBERGER_AEROBIC_FACTOR 1.5     // S, aerobic activity (1.0 anaerobic)     (-)
#define GS_UMBERGER_MIN_HEAT 1.0           // minimum total heat rate per muscle      (W/kg)
#define GS_BASAL_COEFFICIENT 1.2           // basal rate per kg body mass             (W/kg)

// Metabolic parameters of one muscle.
typedef struct gsUmbergerMuscle_ {
  double mass;          // muscle mass m                                  (kg)
  double slow_twitch;   // slow-twitch fibre fraction fST                 (0..1)
  double lopt;          // optimal fibre length                           (m)
  double vmax;          // maximum shortening velocity                    (lopt/s)
} gsUmbergerMuscle;

// Muscle state at one instant.
typedef struct gsUmbergerInput_ {
  double excitation;    // u                                              (0..1)
  double activation;    // a                                              (0..1)
  double fiber_length;  // normalised fibre length lM~ = lM / lopt        (-)
  double fiber_velocity;// fibre velocity vM, shortening < 0              (m/s)
  double active_force;  // active fibre force F_CE = a fL fV Fmax         (N)
  double force_length;  // active force-length multiplier fL(lM~)         (-)
} gsUmbergerInput;

// Per-term result (for `gaitsim inspect` and metabolics.sto).
typedef struct gsUmbergerTerms_ {
  double scale_a;       // activation scaling A                           (-)
  double heat_am;       // activation-maintenance heat rate AM            (W/kg)
  double heat_sl;       // shortening (+) / lengthening heat rate SL      (W/kg)
  double heat;          // total heat rate after the 1 W/kg floor         (W/kg)
  double work;          // positive contractile mechanical work rate W    (W/kg)
  double rate;          // heat + work                                    (W/kg)
  double power;         // rate * m, the muscle's metabolic power Edot    (W)
  double work_power;    // work * m, the positive contractile work rate    (W)
} gsUmbergerTerms;

// Widths of the smooth variant; gs_umberger_smoothing_default() gives the values below.
// Steps use H(x) = (1 + tanh(x / w)) / 2; max/min use (x + y +- sqrt((x - y)^2 + w^2)) / 2.
typedef struct gsUmbergerSmoothing_ {
  double w_excitation;  // step u > a, in u - a                           (-),      0.01
  double w_length;      // step lM~ > 1, in lM~ - 1                        (-),      0.01
  double w_velocity;    // step lengthening/shortening and W, in v~       (lopt/s), 0.01
  double w_cap;         // min(-aST v~, 100)                              (W/kg),   1
  double w_heat;        // max(AM + SL, 1)                                (W/kg),   0.1
  double w_force;       // max(F_CE, 0)                                   (N),      1e-3
  double eps_a;         // A^0.6 -> (A^2 + eps^2)^0.3, finite slope at 0  (-),      1e-6
} gsUmbergerSmoothing;

// Fill s with the default widths (the values listed in gsUmbergerSmoothing).
void gs_umberger_smoothing_default(gsUmbergerSmoothing* s);

// Muscle mass (kg) = Fmax / sigma * rho * lopt with rho = GS_MUSCLE_DENSITY (OpenSim
// Umberger2010MuscleMetabolicsProbe_MetabolicMuscleParameter::setMuscleMass). fmax (N),
// specific_tension sigma (Pa; <= 0 means GS_SPECIFIC_TENSION_DEFAULT), lopt (m).
double gs_muscle_mass(double fmax, double specific_tension, double lopt);

// Fill mus from one actuator user row (GS_ACT_NUSER entries, order of gsActUser): mass from
// GS_ACT_MASS, or from gs_muscle_mass when that entry is <= 0. Returns 0, or -1 with a reason in
// err (errlen bytes, may be NULL) when lopt <= 0, vmax <= 0, fST outside [0, 1] or the mass <= 0.
int gs_umberger_muscle_from_user(const double* user, gsUmbergerMuscle* mus, char* err,
                                 int errlen);

// Basal metabolic rate (W) of a body of mass body_mass (kg): GS_BASAL_COEFFICIENT * body_mass.
double gs_basal_metabolic_rate(double body_mass);

// Whole-body metabolic rate (W): sum of n muscle powers (W) plus the basal rate of body_mass (kg).
double gs_metabolic_rate_total(int n, const double* muscle_power, double body_mass);

// Exact Umberger 2010 model (OpenSim 3.3 probe, branches as in the header comment). Returns the
// muscle's metabolic power Edot (W); terms (may be NULL) receives every term.
double gs_umberger2010(const gsUmbergerMuscle* mus, const gsUmbergerInput* in,
                       gsUmbergerTerms* terms);

// Smooth Umberger 2010 model for gradient-based optimisation: every switch of gs_umberger2010 is
// replaced by a tanh step or a hyperbolic max/min with the widths in sm (NULL: defaults), so
// Edot is C-infinity in (u, a, lM~, vM, F_CE, fL) on A > -inf (A^0.6 regularised by eps_a). Away
// from the switches (|u - a| >= 5 w_excitation, |lM~ - 1| >= 5 w_length, |v~| >= 5 w_velocity,
// |-aST v~ - 100| >= 5 w_cap, |AM + SL - 1| >= 5 w_heat, A >= 100 eps_a) it agrees with the exact
// model within 0.5 % (the largest error is the 1 W/kg floor, w_heat^2 / (4 |AM + SL - 1|) <= 0.005
// W/kg; tests/test_metabolics.c checks 2 %, measures 0.44 %). Where u == a, lM~ == 1 with fL == 1,
// or v~ == 0, the exact model is continuous and the smooth one matches it up to the max/min
// widths.
double gs_umberger2010_smooth(const gsUmbergerMuscle* mus, const gsUmbergerInput* in,
                              const gsUmbergerSmoothing* sm, gsUmbergerTerms* terms);

#endif  // GAITSIM_CALLBACKS_GS_METABOLICS_H_
