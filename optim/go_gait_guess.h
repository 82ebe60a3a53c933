// go_gait_guess.h: initial guess of the gait problem (go_gait.h) from a measured trial.
//
// Coordinates: the measured table's samples, their speeds and accelerations by central
// differences on the table's own grid with the stride wrapped periodically (the sample before the
// first is the one before the last, shifted by the stride's net change, so pelvis_tx's progression
// is kept), then linearly resampled at the node times. Coordinates absent from the table: the
// model's qpos0, speed 0. q' = qdot. Activations and excitations constant; adot = 0. Tendon
// forces in static equilibrium (gs_muscle_equilibrium_fT at the node's muscle-tendon length), fT'
// by periodic central differences over the nodes. Ground reaction variables: the model's contact
// forces at the node's q, qdot (so the grf path rows hold exactly).
#ifndef GAITSIM_OPTIM_GO_GAIT_GUESS_H_
#define GAITSIM_OPTIM_GO_GAIT_GUESS_H_

#include "io/gs_table.h"
#include "optim/go_gait.h"

// Fill z (N nz, physical, the NLP's node-major order) for problem g from coords (radians, model
// coordinate names, >= 3 rows spanning the stride); activation in [0.001, 1] for every muscle.
// Returns 0, or -1 with the reason in err.
int go_gait_guess_from_trial(const go_gait* g, const gsTable* coords, double activation,
                             double* z, char* err, int errsz);

// Fill z (N nz, physical) from a solution of a gait problem on the same model, e.g. the same
// problem on fewer nodes (mesh continuation) or a tracking solution as the guess of a prediction:
// states (gs_state.h columns, radians: coordinates, speeds, activations, tendon forces; time
// spanning the stride) and controls (excitations), both linearly interpolated at the node times
// t_k = t_0 + T' k / (N - 1) with T' = the states' time span times time_scale (> 0; 1 keeps the
// stride, 0.8 makes it 20 % shorter, with speeds and derivatives scaled by 1/time_scale and the
// forward translation kept). Missing quantities as in go_gait_guess_from_trial (activation
// `activation`, tendon forces in equilibrium). q' = qdot; qddot, adot and fT' by periodic
// central differences over the nodes; ground reaction variables from the model's contact. Returns
// 0, or -1 with the reason in err.
int go_gait_guess_from_solution(const go_gait* g, const gsTable* states, const gsTable* controls,
                                double time_scale, double activation, double* z, char* err,
                                int errsz);

// --- static-optimisation guess (`gaitsim track --guess-method static`) ------------------------
//
// Coordinates, speeds, accelerations, q', adot = 0 and the ground reaction variables exactly as
// go_gait_guess_from_trial; then, at every node, static optimisation (Crowninshield & Brand 1981,
// J Biomech 14:793, with the sum of squared activations of Anderson & Pandy 2001, J Biomech Eng
// 123:381):
//   min_a  sum_i a_i^2 + w_res sum_{j in J} r_j^2,   0.001 <= a_i <= 1,
//   r_j = sum_i (-R_ij) F_i(a_i) - tau_j                                        (N m, N)
// tau = the inverse-dynamics generalized forces (go_gait_inverse_dynamics) with the MEASURED
// ground reactions in place of the model's foot contact; R = actuator_moment (MuJoCo's sign: a
// pulling muscle has actuator force -F); J = the matched dofs: every dof but the 6 of the root
// body (the pelvis residuals are unactuated and cannot be matched by muscles) and those held by a
// joint spring (stiffness > 0: the right knee's secondary rotations and translations, whose
// spring takes whatever load the muscles put on them). F_i(a) ~ P_i + G_i a is each muscle's
// force-length-velocity force at the node's lMT, vMT, so each node's problem is a bounded
// least-squares QP (go_static_opt_solve):
//   rigid tendons: gs_muscle_rigid_force, affine in a, exact;
//   elastic tendons: the Hill equilibrium force Fmax fT(a) with fT' = 0 (tendon velocity
//   neglected, vM = vMT cos(alpha): a quasi-static tendon, not a rigid one: the tendon stretches
//   with the force as its curve says) and fT clamped to the NLP's [0, 5], linearised at the
//   previous pass's activation (0.05 first) by the implicit function theorem; GO_STATIC_PASSES
//   passes over all nodes (on the bundled trial the 3rd and 4th agree to 0.01 N m). fT is then
//   the equilibrium at the optimum a, fT' by periodic central differences over the nodes (so
//   the hill rows are not exactly zero: their fT' is not the 0 the equilibrium assumed).
// The residual penalty w_res (GO_STATIC_W_RES, 1/(N m)^2) keeps the problem solvable when the
// muscles cannot produce tau; where they can, the residual left at the optimum is
// |r| ~ a / (w_res |G R|), ~1e-4 N m for typical moment arms and strengths. Activations and
// excitations are set to the optimum a (e = a, adot = 0: the activation rows hold at the node).
// Afterwards: the last node (the first's phase) and the first get the mean of their a, e, fT
// (periodicity rows); the spring-held dofs' q are shifted by -eom_j / k_j (twice) so their
// joint springs balance the node's equation of motion with the model's contact and the guess's
// muscle forces (a few mm on the knee translations), their qdot, q', qddot re-differenced
// periodically over the nodes, and the ground reaction variables recomputed from the model's
// contact at the shifted q.
#define GO_STATIC_W_RES 100.0   // residual weight w_res (1/(N m)^2; 1/N^2 on slide dofs)
#define GO_STATIC_PASSES 4      // linearisation passes over all nodes (-)
#define GO_STATIC_A_MIN 0.001   // activation bounds (-), the problem's own
#define GO_STATIC_A_MAX 1.0

// One foot's ground reaction as a wrench: force (world, N) applied at point (world, m) plus a
// couple torque (world, N m), e.g. the measured force at the centre of pressure with the free
// moment about the vertical.
typedef struct {
  double force[3];   // (N)
  double point[3];   // (m)
  double torque[3];  // (N m)
} go_foot_wrench;

// Measured foot wrenches of node k (right, left; world frame, Z up) from grf (OpenSim
// ExternalLoads columns ground_force_<s>_v{x,y,z}, ground_force_<s>_p{x,y,z},
// ground_torque_<s>_{x,y,z}, Y up, converted (x, y, z) -> (x, -z, y) as go_gait does) linearly
// resampled at the node times t_0 + T k / (N - 1). w: 2 N wrenches. 0, or -1 with the reason.
int go_gait_measured_wrenches(const go_gait* g, const gsTable* grf, go_foot_wrench* w, char* err,
                              int errsz);

// Inverse dynamics of node variables z_k (physical) with the foot contact replaced by the
// wrenches w[0] (right foot), w[1] (left foot): tau (nv; N m for hinges, N for slides) is the
// generalized force the actuators must supply,
//   tau = qfrc_inverse(q, qdot, qddot) + qfrc_contact(q, qdot) - J_r^T w_r - J_l^T w_l,
// qfrc_contact the model's sphere contact (gs_physics_contact_passive; qfrc_inverse subtracts it
// as a passive force), J_s the Jacobian of the foot body carrying side s's contact spheres
// (calcn; the toes are welded to it in jw_fullbody, so the wrench is exact for the rigid foot).
// Muscles balance it when sum_i (-R_ij) F_i = tau_j (go_gait.h's eom rows with this contact).
// d from go_gait_model(g), scratch (go_gait_load_node runs). 0, or -1 when a foot has no spheres.
int go_gait_inverse_dynamics(const go_gait* g, mjData* d, const double* z_k,
                             const go_foot_wrench* w, double* tau);

// Bounded regularised least squares (the per-node static optimisation):
//   min_a  sum_i a_i^2 + w sum_j (sum_i B_ji a_i - c_j)^2,   lo <= a_i <= hi,
// B (m x n, row-major), c (m), w > 0. Primal active-set method on the strictly convex QP
// (Nocedal & Wright 2006, Algorithm 16.3; Cholesky of the free block each step): exact optimum
// in finitely many steps. a (n) receives the optimum. Returns the steps taken (>= 0), or -1 when
// the step limit (20 n + 20) was hit or out of memory (a then holds the last feasible iterate).
int go_static_opt_solve(int n, int m, const double* B, const double* c, double w, double lo,
                        double hi, double* a);

// 1 if dof j of model m is matched by the static optimisation (not a root dof, no joint
// spring, not one of the six-DOF implant knee's secondary dofs, which its contact surrogate and
// ligaments hold), else 0.
int go_static_dof_matched(const mjModel* m, int j);

// What the static guess found, over all nodes.
typedef struct {
  double max_residual;   // largest |r_j| over nodes and matched dofs          (N m or N)
  double rms_residual;   // root mean square of r_j over nodes and matched dofs (N m or N)
  double mean_activation;  // mean of a over nodes and muscles                  (-)
  int n_at_upper;        // node-muscle pairs with a at GO_STATIC_A_MAX         (-)
  int n_matched;         // matched dofs per node (J's size)                    (-)
  int steps;             // active-set steps, all nodes and passes              (-)
  int failed_nodes;      // nodes whose QP hit the step limit (their last iterate kept) (-)
} go_static_report;

// Fill z (N nz, physical) as described above from coords (as go_gait_guess_from_trial) and grf
// (measured ground reactions, as go_gait_measured_wrenches; the table go_gait_create read).
// report may be NULL. Returns 0, or -1 with the reason in err.
int go_gait_guess_static(const go_gait* g, const gsTable* coords, const gsTable* grf, double* z,
                         go_static_report* report, char* err, int errsz);

#endif  // GAITSIM_OPTIM_GO_GAIT_GUESS_H_
