// test_coupling.c: coordinate couplings held by a stiff spring-damper (callbacks/gs_coupling.h) on
// tests/fixtures/coupled_hinges.xml: hinge "follow" (ref 0.3) coupled to hinge "drive" (ref 0.2)
// by follow - 0.3 = 0.1 + 2 x + 0.5 x^2, x = drive - 0.2.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_coupling.h"
#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "optim/go_gait_guess.h"
#include "tests/gs_test.h"

static double target_of(double drive) {
  double x = drive - 0.2;
  return 0.3 + 0.1 + 2 * x + 0.5 * x * x;
}

// gs_physics_prepare adopts the equality: MuJoCo's copy off, one coupling, follower and driver
static void prepare_adopts_the_equality(const mjModel* m) {
  EXPECT_EQ_INT(1, gs_coupling_count(m));
  EXPECT_EQ_INT(0, m->eq_active[0]);
  int f = -1, dr = -1;
  gs_coupling_get(m, 0, &f, &dr);
  EXPECT_EQ_INT(mj_name2id(m, mjOBJ_JOINT, "follow"), f);
  EXPECT_EQ_INT(mj_name2id(m, mjOBJ_JOINT, "drive"), dr);
  EXPECT_TRUE(gs_coupling_joint_follows(m, f) && !gs_coupling_joint_follows(m, dr));
  // the static guess leaves the follower to its coupling (no muscle matches its moment)
  EXPECT_TRUE(!go_static_dof_matched(m, m->jnt_dofadr[f]));
  double slope = 0;
  EXPECT_NEAR(target_of(0.7), gs_coupling_target(m, 0, 0.7, &slope), 1e-15);
  EXPECT_NEAR(2 + 1.0 * (0.7 - 0.2), slope, 1e-15);
}

// the penalty forces are minus the gradient of V = k r^2 / 2 (central differences, step 1e-6),
// and the damping acts on r' = qdot_F - slope qdot_D
static void passive_forces_are_the_penalty_gradient(const mjModel* m, mjData* d) {
  int pf = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "follow")];
  int pd = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "drive")];
  double q[2] = {0.55, target_of(0.55) + 0.004};  // drive, follow: 4 mrad off the target
  for (int c = 0; c < 2; c++) {
    mju_zero(d->qfrc_passive, m->nv);
    d->qpos[pd] = q[0], d->qpos[pf] = q[1];
    mju_zero(d->qvel, m->nv);
    gs_coupling_passive(m, d);
    double h = 1e-6, grad[2];
    for (int i = 0; i < 2; i++) {
      double qp[2] = {q[0], q[1]}, qm[2] = {q[0], q[1]};
      qp[i] += h, qm[i] -= h;
      double rp = qp[1] - target_of(qp[0]), rm = qm[1] - target_of(qm[0]);
      grad[i] = GS_COUPLING_STIFFNESS * (rp * rp - rm * rm) / 2 / (2 * h);
    }
    EXPECT_NEAR(-grad[1], d->qfrc_passive[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "follow")]],
                1e-6 * fabs(grad[1]) + 1e-6);
    EXPECT_NEAR(-grad[0], d->qfrc_passive[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "drive")]],
                1e-6 * fabs(grad[0]) + 1e-6);
    q[1] = target_of(q[0]) - 0.01;  // the other side
  }
  // 400 N m at 4 mrad: the follower is held stiffly
  d->qpos[pd] = 0.55, d->qpos[pf] = target_of(0.55) + 0.004;
  mju_zero(d->qfrc_passive, m->nv);
  gs_coupling_passive(m, d);
  EXPECT_NEAR(-400.0, d->qfrc_passive[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "follow")]], 1e-6);
  // damping: on target, moving apart at r' = 0.2 - slope 0.1
  d->qpos[pf] = target_of(0.55);
  d->qvel[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "follow")]] = 0.2;
  d->qvel[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "drive")]] = 0.1;
  mju_zero(d->qfrc_passive, m->nv);
  gs_coupling_passive(m, d);
  double slope = 2 + (0.55 - 0.2);
  EXPECT_NEAR(-GS_COUPLING_DAMPING * (0.2 - slope * 0.1),
              d->qfrc_passive[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "follow")]], 1e-9);
}

// gs_coupling_follow puts a follower that was not given on its target (position and speed) and
// leaves a given one; mj_forward's passive forces (mjcb_passive) then vanish on the follower
static void follow_sets_missing_followers(const mjModel* m, mjData* d) {
  int jf = mj_name2id(m, mjOBJ_JOINT, "follow"), jd = mj_name2id(m, mjOBJ_JOINT, "drive");
  int pf = m->jnt_qposadr[jf], pd = m->jnt_qposadr[jd];
  int vf = m->jnt_dofadr[jf], vd = m->jnt_dofadr[jd];
  d->qpos[pd] = -0.1, d->qpos[pf] = 5;
  d->qvel[vd] = 0.3, d->qvel[vf] = 7;
  int given_q[2] = {-1, -1}, given_v[2] = {-1, -1};
  given_q[pd] = 0, given_v[vd] = 0;
  gs_coupling_follow(m, d->qpos, d->qvel, given_q, given_v);
  EXPECT_NEAR(target_of(-0.1), d->qpos[pf], 1e-15);
  EXPECT_NEAR((2 + (-0.1 - 0.2)) * 0.3, d->qvel[vf], 1e-15);
  mj_forward(m, d);
  EXPECT_NEAR(0.0, d->qfrc_passive[vf], 1e-9);
  given_q[pf] = 1;  // given: kept
  d->qpos[pf] = 5;
  gs_coupling_follow(m, d->qpos, NULL, given_q, NULL);
  EXPECT_NEAR(5.0, d->qpos[pf], 0);
}

// a forward simulation under gravity (0.5 s) keeps the follower within 0.1 mrad of its target:
// its weight's moment, 1.5 N m, over k is 15 urad
static void simulation_keeps_the_coupling(const mjModel* m, mjData* d) {
  int jf = mj_name2id(m, mjOBJ_JOINT, "follow"), jd = mj_name2id(m, mjOBJ_JOINT, "drive");
  mj_resetData(m, d);
  d->qpos[m->jnt_qposadr[jf]] = target_of(d->qpos[m->jnt_qposadr[jd]]);
  double worst = 0;
  for (int s = 0; s < 10000; s++) {
    mj_step(m, d);
    worst = fmax(worst, fabs(d->qpos[m->jnt_qposadr[jf]] - target_of(d->qpos[m->jnt_qposadr[jd]])));
  }
  EXPECT_TRUE(isfinite(worst) && worst < 1e-4);
}

// an equality gaitsim cannot hold (a joint held at a constant) fails with one line naming it
static void single_joint_equality_fails(void) {
  char path[] = "/tmp/gs_test_coupling_XXXXXX";
  int fd = mkstemp(path);
  EXPECT_TRUE(fd >= 0);
  if (fd < 0) return;
  FILE* f = fdopen(fd, "w");
  fputs("<mujoco><worldbody><body><joint name=\"j\" type=\"hinge\"/><geom size=\"0.1\"/>"
        "</body></worldbody><equality><joint name=\"e\" joint1=\"j\"/></equality></mujoco>",
        f);
  fclose(f);
  char err[512] = "";
  mjModel* m = gs_model_load(path, err, sizeof(err));
  remove(path);
  EXPECT_TRUE(m != NULL);
  if (!m) return;
  EXPECT_EQ_INT(-1, gs_physics_prepare(m, err, sizeof(err)));
  EXPECT_TRUE(strstr(err, "joint equality e") != NULL);
  mj_deleteModel(m);
}

int main(void) {
  gs_mujoco_install_handlers();
  gs_physics_install();
  char err[1024];
  mjModel* m = gs_model_load(GAITSIM_SOURCE_DIR "/tests/fixtures/coupled_hinges.xml", err,
                             sizeof(err));
  EXPECT_TRUE(m != NULL && gs_physics_prepare(m, err, sizeof(err)) == 0);
  if (!m) return GS_TEST_RESULT();
  mjData* d = mj_makeData(m);
  prepare_adopts_the_equality(m);
  passive_forces_are_the_penalty_gradient(m, d);
  follow_sets_missing_followers(m, d);
  simulation_keeps_the_coupling(m, d);
  single_joint_equality_fails();
  mj_deleteData(d);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
