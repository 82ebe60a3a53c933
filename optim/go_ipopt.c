// go_ipopt.c: Ipopt 3.11.9 C-interface glue for the collocation NLP (see go_ipopt.h).
#define _POSIX_C_SOURCE 200809L
#include "optim/go_ipopt.h"

#include <coin/IpStdCInterface.h>
#include <ctype.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "optim/go_hessian.h"
#include "optim/go_jacobian.h"

void openblas_set_num_threads(int num_threads);  // OpenBLAS (cblas.h), declared here alone

// set by go_ipopt_request_stop, cleared at the start of each solve (process-wide)
static volatile sig_atomic_t stop_requested = 0;
// set by a stop signal, cleared by the solve that stops for it (process-wide)
static volatile sig_atomic_t signal_pending = 0;
// stop signals received: from the parent process, and from anyone else
static volatile sig_atomic_t signals_from_parent = 0, signals_other = 0;
static void (*volatile hard_stop_fn)(void) = NULL;
static volatile sig_atomic_t stop_signals_installed = 0;
#define GO_MAX_CHILDREN 8
static volatile pid_t children[GO_MAX_CHILDREN];  // processes stop signals are passed on to

void go_ipopt_request_stop(void) { stop_requested = 1; }

int go_ipopt_stop_signals(void) {
  return (int)(signals_from_parent > signals_other ? signals_from_parent : signals_other);
}

void go_ipopt_forward_signals_to(long pid, int add) {
  for (int i = 0; i < GO_MAX_CHILDREN; i++) {
    if (add ? children[i] == 0 : children[i] == (pid_t)pid) {
      children[i] = add ? (pid_t)pid : 0;
      return;
    }
  }
}

// SIGINT, SIGTERM, SIGHUP: the first asks for a stop, the second ends the process at once
static void on_stop_signal(int sig, siginfo_t* info, void* ctx) {
  (void)ctx;
  int saved = errno;
  int from_parent = info && info->si_code == SI_USER && info->si_pid == getppid();
  int count = from_parent ? ++signals_from_parent : ++signals_other;
  for (int i = 0; i < GO_MAX_CHILDREN; i++)
    if (children[i] > 0) kill(children[i], sig);
  if (count >= 2) {
    if (hard_stop_fn) hard_stop_fn();
    struct sigaction dfl;
    memset(&dfl, 0, sizeof(dfl));
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, NULL);
    sigset_t unblock;
    sigemptyset(&unblock);
    sigaddset(&unblock, sig);
    sigprocmask(SIG_UNBLOCK, &unblock, NULL);
    raise(sig);
    _exit(128 + sig);
  }
  if (count == 1) {
    static const char msg[] = "gaitsim: stop signal: stopping at the next iteration and writing "
                              "the best iterate (a second signal stops at once, writing nothing)\n";
    ssize_t w = write(2, msg, sizeof(msg) - 1);
    (void)w;
  }
  signal_pending = 1;
  errno = saved;
}

static const int kStopSignals[3] = {SIGINT, SIGTERM, SIGHUP};

// install on_stop_signal for the three signals; old (may be NULL) gets the previous actions
static int install_handlers(struct sigaction old[3]) {
  struct sigaction sa;
  memset(&sa, 0, sizeof(sa));
  sa.sa_sigaction = on_stop_signal;
  sa.sa_flags = SA_SIGINFO;
  sigemptyset(&sa.sa_mask);
  for (int i = 0; i < 3; i++) sigaddset(&sa.sa_mask, kStopSignals[i]);
  for (int i = 0; i < 3; i++)
    if (sigaction(kStopSignals[i], &sa, old ? &old[i] : NULL) != 0) return -1;
  return 0;
}

long go_ipopt_fork_forwarded(void) {
  sigset_t stops, before;
  sigemptyset(&stops);
  for (int i = 0; i < 3; i++) sigaddset(&stops, kStopSignals[i]);
  sigprocmask(SIG_BLOCK, &stops, &before);  // held back until the child is registered
  pid_t pid = fork();
  if (pid == 0) {
    for (int i = 0; i < GO_MAX_CHILDREN; i++) children[i] = 0;  // siblings: the parent's
  } else if (pid > 0) {
    go_ipopt_forward_signals_to((long)pid, 1);
  }
  sigprocmask(SIG_SETMASK, &before, NULL);
  return (long)pid;
}

int go_ipopt_install_stop_signals(void (*hard_stop)(void)) {
  hard_stop_fn = hard_stop;
  if (stop_signals_installed) return 0;
  if (install_handlers(NULL) != 0) return -1;
  stop_signals_installed = 1;
  return 0;
}

// --- options ------------------------------------------------------------------------------------

void go_ipopt_opts_default(go_ipopt_opts* o) {
  memset(o, 0, sizeof(*o));
  o->max_iter = -1;
  o->best_viol_tol = 1e-3;
}

int go_ipopt_opts_set(go_ipopt_opts* o, const char* key, const char* val, char* err, int errsz) {
  if (!key[0] || strlen(key) >= sizeof(o->kv[0].key) || strlen(val) >= sizeof(o->kv[0].val)) {
    snprintf(err, (size_t)errsz, "ipopt option '%s': empty or too long", key);
    return -1;
  }
  if (o->n_kv >= GO_IPOPT_MAX_OPTIONS) {
    snprintf(err, (size_t)errsz, "ipopt option '%s': more than %d options", key, GO_IPOPT_MAX_OPTIONS);
    return -1;
  }
  strcpy(o->kv[o->n_kv].key, key);
  strcpy(o->kv[o->n_kv].val, val);
  o->n_kv++;
  return 0;
}

int go_ipopt_opts_add(go_ipopt_opts* o, const char* kv, char* err, int errsz) {
  const char* eq = strchr(kv, '=');
  char key[64];
  if (!eq || eq == kv || (size_t)(eq - kv) >= sizeof(key)) {
    snprintf(err, (size_t)errsz, "ipopt option '%s': expected key=value", kv);
    return -1;
  }
  memcpy(key, kv, (size_t)(eq - kv));
  key[eq - kv] = 0;
  return go_ipopt_opts_set(o, key, eq + 1, err, errsz);
}

int go_ipopt_opts_read_file(go_ipopt_opts* o, const char* path, char* err, int errsz) {
  FILE* f = fopen(path, "r");
  if (!f) {
    snprintf(err, (size_t)errsz, "ipopt options %s: %s", path, strerror(errno));
    return -1;
  }
  char line[512];
  int lineno = 0, rc = 0;
  while (!rc && fgets(line, sizeof(line), f)) {
    lineno++;
    char* hash = strchr(line, '#');
    if (hash) *hash = 0;
    char key[128], val[256], extra[8];
    int nf = sscanf(line, "%127s %255s %7s", key, val, extra);
    if (nf <= 0) continue;  // blank or comment
    if (nf != 2) {
      snprintf(err, (size_t)errsz, "ipopt options %s:%d: expected 'key value'", path, lineno);
      rc = -1;
    } else if (go_ipopt_opts_set(o, key, val, err, errsz)) {
      rc = -1;
    }
  }
  fclose(f);
  return rc;
}

// Ipopt 3.11.9 integer options: setting an option with the wrong type prints to stdout and
// fails, and the C interface cannot query types, so the type is decided here
static const char* const int_options[] = {
    "print_level", "file_print_level", "print_frequency_iter", "max_iter", "acceptable_iter",
    "max_soc", "limited_memory_max_history", "limited_memory_max_skipping",
    "watchdog_shortened_iter_trigger", "watchdog_trial_iter_max", "max_refinement_steps",
    "min_refinement_steps", "mumps_permuting_scaling", "mumps_pivot_order", "mumps_scaling",
    "mumps_mem_percent", "max_resto_iter", "accept_after_max_steps", "max_filter_resets",
    "filter_reset_trigger", "num_linear_variables", "quality_function_max_section_steps",
    "soc_method", "derivative_test_first_index", "max_soft_resto_iters"};

static int is_int_option(const char* key) {
  for (size_t i = 0; i < sizeof(int_options) / sizeof(int_options[0]); i++)
    if (!strcmp(key, int_options[i])) return 1;
  return 0;
}

// apply one option with the type Ipopt expects
static int apply_option(IpoptProblem p, const char* key, const char* val, char* err, int errsz) {
  char k[64], v[192];
  snprintf(k, sizeof(k), "%s", key);
  snprintf(v, sizeof(v), "%s", val);
  char* end = NULL;
  Bool ok;
  if (is_int_option(key)) {
    long iv = strtol(val, &end, 10);
    if (end == val || *end) {
      snprintf(err, (size_t)errsz, "ipopt option %s: '%s' is not an integer", key, val);
      return -1;
    }
    ok = AddIpoptIntOption(p, k, (Int)iv);
  } else {
    double dv = strtod(val, &end);
    if (end != val && !*end)
      ok = AddIpoptNumOption(p, k, dv);
    else
      ok = AddIpoptStrOption(p, k, v);
  }
  if (!ok) {
    snprintf(err, (size_t)errsz, "ipopt option %s=%s rejected by Ipopt", key, val);
    return -1;
  }
  return 0;
}

// --- solve state and callbacks ------------------------------------------------------------------

typedef struct {
  go_nlp* nlp;
  const go_ipopt_opts* opts;
  int n, m;
  double* xj;       // x of the latest eval_jac_g (n)
  int have_xj;
  double* xg;       // x of the latest successful eval_g (n)
  double* gval;     // its g (m)
  int have_g;
  double* xf;       // x of the latest successful eval_f (n)
  double fval;      // its f (scaled)
  int have_f;
  double* gtmp;     // scratch g (m)
  double* best;     // best scaled iterate (n)
  int best_iter;
  double best_f, best_viol;  // scaled objective, violation
  int iterations;
  double last_inf_pr, last_inf_du, last_mu;  // as Ipopt reports them at the latest iteration
  int last_alg_mod;                          // 1: restoration phase
  double low_obj;   // lowest physical objective of iterations with inf_pr <= fallback_viol
  int have_low_obj;
  int stop_reason;  // 0 none, 1 interrupted, 2 wall time, 3 fell back (fallback_rise),
                    // 4 settled (settle_iter), 5 handed over (handover_iter)
  int settle_it[GO_IPOPT_MAX_SETTLE];    // the latest iterations near feasibility, newest last
  double settle_J[GO_IPOPT_MAX_SETTLE];  // their physical objectives
  int settle_n;                          // entries used (at most settle_iter)
  char eval_error[160];  // the latest failed evaluation: which callback, and go_nlp_last_error
  struct timespec t0;
} solve_state;

// note a failed evaluation of callback what, for reason why (Ipopt sees FALSE: a failed
// derivative ends the solve with Invalid_Number_Detected, a failed function value only shortens
// the step)
static void note_eval_error(solve_state* s, const char* what, const char* why) {
  snprintf(s->eval_error, sizeof(s->eval_error), "%s: %s", what, why);
}

// the Hessians set no reason of their own
static const char kHessianFailed[] = "failed or non-finite";

static double elapsed(const struct timespec* t0) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)(t.tv_sec - t0->tv_sec) + 1e-9 * (double)(t.tv_nsec - t0->tv_nsec);
}

static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static Bool cb_f(Index n, Number* x, Bool new_x, Number* f, UserDataPtr u) {
  solve_state* s = u;
  if (go_nlp_eval_f(s->nlp, x, f)) {
    note_eval_error(s, "objective", go_nlp_last_error(s->nlp));
    return FALSE;
  }
  memcpy(s->xf, x, sizeof(double) * (size_t)n);
  s->fval = *f;
  s->have_f = 1;
  return TRUE;
}

static Bool cb_grad_f(Index n, Number* x, Bool new_x, Number* grad, UserDataPtr u) {
  solve_state* s = u;
  if (go_nlp_eval_grad_f(s->nlp, x, grad)) {
    note_eval_error(s, "objective gradient", go_nlp_last_error(s->nlp));
    return FALSE;
  }
  return TRUE;
}

static Bool cb_g(Index n, Number* x, Bool new_x, Index m, Number* g, UserDataPtr u) {
  solve_state* s = u;
  if (go_nlp_eval_g(s->nlp, x, g)) {
    note_eval_error(s, "constraints", go_nlp_last_error(s->nlp));
    s->have_g = 0;
    return FALSE;
  }
  memcpy(s->xg, x, sizeof(double) * (size_t)n);
  memcpy(s->gval, g, sizeof(double) * (size_t)m);
  s->have_g = 1;
  return TRUE;
}

static Bool cb_jac(Index n, Number* x, Bool new_x, Index m, Index nele, Index* irow, Index* jcol,
                   Number* vals, UserDataPtr u) {
  solve_state* s = u;
  if (!vals) {
    go_nlp_jac_structure(s->nlp, irow, jcol);
    return TRUE;
  }
  if (go_nlp_eval_jac(s->nlp, x, vals)) {
    note_eval_error(s, "constraint Jacobian", go_nlp_last_error(s->nlp));
    return FALSE;
  }
  if (s->opts->hess) go_hess_note_jacobian(s->opts->hess, x, vals);
  // the Jacobian is evaluated at iterates only: remember the point for the best iterate
  memcpy(s->xj, x, sizeof(double) * (size_t)n);
  s->have_xj = 1;
  return TRUE;
}

// Hessian of the Lagrangian: the Gauss-Newton diagonal (go_nlp_eval_hess_diag) when asked for;
// with the limited-memory Hessian Ipopt never calls it (it must exist in 3.11.9)
static Bool cb_h(Index n, Number* x, Bool new_x, Number obj_factor, Index m, Number* lambda,
                 Bool new_lambda, Index nele_hess, Index* irow, Index* jcol, Number* vals,
                 UserDataPtr u) {
  solve_state* s = u;
  if (s->opts->hess) {
    if (!vals) {
      go_hess_structure(s->opts->hess, irow, jcol);
      return TRUE;
    }
    if (go_hess_values(s->opts->hess, x, obj_factor, lambda, vals) == 0) return TRUE;
    note_eval_error(s, "Hessian", kHessianFailed);
    return FALSE;
  }
  if (!s->opts->gauss_newton) return FALSE;
  if (!vals) {
    for (Index i = 0; i < n; i++) irow[i] = jcol[i] = i;
    return TRUE;
  }
  if (go_nlp_eval_hess_diag(s->nlp, x, obj_factor, vals) == 0) return TRUE;
  note_eval_error(s, "Gauss-Newton Hessian", kHessianFailed);
  return FALSE;
}

// does (f, viol) beat the best so far?
int go_ipopt_point_better(double f, double viol, double best_f, double best_viol, double tol) {
  if (!isfinite(f) || !isfinite(viol)) return 0;
  if (viol <= tol && best_viol <= tol) return f < best_f;
  if (viol != best_viol) return viol < best_viol;
  return f < best_f;
}

static int better(const solve_state* s, double f, double viol) {
  if (s->best_iter < 0) return isfinite(f) && isfinite(viol);
  return go_ipopt_point_better(f, viol, s->best_f, s->best_viol, s->opts->best_viol_tol);
}

// score the scaled point x (n) as iterate iter; uses cached g/f when they belong to x
static void score(solve_state* s, const double* x, int iter) {
  size_t nb = sizeof(double) * (size_t)s->n;
  const double* g = NULL;
  double f;
  if (s->have_g && !memcmp(s->xg, x, nb)) {
    g = s->gval;
  } else if (!go_nlp_eval_g(s->nlp, x, s->gtmp)) {
    g = s->gtmp;
  }
  if (!g) return;
  if (s->have_f && !memcmp(s->xf, x, nb)) {
    f = s->fval;
  } else if (go_nlp_eval_f(s->nlp, x, &f)) {
    return;
  }
  double viol = s->m > 0 ? go_nlp_violation(s->nlp, g) : 0.0;
  if (better(s, f, viol)) {
    memcpy(s->best, x, nb);
    s->best_iter = iter;
    s->best_f = f;
    s->best_viol = viol;
  }
}

// the settled rule (go_ipopt_opts.settle_iter): note iteration iter of physical objective J
// when inf_pr <= settle_viol, and say whether settle_iter such iterations lie among the last
// 2 settle_iter with objectives spanning at most settle_rel of the lowest per iteration between
// the first and the last of them (Ipopt's acceptable_obj_change_tol bounds each iteration's
// change; this bounds their mean)
static int settled(solve_state* s, int iter, double J, double inf_pr) {
  const go_ipopt_opts* o = s->opts;
  int k = o->settle_iter < GO_IPOPT_MAX_SETTLE ? o->settle_iter : GO_IPOPT_MAX_SETTLE;
  if (k <= 0 || !isfinite(J) || !(inf_pr <= o->settle_viol)) return 0;
  if (s->settle_n == k) {  // keep the newest k: drop the oldest
    memmove(s->settle_it, s->settle_it + 1, sizeof(int) * (size_t)(k - 1));
    memmove(s->settle_J, s->settle_J + 1, sizeof(double) * (size_t)(k - 1));
    s->settle_n--;
  }
  s->settle_it[s->settle_n] = iter;
  s->settle_J[s->settle_n] = J;
  s->settle_n++;
  if (s->settle_n < k || iter - s->settle_it[0] >= 2 * k) return 0;
  double lo = J, hi = J;
  for (int i = 0; i < k; i++) {
    lo = fmin(lo, s->settle_J[i]);
    hi = fmax(hi, s->settle_J[i]);
  }
  return hi - lo <= o->settle_rel * fabs(lo) * (double)(iter - s->settle_it[0]);
}

static Bool cb_iter(Index alg_mod, Index iter, Number obj, Number inf_pr, Number inf_du, Number mu,
                    Number d_norm, Number reg, Number alpha_du, Number alpha_pr, Index ls,
                    UserDataPtr u) {
  solve_state* s = u;
  s->iterations = iter;
  s->last_inf_pr = inf_pr;
  s->last_inf_du = inf_du;
  s->last_mu = mu;
  s->last_alg_mod = (int)alg_mod;
  if (s->have_xj) score(s, s->xj, iter);
  double t = elapsed(&s->t0);
  if (s->opts->progress) {
    fprintf(s->opts->progress,
            "iter %4d%s  obj % .8e  inf_pr %.3e  inf_du %.3e  lg(mu) %5.1f  alpha_pr %.2e  "
            "wall %8.2f s\n",
            (int)iter, alg_mod ? "r" : " ", go_nlp_objective_phys(s->nlp, obj), inf_pr, inf_du,
            mu > 0 ? log10(mu) : -99.0, alpha_pr, t);
    fflush(s->opts->progress);
  }
  if (stop_requested || signal_pending) {
    signal_pending = 0;
    s->stop_reason = 1;
    return FALSE;
  }
  if (s->opts->max_wall_s > 0 && t >= s->opts->max_wall_s) {
    s->stop_reason = 2;
    return FALSE;
  }
  if (!alg_mod && settled(s, (int)iter, go_nlp_objective_phys(s->nlp, obj), inf_pr)) {
    if (s->opts->progress)
      fprintf(s->opts->progress, "settled: %d iterations at inf_pr <= %.0e within the last %d, "
              "objectives within %.0e relative per iteration; stopping\n", s->opts->settle_iter,
              s->opts->settle_viol, 2 * s->opts->settle_iter, s->opts->settle_rel);
    s->stop_reason = 4;
    return FALSE;
  }
  if (s->opts->handover_iter > 0 && iter >= s->opts->handover_iter && !alg_mod &&
      inf_pr <= s->opts->handover_viol) {
    if (s->opts->progress)
      fprintf(s->opts->progress, "handed over: iteration %d (from %d on) at inf_pr <= %.0e; "
              "stopping for the refinement\n", (int)iter, s->opts->handover_iter,
              s->opts->handover_viol);
    s->stop_reason = 5;
    return FALSE;
  }
  if (s->opts->fallback_rise > 0 && !alg_mod && isfinite(obj)) {
    double J = go_nlp_objective_phys(s->nlp, obj);
    if (s->have_low_obj && J > s->low_obj + s->opts->fallback_rise * fabs(s->low_obj)) {
      if (s->opts->progress)
        fprintf(s->opts->progress, "fell back: objective %.6g, %.0f %% above the %.6g reached at "
                "a violation <= %.0e; stopping\n", J, 100.0 * (J / s->low_obj - 1.0), s->low_obj,
                s->opts->fallback_viol);
      s->stop_reason = 3;
      return FALSE;
    }
    if (inf_pr <= s->opts->fallback_viol && (!s->have_low_obj || J < s->low_obj)) {
      s->low_obj = J;
      s->have_low_obj = 1;
    }
  }
  return TRUE;
}

static go_solve_status map_status(int st, int stop_reason) {
  switch (st) {
    case Solve_Succeeded: return GO_SOLVE_SUCCESS;
    case Solved_To_Acceptable_Level: return GO_SOLVE_ACCEPTABLE;
    case Feasible_Point_Found: return GO_SOLVE_FEASIBLE;
    case Infeasible_Problem_Detected: return GO_SOLVE_INFEASIBLE;
    case Search_Direction_Becomes_Too_Small: return GO_SOLVE_SMALL_STEP;
    case Diverging_Iterates: return GO_SOLVE_DIVERGING;
    case User_Requested_Stop:
      return stop_reason == 1 ? GO_SOLVE_INTERRUPTED
             : stop_reason == 2 ? GO_SOLVE_MAX_WALL_TIME
             : stop_reason == 3 ? GO_SOLVE_FELL_BACK
             : stop_reason == 4 ? GO_SOLVE_SETTLED
             : stop_reason == 5 ? GO_SOLVE_HANDED_OVER : GO_SOLVE_INTERNAL_ERROR;
    case Maximum_Iterations_Exceeded: return GO_SOLVE_MAX_ITER;
    case Maximum_CpuTime_Exceeded: return GO_SOLVE_MAX_CPU_TIME;
    case Restoration_Failed: return GO_SOLVE_RESTORATION_FAILED;
    case Error_In_Step_Computation: return GO_SOLVE_STEP_ERROR;
    case Invalid_Number_Detected: return GO_SOLVE_EVAL_ERROR;
    case Not_Enough_Degrees_Of_Freedom:
    case Invalid_Problem_Definition: return GO_SOLVE_BAD_PROBLEM;
    case Invalid_Option: return GO_SOLVE_BAD_OPTION;
    default: return GO_SOLVE_INTERNAL_ERROR;
  }
}

const char* go_solve_status_str(go_solve_status st) {
  switch (st) {
    case GO_SOLVE_SUCCESS: return "optimal solution found";
    case GO_SOLVE_ACCEPTABLE: return "solved to acceptable level";
    case GO_SOLVE_FEASIBLE: return "feasible point found";
    case GO_SOLVE_MAX_ITER: return "iteration limit reached";
    case GO_SOLVE_MAX_WALL_TIME: return "wall-time limit reached";
    case GO_SOLVE_MAX_CPU_TIME: return "CPU-time limit reached";
    case GO_SOLVE_INTERRUPTED: return "interrupted";
    case GO_SOLVE_INFEASIBLE: return "converged to a locally infeasible point";
    case GO_SOLVE_SMALL_STEP: return "search direction became too small";
    case GO_SOLVE_DIVERGING: return "iterates diverging";
    case GO_SOLVE_RESTORATION_FAILED: return "restoration phase failed";
    case GO_SOLVE_STEP_ERROR: return "error in step computation";
    case GO_SOLVE_EVAL_ERROR: return "invalid number in function or derivative evaluation";
    case GO_SOLVE_BAD_PROBLEM: return "invalid problem definition";
    case GO_SOLVE_BAD_OPTION: return "invalid option";
    case GO_SOLVE_FELL_BACK: return "fell back from the solution it had reached";
    case GO_SOLVE_SETTLED: return "objective settled";
    case GO_SOLVE_HANDED_OVER: return "handed over to the refinement";
    case GO_SOLVE_INTERNAL_ERROR: return "internal error";
  }
  return "unknown status";
}

// --- the heap during a solve ---------------------------------------------------------------------

// MUMPS allocates its factorisation workspace anew at every factorisation (at 80 nodes about
// 1.3 GB of address space with Ipopt's mumps_mem_percent of 1000, of which a part is touched),
// and glibc serves a block that large by mmap and returns it by munmap. Each iteration then pays
// the kernel's zeroing of every page MUMPS touches: at 80 nodes a quarter of a prediction's
// iteration went to page faults and the first touches of the fronts' memset (docs/BENCHMARKS.md,
// "Lever kept: the heap kept during a solve"). During the solve glibc serves every block from
// its heap and keeps freed memory there, so the pages stay mapped from one factorisation to the
// next; afterwards the defaults return and the heap is trimmed. Only where and when the memory
// lives changes, not a value: the iterates are bitwise the same.
static void heap_keep_during_solve(int keep) {
#ifdef __GLIBC__
  if (keep) {
    mallopt(M_MMAP_MAX, 0);
    mallopt(M_TRIM_THRESHOLD, -1);  // never trim (mallopt(3)); a finite threshold below the
                                    // workspace's size still returns it at every free
  } else {
    mallopt(M_MMAP_MAX, 65536);             // glibc's default
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);  // glibc's default
    malloc_trim(0);
  }
#else
  (void)keep;
#endif
}

// --- solve --------------------------------------------------------------------------------------

int go_ipopt_solve(go_nlp* nlp, const go_ipopt_opts* opts, double* z, double* z_best,
                   go_ipopt_mult* mult, go_solve_result* res, char* err, int errsz) {
  int n, m, nele;
  go_nlp_sizes(nlp, &n, &m, &nele);
  memset(res, 0, sizeof(*res));
  res->best_iter = -1;

  // one allocation: bounds, scaled x, cached points
  size_t nd = (size_t)4 * (size_t)m + (size_t)7 * (size_t)n + 8;  // xl xu xj xg xf best x, gl gu gval gtmp
  double* buf = malloc(sizeof(double) * nd);
  if (!buf) {
    snprintf(err, (size_t)errsz, "ipopt: out of memory");
    return -1;
  }
  double* xl = buf;
  double* xu = xl + n;
  double* gl = xu + n;
  double* gu = gl + m;
  solve_state s;
  memset(&s, 0, sizeof(s));
  s.last_inf_pr = s.last_inf_du = s.last_mu = NAN;  // until the first iteration is reported
  s.nlp = nlp;
  s.opts = opts;
  s.n = n;
  s.m = m;
  s.xj = gu + m;
  s.xg = s.xj + n;
  s.xf = s.xg + n;
  s.best = s.xf + n;
  s.gval = s.best + n;
  s.gtmp = s.gval + m;
  double* x = s.gtmp + m;
  s.best_iter = -1;
  go_nlp_bounds(nlp, xl, xu, gl, gu);
  go_nlp_scale_z(nlp, z, x);

  if (opts->gauss_newton && !go_nlp_has_hess_diag(nlp)) {
    free(buf);
    snprintf(err, (size_t)errsz, "ipopt: Gauss-Newton Hessian asked for, but the problem has none");
    return -1;
  }
  int nele_hess = opts->hess ? go_hess_nnz(opts->hess) : opts->gauss_newton ? n : 0;
  IpoptProblem p = CreateIpoptProblem(n, xl, xu, m, gl, gu, nele, nele_hess, 0, cb_f, cb_g, cb_grad_f,
                                      cb_jac, cb_h);
  if (!p) {
    free(buf);
    snprintf(err, (size_t)errsz, "ipopt: CreateIpoptProblem failed (n=%d m=%d nele=%d)", n, m, nele);
    return -1;
  }

  // defaults first, then the caller's options in order
  char e2[256];
  int rc = 0;
  const char* fixed[][2] = {{"sb", "yes"},
                            {"print_level", "0"},
                            {"option_file_name", ""},
                            {"hessian_approximation",
                             opts->gauss_newton || opts->hess ? "exact" : "limited-memory"},
                            {"linear_solver", "mumps"},
                            // METIS ordering: 0.84 s instead of 5.7 s per iteration for the
                            // tracking problem at N = 80 (MUMPS' automatic choice;
                            // docs/BENCHMARKS.md)
                            {"mumps_pivot_order", "5"},
                            {"nlp_scaling_method", "none"}};
  for (size_t i = 0; i < sizeof(fixed) / sizeof(fixed[0]) && !rc; i++)
    rc = apply_option(p, fixed[i][0], fixed[i][1], e2, (int)sizeof(e2));
  if (!rc && opts->max_iter >= 0) rc = !AddIpoptIntOption(p, "max_iter", opts->max_iter);
  if (!rc && opts->tol > 0) rc = !AddIpoptNumOption(p, "tol", opts->tol);
  if (!rc && mult && mult->warm) rc = !AddIpoptStrOption(p, "warm_start_init_point", "yes");
  if (rc) snprintf(e2, sizeof(e2), "ipopt: setting the fixed options failed");
  for (int i = 0; i < opts->n_kv && !rc; i++) {
    if (!strcmp(opts->kv[i].key, "linear_solver") && !strcmp(opts->kv[i].val, "ma97")) {
      snprintf(e2, sizeof(e2), "ipopt: linear_solver ma97 exits the process in 3.11.9; refused");
      rc = -1;
      break;
    }
    rc = apply_option(p, opts->kv[i].key, opts->kv[i].val, e2, (int)sizeof(e2));
  }
  if (rc) {
    FreeIpoptProblem(p);
    free(buf);
    snprintf(err, (size_t)errsz, "%s", e2);
    return -1;
  }
  SetIntermediateCallback(p, cb_iter);
  openblas_set_num_threads(1);
  // Debian's MUMPS orders the KKT matrix with SCOTCH 7 (orderings 3 and 5: it links no METIS),
  // whose threaded graph algorithms give a different ordering, and so different pivots and
  // iterates in the 9th digit, from run to run. One SCOTCH thread makes the ordering, and the
  // whole solve, bitwise repeatable (docs/BENCHMARKS.md, "Reproducible runs"); SCOTCH reads the
  // variable at each ordering, and an explicit setting in the environment is left alone.
  setenv("SCOTCH_PTHREAD_NUMBER", "1", 0);

  // stop signals, for this solve unless installed for the process
  struct sigaction old_sa[3];
  int own_handlers = opts->handle_sigint && !stop_signals_installed;
  if (own_handlers) install_handlers(old_sa);
  stop_requested = 0;

  double cpu0 = cpu_now();
  clock_gettime(CLOCK_MONOTONIC, &s.t0);
  double fobj = 0.0;
  heap_keep_during_solve(1);
  int st = IpoptSolve(p, x, NULL, &fobj, mult ? mult->g : NULL, mult ? mult->z_l : NULL,
                      mult ? mult->z_u : NULL, &s);
  if (own_handlers)
    for (int i = 0; i < 3; i++) sigaction(kStopSignals[i], &old_sa[i], NULL);
  FreeIpoptProblem(p);
  heap_keep_during_solve(0);
  res->wall_s = elapsed(&s.t0);
  res->cpu_s = cpu_now() - cpu0;

  // the returned point: objective, violation, and a candidate for the best iterate
  res->ipopt_status = st;
  res->status = map_status(st, s.stop_reason);
  res->iterations = s.iterations;
  res->last_inf_pr = s.last_inf_pr;
  res->last_inf_du = s.last_inf_du;
  res->last_mu = s.last_mu;
  res->last_restoration = s.last_alg_mod != 0;
  snprintf(res->eval_error, sizeof(res->eval_error), "%s", s.eval_error);
  double f = NAN, viol = INFINITY;
  if (!go_nlp_eval_g(nlp, x, s.gtmp)) viol = m > 0 ? go_nlp_violation(nlp, s.gtmp) : 0.0;
  if (go_nlp_eval_f(nlp, x, &f)) f = NAN;
  res->objective = go_nlp_objective_phys(nlp, f);
  res->max_viol = viol;
  if (better(&s, f, viol)) {
    memcpy(s.best, x, sizeof(double) * (size_t)n);
    s.best_iter = s.iterations;
    s.best_f = f;
    s.best_viol = viol;
  }
  res->best_iter = s.best_iter;
  res->best_objective = s.best_iter >= 0 ? go_nlp_objective_phys(nlp, s.best_f) : NAN;
  res->best_viol = s.best_iter >= 0 ? s.best_viol : INFINITY;
  go_nlp_unscale_z(nlp, x, z);
  if (z_best) go_nlp_unscale_z(nlp, s.best_iter >= 0 ? s.best : x, z_best);
  free(buf);
  return 0;
}
