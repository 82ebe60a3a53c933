// cmd_report.c: `gaitsim report DIR [--out D] [--trial T] [--track TRACK_DIR]`: figures (PNG)
// and a Markdown report of a solution folder, like Lin, Walter & Pandy 2018 Fig. 1-3 and Table 1,
// or of a sweep folder (`gaitsim sweep`: sweep.csv, predict_<V>/), comparing the speeds like
// their Fig. 4-6 and 8, or of a batch folder (`gaitsim batch`: batch.csv). The work is done by
// scripts/report.py (Debian python3-matplotlib), run as a child process without a shell, into a
// temporary folder beside the output folder that replaces it in one rename when the script
// succeeds (io/gs_atomic.h gs_folder_*), and is removed when it fails.
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "io/gs_atomic.h"

#define GS_REPORT_PYTHON "/usr/bin/python3"
#define GS_REPORT_SCRIPT GAITSIM_SOURCE_DIR "/scripts/report.py"

static int run_script(const char* dir, const char* out, const char* staging, const char* trial,
                      const char* track);

// the script's process while it runs, and the stop signal received (0: none), for forward_stop
static volatile sig_atomic_t g_child = 0;
static volatile sig_atomic_t g_stop_signal = 0;

// SIGINT, SIGTERM, SIGHUP while the script runs: passed on to it, so that it ends now and the
// temporary folder is removed
static void forward_stop(int sig) {
  g_stop_signal = sig;
  if (g_child > 0) kill((pid_t)g_child, sig);
}

static const char* kReportUsage =
    "usage: gaitsim report DIR [--out D] [--trial T] [--track TRACK_DIR]\n\n"
    "Figures and a table for a solution folder DIR (states.sto, controls.sto, grf.mot,\n"
    "summary.json; knee_contact.sto if present) against the measured trial it tracked, like Lin,\n"
    "Walter & Pandy 2018 Fig. 1-3 and Table 1: kinematics.png, grf.png (BW), knee_contact.png\n"
    "(when DIR has knee_contact.sto), excitations.png (right leg vs healthy EMG timing) and\n"
    "report.md (RMS errors beside the paper's, solve facts, figure links).\n\n"
    "For a sweep folder DIR (gaitsim sweep: sweep.csv, predict_V/), figures comparing the speeds\n"
    "and the tracking solution, like the paper's Fig. 4-6 and 8: kinematics.png, grf.png,\n"
    "excitations.png (main right-leg muscles), knee_contact.png (right and left knee), and\n"
    "gait_parameters.png (stride time, stride length, cost of transport against speed, the\n"
    "paper's values marked); report.md with the sweep table.\n\n"
    "For a batch folder DIR (gaitsim batch: batch.csv), report.md with the batch table and\n"
    "wall_time.png (wall time per solve, by status), gait_speed.png (stride time and cost of\n"
    "transport against speed, each sweep a line) and rms.png (Table 1 RMS errors per track).\n\n"
    "The folder is written whole: into .NAME.tmp.XXXXXX beside it, which replaces it in one\n"
    "rename at the end. A failed report leaves the earlier report (or none), never a mix; an\n"
    "existing --out is replaced only when it holds an earlier report (report.md). A stop signal\n"
    "(SIGINT, SIGTERM, SIGHUP) ends the report at once, the same way (exit 1).\n\n"
    "Needs Debian's python3-matplotlib (" GS_REPORT_PYTHON ").\n\n"
    "  --out D           output folder (default DIR/report)\n"
    "  --trial T         measured trial folder (default: summary.json \"trial\", else\n"
    "                    mjmodels/trials/jw_ngait_og5)\n"
    "  --track TRACK_DIR sweep folders: the tracking solution to draw beside the speeds\n"
    "                    (default: the \"guess\" in the predictions' summary.json, if found)\n";

int gs_cmd_report(int argc, char** argv) {
  static const struct option options[] = {{"out", required_argument, NULL, 'o'},
                                          {"trial", required_argument, NULL, 't'},
                                          {"track", required_argument, NULL, 'k'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  const char* out = NULL;
  const char* trial = NULL;
  const char* track = NULL;
  optind = 1;
  opterr = 0;
  int c;
  while ((c = getopt_long(argc, argv, ":o:t:k:h", options, NULL)) != -1) {
    switch (c) {
      case 'o': out = optarg; break;
      case 't': trial = optarg; break;
      case 'k': track = optarg; break;
      case 'h': fputs(kReportUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("report", c, argv);
    }
  }
  if (gs_opt_one_operand("report", "DIR", argc, argv) != 0) return GS_EXIT_USAGE;
  // a solution folder (not a sweep's or a batch's) is checked whole before the figures are
  // drawn: every storage file reads, the node tables agree
  const char* dir = argv[optind];
  char path[4200];
  snprintf(path, sizeof(path), "%s/sweep.csv", dir);
  int collection = access(path, F_OK) == 0;
  snprintf(path, sizeof(path), "%s/batch.csv", dir);
  collection |= access(path, F_OK) == 0;
  if (!collection && gs_app_check_solution(dir, 0) != 0) return GS_EXIT_FAILURE;

  // the output folder, replaced only when it holds an earlier report; written into a temporary
  // folder beside it
  char out_dir[4200], err[4400];
  snprintf(out_dir, sizeof(out_dir), "%s/report", dir);
  if (out) snprintf(out_dir, sizeof(out_dir), "%s", out);
  gsFolderTx tx;
  if (gs_folder_replaceable(out_dir, "report.md", err, sizeof(err)) != 0 ||
      gs_folder_begin(&tx, out_dir, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: report: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  int rc = run_script(dir, out_dir, tx.staging, trial, track);
  if (rc != GS_EXIT_OK) {
    gs_folder_abort(&tx);
    return rc;
  }
  if (gs_folder_commit(&tx, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: report: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  return GS_EXIT_OK;
}

// run scripts/report.py on dir, writing into staging (its messages name out), and wait: its
// exit status (0, 2 usage), GS_EXIT_FAILURE for anything else
static int run_script(const char* dir, const char* out, const char* staging, const char* trial,
                      const char* track) {
  // the child's arguments: python3 report.py --out D --into S [--gaitsim SELF] [--trial T]
  // [--track K] -- DIR; "--" keeps a DIR that starts with '-' a folder name. SELF: this binary,
  // for the joint-moment figure's `gaitsim moments` (a solution folder's report)
  char* args[15];
  int n = 0;
  args[n++] = (char*)GS_REPORT_PYTHON;
  args[n++] = (char*)GS_REPORT_SCRIPT;
  args[n++] = (char*)"--out";
  args[n++] = (char*)out;
  args[n++] = (char*)"--into";
  args[n++] = (char*)staging;
  static char self[4096];
  ssize_t len = readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (len > 0) {
    self[len] = '\0';
    args[n++] = (char*)"--gaitsim";
    args[n++] = self;
  }
  if (trial) {
    args[n++] = (char*)"--trial";
    args[n++] = (char*)trial;
  }
  if (track) {
    args[n++] = (char*)"--track";
    args[n++] = (char*)track;
  }
  args[n++] = (char*)"--";
  args[n++] = (char*)dir;
  args[n] = NULL;

  // a stop signal whose action is the default one is passed on to the script; one that a caller
  // handles (gaitsim run: it lets the report finish, and its second signal removes the temporary
  // folder) or ignores (nohup) is left so
  static const int stops[3] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction old[3], sa;
  int forward[3];
  memset(&sa, 0, sizeof(sa));
  sa.sa_handler = forward_stop;
  sigemptyset(&sa.sa_mask);
  g_child = 0;
  g_stop_signal = 0;
  for (int i = 0; i < 3; i++) {
    forward[i] = sigaction(stops[i], NULL, &old[i]) == 0 && old[i].sa_handler == SIG_DFL;
    if (forward[i]) sigaction(stops[i], &sa, NULL);
  }

  // run it and wait; stdout is flushed first so nothing buffered is written twice
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) {
    fprintf(stderr, "gaitsim: report: fork: %s\n", strerror(errno));
    for (int i = 0; i < 3; i++)
      if (forward[i]) sigaction(stops[i], &old[i], NULL);
    return GS_EXIT_FAILURE;
  }
  if (pid == 0) {
    execv(GS_REPORT_PYTHON, args);
    fprintf(stderr, "gaitsim: %s: %s (install python3-matplotlib)\n", GS_REPORT_PYTHON,
            strerror(errno));
    _exit(GS_EXIT_FAILURE);
  }
  g_child = pid;
  if (g_stop_signal) kill(pid, g_stop_signal);  // one that came before g_child was set
  int st = 0, waited;
  while ((waited = (int)waitpid(pid, &st, 0)) < 0 && errno == EINTR) continue;
  int saved = errno;
  g_child = 0;
  for (int i = 0; i < 3; i++)
    if (forward[i]) sigaction(stops[i], &old[i], NULL);
  if (waited < 0) {
    fprintf(stderr, "gaitsim: report: waitpid: %s\n", strerror(saved));
    return GS_EXIT_FAILURE;
  }
  if (g_stop_signal) {
    fprintf(stderr, "gaitsim: report: stopped by signal %d; %s is as it was\n", (int)g_stop_signal,
            out);
    return GS_EXIT_FAILURE;
  }
  if (WIFSIGNALED(st)) {
    fprintf(stderr, "gaitsim: report: %s killed by signal %d\n", GS_REPORT_SCRIPT, WTERMSIG(st));
    return GS_EXIT_FAILURE;
  }
  if (!WIFEXITED(st)) return GS_EXIT_FAILURE;
  int rc = WEXITSTATUS(st);
  if (rc == GS_EXIT_OK || rc == GS_EXIT_USAGE) return rc;
  return GS_EXIT_FAILURE;
}
