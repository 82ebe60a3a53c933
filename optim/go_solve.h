// go_solve.h: the solve strategy of a gait problem (go_gait.h), one entry point: go_solve_run
// takes a solve plan and returns a report. The stages, in order:
//   1. main solve: Ipopt (go_ipopt.h) from the start point with the plan's options (the stopping
//      rule of go_solve_plan_default and the caller's extra options) and Hessian;
//   2. restarts: after a fall-back (GO_SOLVE_FELL_BACK: Ipopt came near a solution, violation
//      <= fallback_viol, and left it), again from the best iterate with the iterations and time
//      left, a small barrier and the point barely pushed off its bounds; at most max_restarts;
//   3. refinement: an L-BFGS or Gauss-Newton main solve that stopped short (not converged, not
//      interrupted; with handover_iter, at its first nearly feasible iterate from that iteration
//      on) is
//      followed, from its best iterate, by refine_gn_iter Gauss-Newton iterations (the goals'
//      Hessian, positive semi-definite) and, from where they stop, up to refine_iter Newton
//      iterations with the exact Hessian (structured finite differences, go_hess_create_fd),
//      stopped by Ipopt's tests or the settled rule (settle_iter, settle_rel, settle_viol:
//      GO_SOLVE_SETTLED); their result replaces the main solve's when they converge (Ipopt's
//      optimal or acceptable level, or settled), and so does their best iterate when it beats
//      the main solve's one (go_ipopt_point_better); else the main solve's best iterate stays;
//   4. the point chosen: Ipopt's when it converged by its own tests (or no iterate was scored),
//      else (stopped short, or settled) the best iterate;
//   5. feasibility polish: when that point is violated by more than 1e-8, the dynamically
//      consistent point nearest to it (go_gait_set_proximal, Gauss-Newton Hessian), used when
//      its violation is lower and, from a nearly feasible point, its objective at most
//      GO_POLISH_MAX_RISE above the point's (go_solve_polish_usable).
// Progress (one line per Ipopt iteration, one per stage, the largest violation and multiplier
// per constraint block) goes to plan.progress, each stage line prefixed with plan.label.
// A further stage in front of the main solve adds its settings to go_solve_plan and its figures
// to go_solve_report, as the stages above do. Mesh continuation (e.g. 20 -> 40 -> 80 nodes) would
// add the node counts of the coarser levels and what builds a problem at another node count (the
// model and the go_gait_opts behind gait), solve each level with the stages below, and carry its
// point onto the next mesh (go_refine_trapezoid) as that level's start, the last one onto gait's
// mesh in place of z0; the report would gain one entry per level.
#ifndef GAITSIM_OPTIM_GO_SOLVE_H_
#define GAITSIM_OPTIM_GO_SOLVE_H_

#include <stdio.h>
#include <time.h>

#include "optim/go_defaults.h"
#include "optim/go_gait.h"
#include "optim/go_ipopt.h"

// the Hessian of the main solve
typedef enum {
  GO_HESSIAN_LBFGS = 0,     // Ipopt's limited-memory quasi-Newton (refined when it stops short)
  GO_HESSIAN_PQN,           // partitioned quasi-Newton, SR1 per node element (go_hess_create)
  GO_HESSIAN_EXACT,         // structured finite differences (go_hess_create_fd)
  GO_HESSIAN_GAUSS_NEWTON,  // exact for the tracking squares, constraints left out (refined
                            // when it stops short, as L-BFGS)
} go_hessian_kind;

// a start on both clocks (go_clock_start)
typedef struct {
  struct timespec wall;  // CLOCK_MONOTONIC at the start
  struct timespec cpu;   // CLOCK_PROCESS_CPUTIME_ID at the start (all threads)
} go_clock;

void go_clock_start(go_clock* c);
double go_clock_wall_s(const go_clock* c);  // wall-clock seconds since c's start (s)
double go_clock_cpu_s(const go_clock* c);   // process CPU seconds since c's start (s)

// What to solve and how; go_solve_plan_default fills every setting, the caller sets gait and z0.
typedef struct {
  go_gait* gait;              // the problem (not owned; its proximal goal is set and cleared
                              // by the polish)
  const double* z0;           // start point (n, physical: go_nlp_sizes of go_gait_nlp(gait))
  go_ipopt_opts ipopt;        // options of the main solve and its restarts: the stopping rule,
                              // the fall-back guard, the caller's extra options (applied in
                              // order); max_iter, max_wall_s, progress, handle_sigint and hess
                              // are set from the fields below
  go_hessian_kind hessian;    // Hessian of the main solve
  go_jac_mode main_jacobian;  // how the main solve and its restarts differentiate the path rows
                              // (GO_JAC_SPARSE: central, GO_JAC_SPARSE_FORWARD: forward
                              // differences); the refinement and the polish use central ones
  double gn_mu_init;          // a Gauss-Newton main solve's initial barrier parameter (Ipopt's
                              // mu_init, -), placed before the caller's options so that theirs
                              // wins; <= 0: Ipopt's default (0.1)
  double min_hess_perturbation;  // the smallest Hessian regularisation of Ipopt's inertia
                              // correction (min_hessian_perturbation, -) in every solve with a
                              // Gauss-Newton or exact Hessian (the main solve, the
                              // refinement's phases; not the polish), placed before the
                              // caller's options; <= 0: Ipopt's default (1e-20)
  int max_iter;               // Ipopt iterations of the main solve and its restarts together
                              // (-); < 0: Ipopt's default
  double max_wall_s;          // wall-clock limit (s); <= 0: none. The main solve and its
                              // restarts share it, the refinement gets what they left (at most
                              // refine_wall_s), the polish gets it whole
  int max_restarts;           // restarts after a fall-back, at most (-; GO_MAX_RESTARTS at
                              // most, the size of go_solve_report.restarts)
  int refine_iter;            // refinement's Newton iterations at most (-); 0: no refinement
  int handover_iter;          // > 0 with a refinement after an L-BFGS main solve: that solve
                              // hands over to the refinement at its first iterate from this
                              // iteration on at a violation the polish takes (ipopt.best_viol_tol;
                              // go_ipopt_opts.handover_iter), max_iter staying its cap; 0: off
  double refine_wall_s;       // refinement's wall-clock cap (s; <= 0: none), or less when
                              // max_wall_s says
  int refine_gn_iter;         // Gauss-Newton iterations before the refinement's Newton ones (-);
                              // 0: none
  int settle_iter;            // the refinement's settled rule (go_ipopt_opts.settle_iter, -)
  double settle_rel;          // its relative objective change per iteration (-)
  double settle_viol;         // its violation (scaled, max norm, -)
  double settle_main_viol;    // > 0: the main solve and its restarts stop by the settled rule
                              // too (settle_iter of the last 2 settle_iter iterations) at this
                              // violation (scaled, max norm, -); 0: by Ipopt's tests alone
  double settle_main_rel;     // that rule's relative objective change per iteration (-)
  int polish;                 // 1: feasibility polish of the point chosen
  int polish_iter;            // polish iterations at most (-)
  double stop_polish_wall_s;  // polish's wall-clock cap after a stop signal (s)
  FILE* progress;             // progress lines; NULL: silent
  const char* label;          // prefix of the stage lines, e.g. "track"
  const go_clock* clock;      // report wall_s and cpu_s count from here (e.g. the command's
                              // start); NULL: from go_solve_run's start
} go_solve_plan;

// one restart after a fall-back (summary.json "restarts")
typedef struct {
  int after_iterations;   // iterations done when the solve fell back (-)
  int from_iteration;     // the best iterate it restarted from (-)
  double objective;       // physical objective J there (-)
  double violation;       // max scaled constraint violation there (-)
} go_solve_restart;

// What the solve did and the point it chose; go_solve_report_free frees z.
typedef struct {
  go_solve_result result;     // the solves behind the point chosen (before the polish):
                              // status, iterations and wall time summed over the main solve,
                              // its restarts and a refinement used; last-iteration measures of
                              // the last of them
  int converged;              // 1: result reached Ipopt's optimal or acceptable level
  int n_restarts;             // restarts done (-)
  go_solve_restart restarts[GO_MAX_RESTARTS];  // in order (n_restarts)
  int refined;                // -1: no refinement run, 0: run and not used, 1: used
  go_solve_result refine;     // the refinement (refined >= 0): its Newton solve, iterations
                              // and times including its Gauss-Newton phase
  int refine_gn_run;          // 1: the refinement's Gauss-Newton phase ran
  go_solve_result refine_gn;  // that phase (refine_gn_run)
  int polish_run;             // 1: the polish ran
  int polished;               // 1: its point is the one chosen
  go_solve_result polish;     // the polish solve (polish_run)
  double polish_viol_before;  // max scaled violation of the point polished (-)
  double polish_obj_before;   // physical objective J of the point polished (-)
  double polish_obj_after;    // physical objective J of the polish's point (-; NAN: not
                              // evaluated, the polish being no less violated)
  int best_iterate_written;   // 1: z is a best iterate or its polish, not Ipopt's final point
  double* z;                  // the point chosen (n, physical; owned)
  double initial_violation;   // max scaled violation at z0 (-)
  double objective;           // physical objective J at z (-)
  double max_violation;       // max scaled constraint violation at z (-)
  double max_defect;          // largest |scaled defect| at z (-)
  double wall_s;              // wall clock from plan.clock to the end of go_solve_run (s)
  double cpu_s;               // process CPU time over the same span (s)
} go_solve_report;

// The project's defaults (go_defaults.h): L-BFGS, the stopping rule (Ipopt's optimality at tol
// 1e-4, or its acceptable level: violation <= 1e-4 and the objective settled to 1e-4 relative
// over 15 iterations), the fall-back guard, GO_MAX_RESTARTS, the refinement and the polish on,
// no limits, no progress; gait and z0 NULL.
void go_solve_plan_default(go_solve_plan* plan);

// The main solve (and its restarts) also stops by the settled rule at violation viol (scaled,
// max norm, -) and relative objective change rel per iteration (-), and Ipopt's acceptable
// level asks the same change (acceptable_obj_change_tol rel; extra options the caller adds
// later still override it). gaitsim predict: GO_PREDICT_SETTLE_VIOL, GO_PREDICT_SETTLE_REL.
void go_solve_plan_settle_main(go_solve_plan* plan, double viol, double rel);

// 1 when the feasibility polish's point (violation viol_after, objective obj_after) replaces
// the point polished (viol_before, obj_before): less violated, and, where viol_before <=
// GO_POLISH_GUARD_VIOL, its objective J at most GO_POLISH_MAX_RISE (relative) above (a NaN
// objective fails that test); 0 otherwise.
int go_solve_polish_usable(double viol_before, double obj_before, double viol_after,
                           double obj_after);

// Run the plan. 0 with *report filled (the solve's outcome is report->result.status), or -1
// with the reason in err (a solve could not start, out of memory); report->z is then NULL.
int go_solve_run(const go_solve_plan* plan, go_solve_report* report, char* err, int errsz);

// free report->z
void go_solve_report_free(go_solve_report* report);

#endif  // GAITSIM_OPTIM_GO_SOLVE_H_
