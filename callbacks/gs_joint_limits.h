// gs_joint_limits.h: passive moments at the ends of a joint's range, the ligaments, capsule and
// soft tissue a joint's coordinate presses into near its limits (Anderson & Pandy 1999, Comput
// Methods Biomech Biomed Eng 2:201; the form and coefficients of Falisse et al. 2019, J R Soc
// Interface 16:20190402, their 3D model's getPassiveJointTorque):
//   tau(q) = k1 exp(k2 (q - theta2)) + k3 exp(k4 (q - theta1))      (N m; q in rad)
// theta1 < theta2 the two limits, k1 < 0 < k2 the upper limit's moment pushing q down, k3 > 0 >
// k4 the lower limit's pushing q up. Both terms are tiny inside the range (the knee's: 0.07 N m
// at q = 0, 1.4 N m at 5 deg of hyperextension, 113 N m at 12.4 deg).
// A model carries one MJCF numeric per limited hinge joint J:
//   <numeric name="gs_limit_J" size="6" data="k1 k2 k3 k4 theta1 theta2"/>
// (scripts/osim2mjcf.py writes them; mjmodels/README.md, "Joint-limit moments"). Models without
// such numerics get none.
#ifndef GAITSIM_CALLBACKS_GS_JOINT_LIMITS_H_
#define GAITSIM_CALLBACKS_GS_JOINT_LIMITS_H_

#include <mujoco/mujoco.h>

#define GS_JOINT_LIMIT_PREFIX "gs_limit_"  // numeric name prefix; the joint's name follows
#define GS_JOINT_LIMIT_SIZE 6              // k1 k2 k3 k4 theta1 theta2

// The moment of one limit law (N m) at q (rad) with k = {k1, k2, k3, k4} and theta = {theta1,
// theta2}; *dtau_dq (N m/rad) when not NULL.
double gs_joint_limit_moment(const double k[4], const double theta[2], double q, double* dtau_dq);

// Check every gs_limit_ numeric of m: its joint exists and is a hinge, size 6, finite values,
// k1 <= 0 <= k2, k3 >= 0 >= k4, theta1 < theta2. Returns the number of limited joints, or -1
// with the reason in err.
int gs_joint_limits_check(const mjModel* m, char* err, int errsz);

// Add every limited joint's moment to d->qfrc_passive (mjcb_passive; needs qpos only).
void gs_joint_limits_passive(const mjModel* m, mjData* d);

#endif  // GAITSIM_CALLBACKS_GS_JOINT_LIMITS_H_
