// gs_batch_run.c: the local runner, one Slurm job's solve, resume and the collected table
// (gs_batch_run.h).
#include "app/gs_batch_run.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "io/gs_atomic.h"
#include "io/gs_text.h"

typedef enum runState_ {
  RUN_WAIT = 0,  // not started
  RUN_GOING,     // its child is running
  RUN_ENDED,     // ended with exit 0 or 3 (its dependants may start)
  RUN_BAD,       // failed or interrupted
  RUN_SKIPPED,   // a dependency failed: never started
  RUN_KEPT       // complete from an earlier run (or, for one Slurm job, not this job's)
} runState;

static volatile sig_atomic_t g_stop = 0;  // the signal that asked the batch to stop, or 0

static void on_stop(int sig) { g_stop = sig; }

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void gs_batch_file(char* path, size_t n, const char* dir, const char* name, const char* what) {
  snprintf(path, n, "%s/logs/%s.%s", dir, name, what);
}

void gs_batch_record_read(const char* dir, const char* name, gsBatchRecord* r) {
  char path[2 * GS_BATCH_PATH_MAX];
  memset(r, 0, sizeof(*r));
  gs_batch_file(path, sizeof(path), dir, name, "json");
  cJSON* j = gs_app_read_json(path);
  const cJSON* ex = cJSON_GetObjectItemCaseSensitive(j, "exit");
  const cJSON* fp = cJSON_GetObjectItemCaseSensitive(j, "fingerprint");
  if (cJSON_IsNumber(ex) && cJSON_IsString(fp)) {
    r->present = 1;
    r->exit = ex->valueint;
    r->interrupted = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(j, "interrupted"));
    const cJSON* w = cJSON_GetObjectItemCaseSensitive(j, "wall_s");
    r->wall_s = cJSON_IsNumber(w) ? w->valuedouble : NAN;
    r->fingerprint = strtoull(fp->valuestring, NULL, 16);
  }
  cJSON_Delete(j);
}

const char* gs_batch_record_status(const gsBatchRecord* r) {
  if (r->interrupted) return "interrupted";
  if (r->exit == GS_EXIT_OK) return "done";
  if (r->exit == GS_EXIT_STOPPED_SHORT) return "stopped short";
  return "failed";
}

static int ended_well(const gsBatchRecord* r) {
  return r->present && !r->interrupted &&
         (r->exit == GS_EXIT_OK || r->exit == GS_EXIT_STOPPED_SHORT);
}

int gs_batch_prepare(const char* plan_path, const char* base, const char* dir, char* err,
                     int errsz) {
  if (gs_mkdir_p(dir, err, errsz) != 0) return -1;
  char path[GS_BATCH_PATH_MAX + 32];
  cJSON* j = gs_app_read_json(plan_path);
  if (!j) {
    gs_error_set(err, errsz, "%s: cannot read the plan", plan_path);
    return -1;
  }
  cJSON_DeleteItemFromObjectCaseSensitive(j, "base_dir");
  cJSON_AddStringToObject(j, "base_dir", base);
  char* text = cJSON_Print(j);
  cJSON_Delete(j);
  snprintf(path, sizeof(path), "%s/plan.json", dir);
  int rc = text ? gs_atomic_write_buffer(path, text, strlen(text), err, errsz) : -1;
  free(text);
  return rc;
}

void gs_batch_complete(const gsBatchPlan* plan, const char* dir, char* complete) {
  char path[2 * GS_BATCH_PATH_MAX + 16];
  for (int i = 0; i < plan->nsolve; i++) {  // dependencies come first
    const gsBatchSolve* s = &plan->solve[i];
    gsBatchRecord r;
    gs_batch_record_read(dir, s->name, &r);
    snprintf(path, sizeof(path), "%s/%s/summary.json", dir, s->name);
    int ok = ended_well(&r) && access(path, R_OK) == 0;
    for (int k = 0; ok && k < s->ndeps; k++) ok = complete[s->deps[k]];
    complete[i] = ok && r.fingerprint == gs_batch_fingerprint(plan, i, dir);
  }
}

// write DIR/logs/NAME.json for a child that ended with status st after wall seconds
static void write_record(const gsBatchPlan* plan, int i, const char* dir, const char* exe,
                         unsigned long long fp, int st, double wall, int interrupted) {
  int code = WIFEXITED(st) ? WEXITSTATUS(st) : WIFSIGNALED(st) ? 128 + WTERMSIG(st) : 255;
  cJSON* j = cJSON_CreateObject();
  char hex[32], path[2 * GS_BATCH_PATH_MAX], err[512];
  snprintf(hex, sizeof(hex), "%016llx", fp);
  cJSON_AddStringToObject(j, "solve", plan->solve[i].name);
  cJSON_AddNumberToObject(j, "exit", code);
  cJSON_AddBoolToObject(j, "interrupted", interrupted);
  cJSON_AddNumberToObject(j, "wall_s", wall);
  cJSON_AddStringToObject(j, "fingerprint", hex);
  char** a = gs_batch_argv(plan, i, exe, dir);
  cJSON* cmd = cJSON_AddArrayToObject(j, "command");
  for (int k = 0; a && a[k]; k++) cJSON_AddItemToArray(cmd, cJSON_CreateString(a[k]));
  gs_batch_argv_free(a);
  char* text = cJSON_Print(j);
  cJSON_Delete(j);
  gs_batch_file(path, sizeof(path), dir, plan->solve[i].name, "json");
  if (!text || gs_atomic_write_buffer(path, text, strlen(text), err, sizeof(err)) != 0)
    fprintf(stderr, "gaitsim: %s\n", text ? err : "out of memory");
  free(text);
}

// start solve i: DIR/logs (its old record removed), its log DIR/logs/NAME.log, the child in its
// own process group (so that a terminal's Ctrl-C reaches it only through the batch); its pid, or
// -1 and err. DIR/NAME itself is left to the child (a solve refuses a folder holding anything but
// an earlier result)
static pid_t start(const gsBatchPlan* plan, int i, const char* dir, const char* exe, char* err,
                   int errsz) {
  char path[2 * GS_BATCH_PATH_MAX + 16];
  snprintf(path, sizeof(path), "%s/logs", dir);
  if (gs_mkdir_p(path, err, errsz) != 0) return -1;
  gs_batch_file(path, sizeof(path), dir, plan->solve[i].name, "json");
  unlink(path);
  gs_batch_file(path, sizeof(path), dir, plan->solve[i].name, "log");
  char** argv = gs_batch_argv(plan, i, exe, dir);
  int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (!argv || fd < 0) {
    gs_error_set(err, errsz, "%s: %s", path, argv ? strerror(errno) : "out of memory");
    gs_batch_argv_free(argv);
    if (fd >= 0) close(fd);
    return -1;
  }
  fflush(stdout);
  fflush(stderr);
  pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
    // the solve installs its own stop signals (go_ipopt_install_stop_signals); until then the
    // defaults, not the batch's handlers
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    execv(exe, argv);
    fprintf(stderr, "gaitsim: %s: %s\n", exe, strerror(errno));
    _exit(127);
  }
  close(fd);
  gs_batch_argv_free(argv);
  if (pid < 0) gs_error_set(err, errsz, "fork: %s", strerror(errno));
  else setpgid(pid, pid);  // also here: no race with the SIGINT that stops it
  return pid;
}

// run the solves in state RUN_WAIT, at most nmax at once, each after its dependencies ended
// (RUN_ENDED or RUN_KEPT); the exit status of gs_batch_run_local. A stop signal to the batch
// passes one SIGINT to each running solve, except a SIGTERM when term_reaches_solves (a Slurm
// job: scancel and the time limit send SIGTERM to every process of the job, the solve too), so
// that a solve receives one stop signal either way
static int run(const gsBatchPlan* plan, const char* dir, const char* exe, int nmax,
               int term_reaches_solves, runState* state, char* err, int errsz) {
  int n = plan->nsolve, going = 0, rc = GS_EXIT_OK;
  pid_t* pid = (pid_t*)calloc((size_t)n, sizeof(pid_t));
  double* t0 = (double*)calloc((size_t)n, sizeof(double));
  unsigned long long* fp = (unsigned long long*)calloc((size_t)n, sizeof(*fp));
  char* stopped = (char*)calloc((size_t)n, 1);
  if (!pid || !t0 || !fp || !stopped) {
    gs_error_set(err, errsz, "out of memory");
    free(pid), free(t0), free(fp), free(stopped);
    return GS_EXIT_FAILURE;
  }
  struct sigaction sa, old_int, old_term;
  memset(&sa, 0, sizeof(sa));
  sa.sa_handler = on_stop;  // no SA_RESTART: waitpid returns on the signal
  sigemptyset(&sa.sa_mask);
  g_stop = 0;
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  for (;;) {
    // skip the dependants of failures; start what is ready
    for (int i = 0; i < n; i++) {
      if (state[i] != RUN_WAIT) continue;
      int ready = 1, dead = 0;
      for (int k = 0; k < plan->solve[i].ndeps; k++) {
        runState d = state[plan->solve[i].deps[k]];
        dead |= d == RUN_BAD || d == RUN_SKIPPED;
        ready &= d == RUN_ENDED || d == RUN_KEPT;
      }
      if (dead) {
        state[i] = RUN_SKIPPED;
        printf("batch: %s: skipped (a solve it depends on failed)\n", plan->solve[i].name);
        i = -1;  // its own dependants come later in the order; look again from the start
        continue;
      }
      if (!ready || going >= nmax || g_stop) continue;
      fp[i] = gs_batch_fingerprint(plan, i, dir);
      pid[i] = start(plan, i, dir, exe, err, errsz);
      if (pid[i] < 0) {
        fprintf(stderr, "gaitsim: %s: %s\n", plan->solve[i].name, err);
        err[0] = 0;
        state[i] = RUN_BAD;
        i = -1;
        continue;
      }
      t0[i] = now_s();
      state[i] = RUN_GOING;
      going++;
      printf("batch: %s: started (%s)\n", plan->solve[i].name,
             plan->solve[i].kind == GS_BATCH_TRACK ? "track" : "predict");
      fflush(stdout);
    }
    if (going == 0) break;
    if (g_stop) {  // ask every running solve, once, to stop with its best iterate
      for (int i = 0; i < n; i++)
        if (state[i] == RUN_GOING && !stopped[i]) {
          if (!(term_reaches_solves && g_stop == SIGTERM)) kill(pid[i], SIGINT);
          stopped[i] = 1;
        }
    }
    int st = 0;
    pid_t w = waitpid(-1, &st, 0);
    if (w < 0) {
      if (errno == EINTR) continue;
      break;  // no children left (should not happen while going > 0)
    }
    for (int i = 0; i < n; i++) {
      if (state[i] != RUN_GOING || pid[i] != w) continue;
      double wall = now_s() - t0[i];
      write_record(plan, i, dir, exe, fp[i], st, wall, stopped[i]);
      int code = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 127);
      int good = !stopped[i] && (code == GS_EXIT_OK || code == GS_EXIT_STOPPED_SHORT);
      state[i] = good ? RUN_ENDED : RUN_BAD;
      going--;
      gsBatchRecord r = {1, code, stopped[i], wall, fp[i]};
      printf("batch: %s: exit %d, %s, %.1f s\n", plan->solve[i].name, code,
             gs_batch_record_status(&r), wall);
      fflush(stdout);
    }
  }
  sigaction(SIGINT, &old_int, NULL);
  sigaction(SIGTERM, &old_term, NULL);
  for (int i = 0; i < n; i++) {
    gsBatchRecord r;
    gs_batch_record_read(dir, plan->solve[i].name, &r);
    if (stopped[i]) {  // stopped by the batch: short of its end, not failed
      if (rc == GS_EXIT_OK) rc = GS_EXIT_STOPPED_SHORT;
      continue;
    }
    if (state[i] == RUN_BAD || state[i] == RUN_SKIPPED || (state[i] == RUN_WAIT && !g_stop))
      rc = GS_EXIT_FAILURE;
    else if (rc == GS_EXIT_OK && (state[i] == RUN_WAIT || r.exit == GS_EXIT_STOPPED_SHORT))
      rc = GS_EXIT_STOPPED_SHORT;
  }
  if (g_stop && rc == GS_EXIT_OK) rc = GS_EXIT_STOPPED_SHORT;
  if (g_stop) printf("batch: stopped by signal %d\n", (int)g_stop);
  free(pid), free(t0), free(fp), free(stopped);
  return rc;
}

int gs_batch_run_local(const gsBatchPlan* plan, const char* dir, const char* exe, int nmax,
                       char* err, int errsz) {
  int n = plan->nsolve;
  char* complete = (char*)calloc((size_t)n, 1);
  runState* state = (runState*)calloc((size_t)n, sizeof(runState));
  if (!complete || !state) {
    free(complete), free(state);
    gs_error_set(err, errsz, "out of memory");
    return GS_EXIT_FAILURE;
  }
  gs_batch_complete(plan, dir, complete);
  int kept = 0;
  for (int i = 0; i < n; i++) {
    state[i] = complete[i] ? RUN_KEPT : RUN_WAIT;
    kept += complete[i];
  }
  printf("batch: %d solves, %d kept from an earlier run, at most %d at once\n", n, kept, nmax);
  int rc = run(plan, dir, exe, nmax, 0, state, err, errsz);
  const char** word = (const char**)calloc((size_t)n, sizeof(char*));
  for (int i = 0; word && i < n; i++)
    word[i] = state[i] == RUN_SKIPPED ? "skipped" : state[i] == RUN_WAIT ? "not run" : NULL;
  if (gs_batch_collect(plan, dir, word, stdout, err, errsz) != 0) rc = GS_EXIT_FAILURE;
  free(word), free(complete), free(state);
  return rc;
}

int gs_batch_run_one(const gsBatchPlan* plan, const char* dir, const char* exe, const char* name,
                     char* err, int errsz) {
  int i = gs_batch_plan_find(plan, name);
  if (i < 0) {
    gs_error_set(err, errsz, "no solve \"%s\" in the plan", name);
    return GS_EXIT_FAILURE;
  }
  runState* state = (runState*)calloc((size_t)plan->nsolve, sizeof(runState));
  if (!state) {
    gs_error_set(err, errsz, "out of memory");
    return GS_EXIT_FAILURE;
  }
  for (int k = 0; k < plan->nsolve; k++) state[k] = k == i ? RUN_WAIT : RUN_KEPT;
  int rc = run(plan, dir, exe, 1, 1, state, err, errsz);
  free(state);
  // the table as far as the batch has come (the other jobs rewrite it as they end)
  char cerr[512];
  gs_batch_collect(plan, dir, NULL, NULL, cerr, sizeof(cerr));
  return rc == GS_EXIT_FAILURE ? GS_EXIT_FAILURE : GS_EXIT_OK;
}

// number of key in obj, or NAN
static double num(const cJSON* obj, const char* key) {
  const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, key);
  return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

// append to a growing buffer
typedef struct textBuf_ {
  char* s;      // the text (owned, NUL-terminated)
  size_t n;     // its length (bytes)
  size_t cap;   // allocated (bytes)
  int failed;   // 1 after an allocation failed
} textBuf;

static void put(textBuf* b, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(textBuf* b, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int len = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (b->failed || len < 0) return;
  if (b->n + (size_t)len + 1 > b->cap) {
    size_t cap = 2 * (b->n + (size_t)len + 1);
    char* s = (char*)realloc(b->s, cap);
    if (!s) {
      b->failed = 1;
      return;
    }
    b->s = s, b->cap = cap;
  }
  va_start(ap, fmt);
  vsnprintf(b->s + b->n, b->cap - b->n, fmt, ap);
  va_end(ap);
  b->n += (size_t)len;
}

// a number for the CSV ("" when missing) and the markdown ("-")
static void cell(textBuf* csv, textBuf* md, double x, const char* fmt) {
  char t[64];
  if (isfinite(x)) snprintf(t, sizeof(t), fmt, x);
  else t[0] = 0;
  put(csv, ",%s", t);
  put(md, " %s |", t[0] ? t : "-");
}

int gs_batch_collect(const gsBatchPlan* plan, const char* dir, const char* const* state,
                     FILE* out, char* err, int errsz) {
  // the Table 1 RMS errors of Lin, Walter & Pandy 2018 that a tracking summary.json has
  static const char* rms_keys[] = {"pelvis_rot_deg", "pelvis_trans_cm", "joint_rot_deg",
                                   "grf_ap_bw",      "grf_v_bw",        "grf_ml_bw",
                                   "knee_contact_bw"};
  enum { NRMS = (int)(sizeof(rms_keys) / sizeof(rms_keys[0])) };
  textBuf csv = {0}, md = {0};
  put(&csv, "solve,command,speed_target_mps,status,exit,wall_s,stride_time_s,speed_mps,"
            "cost_of_transport_j_per_kg_m");
  put(&md, "| solve | command | target speed (m/s) | status | exit | wall time (s) | stride time "
           "(s) | speed (m/s) | cost of transport (J/(kg m)) |");
  for (int q = 0; q < NRMS; q++) {
    put(&csv, ",rms_%s", rms_keys[q]);
    put(&md, " RMS %s |", rms_keys[q]);
  }
  put(&csv, "\n");
  put(&md, "\n|");
  for (int q = 0; q < 9 + NRMS; q++) put(&md, "---|");
  put(&md, "\n");
  char path[2 * GS_BATCH_PATH_MAX];
  for (int i = 0; i < plan->nsolve; i++) {
    const gsBatchSolve* s = &plan->solve[i];
    gsBatchRecord r;
    gs_batch_record_read(dir, s->name, &r);
    const char* st = state && state[i] ? state[i] : r.present ? gs_batch_record_status(&r)
                                                              : "not run";
    snprintf(path, sizeof(path), "%s/%s/summary.json", dir, s->name);
    cJSON* j = r.present ? gs_app_read_json(path) : NULL;
    const char* cmd = s->kind == GS_BATCH_TRACK ? "track" : "predict";
    put(&csv, "%s,%s", s->name, cmd);
    put(&md, "| %s | %s |", s->name, cmd);
    cell(&csv, &md, s->kind == GS_BATCH_PREDICT ? s->speed : NAN, "%.4g");
    put(&csv, ",%s", st);
    put(&md, " %s |", st);
    cell(&csv, &md, r.present ? r.exit : NAN, "%.0f");
    cell(&csv, &md, r.present ? r.wall_s : NAN, "%.1f");
    cell(&csv, &md, num(j, "stride_time_s"), "%.4f");
    cell(&csv, &md, num(j, "speed_mps"), "%.4f");
    double cot = num(j, "cost_of_transport_j_per_kg_m");
    cell(&csv, &md, isfinite(cot) ? cot : num(j, "cost_of_transport_exact_j_per_kg_m"), "%.4f");
    const cJSON* rms = s->kind == GS_BATCH_TRACK ? cJSON_GetObjectItemCaseSensitive(j, "rms")
                                                 : NULL;
    for (int q = 0; q < NRMS; q++) cell(&csv, &md, num(rms, rms_keys[q]), "%.4f");
    put(&csv, "\n");
    put(&md, "\n");
    cJSON_Delete(j);
  }
  int rc = -1;
  if (csv.failed || md.failed || !csv.s || !md.s) {
    gs_error_set(err, errsz, "out of memory");
  } else {
    snprintf(path, sizeof(path), "%s/batch.csv", dir);
    if (gs_atomic_write_buffer(path, csv.s, csv.n, err, errsz) == 0) {
      snprintf(path, sizeof(path), "%s/batch.md", dir);
      rc = gs_atomic_write_buffer(path, md.s, md.n, err, errsz);
    }
  }
  if (rc == 0 && out) fputs(md.s, out);
  free(csv.s);
  free(md.s);
  return rc;
}
