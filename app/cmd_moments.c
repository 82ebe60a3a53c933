// cmd_moments.c: `gaitsim moments MODEL --pose FILE --grf GRF.mot --out F.sto`: the net joint
// moments of a gait by inverse dynamics (what OpenSim's Inverse Dynamics tool writes), at every
// row of FILE under the ground reactions of GRF.mot: tau = M(q) qdd + c(q, qd) - sum_feet J^T [F; T]
// (callbacks/gs_balance.h, Winter 2009 ch. 5 in generalised coordinates). The same command on a
// trial's coordinates.mot with its plates and on a solution's states.sto with its grf.mot sets the
// solution's joint moments beside the measured gait's.
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_balance.h"
#include "callbacks/gs_state.h"
#include "io/gs_storage.h"

#define MOMENTS_LOADED_N 0.0  // a foot's ground reaction is applied whenever its vertical force is
                              // above this (N): all of it, as OpenSim's tool applies its loads

static const char* kMomentsUsage =
    "usage: gaitsim moments MODEL --pose FILE --grf GRF.mot --out F.sto\n"
    "\n"
    "The net joint moments of a gait by inverse dynamics, as OpenSim's Inverse Dynamics tool\n"
    "computes them, at every row of FILE (a solution's states.sto, or a trial's coordinates.mot;\n"
    "speeds missing from FILE and all accelerations by central differences of its rows) under the\n"
    "ground reactions of GRF.mot (OpenSim ExternalLoads columns, ground_force_r_vx ...\n"
    "ground_torque_l_z; each foot's force at its centre of pressure and its free moment, whenever\n"
    "the foot is loaded): each coordinate's net generalised force tau = M(q) qdd + c(q, qd) less\n"
    "the ground reactions' J^T [F; T], what the muscles and the passive structures (ligaments,\n"
    "joint-limit moments, the implant's contact) supply together. Written atomically to F.sto,\n"
    "one column per coordinate named as OpenSim names them: COORD_moment (N m) for a hinge,\n"
    "COORD_force (N) for a slide. The pelvis's six columns are the residuals: near zero for a\n"
    "solution with its own grf.mot (the accelerations by differences of the nodes leave a few per\n"
    "cent of body weight), the plates' and the markers' disagreement with the model for a\n"
    "measured gait. A coordinate that follows another through a coupling (jw_patella.xml's\n"
    "patfem_flexion) has its own column: its share, which the coupling carries to its driver.\n"
    "Prints the file written, its rows and the pelvis residuals' RMS.\n"
    "\n"
    "Set a solution beside its trial:\n"
    "  gaitsim moments MODEL --pose TRIAL/coordinates.mot --grf TRIAL/grf.mot --out measured.sto\n"
    "  gaitsim moments MODEL --pose D/states.sto --grf D/grf.mot --out solved.sto\n";

// the same file by name: an existing path whose device and inode equal another's
static int same_file(const char* a, const char* b) {
  struct stat sa, sb;
  return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

// the folder F.sto goes into exists and is a folder (checked before any work)
static int out_folder_ok(const char* out) {
  char dir[4096];
  if (snprintf(dir, sizeof(dir), "%s", out) >= (int)sizeof(dir)) {
    fprintf(stderr, "gaitsim: %s: path too long\n", out);
    return -1;
  }
  char* slash = strrchr(dir, '/');
  if (!slash) snprintf(dir, sizeof(dir), ".");
  else if (slash == dir) dir[1] = '\0';
  else *slash = '\0';
  struct stat st;
  if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
    fprintf(stderr, "gaitsim: %s: folder %s does not exist\n", out, dir);
    return -1;
  }
  if (stat(out, &st) == 0 && S_ISDIR(st.st_mode)) {
    fprintf(stderr, "gaitsim: %s: is a folder, not a file\n", out);
    return -1;
  }
  return 0;
}

// the columns written: every hinge and slide joint (col_of[joint] >= 0)
static int moment_columns(const mjModel* m, int* col_of, char** labels) {
  int n = 0;
  for (int j = 0; j < m->njnt; j++) {
    col_of[j] = -1;
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) continue;
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);  // NULL: an unnamed joint, "joint<j>"
    size_t len = (name ? strlen(name) : 16) + 8;
    labels[n] = (char*)malloc(len);
    if (!labels[n]) return -1;
    const char* kind = m->jnt_type[j] == mjJNT_HINGE ? "moment" : "force";
    if (name) snprintf(labels[n], len, "%s_%s", name, kind);
    else snprintf(labels[n], len, "joint%d_%s", j, kind);
    col_of[j] = n++;
  }
  return n;
}

int gs_cmd_moments(int argc, char** argv) {
  static const struct option options[] = {{"pose", required_argument, NULL, 'p'},
                                          {"grf", required_argument, NULL, 'g'},
                                          {"out", required_argument, NULL, 'o'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  const char *pose = NULL, *grf = NULL, *out = NULL;
  optind = 1;
  opterr = 0;
  int c;
  while ((c = getopt_long(argc, argv, ":p:g:o:h", options, NULL)) != -1) {
    switch (c) {
      case 'p': pose = optarg; break;
      case 'g': grf = optarg; break;
      case 'o': out = optarg; break;
      case 'h': fputs(kMomentsUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("moments", c, argv);
    }
  }
  if (gs_opt_one_operand("moments", "MODEL", argc, argv) != 0) return GS_EXIT_USAGE;
  if (!pose) return gs_opt_usage_error("moments", "missing --pose FILE");
  if (!grf) return gs_opt_usage_error("moments", "missing --grf GRF.mot");
  if (!out) return gs_opt_usage_error("moments", "missing --out F.sto");
  const char* path = argv[optind];
  if (same_file(out, pose) || same_file(out, grf) || same_file(out, path)) {
    fprintf(stderr, "gaitsim: %s: --out names an input file; it would be overwritten\n", out);
    return GS_EXIT_FAILURE;
  }
  if (out_folder_ok(out) != 0) return GS_EXIT_FAILURE;
  mjModel* m = gs_app_load_model(path);
  if (!m) return GS_EXIT_FAILURE;
  int status = GS_EXIT_FAILURE;
  mjData* d = mj_makeData(m);
  gsTable t, g, res;
  gs_table_init(&t);
  gs_table_init(&g);
  gs_table_init(&res);
  gsStateMap map = {0};
  gsBalanceSpec spec;
  char err[1024];
  int col[GS_GRF_NCOL];
  double *q = NULL, *v = NULL, *a = NULL, *tau = NULL;
  int* col_of = (int*)malloc(sizeof(int) * (size_t)(m->njnt > 0 ? m->njnt : 1));
  char** labels = (char**)calloc((size_t)(m->njnt > 0 ? m->njnt : 1), sizeof(char*));
  int ncol = 0;
  if (!col_of || !labels) {
    fprintf(stderr, "gaitsim: moments: out of memory\n");
    goto done;
  }
  if (gs_balance_spec(m, &spec, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    goto done;
  }
  if (gs_app_read_pose_and_loads(m, pose, grf, &t, &map, &g, col) != 0) goto done;
  ncol = moment_columns(m, col_of, labels);
  if (ncol < 0 || gs_table_create(&res, t.nrow, ncol, (const char* const*)labels, err,
                                  sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: moments: %s\n", ncol < 0 ? "out of memory" : err);
    goto done;
  }
  int n = t.nrow, nq = m->nq, nv = m->nv;
  q = (double*)malloc(sizeof(double) * (size_t)(n * nq));
  v = (double*)malloc(sizeof(double) * (size_t)(n * nv));
  a = (double*)malloc(sizeof(double) * (size_t)(n * nv));
  tau = (double*)malloc(sizeof(double) * (size_t)nv);
  if (!q || !v || !a || !tau) {
    fprintf(stderr, "gaitsim: moments: out of memory\n");
    goto done;
  }
  int speeds = gs_app_pose_kinematics(m, d, &t, &map, q, v, a);
  double sumf = 0, summ = 0;
  for (int i = 0; i < n; i++) {
    mj_resetData(m, d);
    mju_copy(d->qpos, q + i * nq, nq);
    mju_copy(d->qvel, v + i * nv, nv);
    gsFootLoad load[2];
    gs_balance_loads_at(&g, col, t.time[i], MOMENTS_LOADED_N, load);
    gsBalance b;
    gs_balance_eval_tau(m, d, &spec, a + i * nv, load, &b, tau);
    res.time[i] = t.time[i];
    for (int j = 0; j < m->njnt; j++)
      if (col_of[j] >= 0) res.data[i * ncol + col_of[j]] = tau[m->jnt_dofadr[j]];
    sumf += mju_dot3(b.residual_force, b.residual_force);
    summ += mju_dot3(b.residual_moment, b.residual_moment);
  }
  char src[8192], units[256];
  snprintf(src, sizeof(src), "source=gaitsim moments %s --pose %s --grf %s", path, pose, grf);
  for (char* s = src; *s; s++)
    if (*s == '\n' || *s == '\r') *s = ' ';
  snprintf(units, sizeof(units), "units=N m (COORD_moment), N (COORD_force); speeds %s",
           speeds ? "from the file" : "by central differences");
  const char* header[] = {"gaitsim_version=" GAITSIM_VERSION, src, units};
  if (gs_table_set_name(&res, "inverse_dynamics", err, sizeof(err)) != 0 ||
      gs_storage_write(out, &res, header, 3, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    goto done;
  }
  printf("moments: wrote %s: %d rows (%.4f-%.4f s), %d coordinates; speeds %s; pelvis "
         "residuals, RMS: force %.1f N, moment %.1f N m\n", out, n, t.time[0], t.time[n - 1],
         ncol, speeds ? "from the file" : "by central differences", sqrt(sumf / n),
         sqrt(summ / n));
  status = GS_EXIT_OK;
done:
  free(q);
  free(v);
  free(a);
  free(tau);
  free(col_of);
  if (labels)
    for (int j = 0; j < m->njnt; j++) free(labels[j]);
  free(labels);
  gs_state_map_free(&map);
  gs_table_free(&t);
  gs_table_free(&g);
  gs_table_free(&res);
  mj_deleteData(d);
  mj_deleteModel(m);
  return status;
}
