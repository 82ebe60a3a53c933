// gs_balance.h: the frontal-plane balance of a gait at one instant, by MuJoCo's rigid-body
// dynamics under given ground reactions (issue 20, stance width): where each foot's centre of
// pressure lies against its hip centre and the whole-body centre of mass, the net hip abduction
// moment by inverse dynamics, the whole-body angular momentum about the centre of mass, the ground
// reaction's moment about it, and the trunk's sway.
//
// Inverse dynamics (Winter 2009, Biomechanics and Motor Control of Human Movement, ch. 5, in
// generalised coordinates):
//   tau = M(q) qdd + c(q, qd) - sum_feet J_foot(q, p)^T [F; T]                        (N, N m)
// M from mj_crb (d->qM), c = d->qfrc_bias (Coriolis, centrifugal, gravity), J^T by mj_applyFT at
// the centre of pressure p on the foot's body (the body of its contact spheres). tau is the net
// generalised force the muscles and passive tissues must supply; gaitsim's own contact and muscle
// forces (qfrc_passive, actuator forces) are not used, so measured and simulated ground reactions
// are treated alike. Its first six entries (pelvis_tx ... pelvis_ry) are the residual: zero for a
// dynamically consistent motion and load.
// Angular momentum about the whole-body centre of mass: MuJoCo's subtree_angmom of the root body
// (mj_subtreeVel: sum of I_i w_i + m_i (c_i - C) x (v_i - V) over the bodies).
// Frames: the model world is Z up, x forward (the direction of progression), y to the left
// (mjmodels/README.md). "Lateral" is away from the midline: -y for the right foot, +y for the
// left. The frontal plane is y-z; its moments and momenta are the x components.
#ifndef GAITSIM_CALLBACKS_GS_BALANCE_H_
#define GAITSIM_CALLBACKS_GS_BALANCE_H_

#include <mujoco/mujoco.h>

#include "callbacks/gs_state.h"
#include "io/gs_table.h"

// One foot's ground reaction in the model world: force (N), centre of pressure (m), free moment
// (N m). loaded 0: no load (force ignored).
typedef struct gsFootLoad_ {
  double force[3];
  double cop[3];
  double torque[3];
  int loaded;
} gsFootLoad;

// What gs_balance_eval needs of the model, found by name once.
typedef struct gsBalanceSpec_ {
  int root_body;        // the body all moving bodies hang from (pelvis)
  int foot_body[2];     // right, left: the body of the foot's first contact sphere (calcaneus)
  int hip_joint[2];     // right, left: hip_adduction, hip_adduction_l
  int trunk_body;       // torso
  int lumbar_bending;   // joint lumbar_bending, -1 when absent
  int knee_adduction[2];  // right, left: joint knee_adduction(_l), -1 when absent (1-DOF knee)
  int ankle_joint[2];     // right, left: ankle_angle(_l) (the shank's lower end), -1 when absent
} gsBalanceSpec;

// The balance at one instant (index 0 right, 1 left).
typedef struct gsBalance_ {
  double com[3];                // whole-body centre of mass (m, world)
  double angmom[3];             // whole-body angular momentum about the CoM (N m s, world)
  double grf_moment[3];         // the ground reactions' moment about the CoM (N m, world)
  double cop_lateral_hip[2];    // centre of pressure minus hip centre, lateral (m), NAN unloaded
  double cop_lateral_com[2];    // centre of pressure minus CoM, lateral (m), NAN unloaded
  double hip_adduction_moment[2];  // net moment about hip_adduction (N m; > 0 adducts, so the
                                   // abductors supply its negative)
  double knee_adduction_moment[2];  // net moment about knee_adduction(_l) (N m, about the joint's
                                    // own axis), NAN without the joint: what the knee's contact,
                                    // ligaments and muscles supply together
  // The ground reaction's part of knee_adduction_moment and its pieces in the knee's own frame
  // (NAN without the joint, the ankle or a load): a, the knee_adduction axis; u, the shank's
  // long axis (ankle centre to knee centre, made normal to a); l, the knee's lateral axis, normal
  // to both and pointing away from the midline. With r = centre of pressure - knee centre (the
  // joint's anchor) and F the foot's ground reaction:
  //   knee_grf_moment = -(J^T [F; T])_knee = s (a . (r x F) + a . T),  s = +-1 the sign of the
  //   net moment's convention, and a . (r x F) = +-(r_u F_l - r_l F_u)
  // so the moment is the axial force F_u times the centre of pressure's lateral offset r_l, plus
  // the force along the lateral axis F_l times the height r_u (about -0.5 m).
  double knee_grf_moment[2];      // the ground reaction's part of the net moment (N m)
  double cop_lateral_knee[2];     // r_l: centre of pressure lateral of the knee centre (m)
  double knee_lateral_force[2];   // F_l: ground reaction along the knee's lateral axis (N)
  double knee_axial_force[2];     // F_u: ground reaction along the shank, upward (N)
  double knee_lateral_tilt[2];    // asin(l_z): the knee's lateral axis against the floor (rad;
                                  // > 0 its lateral end up, as when the leg is abducted: the
                                  // axial force then has a lateral part, F_l ~ F_u tilt)
  // the centre of pressure in its foot's frame (the body of the foot's contact spheres: its
  // origin; its x axis forward, z axis lateral, each signed to point so in the world), NAN
  // unloaded (m)
  double cop_foot_forward[2];
  double cop_foot_lateral[2];
  double trunk_lateral;         // trunk's CoM minus the whole-body CoM along y (m, + left)
  double lumbar_bending;        // lumbar_bending (rad), NAN when absent
  double residual_force[3];     // tau of pelvis_tx, _ty, _tz (N; slide axes, world)
  double residual_moment[3];    // tau of pelvis_rz, _rx, _ry (N m; about the hinge axes)
} gsBalance;

// Find the bodies and joints of spec in m. 0, or -1 with the missing name in err (a model
// without foot contact spheres, hip_adduction(_l), pelvis or torso).
int gs_balance_spec(const mjModel* m, gsBalanceSpec* spec, char* err, int errsz);

// The balance at d's qpos, qvel and the accelerations qacc (nv), with the ground reactions
// load[2] (right, left). Runs MuJoCo's position and velocity stages and mj_subtreeVel on d
// (d->qacc is overwritten).
void gs_balance_eval(const mjModel* m, mjData* d, const gsBalanceSpec* spec, const double* qacc,
                     const gsFootLoad load[2], gsBalance* out);

// As gs_balance_eval, and the whole net generalised force tau (nv; N or N m, the pelvis's six
// entries the residuals) into tau_out when not NULL: M qdd + c - sum J^T [F; T].
void gs_balance_eval_tau(const mjModel* m, mjData* d, const gsBalanceSpec* spec,
                         const double* qacc, const gsFootLoad load[2], gsBalance* out,
                         double* tau_out);

// The columns of a ground reaction table (gs_grf_labels' 18 names, e.g. a grf.mot) into col.
// 0, or -1 with the missing name in err.
int gs_balance_grf_columns(const gsTable* g, int col[GS_GRF_NCOL], char* err, int errsz);

// Both feet's loads at time (s; the table interpolated linearly, in the model world), each
// loaded when its vertical force exceeds stance_n (N).
void gs_balance_loads_at(const gsTable* g, const int col[GS_GRF_NCOL], double time,
                         double stance_n, gsFootLoad load[2]);

// An OpenSim ground-frame vector (Y up, Z right) in the model world (Z up, Y left):
// (x, y, z)_world = (x, -z, y)_OpenSim.
void gs_balance_from_opensim(const double os[3], double world[3]);

#endif  // GAITSIM_CALLBACKS_GS_BALANCE_H_
