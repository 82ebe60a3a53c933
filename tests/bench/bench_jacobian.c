// bench_jacobian.c: cost of one constraint Jacobian of the tracking problem (issue #5): the
// structured finite differences (GO_JAC_SPARSE, the default: analytic columns plus per-node
// central differences over colour groups) against the dense central-difference baseline of Lin,
// Walter & Pandy 2018 (GO_JAC_DENSE: 2 n full constraint evaluations = 2 n N path evaluations),
// in path (model) evaluations and wall time, side by side in one run (alternating repeats,
// medians).
//
// The dense baseline is quadratic in N (about 6.5 M path evaluations, ~10 min, at N = 80), so both
// modes are run at the small node counts SMALL_N..., and only the structured one at LARGE_N. At
// LARGE_N the dense count is stated exactly as 2 n N from the problem size (the small-N runs check
// that formula against the measured count and fail if it does not hold), and the dense wall time
// is extrapolated as the dense wall per path evaluation measured at the largest small N times
// 2 n N (labelled as such).
//
// The problem is built as `gaitsim track` builds it (app/cmd_solve.c): the trial's coordinates and
// ground reactions, pelvis_tz not periodic, the tracking weights of the command, the guess from
// the trial. The command's scaling of the measured ground reactions to the model's weight changes
// only the objective's reference values, not the constraints, so it is left out here.
//
// usage: bench_jacobian MODEL TRIAL_DIR [repeats] [threads] [LARGE_N] [SMALL_N...]
//        defaults: 5 repeats, 2 threads, LARGE_N 80, SMALL_N 4 8
// Last line: evals_ratio=<dense/structured at LARGE_N> wall_ratio=<dense/structured at LARGE_N,
// extrapolated>. Run by scripts/bench_jacobian.sh; not a test.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "io/gs_storage.h"
#include "io/gs_table.h"
#include "optim/go_collocation.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "optim/go_jacobian.h"
#include "tests/bench/bench_common.h"
#include "tests/gs_test_trial.h"

#define MAX_SMALL 16   // small node counts accepted on the command line
#define MAX_REPEATS 99

// positive integer argument in [lo, hi], or -1
static int parse_count(const char* s, int lo, int hi) {
  char* end;
  long x = strtol(s, &end, 10);
  if (*end || end == s || x < lo || x > hi) return -1;
  return (int)x;
}

// one tracking problem at N nodes and its guess, scaled, with room for Jacobian values
typedef struct {
  go_gait* g;
  go_nlp* nlp;
  int N, n, m, nele, groups;
  double* zs;       // guess, scaled (n)
  double* jac_s;    // structured Jacobian values (nele)
  double* jac_d;    // dense Jacobian values (nele)
} bench_problem;

static void problem_free(bench_problem* p) {
  go_gait_free(p->g);
  free(p->zs);
  free(p->jac_s);
  free(p->jac_d);
  memset(p, 0, sizeof(*p));
}

// Build the tracking problem as app/cmd_solve.c does, at N nodes with `threads` workers, and its
// guess from the trial (scaled). 0, or -1 with the reason on stderr.
static int problem_build(bench_problem* p, const mjModel* m, const gsTable* coords,
                         const gsTable* grf, int N, int threads) {
  char err[1024];
  memset(p, 0, sizeof(*p));
  // the tracking problem of the tests (pelvis_tz free when the model has it); goal weights as
  // `gaitsim track`'s of 2026-11 (the Jacobian's cost does not depend on them)
  go_gait_opts go = gs_test_tracking_opts(coords, grf, N);
  go.nthreads = threads;
  if (mj_name2id(m, mjOBJ_JOINT, "pelvis_tz") < 0) go.free_coords = NULL;
  go.w_pelvis_rot = go.w_pelvis_trans = go.w_grf = 10.0;
  go.w_joint = 1.0;
  go.w_effort = 0.1;
  if (go_gait_create(&p->g, m, &go, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_jacobian: N = %d: %s\n", N, err);
    return -1;
  }
  // sizes and buffers
  p->nlp = go_gait_nlp(p->g);
  p->N = N;
  go_nlp_sizes(p->nlp, &p->n, &p->m, &p->nele);
  p->groups = go_nlp_path_groups(p->nlp);
  double* z = (double*)malloc(sizeof(double) * (size_t)p->n);
  p->zs = (double*)malloc(sizeof(double) * (size_t)p->n);
  p->jac_s = (double*)malloc(sizeof(double) * (size_t)p->nele);
  p->jac_d = (double*)malloc(sizeof(double) * (size_t)p->nele);
  if (!z || !p->zs || !p->jac_s || !p->jac_d) {
    fprintf(stderr, "bench_jacobian: N = %d: out of memory\n", N);
    free(z);
    return -1;
  }
  // the guess of `gaitsim track` (activation 0.05), in the solver's scaling
  if (go_gait_guess_from_trial(p->g, coords, 0.05, z, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_jacobian: N = %d: guess: %s\n", N, err);
    free(z);
    return -1;
  }
  go_nlp_scale_z(p->nlp, z, p->zs);
  free(z);
  return 0;
}

// One Jacobian in `mode` into vals: wall time (s) and path evaluations spent; path_jac calls
// (analytic blocks) in *jac_calls. 0, or -1 with the reason on stderr.
static int time_jacobian(bench_problem* p, go_jac_mode mode, double* vals, double* wall,
                         long* evals, long* jac_calls) {
  go_eval_counts c0, c1;
  go_nlp_set_jac_mode(p->nlp, mode);
  go_nlp_counts(p->nlp, &c0);
  double t0 = bench_now();
  int rc = go_nlp_eval_jac(p->nlp, p->zs, vals);
  *wall = bench_now() - t0;
  go_nlp_counts(p->nlp, &c1);
  go_nlp_set_jac_mode(p->nlp, GO_JAC_SPARSE);
  if (rc != 0) {
    fprintf(stderr, "bench_jacobian: N = %d, %s Jacobian: %s\n", p->N,
            mode == GO_JAC_DENSE ? "dense" : "structured", go_nlp_last_error(p->nlp));
    return -1;
  }
  *evals = c1.path_evals_last_jac;
  *jac_calls = c1.path_jac_calls - c0.path_jac_calls;
  return 0;
}

// largest |structured - dense| over the Jacobian entries, and the largest |dense| entry
static void jac_difference(const bench_problem* p, double* max_diff, double* max_abs) {
  *max_diff = *max_abs = 0;
  for (int e = 0; e < p->nele; e++) {
    *max_diff = fmax(*max_diff, fabs(p->jac_s[e] - p->jac_d[e]));
    *max_abs = fmax(*max_abs, fabs(p->jac_d[e]));
  }
}

// results of one node count
typedef struct {
  int N, n;
  long evals_s, evals_d, calls_s;   // path evaluations (structured, dense), path_jac calls
  double wall_s, wall_d;            // median wall (s); wall_d 0 when dense not run
} bench_result;

// Measure N nodes: structured always, dense too when with_dense, alternating, `repeats` each.
// 0, or -1 with the reason on stderr.
static int measure(const mjModel* m, const gsTable* coords, const gsTable* grf, int N, int threads,
                   int repeats, int with_dense, bench_result* res) {
  bench_problem p;
  double t_build = bench_now();
  if (problem_build(&p, m, coords, grf, N, threads) != 0) {
    problem_free(&p);
    return -1;
  }
  t_build = bench_now() - t_build;
  printf("N=%d: n %d variables, m %d constraints, %d Jacobian nonzeros, %d colour groups, "
         "%d threads (set-up %.1f s)\n", N, p.n, p.m, p.nele, p.groups, threads, t_build);
  fflush(stdout);
  // one untimed constraint evaluation: first touch of the workers' scratch
  double* gv = (double*)malloc(sizeof(double) * (size_t)p.m);
  int bad = !gv || go_nlp_eval_g(p.nlp, p.zs, gv) != 0;
  free(gv);
  if (bad) {
    fprintf(stderr, "bench_jacobian: N = %d: constraints at the guess: %s\n", N,
            go_nlp_last_error(p.nlp));
    problem_free(&p);
    return -1;
  }
  // alternating repeats, so drifts in the machine's load hit both modes alike
  double ws[MAX_REPEATS], wd[MAX_REPEATS];
  long es = 0, ed = 0, cs = 0, cd = 0;
  for (int r = 0; r < repeats; r++) {
    long e, c;
    if (time_jacobian(&p, GO_JAC_SPARSE, p.jac_s, &ws[r], &e, &c) != 0) goto fail;
    if (r > 0 && (e != es || c != cs)) {
      fprintf(stderr, "bench_jacobian: N = %d: structured count changed between repeats\n", N);
      goto fail;
    }
    es = e;
    cs = c;
    if (!with_dense) continue;
    if (time_jacobian(&p, GO_JAC_DENSE, p.jac_d, &wd[r], &e, &cd) != 0) goto fail;
    ed = e;
    printf("  repeat %d: structured %.4f s, dense %.3f s\n", r + 1, ws[r], wd[r]);
    fflush(stdout);
  }
  // medians and the report of this node count
  res->N = N;
  res->n = p.n;
  res->evals_s = es;
  res->calls_s = cs;
  res->wall_s = bench_median(ws, repeats);
  res->evals_d = ed;
  res->wall_d = with_dense ? bench_median(wd, repeats) : 0;
  printf("  structured: %ld path evaluations (2 N groups = %ld) + %ld analytic path_jac calls; "
         "median %.4f s over %d repeats\n", es, 2L * N * p.groups, cs, res->wall_s, repeats);
  if (with_dense) {
    long formula = 2L * p.n * N;
    double dmax, amax;
    jac_difference(&p, &dmax, &amax);
    printf("  dense:      %ld path evaluations (2 n N = %ld, %s); median %.3f s = %.2f us per "
           "path evaluation\n", ed, formula, ed == formula ? "equal" : "DIFFERENT", res->wall_d,
           1e6 * res->wall_d / (double)ed);
    printf("  ratio dense/structured: evaluations %.1f, wall %.1f; max |J_structured - J_dense| "
           "%.3g (largest |entry| %.3g)\n", (double)ed / (double)es, res->wall_d / res->wall_s,
           dmax, amax);
    if (ed != formula) {
      fprintf(stderr, "bench_jacobian: N = %d: dense count %ld is not 2 n N = %ld\n", N, ed,
              formula);
      goto fail;
    }
  }
  fflush(stdout);
  problem_free(&p);
  return 0;
fail:
  problem_free(&p);
  return -1;
}

int main(int argc, char** argv) {
  // arguments
  if (argc < 3) {
    fprintf(stderr, "usage: bench_jacobian MODEL TRIAL_DIR [repeats] [threads] [LARGE_N] "
                    "[SMALL_N...]\n");
    return 2;
  }
  int repeats = argc > 3 ? parse_count(argv[3], 1, MAX_REPEATS) : 5;
  int threads = argc > 4 ? parse_count(argv[4], 1, 64) : 2;
  int large = argc > 5 ? parse_count(argv[5], 3, 100000) : 80;
  int small[MAX_SMALL] = {4, 8}, nsmall = 2;
  if (argc > 6) {
    nsmall = argc - 6;
    if (nsmall > MAX_SMALL) nsmall = -1;
    for (int i = 0; i < nsmall; i++)
      if ((small[i] = parse_count(argv[6 + i], 3, 100000)) < 0) nsmall = -1;
  }
  if (repeats < 0 || threads < 0 || large < 0 || nsmall < 0) {
    fprintf(stderr, "bench_jacobian: bad argument (repeats 1-%d, threads 1-64, node counts >= 3, "
                    "at most %d small node counts)\n", MAX_REPEATS, MAX_SMALL);
    return 2;
  }
  // model with gaitsim's physics, as gs_app_load_model does
  char err[1024], path[4096];
  gs_mujoco_install_handlers();
  mjModel* m = gs_model_load(argv[1], err, sizeof(err));
  if (!m || gs_physics_prepare(m, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_jacobian: %s: %s\n", argv[1], err);
    mj_deleteModel(m);
    return 1;
  }
  gs_physics_install();
  // the trial's tables, angles in radians (gs_app_read_table)
  gsTable coords, grf;
  gs_table_init(&coords);
  gs_table_init(&grf);
  int status = 1;
  snprintf(path, sizeof(path), "%s/coordinates.mot", argv[2]);
  if (gs_storage_read(path, &coords, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_jacobian: %s\n", err);
    goto done;
  }
  snprintf(path, sizeof(path), "%s/grf.mot", argv[2]);
  if (gs_storage_read(path, &grf, err, sizeof(err)) != 0) {
    fprintf(stderr, "bench_jacobian: %s\n", err);
    goto done;
  }
  gs_table_to_radians(&coords, gs_state_is_angle, (void*)m);
  gs_table_to_radians(&grf, gs_state_is_angle, (void*)m);
  printf("model %s, trial %s: nv %d, nu %d\n", argv[1], argv[2], m->nv, m->nu);
  // both modes at the small node counts; the largest one gives the dense wall per evaluation
  bench_result rs[MAX_SMALL], rl;
  int ref = 0;
  for (int i = 0; i < nsmall; i++) {
    if (measure(m, &coords, &grf, small[i], threads, repeats, 1, &rs[i]) != 0) goto done;
    if (rs[i].N > rs[ref].N) ref = i;
  }
  // the structured Jacobian at the large node count
  if (measure(m, &coords, &grf, large, threads, repeats, 0, &rl) != 0) goto done;
  // the dense baseline at the large node count: exact count, extrapolated wall
  long dense_evals = 2L * rl.n * large;
  double per_eval = rs[ref].wall_d / (double)rs[ref].evals_d;
  double dense_wall = per_eval * (double)dense_evals;
  double evals_ratio = (double)dense_evals / (double)rl.evals_s;
  double wall_ratio = dense_wall / rl.wall_s;
  printf("N=%d dense baseline (not run): 2 n N = 2 x %d x %d = %ld path evaluations (exact; the "
         "formula matched the measured count at every small N)\n", large, rl.n, large,
         dense_evals);
  printf("N=%d dense wall, EXTRAPOLATED: %.2f us per path evaluation (measured at N = %d) x %ld "
         "= %.0f s\n", large, 1e6 * per_eval, rs[ref].N, dense_evals, dense_wall);
  printf("N=%d structured: %ld path evaluations, %.3f s measured; dense/structured: evaluations "
         "%.1fx (exact), wall %.0fx (extrapolated)\n", large, rl.evals_s, rl.wall_s, evals_ratio,
         wall_ratio);
  printf("evals_ratio=%.1f wall_ratio=%.1f\n", evals_ratio, wall_ratio);
  status = 0;
done:
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  return status;
}
