// gs_coupling.h: coordinate couplings (OpenSim CoordinateCouplerConstraint) written in the MJCF as
// MuJoCo joint equalities, <equality><joint joint1="F" joint2="D" polycoef="a0 a1 a2 a3 a4"/>:
// the follower joint F is held at
//   q_F - q0_F = a0 + a1 x + a2 x^2 + a3 x^3 + a4 x^4,  x = q_D - q0_D   (MuJoCo's definition;
//   q0 the joints' qpos0, i.e. their ref).
// JW's right patella follows the femoral component, turning with knee_flexion about the same
// femoral axis (patfem_flexion = knee_flexion + pi/2 in the .osim; mjmodels/README.md).
//
// Stock MuJoCo enforces such an equality with its constraint solver. gaitsim turns that solver off
// wherever it evaluates the dynamics implicitly (collocation and inverse dynamics run mj_inverse
// with the constraint stage off), so gs_physics_prepare hands every active joint equality to this
// module instead (gs_coupling_adopt: MuJoCo's copy disabled, the equality marked as gaitsim's), and
// mjcb_passive holds it with a stiff spring-damper on the residual r = q_F - target(q_D):
//   V = k r^2 / 2,  Q_F = -(k r + c r'),  Q_D = +(k r + c r') dtarget/dq_D
// (the generalised forces of the penalty; they do no net work on a rigid coupling).
// k = GS_COUPLING_STIFFNESS, c = GS_COUPLING_DAMPING. With the quadriceps pulling up to 3 kN on
// a 5 cm arm about the patella's hinge, the follower then lags its target by at most 1.5 mrad.
#ifndef GAITSIM_CALLBACKS_GS_COUPLING_H_
#define GAITSIM_CALLBACKS_GS_COUPLING_H_

#include <mujoco/mujoco.h>

#define GS_COUPLING_STIFFNESS 1e5  // penalty stiffness k (N m/rad for hinges, N/m for slides)
#define GS_COUPLING_DAMPING 50.0   // penalty damping c (N m s/rad, N s/m); c / k = 0.5 ms
#define GS_COUPLING_MARK 5         // eq_data slot (unused by joint equalities) that marks an
                                   // equality adopted by gaitsim: 1

// Adopt every active joint equality between two hinge or slide joints of m: disable MuJoCo's
// copy (eq_active 0) and mark it (eq_data[GS_COUPLING_MARK] = 1). Returns the number adopted, or
// -1 with the reason in err for a joint equality gaitsim cannot hold (a single-joint equality, a
// ball or free joint).
int gs_coupling_adopt(mjModel* m, char* err, int errsz);

// Number of adopted couplings of m; gs_coupling_get gives the c-th one's follower and driver
// joint ids (0 <= c < count).
int gs_coupling_count(const mjModel* m);
void gs_coupling_get(const mjModel* m, int c, int* follower, int* driver);

// Target of the c-th coupling's follower for driver value qd (qpos), and its derivative d
// target / d qd (NULL: not wanted).
double gs_coupling_target(const mjModel* m, int c, double qd, double* slope);

// Penalty forces of every adopted coupling added to d->qfrc_passive (mjcb_passive; needs qpos
// and qvel only).
void gs_coupling_passive(const mjModel* m, mjData* d);

// 1 when joint jnt is the follower of a joint equality, adopted or still MuJoCo's (active): a
// coordinate a pose file may leave out, held by the coupling rather than by muscles.
int gs_coupling_joint_follows(const mjModel* m, int jnt);

// Put every coupled follower whose value is not given on its target: qpos (nq) from the driver's
// qpos, and qvel (nv; may be NULL) from the driver's speed. given_qpos (nq, may be NULL: none
// given) and given_qvel (nv, may be NULL) are per-address flags or column indices, >= 0 where the
// caller set the value itself (gsStateMap's columns), < 0 where it did not.
void gs_coupling_follow(const mjModel* m, mjtNum* qpos, mjtNum* qvel, const int* given_qpos,
                        const int* given_qvel);

#endif  // GAITSIM_CALLBACKS_GS_COUPLING_H_
