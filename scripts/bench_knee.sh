#!/usr/bin/env bash
# Cost of one surrogate knee-contact evaluation against one elastic-foundation evaluation on JW's
# refined implant surfaces, side by side in one run (medians over repeats), then the cost of the
# whole knee hook of mjcb_passive (gs_knee_passive: surrogate contact + 68 ligament bundles) in
# the full model mjmodels/jw_fullbody_knee6.xml, with the model cached by gs_physics_prepare and
# looked up by name on every call (an unregistered copy of the model).
# Lines: passive_us=... passive_by_name_us=...; last line: surrogate_us=...
# elastic_foundation_us=... speedup=...
#   scripts/bench_knee.sh [repeats] [build dir, default build]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${2:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target bench_knee gaitsim_core >/dev/null

# the passive hook: a small program against the built library (not a test, not installed)
src="$build/bench_knee_passive.c"
cat >"$src" <<'EOF'
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <mujoco/mujoco.h>
#include "callbacks/gs_knee.h"
#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
static int cmp(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}
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
    double t0 = now();
    for (int i = 0; i < n; i++) {
      gs_knee_passive(m, d, &loads);
      sink += loads.qfrc[4];
    }
    tc[r] = (now() - t0) / n;
    t0 = now();
    for (int i = 0; i < n; i++) {
      gsKneeModel km;
      gs_knee_model_init(m, &km, NULL, 0);
      gs_knee_passive_model(&km, m, d, &loads);
      sink += loads.qfrc[4];
    }
    tn[r] = (now() - t0) / n;
  }
  qsort(tc, (size_t)repeats, sizeof(double), cmp);
  qsort(tn, (size_t)repeats, sizeof(double), cmp);
  printf("passive_us=%.3f passive_by_name_us=%.3f (checksum %.6g)\n", 1e6 * tc[repeats / 2],
         1e6 * tn[repeats / 2], sink);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
EOF
${CC:-cc} -O2 -std=c11 -D_GNU_SOURCE -I. -I"$build" "$src" "$build"/libgaitsim_core.a \
  $(pkg-config --libs libcjson) -lmujoco -lpthread -lm -o "$build"/bench_knee_passive
"$build"/bench_knee_passive mjmodels/jw_fullbody_knee6.xml "${1:-21}"

"$build"/bench_knee tests/fixtures/knee6.xml mjmodels/knee/jw_knee_heldout.csv \
  mjmodels/knee/jw_knee_ef_mesh.txt "${1:-21}"
