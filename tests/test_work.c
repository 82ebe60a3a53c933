// test_work.c: the mechanical power budget (callbacks/gs_work.h) on jw_fullbody_knee6, the whole
// model with every source present (muscles with elastic tendons, foot spheres, the implant knee,
// joint limits, the patella's coupling, MuJoCo's joint damping):
// (a) at one state the pieces add up: the muscle-tendon units' power equals qfrc_actuator . qdot
//     (1e-9 relative), the passive pieces qfrc_passive . qdot (1e-9), each unit's contractile,
//     passive-fibre and tendon parts its whole (by construction of the tendon part: checked that
//     the tendon's power is -F_T vT of the tendon alone, 1e-6 of the unit's power scale); the
//     muscles' power by coordinate sums to the units' (1e-9), and the coordinates of each leg
//     belong to its foot, the pelvis's and the trunk's to neither;
// (b) the energy theorem at one state (the body lowered 1 cm into the floor, every dof moving,
//     every muscle at activation 0.2): d/dt (KE + PE) by central differences along the state's
//     own motion equals the budget's total within 1e-6 of the sum of the sources' magnitudes,
//     and the foot contact, the knee and MuJoCo's joint damping (50 N m s/rad put on
//     knee_adduction and knee_rotation here: the shipped model has none) each work more than
//     that tolerance, so leaving any out fails the check; the feet's friction takes energy (< 0) and
//     with their normal forces' power makes up the feet's (1e-9).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "app/gs_app_model.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_work.h"
#include "tests/gs_test.h"

static double passive_sum(const gsPowers* p) {
  return p->foot_pos + p->foot_neg + p->knee + p->joint_limits + p->couplings +
         p->mujoco_passive;
}

int main(void) {
  mjModel* m = gs_app_load_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml");
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  mjData* d = mj_makeData(m);
  int key = mj_name2id(m, mjOBJ_KEY, "standing");
  EXPECT_TRUE(key >= 0);
  mj_resetDataKeyframe(m, d, key >= 0 ? key : 0);
  d->qpos[2] += 0.03;  // pelvis_ty is the third coordinate: drop from 3 cm
  for (int i = 0; i < m->nu; i++) d->ctrl[i] = 0.2;
  for (int i = 0; i < m->na; i++) d->act[i] = 0.2;
  mj_fwdPosition(m, d);
  gs_physics_equilibrate_tendons(m, d, NULL);

  // (a) one state with velocities: a few steps in
  m->opt.timestep = 2e-5;
  mjtNum* fT_dot = (mjtNum*)calloc((size_t)m->nu, sizeof(mjtNum));
  for (int k = 0; k < 200; k++) EXPECT_EQ_INT(0, gs_physics_step(m, d, fT_dot));
  mj_forward(m, d);
  gsPowers p;
  gs_work_powers(m, d, &p);
  double act = mju_dot(d->qfrc_actuator, d->qvel, m->nv);
  double pas = mju_dot(d->qfrc_passive, d->qvel, m->nv);
  EXPECT_NEAR(act, p.mtu_pos + p.mtu_neg + p.other_actuators, 1e-9 * (1 + fabs(act)));
  EXPECT_NEAR(pas, passive_sum(&p), 1e-9 * (1 + fabs(pas)));
  EXPECT_TRUE(p.mtu_pos > 0 && p.mtu_neg < 0);
  double tendon = 0, scale = 0;
  for (int i = 0; i < m->nu; i++) {
    if (!gs_actuator_is_gaitsim_muscle(m, i)) continue;
    gsMuscleOut mo;
    double f = gs_physics_muscle_tension(m, d, i, &mo);
    tendon += -f * mo.vT;
    scale += fabs(f * d->actuator_velocity[i]);
  }
  EXPECT_NEAR(tendon, p.tendon, 1e-6 * scale);
  // the muscles' power by coordinate adds up to the units' power, and each coordinate belongs
  // to the foot below it
  double* dof = (double*)calloc((size_t)m->nv, sizeof(double));
  gs_work_dof_muscle_powers(m, d, dof);
  double dof_sum = 0;
  for (int k = 0; k < m->nv; k++) dof_sum += dof[k];
  EXPECT_NEAR(p.mtu_pos + p.mtu_neg, dof_sum, 1e-9 * scale);
  free(dof);
  const char* sides[][2] = {{"knee_flexion", "r"}, {"ankle_angle_l", "l"}, {"pelvis_tx", ""},
                            {"lumbar_bending", ""}, {"hip_flexion", "r"}};
  for (int k = 0; k < 5; k++) {
    int j = mj_name2id(m, mjOBJ_JOINT, sides[k][0]);
    EXPECT_TRUE(j >= 0);
    if (j >= 0) EXPECT_EQ_INT(sides[k][1][0], gs_work_dof_side(m, m->jnt_dofadr[j]));
  }

  // (b) the energy theorem at one state: d/dt (KE + PE) by central differences along the
  // state's own motion (q +- eps qdot, qdot +- eps qdd, with qdd from mj_forward) against the
  // budget's total. Velocities on every dof so that every source works; the feet pressed in;
  // MuJoCo's joint damping on two knee dofs, so that its power is a source too.
  const char* damped[] = {"knee_adduction", "knee_rotation"};
  for (int k = 0; k < 2; k++) {
    int j = mj_name2id(m, mjOBJ_JOINT, damped[k]);
    EXPECT_TRUE(j >= 0);
    if (j >= 0) m->dof_damping[m->jnt_dofadr[j]] = 50.0;
  }
  mj_resetDataKeyframe(m, d, key >= 0 ? key : 0);
  mj_kinematics(m, d);
  int vertical = 0;  // the pelvis translation whose world axis is the most nearly vertical
  for (int j = 0; j < 3; j++)
    if (fabs(d->xaxis[3 * j + 2]) > fabs(d->xaxis[3 * vertical + 2])) vertical = j;
  d->qpos[m->jnt_qposadr[vertical]] -= 0.01 / d->xaxis[3 * vertical + 2];
  for (int k = 0; k < m->nv; k++) d->qvel[k] = 0.3 * sin(1.0 + k);
  for (int i = 0; i < m->na; i++) d->act[i] = 0.2;
  mj_fwdPosition(m, d);
  gs_physics_equilibrate_tendons(m, d, NULL);
  mj_forward(m, d);
  gs_work_powers(m, d, &p);
  double total = gs_work_total(&p), eps = 1e-6, e[2];
  mjtNum* q0 = (mjtNum*)malloc(sizeof(mjtNum) * (size_t)m->nq);
  mjtNum* v0 = (mjtNum*)malloc(sizeof(mjtNum) * (size_t)m->nv);
  mjtNum* a0 = (mjtNum*)malloc(sizeof(mjtNum) * (size_t)m->nv);
  mju_copy(q0, d->qpos, m->nq);
  mju_copy(v0, d->qvel, m->nv);
  mju_copy(a0, d->qacc, m->nv);
  for (int s = 0; s < 2; s++) {
    double sign = s ? 1.0 : -1.0;
    mju_copy(d->qpos, q0, m->nq);
    mj_integratePos(m, d->qpos, v0, sign * eps);
    for (int k = 0; k < m->nv; k++) d->qvel[k] = v0[k] + sign * eps * a0[k];
    mj_forward(m, d);
    gsPowers ps;
    gs_work_powers(m, d, &ps);
    e[s] = ps.kinetic + ps.potential;
  }
  double rate = (e[1] - e[0]) / (2 * eps);
  double size = fabs(p.mtu_pos) + fabs(p.mtu_neg) + fabs(p.foot_pos) + fabs(p.foot_neg) +
                fabs(p.knee) + fabs(p.joint_limits) + fabs(p.couplings) +
                fabs(p.mujoco_passive) + fabs(p.constraint);
  printf("energy rate by differences %.6f W, budget %.6f W (muscles %.3f, feet %.3f, knee %.3f, "
         "limits %.3f, couplings %.3f, MuJoCo passive %.3f, constraint %.3f, gravity %.3f)\n",
         rate, total, p.mtu_pos + p.mtu_neg, p.foot_pos + p.foot_neg, p.knee, p.joint_limits,
         p.couplings, p.mujoco_passive, p.constraint, p.gravity);
  EXPECT_NEAR(rate, total, 1e-6 * size);
  // every source large enough that leaving it out would fail the check above
  EXPECT_TRUE(fabs(p.foot_pos + p.foot_neg) > 1e-3 * size);
  EXPECT_TRUE(fabs(p.knee) > 1e-4 * size);
  EXPECT_TRUE(fabs(p.mujoco_passive) > 1e-4 * size);
  // friction only takes energy (the smoothed Coulomb law opposes the slip), and the feet's
  // normal and friction parts add up to the feet's power
  EXPECT_TRUE(p.foot_friction < 0);
  EXPECT_NEAR(p.foot_pos + p.foot_neg, p.foot_normal_pos + p.foot_normal_neg + p.foot_friction,
              1e-9 * size);
  free(q0);
  free(v0);
  free(a0);
  free(fT_dot);
  mj_deleteData(d);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
