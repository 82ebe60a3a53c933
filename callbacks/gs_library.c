// gs_library.c: the public entry points of libgaitsim (include/gaitsim/gaitsim.h), thin wrappers
// over the physics of gs_physics.h, so the installed ABI stays small while the internals change.
#include "include/gaitsim/gaitsim.h"

#include <math.h>
#include <string.h>

#include "callbacks/gs_model_info.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_tendon_paths.h"

static const double kLoadedN = 5.0;  // a foot carries load above this normal force (N)

const char* gs_lib_version(void) {
  return GAITSIM_VERSION;
}

int gs_lib_prepare(mjModel* m, char* err, int errsz) {
  return gs_physics_prepare(m, err, errsz);
}

void gs_lib_install(void) {
  gs_physics_install();
}

void gs_lib_equilibrate(const mjModel* m, mjData* d) {
  gs_fwd_position(m, d);
  gs_physics_equilibrate_tendons(m, d, NULL);
}

int gs_lib_step(const mjModel* m, mjData* d) {
  // scratch for the tendon-force rates (nu) on MuJoCo's stack of d
  mjMARKSTACK;
  mjtNum* fT_dot = mj_stackAlloc(d, m->nu > 0 ? m->nu : 1);
  int status = gs_physics_step(m, d, fT_dot);
  mjFREESTACK;
  return status;
}

double gs_lib_muscle_force(const mjModel* m, const mjData* d, int i) {
  if (i < 0 || i >= m->nu) return NAN;
  return gs_actuator_is_gaitsim_muscle(m, i) ? gs_physics_muscle_tension(m, d, i, NULL)
                                             : -d->actuator_force[i];
}

int gs_lib_foot_force(const mjModel* m, const mjData* d, char side, double force[3],
                      double cop[3]) {
  if (side != 'r' && side != 'l') return -1;
  gsFootGrf grf;
  gs_physics_foot_grf(m, d, side, kLoadedN, &grf);
  memcpy(force, grf.force, sizeof(grf.force));
  if (grf.loaded) {
    memcpy(cop, grf.cop, sizeof(grf.cop));
  } else {
    memset(cop, 0, 3 * sizeof(double));
  }
  return grf.loaded;
}
