// gs_test_trial.h: the full-body model and the default trial's measured tables, as the gait
// problem tests load them (mjmodels/jw_fullbody.xml, mjmodels/trials/jw_ngait_og5).
#ifndef GAITSIM_TESTS_GS_TEST_TRIAL_H_
#define GAITSIM_TESTS_GS_TEST_TRIAL_H_

#include <mujoco/mujoco.h>

#include <stdio.h>

#include "app/gs_app_model.h"
#include "io/gs_table.h"
#include "optim/go_gait.h"

#define GS_TEST_TRIAL GAITSIM_SOURCE_DIR "/mjmodels/trials/jw_ngait_og5"

// Load the prepared full-body model and the trial's coordinates.mot and grf.mot (radians, model
// names, as gaitsim track reads them). Returns the model (mj_deleteModel), or NULL when anything
// failed (the reason is on stderr); coords and grf are initialised either way (gs_table_free).
static inline mjModel* gs_test_load_trial(gsTable* coords, gsTable* grf) {
  gs_table_init(coords);
  gs_table_init(grf);
  mjModel* m = gs_app_load_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody.xml");
  if (!m) return NULL;
  if (gs_app_read_table(m, GS_TEST_TRIAL "/coordinates.mot", coords) != 0 ||
      gs_app_read_table(m, GS_TEST_TRIAL "/grf.mot", grf) != 0) {
    mj_deleteModel(m);
    return NULL;
  }
  return m;
}

// go_gait_create with the reason on stderr; NULL when it fails.
static inline go_gait* gs_test_gait_create(const mjModel* m, const go_gait_opts* o) {
  char err[512];
  go_gait* g = NULL;
  if (go_gait_create(&g, m, o, err, sizeof(err)) != 0) fprintf(stderr, "create: %s\n", err);
  return g;
}

// Options of the tracking problem as the tests build it: N nodes, the defaults of
// go_gait_opts_default, coords and grf tracked, pelvis_tz left out of periodicity (the trial
// drifts sideways, as in `gaitsim track`).
static inline go_gait_opts gs_test_tracking_opts(const gsTable* coords, const gsTable* grf, int N) {
  static const char* free_coords[] = {"pelvis_tz", NULL};
  go_gait_opts o;
  go_gait_opts_default(&o);
  o.N = N;
  o.coords = coords;
  o.grf = grf;
  o.free_coords = free_coords;
  return o;
}

#endif  // GAITSIM_TESTS_GS_TEST_TRIAL_H_
