// cmd_balance.c: `gaitsim balance MODEL --pose FILE --grf FILE`: the frontal-plane balance of a
// gait (callbacks/gs_balance.h) at every row of FILE: a solution's states.sto with its grf.mot,
// or a trial's coordinates.mot with its measured grf.mot. Prints each foot's single-stance
// figures and the stride's ranges (the table of docs/BENCHMARKS.md, "Stance width").
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_balance.h"
#include "callbacks/gs_state.h"

#define BALANCE_STANCE_N 20.0  // a foot is in stance above this vertical force (N)

static const char* kBalanceUsage =
    "usage: gaitsim balance MODEL --pose FILE --grf GRF.mot [--rows]\n\n"
    "The frontal-plane balance of a gait by inverse dynamics under the given ground reactions,\n"
    "at every row of FILE (a solution's states.sto, or a trial's coordinates.mot; speeds missing\n"
    "from FILE and all accelerations by central differences of its rows). GRF.mot: OpenSim\n"
    "ExternalLoads columns (ground_force_r_vx ... ground_torque_l_z), e.g. the solution's or the\n"
    "trial's grf.mot. Prints, for each foot's single stance (its vertical force above 20 N, the\n"
    "other's not): the centre of pressure against the hip centre and the whole-body centre of\n"
    "mass (cm, + lateral), the hip abductors' net moment (N m), the ground reaction's frontal\n"
    "moment about the centre of mass; through each foot's stance: the knee's net moment about\n"
    "knee_adduction (the 6-DOF knee only; what its contact, ligaments and muscles supply\n"
    "together); over the stride: the frontal angular momentum about the\n"
    "centre of mass, lumbar_bending, the trunk's sway about the centre of mass, and the pelvis\n"
    "residuals (zero for a dynamically consistent motion and load): their RMS and, per axis,\n"
    "their stride mean (what OpenSim's residual reduction answers by the model's mass and\n"
    "the torso's centre of mass).\n\n"
    "  --rows   also a table of every loaded row of each foot: the centre of pressure in the\n"
    "           foot's frame (forward, lateral), the mediolateral ground force (+ lateral)\n"
    "           and, for a 6-DOF knee, the net moment about knee_adduction, the ground\n"
    "           reaction's part of it and its pieces in the knee's frame\n"
    "           (callbacks/gs_balance.h): the centre of pressure lateral of the knee centre,\n"
    "           the force along the shank and along the knee's lateral axis, that axis's\n"
    "           tilt (+ lateral end up)\n";

typedef struct stat_ {
  double sum, sumsq, lo, hi;
  int n;
} stat;

static void add(stat* s, double x) {
  if (!isfinite(x)) return;
  if (s->n == 0 || x < s->lo) s->lo = x;
  if (s->n == 0 || x > s->hi) s->hi = x;
  s->sum += x;
  s->sumsq += x * x;
  s->n++;
}
static double mean(const stat* s) { return s->n ? s->sum / s->n : NAN; }
static double rms(const stat* s) { return s->n ? sqrt(s->sumsq / s->n) : NAN; }

int gs_cmd_balance(int argc, char** argv) {
  static const struct option options[] = {{"pose", required_argument, NULL, 'p'},
                                          {"grf", required_argument, NULL, 'g'},
                                          {"rows", no_argument, NULL, 'r'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  const char *pose = NULL, *grf = NULL;
  int rows = 0;
  optind = 1;
  opterr = 0;
  int c;
  while ((c = getopt_long(argc, argv, ":p:g:rh", options, NULL)) != -1) {
    switch (c) {
      case 'p': pose = optarg; break;
      case 'g': grf = optarg; break;
      case 'r': rows = 1; break;
      case 'h': fputs(kBalanceUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("balance", c, argv);
    }
  }
  if (gs_opt_one_operand("balance", "MODEL", argc, argv) != 0) return GS_EXIT_USAGE;
  if (!pose) return gs_opt_usage_error("balance", "missing --pose FILE");
  if (!grf) return gs_opt_usage_error("balance", "missing --grf GRF.mot");
  const char* path = argv[optind];
  mjModel* m = gs_app_load_model(path);
  if (!m) return GS_EXIT_FAILURE;
  int status = GS_EXIT_FAILURE;
  mjData* d = mj_makeData(m);
  gsTable t, g;
  gs_table_init(&t);
  gs_table_init(&g);
  gsStateMap map = {0};
  gsBalanceSpec spec;
  char err[512];
  double *q = NULL, *v = NULL, *a = NULL;
  if (gs_balance_spec(m, &spec, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    goto done;
  }
  int col[GS_GRF_NCOL];
  if (gs_app_read_pose_and_loads(m, pose, grf, &t, &map, &g, col) != 0) goto done;
  // qpos and qvel of every row; speeds from the file when it has them all, else differences
  int n = t.nrow, nq = m->nq, nv = m->nv;
  q = (double*)malloc(sizeof(double) * (size_t)(n * nq));
  v = (double*)malloc(sizeof(double) * (size_t)(n * nv));
  a = (double*)malloc(sizeof(double) * (size_t)(n * nv));
  if (!q || !v || !a) {
    fprintf(stderr, "gaitsim: balance: out of memory\n");
    goto done;
  }
  int speeds = gs_app_pose_kinematics(m, d, &t, &map, q, v, a);
  stat cop_hip[2] = {0}, cop_com[2] = {0}, abd[2] = {0}, mom[2] = {0}, ang = {0}, bend = {0},
       sway = {0}, resf = {0}, resm = {0}, knee[2] = {{0}}, resf_axis[3] = {{0}},
       resm_axis[3] = {{0}};
  double weight = mj_getTotalmass(m) * mju_norm3(m->opt.gravity);
  gsBalance* all = rows ? (gsBalance*)malloc(sizeof(gsBalance) * (size_t)n) : NULL;
  int* loaded = rows ? (int*)malloc(sizeof(int) * (size_t)(2 * n)) : NULL;
  if (rows && (!all || !loaded)) {
    fprintf(stderr, "gaitsim: balance: out of memory\n");
    free(all);
    free(loaded);
    goto done;
  }
  for (int i = 0; i < n; i++) {
    mj_resetData(m, d);  // only the coordinates and speeds matter to the balance
    mju_copy(d->qpos, q + i * nq, nq);
    mju_copy(d->qvel, v + i * nv, nv);
    gsFootLoad load[2];
    gs_balance_loads_at(&g, col, t.time[i], BALANCE_STANCE_N, load);
    gsBalance b;
    gs_balance_eval(m, d, &spec, a + i * nv, load, &b);
    if (rows) {
      all[i] = b;
      loaded[2 * i] = load[0].loaded;
      loaded[2 * i + 1] = load[1].loaded;
    }
    for (int s = 0; s < 2; s++) {
      if (load[s].loaded) add(&knee[s], b.knee_adduction_moment[s]);
      if (!load[s].loaded || load[1 - s].loaded) continue;  // single stance of foot s
      add(&cop_hip[s], b.cop_lateral_hip[s]);
      add(&cop_com[s], b.cop_lateral_com[s]);
      add(&abd[s], -b.hip_adduction_moment[s]);
      add(&mom[s], fabs(b.grf_moment[0]));
    }
    add(&ang, b.angmom[0]);
    add(&bend, b.lumbar_bending);
    add(&sway, b.trunk_lateral);
    add(&resf, mju_norm3(b.residual_force));
    add(&resm, mju_norm3(b.residual_moment));
    for (int k = 0; k < 3; k++) {
      add(&resf_axis[k], b.residual_force[k]);
      add(&resm_axis[k], b.residual_moment[k]);
    }
  }
  printf("frontal-plane balance of %s with %s (%s, %d rows, %.3f-%.3f s; speeds %s)\n", pose,
         grf, path, n, t.time[0], t.time[n - 1],
         speeds ? "from the file" : "by central differences");
  printf("| single stance | right | left |\n|---|---|---|\n");
  printf("| rows | %d | %d |\n", cop_hip[0].n, cop_hip[1].n);
  printf("| centre of pressure minus hip centre, mean (cm, + lateral) | %.1f | %.1f |\n",
         100 * mean(&cop_hip[0]), 100 * mean(&cop_hip[1]));
  printf("| centre of pressure minus whole-body CoM, mean (cm, + lateral) | %.1f | %.1f |\n",
         100 * mean(&cop_com[0]), 100 * mean(&cop_com[1]));
  printf("| hip abductors' net moment by inverse dynamics, mean / peak (N m) | %.1f / %.1f | "
         "%.1f / %.1f |\n", mean(&abd[0]), abd[0].hi, mean(&abd[1]), abd[1].hi);
  printf("| ground reaction's frontal moment about the CoM, peak / RMS (N m) | %.1f / %.1f | "
         "%.1f / %.1f |\n", mom[0].hi, rms(&mom[0]), mom[1].hi, rms(&mom[1]));
  printf("| knee's net moment about knee_adduction through stance, mean / min / max (N m) |");
  for (int s = 0; s < 2; s++) {
    if (knee[s].n) printf(" %.1f / %.1f / %.1f |", mean(&knee[s]), knee[s].lo, knee[s].hi);
    else printf(" - (no knee_adduction%s) |", s == 0 ? "" : "_l");
  }
  printf("\n");
  printf("frontal angular momentum about the CoM: %.2f ... %.2f N m s\n", ang.lo, ang.hi);
  printf("lumbar_bending: %.1f ... %.1f deg\n", bend.lo * 180 / M_PI, bend.hi * 180 / M_PI);
  printf("trunk CoM sway about the whole-body CoM (range): %.1f cm\n", 100 * (sway.hi - sway.lo));
  printf("pelvis residuals, RMS: force %.1f N (%.3f BW), moment %.1f N m\n", rms(&resf),
         rms(&resf) / weight, rms(&resm));
  printf("pelvis residuals, stride mean: force along pelvis_tx / _ty / _tz %.1f / %.1f / %.1f N, "
         "moment about pelvis_rz / _rx / _ry %.1f / %.1f / %.1f N m\n", mean(&resf_axis[0]),
         mean(&resf_axis[1]), mean(&resf_axis[2]), mean(&resm_axis[0]), mean(&resm_axis[1]),
         mean(&resm_axis[2]));
  for (int s = 0; rows && s < 2; s++) {
    int has_knee = spec.knee_adduction[s] >= 0 && spec.ankle_joint[s] >= 0;
    double side = s == 0 ? -1.0 : 1.0;  // lateral: -y right, +y left
    printf("\n%s foot, every loaded row (distances in cm, forces in N, moments in N m; the knee's "
           "columns %s)\n", s == 0 ? "right" : "left",
           has_knee ? "about its knee_adduction" : "empty: no knee_adduction");
    printf("| time (s) | stride (%%) | centre of pressure in the foot, forward | and lateral | "
           "knee's net knee_adduction moment | ground reaction's part | centre of pressure "
           "lateral of the knee | force along the shank | force along the knee's lateral axis "
           "| lateral axis tilt (deg) | mediolateral ground force |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < n; i++) {
      if (!loaded[2 * i + s]) continue;
      const gsBalance* b = &all[i];
      gsFootLoad load[2];
      gs_balance_loads_at(&g, col, t.time[i], BALANCE_STANCE_N, load);
      printf("| %.4f | %.1f | %.2f | %.2f |", t.time[i],
             100 * (t.time[i] - t.time[0]) / (t.time[n - 1] - t.time[0]),
             100 * b->cop_foot_forward[s], 100 * b->cop_foot_lateral[s]);
      if (has_knee)
        printf(" %.2f | %.2f | %.2f | %.1f | %.1f | %.2f |", b->knee_adduction_moment[s],
               b->knee_grf_moment[s], 100 * b->cop_lateral_knee[s], b->knee_axial_force[s],
               b->knee_lateral_force[s], b->knee_lateral_tilt[s] * 180 / M_PI);
      else
        printf(" - | - | - | - | - | - |");
      printf(" %.1f |\n", side * load[s].force[1]);
    }
  }
  free(all);
  free(loaded);
  status = GS_EXIT_OK;
done:
  free(q);
  free(v);
  free(a);
  gs_state_map_free(&map);
  gs_table_free(&t);
  gs_table_free(&g);
  mj_deleteData(d);
  mj_deleteModel(m);
  return status;
}
