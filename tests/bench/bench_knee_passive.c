// bench_knee_passive.c: cost of the whole knee hook of mjcb_passive (gs_knee_passive: surrogate
// contact + 68 ligament bundles) in the full model, with the model's knee numerics cached by
// gs_physics_prepare against looked up by name on every call (gs_knee_model_init), at a moving
// standing pose with 2 BW of knee contact (medians over repeats).
// usage: bench_knee_passive MODEL [repeats]   (run by scripts/bench_knee.sh; not a test)
#include <stdio.h>
#include <stdlib.h>
#include <mujoco/mujoco.h>
#include "callbacks/gs_knee.h"
#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "tests/bench/bench_common.h"

int main(int argc, char** argv) {
  char err[300];
  int repeats = argc > 2 ? atoi(argv[2]) : 21, n = 2000;
  repeats = repeats < 1 ? 1 : (repeats > 201 ? 201 : repeats);
  mjModel* m = gs_model_load(argv[1], err, sizeof(err));
  if (!m || gs_physics_prepare(m, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_knee_passive: %s\n", err);
    return 1;
  }
  mjData* d = mj_makeData(m);
  // standing, pelvis raised, moving; knee_ty lowered (bisection) until 2 BW of contact
  d->qpos[m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "pelvis_ty")]] += 1.0;
  for (int i = 0; i < m->nv; i++) {
    d->qvel[i] = 0.1 * ((i * 37 % 11) - 5) / 5.0;
  }
  int ty = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "knee_ty")];
  double ty0 = d->qpos[ty], lo = -0.002, hi = 0.002;
  gsKneeLoads loads;
  for (int it = 0; it < 60; it++) {
    d->qpos[ty] = ty0 + 0.5 * (lo + hi);
    mj_forward(m, d);
    gs_knee_passive(m, d, &loads);
    if (loads.contact.total > 2.0 * 614.25) {
      lo = 0.5 * (lo + hi);
    } else {
      hi = 0.5 * (lo + hi);
    }
  }
  printf("passive pose: knee_ty %+.4f mm from standing, contact %.0f N (medial %.0f, lateral "
         "%.0f), ligaments %.0f N\n", 1e3 * (d->qpos[ty] - ty0), loads.contact.total,
         loads.contact.magnitude[0], loads.contact.magnitude[1], loads.ligament_force);
  double tc[201], tn[201], sink = 0.0;
  for (int r = 0; r < repeats; r++) {
    double t0 = bench_now();
    for (int i = 0; i < n; i++) {
      gs_knee_passive(m, d, &loads);
      sink += loads.qfrc[4];
    }
    tc[r] = (bench_now() - t0) / n;
    t0 = bench_now();
    for (int i = 0; i < n; i++) {
      gsKneeModel km;
      gs_knee_model_init(m, &km, NULL, 0);
      gs_knee_passive_model(&km, m, d, &loads);
      sink += loads.qfrc[4];
    }
    tn[r] = (bench_now() - t0) / n;
  }
  printf("passive_us=%.3f passive_by_name_us=%.3f (checksum %.6g)\n",
         1e6 * bench_median(tc, repeats), 1e6 * bench_median(tn, repeats), sink);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
