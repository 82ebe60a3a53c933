// gs_batch_plan.h: a batch plan (issue #22): the solves of `gaitsim batch PLAN.json`, read from
// JSON, sweeps expanded to one predict per speed, and validated whole before anything runs.
//
// A plan (relative paths are taken from the plan's own folder):
//   {"model": "mjmodels/gait2d.xml",              optional: --model of every solve
//    "options": {"nodes": 20, "threads": 1},      optional: options of every solve that has them
//    "slurm": {"cpus": 2, "time_min": 60, "mem_mb": 2000, "partition": "p"},   optional
//    "solves": [
//      {"name": "og5", "track": "mjmodels/trials/jw_ngait_og5", "options": {"refine": 0}},
//      {"name": "fast", "predict": 1.6, "guess": "og5"},
//      {"name": "up", "sweep": [1.4, 1.6], "guess": "og5"},       up_1.4 and up_1.6, each from og5
//      {"name": "ch", "sweep": [1.4, 1.6], "guess": "og5", "start": "neighbour"},
//                                                    ch_1.4 from og5, then ch_1.6 from ch_1.4
//      {"name": "t2", "track": "trial2", "init": "og5", "depends": ["fast"]}]}
// A solve's "options" are the long options of its command without the dashes (numbers, strings,
// true for a flag, a list for a repeatable one: "weight": ["grf=5", "joint=2"]) and replace the
// plan's of the same name. "guess" and "init" name a solve of the plan (it must finish first) or
// a solution folder; "depends" names solves (a sweep's name: all of its speeds) to wait for.
#ifndef GAITSIM_APP_GS_BATCH_PLAN_H_
#define GAITSIM_APP_GS_BATCH_PLAN_H_

#include <stdint.h>

#define GS_BATCH_NAME_MAX 96  // longest solve name (bytes, with the NUL)
#define GS_BATCH_PATH_MAX 4096  // longest path (bytes, with the NUL)

typedef enum gsBatchKind_ {
  GS_BATCH_TRACK = 0,  // gaitsim track TRIAL --out DIR/NAME ...
  GS_BATCH_PREDICT     // gaitsim predict --guess G --speed V --out DIR/NAME ...
} gsBatchKind;

typedef struct gsBatchSolve_ {
  char name[GS_BATCH_NAME_MAX];  // unique; also the folder DIR/NAME
  gsBatchKind kind;              // track or predict (a sweep's speeds are predicts)
  int index;                     // position in the plan's "solves" (for messages)
  char input[GS_BATCH_PATH_MAX];  // track: trial folder; predict: guess folder (absolute;
                                  // empty when the input is a solve of the plan)
  int from;                      // solve whose result is the guess (predict) or --init (track),
                                 // -1 when none or a folder
  double speed;                  // predict: target mean speed (m/s); track: 0
  int ndeps;                     // number of solves that must finish first
  int* deps;                     // their indices (ndeps x 1; owned)
  int nargs;                     // number of option words
  char** args;                   // option words after the command's own (nargs x 1; owned)
  char model[GS_BATCH_PATH_MAX];  // --model file (absolute), empty for the command's default
  int cpus;                      // Slurm: CPUs per task (the solve's --threads)
  int time_min;                  // Slurm: time limit (minutes)
  int mem_mb;                    // Slurm: memory (MB)
  char partition[64];            // Slurm: partition, empty for the cluster's default
} gsBatchSolve;

typedef struct gsBatchPlan_ {
  char path[GS_BATCH_PATH_MAX];  // the plan file as given (messages)
  char base[GS_BATCH_PATH_MAX];  // folder relative paths are taken from (absolute)
  int nsolve;                    // number of solves, sweeps expanded
  gsBatchSolve* solve;           // the solves, dependencies before dependants (nsolve x 1; owned)
} gsBatchPlan;

// Read, expand and validate the plan at path: names, trial and guess folders, every option by the
// rules of its command, dependencies on known solves, no cycles. base overrides the folder
// relative paths are taken from (NULL: the plan file's folder). On failure returns -1 with one
// line "FIELD: reason" in err (e.g. `solves[3].depends: unknown solve "x"`) and plan zeroed.
// Caller frees with gs_batch_plan_free.
int gs_batch_plan_load(const char* path, const char* base, gsBatchPlan* plan, char* err,
                       int errsz);

// Release everything the plan owns; safe on a zeroed plan.
void gs_batch_plan_free(gsBatchPlan* plan);

// Index of the solve called name, or -1.
int gs_batch_plan_find(const gsBatchPlan* plan, const char* name);

// The child's command line for solve i of plan: exe, the command, its input, --out DIR/NAME and
// the options, NULL-terminated (caller frees with gs_batch_argv_free). NULL when out of memory.
char** gs_batch_argv(const gsBatchPlan* plan, int i, const char* exe, const char* dir);
void gs_batch_argv_free(char** argv);

// Fingerprint of what solve i's result depends on: its command line (without exe) and the
// contents of its inputs (trial files, the guess's or init's summary.json, the model), so that
// an unchanged fingerprint means the same solve from the same inputs.
uint64_t gs_batch_fingerprint(const gsBatchPlan* plan, int i, const char* dir);

#endif  // GAITSIM_APP_GS_BATCH_PLAN_H_
