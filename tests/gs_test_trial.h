// gs_test_trial.h: the full-body model and the default trial's measured tables, as the gait
// problem tests load them (mjmodels/jw_fullbody.xml, mjmodels/trials/jw_ngait_og5).
#ifndef GAITSIM_TESTS_GS_TEST_TRIAL_H_
#define GAITSIM_TESTS_GS_TEST_TRIAL_H_

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "io/gs_table.h"

#define GS_TEST_TRIAL GAITSIM_SOURCE_DIR "/mjmodels/trials/jw_ngait_og5"

// Load the prepared full-body model and the trial's coordinates.mot and grf.mot (radians, model
// names, as gaitsim track reads them). Returns the model (mj_deleteModel), or NULL when anything
// failed (the reason is on stderr); coords and grf are initialised either way (gs_table_free).
static mjModel* gs_test_load_trial(gsTable* coords, gsTable* grf) {
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

#endif  // GAITSIM_TESTS_GS_TEST_TRIAL_H_
