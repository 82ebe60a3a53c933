// go_ipopt.h: solve a collocation NLP (go_collocation.h) with Ipopt 3.11.9 through its C interface.
//
// Fixed settings (overridable by options): limited-memory Hessian (eval_h exists and returns
// FALSE), MUMPS, no banner (sb yes), print_level 0, no ./ipopt.opt (option_file_name ""), no
// Ipopt scaling (nlp_scaling_method none: the engine scales, go_collocation.h). OpenBLAS is set to
// one thread. One progress line per iteration goes to opts.progress.
//
// Best iterate: the C interface's intermediate callback does not expose x. Ipopt evaluates the
// constraint Jacobian only at iterates (never at line-search trial points), and always at the
// current iterate before that iterate's intermediate callback (it needs J for the dual
// infeasibility). So the engine copies x at every eval_jac_g and, at the callback, scores that
// point with the g and f cached from eval_g/eval_f when they were evaluated at the same x (else it
// evaluates them once more). Score: smaller max scaled constraint violation wins, except that
// among points with violation <= best_viol_tol (default 1e-3: points the feasibility polish
// projects onto the dynamics in a few iterations) the smaller objective wins, and such a point
// beats any more violated one; non-finite values never win. So a nearly feasible iterate that
// a later, slightly more violated one beats by a wide margin is not kept (a tracking solve on
// another trial kept objective 32.9 at its least violated iterate against 3.8 reached later at
// a violation of 6e-4). The final point Ipopt returns is scored as well. Limits: in the
// restoration phase the iterates are those of the restoration problem (their x part is scored,
// which is fine); a point whose Jacobian evaluation failed is never scored.
#ifndef GAITSIM_OPTIM_GO_IPOPT_H_
#define GAITSIM_OPTIM_GO_IPOPT_H_

#include <stdio.h>

#include "optim/go_collocation.h"

#define GO_IPOPT_MAX_OPTIONS 64
#define GO_IPOPT_MAX_SETTLE 64  // settle_iter at most

typedef struct {
  char key[64];    // Ipopt option name
  char val[192];   // its value as text (type chosen by go_ipopt_solve)
} go_ipopt_kv;

typedef struct {
  int max_iter;           // iteration limit; < 0: Ipopt default (3000)
  double max_wall_s;      // wall-clock limit (s); <= 0: none
  double tol;             // Ipopt tol; <= 0: Ipopt default (1e-8)
  double best_viol_tol;   // violations at or below count as polishable: among them the best
                          // iterate is the lowest objective (scaled max violation, -)
  FILE* progress;         // one line per iteration; NULL: silent
  int handle_sigint;      // 1: SIGINT, SIGTERM and SIGHUP stop the solve cleanly (handlers
                          // restored afterwards; see go_ipopt_install_stop_signals)
  double fallback_rise;   // > 0: stop (GO_SOLVE_FELL_BACK) at the first iteration outside the
                          // restoration phase whose objective exceeds, by more than this
                          // fraction of its size, the lowest objective of the earlier iterations
                          // with inf_pr <= fallback_viol (the solve had come near a solution and
                          // left it); 0: off
  double fallback_viol;   // the violation (scaled, max norm, Ipopt's inf_pr) below which an
                          // iteration counts as near a solution for fallback_rise
  int gauss_newton;       // 1: Ipopt's exact-Hessian mode with the Gauss-Newton Hessian
                          // (go_nlp_eval_hess_diag; the problem needs integrand_hess);
                          // 0: limited-memory quasi-Newton (L-BFGS)
  struct go_hess* hess;   // non-NULL: Ipopt's exact-Hessian mode with this partitioned
                          // quasi-Newton Hessian (go_hessian.h; takes precedence over
                          // gauss_newton); not owned
  int settle_iter;        // > 0: stop (GO_SOLVE_SETTLED) once settle_iter iterations outside the
                          // restoration phase with inf_pr <= settle_viol have come among the
                          // last 2 settle_iter, and their objectives span at most settle_rel of
                          // the lowest per iteration from the first of them to the last (Ipopt's
                          // acceptable test bounds each change, over consecutive iterations, which
                          // one violation spike resets); 0: off; at most GO_IPOPT_MAX_SETTLE
  double settle_rel;      // the settled rule's relative objective change per iteration (-)
  double settle_viol;     // violation (scaled, max norm, Ipopt's inf_pr) of the settled rule
  int handover_iter;      // > 0: stop (GO_SOLVE_HANDED_OVER) at the first iteration from this
                          // one on, outside the restoration phase, with inf_pr <=
                          // handover_viol: an L-BFGS solve that has a point the exact-Hessian
                          // refinement can start from (go_solve.h); 0: off
  double handover_viol;   // violation (scaled, max norm, Ipopt's inf_pr) of handover_iter
  int n_kv;               // extra Ipopt options, applied after all of the above, in order
  go_ipopt_kv kv[GO_IPOPT_MAX_OPTIONS];
} go_ipopt_opts;

typedef enum {
  GO_SOLVE_SUCCESS = 0,        // optimal to tol
  GO_SOLVE_ACCEPTABLE,         // optimal to the acceptable tolerances
  GO_SOLVE_FEASIBLE,           // feasible point found (square problems)
  GO_SOLVE_MAX_ITER,           // iteration limit
  GO_SOLVE_MAX_WALL_TIME,      // our wall-clock limit
  GO_SOLVE_MAX_CPU_TIME,       // Ipopt's max_cpu_time
  GO_SOLVE_INTERRUPTED,        // a stop signal (SIGINT, SIGTERM, SIGHUP) or go_ipopt_request_stop()
  GO_SOLVE_INFEASIBLE,         // locally infeasible
  GO_SOLVE_SMALL_STEP,         // search direction too small
  GO_SOLVE_DIVERGING,          // iterates diverging
  GO_SOLVE_RESTORATION_FAILED, // restoration phase failed
  GO_SOLVE_STEP_ERROR,         // error in step computation
  GO_SOLVE_EVAL_ERROR,         // invalid number in a function or derivative
  GO_SOLVE_BAD_PROBLEM,        // not enough degrees of freedom or invalid problem definition
  GO_SOLVE_BAD_OPTION,         // invalid option
  GO_SOLVE_FELL_BACK,          // stopped by fallback_rise: the objective rose far above the
                               // lowest one reached near feasibility
  GO_SOLVE_SETTLED,            // stopped by settle_iter: the objective settled near feasibility
                               // (the best iterate is the point to use)
  GO_SOLVE_HANDED_OVER,        // stopped by handover_iter: near feasibility after enough
                               // iterations, for the refinement to go on from
  GO_SOLVE_INTERNAL_ERROR,     // exceptions, memory, internal errors, user stop of unknown cause
} go_solve_status;

typedef struct {
  go_solve_status status;   // mapped from Ipopt's ApplicationReturnStatus
  int ipopt_status;         // the ApplicationReturnStatus itself
  int iterations;           // iterations done
  double wall_s;            // wall-clock time of the solve (s)
  double cpu_s;             // process CPU time of the solve, all threads (s)
  double objective;         // physical objective J at the returned point
  double max_viol;          // max scaled constraint violation at the returned point
  int best_iter;            // iteration of the best iterate (-1: none scored)
  double best_objective;    // physical objective at the best iterate
  double best_viol;         // max scaled constraint violation at the best iterate
  double last_inf_pr;       // Ipopt's primal infeasibility at its last iteration (scaled, max norm)
  double last_inf_du;       // Ipopt's dual infeasibility at its last iteration (scaled, max norm)
  double last_mu;           // Ipopt's barrier parameter at its last iteration (-)
  int last_restoration;     // 1: the last iteration was a restoration-phase iteration
  char eval_error[160];     // the solve's latest failed evaluation, "callback: why" ("": none);
                            // with GO_SOLVE_EVAL_ERROR the one that ended it
} go_solve_result;

// optional multipliers in the solver's scaling: in (when warm != 0) and out (when non-NULL)
typedef struct {
  double* g;     // constraint multipliers (m)
  double* z_l;   // lower bound multipliers (n)
  double* z_u;   // upper bound multipliers (n)
  int warm;      // 1: start from these (sets warm_start_init_point yes)
} go_ipopt_mult;

// defaults: max_iter -1, no wall limit, tol default, best_viol_tol 1e-3, progress NULL,
// handle_sigint 0, no extra options
void go_ipopt_opts_default(go_ipopt_opts* opts);

// add one option "key=value" (command line --ipopt key=value) or key, value; 0 or -1 and err
int go_ipopt_opts_add(go_ipopt_opts* opts, const char* key_eq_value, char* err, int errsz);
int go_ipopt_opts_set(go_ipopt_opts* opts, const char* key, const char* value, char* err, int errsz);

// add the options of a file: "key value" per line, '#' starts a comment; 0 or -1 and err
int go_ipopt_opts_read_file(go_ipopt_opts* opts, const char* path, char* err, int errsz);

// Solve. z (n, physical): in the initial guess, out the point Ipopt returns. z_best (n, physical,
// may be NULL): the best iterate (see above). mult may be NULL. Returns 0 when Ipopt ran (the
// outcome is res->status, whatever it is), -1 with err when the solve could not start.
int go_ipopt_solve(go_nlp* nlp, const go_ipopt_opts* opts, double* z, double* z_best,
                   go_ipopt_mult* mult, go_solve_result* res, char* err, int errsz);

// human-readable status
const char* go_solve_status_str(go_solve_status status);

// ask a running solve to stop at its next iteration (async-signal-safe)
void go_ipopt_request_stop(void);

// Stop signals for the rest of the process: SIGINT, SIGTERM and SIGHUP alike. The first one
// asks the running solve, or the next one to start if none runs, to stop at its next iteration
// (status GO_SOLVE_INTERRUPTED; later solves, e.g. a polish of the best iterate, run) and is
// passed on to the registered child processes. A second one calls hard_stop (may be NULL; it
// must be async-signal-safe, e.g. gs_folder_abort_from_signal), passes the signal on, and ends
// the process by that signal at once. A signal sent by the parent process counts separately
// from the others, so one Ctrl-C that reaches a process group and is also passed on by the
// parent counts once. Idempotent; returns 0, or -1 when sigaction fails.
int go_ipopt_install_stop_signals(void (*hard_stop)(void));

// The number of stop signals received so far (0: none).
int go_ipopt_stop_signals(void);

// Register (pid > 0) or drop a child process that stop signals are passed on to (at most 8).
void go_ipopt_forward_signals_to(long pid, int add);

// fork() a child that stop signals are passed on to: the signals are held back until the child
// is registered (none is lost between fork and registration), and the child starts with no
// registered processes (its siblings get their signals from the parent, not from it). Returns
// fork()'s value; the caller drops the child with go_ipopt_forward_signals_to(pid, 0) once it
// has been waited for.
long go_ipopt_fork_forwarded(void);

// The best-iterate ranking (above): 1 when the point (objective f, max scaled violation viol)
// beats the best one so far (best_f, best_viol), with tol the best_viol_tol of the solve.
int go_ipopt_point_better(double f, double viol, double best_f, double best_viol, double tol);

#endif  // GAITSIM_OPTIM_GO_IPOPT_H_
