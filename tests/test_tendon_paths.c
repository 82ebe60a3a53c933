// test_tendon_paths.c: gs_tendon_paths at a grazing wrap (callbacks/gs_tendon_paths.h).
//
// The pose: jw_fullbody_knee6.xml where eq. 3's band x 1.5 stopped the 1.0 m/s prediction (an
// iterate of `gaitsim predict --guess results/track --speed 1.0 --band-scale 1.5`): adductor
// longus's segment from pelvis to femur passes within about 1e-11 m of its femoral-shaft cylinder
// (AL_at_femshaft, radius 20.9 mm). The graze itself is found by stepping hip adduction from
// there by 1e-11 rad (at most 1000 steps either way) to the first pose where MuJoCo's length is
// NaN: the model's rounding (a regenerated model's body frames) moves it by a few steps. Checks:
//  - MuJoCo 2.2.2 alone fails there: a NaN length (the defect this module is for; should a MuJoCo
//    release fix it, this check says so and the module can go);
//  - gs_fwd_position: the length is the straight site-to-site distance (the path at a graze)
//    to TOL_GRAZE_LEN, its Jacobian row the straight segment's moment arm within TOL_ARM of a
//    central difference of the repaired length, and every other tendon bitwise MuJoCo's;
//  - across the graze, hip adduction stepped by 1e-11, 1e-9 and 1e-7 rad over 2001 poses each:
//    MuJoCo gives NaN or the far side of the cylinder (>= 5 mm longer) at some, the repair at none,
//    and the repaired length's second difference stays below TOL_SECOND (a straight line's
//    rounding; MuJoCo's far side jumps 31 mm);
//  - gs_forward at the graze: the repaired length, and finite accelerations where mj_forward's
//    are not (simulate's recorded rows, inspect); gs_inverse there: the repaired length and the
//    actuator's length from it, where mj_inverse's is NaN;
//  - gs_inverse and gs_forward equal mj_inverse and mj_forward bitwise at a pose without a graze
//    (qpos0 with the hip flexed).
#include <math.h>
#include <mujoco/mujoco.h>
#include <stdio.h>
#include <string.h>

#include "app/gs_app_model.h"
#include "callbacks/gs_tendon_paths.h"
#include "tests/gs_test.h"

#define MODEL_PATH GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml"
#define TOL_GRAZE_LEN 1e-10  // repaired length against the straight segment at the graze  (m)
#define TOL_ARM 1e-6         // moment arm against a central difference of the length    (m)
#define TOL_SECOND 1e-10     // second difference of the repaired length across the graze (m)
#define FAR_SIDE 5e-3        // MuJoCo's far-side path: this much longer, or more          (m)
#define FD_STEP 1e-6         // central-difference step of the moment-arm check          (rad)
#define GRAZE_STEP 1e-11     // hip adduction step of the search for the graze           (rad)

// qpos of the grazing pose, in the model's joint order (pelvis_tx ... lumbar_rotation)
static const double kGrazePose[26] = {
    0.29611531787022244,    0.99429568778322208,  0.19636262646865985,
    -0.081387749526240019,  -0.14734711137781431, 0.2748350568041138,
    0.35538040486628514,    0.23039237495552006,  -0.14162615523942959,
    -0.024558321616934452,  0.0016014971446775511, -0.44753409595507526,
    -0.0036432009546488783, 0.044138216424693247, 0.00061201879704151784,
    0.097059355285015109,   -0.12602287701130402, 0.095379331245007262,
    -0.038519199540756319,  0.25147732677226203,  -0.2243615913171412,
    0.31100419569644766,    0.0038463726437819312, -0.39031303691125108,
    0.065994544783592776,   0.097025880953078278};

// |P1 P2| of a site-geom-site tendon (m)
static double straight_length(const mjModel* m, const mjData* d, int t) {
  int a = m->wrap_objid[m->tendon_adr[t]];
  int b = m->wrap_objid[m->tendon_adr[t] + m->tendon_num[t] - 1];
  double v[3];
  mju_sub3(v, d->site_xpos + 3 * b, d->site_xpos + 3 * a);
  return mju_norm3(v);
}

static void set_pose(const mjModel* m, mjData* d, int dof, double dq) {
  mju_copy(d->qpos, kGrazePose, m->nq);
  d->qpos[dof] += dq;
}

int main(void) {
  mjModel* m = gs_app_load_model(MODEL_PATH);
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  EXPECT_EQ_INT(26, m->nq);
  mjData* d = mj_makeData(m);
  mjData* raw = mj_makeData(m);
  int t = mj_name2id(m, mjOBJ_TENDON, "addlong");
  int add = m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "hip_adduction")];
  EXPECT_TRUE(t >= 0 && add >= 0);
  EXPECT_EQ_INT(3, m->tendon_num[t]);  // site, cylinder, site

  // the graze: the nearest pose to kGrazePose along hip adduction where MuJoCo's length is NaN
  double g = NAN;
  for (int k = 0; k <= 2000 && isnan(g); k++) {
    double dq = (k % 2 ? 1 : -1) * ((k + 1) / 2) * GRAZE_STEP;
    set_pose(m, raw, add, dq);
    mj_fwdPosition(m, raw);
    if (!isfinite(raw->ten_length[t])) g = dq;
  }
  EXPECT_TRUE(!isnan(g));
  if (isnan(g)) return GS_TEST_RESULT();

  // MuJoCo alone, and the repair, at the graze
  set_pose(m, raw, add, g);
  mj_fwdPosition(m, raw);
  EXPECT_TRUE(!isfinite(raw->ten_length[t]));
  set_pose(m, d, add, g);
  EXPECT_EQ_INT(1, gs_fwd_position(m, d));
  EXPECT_NEAR(straight_length(m, d, t), d->ten_length[t], TOL_GRAZE_LEN);
  EXPECT_NEAR(d->ten_length[t], d->actuator_length[t], 0);  // transmission redone
  int same = 1;
  for (int i = 0; i < m->ntendon; i++) {
    if (i == t) continue;
    same &= raw->ten_length[i] == d->ten_length[i];
    same &= !memcmp(raw->ten_J + i * m->nv, d->ten_J + i * m->nv, sizeof(mjtNum) * m->nv);
  }
  EXPECT_TRUE(same);
  double arm = d->ten_J[t * m->nv + add], lp, lm;
  set_pose(m, d, add, g + FD_STEP);
  gs_fwd_position(m, d);
  lp = d->ten_length[t];
  set_pose(m, d, add, g - FD_STEP);
  gs_fwd_position(m, d);
  lm = d->ten_length[t];
  EXPECT_NEAR((lp - lm) / (2 * FD_STEP), arm, TOL_ARM);

  // gs_forward at the graze: the repaired tendon of gs_fwd_position, and accelerations finite
  // where mj_forward's are not
  double repaired_len = 0;
  set_pose(m, d, add, g);
  gs_fwd_position(m, d);
  repaired_len = d->ten_length[t];
  set_pose(m, raw, add, g);
  mj_forward(m, raw);
  set_pose(m, d, add, g);
  EXPECT_EQ_INT(1, gs_forward(m, d));
  EXPECT_TRUE(d->ten_length[t] == repaired_len);
  int raw_finite = 1, finite = 1;
  for (int j = 0; j < m->nv; j++) {
    raw_finite &= isfinite(raw->qacc[j]);
    finite &= isfinite(d->qacc[j]);
  }
  EXPECT_TRUE(!raw_finite);
  EXPECT_TRUE(finite);
  // gs_inverse at the graze: the same repaired tendon, and the actuator's length from it
  set_pose(m, raw, add, g);
  mj_inverse(m, raw);
  set_pose(m, d, add, g);
  EXPECT_EQ_INT(1, gs_inverse(m, d));
  EXPECT_TRUE(!isfinite(raw->actuator_length[t]));
  EXPECT_TRUE(d->ten_length[t] == repaired_len && d->actuator_length[t] == repaired_len);

  // across the graze
  const double steps[3] = {1e-11, 1e-9, 1e-7};
  for (int s = 0; s < 3; s++) {
    int raw_bad = 0, bad = 0, repaired = 0;
    double L[3] = {0, 0, 0}, worst = 0;
    for (int k = -1000; k <= 1000; k++) {
      set_pose(m, raw, add, g + k * steps[s]);
      mj_fwdPosition(m, raw);
      set_pose(m, d, add, g + k * steps[s]);
      repaired += gs_fwd_position(m, d) > 0;
      double straight = straight_length(m, d, t);
      raw_bad += !isfinite(raw->ten_length[t]) || raw->ten_length[t] > straight + FAR_SIDE;
      bad += !isfinite(d->ten_length[t]) || d->ten_length[t] > straight + FAR_SIDE;
      L[0] = L[1], L[1] = L[2], L[2] = d->ten_length[t];
      if (k >= -998) worst = fmax(worst, fabs(L[0] - 2 * L[1] + L[2]));
    }
    printf("step %g rad: MuJoCo fails at %d poses, the repair at %d (%d recomputed); largest "
           "second difference %.3g m\n", steps[s], raw_bad, bad, repaired, worst);
    EXPECT_TRUE(raw_bad > 0);
    EXPECT_EQ_INT(0, bad);
    EXPECT_TRUE(repaired > 0);
    EXPECT_TRUE(worst <= TOL_SECOND);
  }

  // no graze: gs_inverse is mj_inverse
  mju_copy(raw->qpos, m->qpos0, m->nq);
  raw->qpos[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "hip_flexion")]] = 0.4;
  for (int j = 0; j < m->nv; j++) raw->qvel[j] = 0.1 * (j % 5) - 0.2, raw->qacc[j] = 0.3 * (j % 3);
  mju_copy(d->qpos, raw->qpos, m->nq);
  mju_copy(d->qvel, raw->qvel, m->nv);
  mju_copy(d->qacc, raw->qacc, m->nv);
  mj_inverse(m, raw);
  EXPECT_EQ_INT(0, gs_inverse(m, d));
  EXPECT_TRUE(!memcmp(raw->qfrc_inverse, d->qfrc_inverse, sizeof(mjtNum) * m->nv));
  EXPECT_TRUE(!memcmp(raw->actuator_length, d->actuator_length, sizeof(mjtNum) * m->nu));
  // no graze: gs_forward is mj_forward
  mj_forward(m, raw);
  EXPECT_EQ_INT(0, gs_forward(m, d));
  EXPECT_TRUE(!memcmp(raw->qacc, d->qacc, sizeof(mjtNum) * m->nv));
  EXPECT_TRUE(!memcmp(raw->actuator_force, d->actuator_force, sizeof(mjtNum) * m->nu));

  mj_deleteData(raw);
  mj_deleteData(d);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
