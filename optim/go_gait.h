// go_gait.h: the gait collocation problem (DESIGN.md, "Formulation choices") on the engine
// (go_collocation.h): full-body, muscle-driven, implicit multibody dynamics, one stride.
//
// Node variables z_k = [x | xdot | u] (go_collocation.h), with
//   x    = [q (nv) | qdot (nv) | a (na) | fT (ne)]      coordinates (rad, m), speeds, activations,
//                                                       normalised tendon forces of the ne
//                                                       elastic-tendon muscles
//   xdot = [q' (nv) | qddot (nv) | adot (na) | fT' (ne)]
//   u    = [e (na) | grf (6 or 12)]                     excitations; ground reaction of the right
//                                                       then left foot, world frame: forces (N, 6)
//                                                       then, with w_grm > 0, moments about the
//                                                       world origin (N m, 6)
// The engine's state derivative of q is a separate variable q' from the state qdot: path rows
// qdot - q' = 0 tie them (linear, analytic -1 column; the qdot column is finite-differenced with
// the others and is exact since the row is linear). We chose these rows over a deriv_idx map in
// the engine because the engine is done and tested; they cost nv rows and 2 nv nonzeros per node.
//
// Path rows per node,
//   [link (nv) | eom (nv) | hill (ne) | act (na) | grf (6|12) | fibre (na)? | walk (1)?]:
//   link  qdot - q'                                                        (rad/s, m/s)
//   eom   mj_inverse(q, qdot, qddot).qfrc_inverse + actuator_moment^T tension    (N m, N)
//         (qfrc_inverse runs mjcb_passive: the foot contact; all nv rows, pelvis included: no
//         residual actuators; mj_inverse's constraint stage is off in the private model copy,
//         joint ranges are variable bounds instead)
//   hill  gs_muscle_equilibrium_residual(a, lMT, vMT, fT, fT') for each elastic muscle     (-)
//   act   adot - gs_activation_dot(e, a)                                             (1/s)
//   grf   grf - gs_physics_foot_grf(q, qdot).force, per foot                           (N)
//         then grf moment - gs_physics_foot_grf(q, qdot).moment (about the world origin:
//         r_cop x F + free moment; tracking it is tracking the centre of pressure weighted by
//         the force, and so the feet's placement)                                     (N m)
//   fibre (only with opts.fibre_bounds) fibre_lo <= lM / lopt <= fibre_hi for every muscle,
//         default 0.25 and 1.5 (Lin, Walter & Pandy 2018, eq. 2's bounds on the normalised fibre
//         length): lM = gs_muscle_fibre_length(lMT(q), lT) with lT = lts
//         gs_muscle_ft_inverse(fT) for an elastic tendon, lT = lts for a rigid one          (-)
//         Inequalities; off for tracking, on in `gaitsim predict` (--no-fibre-bounds).
//   walk  (only with opts.min_vgrf > 0) grf_r,z + grf_l,z >= min_vgrf m g: the summed vertical
//         ground reaction of both feet at every node, an inequality that rules out flight
//         phases, so the predicted gait is a walk (a definition of walking, not in the paper;
//         `gaitsim predict --min-vgrf`)                                                   (N)
// Tension: elastic Fmax fT; rigid gs_muscle_rigid_force(a, lMT, vMT).
//
// Derivatives: analytic columns q' (-1), qddot (mass matrix M from mj_fullM after mj_inverse),
// a (rigid: moment dF/da; act row), fT (moment Fmax; hill row; fibre row
// -cos(alpha) lts dlT_norm/dfT / lopt), adot, fT', e, grf. Central
// differences for the q and qdot columns only (2 nv colour groups, the eom rows being dense in
// them). Pattern per node: eom rows dense in q and qdot; qddot columns of the eom rows where the
// two dofs are on one branch of the kinematic tree (M's structure); a muscle's eom rows, and its
// hill row's q and qdot columns, are the coordinates it crosses: |actuator_moment| > 1e-9 at any
// of the trial poses or at 64 random poses around them (+-0.35 rad, +-0.03 m on every
// coordinate, fixed seed): the perturbations are the safety margin for moment arms that vanish at
// some poses (wrapping). Grf rows: q and qdot of the dofs on the path from the world to the
// foot's contact spheres. Fibre rows: the q columns of the dofs the muscle crosses and, elastic,
// its fT column.
//
// Scaling (Ipopt sees O(1)): q 1, qdot and q' 5, qddot 50, a and e 1, adot 20, fT 1, fT' 10,
// grf m g (forces) and m g * 1 m (moments); rows: link 5, eom m g * 1 m (N m; N for slides), hill 1,
// act 20, grf as their variables, walk m g; periodicity
// fibre 1 (lM / lopt is O(1)); rows as their variable, speed row 1 m/s; objective 1.
//
// Objective J = I / T, I = trapezoidal integral of (means over each group of terms)
//   w_pelvis_rot ((q - q_meas)/5 deg)^2 + w_pelvis_trans ((q - q_meas)/2 cm)^2
//   + w_joint ((q - q_meas)/(5 deg or 2 cm))^2 + w_grf ((grf - grf_meas)/(0.1 m g))^2
//   + w_grm ((M - M_meas)/(0.1 m g x GO_GAIT_GRM_LENGTH))^2   (the "grf" goal; the mean over
//     its 6 force and 6 moment components)
//   + w_effort e^2 + w_accel (qddot / GO_GAIT_ACCEL_SCALE)^2
// over the coordinates present in the measured table (pelvis: the dofs of the root body; accel:
// every dof), with an analytic gradient and the exact diagonal Hessian (integrand_hess, for the
// Gauss-Newton option). The acceleration term (issue #5) is a smoothness regularisation of the
// predictive problem; its scale is qddot's variable scale below. With w_cot > 0 the integrand
// gains w_cot Edot / (m V) (J = w_cot COT + ...; its gradient by the chain rule through each
// actuator's length and velocity and the moment arms' derivative along qdot, with central
// differences of the muscle model in e, a, fT, l and v; no Hessian term).
// go_gait_objective_terms splits J into these goals.
//
// Boundary: periodicity of every state but pelvis_tx (and the coordinates named in free_coords),
// and of the excitations; optionally mean speed (tx_last - tx_first) / T = speed.
// Bounds: a, e in [0.001, 1]; fT in [0, 5]; q within joint ranges (limited joints), root dofs
// within the measured range +- 0.5 rad / 0.5 m, others +-pi; qdot, q' +-20; qddot +-500;
// adot +-1000; fT' +-1000; grf +-10 m g (forces), +-10 m g x 1 m (moments).
//
// Threads: one mjData (the model's nuserdata) per engine worker; results are bitwise identical
// for any number of threads (the engine's rule).
#ifndef GAITSIM_OPTIM_GO_GAIT_H_
#define GAITSIM_OPTIM_GO_GAIT_H_

#include <mujoco/mujoco.h>

#include "io/gs_table.h"
#include "optim/go_collocation.h"
#include "optim/go_hessian.h"

#define GO_GAIT_NGRF 12  // most grf variables per node (layout ngrf): force right x y z, left
                         // x y z (world, N), then moment about the world origin right x y z,
                         // left x y z (N m); go_gait_grf_ref has all 12
#define GO_GAIT_GRM_OFFSET 6     // first moment among the grf variables
#define GO_GAIT_GRM_LENGTH 0.1   // lever of the moment goal's scale (m): a moment error of
                                 // 0.1 m g x 0.1 m (a 1 cm centre-of-pressure error at 1 BW)
                                 // weighs as a force error of 0.1 m g
#define GO_GAIT_ACCEL_SCALE 50.0  // s_j of the acceleration goal (rad/s^2, m/s^2): qddot's scale

// goals of J (go_gait_objective_terms), in this order; names in GO_GAIT_TERM_NAMES
enum { GO_GAIT_TERM_PELVIS, GO_GAIT_TERM_JOINTS, GO_GAIT_TERM_GRF, GO_GAIT_TERM_EFFORT,
       GO_GAIT_TERM_COT, GO_GAIT_TERM_ACCEL, GO_GAIT_NTERMS };
#define GO_GAIT_TERM_NAMES {"pelvis", "joints", "grf", "effort", "cot", "accel"}

// Options of the gait problem; go_gait_opts_default fills them.
typedef struct {
  int N;                            // nodes (>= 2)
  int nthreads;                     // engine workers (>= 1)
  double T;                         // stride time (s); <= 0: the coordinate table's time span
  const gsTable* coords;            // measured coordinates, radians, model names (NULL: none)
  const gsTable* grf;               // measured ground reactions, OpenSim ExternalLoads names and
                                    // frame (Y up), same time base as coords (NULL: none)
  double w_pelvis_rot;              // weight of pelvis rotation tracking                 (-)
  double w_pelvis_trans;            // weight of pelvis translation tracking              (-)
  double w_joint;                   // weight of the other coordinates                    (-)
  double w_grf;                     // weight of ground reaction force tracking           (-)
  double w_grm;                     // weight of ground reaction moment tracking (about the
                                    // world origin: centre of pressure x force)          (-)
  double w_effort;                  // weight of the mean squared excitation              (-)
  double w_accel;                   // weight of the mean over all nv dofs of
                                    // (qddot_j / GO_GAIT_ACCEL_SCALE)^2; 0: none         (-)
  int periodic;                     // 1: periodicity boundary rows
  const char* const* free_coords;   // NULL-terminated coordinates left out of periodicity
                                    // besides pelvis_tx (NULL: none)
  double speed;                     // > 0: mean forward speed constraint                (m/s)
  // prediction (Lin, Walter & Pandy 2018, eqs. 1-3)
  double w_cot;                     // > 0: cost-of-transport goal weight: the integrand gains
                                    // w_cot Edot / (m g V) ... see go_gait_cot             (-)
  int free_time;                    // 1: stride time T is a variable in [T_lb, T_ub]
  double T_lb, T_ub;                // bounds of T (s); equal: T held fixed (Ipopt fixes it)
  const double* band_z;             // NULL, or node variables (N nz, physical) of the solution
                                    // the band of eq. 3 is centred on (the tracking solution);
                                    // the band is intersected with the joint ranges (the range
                                    // alone where a centre lies more than the half-width out)
  const double* band_q;             // half-width per dof of the coordinate band (nv; <= 0: none)
  const double* band_qd;            // half-width per dof of the speed band (nv; <= 0: none)
  int fibre_bounds;                 // 1: fibre path rows fibre_lo <= lM/lopt <= fibre_hi (eq. 2)
  double fibre_lo, fibre_hi;        // bounds of the normalised fibre length lM / lopt     (-)
  double min_vgrf;                  // > 0: the walk row, summed vertical ground reaction of
                                    // both feet >= min_vgrf m g at every node; 0: none (BW)
  double metabolic_smoothing;       // factor on every width of gs_umberger_smoothing_default
                                    // (the smooth steps and max/min of the cost; eps_a kept) (-)
} go_gait_opts;

// Where everything sits in z_k and in the path rows of a node.
typedef struct {
  int nv;        // degrees of freedom (nq == nv)
  int na;        // muscles (activations, excitations)
  int ne;        // elastic-tendon muscles
  int nx;        // states, 2 nv + na + ne
  int nz;        // node variables, 2 nx + na + ngrf
  int n_path;    // path rows, 2 nv + ne + na + ngrf (+ na with fibre bounds)
  int x_q, x_qd, x_a, x_ft;        // offsets of q, qdot, a, fT in z_k
  int xd_q, xd_qdd, xd_a, xd_ft;   // offsets of q', qddot, adot, fT'
  int u_e, u_grf;                  // offsets of excitations and grf variables
  int ngrf;                        // grf variables (and rows): GO_GAIT_GRM_OFFSET (forces) or,
                                   // with w_grm > 0, GO_GAIT_NGRF (forces and moments)
  int r_link, r_eom, r_hill, r_act, r_grf;  // offsets of the path row blocks
  int r_fib;                       // offset of the fibre rows (na), -1 without fibre bounds
  int r_walk;                      // the walk row (1), -1 without min_vgrf
  const int* elastic;              // actuator of elastic muscle e (ne)
  const int* elastic_of;           // elastic index of actuator i, -1 if rigid (na)
  int tx;                          // dof of pelvis_tx, -1 if none
} go_gait_layout;

typedef struct go_gait go_gait;

// defaults: N GO_NODES_TRACK (go_defaults.h), 1 thread, T from coords, w_pelvis_rot 1,
// w_pelvis_trans 1, w_joint 1, w_grf 1, w_grm 0, w_effort 0.1, w_accel 0, periodic 1, no free
// coordinates, no speed constraint; no prediction (w_cot 0, fixed time, no band, no fibre
// bounds; fibre_lo 0.25, fibre_hi 1.5; min_vgrf 0)
void go_gait_opts_default(go_gait_opts* opts);

// Build the problem for model m (prepared by gs_physics_prepare; every actuator must be a gaitsim
// muscle with an activation state). m is copied (the copy has MuJoCo's constraint stage off);
// coords and grf are read here and not kept. Returns 0 and *out (free with go_gait_free), or -1
// with the reason in err.
int go_gait_create(go_gait** out, const mjModel* m, const go_gait_opts* opts, char* err,
                   int errsz);
void go_gait_free(go_gait* g);

// the collocation NLP (owned by g), its layout, and the private model copy
go_nlp* go_gait_nlp(go_gait* g);
const go_gait_layout* go_gait_layout_get(const go_gait* g);
const mjModel* go_gait_model(const go_gait* g);
int go_gait_nodes(const go_gait* g);
int go_gait_threads(const go_gait* g);     // engine workers
double go_gait_stride_time(const go_gait* g);
double go_gait_weight(const go_gait* g);   // body weight m g (N)

// 1 if dof j belongs to the root body (the pelvis: the body of the tree's first dof), else 0.
int go_gait_dof_is_root(const mjModel* m, int j);

// Hessian elements of one node for the partitioned quasi-Newton Hessian (go_hessian.h): the
// dynamics (eom and grf rows), one per elastic tendon (hill row), one per muscle (activation row).
const go_elements* go_gait_elements(const go_gait* g);

// Stride time (s) of the NLP point z (N nz [+ 1], physical): the variable T with free time.
double go_gait_time_of(const go_gait* g, const double* z);

// Cost of transport J (J / (kg m)) of the physical point z: the trapezoidal integral of the
// muscles' smooth Umberger 2010 metabolic power over the stride divided by the body mass and the
// pelvis_tx displacement (Lin, Walter & Pandy 2018, eq. 1). NAN without pelvis_tx.
double go_gait_cot(const go_gait* g, const double* z);

// Goals of J at the physical point z (N nz [+ 1]): terms[GO_GAIT_NTERMS] (order of the
// GO_GAIT_TERM_* enum: pelvis rotation and translation tracking, other coordinates, grf, effort,
// cost of transport (w_cot E / (m V T): w_cot COT when the speed row holds), acceleration), each
// the trapezoidal integral of its part of the integrand over T, so they sum to J (the tracking
// goals, whatever go_gait_set_proximal says).
// 0, or -1 when a value is not finite.
int go_gait_objective_terms(const go_gait* g, const double* z, double* terms);

// Normalised fibre lengths lM / lopt (na, -) of node variables z_k (physical) as the fibre rows
// compute them (with or without fibre bounds), d as scratch (go_gait_load_node runs).
void go_gait_fibre_lengths(const go_gait* g, mjData* d, const double* z_k, double* lm_norm);

// Feasibility polish: with z0 (N nz, physical; copied) the objective becomes the proximal term
// sum_k w_k h sum_j ((z_kj - z0_kj) / z_scale_j)^2 / T instead of the tracking goals, so a solve
// (best with the Gauss-Newton Hessian, exact for this objective, go_ipopt_opts.gauss_newton)
// finds the dynamically consistent point nearest to z0; its multipliers are of the order of z0's
// violation, so the missing constraint curvature hardly matters. z0 NULL restores the tracking
// goals. 0, or -1 when out of memory.
int go_gait_set_proximal(go_gait* g, const double* z0);

// Measured coordinate at node k, dof j (physical), or NAN when not measured.
double go_gait_q_ref(const go_gait* g, int k, int j);
// Measured ground reaction at node k, component c (world, N, GO_GAIT_NGRF), or NAN.
double go_gait_grf_ref(const go_gait* g, int k, int c);

// Load node variables z_k (physical) into d (qpos, qvel, qacc, act, ctrl, userdata) and run
// mj_inverse: afterwards d holds the node's kinematics, contact and inverse dynamics (for
// writing tables). d must come from go_gait_model(g).
void go_gait_load_node(const go_gait* g, mjData* d, const double* z_k);

// Path rows of node k at physical z_k into res (n_path), with d as scratch. 0, or -1 when a value
// is not finite.
int go_gait_path_eval(const go_gait* g, mjData* d, const double* z_k, double* res);

// Evaluations of the path rows or their analytic columns, summed over the workers since
// go_gait_create, that reused the worker's position stage (MuJoCo's kinematics, tendon paths,
// moment arms and mass matrix) because the node's coordinates were bitwise those of the previous
// evaluation: finite differences in anything but q
long go_gait_position_reuses(const go_gait* g);

#endif  // GAITSIM_OPTIM_GO_GAIT_H_
