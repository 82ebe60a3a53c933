// bench_forward.c: cost of one mj_forward of a model with gaitsim's physics (Hill muscles with
// elastic tendons, smooth foot contact in mjcb_passive, MuJoCo contacts off) against the same
// model with MuJoCo's native muscles and contacts, measured side by side in one run.
// usage: bench_forward MODEL [repeats]   (run by scripts/bench_physics.sh; not a test)
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "tests/bench/bench_common.h"

// seconds per mj_forward over `calls` calls
static double time_forward(const mjModel* m, mjData* d, int calls) {
  double t0 = bench_now();
  for (int c = 0; c < calls; c++) {
    mj_forward(m, d);
  }
  return (bench_now() - t0) / calls;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_forward MODEL [repeats]\n");
    return 2;
  }
  int repeats = argc > 2 ? atoi(argv[2]) : 21;
  gs_mujoco_install_handlers();
  char err[1024];
  mjModel* native = gs_model_load(argv[1], err, sizeof(err));
  mjModel* ours = gs_model_load(argv[1], err, sizeof(err));
  if (!native || !ours || gs_physics_prepare(ours, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_forward: %s: %s\n", argv[1], err);
    return 1;
  }
  mjData* dn = mj_makeData(native);
  mjData* dg = mj_makeData(ours);
  int key = mj_name2id(native, mjOBJ_KEY, "standing");
  if (key >= 0) {
    mj_resetDataKeyframe(native, dn, key);
    mj_resetDataKeyframe(ours, dg, key);
  }
  for (int i = 0; i < native->nu; i++) {
    dn->ctrl[i] = dg->ctrl[i] = 0.1;
  }
  for (int i = 0; i < native->na; i++) {
    dn->act[i] = dg->act[i] = 0.1;
  }
  for (int i = 0; i < ours->nu; i++) {
    dg->userdata[i] = 0.1;
  }
  int calls = 2000;
  double* tn = (double*)malloc(sizeof(double) * repeats);
  double* tg = (double*)malloc(sizeof(double) * repeats);
  for (int r = 0; r < repeats; r++) {  // alternate, so drifts hit both alike
    mjcb_passive = NULL;
    mjcb_act_dyn = mjcb_act_gain = mjcb_act_bias = NULL;
    tn[r] = time_forward(native, dn, calls);
    gs_physics_install();
    tg[r] = time_forward(ours, dg, calls);
  }
  double mn = bench_median(tn, repeats), mg = bench_median(tg, repeats);
  printf("model %s: nv %d, nu %d, native contacts %d\n", argv[1], native->nv, native->nu, dn->ncon);
  printf("mj_forward native muscles+contacts: median %.2f us (%d repeats x %d calls)\n", 1e6 * mn,
         repeats, calls);
  printf("mj_forward gaitsim physics:         median %.2f us\n", 1e6 * mg);
  printf("ratio=%.3f\n", mg / mn);
  free(tn);
  free(tg);
  mj_deleteData(dn);
  mj_deleteData(dg);
  mj_deleteModel(native);
  mj_deleteModel(ours);
  return 0;
}
