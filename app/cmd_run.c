// cmd_run.c: `gaitsim run`: the default job on the bundled model and trial: the tracking solve of
// JW's stride (Lin, Walter & Pandy 2018) by mesh continuation (20 nodes, then the requested
// number started from it), then the report (figures and Table 1) and a video and a filmstrip of
// the solution. Prediction joins when it lands (issue #8).
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"

static const char* kRunUsage =
    "usage: gaitsim run [--out DIR] [--nodes N] [--threads N] [--max-time S] [--no-video]\n\n"
    "The default job on the bundled model and trial (mjmodels/jw_fullbody.xml,\n"
    "mjmodels/trials/jw_ngait_og5): tracking solve on 20 nodes, then on N nodes (default 80)\n"
    "started from it, then DIR/track/report/ (figures, report.md), DIR/track/gait.mp4 and\n"
    "DIR/track/strip.png. Results in DIR (default\n"
    "results/). Exit status as `gaitsim track` (3: a solve stopped short, its best iterate\n"
    "written).\n\n"
    "  --max-time S   wall-clock limit of each solve, s (default 600)\n";

// run one subcommand with the given words (argv[0] is the subcommand)
static int sub(gsCommandFn fn, const char* const* words) {
  int argc = 0;
  while (words[argc]) argc++;
  char** argv = (char**)calloc((size_t)argc + 1, sizeof(char*));
  for (int i = 0; i < argc; i++) argv[i] = (char*)words[i];
  int rc = fn(argc, argv);
  free(argv);
  return rc;
}

int gs_cmd_run(int argc, char** argv) {
  static const struct option options[] = {
      {"out", required_argument, NULL, 'o'},      {"nodes", required_argument, NULL, 'n'},
      {"threads", required_argument, NULL, 't'},  {"max-time", required_argument, NULL, 'T'},
      {"no-video", no_argument, NULL, 'V'},       {"help", no_argument, NULL, 'h'},
      {NULL, 0, NULL, 0}};
  const char *out = "results", *nodes = "80", *threads = "2", *max_time = "600";
  int video = 1;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, "o:n:t:T:Vh", options, NULL)) != -1) {
    switch (c) {
      case 'o': out = optarg; break;
      case 'n': nodes = optarg; break;
      case 't': threads = optarg; break;
      case 'T': max_time = optarg; break;
      case 'V': video = 0; break;
      case 'h': fputs(kRunUsage, stdout); return GS_EXIT_OK;
      default: fputs(kRunUsage, stderr); return GS_EXIT_USAGE;
    }
  }
  if (optind != argc) {
    fputs(kRunUsage, stderr);
    return GS_EXIT_USAGE;
  }
  const char* trial = GAITSIM_SOURCE_DIR "/mjmodels/trials/jw_ngait_og5";
  char coarse[4096], fine[4096], mp4[4200], strip[4200];
  snprintf(coarse, sizeof(coarse), "%s/track_n20", out);
  snprintf(fine, sizeof(fine), "%s/track", out);
  snprintf(mp4, sizeof(mp4), "%s/gait.mp4", fine);
  snprintf(strip, sizeof(strip), "%s/strip.png", fine);

  printf("[1/4] tracking solve, 20 nodes -> %s\n", coarse);
  fflush(stdout);
  const char* w1[] = {"track", trial, "--out", coarse, "--nodes", "20", "--threads", threads,
                      "--max-iter", "800", "--max-time", max_time, NULL};
  int rc = sub(gs_cmd_track, w1);
  if (rc != GS_EXIT_OK && rc != GS_EXIT_STOPPED_SHORT) return rc;
  printf("[2/4] tracking solve, %s nodes, started from it -> %s\n", nodes, fine);
  fflush(stdout);
  const char* w2[] = {"track", trial, "--out", fine, "--nodes", nodes, "--threads", threads,
                      "--init", coarse, "--max-iter", "1000", "--max-time", max_time, NULL};
  rc = sub(gs_cmd_track, w2);
  if (rc != GS_EXIT_OK && rc != GS_EXIT_STOPPED_SHORT) return rc;
  int track_rc = rc;
  printf("[3/4] report -> %s/report\n", fine);
  fflush(stdout);
  const char* w5[] = {"report", fine, NULL};
  if ((rc = sub(gs_cmd_report, w5)) != GS_EXIT_OK) return rc;
  if (video) {
    printf("[4/4] video %s and filmstrip %s\n", mp4, strip);
    fflush(stdout);
    const char* w3[] = {"render", fine, "--out", mp4, "--cycles", "3", NULL};
    const char* w4[] = {"render", fine, "--strip", strip, "--count", "8", NULL};
    if ((rc = sub(gs_cmd_render, w3)) != GS_EXIT_OK) return rc;
    if ((rc = sub(gs_cmd_render, w4)) != GS_EXIT_OK) return rc;
  }
  printf("run: results in %s (summary.json, *.sto, grf.mot, report/%s)%s\n", fine,
         video ? ", gait.mp4, strip.png" : "",
         track_rc == GS_EXIT_STOPPED_SHORT ? "; the solve stopped short: best iterate" : "");
  return track_rc;
}
