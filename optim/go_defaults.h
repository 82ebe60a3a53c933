// go_defaults.h: the one table of gaitsim's solve defaults, read by go_gait_opts_default,
// go_solve_plan_default and every command (track, predict, sweep, run) and by their --help texts
// (GO_STR makes the text from the value, so a default is written once). Plain literals only:
// GO_STR(GO_NODES_TRACK) is the string "80".
#ifndef GAITSIM_OPTIM_GO_DEFAULTS_H_
#define GAITSIM_OPTIM_GO_DEFAULTS_H_

#define GO_STR_(x) #x
#define GO_STR(x) GO_STR_(x)  // the text of a default, e.g. GO_STR(GO_NODES_TRACK) "80"

// collocation nodes per stride (-)
#define GO_NODES_TRACK 80     // gaitsim track, and go_gait_opts_default: the paper's resolution
                              // (Lin, Walter & Pandy 2018)
#define GO_NODES_PREDICT 20   // gaitsim predict and sweep when the guess's summary.json gives no
                              // node count (else they solve on the guess's mesh)
#define GO_NODES_MAIN_JOB 80  // gaitsim run's main job (its tracking solve, then its sweep)
// worker threads of one solve (-)
#define GO_THREADS 2
// Ipopt iteration limits (-)
#define GO_MAX_ITER 4000           // each prediction: gaitsim predict, each speed of sweep and of
                                   // run's main job (--max-iter). An iteration budget, not a time
                                   // limit, so results do not depend on the load of the machine;
                                   // at 80 nodes the main job's predictions stop after 840
                                   // (0.8 m/s) and 1660 (2.0 m/s) iterations, and every speed of
                                   // the default sweep settles within it (1.0, 1.2 and 1.6 m/s
                                   // after 3525, 2806 and 3186: docs/BENCHMARKS.md, "The whole
                                   // sweep on the current model"); a larger limit retraces a
                                   // smaller one's iterations bitwise, so it changes no solve that
                                   // settled within it
#define GO_MAX_ITER_TRACK 60       // track's main solve, Gauss-Newton from the trial's guess at
                                   // barrier GO_GN_MU_INIT, before the refinement (--max-iter).
                                   // At N = 80 it brings the violation from 182 to about 0.1 at
                                   // J 3.5, where the refinement's Gauss-Newton and Newton
                                   // phases take over; 300 L-BFGS iterations did the same job in
                                   // 11 minutes (docs/BENCHMARKS.md, "Gauss-Newton from the
                                   // trial")
#define GO_GN_MU_INIT 1e-4         // a Gauss-Newton main solve's initial barrier (Ipopt's
                                   // mu_init, -): from Ipopt's 0.1 the Gauss-Newton steps stay
                                   // tiny (J 54 after 300 iterations at N = 20); from 1e-4 they
                                   // are full within 40
#define GO_MIN_HESS_PERTURBATION 0.1  // the smallest regularisation delta_w of Ipopt's inertia
                                   // correction in the Gauss-Newton and Newton solves (-; Ipopt's
                                   // default 1e-20). Where the Lagrangian's Hessian is indefinite
                                   // on the constraints' null space, Ipopt shifts it by delta_w,
                                   // lowering delta_w by 3 each iteration: from 1e-3 shifts the
                                   // Newton steps ran long along nearly flat directions and left
                                   // the violation at 1e-3 - 4e-2 every other iteration, so that
                                   // jw_bouncy7's 80-node track never settled (82 iterations,
                                   // exit 3); with a floor of 0.1 it settles after 23 Newton
                                   // iterations, and jw_ngait_og5's after 18 instead of 96, at
                                   // the same Table 1 figures (docs/BENCHMARKS.md, "A floor
                                   // under the Hessian regularisation")
#define GO_HANDOVER_ITER_TRACK 0   // with --hessian lbfgs and --refine-after N > 0, L-BFGS
                                   // hands over to the refinement at its first iterate from
                                   // iteration N on at a violation <= 1e-3. Off: on
                                   // jw_ngait_og5 at N = 80 (300 L-BFGS iterations), N = 150
                                   // handed over at iteration 230 and the whole solve took as
                                   // long (1097 s against 1140 s, J 2.649 against 2.641); a flat
                                   // 150-iteration cap was 4 minutes faster there but left
                                   // jw_bouncy7 without a usable start (docs/BENCHMARKS.md, "A
                                   // shorter L-BFGS phase")
// initial activations and excitations of a guess from the trial or a solution's states (-)
#define GO_ACTIVATION 0.05
// fall-back guard (go_ipopt_opts.fallback_rise, fallback_viol): stop when the objective rises by
// more than GO_FALLBACK_RISE (fraction, -) above the lowest one reached at a scaled violation
// <= GO_FALLBACK_VIOL (the acceptable level's), and restart from the best iterate, at most
// GO_MAX_RESTARTS times (go_solve.h)
#define GO_FALLBACK_RISE 0.25
#define GO_FALLBACK_VIOL 1e-4
#define GO_MAX_RESTARTS 2
// exact-Hessian refinement of an L-BFGS tracking solve that stopped short (go_solve.h): at most
// GO_REFINE_ITER Newton iterations (-) and GO_REFINE_WALL_S seconds of wall clock (0: no clock,
// the default: a clock would make the same command stop at another iterate on a slower or busier
// machine; the iteration cap bounds it: 4.6-6.2 s per Newton iteration at N = 80, docs/
// BENCHMARKS.md, "The right hip abductors' tendons by a converter rule"). From the main job's
// 600-iteration N = 20 solution they reached Ipopt's acceptable level after 78 (238 s,
// 2 threads), J -3.8 % (docs/BENCHMARKS.md, "Exact-Hessian refinement of the tracking solve");
// at N = 80 one exact-Hessian iteration costs about 4 times the N = 20 one
#define GO_REFINE_ITER 150
#define GO_REFINE_WALL_S 0
// the refinement's first phase: GO_REFINE_GN_ITER Gauss-Newton iterations (-); Newton starts
// where they stop. From the L-BFGS best iterate at N = 80 they lowered J from 2.872 to 2.645 (at
// a violation of 0.1, which Newton's first 11 iterations brought to 4e-4 at J 2.643), where 124
// Newton iterations alone reached 2.726 (docs/BENCHMARKS.md, "Gauss-Newton before Newton")
#define GO_REFINE_GN_ITER 60
// the refinement's settled rule (go_ipopt_opts.settle_iter): GO_SETTLE_ITER iterations (-) at a
// scaled violation <= GO_SETTLE_VIOL (the level the polish takes in a few iterations) among the
// last 2 GO_SETTLE_ITER, whose objectives span <= GO_SETTLE_REL (-) relative per iteration
// between the first and the last of them: Ipopt's acceptable level (each of 15 consecutive
// iterations changes J by <= 1e-4 relative, at a violation <= 1e-4) in the mean, without the
// need for consecutive iterations that the exact Hessian's violation spikes (1e-3 - 1e-1 every
// few iterations) reset
#define GO_SETTLE_ITER 15
#define GO_SETTLE_REL 1e-4
#define GO_SETTLE_VIOL 1e-3
// a prediction's stopping rule (gaitsim predict, sweep, run): Ipopt's acceptable level at a
// violation of 1e-4 (scaled, -) with the objective changing <= GO_PREDICT_SETTLE_REL relative per
// iteration (-) over GO_SETTLE_ITER consecutive iterations (acceptable_obj_change_tol), or the
// settled rule at the same figures over GO_SETTLE_ITER of the last 2 GO_SETTLE_ITER
// (go_solve_plan.settle_main_viol, settle_main_rel). L-BFGS's violation spikes (1e-3 - 1e-2
// every few iterations) reset Ipopt's count: in a main job at 80 nodes the 0.8 m/s prediction's
// objective stayed within 0.5 % of its final value for its last 700 of 1389 iterations while the
// adaptive barrier wandered. 1e-5 rather than Ipopt's and the track's 1e-4: in the main job the
// 2.0 m/s prediction stopped at iteration 536 with 1e-4 and at 729 with 1e-5, 0.11 % lower; the
// 0.8 m/s one at 405 and 415, at the same point (docs/BENCHMARKS.md, "Predictions: one
// factorisation per L-BFGS iteration, and the settled rule")
#define GO_PREDICT_SETTLE_VIOL 1e-4
#define GO_PREDICT_SETTLE_REL 1e-5
// a prediction's main solve differentiates the path rows by central differences (0), not
// forward ones (GO_JAC_SPARSE_FORWARD; 1, `predict --jacobian forward`): forward differences
// make an 80-node iteration a third cheaper, but the 2.0 m/s prediction then went into a basin
// 13 % higher in J and had not settled after 550 iterations (docs/BENCHMARKS.md, "Tried, not
// kept: forward differences in a prediction's main solve")
#define GO_PREDICT_FORWARD_JACOBIAN 0
#if GO_PREDICT_FORWARD_JACOBIAN
#define GO_PREDICT_JACOBIAN_NAME "forward"
#else
#define GO_PREDICT_JACOBIAN_NAME "central"
#endif
// feasibility polish (go_solve.h): Gauss-Newton iterations at most (-), and its wall-clock cap
// after a stop signal (s)
#define GO_POLISH_ITER 200
#define GO_STOP_POLISH_S 30
// from a point polished at a violation of at most GO_POLISH_GUARD_VIOL (-; a solve's answer: the
// refinement and the predictions stop at 1e-3 or below), the polish's point is used only where
// its objective J lies at most GO_POLISH_MAX_RISE (-) above the point's: the nearest consistent
// point moves J by 0.05 % (80-node tracking solves) to 2 % (predictions), but a polish that hit
// its iteration limit in Ipopt's restoration phase once returned a point at J 81.3 from J 2.053
// (jw_bouncy7 on a model variant; docs/BENCHMARKS.md, "The welded arms' pose and the pitch
// residual"). From farther (a solve stopped by a signal mid-way: violations 0.03-0.6 in
// cli_bad_inputs' planar solve) the projection moves J by 10-35 % and is used as before.
#define GO_POLISH_GUARD_VIOL 1e-2
#define GO_POLISH_MAX_RISE 0.10

// goal weights of gaitsim track (go_gait_opts.w_*, -); go_gait_opts_default keeps its own
// unit weights for library callers
#define GO_TRACK_W_PELVIS_ROT 10
#define GO_TRACK_W_PELVIS_TRANS 10
#define GO_TRACK_W_JOINT 1
#define GO_TRACK_W_GRF 10
#define GO_TRACK_W_GRM 0     // off: 10 narrows the stance to the measured one but, at 600
                             // iterations, worsens pelvis, GRF and knee tracking
                             // (docs/BENCHMARKS.md, "Foot placement and the
                             // centre-of-pressure goal")
#define GO_TRACK_W_EFFORT 50  // 0.1 left mean activation at 0.37 (co-contraction); issue #6 note
#define GO_TRACK_W_ACCEL 0    // none (results stay as they were)
// gaitsim predict's regularisation weights (-): effort, the mean squared excitation; accel, the
// mean squared acceleration (qddot / 50)^2: at the tracking solution results/track (peak |qddot|
// 500 rad/s^2, the variable bound) the goal is 0.26 against J = 178; after 40 iterations at
// 0.8 m/s (polished) it cut RMS qddot from 62 to 45 and the peak from 353 to 183 rad/s^2 at
// 0.06 % of J (1: 23 and 113, 0.13 %); small enough not to move the cost of transport
#define GO_PREDICT_W_EFFORT 0.01
#define GO_PREDICT_W_ACCEL 0.1
// gaitsim predict's factor on the smooth Umberger 2010 widths (-): with the widths of
// gs_umberger_smoothing_default (steps 0.01 wide in u - a, lM~ - 1 and v~ in lopt/s) no full-body
// prediction reached Ipopt's stopping test in up to 1500 L-BFGS iterations; 10 times wider, 0.8
// m/s reached the acceptable level after 477 and 2.0 m/s the optimal solution after 993 from the
// same tracking solution, and the exact (unsmoothed) cost of transport of the solution differs by
// 1.8 % (docs/BENCHMARKS.md, "Wider metabolic smoothing: the predictions converge"); 3 times
// wider did not converge in 1000 at 0.8 m/s
#define GO_PREDICT_METABOLIC_SMOOTHING 10
// gaitsim predict's floor on the summed vertical ground reaction of both feet at every node
// (BW): no flight phase. Not in the paper; without it, 20-node solves at 2.0 m/s found a gait
// with 2 of 20 nodes in flight (2.5 BW peaks) and a bouncing one with flight at 3 nodes and a
// 75 % longer stride, cheaper than the walks; with it the same guess gave a walk (double support
// at 2 nodes, lowest summed force 0.22 BW). Human walking keeps it above about 0.4 BW even at
// 2 m/s (docs/BENCHMARKS.md, "Walking: a floor on the vertical ground reaction")
#define GO_PREDICT_MIN_VGRF 0.2
// gaitsim predict's factor on the half-widths of eq. 3's band around the guess (-; at 1: 20 deg,
// 5 cm, 6 rad/s, 1 m/s, app/cmd_solve.c PREDICT_BAND_*; the paper gives none). On the 80-node
// sweep from the tracking solution at 0.8-2.0 m/s: at 1 every speed settled but the band held the
// predictions at its edge, the cost of transport was not monotonic in speed (1.6 m/s above 1.4
// and 1.8) and the left knee peaked at 4.7 BW at 2.0 m/s; at 1.5 every speed settles 3-12 % lower
// in the objective, the cost falls steadily to 1.8 m/s, both knees peak at <= 3.1 BW, though
// the vertical GRF peaks at 2.0 BW at 2.0 m/s (1.6 at x 1) (docs/BENCHMARKS.md, "Eq. 3's band
// x 1.5, the default")
#define GO_PREDICT_BAND_SCALE 1.5

#endif  // GAITSIM_OPTIM_GO_DEFAULTS_H_
