// cmd_batch.c: `gaitsim batch` (a plan of many solves on this machine or a Slurm cluster) and
// `gaitsim batch-status` (issue #22). Options only; the plan is app/gs_batch_plan.h, the runners
// app/gs_batch_run.h and app/gs_batch_slurm.h.
#include <getopt.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/gs_batch_plan.h"
#include "app/gs_batch_run.h"
#include "app/gs_batch_slurm.h"
#include "app/gs_commands.h"
#include "io/gs_atomic.h"

static const char* kBatchUsage =
    "usage: gaitsim batch PLAN.json --out DIR [--local N | --slurm] [--check]\n\n"
    "Many solves from one plan (README \"Batches\"): tracks of trials, predictions at speeds from\n"
    "a named solve's result, sweeps (every speed from the sweep's guess; with \"start\":\n"
    "\"neighbour\" in order, each from the one before), with the options of gaitsim track /\n"
    "predict. The plan is checked whole first (trial and guess folders, every option,\n"
    "dependencies, cycles); on an error nothing runs. Each solve runs `gaitsim track` or\n"
    "`gaitsim predict` into its solution folder DIR/NAME/ (its progress in DIR/logs/NAME.log,\n"
    "its exit status and wall time in DIR/logs/NAME.json). Running a plan\n"
    "again on the same DIR keeps the solves that ended (exit 0 or 3) with unchanged options and\n"
    "inputs and redoes the rest.\n"
    "DIR/batch.csv and DIR/batch.md: one row per solve (status, wall time, stride time, cost of\n"
    "transport, Table 1 RMS errors of tracks).\n\n"
    "  --local N   run here, at most N solves at once (default 1), each after the solves it\n"
    "              depends on ended with exit 0 or 3; a failed solve's dependants are skipped;\n"
    "              Ctrl-C or SIGTERM stops the running solves (best iterates written)\n"
    "  --slurm     submit to Slurm with sbatch (job arrays, afterok dependencies; CPUs, time\n"
    "              and memory per solve from its options or the plan's \"slurm\"); follow it with\n"
    "              gaitsim batch-status DIR. DIR must be on a file system the nodes share\n"
    "  --check     check the plan and print each solve's command; nothing is created\n"
    "Exit status (--local): 0 all done, 3 some stopped short or the batch was interrupted, 1 some\n"
    "failed or were skipped, or the plan is wrong (one line naming the field).\n";

static const char* kStatusUsage =
    "usage: gaitsim batch-status DIR [--wait]\n\n"
    "The state of each solve of the batch in DIR: done, stopped short, failed, interrupted (from\n"
    "DIR/logs/NAME.json), pending or running (squeue, for a batch submitted with --slurm),\n"
    "skipped (a solve it depends on failed) or not run; rewrites DIR/batch.csv and batch.md.\n\n"
    "  --wait      poll every 5 s until no solve is pending or running\n";

// DIR made absolute (it exists), into abs
static int absolute_dir(const char* dir, char* abs) {
  char err[512];
  if (gs_mkdir_p(dir, err, sizeof(err)) != 0 || !realpath(dir, abs)) {
    fprintf(stderr, "gaitsim: %s: %s\n", dir, err[0] ? err : "cannot resolve");
    return -1;
  }
  return 0;
}

int gs_cmd_batch(int argc, char** argv) {
  static const struct option options[] = {
      {"out", required_argument, NULL, 'o'},  {"local", required_argument, NULL, 'l'},
      {"slurm", no_argument, NULL, 's'},      {"check", no_argument, NULL, 'c'},
      {"run-one", required_argument, NULL, 'r'}, {"help", no_argument, NULL, 'h'},
      {NULL, 0, NULL, 0}};
  const char *dir = NULL, *one = NULL;
  int nlocal = 1, slurm = 0, check = 0, local_given = 0, c;
  char* end;
  optind = 1;
  while ((c = getopt_long(argc, argv, "o:l:scr:h", options, NULL)) != -1) {
    switch (c) {
      case 'o': dir = optarg; break;
      case 'l':
        nlocal = (int)strtol(optarg, &end, 10);
        if (*end || end == optarg || nlocal < 1 || nlocal > 1024) nlocal = 0;
        local_given = 1;
        break;
      case 's': slurm = 1; break;
      case 'c': check = 1; break;
      case 'r': one = optarg; break;  // a Slurm job's solve (gs_batch_slurm.h), not for users
      case 'h': fputs(kBatchUsage, stdout); return GS_EXIT_OK;
      default: fputs(kBatchUsage, stderr); return GS_EXIT_USAGE;
    }
  }
  if (optind != argc - 1 || (!dir && !check) || nlocal < 1 || (slurm && local_given)) {
    fputs(kBatchUsage, stderr);
    return GS_EXIT_USAGE;
  }
  const char* path = argv[optind];
  gsBatchPlan plan;
  char err[2048], exe[PATH_MAX], abs[PATH_MAX];
  if (gs_batch_plan_load(path, NULL, &plan, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    return GS_EXIT_FAILURE;
  }
  ssize_t len = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  exe[len > 0 ? len : 0] = 0;
  int rc = GS_EXIT_FAILURE;
  if (check) {
    for (int i = 0; i < plan.nsolve; i++) {
      char** a = gs_batch_argv(&plan, i, "gaitsim", dir ? dir : "DIR");
      printf("%s:", plan.solve[i].name);
      for (int k = 0; a && a[k]; k++) printf(" %s", a[k]);
      printf("\n");
      gs_batch_argv_free(a);
    }
    printf("batch: %s: %d solves, plan checked\n", path, plan.nsolve);
    rc = GS_EXIT_OK;
  } else if (absolute_dir(dir, abs) != 0) {
    rc = GS_EXIT_FAILURE;
  } else if (one) {
    rc = gs_batch_run_one(&plan, abs, exe, one, err, sizeof(err));
  } else if (gs_batch_prepare(path, plan.base, abs, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
  } else if (slurm) {
    if (gs_batch_slurm_submit(&plan, abs, exe, err, sizeof(err)) == 0) {
      printf("batch: submitted; gaitsim batch-status %s\n", abs);
      rc = GS_EXIT_OK;
    }
  } else {
    err[0] = 0;
    rc = gs_batch_run_local(&plan, abs, exe, nlocal, err, sizeof(err));
  }
  if (rc == GS_EXIT_FAILURE && err[0] && !check) fprintf(stderr, "gaitsim: %s: %s\n", path, err);
  gs_batch_plan_free(&plan);
  return rc;
}

int gs_cmd_batch_status(int argc, char** argv) {
  static const struct option options[] = {{"wait", no_argument, NULL, 'w'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  int wait = 0, c;
  optind = 1;
  while ((c = getopt_long(argc, argv, "wh", options, NULL)) != -1) {
    switch (c) {
      case 'w': wait = 1; break;
      case 'h': fputs(kStatusUsage, stdout); return GS_EXIT_OK;
      default: fputs(kStatusUsage, stderr); return GS_EXIT_USAGE;
    }
  }
  if (optind != argc - 1) {
    fputs(kStatusUsage, stderr);
    return GS_EXIT_USAGE;
  }
  const char* dir = argv[optind];
  char path[PATH_MAX + 16], err[2048];
  snprintf(path, sizeof(path), "%s/plan.json", dir);
  gsBatchPlan plan;
  if (gs_batch_plan_load(path, NULL, &plan, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    return GS_EXIT_FAILURE;
  }
  const char** state = (const char**)calloc((size_t)plan.nsolve, sizeof(char*));
  int live = 0, rc = GS_EXIT_OK;
  while (state && (live = gs_batch_slurm_status(&plan, dir, state, err, sizeof(err))) > 0 && wait)
    sleep(5);
  if (!state || live < 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", dir, state ? err : "out of memory");
    rc = GS_EXIT_FAILURE;
  } else {
    for (int i = 0; i < plan.nsolve; i++) printf("%-24s %s\n", plan.solve[i].name, state[i]);
    if (gs_batch_collect(&plan, dir, state, NULL, err, sizeof(err)) != 0) {
      fprintf(stderr, "gaitsim: %s\n", err);
      rc = GS_EXIT_FAILURE;
    }
  }
  free(state);
  gs_batch_plan_free(&plan);
  return rc;
}
