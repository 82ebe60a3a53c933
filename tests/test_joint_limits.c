// test_joint_limits.c: the passive joint-limit moments (callbacks/gs_joint_limits.h) on
// tests/fixtures/limited_hinge.xml, whose hinge "knee" carries Falisse et al. 2019's knee law
// (k = -6.09, 33.94, 11.03, -11.33; theta = -2.4, 0.13 rad) and whose hinge "free" carries none.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_joint_limits.h"
#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "tests/gs_test.h"

static const double K[4] = {-6.09, 33.94, 11.03, -11.33}, THETA[2] = {-2.4, 0.13};

// at each limit one term is its k exactly (the other below 1e-11 N m); inside the range both are
// small: 0.074 N m at q = 0 (the straight knee), 1.43 N m at 5 deg of hyperextension, 114 N m
// at 12.4 deg (values of the law by hand: -6.09 e^(33.94 (q - 0.13)))
static void moments_at_anchor_points(void) {
  EXPECT_NEAR(-6.09, gs_joint_limit_moment(K, THETA, 0.13, NULL), 1e-11);
  EXPECT_NEAR(11.03, gs_joint_limit_moment(K, THETA, -2.4, NULL), 1e-11);
  EXPECT_NEAR(-0.0738624, gs_joint_limit_moment(K, THETA, 0.0, NULL), 1e-6);
  EXPECT_NEAR(-1.427996, gs_joint_limit_moment(K, THETA, 5.0 * M_PI / 180.0, NULL), 1e-5);
  EXPECT_NEAR(-114.408, gs_joint_limit_moment(K, THETA, 12.4 * M_PI / 180.0, NULL), 1e-2);
  EXPECT_TRUE(fabs(gs_joint_limit_moment(K, THETA, -1.0, NULL)) < 2e-6);
}

// d tau / d q against central differences (step 1e-6 rad) across the range and past both limits
static void derivative_matches_differences(void) {
  const double qs[] = {-2.6, -2.4, -1.2, -0.3, 0.0, 0.1, 0.13, 0.25};
  for (size_t i = 0; i < sizeof(qs) / sizeof(qs[0]); i++) {
    double h = 1e-6, d = 0;
    gs_joint_limit_moment(K, THETA, qs[i], &d);
    double fd = (gs_joint_limit_moment(K, THETA, qs[i] + h, NULL) -
                 gs_joint_limit_moment(K, THETA, qs[i] - h, NULL)) /
                (2 * h);
    EXPECT_NEAR(fd, d, 1e-6 * fabs(d) + 1e-7);
  }
}

// mj_forward (mjcb_passive installed) adds the law to the limited joint's dof only
static void forward_adds_the_moment(const mjModel* m, mjData* d) {
  int knee = mj_name2id(m, mjOBJ_JOINT, "knee"), free_j = mj_name2id(m, mjOBJ_JOINT, "free");
  const double qs[] = {-2.5, -0.4, 0.0, 0.2};
  for (size_t i = 0; i < sizeof(qs) / sizeof(qs[0]); i++) {
    mj_resetData(m, d);
    d->qpos[m->jnt_qposadr[knee]] = qs[i];
    d->qpos[m->jnt_qposadr[free_j]] = 0.3;
    mj_forward(m, d);
    EXPECT_NEAR(gs_joint_limit_moment(K, THETA, qs[i], NULL),
                d->qfrc_passive[m->jnt_dofadr[knee]], 1e-12);
    EXPECT_NEAR(0.0, d->qfrc_passive[m->jnt_dofadr[free_j]], 0);
  }
}

// gs_joint_limits_check counts the limited joint and rejects a law that pushes out of the range,
// crossed limits and a value that is not finite, each with one line naming the numeric
static void check_rejects_bad_laws(mjModel* m) {
  char err[256] = "";
  EXPECT_EQ_INT(1, gs_joint_limits_check(m, err, sizeof(err)));
  mjtNum* v = m->numeric_data + m->numeric_adr[mj_name2id(m, mjOBJ_NUMERIC, "gs_limit_knee")];
  mjtNum keep[6];
  memcpy(keep, v, sizeof(keep));
  const int slot[3] = {0, 4, 2};
  const double bad[3] = {6.09, 0.5, NAN};  // k1 > 0; theta1 > theta2; k3 not finite
  for (int c = 0; c < 3; c++) {
    memcpy(v, keep, sizeof(keep));
    v[slot[c]] = bad[c];
    err[0] = 0;
    EXPECT_EQ_INT(-1, gs_joint_limits_check(m, err, sizeof(err)));
    EXPECT_TRUE(strstr(err, "gs_limit_knee") != NULL && strchr(err, '\n') == NULL);
    printf("  rejected: %s\n", err);
  }
  memcpy(v, keep, sizeof(keep));
}

int main(void) {
  gs_mujoco_install_handlers();
  gs_physics_install();
  moments_at_anchor_points();
  derivative_matches_differences();
  char err[512];
  mjModel* m = gs_model_load(GAITSIM_SOURCE_DIR "/tests/fixtures/limited_hinge.xml", err,
                             sizeof(err));
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  mjData* d = mj_makeData(m);
  forward_adds_the_moment(m, d);
  check_rejects_bad_laws(m);
  mj_deleteData(d);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
