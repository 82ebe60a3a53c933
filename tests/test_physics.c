// test_physics.c: gaitsim's physics inside MuJoCo (callbacks/gs_physics.h) on the one-muscle
// bench (tests/fixtures/one_muscle.xml): a 101.97 kg block (weight 1000 N = Fmax) hanging from an
// elastic-tendon Hill muscle.
#include <math.h>
#include <stdio.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_muscle.h"
#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "tests/gs_test.h"

static const double kFmax = 1000.0;  // N
static const double kLopt = 0.10;    // m
static const double kLts = 0.20;     // m

static mjModel* load_bench(void) {
  char err[1024];
  mjModel* m = gs_model_load(GAITSIM_SOURCE_DIR "/tests/fixtures/one_muscle.xml", err, sizeof(err));
  if (!m) {
    fprintf(stderr, "one_muscle.xml: %s\n", err);
    return NULL;
  }
  if (gs_physics_prepare(m, err, sizeof(err)) != 0) {
    fprintf(stderr, "prepare: %s\n", err);
    mj_deleteModel(m);
    return NULL;
  }
  return m;
}

// At optimal fibre length, full activation and no velocity, the Hill equilibrium force is Fmax
// within 1 % (fL(1) = 0.9993 in De Groote's curve), and the callbacks apply -Fmax fT to MuJoCo.
static void isometric_force_at_optimal_length(const mjModel* m, mjData* d) {
  double lT = kLts * gs_muscle_ft_inverse(1.0, 35.0, NULL);
  double lMT = kLopt + lT;
  mj_resetData(m, d);
  d->qpos[0] = -(lMT - 0.3);  // the block starts 0.3 m below the origin; lengthen to lMT
  mj_fwdPosition(m, d);
  EXPECT_NEAR(lMT, d->actuator_length[0], 1e-12);

  gsMuscleParams prm;
  EXPECT_EQ_INT(0, gs_muscle_params_from_user(m->actuator_user, &prm, NULL, 0));
  double fT = 0;
  gsMuscleOut out;
  EXPECT_EQ_INT(0, gs_muscle_equilibrium_fT(&prm, 1.0, lMT, &fT, &out));
  EXPECT_NEAR(1.0, out.lM_norm, 0.01);
  EXPECT_NEAR(kFmax, kFmax * fT, 0.01 * kFmax);

  // the actuator force MuJoCo sees is minus the tendon tension
  d->act[0] = 1.0;
  d->ctrl[0] = 1.0;
  d->userdata[0] = fT;
  mj_forward(m, d);
  EXPECT_NEAR(-kFmax * fT, d->actuator_force[0], 1e-9);
  // at u = a the activation rate vanishes
  EXPECT_NEAR(0.0, d->act_dot[0], 1e-9);
}

// Released away from equilibrium with full excitation, the block settles where the tendon
// carries its weight (1000 N) and the fibre sits near optimal length.
static void hanging_mass_settles_at_its_weight(const mjModel* m, mjData* d) {
  mj_resetData(m, d);
  d->act[0] = 1.0;
  d->ctrl[0] = 1.0;
  mj_fwdPosition(m, d);
  gsMuscleParams prm;
  gs_muscle_params_from_user(m->actuator_user, &prm, NULL, 0);
  double fT = 0;
  gs_muscle_equilibrium_fT(&prm, 1.0, d->actuator_length[0], &fT, NULL);
  d->userdata[0] = fT;
  mjtNum fT_dot[1];
  int ok = 1;
  int steps = (int)lround(3.0 / m->opt.timestep);
  for (int s = 0; s < steps && ok; s++) {
    ok = gs_physics_step(m, d, fT_dot) == 0;
  }
  EXPECT_TRUE(ok);
  mj_forward(m, d);
  gsMuscleOut out;
  double tension = gs_physics_muscle_tension(m, d, 0, &out);
  double weight = 101.9716 * 9.81;
  EXPECT_NEAR(weight, tension, 0.005 * weight);
  EXPECT_NEAR(0.0, d->qvel[0], 1e-3);
  EXPECT_NEAR(1.0, out.lM_norm, 0.03);
}

int main(void) {
  gs_mujoco_install_handlers();
  gs_physics_install();
  mjModel* m = load_bench();
  EXPECT_TRUE(m != NULL);
  if (!m) {
    return GS_TEST_RESULT();
  }
  mjData* d = mj_makeData(m);
  isometric_force_at_optimal_length(m, d);
  hanging_mass_settles_at_its_weight(m, d);
  mj_deleteData(d);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
