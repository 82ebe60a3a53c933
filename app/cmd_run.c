// cmd_run.c: `gaitsim run`: the default job on the bundled model and trial (Lin, Walter & Pandy
// 2018, reproduced): the tracking solve of JW's stride, predictions at 0.8 and 2.0 m/s from it
// (gaitsim sweep, the two speeds in parallel processes), a report (figures, Table 1) and a video
// and filmstrip of each solution.
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <sys/wait.h>
#include <unistd.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "io/gs_atomic.h"
#include "optim/go_defaults.h"
#include "optim/go_ipopt.h"

static const char* kRunUsage =
    "usage: gaitsim run [--out DIR] [--trial DIR] [--nodes N] [--threads N] [--max-iter N]\n"
    "                   [--max-time S] [--speeds LIST]\n"
    "                   [--no-video]\n\n"
    "The default job on the bundled model and trial (mjmodels/jw_fullbody_knee6.xml, the\n"
    "six-DOF implant knee with surrogate contact, and mjmodels/trials/jw_ngait_og5, or the\n"
    "trial folder of --trial, e.g. mjmodels/trials/jw_bouncy7):\n"
    "  1. DIR/track: tracking solve on N nodes (default " GO_STR(GO_NODES_MAIN_JOB)
    ", the paper's resolution) from the trial,\n"
    "     as gaitsim track: " GO_STR(GO_MAX_ITER_TRACK) " Gauss-Newton iterations from the trial's "
    "guess, then\n"
    "     " GO_STR(GO_REFINE_GN_ITER) " more from their best iterate at a smaller barrier and up "
    "to " GO_STR(GO_REFINE_ITER) " Newton iterations with\n"
    "     the exact Hessian until the objective settles (gaitsim track --refine); polished to a\n"
    "     dynamically consistent point;\n"
    "  2. DIR/sweep/predict_V: predictive solves at the speeds of LIST (default 0.8,2.0: 0.8 and\n"
    "     2.0 m/s), each started from the tracking solution as in the paper, two at once in\n"
    "     processes of their own (gaitsim sweep), DIR/sweep/sweep.md;\n"
    "     walks: the summed vertical ground reaction stays above 0.2 BW (gaitsim predict\n"
    "     --min-vgrf; not in the paper), so no node is in flight;\n"
    "  3. DIR/*/report/: figures and report.md of every solution, DIR/sweep/report/: the speeds\n"
    "     side by side (kinematics, GRF, excitations, stride and cost against speed, knee);\n"
    "  4. DIR/*/gait.mp4 and strip.png: video (3 strides) and filmstrip of every solution.\n"
    "Results in DIR (default results/). Exit status 0 when every solve converged, 3 when one\n"
    "stopped short (its best iterate written), else as the failing step.\n\n"
    "  --trial DIR    the trial folder to track (coordinates.mot, grf.mot, knee_contact.sto;\n"
    "                 scripts/prepare_trial.py makes one; default mjmodels/trials/jw_ngait_og5)\n"
    "  --max-iter N   Ipopt iteration limit of each predictive solve (default "
    GO_STR(GO_MAX_ITER) ": an iteration\n"
    "                 budget, not a time limit, so that the results do not depend on the load\n"
    "                 of the machine; in the main job (docs/BENCHMARKS.md) they settle\n"
    "                 after 840 (0.8 m/s) and 1660 (2.0 m/s) iterations, about 1 s each on\n"
    "                 one core)\n"
    "  --nodes N      collocation nodes of every solve (default " GO_STR(GO_NODES_MAIN_JOB)
    "; 20 gives a coarse\n"
    "                 look in minutes)\n"
    "  --threads N    worker threads of the tracking solve (default " GO_STR(GO_THREADS)
    "; each prediction runs\n"
    "                 on one, in its own process)\n"
    "  --max-time S   wall-clock limit of each predictive solve, s (default none)\n";

// run one subcommand with the given words (argv[0] is the subcommand)
static int sub(gsCommandFn fn, const char* const* words) {
  int argc = 0;
  while (words[argc]) argc++;
  char** argv = (char**)calloc((size_t)argc + 1, sizeof(char*));
  for (int i = 0; i < argc; i++) argv[i] = (char*)words[i];
  fflush(stdout);
  int rc = fn(argc, argv);
  free(argv);
  return rc;
}

// run one solve step in a process of its own, so that every solve starts from the state of a
// fresh process, as the same solve run by its own command does: the tracking solve leaves
// state behind in the process (allocations, library buffers) that changed a later prediction's
// rounding from its 9th digit on (docs/BENCHMARKS.md, "One process per solve step"). Stop
// signals are passed on to the step's process, which writes what it holds.
static int sub_in_child(gsCommandFn fn, const char* const* words) {
  fflush(stdout);
  fflush(stderr);
  pid_t pid = (pid_t)go_ipopt_fork_forwarded();
  if (pid == 0) {
    int rc = sub(fn, words);
    fflush(stdout);
    fflush(stderr);
    _exit(rc);
  }
  if (pid < 0) {
    fprintf(stderr, "gaitsim: run: fork: %s\n", strerror(errno));
    return GS_EXIT_FAILURE;
  }
  int st = 0;
  while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
  }
  go_ipopt_forward_signals_to((long)pid, 0);
  if (WIFEXITED(st)) return WEXITSTATUS(st);
  fprintf(stderr, "gaitsim: run: %s step ended by signal %d\n", words[0],
          WIFSIGNALED(st) ? WTERMSIG(st) : 0);
  return GS_EXIT_FAILURE;
}

// after a stop signal: say what is kept, 1; else 0
static int stopped_by_signal(const char* out) {
  if (go_ipopt_stop_signals() == 0) return 0;
  printf("run: stopped by a signal; the steps that finished are in %s\n", out);
  return 1;
}

// report and pictures of the solution in dir
static int show(const char* dir, int video) {
  char mp4[4200], strip[4200];
  snprintf(mp4, sizeof(mp4), "%s/gait.mp4", dir);
  snprintf(strip, sizeof(strip), "%s/strip.png", dir);
  const char* w_report[] = {"report", dir, NULL};
  int rc = sub(gs_cmd_report, w_report);
  if (rc != GS_EXIT_OK || !video) return rc;
  const char* w_video[] = {"render", dir, "--out", mp4, "--cycles", "3", NULL};
  const char* w_strip[] = {"render", dir, "--strip", strip, "--count", "8", NULL};
  if ((rc = sub(gs_cmd_render, w_video)) != GS_EXIT_OK) return rc;
  return sub(gs_cmd_render, w_strip);
}

int gs_cmd_run(int argc, char** argv) {
  static const struct option options[] = {
      {"out", required_argument, NULL, 'o'},      {"nodes", required_argument, NULL, 'n'},
      {"threads", required_argument, NULL, 't'},  {"max-time", required_argument, NULL, 'T'},
      {"max-iter", required_argument, NULL, 'i'},
      {"speeds", required_argument, NULL, 's'},   {"no-video", no_argument, NULL, 'V'},
      {"trial", required_argument, NULL, 'r'},    {"help", no_argument, NULL, 'h'},
      {NULL, 0, NULL, 0}};
  const char *out = "results", *nodes = GO_STR(GO_NODES_MAIN_JOB), *max_time = NULL;
  const char *threads = GO_STR(GO_THREADS), *max_iter = GO_STR(GO_MAX_ITER);
  char speeds[256] = "0.8,2.0";
  int video = 1;
  const char* trial = GAITSIM_SOURCE_DIR "/mjmodels/trials/jw_ngait_og5";
  optind = 1;
  opterr = 0;
  int c, bad = 0, k;
  double v[GS_MAX_SPEEDS];
  // every value the steps are given is checked here, before the first solve
  while (!bad && (c = getopt_long(argc, argv, ":o:r:n:t:T:i:s:Vh", options, NULL)) != -1) {
    switch (c) {
      case 'o': out = optarg; break;
      case 'r': trial = optarg; break;
      case 'n': bad = gs_opt_solve_limit(c, optarg, &nodes); break;
      case 'T': bad = gs_opt_solve_limit(c, optarg, &max_time); break;
      case 'i': bad = gs_opt_solve_limit(c, optarg, &max_iter); break;
      case 't':
        threads = optarg;
        bad = gs_opt_int("--threads", optarg, 1, 64, &k);
        break;
      case 's':
        bad = gs_opt_speeds("--speeds", optarg, v) < 0;
        if (!bad && snprintf(speeds, sizeof(speeds), "%s", optarg) >= (int)sizeof(speeds)) {
          fprintf(stderr, "gaitsim: --speeds: at most %d characters\n", (int)sizeof(speeds) - 1);
          bad = 1;
        }
        break;
      case 'V': video = 0; break;
      case 'h': fputs(kRunUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("run", c, argv);
    }
  }
  if (bad) return GS_EXIT_USAGE;
  if (optind != argc) return gs_opt_usage_error("run", "unexpected argument '%s'", argv[optind]);
  // the trial folder holds what the tracking solve reads
  static const char* trial_files[] = {"coordinates.mot", "grf.mot"};
  for (int i = 0; i < 2; i++) {
    char path[4200];
    snprintf(path, sizeof(path), "%s/%s", trial, trial_files[i]);
    if (access(path, R_OK) != 0) {
      fprintf(stderr, "gaitsim: --trial: %s: %s\n", path, strerror(errno));
      return GS_EXIT_USAGE;
    }
  }
  // the folders it replaces must be earlier results (a solution's summary.json, a sweep's
  // sweep.csv) or absent; each is written whole by its step (track, sweep), so a failed or
  // interrupted run leaves the steps that finished and no half-written folder
  char err[1024], sub_dir[4200];
  static const char* const kSteps[2][2] = {{"track", "summary.json"}, {"sweep", "sweep.csv"}};
  for (int i = 0; i < 2; i++) {
    snprintf(sub_dir, sizeof(sub_dir), "%s/%s", out, kSteps[i][0]);
    if (gs_folder_replaceable(sub_dir, kSteps[i][1], err, sizeof(err)) != 0) {
      fprintf(stderr, "gaitsim: %s\n", err);
      return GS_EXIT_FAILURE;
    }
  }
  go_ipopt_install_stop_signals(gs_folder_abort_from_signal);
  char track[4096];
  snprintf(track, sizeof(track), "%s/track", out);
  int stopped_short = 0, rc;

  // 1. tracking, as gaitsim track on the asked mesh
  printf("[1] tracking solve of %s, %s nodes -> %s\n", trial, nodes, track);
  const char* w1[] = {"track", trial, "--out", track, "--nodes", nodes, "--threads", threads,
                      NULL};
  rc = sub_in_child(gs_cmd_track, w1);
  if (rc != GS_EXIT_OK && rc != GS_EXIT_STOPPED_SHORT) return rc;
  stopped_short |= rc == GS_EXIT_STOPPED_SHORT;
  if (stopped_by_signal(out)) return GS_EXIT_STOPPED_SHORT;

  // 2. predictions (gaitsim sweep): each speed from the tracking solution, two at once
  char sweep_dir[4096];
  snprintf(sweep_dir, sizeof(sweep_dir), "%s/sweep", out);
  printf("[2] predictive solves at %s m/s from the tracking solution -> %s\n",
         speeds, sweep_dir);
  const char* w3[] = {"sweep", "--guess", track, "--speeds", speeds, "--out", sweep_dir,
                      "--nodes", nodes, "--max-iter", max_iter,
                      max_time ? "--max-time" : NULL, max_time, NULL};
  rc = sub_in_child(gs_cmd_sweep, w3);
  if (rc != GS_EXIT_OK && rc != GS_EXIT_STOPPED_SHORT) return rc;
  stopped_short |= rc == GS_EXIT_STOPPED_SHORT;
  if (stopped_by_signal(out)) return GS_EXIT_STOPPED_SHORT;
  int nv = 0;
  FILE* f = NULL;
  char csv[4200];
  snprintf(csv, sizeof(csv), "%s/sweep.csv", sweep_dir);
  if ((f = fopen(csv, "r")) != NULL) {
    char line[512];
    if (fgets(line, sizeof(line), f))  // header
      while (nv < GS_MAX_SPEEDS && fgets(line, sizeof(line), f)) v[nv++] = strtod(line, NULL);
    fclose(f);
  }
  static char dirs[GS_MAX_SPEEDS][4200];
  int ndir = 0;
  for (int i = 0; i < nv; i++) snprintf(dirs[ndir++], sizeof(dirs[0]), "%s/predict_%.4g", sweep_dir, v[i]);
  // 3, 4. report and pictures
  printf("[3] report%s of %s\n", video ? ", video and filmstrip" : "", track);
  if ((rc = show(track, video)) != GS_EXIT_OK) return rc;
  if (stopped_by_signal(out)) return GS_EXIT_STOPPED_SHORT;
  for (int i = 0; i < ndir; i++) {
    printf("[3] report%s of %s\n", video ? ", video and filmstrip" : "", dirs[i]);
    if ((rc = show(dirs[i], video)) != GS_EXIT_OK) return rc;
    if (stopped_by_signal(out)) return GS_EXIT_STOPPED_SHORT;
  }
  // the speeds side by side (Lin, Walter & Pandy 2018, Fig. 4-6 and 8 style)
  printf("[3] report of the sweep %s\n", sweep_dir);
  const char* w_sweep_report[] = {"report", sweep_dir, "--track", track, NULL};
  if ((rc = sub(gs_cmd_report, w_sweep_report)) != GS_EXIT_OK) return rc;
  printf("run: results in %s (track/, sweep/predict_*/: summary.json, *.sto, grf.mot, report/%s; "
         "sweep/sweep.md, sweep/report/)%s\n",
         out, video ? ", gait.mp4, strip.png" : "",
         stopped_short ? "; a solve stopped short: its best iterate, polished, is written" : "");
  return stopped_short ? GS_EXIT_STOPPED_SHORT : GS_EXIT_OK;
}
