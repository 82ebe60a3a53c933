// cmd_report.c: `gaitsim report DIR [--out D] [--trial T] [--track TRACK_DIR]`: figures (PNG)
// and a Markdown report of a solution folder, like Lin, Walter & Pandy 2018 Fig. 1-3 and Table 1,
// or of a sweep folder (`gaitsim sweep`: sweep.csv, predict_<V>/), comparing the speeds like
// their Fig. 4-6 and 8. The work is done by scripts/report.py (Debian python3-matplotlib), run as
// a child process without a shell; its exit status is passed through.
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"

#define GS_REPORT_PYTHON "/usr/bin/python3"
#define GS_REPORT_SCRIPT GAITSIM_SOURCE_DIR "/scripts/report.py"

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
    "Each file is written whole (temporary file + rename), and nothing is written on bad input.\n"
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
  // a solution folder (not a sweep's) is checked whole before the figures are drawn: every
  // storage file reads, the node tables agree
  char csv[4200];
  snprintf(csv, sizeof(csv), "%s/sweep.csv", argv[optind]);
  if (access(csv, F_OK) != 0 && gs_app_check_solution(argv[optind], 0) != 0)
    return GS_EXIT_FAILURE;

  // the child's arguments: python3 report.py [--out D] [--trial T] [--track K] -- DIR; "--"
  // keeps a DIR that starts with '-' a folder name
  char* args[11];
  int n = 0;
  args[n++] = (char*)GS_REPORT_PYTHON;
  args[n++] = (char*)GS_REPORT_SCRIPT;
  if (out) {
    args[n++] = (char*)"--out";
    args[n++] = (char*)out;
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
  args[n++] = argv[optind];
  args[n] = NULL;

  // run it and wait; stdout is flushed first so nothing buffered is written twice
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) {
    fprintf(stderr, "gaitsim: report: fork: %s\n", strerror(errno));
    return GS_EXIT_FAILURE;
  }
  if (pid == 0) {
    execv(GS_REPORT_PYTHON, args);
    fprintf(stderr, "gaitsim: %s: %s (install python3-matplotlib)\n", GS_REPORT_PYTHON,
            strerror(errno));
    _exit(GS_EXIT_FAILURE);
  }
  int st = 0;
  while (waitpid(pid, &st, 0) < 0) {
    if (errno != EINTR) {
      fprintf(stderr, "gaitsim: report: waitpid: %s\n", strerror(errno));
      return GS_EXIT_FAILURE;
    }
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
