// bench_knee.c: cost of one surrogate knee-contact evaluation (gs_knee_surrogate) against one
// elastic-foundation evaluation (gs_knee_ef_eval) on JW's refined surfaces, at the held-out poses
// of mjmodels/knee/jw_knee_heldout.csv, side by side in one run (medians over repeats).
// usage: bench_knee FIXTURE HELDOUT EF_MESH [repeats]   (run by scripts/bench_knee.sh; not a test)
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_knee.h"
#include "tests/gs_test_csv.h"
#include "tests/bench/bench_common.h"

#define MAXROWS 64

// poses (first 6 numbers of every non-comment row)
static int read_poses(const char* path, double q[MAXROWS][6]) {
  return gs_test_read_csv_rows(path, 6, 6, &q[0][0], MAXROWS);
}

// the refined surfaces written by scripts/prepare_knee.py
static int read_mesh(const char* path, gsKneeEf* ef) {
  FILE* fp = fopen(path, "r");
  char line[512];
  int nv, nf, ne, ok;
  if (!fp) {
    return -1;
  }
  while (fgets(line, sizeof(line), fp) && line[0] == '#') {
  }
  if (sscanf(line, "%d %d", &nv, &nf) != 2 || nv <= 0 || nf <= 0) {
    fclose(fp);
    return -1;
  }
  double* v = malloc(sizeof(double) * 3 * (size_t)nv);
  int* f = malloc(sizeof(int) * 3 * (size_t)nf);
  ok = v && f;
  for (int i = 0; ok && i < nv; i++) {
    ok = fscanf(fp, "%lf %lf %lf", v + 3 * i, v + 3 * i + 1, v + 3 * i + 2) == 3;
  }
  for (int i = 0; ok && i < nf; i++) {
    ok = fscanf(fp, "%d %d %d", f + 3 * i, f + 3 * i + 1, f + 3 * i + 2) == 3;
  }
  ok = ok && fscanf(fp, "%d", &ne) == 1 && ne > 0;
  double* ec = ok ? malloc(sizeof(double) * 3 * (size_t)ne) : NULL;
  double* en = ok ? malloc(sizeof(double) * 3 * (size_t)ne) : NULL;
  double* ea = ok ? malloc(sizeof(double) * (size_t)ne) : NULL;
  int* comp = ok ? malloc(sizeof(int) * (size_t)ne) : NULL;
  ok = ok && ec && en && ea && comp;
  for (int i = 0; ok && i < ne; i++) {
    ok = fscanf(fp, "%lf %lf %lf %lf %lf %lf %lf %d", ec + 3 * i, ec + 3 * i + 1, ec + 3 * i + 2,
                en + 3 * i, en + 3 * i + 1, en + 3 * i + 2, ea + i, comp + i) == 8;
  }
  fclose(fp);
  memset(ef, 0, sizeof(*ef));
  ef->nv = nv;
  ef->v = v;
  ef->nf = nf;
  ef->f = f;
  ef->ne = ne;
  ef->ec = ec;
  ef->en = en;
  ef->ea = ea;
  ef->ecomp = comp;
  ef->k_over_h = gs_knee_ef_layer_modulus(46.3e6, 0.46) / 0.005;
  ef->reach = 0.003;
  return ok ? 0 : -1;
}

int main(int argc, char** argv) {
  char err[300];
  double q[MAXROWS][6];
  if (argc < 4) {
    fprintf(stderr, "usage: bench_knee FIXTURE HELDOUT EF_MESH [repeats]\n");
    return 2;
  }
  int repeats = argc > 4 ? atoi(argv[4]) : 21;
  repeats = repeats < 1 ? 1 : (repeats > 201 ? 201 : repeats);
  mjModel* m = mj_loadXML(argv[1], NULL, err, sizeof(err));
  gsKneeModel km;
  gsKneeEf ef;
  int n = read_poses(argv[2], q);
  if (!m || gs_knee_model_init(m, &km, err, sizeof(err)) != 1 || n <= 0 ||
      read_mesh(argv[3], &ef) != 0 || gs_knee_ef_build(&ef, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_knee: bad input: %s\n", err);
    return 1;
  }

  // alternate the two models per repeat; each timing covers all poses
  double ts[201], te[201], sink = 0.0;
  int inner = 200;
  for (int r = 0; r < repeats; r++) {
    gsKneeContact out;
    double t0 = bench_now();
    for (int k = 0; k < inner; k++) {
      for (int i = 0; i < n; i++) {
        gs_knee_surrogate(&km, q[i], &out);
        sink += out.total;
      }
    }
    ts[r] = (bench_now() - t0) / (inner * n);
    t0 = bench_now();
    for (int i = 0; i < n; i++) {
      double R[9], t[3];
      gs_knee_pose(q[i], R, t);
      gs_knee_ef_eval(&ef, R, t, &out);
      sink += out.total;
    }
    te[r] = (bench_now() - t0) / n;
  }
  double med_s = bench_median(ts, repeats), med_e = bench_median(te, repeats);
  printf("poses %d, surrogate elements %d + %d, elastic foundation %d elements x %d femoral faces\n",
         n, km.nelem[0], km.nelem[1], ef.ne, ef.nf);
  printf("surrogate_us=%.3f elastic_foundation_us=%.1f speedup=%.0f (checksum %.6g)\n",
         1e6 * med_s, 1e6 * med_e, med_e / med_s, sink);
  gs_knee_ef_free(&ef);
  mj_deleteModel(m);
  return 0;
}
