// gs_batch_run.h: running a batch plan (gs_batch_plan.h) on this machine, one solve at a time for
// a Slurm job, resuming, and the collected table DIR/batch.csv, DIR/batch.md (issue #22).
//
// Each solve runs the gaitsim binary itself as a child process (`gaitsim track` or `gaitsim
// predict`, gs_batch_argv) writing its solution folder DIR/NAME/ (written whole by the solve, and
// refused by it when it holds anything but an earlier result, so the batch puts nothing there),
// its output in DIR/logs/NAME.log. When it ends, DIR/logs/NAME.json records its exit status, wall
// time, command line and the fingerprint of its
// inputs (gs_batch_fingerprint); a later run of the same plan on DIR skips the solves whose
// record says they ended (exit 0, or 3: stopped short at the plan's limits) uninterrupted, whose
// summary.json is there, whose dependencies are skipped likewise, and whose fingerprint is
// unchanged.
#ifndef GAITSIM_APP_GS_BATCH_RUN_H_
#define GAITSIM_APP_GS_BATCH_RUN_H_

#include <stdio.h>

#include "app/gs_batch_plan.h"

// The batch's own files about solve name: DIR/logs/NAME.log (its output), DIR/logs/NAME.json
// (its record), into path (n bytes); what is "log" or "json".
void gs_batch_file(char* path, size_t n, const char* dir, const char* name, const char* what);

// What a solve's DIR/logs/NAME.json records.
typedef struct gsBatchRecord_ {
  int present;              // 1: the record exists (the solve ended)
  int exit;                 // the child's exit status (128 + N for signal N)
  int interrupted;          // 1: stopped by the batch (Ctrl-C, SIGTERM)
  double wall_s;            // wall time of the child (s)
  unsigned long long fingerprint;  // gs_batch_fingerprint when it started
} gsBatchRecord;

// Read DIR/logs/NAME.json into r (r->present 0 when missing or unreadable).
void gs_batch_record_read(const char* dir, const char* name, gsBatchRecord* r);

// The status word of a record: "done" (exit 0), "stopped short" (3), "interrupted", "failed".
const char* gs_batch_record_status(const gsBatchRecord* r);

// Create DIR and write DIR/plan.json: the plan file with "base_dir" (where its relative paths
// point) added, so that later runs, Slurm jobs and batch-status read the same plan. 0, or -1 and
// err.
int gs_batch_prepare(const char* plan_path, const char* base, const char* dir, char* err,
                     int errsz);

// Resume: complete[i] = 1 for every solve whose result in DIR can be kept (see above).
void gs_batch_complete(const gsBatchPlan* plan, const char* dir, char* complete);

// Run the solves of plan not complete in DIR, at most nmax at once, each once its dependencies
// have ended with exit 0 or 3; the dependants of a failed solve are skipped. SIGINT and SIGTERM
// stop the running solves cleanly and start no more: each solve (in its own process group, so a
// terminal's Ctrl-C does not reach it directly) gets exactly one SIGINT from the batch, on which
// it writes its best iterate (a second stop signal would end it at once, writing nothing). Prints one line per start and end on stdout, writes batch.csv and batch.md. Returns the
// exit status: 0 all done, 3 some stopped short or the batch was interrupted, 1 some failed or
// were skipped (or err set: nothing ran).
int gs_batch_run_local(const gsBatchPlan* plan, const char* dir, const char* exe, int nmax,
                       char* err, int errsz);

// Run solve `name` alone (a Slurm job: its dependencies are assumed ended), record it and
// rewrite batch.csv and batch.md. A SIGTERM is not passed on (Slurm sends it to every process of
// the job, the solve included: one stop signal, best iterate written); a SIGINT is. Returns 0 when it ended with exit 0 or 3 (so that its
// dependants start), 1 otherwise.
int gs_batch_run_one(const gsBatchPlan* plan, const char* dir, const char* exe, const char* name,
                     char* err, int errsz);

// Write DIR/batch.csv and DIR/batch.md, one row per solve: status (state[i] when state and
// state[i] are not NULL, else from its record: "not run" without one), exit, wall time, stride
// time, speed, cost of transport, and for tracks the Table 1 RMS errors (summary.json "rms").
// Prints batch.md on out when out is not NULL. 0, or -1 and err.
int gs_batch_collect(const gsBatchPlan* plan, const char* dir, const char* const* state,
                     FILE* out, char* err, int errsz);

#endif  // GAITSIM_APP_GS_BATCH_RUN_H_
