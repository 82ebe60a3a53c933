// cmd_sweep.c: `gaitsim sweep`: predictive solves over a range of speeds (issue #8). By default
// every speed starts from the guess (the tracking solution, as in Lin, Walter & Pandy 2018), so
// the speeds are independent: they run in --jobs processes and each gives the solution `gaitsim
// predict --guess G --speed V` gives, whatever the other speeds and the process count. With
// --start neighbour they are solved by continuation instead: the speeds below the guess's speed
// downwards and those above upwards, each from the nearest speed already solved (the first from
// the guess), the two chains in two processes. Writes DIR/predict_<V>/ per speed and
// DIR/sweep.csv and DIR/sweep.md: stride time and length, cost of transport, peak vertical ground
// reaction and peak knee contact force of both knees per speed (right: the implant knee, the one
// measured in vivo; left: the 1-DOF knee's joint reaction, callbacks/gs_knee_reaction.h), in BW.
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "io/gs_atomic.h"
#include "io/gs_storage.h"
#include "optim/go_defaults.h"
#include "optim/go_ipopt.h"

#define SWEEP_MAX_SPEEDS GS_MAX_SPEEDS
#define SWEEP_DEFAULT_JOBS 2
#define SWEEP_MAX_JOBS 8  // go_ipopt passes stop signals on to at most 8 processes

static const char* kSweepUsage =
    "usage: gaitsim sweep --guess TRACK_DIR --speeds LIST --out DIR [options]\n\n"
    "Predictive solves (gaitsim predict) at every speed of LIST, each started from TRACK_DIR\n"
    "(the tracking solution), in --jobs processes; each speed's solution is the one\n"
    "`gaitsim predict --guess TRACK_DIR --speed V --threads 1` gives. With --start neighbour,\n"
    "by continuation instead: each speed from the nearest speed already solved, those below\n"
    "and above the guess's own speed in two processes.\n"
    "LIST is A:STEP:B (m/s, e.g. 0.8:0.2:2.0) or comma-separated speeds. Writes DIR/predict_V/\n"
    "(the solver's progress in DIR/predict_V/log.txt), DIR/sweep.csv and DIR/sweep.md.\n"
    "DIR is written whole: into .DIR.tmp.XXXXXX beside it, which replaces DIR at the end (an\n"
    "existing DIR only when it holds an earlier sweep, sweep.csv). A stop signal (SIGINT,\n"
    "SIGTERM, SIGHUP) reaches every process: the running solves write their best iterates and\n"
    "DIR holds the speeds solved, the table saying which were not (exit 3); a second signal\n"
    "ends the sweep at once and DIR stays as it was. No speed solved: DIR stays as it was.\n\n"
    "  --start guess|neighbour  where each speed starts (default guess: the tracking solution)\n"
    "  --jobs P        solves at once with --start guess, 1-" GO_STR(SWEEP_MAX_JOBS)
    " (default " GO_STR(SWEEP_DEFAULT_JOBS) "; one\n"
    "                  thread each)\n"
    "  --nodes N       collocation nodes (default: the guess's, as gaitsim predict)\n"
    "  --max-time S    wall-clock limit of each solve, s (default none: the iteration limit,\n"
    "                  so that the results do not depend on the load of the machine)\n"
    "  --max-iter N    Ipopt iteration limit of each solve (default " GO_STR(GO_MAX_ITER)
    ")\n"
    "  --band-scale F  factor on the half-widths of eq. 3's band around the guess, as gaitsim\n"
    "                  predict (default " GO_STR(GO_PREDICT_BAND_SCALE)
    "; 0 removes the band; 0-10)\n";

// the guess's mean speed (summary.json speed_mps), or NAN
static double guess_speed(const char* dir) {
  char path[4096];
  snprintf(path, sizeof(path), "%s/summary.json", dir);
  cJSON* j = gs_app_read_json(path);
  const cJSON* v = cJSON_GetObjectItemCaseSensitive(j, "speed_mps");
  double s = cJSON_IsNumber(v) ? v->valuedouble : NAN;
  cJSON_Delete(j);
  return s;
}

// largest value of column label in DIR/file, or NAN
static double column_max(const char* dir, const char* file, const char* label) {
  char path[4096], err[256];
  snprintf(path, sizeof(path), "%s/%s", dir, file);
  gsTable t;
  gs_table_init(&t);
  double mx = NAN;
  if (gs_storage_read(path, &t, err, sizeof(err)) == 0) {
    int c = gs_table_column(&t, label);
    for (int k = 0; c >= 0 && k < t.nrow; k++)
      if (!(t.data[k * t.ncol + c] <= mx)) mx = t.data[k * t.ncol + c];
  }
  gs_table_free(&t);
  return mx;
}

// predict's options every speed gets, as the words given to sweep (NULL: predict's default)
typedef struct {
  const char* nodes;       // --nodes
  const char* max_time;    // --max-time
  const char* max_iter;    // --max-iter (never NULL: sweep's default is GO_MAX_ITER)
  const char* band_scale;  // --band-scale
} sweep_predict_opts;

// one predictive solve: speed v from guess into out, progress into out/log.txt
static int solve_one(const char* guess, double v, const char* out, const sweep_predict_opts* po) {
  char speed[32], log[4200], final_log[4200];
  snprintf(speed, sizeof(speed), "%.4g", v);
  // the progress goes to OUT.log while predict writes OUT whole, then into OUT/log.txt (a solve
  // that wrote nothing leaves OUT.log)
  snprintf(log, sizeof(log), "%s.log", out);
  snprintf(final_log, sizeof(final_log), "%s/log.txt", out);
  fflush(stderr);
  int saved = dup(2);
  FILE* lf = fopen(log, "w");
  if (lf) dup2(fileno(lf), 2);
  // --nodes, --max-time and --band-scale only when given (predict then takes the guess's node
  // count, no time limit, its default band)
  char* argv[18] = {"predict", "--guess", (char*)guess, "--speed", speed, "--out", (char*)out,
                    "--threads", "1", "--max-iter", (char*)po->max_iter};
  int argc = 11;
  const char* given[3][2] = {{"--nodes", po->nodes}, {"--max-time", po->max_time},
                             {"--band-scale", po->band_scale}};
  for (int i = 0; i < 3; i++) {
    if (!given[i][1]) continue;
    argv[argc++] = (char*)given[i][0];
    argv[argc++] = (char*)given[i][1];
  }
  argv[argc] = NULL;
  int rc = gs_cmd_predict(argc, argv);
  fflush(stderr);
  if (lf) {
    dup2(saved, 2);
    fclose(lf);
  }
  close(saved);
  // a failed solve: its reason (the last "gaitsim:" line of its log) on stderr too
  FILE* rf = rc != GS_EXIT_OK && rc != GS_EXIT_STOPPED_SHORT ? fopen(log, "r") : NULL;
  if (rf) {
    char line[1024], last[1024] = "";
    while (fgets(line, sizeof(line), rf))
      if (strncmp(line, "gaitsim: ", 9) == 0) snprintf(last, sizeof(last), "%s", line);
    fclose(rf);
    if (last[0]) fprintf(stderr, "gaitsim: sweep: %s m/s: %s", speed, last + 9);
  }
  if (lf && access(out, F_OK) == 0 && rename(log, final_log) != 0)
    fprintf(stderr, "gaitsim: %s: %s\n", final_log, strerror(errno));
  printf("sweep: %s m/s from %s: exit %d (%s)\n", speed, guess, rc, out);
  fflush(stdout);
  return rc;
}

// solve the speeds idx[0..n) in order, each from the previous one (the first from guess)
static int chain(const char* guess, const double* v, const int* idx, int n, const char* dir,
                 const sweep_predict_opts* po) {
  char prev[4096], out[4096];
  snprintf(prev, sizeof(prev), "%s", guess);
  int worst = GS_EXIT_OK;
  for (int i = 0; i < n; i++) {
    if (go_ipopt_stop_signals() > 0) {  // stopped by a signal: what finished stays
      printf("sweep: stopped by a signal before %.4g m/s\n", v[idx[i]]);
      return GS_EXIT_STOPPED_SHORT;
    }
    snprintf(out, sizeof(out), "%s/predict_%.4g", dir, v[idx[i]]);
    int rc = solve_one(prev, v[idx[i]], out, po);
    if (rc != GS_EXIT_OK && rc != GS_EXIT_STOPPED_SHORT) return rc;
    if (rc == GS_EXIT_STOPPED_SHORT) worst = rc;
    snprintf(prev, sizeof(prev), "%s", out);
  }
  return worst;
}

// solve the speeds v[0..n) each from guess, at most jobs at once, each in a process of its own.
// A stop signal (passed on to the running solves) starts no further speed; a failed speed does
// not stop the others. Returns the first failure, else GS_EXIT_STOPPED_SHORT when a solve stopped
// short or a speed was not started, else GS_EXIT_OK.
static int from_guess(const char* guess, const double* v, int n, int jobs, const char* dir,
                      const sweep_predict_opts* po) {
  pid_t running[SWEEP_MAX_JOBS] = {0};
  int nrun = 0, next = 0, failed = GS_EXIT_OK, stopped_short = 0;
  while (next < n || nrun > 0) {
    if (next < n && nrun < jobs && go_ipopt_stop_signals() == 0) {
      char out[4096];
      snprintf(out, sizeof(out), "%s/predict_%.4g", dir, v[next]);
      fflush(stdout);
      fflush(stderr);
      pid_t pid = (pid_t)go_ipopt_fork_forwarded();
      if (pid == 0) _exit(solve_one(guess, v[next], out, po));
      if (pid > 0) running[nrun++] = pid;
      if (pid < 0) {
        fprintf(stderr, "gaitsim: sweep: %.4g m/s: fork: %s\n", v[next], strerror(errno));
        if (failed == GS_EXIT_OK) failed = GS_EXIT_FAILURE;
      }
      next++;
      continue;
    }
    if (nrun == 0) break;  // stopped by a signal with nothing running
    int st = 0;
    pid_t pid = waitpid(-1, &st, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int k = 0; k < nrun; k++)
      if (running[k] == pid) {
        go_ipopt_forward_signals_to((long)pid, 0);
        running[k] = running[--nrun];
        int rc = WIFEXITED(st) ? WEXITSTATUS(st) : GS_EXIT_FAILURE;
        if (rc == GS_EXIT_STOPPED_SHORT) stopped_short = 1;
        else if (rc != GS_EXIT_OK && failed == GS_EXIT_OK) failed = rc;
        break;
      }
  }
  if (next < n) {
    printf("sweep: stopped by a signal before %.4g m/s\n", v[next]);
    stopped_short = 1;
  }
  return failed != GS_EXIT_OK ? failed : stopped_short ? GS_EXIT_STOPPED_SHORT : GS_EXIT_OK;
}

int gs_cmd_sweep(int argc, char** argv) {
  static const struct option options[] = {
      {"guess", required_argument, NULL, 'g'},   {"speeds", required_argument, NULL, 's'},
      {"out", required_argument, NULL, 'o'},     {"nodes", required_argument, NULL, 'n'},
      {"max-time", required_argument, NULL, 'T'}, {"max-iter", required_argument, NULL, 'i'},
      {"start", required_argument, NULL, 'S'},   {"jobs", required_argument, NULL, 'j'},
      {"band-scale", required_argument, NULL, 'B'}, {"help", no_argument, NULL, 'h'},
      {NULL, 0, NULL, 0}};
  static const char* const starts[] = {"guess", "neighbour", NULL};
  int start = 0, jobs = SWEEP_DEFAULT_JOBS;
  const char *guess = NULL, *dir = NULL;
  sweep_predict_opts po = {NULL, NULL, GO_STR(GO_MAX_ITER), NULL};
  double band_scale = GO_PREDICT_BAND_SCALE;
  double v[SWEEP_MAX_SPEEDS];
  int n = -1, c, bad = 0;
  optind = 1;
  opterr = 0;
  // every value checked here; predict gets the words as given
  while (!bad && (c = getopt_long(argc, argv, ":g:s:o:n:T:i:S:j:B:h", options, NULL)) != -1) {
    switch (c) {
      case 'g': guess = optarg; break;
      case 's': bad = (n = gs_opt_speeds("--speeds", optarg, v)) < 0; break;
      case 'o': dir = optarg; break;
      case 'n': bad = gs_opt_solve_limit(c, optarg, &po.nodes); break;
      case 'T': bad = gs_opt_solve_limit(c, optarg, &po.max_time); break;
      case 'i': bad = gs_opt_solve_limit(c, optarg, &po.max_iter); break;
      case 'B':
        bad = gs_opt_real("--band-scale", optarg, 0, 10, 0, &band_scale);
        po.band_scale = optarg;
        break;
      case 'S': bad = gs_opt_choice("--start", optarg, starts, &start); break;
      case 'j': bad = gs_opt_int("--jobs", optarg, 1, SWEEP_MAX_JOBS, &jobs); break;
      case 'h': fputs(kSweepUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("sweep", c, argv);
    }
  }
  if (bad) return GS_EXIT_USAGE;
  if (optind != argc) return gs_opt_usage_error("sweep", "unexpected argument '%s'", argv[optind]);
  if (!guess) return gs_opt_usage_error("sweep", "missing --guess TRACK_DIR");
  if (n < 1) return gs_opt_usage_error("sweep", "missing --speeds LIST");
  if (!dir) return gs_opt_usage_error("sweep", "missing --out DIR");
  go_ipopt_install_stop_signals(gs_folder_abort_from_signal);
  if (gs_app_check_solution(guess, 1) != 0) return GS_EXIT_FAILURE;
  double v0 = guess_speed(guess);
  if (!isfinite(v0)) {
    fprintf(stderr, "gaitsim: %s/summary.json: no speed_mps (not a solution folder?)\n", guess);
    return GS_EXIT_FAILURE;
  }
  // the sweep is written whole: into a temporary folder beside DIR that replaces DIR at the end,
  // so that no predict_V of an earlier sweep stays beside the new ones; an existing DIR is
  // replaced only when it holds an earlier sweep
  char err[1024];
  if (gs_folder_replaceable(dir, "sweep.csv", err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  gsFolderTx tx;
  if (gs_folder_begin(&tx, dir, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  const char* final_dir = dir;
  dir = tx.staging;
  int rc_down = GS_EXIT_OK, rc_up = GS_EXIT_OK;
  if (start == 0) {
    printf("sweep: %d speeds, each from the guess (%.3f m/s), %d at once\n", n, v0,
           jobs < n ? jobs : n);
    fflush(stdout);
    rc_up = from_guess(guess, v, n, jobs, dir, &po);
  } else {
    // the chains: downwards from the guess's speed, upwards from it
    int down[SWEEP_MAX_SPEEDS], up[SWEEP_MAX_SPEEDS], nd = 0, nu = 0;
    for (int i = n - 1; i >= 0; i--)
      if (v[i] < v0) down[nd++] = i;
    for (int i = 0; i < n; i++)
      if (v[i] >= v0) up[nu++] = i;
    printf("sweep: %d speeds around the guess's %.3f m/s by continuation: %d downwards, %d "
           "upwards\n", n, v0, nd, nu);
    fflush(stdout);
    // stop signals reach both chains
    pid_t pid = nd > 0 && nu > 0 ? (pid_t)go_ipopt_fork_forwarded() : -1;
    if (pid == 0) _exit(chain(guess, v, down, nd, dir, &po));
    rc_up = chain(guess, v, up, nu, dir, &po);
    if (pid > 0) {
      int st = 0;
      while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
      }
      go_ipopt_forward_signals_to((long)pid, 0);
      rc_down = WIFEXITED(st) ? WEXITSTATUS(st) : GS_EXIT_FAILURE;
    } else if (nd > 0) {
      rc_down = chain(guess, v, down, nd, dir, &po);
    }
  }

  // the table; changes against the guess (the tracking solution: the paper's comparison) and the
  // right triceps surae's peak excitations (summary.json peak_excitation)
  double T0 = NAN, L0 = NAN;
  char sol[4096];
  {
    snprintf(sol, sizeof(sol), "%s/summary.json", guess);
    cJSON* j = gs_app_read_json(sol);
    const cJSON* t = cJSON_GetObjectItemCaseSensitive(j, "stride_time_s");
    if (cJSON_IsNumber(t)) T0 = t->valuedouble, L0 = v0 * T0;
    cJSON_Delete(j);
  }
  char csv[16384], md[16384], path[4200];
  int lc = snprintf(csv, sizeof(csv), "speed_mps,stride_time_s,stride_length_m,"
                    "stride_time_change_pct,stride_length_change_pct,"
                    "cost_of_transport_j_per_kg_m,peak_vertical_grf_bw,peak_knee_contact_r_bw,"
                    "peak_knee_contact_l_bw,peak_soleus_excitation,peak_gastrocnemius_excitation,"
                    "min_summed_vgrf_bw,flight_nodes,double_support_nodes,status\n");
  int lm = snprintf(md, sizeof(md), "| speed (m/s) | stride time (s) | stride length (m) | "
                    "change from the guess: time, length (%%) | cost of transport (J/(kg m)) | "
                    "peak vertical GRF (BW) | peak knee contact, right (BW) | peak knee contact, "
                    "left (BW) | peak excitation: soleus, gastrocnemius | lowest summed vertical "
                    "GRF (BW); nodes in flight, in double support | status |\n"
                    "|---|---|---|---|---|---|---|---|---|---|---|\n");
  double sol_ex[SWEEP_MAX_SPEEDS], gas_ex[SWEEP_MAX_SPEEDS];
  int written = 0;  // speeds whose folder was written (converged, stopped short or interrupted)
  for (int i = 0; i < n; i++) {
    snprintf(sol, sizeof(sol), "%s/predict_%.4g", dir, v[i]);
    written += access(sol, F_OK) == 0;
    snprintf(path, sizeof(path), "%s/summary.json", sol);
    cJSON* j = gs_app_read_json(path);
    // walk or run: summary.json's lowest summed vertical force and flight, double-support nodes
    const char* keys[7] = {"stride_time_s", "stride_length_m", "cost_of_transport_j_per_kg_m",
                           "body_weight_n", "min_summed_vgrf_bw", "flight_nodes",
                           "double_support_nodes"};
    double f[sizeof(keys) / sizeof(keys[0])];
    for (size_t q = 0; q < sizeof(keys) / sizeof(keys[0]); q++) {
      const cJSON* x = cJSON_GetObjectItemCaseSensitive(j, keys[q]);
      f[q] = cJSON_IsNumber(x) ? x->valuedouble : NAN;
    }
    const cJSON* st = cJSON_GetObjectItemCaseSensitive(j, "status");
    const char* status = cJSON_IsString(st) ? st->valuestring : "not solved";
    // right leg: soleus; gastrocnemius the larger of its heads (JW's right-leg names)
    const cJSON* pe = cJSON_GetObjectItemCaseSensitive(j, "peak_excitation");
    const cJSON* so = cJSON_GetObjectItemCaseSensitive(pe, "soleus");
    const cJSON* gm = cJSON_GetObjectItemCaseSensitive(pe, "gasmed");
    const cJSON* gl = cJSON_GetObjectItemCaseSensitive(pe, "gaslat");
    sol_ex[i] = cJSON_IsNumber(so) ? so->valuedouble : NAN;
    gas_ex[i] = fmax(cJSON_IsNumber(gm) ? gm->valuedouble : NAN,
                     cJSON_IsNumber(gl) ? gl->valuedouble : NAN);
    double bw = f[3];  // the model's weight (N)
    double grf = fmax(column_max(sol, "grf.mot", "ground_force_r_vy"),
                      column_max(sol, "grf.mot", "ground_force_l_vy")) / bw;
    double knee = column_max(sol, "knee_contact.sto", "contact_total_r") / bw;
    double knee_l = column_max(sol, "knee_contact.sto", "contact_total_l") / bw;
    double dT = 100 * (f[0] / T0 - 1), dL = 100 * (f[1] / L0 - 1);
    if (lc < (int)sizeof(csv))
      lc += snprintf(csv + lc, sizeof(csv) - (size_t)lc,
                     "%.4g,%.4f,%.4f,%.2f,%.2f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.0f,%.0f,%s\n",
                     v[i], f[0], f[1], dT, dL, f[2], grf, knee, knee_l, sol_ex[i], gas_ex[i], f[4],
                     f[5], f[6], status);
    if (lm < (int)sizeof(md))
      lm += snprintf(md + lm, sizeof(md) - (size_t)lm,
                     "| %.4g | %.3f | %.3f | %+.1f, %+.1f | %.2f | %.2f | %.2f | %.2f | %.2f, %.2f "
                     "| %.2f; %.0f, %.0f | %s |\n",
                     v[i], f[0], f[1], dT, dL, f[2], grf, knee, knee_l, sol_ex[i], gas_ex[i], f[4],
                     f[5], f[6], status);
    cJSON_Delete(j);
  }
  // Lin, Walter & Pandy 2018 report peak soleus and gastrocnemius excitations about 2.5 times
  // higher at 2.0 than at 0.8 m/s: the same ratio between the fastest and slowest speed here
  if (n >= 2 && lm < (int)sizeof(md))
    lm += snprintf(md + lm, sizeof(md) - (size_t)lm,
                   "\nFast/slow peak excitation ratio (%.4g vs %.4g m/s): soleus %.2f, "
                   "gastrocnemius %.2f (paper: about 2.5). Changes are against the guess %s "
                   "(stride %.3f s, %.3f m).\n",
                   v[n - 1], v[0], sol_ex[n - 1] / sol_ex[0], gas_ex[n - 1] / gas_ex[0], guess,
                   T0, L0);
  // what finished replaces DIR (a sweep stopped by a signal or a failed speed: the speeds
  // solved, the table saying which); nothing finished: DIR stays as it was
  if (written == 0) {
    gs_folder_abort(&tx);
    printf("sweep: no speed was solved; %s left as it was\n", final_dir);
    return rc_down != GS_EXIT_OK ? rc_down : rc_up != GS_EXIT_OK ? rc_up : GS_EXIT_FAILURE;
  }
  snprintf(path, sizeof(path), "%s/sweep.csv", dir);
  int ok = gs_atomic_write_buffer(path, csv, strlen(csv), err, sizeof(err)) == 0;
  snprintf(path, sizeof(path), "%s/sweep.md", dir);
  ok = ok && gs_atomic_write_buffer(path, md, strlen(md), err, sizeof(err)) == 0;
  if (!ok || gs_folder_commit(&tx, err, sizeof(err)) != 0) {
    gs_folder_abort(&tx);
    fprintf(stderr, "gaitsim: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  printf("sweep: wrote %s (%d of %d speeds written)\n", final_dir, written, n);
  fputs(md, stdout);
  for (int r = 0; r < 2; r++) {
    int rc = r ? rc_up : rc_down;
    if (rc != GS_EXIT_OK && rc != GS_EXIT_STOPPED_SHORT) return rc;
  }
  return rc_down == GS_EXIT_STOPPED_SHORT || rc_up == GS_EXIT_STOPPED_SHORT ? GS_EXIT_STOPPED_SHORT
                                                                            : GS_EXIT_OK;
}
