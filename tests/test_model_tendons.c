// test_model_tendons.c: the tendon slack lengths of the bundled models keep every fibre inside the
// converter's calibration rules over the bundled trial, on the paths MuJoCo computes (wrap geoms
// included): scripts/osim2mjcf.py, cap_fibre_stretch and floor_fibre_shortening, documented in
// mjmodels/README.md, "Tendon slack lengths". With the tendon at slack and constant-thickness
// pennation the normalised fibre length is
//   lM/lopt = sign(L - lts) sqrt((L - lts)^2 + (lopt sin alpha0)^2) / lopt,
// L the muscle-tendon length of mj_fwdPosition at each row of the trial's coordinates.mot.
// Checks, for every muscle of jw_fullbody.xml and jw_fullbody_knee6.xml:
//  - the largest value over the trial is at most LM_MAX_HARD + TOL_RESAMPLE: rule 2 caps it at
//    1.3, rule 3 (which shortens a tendon so that the shortest fibre is 0.4 lopt) may raise it
//    up to 1.5, the predictive problem's fibre bound (Lin, Walter & Pandy 2018, eq. 2). Rules
//    evaluated on the straight .osim line fail it: the right medial gastrocnemius, whose MuJoCo
//    path wraps 16-23 mm longer than that line, reached 1.73;
//  - the smallest value is positive (rule 3's reason: a fibre exists at every pose).
// The muscles above LM_MAX_TRIAL + TOL_RESAMPLE are printed.
// TOL_RESAMPLE: the converter samples every second 120 Hz IK frame of the whole trial, the test
// the 134 rows of coordinates.mot (a cubic-spline resample of the stride window), so the two maxima
// differ by what one frame changes.
#include <math.h>
#include <mujoco/mujoco.h>
#include <stdio.h>

#include "app/gs_app_model.h"
#include "callbacks/gs_model_layout.h"
#include "callbacks/gs_model_info.h"
#include "io/gs_table.h"
#include "tests/gs_test.h"

#define COORDS_PATH GAITSIM_SOURCE_DIR "/mjmodels/trials/jw_ngait_og5/coordinates.mot"
#define LM_MAX_TRIAL 1.3    // rule 2's largest normalised fibre length (scripts/osim2mjcf.py) (-)
#define LM_MAX_HARD 1.5     // rule 3's limit, the predictive problem's fibre bound        (-)
#define TOL_RESAMPLE 0.02   // the trial's rows against the converter's frames          (-)
#define NROWS_EXPECTED 134  // rows of coordinates.mot                                  (count)

// normalised fibre length with the tendon at slack (-) of actuator i at length lMT (m)
static double slack_fibre(const mjModel* m, int i, double lMT) {
  const double* u = m->actuator_user + i * m->nuser_actuator;
  double lopt = u[GS_ACT_LOPT], lts = u[GS_ACT_LTS], h = lopt * sin(u[GS_ACT_PENNATION]);
  double x = lMT - lts;
  return copysign(sqrt(x * x + h * h), x) / lopt;
}

static void check_model(const char* path) {
  mjModel* m = gs_app_load_model(path);
  EXPECT_TRUE(m != NULL);
  if (!m) return;
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(0, gs_app_read_table(m, COORDS_PATH, &t));
  EXPECT_EQ_INT(NROWS_EXPECTED, t.nrow);
  mjData* d = mj_makeData(m);
  double lo[256], hi[256];
  for (int i = 0; i < m->nu && i < 256; i++) lo[i] = INFINITY, hi[i] = -INFINITY;
  for (int r = 0; r < t.nrow; r++) {
    for (int j = 0; j < m->njnt; j++) {
      int c = gs_table_column(&t, mj_id2name(m, mjOBJ_JOINT, j));
      d->qpos[m->jnt_qposadr[j]] = c >= 0 ? t.data[r * t.ncol + c] : m->qpos0[m->jnt_qposadr[j]];
    }
    mj_fwdPosition(m, d);
    for (int i = 0; i < m->nu && i < 256; i++) {
      if (!gs_actuator_is_gaitsim_muscle(m, i)) continue;
      double f = slack_fibre(m, i, d->actuator_length[i]);
      lo[i] = f < lo[i] ? f : lo[i];
      hi[i] = f > hi[i] ? f : hi[i];
    }
  }
  int nmuscle = 0, worst = -1;
  for (int i = 0; i < m->nu && i < 256; i++) {
    if (!gs_actuator_is_gaitsim_muscle(m, i)) continue;
    nmuscle++;
    if (worst < 0 || hi[i] > hi[worst]) worst = i;
    if (hi[i] > LM_MAX_TRIAL + TOL_RESAMPLE || lo[i] <= 0.0) {
      printf("  %s: lM/lopt %.3f to %.3f over the trial\n", mj_id2name(m, mjOBJ_ACTUATOR, i),
             lo[i], hi[i]);
    }
    EXPECT_TRUE(hi[i] <= LM_MAX_HARD + TOL_RESAMPLE);
    EXPECT_TRUE(lo[i] > 0.0);
  }
  EXPECT_EQ_INT(93, nmuscle);
  if (worst >= 0) {
    printf("%s: %d muscles, longest slack-tendon fibre %.3f lopt (%s)\n", path, nmuscle, hi[worst],
           mj_id2name(m, mjOBJ_ACTUATOR, worst));
  }
  mj_deleteData(d);
  gs_table_free(&t);
  mj_deleteModel(m);
}

int main(void) {
  check_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody.xml");
  check_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml");
  return GS_TEST_RESULT();
}
