// cmd_track.c: `gaitsim track`: the tracking problem (Lin, Walter & Pandy 2018): one stride of the
// full-body muscle-driven model by direct collocation (optim/go_gait.h), tracking the measured
// coordinates and ground reactions of a trial; writes the solution as OpenSim storage files and a
// summary.
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>
#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "io/gs_atomic.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "optim/go_ipopt.h"
#include "optim/go_jacobian.h"

static const char* kTrackUsage =
    "usage: gaitsim track TRIAL_DIR --out DIR [options]\n\n"
    "Tracking solve of one stride: measured coordinates (TRIAL_DIR/coordinates.mot) and ground\n"
    "reactions (TRIAL_DIR/grf.mot) tracked by the muscle-driven model. Writes DIR/states.sto,\n"
    "controls.sto, grf.mot, muscle_forces.sto, summary.json. Exit status 3 when the solver stopped\n"
    "short (its best iterate is written).\n\n"
    "  --model FILE        MJCF model (default: mjmodels/jw_fullbody.xml)\n"
    "  --nodes N           collocation nodes (default 80)\n"
    "  --threads N         worker threads (default 2)\n"
    "  --max-iter N        Ipopt iteration limit (default 1000)\n"
    "  --max-time S        wall-clock limit, s (default none)\n"
    "  --activation A      initial activations and excitations (default 0.05)\n"
    "  --ipopt KEY=VALUE   extra Ipopt option (repeatable)\n";

typedef struct {
  const char* trial;   // trial folder
  const char* out;     // output folder
  const char* model;   // MJCF path
  int nodes;           // collocation nodes
  int threads;         // workers
  int max_iter;        // iteration limit
  double max_time;     // wall limit (s), <= 0: none
  double activation;   // initial activation (-)
  go_ipopt_opts ipopt; // solver options
} gsTrackOptions;

static int parse_int(const char* s, int lo, int* v) {
  char* end;
  long x = strtol(s, &end, 10);
  if (*end || end == s || x < lo || x > 1000000) return -1;
  *v = (int)x;
  return 0;
}

static int parse(int argc, char** argv, gsTrackOptions* o) {
  static const struct option options[] = {
      {"out", required_argument, NULL, 'o'},      {"model", required_argument, NULL, 'm'},
      {"nodes", required_argument, NULL, 'n'},    {"threads", required_argument, NULL, 't'},
      {"max-iter", required_argument, NULL, 'i'}, {"max-time", required_argument, NULL, 'T'},
      {"activation", required_argument, NULL, 'a'}, {"ipopt", required_argument, NULL, 'p'},
      {"help", no_argument, NULL, 'h'},           {NULL, 0, NULL, 0}};
  memset(o, 0, sizeof(*o));
  o->model = GS_DEFAULT_MODEL;
  o->nodes = 80;
  o->threads = 2;
  o->max_iter = 1000;
  o->activation = 0.05;
  go_ipopt_opts_default(&o->ipopt);
  optind = 1;
  int c;
  char err[256], *end;
  while ((c = getopt_long(argc, argv, "o:m:n:t:i:T:a:p:h", options, NULL)) != -1) {
    switch (c) {
      case 'o': o->out = optarg; break;
      case 'm': o->model = optarg; break;
      case 'n':
        if (parse_int(optarg, 3, &o->nodes)) return -1;
        break;
      case 't':
        if (parse_int(optarg, 1, &o->threads) || o->threads > 64) return -1;
        break;
      case 'i':
        if (parse_int(optarg, 0, &o->max_iter)) return -1;
        break;
      case 'T':
        o->max_time = strtod(optarg, &end);
        if (*end || end == optarg || !(o->max_time > 0)) return -1;
        break;
      case 'a':
        o->activation = strtod(optarg, &end);
        if (*end || end == optarg || !(o->activation >= 0.001 && o->activation <= 1)) return -1;
        break;
      case 'p':
        if (go_ipopt_opts_add(&o->ipopt, optarg, err, sizeof(err)) != 0) {
          fprintf(stderr, "gaitsim: track: %s\n", err);
          return -1;
        }
        break;
      case 'h': fputs(kTrackUsage, stdout); exit(GS_EXIT_OK);
      default: return -1;
    }
  }
  if (optind != argc - 1 || !o->out) return -1;
  o->trial = argv[optind];
  return 0;
}

static double sq(double x) { return x * x; }

// write the solution tables and accumulate the RMS errors into summary
static int write_solution(go_gait* g, const double* z, const char* out, cJSON* summary) {
  const mjModel* m = go_gait_model(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int N = go_gait_nodes(g), nv = L->nv, na = L->na, status = -1;
  double T = go_gait_stride_time(g), bw = go_gait_weight(g);
  mjData* d = mj_makeData(m);
  gsTable states, controls, grf, forces;
  gs_table_init(&states);
  gs_table_init(&controls);
  gs_table_init(&grf);
  gs_table_init(&forces);
  const char** names = (const char**)calloc((size_t)na, sizeof(char*));
  for (int i = 0; i < na; i++) names[i] = mj_id2name(m, mjOBJ_ACTUATOR, i);
  char err[512];
  if (gs_state_table_create(m, N, &states, err, sizeof(err)) != 0 ||
      gs_table_create(&controls, N, na, names, err, sizeof(err)) != 0 ||
      gs_grf_table_create(N, &grf, err, sizeof(err)) != 0 ||
      gs_table_create(&forces, N, na, names, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: track: %s\n", err);
    goto done;
  }
  // sums of squares: pelvis rot, pelvis trans, joint rot, grf ap, v, ml; counts
  double ss[6] = {0}, cnt[6] = {0};
  for (int k = 0; k < N; k++) {
    const double* zk = z + (size_t)k * L->nz;
    double t = T * k / (N - 1);
    go_gait_load_node(g, d, zk);
    gs_state_table_set_row(m, d, t, &states, k);
    gs_grf_table_set_row(m, d, t, &grf, k);
    controls.time[k] = forces.time[k] = t;
    for (int i = 0; i < na; i++) {
      controls.data[k * na + i] = zk[L->u_e + i];
      forces.data[k * na + i] = gs_physics_muscle_tension(m, d, i, NULL);
    }
    for (int j = 0; j < nv; j++) {
      double ref = go_gait_q_ref(g, k, j);
      if (!isfinite(ref)) continue;
      int jnt = m->dof_jntid[j];
      const char* name = mj_id2name(m, mjOBJ_JOINT, jnt);
      int slide = m->jnt_type[jnt] == mjJNT_SLIDE;
      int root = go_gait_dof_is_root(m, j);
      int grp = root ? (slide ? 1 : 0) : (slide ? -1 : 2);
      if (grp == 2 && (strcmp(name, "knee_adduction") == 0 || strcmp(name, "knee_rotation") == 0))
        grp = -1;
      if (grp < 0) continue;
      double e = zk[L->x_q + j] - ref;
      ss[grp] += sq(grp == 1 ? 100 * e : e * 180 / M_PI);
      cnt[grp]++;
    }
    for (int s = 0; s < 2; s++) {
      gsFootGrf fg;
      gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &fg);
      static const int comp[3] = {0, 2, 1};  // ap = x, vertical = z, ml = y (world)
      for (int c = 0; c < 3; c++) {
        double ref = go_gait_grf_ref(g, k, 3 * s + comp[c]);
        if (!isfinite(ref)) continue;
        ss[3 + c] += sq((fg.force[comp[c]] - ref) / bw);
        cnt[3 + c]++;
      }
    }
  }
  static const char* keys[6] = {"pelvis_rot_deg", "pelvis_trans_cm", "joint_rot_deg",
                                "grf_ap_bw", "grf_v_bw", "grf_ml_bw"};
  cJSON* rms = cJSON_AddObjectToObject(summary, "rms");
  for (int q = 0; q < 6; q++) {
    if (cnt[q] > 0) cJSON_AddNumberToObject(rms, keys[q], sqrt(ss[q] / cnt[q]));
    else cJSON_AddNullToObject(rms, keys[q]);
  }
  if (L->tx >= 0) {
    double dx = z[(size_t)(N - 1) * L->nz + L->x_q + L->tx] - z[L->x_q + L->tx];
    cJSON_AddNumberToObject(summary, "speed_mps", dx / T);
  }
  gs_table_to_degrees(&states, gs_state_is_angle, (void*)m);
  if (gs_app_write_table(out, "states.sto", &states) == 0 &&
      gs_app_write_table(out, "controls.sto", &controls) == 0 &&
      gs_app_write_table(out, "grf.mot", &grf) == 0 &&
      gs_app_write_table(out, "muscle_forces.sto", &forces) == 0) {
    status = 0;
  }
done:
  free(names);
  gs_table_free(&states);
  gs_table_free(&controls);
  gs_table_free(&grf);
  gs_table_free(&forces);
  mj_deleteData(d);
  return status;
}

// largest scaled violation per constraint block, one line to stderr
static void print_blocks(go_gait* g, const double* gv, const char* when) {
  go_nlp* nlp = go_gait_nlp(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int N = go_gait_nodes(g), n, mm, ne;
  go_nlp_sizes(nlp, &n, &mm, &ne);
  double mx[7] = {0};
  int at[7] = {0};
  static const char* names[7] = {"defect", "link", "eom", "hill", "act", "grf", "boundary"};
  for (int r = 0; r < mm; r++) {
    int blk;
    int p0 = go_nlp_row_path(nlp, 0, 0), b0 = go_nlp_row_boundary(nlp, 0);
    if (r < p0) {
      blk = 0;
    } else if (r < p0 + N * L->n_path) {
      int pr = (r - p0) % L->n_path;
      blk = pr < L->r_eom ? 1 : pr < L->r_hill ? 2 : pr < L->r_act ? 3 : pr < L->r_grf ? 4 : 5;
    } else {
      blk = 6;
    }
    (void)b0;
    if (fabs(gv[r]) > mx[blk]) {
      mx[blk] = fabs(gv[r]);
      at[blk] = blk == 0 ? r % L->nx : blk < 6 ? (r - p0) % L->n_path : r - b0;
    }
  }
  fprintf(stderr, "track: %s violation by block:", when);
  for (int b = 0; b < 7; b++) fprintf(stderr, " %s %.3g (#%d)", names[b], mx[b], at[b]);
  fprintf(stderr, "\n");
}

int gs_cmd_track(int argc, char** argv) {
  gsTrackOptions o;
  if (parse(argc, argv, &o) != 0) {
    fputs(kTrackUsage, stderr);
    return GS_EXIT_USAGE;
  }
  mjModel* m = gs_app_load_model(o.model);
  if (!m) return GS_EXIT_FAILURE;
  int status = GS_EXIT_FAILURE;
  gsTable coords, grf;
  gs_table_init(&coords);
  gs_table_init(&grf);
  go_gait* g = NULL;
  double *z = NULL, *zb = NULL, *zs = NULL, *gv = NULL;
  cJSON* summary = NULL;
  char path[4096], err[1024];
  snprintf(path, sizeof(path), "%s/coordinates.mot", o.trial);
  if (gs_app_read_table(m, path, &coords) != 0) goto done;
  snprintf(path, sizeof(path), "%s/grf.mot", o.trial);
  if (gs_app_read_table(m, path, &grf) != 0) goto done;
  if (gs_mkdir_p(o.out, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", o.out, err);
    goto done;
  }
  go_gait_opts go;
  go_gait_opts_default(&go);
  static const char* free_coords[] = {"pelvis_tz", NULL};  // the trial drifts sideways
  go.N = o.nodes;
  go.nthreads = o.threads;
  go.coords = &coords;
  go.grf = &grf;
  go.free_coords = free_coords;
  if (go_gait_create(&g, m, &go, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: track: %s\n", err);
    goto done;
  }
  go_nlp* nlp = go_gait_nlp(g);
  int n, mm, ne;
  go_nlp_sizes(nlp, &n, &mm, &ne);
  z = (double*)malloc(sizeof(double) * (size_t)n);
  zb = (double*)malloc(sizeof(double) * (size_t)n);
  zs = (double*)malloc(sizeof(double) * (size_t)n);
  gv = (double*)malloc(sizeof(double) * (size_t)mm);
  if (go_gait_guess_from_trial(g, &coords, o.activation, z, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: track: %s\n", err);
    goto done;
  }
  go_nlp_scale_z(nlp, z, zs);
  double viol0 = go_nlp_eval_g(nlp, zs, gv) == 0 ? go_nlp_violation(nlp, gv) : INFINITY;
  fprintf(stderr, "track: %d nodes, %d variables, %d constraints, %d Jacobian nonzeros, %d "
          "colour groups, %d threads; initial violation %.3g\n", o.nodes, n, mm, ne,
          go_nlp_path_groups(nlp), o.threads, viol0);
  print_blocks(g, gv, "initial");
  o.ipopt.max_iter = o.max_iter;
  o.ipopt.max_wall_s = o.max_time;
  o.ipopt.progress = stderr;
  o.ipopt.handle_sigint = 1;
  go_solve_result res;
  if (go_ipopt_solve(nlp, &o.ipopt, z, zb, NULL, &res, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: track: %s\n", err);
    goto done;
  }
  int converged = res.status == GO_SOLVE_SUCCESS || res.status == GO_SOLVE_ACCEPTABLE;
  const double* zout = converged || res.best_iter < 0 ? z : zb;
  go_nlp_scale_z(nlp, zout, zs);
  double viol = go_nlp_eval_g(nlp, zs, gv) == 0 ? go_nlp_violation(nlp, gv) : INFINITY;
  print_blocks(g, gv, "final");
  double max_defect = 0;
  const go_gait_layout* L = go_gait_layout_get(g);
  for (int r = 0; r < (o.nodes - 1) * L->nx; r++) max_defect = fmax(max_defect, fabs(gv[r]));
  summary = cJSON_CreateObject();
  cJSON_AddStringToObject(summary, "problem", "tracking");
  cJSON_AddStringToObject(summary, "model", o.model);
  cJSON_AddStringToObject(summary, "trial", o.trial);
  cJSON_AddStringToObject(summary, "status", go_solve_status_str(res.status));
  cJSON_AddNumberToObject(summary, "iterations", res.iterations);
  cJSON_AddNumberToObject(summary, "wall_s", res.wall_s);
  cJSON_AddNumberToObject(summary, "cpu_s", res.cpu_s);
  cJSON_AddNumberToObject(summary, "nodes", o.nodes);
  cJSON_AddNumberToObject(summary, "threads", o.threads);
  cJSON_AddNumberToObject(summary, "stride_time_s", go_gait_stride_time(g));
  cJSON_AddNumberToObject(summary, "objective", zout == z ? res.objective : res.best_objective);
  cJSON_AddNumberToObject(summary, "initial_violation", viol0);
  cJSON_AddNumberToObject(summary, "max_violation", viol);
  cJSON_AddNumberToObject(summary, "max_defect", max_defect);
  cJSON_AddBoolToObject(summary, "best_iterate_written", zout == zb);
  if (write_solution(g, zout, o.out, summary) != 0) goto done;
  char* text = cJSON_Print(summary);
  snprintf(path, sizeof(path), "%s/summary.json", o.out);
  size_t len = text ? strlen(text) : 0;
  int wrote = text && gs_atomic_write_buffer(path, text, len, err, sizeof(err)) == 0;
  free(text);
  if (!wrote) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    goto done;
  }
  printf("track: %s after %d iterations, %.1f s; max violation %.3g (from %.3g); wrote %s\n",
         go_solve_status_str(res.status), res.iterations, res.wall_s, viol, viol0, o.out);
  status = converged ? GS_EXIT_OK : GS_EXIT_STOPPED_SHORT;

done:
  cJSON_Delete(summary);
  free(z), free(zb), free(zs), free(gv);
  go_gait_free(g);
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  return status;
}
