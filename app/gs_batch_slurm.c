// gs_batch_slurm.c: submitting a batch plan to Slurm and reading its state (gs_batch_slurm.h).
#include "app/gs_batch_slurm.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "app/gs_app_model.h"
#include "app/gs_batch_run.h"
#include "io/gs_atomic.h"
#include "io/gs_text.h"

// run argv (PATH searched) with stdout and stderr into out (n bytes, NUL-terminated, trailing
// newlines cut); its exit status, 127 when it could not be started
static int capture(char* const* argv, char* out, size_t n) {
  int fd[2];
  out[0] = 0;
  if (pipe(fd) != 0) return 127;
  fflush(stdout);
  pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    dup2(fd[1], 1);
    dup2(fd[1], 2);
    close(fd[1]);
    execvp(argv[0], argv);
    fprintf(stderr, "%s: %s", argv[0], strerror(errno));
    _exit(127);
  }
  close(fd[1]);
  size_t len = 0;
  ssize_t got;
  char sink[4096];
  while ((got = read(fd[0], len + 1 < n ? out + len : sink,
                     len + 1 < n ? n - 1 - len : sizeof(sink))) != 0) {
    if (got < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (len + 1 < n) len += (size_t)got;
  }
  close(fd[0]);
  out[len] = 0;
  while (len > 0 && out[len - 1] == '\n') out[--len] = 0;
  int st = 0;
  if (pid < 0) return 127;
  while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(st) ? WEXITSTATUS(st) : 127;
}

// s in single quotes for sh
static void quote(FILE* f, const char* s) {
  fputc('\'', f);
  for (; *s; s++) {
    if (*s == '\'') fputs("'\\''", f);
    else fputc(*s, f);
  }
  fputc('\'', f);
}

// write the job script path: it runs solve names[SLURM_ARRAY_TASK_ID] (or names[0])
static int write_script(const char* path, const char* exe, const char* dir, const char** names,
                        int n, char* err, int errsz) {
  gsAtomicFile a;
  if (gs_atomic_open(&a, path, err, errsz) != 0) return -1;
  fputs("#!/bin/sh\n# written by gaitsim batch --slurm: one solve of DIR/plan.json\nset --", a.f);
  for (int k = 0; k < n; k++) fprintf(a.f, " %s", names[k]);  // names are [A-Za-z0-9._-]
  fputs("\nshift \"${SLURM_ARRAY_TASK_ID:-0}\"\nexec ", a.f);
  quote(a.f, exe);
  fputs(" batch ", a.f);
  char plan[GS_BATCH_PATH_MAX + 16];
  snprintf(plan, sizeof(plan), "%s/plan.json", dir);
  quote(a.f, plan);
  fputs(" --out ", a.f);
  quote(a.f, dir);
  fputs(" --run-one \"$1\"\n", a.f);
  return gs_atomic_commit(&a, err, errsz);
}

// sbatch the script for solve s (its resources) with extra words; the job id into id
static int sbatch(const gsBatchSolve* s, const char* dir, const char* script, const char* name,
                  const char* array, const char* dep, char* id, size_t idn, char* err,
                  int errsz) {
  char cpus[32], time[32], mem[32], part[96], jn[128], out[GS_BATCH_PATH_MAX + 64], arr[64],
      msg[1024];
  snprintf(cpus, sizeof(cpus), "--cpus-per-task=%d", s->cpus);
  snprintf(time, sizeof(time), "--time=%d", s->time_min);
  snprintf(mem, sizeof(mem), "--mem=%dM", s->mem_mb);
  snprintf(part, sizeof(part), "--partition=%s", s->partition);
  snprintf(jn, sizeof(jn), "--job-name=gaitsim-%s", name);
  snprintf(out, sizeof(out), "--output=%s/slurm/%%x-%s.out", dir, array ? "%A_%a" : "%j");
  snprintf(arr, sizeof(arr), "--array=%s", array ? array : "");
  const char* argv[16];
  int n = 0;
  argv[n++] = "sbatch";
  argv[n++] = "--parsable";
  argv[n++] = jn;
  argv[n++] = cpus;
  argv[n++] = time;
  argv[n++] = mem;
  argv[n++] = out;
  if (s->partition[0]) argv[n++] = part;
  if (array) argv[n++] = arr;
  if (dep) {
    argv[n++] = dep;
    argv[n++] = "--kill-on-invalid-dep=yes";
  }
  argv[n++] = script;
  argv[n] = NULL;
  int rc = capture((char* const*)argv, msg, sizeof(msg));
  char* semi = strchr(msg, ';');  // "jobid;cluster"
  if (semi) *semi = 0;
  if (rc != 0 || !msg[0] || strspn(msg, "0123456789") != strlen(msg) || strlen(msg) >= 24) {
    gs_error_set(err, errsz, "sbatch %s: %s", name,
                 rc == 127 ? "cannot run sbatch (is Slurm installed?)" : msg);
    return -1;
  }
  return snprintf(id, idn, "%s", msg) < (int)idn ? 0 : -1;
}

static int same_resources(const gsBatchSolve* a, const gsBatchSolve* b) {
  return a->cpus == b->cpus && a->time_min == b->time_min && a->mem_mb == b->mem_mb &&
         strcmp(a->partition, b->partition) == 0;
}

static cJSON* read_jobs(const char* dir) {
  char path[GS_BATCH_PATH_MAX + 32];
  snprintf(path, sizeof(path), "%s/slurm/jobs.json", dir);
  cJSON* j = gs_app_read_json(path);
  if (!cJSON_IsObject(j)) {
    cJSON_Delete(j);
    j = cJSON_CreateObject();
  }
  return j;
}

static int write_jobs(const char* dir, cJSON* jobs, char* err, int errsz) {
  char path[GS_BATCH_PATH_MAX + 32];
  snprintf(path, sizeof(path), "%s/slurm/jobs.json", dir);
  char* text = cJSON_Print(jobs);
  int rc = text ? gs_atomic_write_buffer(path, text, strlen(text), err, errsz) : -1;
  free(text);
  return rc;
}

int gs_batch_slurm_submit(const gsBatchPlan* plan, const char* dir, const char* exe, char* err,
                          int errsz) {
  int n = plan->nsolve, rc = -1;
  char path[GS_BATCH_PATH_MAX + 128];
  snprintf(path, sizeof(path), "%s/slurm", dir);
  if (gs_mkdir_p(path, err, errsz) != 0) return -1;
  char* complete = (char*)calloc((size_t)n, 1);
  char(*id)[64] = calloc((size_t)n, sizeof(*id));
  char* taken = (char*)calloc((size_t)n, 1);
  const char** names = (const char**)calloc((size_t)n, sizeof(char*));
  cJSON* jobs = read_jobs(dir);
  if (!complete || !id || !taken || !names || !jobs) {
    gs_error_set(err, errsz, "out of memory");
    goto done;
  }
  // solves of an earlier submission still queued or running: no second job for them
  const char** state = (const char**)calloc((size_t)n, sizeof(char*));
  int live = state ? gs_batch_slurm_status(plan, dir, state, err, errsz) : -1;
  if (live != 0) {
    if (live > 0) {
      char list[512] = "";
      for (int i = 0; i < n; i++)
        if (!strcmp(state[i], "pending") || !strcmp(state[i], "running"))
          snprintf(list + strlen(list), sizeof(list) - strlen(list), "%s%s", list[0] ? ", " : "",
                   plan->solve[i].name);
      gs_error_set(err, errsz, "%d solves of an earlier submission are still queued or running "
                   "(%s): wait for them (gaitsim batch-status --wait) or scancel them", live, list);
    }
    free(state);
    goto done;
  }
  free(state);
  gs_batch_complete(plan, dir, complete);
  int kept = 0;
  for (int i = 0; i < n; i++) {
    kept += complete[i];
    if (complete[i]) continue;
    cJSON_DeleteItemFromObjectCaseSensitive(jobs, plan->solve[i].name);
    gs_batch_file(path, sizeof(path), dir, plan->solve[i].name, "json");
    unlink(path);  // an old record would read as this run's result
  }
  printf("batch: %d solves, %d kept from an earlier run, %d to submit\n", n, kept, n - kept);
  // solves that wait for no submitted solve: job arrays, one per set of resources
  for (int i = 0; i < n; i++) {
    const gsBatchSolve* s = &plan->solve[i];
    int root = !complete[i] && !taken[i];
    for (int k = 0; root && k < s->ndeps; k++) root = complete[s->deps[k]];
    if (!root) continue;
    int m = 0;
    for (int j = i; j < n; j++) {
      int rj = !complete[j] && !taken[j] && same_resources(s, &plan->solve[j]);
      for (int k = 0; rj && k < plan->solve[j].ndeps; k++) rj = complete[plan->solve[j].deps[k]];
      if (rj) names[m++] = plan->solve[j].name, taken[j] = 1;
    }
    char array[32], job[32];
    snprintf(array, sizeof(array), "0-%d", m - 1);
    snprintf(path, sizeof(path), "%s/slurm/array-%s.sh", dir, s->name);
    if (write_script(path, exe, dir, names, m, err, errsz) ||
        sbatch(s, dir, path, "array", array, NULL, job, sizeof(job), err, errsz))
      goto done;
    for (int t = 0; t < m; t++) {
      int j = gs_batch_plan_find(plan, names[t]);
      snprintf(id[j], sizeof(id[j]), "%s_%d", job, t);
      cJSON_AddStringToObject(jobs, names[t], id[j]);
    }
    printf("batch: job array %s: %d solves (%d CPUs, %d min, %d MB each)\n", job, m, s->cpus,
           s->time_min, s->mem_mb);
  }
  // the others, each after the submitted jobs it waits for
  for (int i = 0; i < n; i++) {
    const gsBatchSolve* s = &plan->solve[i];
    if (complete[i] || taken[i]) continue;
    char dep[1024] = "--dependency=afterok";
    for (int k = 0; k < s->ndeps; k++)
      if (!complete[s->deps[k]])
        snprintf(dep + strlen(dep), sizeof(dep) - strlen(dep), ":%s", id[s->deps[k]]);
    snprintf(path, sizeof(path), "%s/slurm/%s.sh", dir, s->name);
    names[0] = s->name;
    if (write_script(path, exe, dir, names, 1, err, errsz) ||
        sbatch(s, dir, path, s->name, NULL, dep, id[i], sizeof(id[i]), err, errsz))
      goto done;
    taken[i] = 1;
    cJSON_AddStringToObject(jobs, s->name, id[i]);
    printf("batch: job %s: %s (%d CPUs, %d min, %d MB; %s)\n", id[i], s->name, s->cpus,
           s->time_min, s->mem_mb, dep + 13);
  }
  rc = 0;
done:
  if (jobs) {
    char werr[512];
    if (write_jobs(dir, jobs, werr, sizeof(werr)) != 0 && rc == 0) {
      gs_error_set(err, errsz, "%s", werr);
      rc = -1;
    }
  }
  cJSON_Delete(jobs);
  free(complete), free(id), free(taken), free(names);
  return rc;
}

int gs_batch_slurm_status(const gsBatchPlan* plan, const char* dir, const char** state,
                          char* err, int errsz) {
  cJSON* jobs = read_jobs(dir);
  int live = 0, n = plan->nsolve;
  // every job Slurm still knows: "ID STATE REASON", arrays one line per task (-r)
  static char queue[1 << 20];
  queue[0] = 0;
  if (cJSON_GetArraySize(jobs) > 0) {
    char* const argv[] = {"squeue", "-h", "-r", "-o", "%i %T %r", NULL};
    if (capture(argv, queue, sizeof(queue)) != 0) {
      gs_error_set(err, errsz, "squeue: %s", queue[0] ? queue : "cannot run squeue");
      cJSON_Delete(jobs);
      return -1;
    }
  }
  for (int i = 0; i < n; i++) {
    const gsBatchSolve* s = &plan->solve[i];
    gsBatchRecord r;
    gs_batch_record_read(dir, s->name, &r);
    const cJSON* id = cJSON_GetObjectItemCaseSensitive(jobs, s->name);
    char key[96], line[256] = "";
    if (cJSON_IsString(id)) {
      snprintf(key, sizeof(key), "%s ", id->valuestring);
      for (const char* p = queue; *p;) {
        const char* e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (strncmp(p, key, strlen(key)) == 0 && len < sizeof(line)) {
          memcpy(line, p, len);
          line[len] = 0;
          break;
        }
        p += len + (e != NULL);
      }
    }
    int dead = 0;
    for (int k = 0; k < s->ndeps; k++) {
      const char* d = state[s->deps[k]];
      dead |= !strcmp(d, "failed") || !strcmp(d, "skipped") || !strcmp(d, "interrupted");
    }
    if (r.present) {
      state[i] = gs_batch_record_status(&r);
    } else if (line[0] && strstr(line, "DependencyNeverSatisfied")) {
      state[i] = "skipped";
    } else if (line[0] && strstr(line, " PENDING")) {
      state[i] = "pending";
      live++;
    } else if (line[0]) {
      state[i] = "running";
      live++;
    } else if (dead) {
      state[i] = "skipped";
    } else {
      state[i] = cJSON_IsString(id) ? "failed" : "not run";
    }
  }
  cJSON_Delete(jobs);
  return live;
}
