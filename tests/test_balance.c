// test_balance.c: frontal-plane balance by inverse dynamics (callbacks/gs_balance.h) on
// jw_fullbody_knee6:
// (a) the OpenSim-to-world conversion: (x, y, z)_world = (x, -z, y)_OpenSim;
// (b) standing still on the right foot, the body weight W applied straight up at the point of
//     the floor below the whole-body centre of mass: the pelvis residuals vanish (force and
//     moment within 1e-9 W, 1e-9 W m); the hip abductors hold the body (net hip_adduction moment
//     negative, 20-150 N m); the lifted left foot's columns are NAN;
// (c) moving that centre of pressure sideways by delta changes the hip_adduction moment by
//     exactly -(hip axis)_x delta W (J^T of a vertical force; linear, to 1e-9 relative), and the
//     lateral distances by delta with the side's sign;
// (d) with only the pelvis translating, the angular momentum about the centre of mass is zero
//     (1e-12), and the pelvis_tx residual is the total mass times its acceleration (1e-7);
// (e) a model without the named joints is refused with the name in the reason;
// (f) the ground reaction's part of the right knee's moment: the net moment less the gravity
//     part (a static pose: M qdd + c = gravity) and, from MuJoCo's J^T, the cross product
//     a . (r x F) about the knee_adduction axis through its anchor (1e-9 relative); its pieces:
//     the centre of pressure moved 3 cm laterally lies 3 cm further lateral of the knee (to 1 %,
//     the shank's small frontal tilt) and moves by its projections on the foot's axes (1e-12), the
//     lateral axis level within 5 deg in the zero pose and
//     tilting by -0.1 rad (to 0.01) when the hip adducts by 0.1 rad.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "app/gs_app_model.h"
#include "callbacks/gs_balance.h"
#include "tests/gs_test.h"

static void set_joint(const mjModel* m, mjData* d, const char* name, double v) {
  int j = mj_name2id(m, mjOBJ_JOINT, name);
  if (j >= 0) d->qpos[m->jnt_qposadr[j]] = v;
}

// OpenSim's zero pose at pelvis height 0.95 m with the left leg lifted, still
static void stand_on_right(const mjModel* m, mjData* d) {
  mj_resetData(m, d);
  for (int j = 0; j < m->njnt; j++)
    if (m->jnt_type[j] == mjJNT_HINGE) d->qpos[m->jnt_qposadr[j]] = 0;
  set_joint(m, d, "pelvis_ty", 0.95);
  set_joint(m, d, "hip_flexion_l", 0.6);
  set_joint(m, d, "knee_flexion_l", -1.2);
  mju_zero(d->qvel, m->nv);
}

int main(void) {
  // (a)
  double os[3] = {1, 2, 3}, w[3];
  gs_balance_from_opensim(os, w);
  EXPECT_NEAR(1, w[0], 0);
  EXPECT_NEAR(-3, w[1], 0);
  EXPECT_NEAR(2, w[2], 0);

  mjModel* m = gs_app_load_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml");
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  mjData* d = mj_makeData(m);
  char err[256];
  gsBalanceSpec spec;
  EXPECT_EQ_INT(0, gs_balance_spec(m, &spec, err, sizeof(err)));
  double W = mj_getTotalmass(m) * mju_norm3(m->opt.gravity);
  double* zero = (double*)calloc((size_t)m->nv, sizeof(double));

  // (b) the weight straight up below the centre of mass
  stand_on_right(m, d);
  mj_forward(m, d);
  const double* com = d->subtree_com + 3 * spec.root_body;
  gsFootLoad load[2] = {{{0, 0, W}, {com[0], com[1], 0}, {0, 0, 0}, 1}, {{0}, {0}, {0}, 0}};
  gsBalance b;
  gs_balance_eval(m, d, &spec, zero, load, &b);
  EXPECT_NEAR(0, mju_norm3(b.residual_force), 1e-9 * W);
  EXPECT_NEAR(0, mju_norm3(b.residual_moment), 1e-9 * W);
  EXPECT_TRUE(b.hip_adduction_moment[0] < -20 && b.hip_adduction_moment[0] > -150);
  EXPECT_TRUE(isnan(b.cop_lateral_hip[1]) && isnan(b.cop_lateral_com[1]));
  EXPECT_NEAR(0, b.cop_lateral_com[0], 1e-12);
  EXPECT_NEAR(0, mju_norm3(b.angmom), 1e-12);
  // the ground reaction's moment about the centre of mass: zero (force through it)
  EXPECT_NEAR(0, mju_norm3(b.grf_moment), 1e-9 * W);

  // (c) the centre of pressure 3 cm to the right (-y: lateral of the right foot)
  double delta = 0.03, axis_x = d->xaxis[3 * spec.hip_joint[0]];
  gsBalance b2;
  gsFootLoad moved[2] = {load[0], load[1]};
  moved[0].cop[1] -= delta;
  gs_balance_eval(m, d, &spec, zero, moved, &b2);
  EXPECT_REL(-axis_x * (-delta) * W, b2.hip_adduction_moment[0] - b.hip_adduction_moment[0],
             1e-9, 1e-9);
  // the right knee's (6-DOF) moment about knee_adduction changes alike; the left knee has none
  EXPECT_TRUE(spec.knee_adduction[0] >= 0 && spec.knee_adduction[1] < 0);
  double knee_x = d->xaxis[3 * spec.knee_adduction[0]];
  EXPECT_TRUE(fabs(knee_x) > 0.9);  // about the forward axis
  EXPECT_REL(-knee_x * (-delta) * W,
             b2.knee_adduction_moment[0] - b.knee_adduction_moment[0], 1e-9, 1e-9);
  EXPECT_TRUE(isnan(b.knee_adduction_moment[1]));
  EXPECT_NEAR(delta, b2.cop_lateral_hip[0] - b.cop_lateral_hip[0], 1e-12);
  EXPECT_NEAR(delta, b2.cop_lateral_com[0], 1e-12);
  // the residual moment it leaves is W delta about the forward axis
  EXPECT_NEAR(W * delta, fabs(b2.grf_moment[0]), 1e-9 * W);

  // (f) the ground reaction's part of the knee's moment
  {
    int kj = spec.knee_adduction[0];
    const double* a = d->xaxis + 3 * kj;
    double r[3], rxf[3];
    mju_sub3(r, moved[0].cop, d->xanchor + 3 * kj);
    mju_cross(rxf, r, moved[0].force);
    EXPECT_REL(fabs(mju_dot3(a, rxf)), fabs(b2.knee_grf_moment[0]), 1e-9, 1e-9);
    // the gravity part does not depend on where the load acts
    EXPECT_REL(b.knee_adduction_moment[0] - b.knee_grf_moment[0],
               b2.knee_adduction_moment[0] - b2.knee_grf_moment[0], 1e-9, 1e-9);
    EXPECT_REL(delta, b2.cop_lateral_knee[0] - b.cop_lateral_knee[0], 0.01, 0);
    EXPECT_NEAR(W, b.knee_axial_force[0], 0.02 * W);
    EXPECT_TRUE(fabs(b.knee_lateral_tilt[0]) < 5 * M_PI / 180);
    EXPECT_TRUE(isnan(b.knee_grf_moment[1]) && isnan(b.knee_lateral_tilt[1]));
    // in the foot's frame: the move (0, -delta, 0) projected on its axes (calcn is turned out
    // about 14 deg in the zero pose: most of it lateral, some of it backward)
    const double* fm = d->xmat + 9 * spec.foot_body[0];
    double lat_y = fm[5] < 0 ? fm[5] : -fm[5], fwd_y = fm[0] < 0 ? -fm[3] : fm[3];
    EXPECT_NEAR(-delta * lat_y, b2.cop_foot_lateral[0] - b.cop_foot_lateral[0], 1e-12);
    EXPECT_NEAR(-delta * fwd_y, b2.cop_foot_forward[0] - b.cop_foot_forward[0], 1e-12);
    EXPECT_TRUE(-lat_y > 0.9);
    EXPECT_TRUE(isnan(b.cop_foot_lateral[1]));
    double tilt0 = b.knee_lateral_tilt[0];
    set_joint(m, d, "hip_adduction", 0.1);
    gs_balance_eval(m, d, &spec, zero, load, &b2);
    EXPECT_NEAR(-0.1, b2.knee_lateral_tilt[0] - tilt0, 0.01);
    set_joint(m, d, "hip_adduction", 0);
  }

  // (d) the pelvis translating forward at 1.3 m/s, accelerating at 2 m/s^2, nothing loaded
  int tx = mj_name2id(m, mjOBJ_JOINT, "pelvis_tx");
  EXPECT_TRUE(tx >= 0);
  d->qvel[m->jnt_dofadr[tx]] = 1.3;
  double* acc = (double*)calloc((size_t)m->nv, sizeof(double));
  acc[m->jnt_dofadr[tx]] = 2.0;
  gsFootLoad none[2] = {{{0}, {0}, {0}, 0}, {{0}, {0}, {0}, 0}};
  gs_balance_eval(m, d, &spec, acc, none, &b);
  EXPECT_NEAR(0, mju_norm3(b.angmom), 1e-12);
  EXPECT_REL(mj_getTotalmass(m) * 2.0, b.residual_force[0], 1e-7, 1e-9);  // rounding: 5e-9

  // (e) the planar model has no hip_adduction
  mjModel* planar = gs_app_load_model(GAITSIM_SOURCE_DIR "/mjmodels/gait2d.xml");
  EXPECT_TRUE(planar != NULL);
  if (planar) {
    EXPECT_EQ_INT(-1, gs_balance_spec(planar, &spec, err, sizeof(err)));
    EXPECT_TRUE(strstr(err, "\"") != NULL);
    mj_deleteModel(planar);
  }
  free(acc);
  free(zero);
  mj_deleteData(d);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
