// go_solve.c: the solve strategy of a gait problem (see go_solve.h).
#define _POSIX_C_SOURCE 200809L
#include "optim/go_solve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "optim/go_hessian.h"
#include "optim/go_jacobian.h"

void go_clock_start(go_clock* c) {
  clock_gettime(CLOCK_MONOTONIC, &c->wall);
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c->cpu);
}

static double seconds_since(clockid_t id, const struct timespec* a) {
  struct timespec b;
  clock_gettime(id, &b);
  return (double)(b.tv_sec - a->tv_sec) + 1e-9 * (double)(b.tv_nsec - a->tv_nsec);
}

double go_clock_wall_s(const go_clock* c) { return seconds_since(CLOCK_MONOTONIC, &c->wall); }
double go_clock_cpu_s(const go_clock* c) {
  return seconds_since(CLOCK_PROCESS_CPUTIME_ID, &c->cpu);
}

void go_solve_plan_default(go_solve_plan* p) {
  char err[256];
  memset(p, 0, sizeof(*p));
  go_ipopt_opts_default(&p->ipopt);
  // stopping rule (the caller's extra options come after and override it): Ipopt's own
  // optimality at tol 1e-4, or its acceptable level: violation <= 1e-4 (scaled; the polish then
  // projects the point onto the dynamics, to <= 1e-8) and the objective settled to 1e-4 relative
  // per iteration (gaitsim predict: GO_PREDICT_SETTLE_REL) over GO_SETTLE_ITER (15) consecutive
  // iterations, the count of the settled rule. With 1e-6 instead of 1e-4, the predictions at
  // 0.8 and 2.0 m/s went on past their settled objective (within 0.1 % of the lowest ever
  // reached) and, in 2 of 4 solves, climbed back 40-50 % when the adaptive barrier fell back to
  // its monotone mode (docs/BENCHMARKS.md, "The acceptable level at 1e-4").
  static const char* stop_rule[][2] = {
      {"tol", "1e-4"},          {"constr_viol_tol", "1e-6"},
      {"acceptable_tol", "1"},  {"acceptable_constr_viol_tol", "1e-4"},
      {"acceptable_compl_inf_tol", "1e-3"}, {"acceptable_obj_change_tol", "1e-4"},
      {"acceptable_iter", GO_STR(GO_SETTLE_ITER)}, {"limited_memory_max_history", "20"}};
  for (size_t i = 0; i < sizeof(stop_rule) / sizeof(stop_rule[0]); i++)
    go_ipopt_opts_set(&p->ipopt, stop_rule[i][0], stop_rule[i][1], err, sizeof(err));
  // the limited-memory Hessian's KKT systems: one factorisation of the augmented system extended
  // by the 2 x 20 low-rank columns, instead of Ipopt's default Sherman-Morrison update, which
  // re-solves the system for each of those columns at every iteration (the barrier diagonal
  // changes the factor each time). At N = 80 the 40 back-solves took 57 % of an L-BFGS
  // iteration; extended, a prediction's iteration costs about 1.0 s instead of 1.6 s on one core
  // (docs/BENCHMARKS.md, "Predictions: one factorisation per L-BFGS iteration, and the settled
  // rule")
  go_ipopt_opts_set(&p->ipopt, "limited_memory_aug_solver", "extended", err, sizeof(err));
  // fall-back guard: stop when the objective rises GO_FALLBACK_RISE above the lowest one
  // reached at a violation <= GO_FALLBACK_VIOL, and restart from the best iterate
  p->ipopt.fallback_rise = GO_FALLBACK_RISE;
  p->ipopt.fallback_viol = GO_FALLBACK_VIOL;
  p->hessian = GO_HESSIAN_LBFGS;
  p->main_jacobian = GO_JAC_SPARSE;
  p->gn_mu_init = GO_GN_MU_INIT;
  p->min_hess_perturbation = GO_MIN_HESS_PERTURBATION;
  p->max_iter = -1;
  p->max_restarts = GO_MAX_RESTARTS;
  p->refine_iter = GO_REFINE_ITER;
  p->refine_wall_s = GO_REFINE_WALL_S;
  p->refine_gn_iter = GO_REFINE_GN_ITER;
  p->settle_iter = GO_SETTLE_ITER;
  p->settle_rel = GO_SETTLE_REL;
  p->settle_viol = GO_SETTLE_VIOL;
  p->settle_main_viol = 0;  // the main solve: Ipopt's tests alone (predictions set it)
  p->settle_main_rel = GO_SETTLE_REL;
  p->polish = 1;
  p->polish_iter = GO_POLISH_ITER;
  p->stop_polish_wall_s = GO_STOP_POLISH_S;
  p->label = "solve";
}

void go_solve_plan_settle_main(go_solve_plan* p, double viol, double rel) {
  char val[32], err[256];
  p->settle_main_viol = viol;
  p->settle_main_rel = rel;
  snprintf(val, sizeof(val), "%g", rel);
  go_ipopt_opts_set(&p->ipopt, "acceptable_obj_change_tol", val, err, sizeof(err));
}

void go_solve_report_free(go_solve_report* r) {
  free(r->z);
  r->z = NULL;
}

// constraint blocks of the gait NLP, for the diagnostic lines
enum { BLOCKS = 9 };
static const char* kBlockNames[BLOCKS] = {"defect", "link",  "eom", "hill", "act",
                                          "grf",    "boundary", "fibre", "walk"};

// block of constraint row r, its index within the node (state, path row, boundary row) and node
static int block_of_row(go_gait* g, int r, int* idx, int* node) {
  go_nlp* nlp = go_gait_nlp(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int p0 = go_nlp_row_path(nlp, 0, 0), b0 = go_nlp_row_boundary(nlp, 0);
  if (r < p0) {
    *idx = r % L->nx, *node = r / L->nx;
    return 0;
  }
  if (r >= b0) {
    *idx = r - b0, *node = 0;
    return 6;
  }
  int pr = (r - p0) % L->n_path;
  *idx = pr, *node = (r - p0) / L->n_path;
  if (L->r_walk >= 0 && pr == L->r_walk) return 8;
  if (L->r_fib >= 0 && pr >= L->r_fib) return 7;
  return pr < L->r_eom ? 1 : pr < L->r_hill ? 2 : pr < L->r_act ? 3 : pr < L->r_grf ? 4 : 5;
}

// largest of v[r] per block, one line to f
static void print_block_max(FILE* f, go_gait* g, const double* v, int mm, const char* what,
                            int with_node) {
  double mx[BLOCKS] = {0};
  int at[BLOCKS] = {0}, node[BLOCKS] = {0};
  for (int r = 0; r < mm; r++) {
    int idx, k, blk = block_of_row(g, r, &idx, &k);
    if (v[r] > mx[blk]) mx[blk] = v[r], at[blk] = idx, node[blk] = k;
  }
  fprintf(f, "%s by block:", what);
  const go_gait_layout* L = go_gait_layout_get(g);
  for (int b = 0; b < BLOCKS; b++) {
    if ((b == 7 && L->r_fib < 0) || (b == 8 && L->r_walk < 0)) continue;  // rows not in the NLP
    if (with_node) fprintf(f, " %s %.3g (#%d node %d)", kBlockNames[b], mx[b], at[b], node[b]);
    else fprintf(f, " %s %.3g (#%d)", kBlockNames[b], mx[b], at[b]);
  }
  fprintf(f, "\n");
}

// largest |multiplier| per constraint block (solver scaling), one line: which constraints the
// solve is fighting (a multiplier that grows without bound marks a degenerate or nearly
// dependent block)
static void print_largest_multipliers(FILE* f, go_gait* g, const double* lam, const char* what) {
  int n, mm, ne;
  go_nlp_sizes(go_gait_nlp(g), &n, &mm, &ne);
  double* a = (double*)malloc(sizeof(double) * (size_t)mm);
  if (!a) return;
  for (int r = 0; r < mm; r++) a[r] = fabs(lam[r]);
  char label[64];
  snprintf(label, sizeof(label), "%s: largest multiplier", what);
  print_block_max(f, g, a, mm, label, 1);
  free(a);
}

// largest scaled violation per constraint block, one line: |g| for the equalities, the
// distance outside [lb, ub] for the inequality rows
static void print_blocks(FILE* f, go_gait* g, const double* gv, const char* label,
                         const char* when) {
  go_nlp* nlp = go_gait_nlp(g);
  int n, mm, ne;
  go_nlp_sizes(nlp, &n, &mm, &ne);
  double* gl = (double*)malloc(sizeof(double) * (size_t)mm);
  double* gu = (double*)malloc(sizeof(double) * (size_t)mm);
  double* xl = (double*)malloc(sizeof(double) * (size_t)n);
  double* xu = (double*)malloc(sizeof(double) * (size_t)n);
  double* v = (double*)malloc(sizeof(double) * (size_t)mm);
  if (gl && gu && xl && xu && v) {
    go_nlp_bounds(nlp, xl, xu, gl, gu);
    for (int r = 0; r < mm; r++) v[r] = fmax(fmax(gl[r] - gv[r], gv[r] - gu[r]), 0.0);
    char text[96];
    snprintf(text, sizeof(text), "%s: %s violation", label, when);
    print_block_max(f, g, v, mm, text, 0);
  }
  free(gl), free(gu), free(xl), free(xu), free(v);
}

// Ipopt options for a solve that starts at a point near a solution (the restarts after a
// fall-back, the exact-Hessian refinement): bound multipliers from a small barrier (z = mu / s,
// mu 1e-6), so that the barrier update starts small, and the point barely pushed off its bounds
static int set_start_near_solution(go_ipopt_opts* ro, char* err, int errsz) {
  static const char* kv[][2] = {{"bound_mult_init_method", "mu-based"}, {"mu_init", "1e-6"},
                                {"bound_push", "1e-8"}, {"bound_frac", "1e-8"}};
  for (size_t i = 0; i < sizeof(kv) / sizeof(kv[0]); i++)
    if (go_ipopt_opts_set(ro, kv[i][0], kv[i][1], err, errsz) != 0) return -1;
  return 0;
}

// Ipopt options of the feasibility polish: Gauss-Newton (exact for the proximal goal), tol 1e-6,
// violation 1e-8, the best iterate ranked by violation alone, starting at the point itself: a
// small barrier, the point barely pushed off its bounds. The barrier's pull mu / s on a variable
// pushed 1e-8 off its bound must stay below the proximal term's: with mu 1e-6 (100 there) the
// polish of a prediction at 2.0 m/s, whose activations sit at their 0.001 bound, wandered for 200
// iterations at 2e-5 - 1e-3; with 1e-9 it reached 1.6e-9 in 7 (docs/BENCHMARKS.md, "The
// acceptable level at 1e-4")
static int set_polish(go_ipopt_opts* po, char* err, int errsz) {
  static const char* kv[][2] = {{"tol", "1e-6"},        {"constr_viol_tol", "1e-8"},
                                {"mu_init", "1e-9"},    {"bound_push", "1e-8"},
                                {"bound_frac", "1e-8"}};
  go_ipopt_opts_default(po);
  po->gauss_newton = 1;
  // its best iterate is the least violated one: the objective (the distance from the start) is
  // not a rank here, and with the default 1e-3 the start itself (objective 0) beat every later
  // iterate below 1e-3, so a polish that did not converge was never used (a 1.8 m/s prediction
  // at band x 1.5: 200 iterations reaching 7e-8, the settled point's 2.6e-4 written)
  po->best_viol_tol = 0;
  for (size_t i = 0; i < sizeof(kv) / sizeof(kv[0]); i++)
    if (go_ipopt_opts_set(po, kv[i][0], kv[i][1], err, errsz) != 0) return -1;
  return 0;
}

// Ipopt's optimal or acceptable level: the project's stopping rule was met
static int solve_converged(const go_solve_result* r) {
  return r->status == GO_SOLVE_SUCCESS || r->status == GO_SOLVE_ACCEPTABLE ||
         r->status == GO_SOLVE_SETTLED;
}

// a solve that continued an earlier one: iterations, the best iterate's index, times add up
static void continue_result(go_solve_result* later, const go_solve_result* earlier) {
  later->iterations += earlier->iterations;
  later->best_iter = later->best_iter >= 0 ? later->best_iter + earlier->iterations : -1;
  later->wall_s += earlier->wall_s;
  later->cpu_s += earlier->cpu_s;
}

// the points and buffers of one run
typedef struct {
  const go_solve_plan* p;   // the plan
  go_gait* g;               // its problem
  go_nlp* nlp;              // its NLP
  int n, mm, ne;            // variables, constraints, Jacobian nonzeros
  double* z;                // Ipopt's point (n, physical)
  double* zb;               // the best iterate (n, physical)
  double* zs;               // scratch: a stage's best iterate, scaled points (n)
  double* gv;               // constraint values (mm)
  double* lam;              // the last solve's constraint multipliers (mm, scaled), or NULL
  go_ipopt_mult mult;       // lam as Ipopt's output
  go_hess* hess;            // Hessian of the main solve or of the refinement, or NULL
} run_state;

// stages 1-2: the main solve and the restarts after fall-backs; 0 or -1 with err
static int main_solve(run_state* s, go_ipopt_opts* opts, go_solve_report* rep, char* err,
                      int errsz) {
  const go_solve_plan* p = s->p;
  go_solve_result* res = &rep->result;
  go_ipopt_mult* mult = s->lam ? &s->mult : NULL;
  if (go_ipopt_solve(s->nlp, opts, s->z, s->zb, mult, res, err, errsz) != 0) return -1;
  // restarts after a fall-back: Ipopt once came near a solution (violation <= 1e-4) and left it
  // (the adaptive barrier's fixed mode or a restoration phase raised mu by 3-9 decades and the
  // objective by 40-600 %; docs/BENCHMARKS.md, "Fall-backs and restarts"). Start again from the
  // best iterate with the iterations left (set_start_near_solution)
  while (res->status == GO_SOLVE_FELL_BACK && res->best_iter >= 0 &&
         rep->n_restarts < p->max_restarts && rep->n_restarts < GO_MAX_RESTARTS &&
         (p->max_iter < 0 || res->iterations < p->max_iter) &&
         (p->max_wall_s <= 0 || res->wall_s < p->max_wall_s)) {
    rep->restarts[rep->n_restarts] = (go_solve_restart){res->iterations, res->best_iter,
                                                        res->best_objective, res->best_viol};
    if (p->progress)
      fprintf(p->progress, "%s: fell back after %d iterations; restart from the best iterate "
              "(iteration %d, objective %.6g, violation %.3g)\n", p->label, res->iterations,
              res->best_iter, res->best_objective, res->best_viol);
    go_ipopt_opts ro = *opts;
    if (p->max_iter >= 0) ro.max_iter = p->max_iter - res->iterations;
    if (ro.handover_iter > 0)  // counted from the main solve's start
      ro.handover_iter = ro.handover_iter > res->iterations ? ro.handover_iter - res->iterations
                                                            : 1;
    if (p->max_wall_s > 0) ro.max_wall_s = p->max_wall_s - res->wall_s;
    char why[512];
    if (set_start_near_solution(&ro, why, sizeof(why)) != 0) {
      snprintf(err, (size_t)errsz, "restart: %s", why);
      return -1;
    }
    memcpy(s->z, s->zb, sizeof(double) * (size_t)s->n);
    go_solve_result r2;
    if (go_ipopt_solve(s->nlp, &ro, s->z, s->zb, mult, &r2, why, sizeof(why)) != 0) {
      snprintf(err, (size_t)errsz, "restart: %s", why);
      return -1;
    }
    // the restart's iteration 0 is the best iterate itself (pushed 1e-8 off its bounds), so its
    // best iterate is at least as good; counts and times add up
    continue_result(&r2, res);
    *res = r2;
    rep->n_restarts++;
  }
  return 0;
}

// key = value in front of opts' options, so that one of the caller's (later) overrides it; 0, or
// -1 with err when the list is full
static int prepend_option(go_ipopt_opts* opts, const char* key, double value, char* err,
                          int errsz) {
  if (opts->n_kv >= GO_IPOPT_MAX_OPTIONS) {
    snprintf(err, (size_t)errsz, "more than %d Ipopt options", GO_IPOPT_MAX_OPTIONS - 1);
    return -1;
  }
  memmove(opts->kv + 1, opts->kv, sizeof(opts->kv[0]) * (size_t)opts->n_kv);
  snprintf(opts->kv[0].key, sizeof(opts->kv[0].key), "%s", key);
  snprintf(opts->kv[0].val, sizeof(opts->kv[0].val), "%.17g", value);
  opts->n_kv++;
  return 0;
}

// stage 3: exact-Hessian refinement of an L-BFGS or Gauss-Newton main solve that stopped short,
// from its best iterate
// with a small barrier (mu 1e-6, bound multipliers mu / s, the point barely pushed off its
// bounds); 0 or -1 with err
static int refine(run_state* s, const go_ipopt_opts* opts, go_solve_report* rep, char* err,
                  int errsz) {
  const go_solve_plan* p = s->p;
  go_solve_result* res = &rep->result;
  if (!(p->refine_iter > 0 &&
        (p->hessian == GO_HESSIAN_LBFGS || p->hessian == GO_HESSIAN_GAUSS_NEWTON) &&
        res->best_iter >= 0 &&
        !solve_converged(res) && res->status != GO_SOLVE_INTERRUPTED &&
        (p->max_wall_s <= 0 || res->wall_s < p->max_wall_s)))
    return 0;
  char why[512];
  if (go_hess_create_fd(&s->hess, s->nlp, go_gait_elements(s->g), why, sizeof(why)) != 0) {
    snprintf(err, (size_t)errsz, "refine: %s", why);
    return -1;
  }
  // both phases share at most refine_wall_s and what is left of max_wall_s (<= 0: no clock)
  double budget = p->refine_wall_s;
  if (p->max_wall_s > 0) {  // > 0 here: the guard above returned when it was spent
    double left = p->max_wall_s - res->wall_s;
    budget = budget > 0 ? fmin(left, budget) : left;
  }
  go_ipopt_opts ro = *opts;
  ro.gauss_newton = 0;
  ro.max_wall_s = budget;
  if (p->hessian == GO_HESSIAN_LBFGS && p->min_hess_perturbation > 0 &&
      prepend_option(&ro, "min_hessian_perturbation", p->min_hess_perturbation, err, errsz) != 0)
    return -1;
  ro.handover_iter = 0;
  ro.settle_iter = 0;  // the Gauss-Newton phase runs its iterations; Newton's rule is set below
  if (set_start_near_solution(&ro, why, sizeof(why)) != 0) {
    snprintf(err, (size_t)errsz, "refine: %s", why);
    return -1;
  }
  // z (Ipopt's point of a solve that stopped short, not used: its output is zb) takes the
  // refinement's point, zs its best iterate
  memcpy(s->z, s->zb, sizeof(double) * (size_t)s->n);
  go_ipopt_mult* mult = s->lam ? &s->mult : NULL;
  // phase 1, Gauss-Newton: the goals' exact Hessian without the constraints' curvature, positive
  // semi-definite, so Ipopt takes its steps without the inertia correction that shrinks the
  // exact Hessian's (docs/BENCHMARKS.md, "Gauss-Newton before Newton")
  go_solve_result* gres = &rep->refine_gn;
  rep->refine_gn_run = p->refine_gn_iter > 0;
  if (rep->refine_gn_run) {
    go_ipopt_opts go = ro;
    go.hess = NULL;
    go.gauss_newton = 1;
    go.max_iter = p->refine_gn_iter;
    if (p->progress)
      fprintf(p->progress, "%s: %s after %d iterations; Gauss-Newton refinement from the best "
              "iterate (iteration %d, objective %.6g, violation %.3g), %d iterations\n",
              p->label, go_solve_status_str(res->status), res->iterations, res->best_iter,
              res->best_objective, res->best_viol, p->refine_gn_iter);
    if (go_ipopt_solve(s->nlp, &go, s->z, s->zs, mult, gres, why, sizeof(why)) != 0) {
      snprintf(err, (size_t)errsz, "refine: %s", why);
      return -1;
    }
    if (p->progress)
      fprintf(p->progress, "%s: Gauss-Newton: %s after %d iterations, %.1f s, objective %.6g at "
              "violation %.3g\n", p->label, go_solve_status_str(gres->status),
              gres->iterations, gres->wall_s, gres->objective, gres->max_viol);
    // Newton starts where Gauss-Newton stopped: its iterates stay 1e-2 - 1e-1 off the dynamics,
    // which Newton's first iterations take back to 1e-4 at about the same objective (a
    // projection onto the dynamics does not: the nearest consistent point lets the pelvis
    // drift); unless Gauss-Newton failed, when Newton starts from the main solve's best iterate
    int gn_usable = isfinite(gres->objective) && isfinite(gres->max_viol) &&
                    !gres->last_restoration &&
                    (gres->status == GO_SOLVE_MAX_ITER || solve_converged(gres));
    if (!gn_usable) memcpy(s->z, s->zb, sizeof(double) * (size_t)s->n);
    ro.max_wall_s = budget > 0 ? budget - gres->wall_s : 0.0;
    if (gres->status == GO_SOLVE_INTERRUPTED || (budget > 0 && ro.max_wall_s <= 0)) {
      // nothing left for Newton: the Gauss-Newton phase stands for the refinement, its best
      // iterate (by the usual ranking) kept when it beats the main solve's
      rep->refine = *gres;
      rep->refined = gres->best_iter >= 0 &&
                     go_ipopt_point_better(gres->best_objective, gres->best_viol,
                                           res->best_objective, res->best_viol,
                                           ro.best_viol_tol);
      goto kept;
    }
  }
  // phase 2, Newton with the exact Hessian, stopped by Ipopt's tests or the settled rule
  ro.hess = s->hess;
  ro.max_iter = p->refine_iter;
  ro.settle_iter = p->settle_iter;
  ro.settle_rel = p->settle_rel;
  ro.settle_viol = p->settle_viol;
  if (p->progress)
    fprintf(p->progress, "%s: exact-Hessian refinement, up to %d iterations\n", p->label,
            p->refine_iter);
  go_solve_result* rres = &rep->refine;
  if (go_ipopt_solve(s->nlp, &ro, s->z, s->zs, mult, rres, why, sizeof(why)) != 0) {
    snprintf(err, (size_t)errsz, "refine: %s", why);
    return -1;
  }
  if (rep->refine_gn_run) continue_result(rres, gres);
  // used: converged, or stopped short at a best iterate that beats the main solve's by the glue's
  // ranking (among points the polish can take, the lower objective)
  rep->refined = solve_converged(rres) ||
                 (rres->best_iter >= 0 &&
                  go_ipopt_point_better(rres->best_objective, rres->best_viol, res->best_objective,
                                        res->best_viol, ro.best_viol_tol));
  if (p->progress)
    fprintf(p->progress, "%s: refinement: %s after %d iterations, %.1f s, objective %.6g%s\n",
            p->label, go_solve_status_str(rres->status), rres->iterations, rres->wall_s,
            rres->objective,
            solve_converged(rres) ? ""
            : rep->refined ? "; its best iterate beats the main solve's and is kept"
                           : "; the main solve's best iterate stays");
kept:
  if (rep->refined) {
    memcpy(s->zb, s->zs, sizeof(double) * (size_t)s->n);
    go_solve_result merged = rep->refine;
    continue_result(&merged, res);
    *res = merged;
  }
  return 0;
}

// the physical objective J at the physical point z (NAN where it cannot be evaluated); zs
// (n) receives z scaled
static double objective_at(go_nlp* nlp, const double* z, double* zs) {
  double f;
  go_nlp_scale_z(nlp, z, zs);
  return go_nlp_eval_f(nlp, zs, &f) == 0 ? go_nlp_objective_phys(nlp, f) : NAN;
}

// stage 5: the feasibility polish of *zout (Ipopt's point when converged and not settled, whose
// acceptable test allows a violation of 1e-4, else the best iterate; go_gait_set_proximal), by
// Gauss-Newton, whenever that point is violated by more than 1e-8; *zout becomes zb when the
// polished point is less violated than *zout and go_solve_polish_usable. 0 or -1 with err
static int polish(run_state* s, double** zout, go_solve_report* rep, char* err, int errsz) {
  const go_solve_plan* p = s->p;
  const go_solve_result* res = &rep->result;
  // the point polished is Ipopt's or the best iterate (a settled solve's, though it converged)
  int from_best = *zout == s->zb;
  rep->polish_viol_before = from_best ? res->best_viol : res->max_viol;
  rep->polish_obj_before = from_best ? res->best_objective : res->objective;
  rep->polish_run = p->polish && (rep->converged || res->best_iter >= 0) &&
                    rep->polish_viol_before > 1e-8;
  if (!rep->polish_run) return 0;
  if (go_gait_set_proximal(s->g, *zout) != 0) {
    snprintf(err, (size_t)errsz, "out of memory (polish)");
    return -1;
  }
  if (s->z != *zout) memcpy(s->z, *zout, sizeof(double) * (size_t)s->n);
  // the point polished, kept for when the polish's point is refused (Ipopt overwrites s->z),
  // and a scaled copy of the polish's point for its objective
  double* keep = (double*)malloc(sizeof(double) * (size_t)(2 * s->n));
  if (!keep) {
    go_gait_set_proximal(s->g, NULL);
    snprintf(err, (size_t)errsz, "out of memory (polish)");
    return -1;
  }
  memcpy(keep, *zout, sizeof(double) * (size_t)s->n);
  go_ipopt_opts po;
  char why[512];
  if (set_polish(&po, why, sizeof(why)) != 0) {
    go_gait_set_proximal(s->g, NULL);
    free(keep);
    snprintf(err, (size_t)errsz, "polish: %s", why);
    return -1;
  }
  po.max_iter = p->polish_iter;
  po.max_wall_s = p->max_wall_s;
  // after a stop signal, only a quick polish (a second signal ends it at once, writing nothing)
  if (res->status == GO_SOLVE_INTERRUPTED &&
      !(po.max_wall_s > 0 && po.max_wall_s < p->stop_polish_wall_s))
    po.max_wall_s = p->stop_polish_wall_s;
  po.progress = p->progress;
  po.handle_sigint = 1;
  if (p->progress)
    fprintf(p->progress, "%s: feasibility polish from violation %.3g\n", p->label,
            rep->polish_viol_before);
  go_solve_result* pres = &rep->polish;
  int prc = go_ipopt_solve(s->nlp, &po, s->z, s->zs, NULL, pres, why, sizeof(why));
  go_gait_set_proximal(s->g, NULL);
  if (prc != 0) {
    free(keep);
    snprintf(err, (size_t)errsz, "polish: %s", why);
    return -1;
  }
  int pconv = solve_converged(pres);
  const double* zp = pconv || pres->best_iter < 0 ? s->z : s->zs;
  double vp = pconv || pres->best_iter < 0 ? pres->max_viol : pres->best_viol;
  rep->polish_obj_after = NAN;
  if (vp < rep->polish_viol_before) {
    // its objective (the proximal term is off again): a point far above the one polished is
    // not the nearest consistent one but where Ipopt wandered (e.g. in its restoration phase)
    rep->polish_obj_after = objective_at(s->nlp, zp, keep + s->n);
    if (go_solve_polish_usable(rep->polish_viol_before, rep->polish_obj_before, vp,
                               rep->polish_obj_after)) {
      memcpy(s->zb, zp, sizeof(double) * (size_t)s->n);
      *zout = s->zb;
      rep->polished = 1;
    } else if (p->progress) {
      fprintf(p->progress, "%s: polish: its point's objective %.6g is more than %.0f %% above "
              "the point polished (%.6g): not used\n", p->label, rep->polish_obj_after,
              100 * GO_POLISH_MAX_RISE, rep->polish_obj_before);
    }
  }
  // the point polished stays where the polish is not used (s->z held it and Ipopt moved it)
  if (!rep->polished && *zout == s->z) memcpy(s->z, keep, sizeof(double) * (size_t)s->n);
  free(keep);
  return 0;
}

int go_solve_polish_usable(double viol_before, double obj_before, double viol_after,
                           double obj_after) {
  return viol_after < viol_before &&
         (viol_before > GO_POLISH_GUARD_VIOL ||
          obj_after <= obj_before + GO_POLISH_MAX_RISE * fmax(fabs(obj_before), 1e-12));
}

// the stages of go_solve_run on the buffers of s; 0 or -1 with err
static int run_stages(run_state* s, go_solve_report* rep, char* err, int errsz) {
  const go_solve_plan* p = s->p;
  FILE* f = p->progress;
  char why[512];
  // the start point: sizes and its violation
  go_nlp_scale_z(s->nlp, p->z0, s->zs);
  rep->initial_violation =
      go_nlp_eval_g(s->nlp, s->zs, s->gv) == 0 ? go_nlp_violation(s->nlp, s->gv) : INFINITY;
  if (f) {
    fprintf(f, "%s: %d nodes, %d variables, %d constraints, %d Jacobian nonzeros, %d colour "
            "groups, %d threads; initial violation %.3g\n", p->label, go_gait_nodes(s->g), s->n,
            s->mm, s->ne, go_nlp_path_groups(s->nlp), go_gait_threads(s->g),
            rep->initial_violation);
    print_blocks(f, s->g, s->gv, p->label, "initial");
  }
  // the main solve's options and Hessian
  go_ipopt_opts opts = p->ipopt;
  int second_order = p->hessian == GO_HESSIAN_GAUSS_NEWTON || p->hessian == GO_HESSIAN_EXACT;
  if ((p->hessian == GO_HESSIAN_GAUSS_NEWTON && p->gn_mu_init > 0 &&
       prepend_option(&opts, "mu_init", p->gn_mu_init, err, errsz) != 0) ||
      (second_order && p->min_hess_perturbation > 0 &&
       prepend_option(&opts, "min_hessian_perturbation", p->min_hess_perturbation, err, errsz)))
    return -1;
  opts.max_iter = p->max_iter;
  opts.max_wall_s = p->max_wall_s;
  opts.progress = f;
  opts.handle_sigint = 1;
  opts.gauss_newton = p->hessian == GO_HESSIAN_GAUSS_NEWTON;
  if ((p->hessian == GO_HESSIAN_PQN &&
       go_hess_create(&s->hess, s->nlp, go_gait_elements(s->g), why, sizeof(why)) != 0) ||
      (p->hessian == GO_HESSIAN_EXACT &&
       go_hess_create_fd(&s->hess, s->nlp, go_gait_elements(s->g), why, sizeof(why)) != 0)) {
    snprintf(err, (size_t)errsz, "%s", why);
    return -1;
  }
  opts.hess = s->hess;
  if (p->settle_main_viol > 0) {
    opts.settle_iter = p->settle_iter;
    opts.settle_rel = p->settle_main_rel;
    opts.settle_viol = p->settle_main_viol;
  }
  if (p->handover_iter > 0 && p->refine_iter > 0 && p->hessian == GO_HESSIAN_LBFGS) {
    opts.handover_iter = p->handover_iter;
    opts.handover_viol = opts.best_viol_tol;
  }
  memcpy(s->z, p->z0, sizeof(double) * (size_t)s->n);
  go_nlp_set_jac_mode(s->nlp, p->main_jacobian);
  int main_rc = main_solve(s, &opts, rep, err, errsz);
  go_nlp_set_jac_mode(s->nlp, GO_JAC_SPARSE);
  if (main_rc != 0 || refine(s, &opts, rep, err, errsz) != 0) return -1;
  if (s->lam && f) print_largest_multipliers(f, s->g, s->lam, p->label);
  // the point chosen: Ipopt's when it converged, else the best iterate; then its polish
  rep->converged = solve_converged(&rep->result);
  // (a settled solve stopped where it was: its best iterate is the point)
  double* zout =
      (rep->converged && rep->result.status != GO_SOLVE_SETTLED) || rep->result.best_iter < 0
          ? s->z : s->zb;
  if (polish(s, &zout, rep, err, errsz) != 0) return -1;
  rep->best_iterate_written = zout == s->zb;
  memcpy(rep->z, zout, sizeof(double) * (size_t)s->n);
  // its objective, violation and largest defect
  rep->objective = objective_at(s->nlp, zout, s->zs);
  rep->max_violation =
      go_nlp_eval_g(s->nlp, s->zs, s->gv) == 0 ? go_nlp_violation(s->nlp, s->gv) : INFINITY;
  if (f) print_blocks(f, s->g, s->gv, p->label, "final");
  const go_gait_layout* L = go_gait_layout_get(s->g);
  rep->max_defect = 0;
  for (int r = 0; r < (go_gait_nodes(s->g) - 1) * L->nx; r++)
    rep->max_defect = fmax(rep->max_defect, fabs(s->gv[r]));
  return 0;
}

int go_solve_run(const go_solve_plan* p, go_solve_report* rep, char* err, int errsz) {
  go_clock own;
  go_clock_start(&own);
  memset(rep, 0, sizeof(*rep));
  rep->refined = -1;
  if (!p->gait || !p->z0) {
    snprintf(err, (size_t)errsz, "go_solve_run: no problem or no start point");
    return -1;
  }
  run_state s;
  memset(&s, 0, sizeof(s));
  s.p = p;
  s.g = p->gait;
  s.nlp = go_gait_nlp(s.g);
  go_nlp_sizes(s.nlp, &s.n, &s.mm, &s.ne);
  s.z = (double*)malloc(sizeof(double) * (size_t)s.n);
  s.zb = (double*)malloc(sizeof(double) * (size_t)s.n);
  s.zs = (double*)malloc(sizeof(double) * (size_t)s.n);
  s.gv = (double*)malloc(sizeof(double) * (size_t)s.mm);
  rep->z = (double*)malloc(sizeof(double) * (size_t)s.n);
  // the final constraint multipliers, for the diagnostic line (the largest per block); without
  // them the solve runs all the same
  s.lam = (double*)calloc((size_t)s.mm, sizeof(double));
  s.mult = (go_ipopt_mult){s.lam, NULL, NULL, 0};
  int rc = -1;
  if (!s.z || !s.zb || !s.zs || !s.gv || !rep->z)
    snprintf(err, (size_t)errsz, "go_solve_run: out of memory");
  else
    rc = run_stages(&s, rep, err, errsz);
  const go_clock* c = p->clock ? p->clock : &own;
  rep->wall_s = go_clock_wall_s(c);
  rep->cpu_s = go_clock_cpu_s(c);
  free(s.z), free(s.zb), free(s.zs), free(s.gv), free(s.lam);
  go_hess_free(s.hess);
  if (rc != 0) go_solve_report_free(rep);
  return rc;
}
