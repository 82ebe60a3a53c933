// cmd_solve.c: `gaitsim track` and `gaitsim predict` (Lin, Walter & Pandy 2018): one stride of
// the full-body muscle-driven model by direct collocation (optim/go_gait.h), either tracking the
// measured coordinates and ground reactions of a trial or, at a prescribed speed, minimising the
// cost of transport from a tracking solution. Both share one pipeline: problem, initial guess,
// the solve strategy (optim/go_solve.h: Ipopt, restarts, refinement, feasibility polish), and the
// solution folder (OpenSim storage files, variables.sto for restarts, summary.json).
#define _POSIX_C_SOURCE 200809L
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>
#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_knee.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_knee_reaction.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "io/gs_atomic.h"
#include "io/gs_storage.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "optim/go_ipopt.h"
#include "optim/go_solve.h"

static const char* kTrackUsage =
    "usage: gaitsim track TRIAL_DIR --out DIR [options]\n\n"
    "Tracking solve of one stride: measured coordinates (TRIAL_DIR/coordinates.mot) and ground\n"
    "reactions (TRIAL_DIR/grf.mot) tracked by the muscle-driven model. Writes DIR/states.sto,\n"
    "controls.sto, grf.mot, muscle_forces.sto, metabolics.sto (W per muscle and total),\n"
    "knee_contact.sto (right knee; left knee contact_total_l from its joint reaction),\n"
    "variables.sto (every node variable: the exact restart) and summary.json (with the peak\n"
    "knee contact forces). Exit status 3 when the solver stopped short (its best iterate,\n"
    "polished, is written).\n\n"
    "  --model FILE        MJCF model (default: mjmodels/jw_fullbody_knee6.xml, the six-DOF\n"
    "                      implant knee; mjmodels/jw_fullbody.xml has the placeholder knee)\n"
    "  --nodes N           collocation nodes (default " GO_STR(GO_NODES_TRACK) ")\n"
    "  --init DIR          start from the solution in DIR: its variables.sto on the same nodes,\n"
    "                      or refined from fewer (N - 1 a multiple, e.g. 20 -> 39 -> 77, defects\n"
    "                      kept), else its states.sto and controls.sto interpolated (default:\n"
    "                      the trial)\n"
    "  --threads N         worker threads (default " GO_STR(GO_THREADS) ")\n"
    "  --max-iter N        Ipopt iteration limit of the main solve (default "
    GO_STR(GO_MAX_ITER_TRACK) "; 300 with\n"
    "                      --hessian lbfgs)\n"
    "  --max-time S        wall-clock limit, s (default none)\n"
    "  --activation A      initial activations and excitations (default " GO_STR(GO_ACTIVATION)
    ")\n"
    "  --guess-method M    initial guess from the trial (without --init): trial (default:\n"
    "                      measured coordinates, activations A) or static (static optimisation\n"
    "                      at every node: min sum a^2 with the muscles' force-length-velocity\n"
    "                      forces matching the inverse-dynamics moments of every dof but the\n"
    "                      pelvis and the spring-held knee dofs, measured GRF at the measured\n"
    "                      centres of pressure; tendon forces from the muscle forces)\n"
    "  --hessian H         Hessian of the main solve: gauss-newton (default: exact for the\n"
    "                      tracking squares, the constraints' curvature left out; from an\n"
    "                      initial barrier of " GO_STR(GO_GN_MU_INIT) "), lbfgs (Ipopt's limited-memory\n"
    "                      quasi-Newton), pqn (partitioned quasi-Newton, SR1 per node element;\n"
    "                      experimental) or exact (the Lagrangian's Hessian by structured\n"
    "                      finite differences)\n"
    "  --weight NAME=W     goal weight, NAME one of pelvis_rot (default "
    GO_STR(GO_TRACK_W_PELVIS_ROT) "), pelvis_trans (" GO_STR(GO_TRACK_W_PELVIS_TRANS) "),\n"
    "                      joint (" GO_STR(GO_TRACK_W_JOINT) "), grf (" GO_STR(GO_TRACK_W_GRF)
    "), grm (" GO_STR(GO_TRACK_W_GRM) "), effort (" GO_STR(GO_TRACK_W_EFFORT) "), accel ("
    GO_STR(GO_TRACK_W_ACCEL) ") (repeatable);\n"
    "                      grm: the ground reaction moment about the origin (centre of pressure\n"
    "                      x force, so the feet's placement); each tracking group is a mean of\n"
    "                      squared errors over 5 deg, 2 cm, 0.1 BW or 0.1 BW x 0.1 m;\n"
    "                      accel: the mean over all coordinates of (qddot / 50 rad/s^2 or\n"
    "                      m/s^2)^2, a smoothness regularisation. summary.json: objective_terms\n"
    "                      (each goal's part of J) and objective_share (its fraction of J)\n"
    "  --no-polish         no feasibility polish (by default a solve that stops short is\n"
    "                      followed by a Gauss-Newton projection of its best iterate onto the\n"
    "                      dynamics: the nearest dynamically consistent point)\n"
;
// (in two parts: C11 compilers need not take string literals over 4095 characters)
static const char* kTrackUsageSolver =
    "  --fallback-rise F   stop when the objective rises by more than the fraction F above the\n"
    "                      lowest one reached at a violation <= " GO_STR(GO_FALLBACK_VIOL)
    ", and restart from the\n"
    "                      best iterate (at most " GO_STR(GO_MAX_RESTARTS) " times; summary.json "
    "restarts); default " GO_STR(GO_FALLBACK_RISE) ",\n"
    "                      0 turns the guard off\n"
    "  --refine N          after a Gauss-Newton or L-BFGS main solve that stopped short (as\n"
    "                      the default one does after --max-iter iterations), up to N Newton\n"
    "                      iterations with the exact Hessian (structured finite differences)\n"
    "                      from its best iterate (default " GO_STR(GO_REFINE_ITER) "; 0: none;\n"
    "                      summary.json refine). They stop at Ipopt's tests or once the\n"
    "                      objective has settled: " GO_STR(GO_SETTLE_ITER) " of the last "
    "2 x " GO_STR(GO_SETTLE_ITER) " iterations\n"
    "                      at a violation <= " GO_STR(GO_SETTLE_VIOL) ", their objectives within "
    GO_STR(GO_SETTLE_REL) " relative per\n"
    "                      iteration (status \"objective settled\")\n"
    "  --refine-gn N       Gauss-Newton iterations (the goals' Hessian, without the constraints'\n"
    "                      curvature) that start the refinement; the Newton iterations start\n"
    "                      where they stop (default "
    GO_STR(GO_REFINE_GN_ITER) ";\n"
    "                      0: none; summary.json refine.gauss_newton)\n"
    "  --refine-after N    with --hessian lbfgs: hands over to the refinement at its first\n"
    "                      iterate from iteration N on at a violation <= 1e-3 (a point the\n"
    "                      refinement and the polish can start from; status \"handed over to\n"
    "                      the refinement\"), --max-iter staying its cap (default "
    GO_STR(GO_HANDOVER_ITER_TRACK) ";\n"
    "                      0: L-BFGS runs to --max-iter)\n"
    "  --refine-time S     the refinement's wall-clock limit in seconds (default none: it\n"
    "                      stops at the same iterate on any machine; --max-time, when given,\n"
    "                      caps it too)\n"
    "  --ipopt KEY=VALUE   extra Ipopt option (repeatable)\n";

typedef struct {
  const char* trial;   // trial folder
  const char* out;     // output folder
  const char* model;   // MJCF path
  const char* init;    // solution folder to start from (NULL: the trial)
  int nodes;           // collocation nodes
  int threads;         // workers
  double activation;   // initial activation (-)
  int guess_static;    // 1: static-optimisation guess (go_gait_guess_static), 0: the trial's
  go_solve_plan plan;  // the solve strategy's settings: Ipopt options, Hessian, iteration and
                       // wall-clock limits, restarts, refinement, polish (optim/go_solve.h)
  double w_pelvis_rot, w_pelvis_trans, w_joint, w_grf, w_effort;  // goal weights (-)
  double w_grm;        // weight of the ground reaction moment (centre of pressure) goal (-)
  double w_accel;      // weight of the mean squared acceleration (qddot / 50)^2 (-)
  int fibre_bounds;    // predict: 1: 0.25 <= lM/lopt <= 1.5 path rows (go_gait_opts.fibre_bounds)
  int predict;         // 1: the predictive problem (gaitsim predict)
  const char* guess;   // predict: solution folder to start from (the tracking solution)
  double speed;        // predict: prescribed mean speed (m/s)
  double metabolic_smoothing;  // predict: factor on the smooth Umberger widths (-), 1
  double min_vgrf;     // predict: floor on the summed vertical ground reaction of both feet at
                       // every node (BW; go_gait_opts.min_vgrf), 0: none
  double stride_time;  // predict: > 0: the stride time held at this value (s), 0: free
  double stride_time_start;  // predict: > 0: a free stride time's starting value (s), 0: the
                             // guess's
  double band_scale;   // predict: factor on the half-widths of eq. 3's band (PREDICT_BAND_*; -),
                       // 0: no band
} gsTrackOptions;

// --weight NAME=VALUE
static int parse_weight(const char* arg, gsTrackOptions* o) {
  static const char* names[] = {"pelvis_rot", "pelvis_trans", "joint", "grf",
                                "grm",        "effort",       "accel"};
  double* slots[] = {&o->w_pelvis_rot, &o->w_pelvis_trans, &o->w_joint, &o->w_grf,
                     &o->w_grm,        &o->w_effort,       &o->w_accel};
  const char* eq = strchr(arg, '=');
  for (int i = 0; eq && i < 7; i++) {
    if (strlen(names[i]) == (size_t)(eq - arg) && strncmp(arg, names[i], (size_t)(eq - arg)) == 0) {
      char label[64];
      snprintf(label, sizeof(label), "--weight %s", names[i]);
      return gs_opt_real(label, eq + 1, 0, HUGE_VAL, 0, slots[i]);
    }
  }
  fprintf(stderr, "gaitsim: --weight: must be NAME=W, NAME one of pelvis_rot, pelvis_trans, "
          "joint, grf, grm, effort, accel (got %s)\n", arg);
  return -1;
}

// the defaults of every option (tracking; gaitsim predict changes a few): the solve strategy's
// (stopping rule, fall-back guard, refinement, polish) from go_solve_plan_default, the values
// from optim/go_defaults.h
static void defaults(gsTrackOptions* o) {
  memset(o, 0, sizeof(*o));
  o->model = GS_DEFAULT_MODEL;
  o->nodes = GO_NODES_TRACK;
  o->threads = GO_THREADS;
  o->activation = GO_ACTIVATION;
  go_solve_plan_default(&o->plan);
  o->plan.hessian = GO_HESSIAN_GAUSS_NEWTON;  // predict: L-BFGS
  o->plan.max_iter = GO_MAX_ITER_TRACK;
  o->plan.handover_iter = GO_HANDOVER_ITER_TRACK;
  o->plan.progress = stderr;
  o->w_pelvis_rot = GO_TRACK_W_PELVIS_ROT;
  o->w_pelvis_trans = GO_TRACK_W_PELVIS_TRANS;
  o->w_grf = GO_TRACK_W_GRF;
  o->w_grm = GO_TRACK_W_GRM;
  o->w_joint = GO_TRACK_W_JOINT;
  o->w_effort = GO_TRACK_W_EFFORT;
  o->w_accel = GO_TRACK_W_ACCEL;  // predict: GO_PREDICT_W_ACCEL
  o->fibre_bounds = 0; // tracking: none; predict: on (--no-fibre-bounds)
  o->metabolic_smoothing = 1.0;
  o->plan.label = "track";  // the refinement: tracking only; predict turns it off
}

// the options of gaitsim track into o; 0, or GS_EXIT_USAGE after one line on stderr (the usage
// text goes to stdout for --help: -1)
static int parse(int argc, char** argv, gsTrackOptions* o) {
  char err[256];
  static const struct option options[] = {
      {"out", required_argument, NULL, 'o'},      {"model", required_argument, NULL, 'm'},
      {"nodes", required_argument, NULL, 'n'},    {"threads", required_argument, NULL, 't'},
      {"max-iter", required_argument, NULL, 'i'}, {"max-time", required_argument, NULL, 'T'},
      {"activation", required_argument, NULL, 'a'}, {"ipopt", required_argument, NULL, 'p'},
      {"hessian", required_argument, NULL, 'H'},  {"weight", required_argument, NULL, 'w'},
      {"init", required_argument, NULL, 'I'},     {"no-polish", no_argument, NULL, 'P'},
      {"guess-method", required_argument, NULL, 'G'},
      {"fallback-rise", required_argument, NULL, 'R'},
      {"refine", required_argument, NULL, 'r'},
      {"refine-time", required_argument, NULL, 'W'},
      {"refine-gn", required_argument, NULL, 'g'},
      {"refine-after", required_argument, NULL, 'A'},
      {"help", no_argument, NULL, 'h'},           {NULL, 0, NULL, 0}};
  static const char* const hessians[] = {"lbfgs", "pqn", "exact", "gauss-newton", NULL};
  static const go_hessian_kind kinds[] = {GO_HESSIAN_LBFGS, GO_HESSIAN_PQN, GO_HESSIAN_EXACT,
                                          GO_HESSIAN_GAUSS_NEWTON};
  static const char* const guesses[] = {"trial", "static", NULL};
  defaults(o);
  optind = 1;
  opterr = 0;
  int c, bad = 0, k;
  while (!bad &&
         (c = getopt_long(argc, argv, ":o:m:n:t:i:T:a:p:H:w:I:G:R:r:W:g:A:Ph", options, NULL)) != -1) {
    switch (c) {
      case 'o': o->out = optarg; break;
      case 'm': o->model = optarg; break;
      case 'n': bad = gs_opt_int("--nodes", optarg, GS_MIN_NODES, GS_MAX_NODES, &o->nodes); break;
      case 't': bad = gs_opt_int("--threads", optarg, 1, 64, &o->threads); break;
      case 'i':
        bad = gs_opt_int("--max-iter", optarg, 0, GS_OPT_NO_MAX, &o->plan.max_iter);
        break;
      case 'T':
        bad = gs_opt_real("--max-time", optarg, 0, HUGE_VAL, GS_OPT_LO_OPEN, &o->plan.max_wall_s);
        break;
      case 'R':
        bad = gs_opt_real("--fallback-rise", optarg, 0, HUGE_VAL, 0,
                          &o->plan.ipopt.fallback_rise);
        break;
      case 'r':
        bad = gs_opt_int("--refine", optarg, 0, GS_OPT_NO_MAX, &o->plan.refine_iter);
        break;
      case 'g':
        bad = gs_opt_int("--refine-gn", optarg, 0, GS_OPT_NO_MAX, &o->plan.refine_gn_iter);
        break;
      case 'A':
        bad = gs_opt_int("--refine-after", optarg, 0, GS_OPT_NO_MAX, &o->plan.handover_iter);
        break;
      case 'W':
        bad = gs_opt_real("--refine-time", optarg, 0, HUGE_VAL, GS_OPT_LO_OPEN,
                          &o->plan.refine_wall_s);
        break;
      case 'a': bad = gs_opt_real("--activation", optarg, 0.001, 1, 0, &o->activation); break;
      case 'p':
        if (go_ipopt_opts_add(&o->plan.ipopt, optarg, err, sizeof(err)) != 0) {
          fprintf(stderr, "gaitsim: --ipopt: %s\n", err);
          bad = 1;
        }
        break;
      case 'H':
        bad = gs_opt_choice("--hessian", optarg, hessians, &k);
        if (!bad) o->plan.hessian = kinds[k];
        break;
      case 'w': bad = parse_weight(optarg, o); break;
      case 'I': o->init = optarg; break;
      case 'G':
        bad = gs_opt_choice("--guess-method", optarg, guesses, &k);
        o->guess_static = !bad && k == 1;
        break;
      case 'P': o->plan.polish = 0; break;
      case 'h':
        fputs(kTrackUsage, stdout);
        fputs(kTrackUsageSolver, stdout);
        return -1;
      default: return gs_opt_getopt_error("track", c, argv);
    }
  }
  if (bad) return GS_EXIT_USAGE;
  if (gs_opt_one_operand("track", "TRIAL_DIR", argc, argv) != 0) return GS_EXIT_USAGE;
  if (!o->out) return gs_opt_usage_error("track", "missing --out DIR");
  if (o->guess_static && o->init)
    return gs_opt_usage_error("track", "--guess-method static and --init exclude each other");
  o->trial = argv[optind];
  return 0;
}

static double sq(double x) { return x * x; }

// Scale the measured ground reactions (force and free-torque columns) so that their stride-mean
// total vertical force equals the model's weight, and return the factor. The force plates imply
// 65.85 kg for JW's trial against the scaled model's 62.64 kg; a periodic solve can only
// average m g, so unscaled data would leave a constant vertical offset of 0.05 BW. Tracking and
// the reported RMS errors are thereby in each one's own body weights (the paper's BW). Returns
// 0 when the table has no vertical force columns or no positive mean.
static double normalise_grf_to_weight(gsTable* grf, double weight) {
  int cr = gs_table_column(grf, "ground_force_r_vy"), cl = gs_table_column(grf, "ground_force_l_vy");
  if (cr < 0 || cl < 0 || grf->nrow < 2) return 0;
  double area = 0, span = grf->time[grf->nrow - 1] - grf->time[0];
  for (int i = 0; i + 1 < grf->nrow; i++) {
    double a = grf->data[i * grf->ncol + cr] + grf->data[i * grf->ncol + cl];
    double b = grf->data[(i + 1) * grf->ncol + cr] + grf->data[(i + 1) * grf->ncol + cl];
    area += 0.5 * (a + b) * (grf->time[i + 1] - grf->time[i]);
  }
  if (!(area > 0 && span > 0)) return 0;
  double factor = weight / (area / span);
  for (int j = 0; j < grf->ncol; j++) {
    const char* lab = grf->labels[j];
    int force = strncmp(lab, "ground_force_", 13) == 0 && strstr(lab, "_v") != NULL;
    int torque = strncmp(lab, "ground_torque_", 14) == 0;
    if (!force && !torque) continue;
    for (int i = 0; i < grf->nrow; i++) grf->data[i * grf->ncol + j] *= factor;
  }
  return factor;
}

// Right (implant) knee contact forces (N) at the loaded state d into f = {medial, lateral, total}.
// A model with the gs_knee numerics (callbacks/gs_knee.h): the surrogate's compartment forces'
// axial (compressive) components in the tibial_tray frame, as the eTibia measures them
// (d->qfrc_passive gains the knee loads once more: d is scratch). The placeholder knee
// (a stiff spring-damper on knee_ty, mjmodels/README.md): total only, the spring-damper force
// -(k (q - q_spring) + b qdot) along the joint axis, which points from the femoral component to
// the tibial tray (-y of the femoral component), so compression gives a positive force; medial
// and lateral NAN. All NAN without a knee_ty joint.
static void knee_contact(const mjModel* m, mjData* d, double f[3], double* ligament) {
  f[0] = f[1] = f[2] = *ligament = NAN;
  gsKneeLoads loads;
  if (gs_knee_passive(m, d, &loads) == 1) {
    *ligament = loads.ligament_force;
    // what the eTibia's load cells measure (Fregly et al. 2012): the axial component, along the
    // tibial_tray y axis (the tray's long axis); the surrogate's force on the tibia points -y in
    // compression. Shear (the posterior slope, roll-back) is left out as in the measurement.
    f[0] = -loads.contact.force[0][1];
    f[1] = -loads.contact.force[1][1];
    f[2] = f[0] + f[1];
    return;
  }
  int j = mj_name2id(m, mjOBJ_JOINT, "knee_ty");
  if (j < 0 || m->jnt_type[j] != mjJNT_SLIDE) return;
  int qa = m->jnt_qposadr[j], da = m->jnt_dofadr[j];
  double spring = -m->jnt_stiffness[j] * (d->qpos[qa] - m->qpos_spring[qa]);
  double damper = -m->dof_damping[da] * d->qvel[da];
  f[2] = spring + damper;
}

// Name of node variable j (go_gait.h layout), e.g. "q.hip_flexion", "qddot.hip_flexion",
// "a.soleus", "fT.soleus", "e.soleus", "grf.r_y": the columns of variables.sto
static void variable_name(const go_gait* g, int j, char* buf, size_t n) {
  const mjModel* m = go_gait_model(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int nv = L->nv, na = L->na, ne = L->ne;
  const char* dof = NULL;
  const char* kind = NULL;
  int idx = -1;
  struct { int off, count; const char* kind; int what; } blocks[] = {
      {L->x_q, nv, "q", 0},      {L->x_qd, nv, "qdot", 0},   {L->x_a, na, "a", 1},
      {L->x_ft, ne, "fT", 2},    {L->xd_q, nv, "dq", 0},     {L->xd_qdd, nv, "qddot", 0},
      {L->xd_a, na, "adot", 1},  {L->xd_ft, ne, "dfT", 2},   {L->u_e, na, "e", 1},
      {L->u_grf, L->ngrf, "grf", 3}};
  for (size_t b = 0; b < sizeof(blocks) / sizeof(blocks[0]); b++) {
    if (j < blocks[b].off || j >= blocks[b].off + blocks[b].count) continue;
    kind = blocks[b].kind;
    idx = j - blocks[b].off;
    switch (blocks[b].what) {
      case 0: dof = mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[idx]); break;
      case 1: dof = mj_id2name(m, mjOBJ_ACTUATOR, idx); break;
      case 2: dof = mj_id2name(m, mjOBJ_ACTUATOR, L->elastic[idx]); break;
      default: {
        static const char* grf[GO_GAIT_NGRF] = {"r_x",  "r_y",  "r_z",  "l_x",  "l_y",  "l_z",
                                                "r_mx", "r_my", "r_mz", "l_mx", "l_my", "l_mz"};
        dof = grf[idx];
      }
    }
  }
  snprintf(buf, n, "%s.%s", kind ? kind : "z", dof ? dof : "?");
}

// variables.sto: every node variable (physical, radians), the exact restart of this solution
// for --init (and, on a refined mesh, go_refine_trapezoid)
static int write_variables(const go_gait* g, const double* z, const char* out) {
  const go_gait_layout* L = go_gait_layout_get(g);
  int N = go_gait_nodes(g), nz = L->nz, rc = -1;
  char** labels = (char**)calloc((size_t)nz, sizeof(char*));
  gsTable t;
  gs_table_init(&t);
  char err[256];
  for (int j = 0; j < nz; j++) {
    labels[j] = (char*)malloc(96);
    variable_name(g, j, labels[j], 96);
  }
  if (gs_table_create(&t, N, nz, (const char* const*)labels, err, sizeof(err)) == 0) {
    double T = go_gait_time_of(g, z);
    for (int k = 0; k < N; k++) {
      t.time[k] = T * k / (N - 1);
      memcpy(t.data + (size_t)k * nz, z + (size_t)k * nz, sizeof(double) * (size_t)nz);
    }
    rc = gs_app_write_table(out, "variables.sto", &t);
  } else {
    fprintf(stderr, "gaitsim: variables.sto: %s\n", err);
  }
  gs_table_free(&t);
  for (int j = 0; j < nz; j++) free(labels[j]);
  free(labels);
  return rc;
}

// Restart from DIR/variables.sto when it matches this problem's layout: the same nodes copied,
// or a coarser mesh refined (go_refine_trapezoid). 1 done, 0 not usable (no file, other
// layout or node count), -1 error (printed).
static int guess_from_variables(const go_gait* g, const char* dir, double* z) {
  const go_gait_layout* L = go_gait_layout_get(g);
  int N = go_gait_nodes(g), nz = L->nz;
  char path[4096], err[512], name[96];
  snprintf(path, sizeof(path), "%s/variables.sto", dir);
  gsTable t;
  gs_table_init(&t);
  if (gs_storage_read(path, &t, err, sizeof(err)) != 0) {
    gs_table_free(&t);
    return 0;
  }
  int ok = t.ncol == nz && t.nrow >= 2;
  for (int j = 0; ok && j < nz; j++) {
    variable_name(g, j, name, sizeof(name));
    ok = strcmp(name, t.labels[j]) == 0;
  }
  double T = t.time[t.nrow - 1] - t.time[0];
  int rc = 0;
  if (ok && t.nrow == N) {
    memcpy(z, t.data, sizeof(double) * (size_t)N * nz);
    rc = 1;
  } else if (ok && go_refine_trapezoid(L->nx, nz - 2 * L->nx, t.nrow, t.data, T, N, z) == 0) {
    rc = 1;
  }
  if (rc == 1) {
    for (size_t v = 0; v < (size_t)N * nz; v++)
      if (!isfinite(z[v])) {
        fprintf(stderr, "gaitsim: %s: non-finite value in column %s\n", path, t.labels[v % nz]);
        rc = -1;
        break;
      }
    if (rc == 1) fprintf(stderr, "track: start from %s (%d nodes%s)\n", path, t.nrow,
                         t.nrow == N ? "" : ", refined");
  }
  gs_table_free(&t);
  return rc;
}

// knee_contact.sto columns (N): right (implant) knee medial, lateral, total (knee_contact), left
// (1-DOF) knee compressive joint reaction along the tibia (gs_knee_reaction.h), and the right
// knee's ligament tension, the sum over its bundles (surrogate knee only)
#define GS_KNEE_COLUMNS 5
static const char* const kKneeLabels[GS_KNEE_COLUMNS] = {
    "contact_medial_r", "contact_lateral_r", "contact_total_r", "contact_total_l",
    "ligament_total_r"};

// knee_contact.sto: the columns that are finite at every node (none: no file)
static int write_knee_table(const char* out, const gsTable* knee) {
  const char* keep[GS_KNEE_COLUMNS];
  int n = 0;
  for (int c = 0; c < knee->ncol && c < GS_KNEE_COLUMNS; c++) {
    int finite = 1;
    for (int k = 0; k < knee->nrow; k++) finite &= isfinite(knee->data[k * knee->ncol + c]);
    if (finite) keep[n++] = knee->labels[c];
  }
  if (n == 0) return 0;
  gsTable sel;
  gs_table_init(&sel);
  char err[256];
  int rc = gs_table_select(knee, keep, n, &sel, err, sizeof(err));
  if (rc == 0) rc = gs_app_write_table(out, "knee_contact.sto", &sel);
  else fprintf(stderr, "gaitsim: knee_contact.sto: %s\n", err);
  gs_table_free(&sel);
  return rc;
}

// write the solution tables and accumulate the RMS errors and the peak knee contact forces into
// summary; knee_ref: measured medial, lateral and total knee contact force (N, N x 3) at the
// nodes, or NULL; per coordinate the RMS and mean of model - measured (coordinate_errors);
// knee_contact.sto only for a model with the right knee's knee_ty joint or the left knee's
// tibia_l (its columns finite at every node); metabolics.sto: each muscle's metabolic power (W,
// gs_physics_muscle_metabolics) and their sum, "total"
static int write_solution(go_gait* g, const double* z, const char* out, const double* knee_ref,
                          cJSON* summary) {
  const mjModel* m = go_gait_model(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int N = go_gait_nodes(g), nv = L->nv, na = L->na, status = -1;
  double T = go_gait_time_of(g, z), bw = go_gait_weight(g);
  mjData* d = mj_makeData(m);
  gsTable states, controls, grf, forces, knee, metab;
  gs_table_init(&knee);
  gs_table_init(&metab);
  gs_table_init(&states);
  gs_table_init(&controls);
  gs_table_init(&grf);
  gs_table_init(&forces);
  const char** names = (const char**)calloc((size_t)na, sizeof(char*));
  const char** mnames = (const char**)calloc((size_t)na + 1, sizeof(char*));
  for (int i = 0; i < na; i++) names[i] = mnames[i] = mj_id2name(m, mjOBJ_ACTUATOR, i);
  mnames[na] = "total";
  char err[512];
  // the left knee's joint reaction (a model without tibia_l: no contact_total_l column)
  gsKneeReactionSpec left_knee;
  int have_left = gs_knee_reaction_spec_left(m, &left_knee, err, sizeof(err)) == 0;
  if (gs_state_table_create(m, N, &states, err, sizeof(err)) != 0 ||
      gs_table_create(&controls, N, na, names, err, sizeof(err)) != 0 ||
      gs_grf_table_create(N, &grf, err, sizeof(err)) != 0 ||
      gs_table_create(&forces, N, na, names, err, sizeof(err)) != 0 ||
      gs_table_create(&metab, N, na + 1, mnames, err, sizeof(err)) != 0 ||
      gs_table_create(&knee, N, GS_KNEE_COLUMNS, kKneeLabels, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: track: %s\n", err);
    goto done;
  }
  // sums of squares: pelvis rot, pelvis trans, joint rot, grf ap, v, ml, knee contact total,
  // centre of pressure fore-aft and mediolateral, knee contact medial and lateral; counts
  double ss[11] = {0}, cnt[11] = {0};
  // per coordinate: sum of the errors and of their squares (deg or cm), count
  double* qsum = (double*)calloc(3 * (size_t)nv, sizeof(double));
  double* work = (double*)calloc((size_t)N, sizeof(double));  // muscles' positive work rate (W)
  double peak_r = -INFINITY, peak_l = -INFINITY;  // largest total contact, right and left (N)
  for (int k = 0; k < N; k++) {
    const double* zk = z + (size_t)k * L->nz;
    double t = T * k / (N - 1);
    go_gait_load_node(g, d, zk);
    gs_state_table_set_row(m, d, t, &states, k);
    gs_grf_table_set_row(m, d, t, &grf, k);
    controls.time[k] = forces.time[k] = knee.time[k] = metab.time[k] = t;
    double* kc = knee.data + GS_KNEE_COLUMNS * k;
    knee_contact(m, d, kc, kc + 4);
    gsKneeReaction kr;
    kc[3] = have_left && gs_knee_reaction(m, d, &left_knee, NULL, &kr) == 0 ? kr.compression : NAN;
    peak_r = isfinite(kc[2]) && !isnan(peak_r) ? fmax(peak_r, kc[2]) : NAN;
    peak_l = isfinite(kc[3]) && !isnan(peak_l) ? fmax(peak_l, kc[3]) : NAN;
    for (int q = 0; knee_ref && q < 3; q++) {  // medial, lateral, total
      int slot = q == 2 ? 6 : 9 + q;
      if (isfinite(kc[q]) && isfinite(knee_ref[3 * k + q])) {
        ss[slot] += sq((kc[q] - knee_ref[3 * k + q]) / bw);
        cnt[slot]++;
      }
    }
    double* mk = metab.data + (size_t)k * (na + 1);
    mk[na] = 0;
    work[k] = 0;
    for (int i = 0; i < na; i++) {
      gsUmbergerTerms terms;
      controls.data[k * na + i] = zk[L->u_e + i];
      forces.data[k * na + i] = gs_physics_muscle_tension(m, d, i, NULL);
      mk[i] = gs_physics_muscle_metabolics(m, d, i, &terms);
      mk[na] += mk[i];
      work[k] += terms.work_power;
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
      double e = zk[L->x_q + j] - ref;
      double e_unit = slide ? 100 * e : e * 180 / M_PI;  // cm or deg
      qsum[3 * j] += e_unit;
      qsum[3 * j + 1] += e_unit * e_unit;
      qsum[3 * j + 2]++;
      if (grp < 0) continue;
      ss[grp] += sq(e_unit);
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
      // centre of pressure where the measured foot carries > 0.1 BW and the model's is loaded:
      // the measured one from the moment reference about the origin (x = -M_y / F_z, y = M_x /
      // F_z on the floor)
      double fz = go_gait_grf_ref(g, k, 3 * s + 2);
      double mx = go_gait_grf_ref(g, k, GO_GAIT_GRM_OFFSET + 3 * s);
      double my = go_gait_grf_ref(g, k, GO_GAIT_GRM_OFFSET + 3 * s + 1);
      if (fz > 0.1 * bw && isfinite(mx) && isfinite(my) && fg.loaded) {
        ss[7] += sq(100 * (fg.cop[0] + my / fz));
        ss[8] += sq(100 * (fg.cop[1] - mx / fz));
        cnt[7]++, cnt[8]++;
      }
    }
  }
  static const char* keys[11] = {"pelvis_rot_deg",   "pelvis_trans_cm",       "joint_rot_deg",
                                 "grf_ap_bw",        "grf_v_bw",              "grf_ml_bw",
                                 "knee_contact_bw",  "cop_ap_cm",             "cop_ml_cm",
                                 "knee_medial_bw",   "knee_lateral_bw"};
  cJSON* rms = cJSON_AddObjectToObject(summary, "rms");
  for (int q = 0; q < 11; q++) {
    if (cnt[q] > 0) cJSON_AddNumberToObject(rms, keys[q], sqrt(ss[q] / cnt[q]));
    else cJSON_AddNullToObject(rms, keys[q]);
  }
  // every measured coordinate: RMS and mean of model - measured over the nodes
  cJSON* qerr = cJSON_AddObjectToObject(summary, "coordinate_errors");
  for (int j = 0; j < nv; j++) {
    if (!(qsum[3 * j + 2] > 0)) continue;
    int jnt = m->dof_jntid[j];
    cJSON* e = cJSON_AddObjectToObject(qerr, mj_id2name(m, mjOBJ_JOINT, jnt));
    cJSON_AddNumberToObject(e, "rms", sqrt(qsum[3 * j + 1] / qsum[3 * j + 2]));
    cJSON_AddNumberToObject(e, "mean", qsum[3 * j] / qsum[3 * j + 2]);
    cJSON_AddStringToObject(e, "unit", m->jnt_type[jnt] == mjJNT_SLIDE ? "cm" : "deg");
  }
  free(qsum);
  if (L->tx >= 0) {
    double dx = z[(size_t)(N - 1) * L->nz + L->x_q + L->tx] - z[L->x_q + L->tx];
    cJSON_AddNumberToObject(summary, "speed_mps", dx / T);
    // the exact (unsmoothed) Umberger 2010 cost of transport of metabolics.sto's totals, by the
    // solve's trapezoid: what the smooth objective approximates (J/(kg m))
    double energy = 0, positive_work = 0;
    for (int k = 0; k + 1 < N; k++) {
      energy += 0.5 * (T / (N - 1)) * (metab.data[(size_t)k * (na + 1) + na] +
                                       metab.data[(size_t)(k + 1) * (na + 1) + na]);
      positive_work += 0.5 * (T / (N - 1)) * (work[k] + work[k + 1]);
    }
    if (fabs(dx) > 1e-9) {
      cJSON_AddNumberToObject(summary, "cost_of_transport_exact_j_per_kg_m",
                              energy / (mj_getTotalmass(m) * fabs(dx)));
      // the fibres' positive work (Umberger's work term) per metre, and its share of the muscles'
      // metabolic energy: their apparent efficiency, about 0.25 in human walking (Margaria 1968)
      cJSON_AddNumberToObject(summary, "muscle_positive_work_j_per_kg_m",
                              positive_work / (mj_getTotalmass(m) * fabs(dx)));
    }
    if (energy > 0) cJSON_AddNumberToObject(summary, "muscle_efficiency", positive_work / energy);
  }
  free(work);
  // peak knee contact over the nodes: right (implant; measured in vivo) and left (1-DOF joint
  // reaction), N and BW; null without the column or with a non-finite node
  const char* peak_keys[4] = {"peak_knee_contact_r_n", "peak_knee_contact_r_bw",
                              "peak_knee_contact_l_n", "peak_knee_contact_l_bw"};
  double peaks[4] = {peak_r, peak_r / bw, peak_l, peak_l / bw};
  for (int q = 0; q < 4; q++) {
    if (isfinite(peaks[q])) cJSON_AddNumberToObject(summary, peak_keys[q], peaks[q]);
    else cJSON_AddNullToObject(summary, peak_keys[q]);
  }
  gs_table_to_degrees(&states, gs_state_is_angle, (void*)m);
  if (gs_app_write_table(out, "states.sto", &states) == 0 &&
      gs_app_write_table(out, "controls.sto", &controls) == 0 &&
      gs_app_write_table(out, "grf.mot", &grf) == 0 &&
      gs_app_write_table(out, "muscle_forces.sto", &forces) == 0 &&
      gs_app_write_table(out, "metabolics.sto", &metab) == 0 &&
      write_knee_table(out, &knee) == 0 && write_variables(g, z, out) == 0) {
    status = 0;
  }
done:
  free(names);
  free(mnames);
  gs_table_free(&metab);
  gs_table_free(&states);
  gs_table_free(&controls);
  gs_table_free(&grf);
  gs_table_free(&forces);
  gs_table_free(&knee);
  mj_deleteData(d);
  return status;
}

// measured knee contact force (N) of the trial at the N node times, N x 3: medial, lateral,
// total (NAN where the file lacks the column); caller frees. NULL when the trial has no
// knee_contact.sto with a contact_total_r column
static double* measured_knee_contact(const char* trial, const go_gait* g) {
  char path[4096], err[256];
  snprintf(path, sizeof(path), "%s/knee_contact.sto", trial);
  gsTable t, rs;
  gs_table_init(&t);
  gs_table_init(&rs);
  int N = go_gait_nodes(g);
  double* out = NULL;
  double* times = (double*)malloc(sizeof(double) * (size_t)N);
  if (gs_storage_read(path, &t, err, sizeof(err)) == 0 &&
      gs_table_column(&t, "contact_total_r") >= 0) {
    for (int k = 0; k < N; k++) times[k] = t.time[0] + go_gait_stride_time(g) * k / (N - 1);
    if (gs_table_resample(&t, times, N, &rs, err, sizeof(err)) == 0) {
      out = (double*)malloc(sizeof(double) * 3 * (size_t)N);
      for (int q = 0; q < 3; q++) {
        int c = gs_table_column(&rs, kKneeLabels[q]);
        for (int k = 0; k < N; k++) out[3 * k + q] = c >= 0 ? rs.data[k * rs.ncol + c] : NAN;
      }
    }
  }
  free(times);
  gs_table_free(&t);
  gs_table_free(&rs);
  return out;
}

// initial guess from the solution folder dir (states.sto, controls.sto); prints the reason
static int guess_from_folder(go_gait* g, const mjModel* m, const char* dir, double activation,
                             double* z) {
  gsTable states, controls;
  gs_table_init(&states);
  gs_table_init(&controls);
  char path[4096], err[512];
  int rc = -1;
  snprintf(path, sizeof(path), "%s/states.sto", dir);
  if (gs_app_read_table(m, path, &states) != 0 || gs_app_require_coordinates(m, &states, path) != 0)
    goto done;
  snprintf(path, sizeof(path), "%s/controls.sto", dir);
  if (gs_app_read_table(m, path, &controls) != 0) goto done;
  if (go_gait_guess_from_solution(g, &states, &controls, 1.0, activation, z, err,
                                  sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", dir, err);
    goto done;
  }
  rc = 0;
done:
  gs_table_free(&states);
  gs_table_free(&controls);
  return rc;
}

static int solve(gsTrackOptions o);

// the "trial" of DIR/summary.json (caller frees), or NULL when absent or unreadable
static char* trial_of_solution(const char* dir) {
  char path[4096];
  snprintf(path, sizeof(path), "%s/summary.json", dir);
  cJSON* j = gs_app_read_json(path);
  const cJSON* t = cJSON_GetObjectItemCaseSensitive(j, "trial");
  char* out = cJSON_IsString(t) ? strdup(t->valuestring) : NULL;
  cJSON_Delete(j);
  return out;
}

// Predictive problem set-up (Lin, Walter & Pandy 2018, eqs. 1-3): the guess from o->guess at the
// node times (band, N nz + 1 + 2 nv doubles: node variables, T, then the half-widths of the q and
// qdot bands), cost of transport with free stride time and the mean speed, the band of eq. 3
// around the guess: PREDICT_BAND_ROT rad / PREDICT_BAND_TRANS m, PREDICT_BAND_ROT_SPEED rad/s /
// PREDICT_BAND_TRANS_SPEED m/s, each times o->band_scale (pelvis_tx itself unbounded; the paper
// gives no widths). Prints the reason on failure.
#define PREDICT_BAND_ROT 0.35         // rad (20 deg)
#define PREDICT_BAND_TRANS 0.05       // m
#define PREDICT_BAND_ROT_SPEED 6.0    // rad/s
#define PREDICT_BAND_TRANS_SPEED 1.0  // m/s
static int predict_setup(const mjModel* m, gsTrackOptions* o, go_gait_opts* go, double** band,
                         double* T0, double* dx0) {
  gsTable states, controls;
  gs_table_init(&states);
  gs_table_init(&controls);
  go_gait* tmp = NULL;
  char path[4096], err[512];
  int rc = -1, nv = m->nv;
  snprintf(path, sizeof(path), "%s/states.sto", o->guess);
  if (gs_app_read_table(m, path, &states) != 0 || gs_app_require_coordinates(m, &states, path) != 0)
    goto done;
  snprintf(path, sizeof(path), "%s/controls.sto", o->guess);
  if (gs_app_read_table(m, path, &controls) != 0) goto done;
  *T0 = states.time[states.nrow - 1] - states.time[0];
  go_gait_opts to;
  go_gait_opts_default(&to);
  to.N = go->N;
  to.T = *T0;
  if (go_gait_create(&tmp, m, &to, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: predict: %s\n", err);
    goto done;
  }
  const go_gait_layout* L = go_gait_layout_get(tmp);
  size_t nzN = (size_t)go->N * (size_t)L->nz;
  *band = (double*)calloc(nzN + 1 + 2 * (size_t)nv, sizeof(double));
  if (!*band) goto done;
  int exact = guess_from_variables(tmp, o->guess, *band);  // variables.sto: the exact solution
  if (exact < 0) goto done;
  if (!exact && go_gait_guess_from_solution(tmp, &states, &controls, 1.0, o->activation, *band,
                                            err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", o->guess, err);
    goto done;
  }
  if (L->tx < 0) {
    fprintf(stderr, "gaitsim: predict: the model has no pelvis_tx (forward translation)\n");
    goto done;
  }
  *dx0 = (*band)[nzN - L->nz + L->x_q + L->tx] - (*band)[L->x_q + L->tx];
  (*band)[nzN] = *T0;
  double* bq = *band + nzN + 1;
  double* bqd = bq + nv;
  for (int j = 0; j < nv; j++) {
    int slide = m->jnt_type[m->dof_jntid[j]] == mjJNT_SLIDE;
    bq[j] = o->band_scale * (slide ? PREDICT_BAND_TRANS : PREDICT_BAND_ROT);
    bqd[j] = o->band_scale * (slide ? PREDICT_BAND_TRANS_SPEED : PREDICT_BAND_ROT_SPEED);
  }
  bq[L->tx] = 0;  // pelvis_tx advances over the stride: no band on it (go_gait skips it too)
  go->w_cot = 1.0;
  go->speed = o->speed;
  go->free_time = 1;
  go->T_lb = 0.4;
  go->T_ub = 2.5;
  if (o->stride_time > 0) go->T_lb = go->T_ub = o->stride_time;  // Ipopt fixes the variable
  go->band_z = *band;
  go->band_q = bq;
  go->band_qd = bqd;
  // eq. 2's fibre-length bounds (go_gait_opts.fibre_bounds); how far the guess is outside them
  go->fibre_bounds = o->fibre_bounds;
  go->min_vgrf = o->min_vgrf;
  {
    mjData* d = mj_makeData(go_gait_model(tmp));
    double* lm = (double*)malloc(sizeof(double) * (size_t)L->na);
    int* outside = (int*)calloc((size_t)L->na, sizeof(int));
    int muscles = 0, values = 0, ilo = 0, ihi = 0;
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; d && lm && outside && k < go->N; k++) {
      go_gait_fibre_lengths(tmp, d, *band + (size_t)k * L->nz, lm);
      for (int i = 0; i < L->na; i++) {
        int out = lm[i] < go->fibre_lo || lm[i] > go->fibre_hi;
        muscles += out && !outside[i];
        outside[i] |= out;
        values += out;
        if (lm[i] < lo) lo = lm[i], ilo = i;
        if (lm[i] > hi) hi = lm[i], ihi = i;
      }
    }
    free(outside);
    if (d && lm)
      fprintf(stderr, "predict: guess: %d of %d muscles outside %g <= lM/lopt <= %g (%d of %d node "
              "values; range %.3f, %s, to %.3f, %s)%s\n", muscles, L->na, go->fibre_lo,
              go->fibre_hi, values, L->na * go->N, lo, mj_id2name(m, mjOBJ_ACTUATOR, ilo), hi,
              mj_id2name(m, mjOBJ_ACTUATOR, ihi), o->fibre_bounds ? "" : "; bounds off");
    free(lm);
    if (d) mj_deleteData(d);
  }
  rc = 0;
done:
  go_gait_free(tmp);
  gs_table_free(&states);
  gs_table_free(&controls);
  return rc;
}

// scale the guess's forward progression (pelvis_tx relative to its start, its speed, q' and
// acceleration) to the prescribed speed V over the guess's stride time T0; set T = T0
static void retime_progression(const go_gait* g, double* z, double V, double T0) {
  const go_gait_layout* L = go_gait_layout_get(g);
  int N = go_gait_nodes(g), nz = L->nz;
  double tx0 = z[L->x_q + L->tx], dx = z[(size_t)(N - 1) * nz + L->x_q + L->tx] - tx0;
  double f = fabs(dx) > 1e-9 ? V * T0 / dx : 1.0;
  for (int k = 0; k < N; k++) {
    double* zk = z + (size_t)k * nz;
    zk[L->x_q + L->tx] = tx0 + f * (zk[L->x_q + L->tx] - tx0);
    zk[L->x_qd + L->tx] *= f;
    zk[L->xd_q + L->tx] *= f;
    zk[L->xd_qdd + L->tx] *= f;
  }
  z[(size_t)N * nz] = T0;
}

// a foot is on the ground when it bears at least this vertical force (BW): 0.02 BW, about 12 N
// for JW, below the 20 N threshold of force-plate event detection
#define GAIT_CONTACT_BW 0.02

// prediction figures for summary.json: speed, stride time and length and their change from the
// guess, cost of transport, share of the regularisation, peak triceps surae excitations, and
// where eq. 3's band holds the solution (band: predict_setup's)
static void predict_summary(const go_gait* g, const double* z, const gsTrackOptions* o,
                            const double* band, double T0, double dx0, double objective,
                            cJSON* summary) {
  const mjModel* m = go_gait_model(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int N = go_gait_nodes(g);
  double T = go_gait_time_of(g, z);
  double dx = z[(size_t)(N - 1) * L->nz + L->x_q + L->tx] - z[L->x_q + L->tx];
  double cot = go_gait_cot(g, z);
  cJSON_AddNumberToObject(summary, "speed_target_mps", o->speed);
  cJSON_AddNumberToObject(summary, "stride_length_m", dx);
  cJSON_AddNumberToObject(summary, "guess_stride_time_s", T0);
  cJSON_AddNumberToObject(summary, "guess_stride_length_m", dx0);
  cJSON_AddNumberToObject(summary, "stride_time_change_pct", 100 * (T / T0 - 1));
  cJSON_AddNumberToObject(summary, "stride_length_change_pct", 100 * (dx / dx0 - 1));
  cJSON_AddNumberToObject(summary, "cost_of_transport_j_per_kg_m", cot);
  cJSON_AddNumberToObject(summary, "regularisation_share", objective > 0 ? 1 - cot / objective : NAN);
  cJSON_AddNumberToObject(summary, "metabolic_smoothing", o->metabolic_smoothing);
  // walk or run: the summed vertical ground reaction's minimum over the nodes, the nodes where no
  // foot bears GAIT_CONTACT_BW and those where both do (double support); the floor asked for
  double bw = go_gait_weight(g), vmin = INFINITY;
  int flight = 0, dsupport = 0;
  for (int k = 0; k < N; k++) {
    const double* f = z + (size_t)k * L->nz + L->u_grf;
    vmin = fmin(vmin, (f[2] + f[5]) / bw);
    flight += f[2] < GAIT_CONTACT_BW * bw && f[5] < GAIT_CONTACT_BW * bw;
    dsupport += f[2] >= GAIT_CONTACT_BW * bw && f[5] >= GAIT_CONTACT_BW * bw;
  }
  cJSON_AddNumberToObject(summary, "min_vgrf_bound_bw", o->min_vgrf);
  if (o->stride_time > 0) cJSON_AddNumberToObject(summary, "stride_time_fixed_s", o->stride_time);
  else cJSON_AddNullToObject(summary, "stride_time_fixed_s");
  cJSON_AddNumberToObject(summary, "min_summed_vgrf_bw", vmin);
  cJSON_AddNumberToObject(summary, "flight_nodes", flight);
  cJSON_AddNumberToObject(summary, "double_support_nodes", dsupport);
  static const char* peaks[] = {"soleus", "gasmed", "gaslat", "soleus_l", "med_gas_l", "lat_gas_l"};
  cJSON* pk = cJSON_AddObjectToObject(summary, "peak_excitation");
  for (size_t q = 0; q < sizeof(peaks) / sizeof(peaks[0]); q++) {
    int i = mj_name2id(m, mjOBJ_ACTUATOR, peaks[q]);
    if (i < 0) continue;
    double mx = 0;
    for (int k = 0; k < N; k++) mx = fmax(mx, z[(size_t)k * L->nz + L->u_e + i]);
    cJSON_AddNumberToObject(pk, peaks[q], mx);
  }
  // eq. 3's band: per coordinate (and its speed, "NAME_speed"), the nodes at which the solution
  // lies within 0.1 % of the band's half-width from its edge, so that the band, not the
  // objective, placed it there; coordinates never at the band are left out
  cJSON_AddNumberToObject(summary, "band_scale", o->band_scale);
  cJSON* widths = cJSON_AddObjectToObject(summary, "band_half_widths_at_scale_1");
  cJSON_AddNumberToObject(widths, "rotation_rad", PREDICT_BAND_ROT);
  cJSON_AddNumberToObject(widths, "translation_m", PREDICT_BAND_TRANS);
  cJSON_AddNumberToObject(widths, "rotation_speed_rad_per_s", PREDICT_BAND_ROT_SPEED);
  cJSON_AddNumberToObject(widths, "translation_speed_m_per_s", PREDICT_BAND_TRANS_SPEED);
  cJSON* ba = cJSON_AddObjectToObject(summary, "band_active_nodes");
  const double* bq = band + (size_t)N * L->nz + 1;
  for (int j = 0; j < m->nv; j++) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[j]);
    for (int sp = 0; sp < 2; sp++) {
      double hw = bq[sp * m->nv + j];
      int col = (sp ? L->x_qd : L->x_q) + j, at = 0;
      if (!(hw > 0)) continue;
      for (int k = 0; k < N; k++)
        at += fabs(z[(size_t)k * L->nz + col] - band[(size_t)k * L->nz + col]) >= (1 - 1e-3) * hw;
      if (!at) continue;
      char key[128];
      snprintf(key, sizeof(key), "%s%s", name ? name : "dof", sp ? "_speed" : "");
      cJSON_AddNumberToObject(ba, key, at);
    }
  }
}

static const char* kPredictUsage =
    "usage: gaitsim predict --guess TRACK_DIR --speed V --out DIR [options]\n\n"
    "Predictive solve of one stride at mean speed V (m/s), no data tracked (Lin, Walter & Pandy\n"
    "2018): minimise the cost of transport (smooth Umberger 2010 metabolic energy / (mass x\n"
    "distance)) with free stride time, periodic but for pelvis_tx, q and qdot within a band\n"
    "around the guess (eq. 3: 20 deg, 5 cm, 6 rad/s, 1 m/s, times --band-scale, default "
    GO_STR(GO_PREDICT_BAND_SCALE) ")\n"
    "and q within the model's joint ranges, started from the solution in TRACK_DIR (its forward\n"
    "progression rescaled to V). Writes the files of `gaitsim track`; summary.json adds stride\n"
    "time and length, their change from the guess, the cost of transport and peak triceps surae\n"
    "excitations. L-BFGS (Ipopt's limited-memory Hessian) stops at Ipopt's optimal solution,\n"
    "at its acceptable level (" GO_STR(GO_SETTLE_ITER) " consecutive iterations at a violation <= "
    GO_STR(GO_PREDICT_SETTLE_VIOL) ",\n"
    "the objective changing <= " GO_STR(GO_PREDICT_SETTLE_REL) " relative per iteration), or once "
    GO_STR(GO_SETTLE_ITER) " of the\n"
    "last 2 x " GO_STR(GO_SETTLE_ITER) " iterations meet it (status \"objective settled\"); then "
    "the polish onto the\n"
    "dynamics. Exit status 3 when the solver stopped short.\n\n"
    "  --model FILE        MJCF model (default: the one TRACK_DIR/summary.json names, else\n"
    "                      mjmodels/jw_fullbody_knee6.xml)\n"
    "  --nodes N           collocation nodes (default: the guess's, TRACK_DIR/summary.json\n"
    "                      nodes, so an 80-node tracking solution is continued on 80; else\n"
    "                      " GO_STR(GO_NODES_PREDICT) ")\n"
    "  --threads N         worker threads (default " GO_STR(GO_THREADS) ")\n"
    "  --max-iter N        Ipopt iteration limit (default " GO_STR(GO_MAX_ITER) ")\n"
    "  --max-time S        wall-clock limit, s (default none)\n"
    "  --weight NAME=W     regularisation weight: effort, the mean squared excitation (default\n"
    "                      " GO_STR(GO_PREDICT_W_EFFORT)
    "); accel, the mean over all coordinates of (qddot / 50 rad/s^2\n"
    "                      or m/s^2)^2 (default " GO_STR(GO_PREDICT_W_ACCEL)
    ", a smoothness term; objective_share in\n"
    "                      summary.json gives its fraction of J) (repeatable)\n"
    "  --no-fibre-bounds   no path bounds 0.25 <= lM/lopt <= 1.5 on every muscle's normalised\n"
    "                      fibre length (Lin, Walter & Pandy 2018, eq. 2; on by default; the\n"
    "                      guess's count outside them is printed)\n"
    "  --min-vgrf F        walking: the summed vertical ground reaction of both feet at least F\n"
    "                      body weights at every node, so no node is in flight (not in the\n"
    "                      paper; default " GO_STR(GO_PREDICT_MIN_VGRF)
    ", 0 turns it off; summary.json min_summed_vgrf_bw,\n"
    "                      flight_nodes, double_support_nodes tell a walk from a run)\n"
    "  --stride-time S     hold the stride time at S seconds (0.4-2.5) instead of leaving it\n"
    "                      free: the cost of transport at a prescribed cadence\n"
    "  --stride-time-start S  start the free stride time at S seconds (0.4-2.5; default the\n"
    "                      guess's): where the solve starts, not a bound\n"
    "  --metabolic-smoothing F  factor on every width of the smooth Umberger 2010 rates\n"
    "                      (steps in u - a, lM~ - 1 and v~, the maxima and minima; widths of\n"
    "                      gs_metabolics.h times F; default " GO_STR(GO_PREDICT_METABOLIC_SMOOTHING)
    ": steps 0.1 wide, which lets the\n"
    "                      solves converge; summary.json gives the exact cost of transport too)\n"
    "  --jacobian forward|central  finite differences of the path rows in the main solve:\n"
    "                      forward (half the model evaluations per Jacobian) or central\n"
    "                      (default " GO_PREDICT_JACOBIAN_NAME "; the polish uses central ones)\n"
    "  --no-polish         no feasibility polish of a solve that stopped short\n";
// (in two parts: C11 compilers need not take string literals over 4095 characters)
static const char* kPredictUsageBand =
    "  --band-scale F      factor on the half-widths of eq. 3's band around the guess (20 deg,\n"
    "                      5 cm, 6 rad/s, 1 m/s: summary.json band_half_widths_at_scale_1; the\n"
    "                      paper gives none): default " GO_STR(GO_PREDICT_BAND_SCALE)
    ", 0: no band; summary.json\n"
    "                      band_active_nodes counts, per coordinate and speed, the nodes the\n"
    "                      band holds\n"
    "  --fallback-rise F   stop when the objective rises by more than the fraction F above the\n"
    "                      lowest one reached at a violation <= " GO_STR(GO_FALLBACK_VIOL)
    ", and restart from the\n"
    "                      best iterate (at most " GO_STR(GO_MAX_RESTARTS) " times; summary.json "
    "restarts); default " GO_STR(GO_FALLBACK_RISE) ",\n"
    "                      0 turns the guard off\n"
    "  --ipopt KEY=VALUE   extra Ipopt option (repeatable)\n";

int gs_cmd_predict(int argc, char** argv) {
  static const struct option options[] = {
      {"guess", required_argument, NULL, 'g'},    {"speed", required_argument, NULL, 's'},
      {"out", required_argument, NULL, 'o'},      {"model", required_argument, NULL, 'm'},
      {"nodes", required_argument, NULL, 'n'},    {"threads", required_argument, NULL, 't'},
      {"max-iter", required_argument, NULL, 'i'}, {"max-time", required_argument, NULL, 'T'},
      {"weight", required_argument, NULL, 'w'},   {"no-polish", no_argument, NULL, 'P'},
      {"ipopt", required_argument, NULL, 'p'},    {"help", no_argument, NULL, 'h'},
      {"no-fibre-bounds", no_argument, NULL, 'F'},
      {"metabolic-smoothing", required_argument, NULL, 'S'},
      {"fallback-rise", required_argument, NULL, 'R'},
      {"min-vgrf", required_argument, NULL, 'W'},
      {"stride-time", required_argument, NULL, 'D'},
      {"stride-time-start", required_argument, NULL, 'E'},
      {"jacobian", required_argument, NULL, 'J'},
      {"band-scale", required_argument, NULL, 'B'},           {NULL, 0, NULL, 0}};
  gsTrackOptions o;
  defaults(&o);
  o.predict = 1;
  o.plan.label = "predict";
  o.plan.hessian = GO_HESSIAN_LBFGS;
  o.plan.refine_iter = 0;  // Newton after L-BFGS settles at a higher cost (docs/BENCHMARKS.md,
                           // "Predictions: the metabolic Hessian and Newton")
  o.plan.max_iter = GO_MAX_ITER;
  go_solve_plan_settle_main(&o.plan, GO_PREDICT_SETTLE_VIOL, GO_PREDICT_SETTLE_REL);
  o.plan.main_jacobian = GO_PREDICT_FORWARD_JACOBIAN ? GO_JAC_SPARSE_FORWARD : GO_JAC_SPARSE;
  o.nodes = GO_NODES_PREDICT;
  o.w_effort = GO_PREDICT_W_EFFORT;
  o.w_accel = GO_PREDICT_W_ACCEL;
  o.metabolic_smoothing = GO_PREDICT_METABOLIC_SMOOTHING;
  o.fibre_bounds = 1;
  o.min_vgrf = GO_PREDICT_MIN_VGRF;
  o.band_scale = GO_PREDICT_BAND_SCALE;
  optind = 1;
  opterr = 0;
  int c, bad = 0, model_given = 0, nodes_given = 0;
  char err[256];
  while (!bad && (c = getopt_long(argc, argv, ":g:s:o:m:n:t:i:T:w:PFS:R:W:D:E:J:B:p:h", options,
                                  NULL)) != -1) {
    switch (c) {
      case 'g': o.guess = optarg; break;
      case 's': bad = gs_opt_real("--speed", optarg, 0, 10, GS_OPT_LO_OPEN | GS_OPT_HI_OPEN, &o.speed); break;
      case 'o': o.out = optarg; break;
      case 'm':
        o.model = optarg;
        model_given = 1;
        break;
      case 'n':
        bad = gs_opt_int("--nodes", optarg, GS_MIN_NODES, GS_MAX_NODES, &o.nodes);
        nodes_given = 1;
        break;
      case 't': bad = gs_opt_int("--threads", optarg, 1, 64, &o.threads); break;
      case 'i': bad = gs_opt_int("--max-iter", optarg, 0, GS_OPT_NO_MAX, &o.plan.max_iter); break;
      case 'T':
        bad = gs_opt_real("--max-time", optarg, 0, HUGE_VAL, GS_OPT_LO_OPEN, &o.plan.max_wall_s);
        break;
      case 'w': bad = parse_weight(optarg, &o); break;
      case 'P': o.plan.polish = 0; break;
      case 'B': bad = gs_opt_real("--band-scale", optarg, 0, 10, 0, &o.band_scale); break;
      case 'F': o.fibre_bounds = 0; break;
      case 'D': bad = gs_opt_real("--stride-time", optarg, 0.4, 2.5, 0, &o.stride_time); break;
      case 'E':
        bad = gs_opt_real("--stride-time-start", optarg, 0.4, 2.5, 0, &o.stride_time_start);
        break;
      case 'W':
        bad = gs_opt_real("--min-vgrf", optarg, 0, 10, GS_OPT_HI_OPEN, &o.min_vgrf);
        break;
      case 'R':
        bad = gs_opt_real("--fallback-rise", optarg, 0, HUGE_VAL, 0, &o.plan.ipopt.fallback_rise);
        break;
      case 'S':
        bad = gs_opt_real("--metabolic-smoothing", optarg, 0, 1e3, GS_OPT_LO_OPEN,
                          &o.metabolic_smoothing);
        break;
      case 'J': {
        static const char* const jacobians[] = {"forward", "central", NULL};
        int k = 0;
        bad = gs_opt_choice("--jacobian", optarg, jacobians, &k);
        if (!bad) o.plan.main_jacobian = k == 0 ? GO_JAC_SPARSE_FORWARD : GO_JAC_SPARSE;
        break;
      }
      case 'p':
        if (go_ipopt_opts_add(&o.plan.ipopt, optarg, err, sizeof(err)) != 0) {
          fprintf(stderr, "gaitsim: --ipopt: %s\n", err);
          bad = 1;
        }
        break;
      case 'h':
        fputs(kPredictUsage, stdout);
        fputs(kPredictUsageBand, stdout);
        return GS_EXIT_OK;
      default: return gs_opt_getopt_error("predict", c, argv);
    }
  }
  if (bad) return GS_EXIT_USAGE;
  if (optind != argc)
    return gs_opt_usage_error("predict", "unexpected argument '%s'", argv[optind]);
  if (!o.guess) return gs_opt_usage_error("predict", "missing --guess TRACK_DIR");
  if (!(o.speed > 0)) return gs_opt_usage_error("predict", "missing --speed V");
  if (!o.out) return gs_opt_usage_error("predict", "missing --out DIR");
  o.trial = o.guess;
  // the guess's own model unless --model: a solution continues on the model it was solved with
  static char guess_model[4096];
  if (!model_given && gs_app_solution_model(o.guess, guess_model, (int)sizeof(guess_model)))
    o.model = guess_model;
  // and its mesh unless --nodes: the prediction continues the solution at its resolution
  int guess_nodes = gs_app_solution_nodes(o.guess);
  if (!nodes_given && guess_nodes >= GS_MIN_NODES && guess_nodes <= GS_MAX_NODES)
    o.nodes = guess_nodes;
  return solve(o);
}

int gs_cmd_track(int argc, char** argv) {
  gsTrackOptions o;
  int rc = parse(argc, argv, &o);
  if (rc != 0) return rc < 0 ? GS_EXIT_OK : rc;
  return solve(o);
}

// the tracking (o.predict == 0) or predictive problem: build, guess, solve (the plan,
// go_solve_run), write
static int solve(gsTrackOptions o) {
  char err[1024];
  // the whole solve's clocks (summary.json wall_s, cpu_s): problem set-up, guess and every
  // Ipopt solve (restarts, a refinement kept or not, the polish)
  go_clock clock;
  go_clock_start(&clock);
  // stop signals: the first stops the solve (its best iterate written, exit 3), a second ends
  // the process at once, the temporary output folder removed
  go_ipopt_install_stop_signals(gs_folder_abort_from_signal);
  // inputs and the output folder checked before any work: an existing --out is replaced only
  // when it holds an earlier result (its summary.json)
  if (gs_folder_replaceable(o.out, "summary.json", err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  const char* from = o.predict ? o.guess : o.init;
  if (from && gs_app_check_solution(from, 1) != 0) return GS_EXIT_FAILURE;
  mjModel* m = gs_app_load_model(o.model);
  if (!m) return GS_EXIT_FAILURE;
  gsModelInfo info;  // a gait needs both feet on the ground
  gs_model_info(m, &info);
  if (info.ncontact_r == 0 || info.ncontact_l == 0) {
    fprintf(stderr, "gaitsim: %s: no foot contact spheres (contact_r_*: %d, contact_l_*: %d); "
            "a gait needs both feet (gaitsim info MODEL)\n", o.model, info.ncontact_r,
            info.ncontact_l);
    mj_deleteModel(m);
    return GS_EXIT_FAILURE;
  }
  gsFolderTx tx = {NULL, NULL, NULL};
  int status = GS_EXIT_FAILURE;
  gsTable coords, grf;
  gs_table_init(&coords);
  gs_table_init(&grf);
  go_gait* g = NULL;
  double* z = NULL;  // the start point
  go_solve_report rep = {0};
  cJSON* summary = NULL;
  char path[4096];
  const char* what = o.predict ? "predict" : "track";
  double grf_scale = 0, *band = NULL, T0 = 0, dx0 = 0;
  if (!o.predict) {
    snprintf(path, sizeof(path), "%s/coordinates.mot", o.trial);
    if (gs_app_read_table(m, path, &coords) != 0 ||
        gs_app_require_coordinates(m, &coords, path) != 0)
      goto done;
    snprintf(path, sizeof(path), "%s/grf.mot", o.trial);
    if (gs_app_read_table(m, path, &grf) != 0) goto done;
    double model_weight = mj_getTotalmass(m) * mju_norm3(m->opt.gravity);
    grf_scale = normalise_grf_to_weight(&grf, model_weight);
    if (!(grf_scale > 0)) {
      fprintf(stderr, "gaitsim: %s/grf.mot: no positive vertical ground reaction to normalise\n",
              o.trial);
      goto done;
    }
  }
  // the solution is written into a temporary folder beside --out that replaces it at the end
  if (gs_folder_begin(&tx, o.out, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    goto done;
  }
  go_gait_opts go;
  go_gait_opts_default(&go);
  // the trial drifts sideways: pelvis_tz is not periodic when tracking (if the model has it)
  static const char* free_coords[] = {"pelvis_tz", NULL};
  go.N = o.nodes;
  go.nthreads = o.threads;
  go.w_effort = o.w_effort;
  go.w_accel = o.w_accel;
  go.metabolic_smoothing = o.metabolic_smoothing;
  if (!o.predict) {
    go.coords = &coords;
    go.grf = &grf;
    go.free_coords = mj_name2id(m, mjOBJ_JOINT, "pelvis_tz") >= 0 ? free_coords : NULL;
    go.w_pelvis_rot = o.w_pelvis_rot;
    go.w_pelvis_trans = o.w_pelvis_trans;
    go.w_joint = o.w_joint;
    go.w_grf = o.w_grf;
    go.w_grm = o.w_grm;
  } else if (predict_setup(m, &o, &go, &band, &T0, &dx0) != 0) {
    goto done;
  }
  if (go_gait_create(&g, m, &go, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", what, err);
    goto done;
  }
  int n, mm, ne;
  go_nlp_sizes(go_gait_nlp(g), &n, &mm, &ne);
  z = (double*)malloc(sizeof(double) * (size_t)n);
  if (!z) {
    fprintf(stderr, "gaitsim: %s: out of memory\n", what);
    goto done;
  }
  if (o.predict) {
    memcpy(z, band, sizeof(double) * (size_t)n);
    retime_progression(g, z, o.speed,
                       o.stride_time > 0 ? o.stride_time
                       : o.stride_time_start > 0 ? o.stride_time_start : T0);
  } else if (o.init) {
    int from_vars = guess_from_variables(g, o.init, z);
    if (from_vars < 0 || (from_vars == 0 && guess_from_folder(g, m, o.init, o.activation, z) != 0))
      goto done;
  } else if (o.guess_static) {
    go_static_report sr;
    if (go_gait_guess_static(g, &coords, &grf, z, &sr, err, sizeof(err)) != 0) {
      fprintf(stderr, "gaitsim: track: %s\n", err);
      goto done;
    }
    fprintf(stderr, "track: static-optimisation guess: %d matched dofs, residual rms %.3g max "
            "%.3g (N m), mean activation %.3f, %d node-muscle pairs at a = 1, %d QP steps, %d "
            "nodes at the step limit\n", sr.n_matched, sr.rms_residual, sr.max_residual,
            sr.mean_activation, sr.n_at_upper, sr.steps, sr.failed_nodes);
  } else if (go_gait_guess_from_trial(g, &coords, o.activation, z, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: track: %s\n", err);
    goto done;
  }
  // the solve strategy (optim/go_solve.h)
  o.plan.gait = g;
  o.plan.z0 = z;
  o.plan.clock = &clock;
  if (go_solve_run(&o.plan, &rep, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", what, err);
    goto done;
  }
  const go_solve_result* res = &rep.result;
  summary = cJSON_CreateObject();
  cJSON_AddStringToObject(summary, "problem", o.predict ? "prediction" : "tracking");
  cJSON_AddStringToObject(summary, "model", o.model);
  if (o.predict) {
    // the measured trial behind the guess (for the report's reference curves), when it says
    cJSON_AddStringToObject(summary, "guess", o.guess);
    char* trial = trial_of_solution(o.guess);
    if (trial) cJSON_AddStringToObject(summary, "trial", trial);
    free(trial);
  } else {
    cJSON_AddStringToObject(summary, "trial", o.trial);
  }
  cJSON_AddStringToObject(summary, "status", go_solve_status_str(res->status));
  // the project's stopping rule met (Ipopt's optimal or acceptable level, or settled): the
  // solution is a minimum the solver vouches for, not a best iterate stopped short
  cJSON_AddBoolToObject(summary, "converged", rep.converged);
  if (res->status == GO_SOLVE_EVAL_ERROR)  // which evaluation failed last ("": none of ours)
    cJSON_AddStringToObject(summary, "eval_error", res->eval_error);
  cJSON_AddNumberToObject(summary, "iterations", res->iterations);
  cJSON* restarts = cJSON_AddArrayToObject(summary, "restarts");  // after fall-backs, in order
  for (int r = 0; r < rep.n_restarts; r++) {
    cJSON* rj = cJSON_CreateObject();
    cJSON_AddNumberToObject(rj, "after_iterations", rep.restarts[r].after_iterations);
    cJSON_AddNumberToObject(rj, "from_iteration", rep.restarts[r].from_iteration);
    cJSON_AddNumberToObject(rj, "objective", rep.restarts[r].objective);
    cJSON_AddNumberToObject(rj, "violation", rep.restarts[r].violation);
    cJSON_AddItemToArray(restarts, rj);
  }
  if (rep.refined >= 0) {
    cJSON* fj = cJSON_AddObjectToObject(summary, "refine");
    cJSON_AddStringToObject(fj, "hessian", "exact (structured finite differences)");
    cJSON_AddStringToObject(fj, "status", go_solve_status_str(rep.refine.status));
    cJSON_AddNumberToObject(fj, "iterations", rep.refine.iterations);
    cJSON_AddNumberToObject(fj, "wall_s", rep.refine.wall_s);
    cJSON_AddNumberToObject(fj, "objective", rep.refine.objective);
    cJSON_AddBoolToObject(fj, "used", rep.refined);
    if (rep.refine_gn_run) {  // its first phase; iterations and wall_s above include it
      cJSON* gj = cJSON_AddObjectToObject(fj, "gauss_newton");
      cJSON_AddStringToObject(gj, "status", go_solve_status_str(rep.refine_gn.status));
      cJSON_AddNumberToObject(gj, "iterations", rep.refine_gn.iterations);
      cJSON_AddNumberToObject(gj, "wall_s", rep.refine_gn.wall_s);
      // its last point, where the Newton iterations start
      cJSON_AddNumberToObject(gj, "objective", rep.refine_gn.objective);
      cJSON_AddNumberToObject(gj, "violation", rep.refine_gn.max_viol);
    }
  }
  // Ipopt's own measures at its last iteration (scaled problem; before the polish)
  cJSON* lj = cJSON_AddObjectToObject(summary, "ipopt_last_iteration");
  cJSON_AddNumberToObject(lj, "inf_pr", res->last_inf_pr);
  cJSON_AddNumberToObject(lj, "inf_du", res->last_inf_du);
  cJSON_AddNumberToObject(lj, "mu", res->last_mu);
  cJSON_AddBoolToObject(lj, "restoration", res->last_restoration);
  cJSON_AddNumberToObject(summary, "wall_s", rep.wall_s);  // from the start of solve()
  cJSON_AddNumberToObject(summary, "cpu_s", rep.cpu_s);
  cJSON_AddNumberToObject(summary, "ipopt_wall_s", res->wall_s);  // the solves behind the result
  cJSON_AddNumberToObject(summary, "nodes", o.nodes);
  cJSON_AddNumberToObject(summary, "threads", o.threads);
  cJSON_AddNumberToObject(summary, "stride_time_s", go_gait_time_of(g, rep.z));
  cJSON_AddNumberToObject(summary, "body_weight_n", go_gait_weight(g));
  if (o.predict) {
    predict_summary(g, rep.z, &o, band, T0, dx0, rep.objective, summary);
  } else {
    cJSON_AddNumberToObject(summary, "grf_scale", grf_scale);
  }
  double obj_out = rep.objective;
  cJSON_AddNumberToObject(summary, "objective", obj_out);
  double terms[GO_GAIT_NTERMS];  // each goal's part of J and its share
  if (go_gait_objective_terms(g, rep.z, terms) == 0) {
    static const char* tn[GO_GAIT_NTERMS] = GO_GAIT_TERM_NAMES;
    cJSON* tj = cJSON_AddObjectToObject(summary, "objective_terms");
    cJSON* sj = cJSON_AddObjectToObject(summary, "objective_share");
    for (int t = 0; t < GO_GAIT_NTERMS; t++) {
      cJSON_AddNumberToObject(tj, tn[t], terms[t]);
      cJSON_AddNumberToObject(sj, tn[t], obj_out > 0 ? terms[t] / obj_out : 0.0);
    }
  }
  if (rep.polish_run) {
    cJSON* pj = cJSON_AddObjectToObject(summary, "polish");
    cJSON_AddStringToObject(pj, "status", go_solve_status_str(rep.polish.status));
    cJSON_AddNumberToObject(pj, "iterations", rep.polish.iterations);
    cJSON_AddNumberToObject(pj, "wall_s", rep.polish.wall_s);
    cJSON_AddNumberToObject(pj, "violation_before", rep.polish_viol_before);
    // the objective J of the point polished (what the polish costs: J there against "objective")
    cJSON_AddNumberToObject(pj, "objective_before", rep.polish_obj_before);
    // the objective J of the polish's point (null where it was not less violated): from a point
    // within GO_POLISH_GUARD_VIOL of feasibility, one more than GO_POLISH_MAX_RISE above
    // objective_before is not used
    if (isfinite(rep.polish_obj_after))
      cJSON_AddNumberToObject(pj, "objective_after", rep.polish_obj_after);
    else
      cJSON_AddNullToObject(pj, "objective_after");
    cJSON_AddBoolToObject(pj, "used", rep.polished);
  }
  cJSON_AddNumberToObject(summary, "initial_violation", rep.initial_violation);
  cJSON_AddNumberToObject(summary, "max_violation", rep.max_violation);
  cJSON_AddNumberToObject(summary, "max_defect", rep.max_defect);
  cJSON_AddBoolToObject(summary, "best_iterate_written", rep.best_iterate_written);
  double* knee_ref = o.predict ? NULL : measured_knee_contact(o.trial, g);
  int wrote_solution = write_solution(g, rep.z, tx.staging, knee_ref, summary);
  free(knee_ref);
  if (wrote_solution != 0) goto done;
  char* text = cJSON_Print(summary);
  snprintf(path, sizeof(path), "%s/summary.json", tx.staging);
  size_t len = text ? strlen(text) : 0;
  int wrote = text && gs_atomic_write_buffer(path, text, len, err, sizeof(err)) == 0;
  free(text);
  if (!wrote) {
    fprintf(stderr, "gaitsim: %s\n", err);
    goto done;
  }
  if (gs_folder_commit(&tx, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    goto done;
  }
  printf("%s: %s after %d iterations, %.1f s; max violation %.3g (from %.3g); wrote %s\n", what,
         go_solve_status_str(res->status), res->iterations, res->wall_s, rep.max_violation,
         rep.initial_violation, o.out);
  if (res->status == GO_SOLVE_EVAL_ERROR)
    printf("%s: the last failed evaluation: %s\n", what,
           res->eval_error[0] ? res->eval_error : "none (Ipopt's own arithmetic)");
  status = rep.converged ? GS_EXIT_OK : GS_EXIT_STOPPED_SHORT;

done:
  gs_folder_abort(&tx);  // nothing when committed
  cJSON_Delete(summary);
  go_solve_report_free(&rep);
  free(z), free(band);
  go_gait_free(g);
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  return status;
}
