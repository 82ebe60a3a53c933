// gs_batch_slurm.h: a batch plan (gs_batch_plan.h) on a Slurm cluster (issue #22).
//
// Submission: the solves not complete in DIR (gs_batch_complete) go to `sbatch`; those that wait
// for no other submitted solve as job arrays (one per set of resources), the others one job each
// with --dependency=afterok on the jobs they wait for and --kill-on-invalid-dep=yes, so a failed
// solve's dependants are cancelled while independent ones go on. Every job runs
// `gaitsim batch DIR/plan.json --out DIR --run-one NAME` with the submitting binary's absolute
// path (gs_batch_run_one); DIR must be on a file system the compute nodes share. The job ids go
// to DIR/slurm/jobs.json, the job scripts and Slurm's output to DIR/slurm/.
#ifndef GAITSIM_APP_GS_BATCH_SLURM_H_
#define GAITSIM_APP_GS_BATCH_SLURM_H_

#include "app/gs_batch_plan.h"

// Submit the plan's incomplete solves (DIR absolute, exe the absolute gaitsim path). Prints one
// line per job on stdout. 0, or -1 and err: solves of an earlier submission still pending or
// running (nothing submitted), or sbatch missing or refusing (what was submitted before stays
// submitted and is in jobs.json).
int gs_batch_slurm_submit(const gsBatchPlan* plan, const char* dir, const char* exe, char* err,
                          int errsz);

// The status of every solve: from its record in DIR (done, stopped short, failed, interrupted),
// else from squeue (pending, running) for the job in DIR/slurm/jobs.json, else "skipped" when a
// dependency failed or was skipped, "failed" when its job ended without a record, "not run"
// without a job. state[i] points at a static string. Returns the number of solves still pending
// or running, or -1 with err when squeue fails while jobs are listed.
int gs_batch_slurm_status(const gsBatchPlan* plan, const char* dir, const char** state,
                          char* err, int errsz);

#endif  // GAITSIM_APP_GS_BATCH_SLURM_H_
