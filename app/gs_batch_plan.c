// gs_batch_plan.c: reading, expanding and validating a batch plan (gs_batch_plan.h).
#include "app/gs_batch_plan.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "io/gs_text.h"
#include "optim/go_defaults.h"
#include "optim/go_ipopt.h"

enum { KIND_TRACK = 1, KIND_PREDICT = 2 };  // bits: the commands an option belongs to

typedef enum optType_ {
  OPT_INT,      // JSON integer within [lo, hi]
  OPT_NUM,      // JSON number within [lo, hi] (above lo when lo_open)
  OPT_FLAG,     // true (false leaves it out)
  OPT_ENUM,     // one of the '|'-separated choices
  OPT_WEIGHT,   // NAME=W, W >= 0 (repeatable)
  OPT_IPOPT,    // KEY=VALUE, an Ipopt option (repeatable)
  OPT_FILE,     // an existing file (made absolute)
  OPT_SOLUTION  // a solve of the plan or a solution folder (track's --init)
} optType;

typedef struct optRule_ {
  const char* name;     // long option without the dashes
  unsigned kinds;       // KIND_TRACK | KIND_PREDICT
  optType type;         // value rule
  double lo, hi;        // range of OPT_INT, OPT_NUM
  int lo_open;          // 1: lo itself is out of range
  const char* choices;  // OPT_ENUM: "a|b|c"
} optRule;

// the options of `gaitsim track` and `gaitsim predict` and their rules (app/cmd_solve.c);
// --out, --guess and --speed come from the plan itself
static const optRule kRules[] = {
    {"model", KIND_TRACK | KIND_PREDICT, OPT_FILE, 0, 0, 0, NULL},
    {"nodes", KIND_TRACK | KIND_PREDICT, OPT_INT, 3, 1000000, 0, NULL},
    {"threads", KIND_TRACK | KIND_PREDICT, OPT_INT, 1, 64, 0, NULL},
    {"max-iter", KIND_TRACK | KIND_PREDICT, OPT_INT, 0, 1000000, 0, NULL},
    {"max-time", KIND_TRACK | KIND_PREDICT, OPT_NUM, 0, INFINITY, 1, NULL},
    {"weight", KIND_TRACK | KIND_PREDICT, OPT_WEIGHT, 0, 0, 0, NULL},
    {"ipopt", KIND_TRACK | KIND_PREDICT, OPT_IPOPT, 0, 0, 0, NULL},
    {"no-polish", KIND_TRACK | KIND_PREDICT, OPT_FLAG, 0, 0, 0, NULL},
    {"fallback-rise", KIND_TRACK | KIND_PREDICT, OPT_NUM, 0, INFINITY, 0, NULL},
    {"activation", KIND_TRACK, OPT_NUM, 0.001, 1, 0, NULL},
    {"hessian", KIND_TRACK, OPT_ENUM, 0, 0, 0, "lbfgs|pqn|gauss-newton|exact"},
    {"guess-method", KIND_TRACK, OPT_ENUM, 0, 0, 0, "trial|static"},
    {"refine", KIND_TRACK, OPT_INT, 0, 1000000, 0, NULL},
    {"refine-gn", KIND_TRACK, OPT_INT, 0, 1000000, 0, NULL},
    {"refine-time", KIND_TRACK, OPT_NUM, 0, INFINITY, 1, NULL},
    {"refine-after", KIND_TRACK, OPT_INT, 0, 1000000, 0, NULL},
    {"init", KIND_TRACK, OPT_SOLUTION, 0, 0, 0, NULL},
    {"no-fibre-bounds", KIND_PREDICT, OPT_FLAG, 0, 0, 0, NULL},
    {"metabolic-smoothing", KIND_PREDICT, OPT_NUM, 0, 1e3, 1, NULL},
    {"min-vgrf", KIND_PREDICT, OPT_NUM, 0, 10, 0, NULL},
    {"stride-time", KIND_PREDICT, OPT_NUM, 0.4, 2.5, 0, NULL},
    {"stride-time-start", KIND_PREDICT, OPT_NUM, 0.4, 2.5, 0, NULL},
    {"jacobian", KIND_PREDICT, OPT_ENUM, 0, 0, 0, "forward|central"},
    {"band-scale", KIND_PREDICT, OPT_NUM, 0, 10, 0, NULL},
};
#define NRULES ((int)(sizeof(kRules) / sizeof(kRules[0])))

static const optRule* find_rule(const char* name) {
  for (int r = 0; r < NRULES; r++)
    if (strcmp(kRules[r].name, name) == 0) return &kRules[r];
  return NULL;
}

// path made absolute against base (no check that it exists; empty when too long)
static void absolute(const char* base, const char* p, char* out) {
  int len = p[0] == '/' ? snprintf(out, GS_BATCH_PATH_MAX, "%s", p)
                        : snprintf(out, GS_BATCH_PATH_MAX, "%s/%s", base, p);
  if (len < 0 || len >= GS_BATCH_PATH_MAX) out[0] = 0;
}

static int is_file(const char* p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static int file_in(const char* dir, const char* name) {
  char p[GS_BATCH_PATH_MAX + 64];
  snprintf(p, sizeof(p), "%s/%s", dir, name);
  return is_file(p);
}

// one value of option rule r: 0, or -1 with the reason in why
static int check_value(const optRule* r, const cJSON* v, const char* base, char* why, int n) {
  char err[256];
  switch (r->type) {
    case OPT_INT:
    case OPT_NUM: {
      double x = cJSON_IsNumber(v) ? v->valuedouble : NAN;
      int ok = isfinite(x) && x <= r->hi && (r->lo_open ? x > r->lo : x >= r->lo);
      if (r->type == OPT_INT) ok = ok && x == floor(x);
      if (!ok) {
        snprintf(why, (size_t)n, "%s %s%.10g and <= %.10g expected", r->type == OPT_INT ? "an integer"
                                                                            : "a number",
                 r->lo_open ? "> " : ">= ", r->lo, r->hi);
        return -1;
      }
      return 0;
    }
    case OPT_FLAG:
      if (cJSON_IsBool(v)) return 0;
      snprintf(why, (size_t)n, "true or false expected (a flag)");
      return -1;
    default: break;
  }
  if (!cJSON_IsString(v)) {
    snprintf(why, (size_t)n, "a string expected");
    return -1;
  }
  const char* s = v->valuestring;
  switch (r->type) {
    case OPT_ENUM: {
      size_t len = strlen(s);
      for (const char* c = r->choices; *c;) {
        const char* bar = strchr(c, '|');
        size_t cl = bar ? (size_t)(bar - c) : strlen(c);
        if (cl == len && strncmp(c, s, len) == 0) return 0;
        c += cl + (bar != NULL);
      }
      snprintf(why, (size_t)n, "\"%s\" is not one of %s", s, r->choices);
      return -1;
    }
    case OPT_WEIGHT: {
      static const char* names[] = {"pelvis_rot", "pelvis_trans", "joint", "grf",
                                    "grm",        "effort",       "accel"};
      const char* eq = strchr(s, '=');
      char* end = NULL;
      double w = eq ? strtod(eq + 1, &end) : NAN;
      int known = 0;
      for (int i = 0; eq && i < 7; i++)
        known |= strlen(names[i]) == (size_t)(eq - s) && strncmp(s, names[i], (size_t)(eq - s)) == 0;
      if (!known || !end || *end || end == eq + 1 || !(w >= 0) || !isfinite(w)) {
        snprintf(why, (size_t)n, "\"%s\": NAME=W expected, NAME one of pelvis_rot, pelvis_trans, "
                 "joint, grf, grm, effort, accel, W >= 0", s);
        return -1;
      }
      return 0;
    }
    case OPT_IPOPT: {
      go_ipopt_opts o;
      go_ipopt_opts_default(&o);
      if (go_ipopt_opts_add(&o, s, err, sizeof(err)) != 0) {
        snprintf(why, (size_t)n, "%s", err);
        return -1;
      }
      return 0;
    }
    case OPT_FILE: {
      char p[GS_BATCH_PATH_MAX];
      absolute(base, s, p);
      if (is_file(p)) return 0;
      snprintf(why, (size_t)n, "no such file \"%s\"", p);
      return -1;
    }
    default: return 0;  // OPT_SOLUTION: resolved with the other references
  }
}

// the option object o (plan-wide when kinds == 0, else a solve's of those kinds): every key known
// and every value right; 0, or -1 with "FIELD: reason" in err
static int check_options(const cJSON* o, unsigned kinds, const char* field, const char* base,
                         char* err, int errsz) {
  if (!o) return 0;
  if (!cJSON_IsObject(o)) {
    gs_error_set(err, errsz, "%s: an object expected", field);
    return -1;
  }
  char why[GS_BATCH_PATH_MAX + 512];
  const cJSON* v;
  cJSON_ArrayForEach(v, o) {
    const optRule* r = find_rule(v->string);
    if (!r) {
      int reserved = !strcmp(v->string, "out") || !strcmp(v->string, "guess") ||
                     !strcmp(v->string, "speed");
      gs_error_set(err, errsz, "%s.%s: %s", field, v->string,
                   reserved ? "set by the plan (the solve's folder, \"guess\", \"predict\")"
                            : "unknown option");
      return -1;
    }
    if (kinds && !(r->kinds & kinds)) {
      gs_error_set(err, errsz, "%s.%s: not an option of gaitsim %s", field, v->string,
                   kinds == KIND_TRACK ? "track" : "predict");
      return -1;
    }
    int repeat = r->type == OPT_WEIGHT || r->type == OPT_IPOPT;
    if (repeat && cJSON_IsArray(v)) {
      const cJSON* e;
      cJSON_ArrayForEach(e, v) {
        if (check_value(r, e, base, why, sizeof(why)) != 0) {
          gs_error_set(err, errsz, "%s.%s: %s", field, v->string, why);
          return -1;
        }
      }
    } else if (check_value(r, v, base, why, sizeof(why)) != 0) {
      gs_error_set(err, errsz, "%s.%s: %s", field, v->string, why);
      return -1;
    }
  }
  return 0;
}

static int push_arg(gsBatchSolve* s, int* cap, const char* w) {
  if (s->nargs == *cap) {
    int nc = *cap ? 2 * *cap : 16;
    char** a = (char**)realloc(s->args, sizeof(char*) * (size_t)nc);
    if (!a) return -1;
    s->args = a;
    *cap = nc;
  }
  s->args[s->nargs] = gs_string_dup(w);
  return s->args[s->nargs++] ? 0 : -1;
}

// option words of one option (name, value) for solve s; model and init are kept apart
static int add_option(gsBatchSolve* s, int* cap, const cJSON* v, const char* base,
                      const char** init) {
  const optRule* r = find_rule(v->string);
  if (!(r->kinds & (s->kind == GS_BATCH_TRACK ? KIND_TRACK : KIND_PREDICT))) return 0;
  if (r->type == OPT_FILE) {
    absolute(base, v->valuestring, s->model);
    return 0;
  }
  if (r->type == OPT_SOLUTION) {
    *init = v->valuestring;
    return 0;
  }
  char flag[64], num[64];
  snprintf(flag, sizeof(flag), "--%s", r->name);
  if (r->type == OPT_FLAG) return cJSON_IsTrue(v) ? push_arg(s, cap, flag) : 0;
  if (cJSON_IsArray(v)) {
    const cJSON* e;
    cJSON_ArrayForEach(e, v) {
      if (push_arg(s, cap, flag) || push_arg(s, cap, e->valuestring)) return -1;
    }
    return 0;
  }
  if (cJSON_IsNumber(v)) snprintf(num, sizeof(num), "%.17g", v->valuedouble);
  return push_arg(s, cap, flag) || push_arg(s, cap, cJSON_IsNumber(v) ? num : v->valuestring);
}

static int add_dep(gsBatchSolve* s, int j) {
  for (int k = 0; k < s->ndeps; k++)
    if (s->deps[k] == j) return 0;
  int* d = (int*)realloc(s->deps, sizeof(int) * (size_t)(s->ndeps + 1));
  if (!d) return -1;
  s->deps = d;
  s->deps[s->ndeps++] = j;
  return 0;
}

void gs_batch_plan_free(gsBatchPlan* plan) {
  for (int i = 0; plan->solve && i < plan->nsolve; i++) {
    for (int k = 0; k < plan->solve[i].nargs; k++) free(plan->solve[i].args[k]);
    free(plan->solve[i].args);
    free(plan->solve[i].deps);
  }
  free(plan->solve);
  memset(plan, 0, sizeof(*plan));
}

int gs_batch_plan_find(const gsBatchPlan* plan, const char* name) {
  for (int i = 0; i < plan->nsolve; i++)
    if (strcmp(plan->solve[i].name, name) == 0) return i;
  return -1;
}

// the expanded solves that a plan name stands for: [first, first + count); count 0 when unknown
static int lookup(const gsBatchPlan* p, const cJSON* solves, const char* name, int* first) {
  int k = 0;
  const cJSON* s;
  cJSON_ArrayForEach(s, solves) {
    const cJSON* sw = cJSON_GetObjectItemCaseSensitive(s, "sweep");
    int n = cJSON_IsArray(sw) ? cJSON_GetArraySize(sw) : 1;
    const cJSON* nm = cJSON_GetObjectItemCaseSensitive(s, "name");
    if (strcmp(nm->valuestring, name) == 0) {
      *first = k;
      return n;
    }
    k += n;
  }
  int i = gs_batch_plan_find(p, name);  // one speed of a sweep, NAME_V
  *first = i;
  return i >= 0;
}

// "guess" or "init" of solve s (plan entry index idx): a solve of the plan (a dependency) or a
// solution folder
static int resolve_from(gsBatchPlan* p, const cJSON* solves, gsBatchSolve* s, const char* ref,
                        const char* field, char* err, int errsz) {
  int first, n = lookup(p, solves, ref, &first);
  if (n > 1) {
    gs_error_set(err, errsz, "solves[%d].%s: \"%s\" is a sweep; name one of its speeds "
                 "(e.g. \"%s\")", s->index, field, ref, p->solve[first].name);
    return -1;
  }
  if (n == 1) {
    s->from = first;
    s->input[0] = 0;
    return add_dep(s, first);
  }
  char dir[GS_BATCH_PATH_MAX];
  absolute(p->base, ref, dir);
  if (!file_in(dir, "states.sto") || !file_in(dir, "controls.sto")) {
    gs_error_set(err, errsz, "solves[%d].%s: neither a solve of the plan nor a solution folder "
                 "(states.sto, controls.sto): \"%s\"", s->index, field, ref);
    return -1;
  }
  snprintf(s->input, GS_BATCH_PATH_MAX, "%s", dir);
  return 0;
}

// depth-first search for a cycle through solve i; the path so far in stack (depth d)
static int find_cycle(const gsBatchPlan* p, int i, char* mark, int* stack, int d, int* len) {
  mark[i] = 1;  // on the path
  stack[d] = i;
  for (int k = 0; k < p->solve[i].ndeps; k++) {
    int j = p->solve[i].deps[k];
    if (mark[j] == 1) {
      stack[d + 1] = j;
      *len = d + 2;
      return 1;
    }
    if (mark[j] == 0 && find_cycle(p, j, mark, stack, d + 1, len)) return 1;
  }
  mark[i] = 2;  // finished
  return 0;
}

// reorder the solves so that every solve comes after its dependencies (they have no cycle)
static int topological(gsBatchPlan* p) {
  int n = p->nsolve;
  int* order = (int*)malloc(sizeof(int) * (size_t)n);
  int* pos = (int*)malloc(sizeof(int) * (size_t)n);
  char* done = (char*)calloc((size_t)n, 1);
  gsBatchSolve* s = (gsBatchSolve*)malloc(sizeof(gsBatchSolve) * (size_t)n);
  if (!order || !pos || !done || !s) {
    free(order), free(pos), free(done), free(s);
    return -1;
  }
  // repeatedly take, in plan order, the first solve whose dependencies are all taken
  for (int m = 0; m < n; m++) {
    for (int i = 0; i < n; i++) {
      int ready = !done[i];
      for (int k = 0; ready && k < p->solve[i].ndeps; k++) ready = done[p->solve[i].deps[k]];
      if (ready) {
        done[i] = 1;
        order[m] = i;
        pos[i] = m;
        break;
      }
    }
  }
  for (int m = 0; m < n; m++) {
    s[m] = p->solve[order[m]];
    for (int k = 0; k < s[m].ndeps; k++) s[m].deps[k] = pos[s[m].deps[k]];
    if (s[m].from >= 0) s[m].from = pos[s[m].from];
  }
  free(p->solve);
  p->solve = s;
  free(order), free(pos), free(done);
  return 0;
}

// a solve name: letters, digits, '_', '-', '.', not starting with '.', and not one of the
// batch's own entries in DIR
static int valid_name(const char* s) {
  static const char* taken[] = {"logs", "slurm", "plan.json", "batch.csv", "batch.md"};
  if (!*s || strlen(s) >= GS_BATCH_NAME_MAX - 16 || s[0] == '.') return 0;
  for (size_t k = 0; k < sizeof(taken) / sizeof(taken[0]); k++)
    if (strcmp(s, taken[k]) == 0) return 0;
  for (const char* c = s; *c; c++)
    if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
          *c == '_' || *c == '-' || *c == '.'))
      return 0;
  return 1;
}

// Slurm resources from obj (the plan's or a solve's "slurm") into s
static int slurm_resources(const cJSON* obj, gsBatchSolve* s, const char* field, char* err,
                           int errsz) {
  if (!obj) return 0;
  if (!cJSON_IsObject(obj)) {
    gs_error_set(err, errsz, "%s: an object expected", field);
    return -1;
  }
  const cJSON* v;
  cJSON_ArrayForEach(v, obj) {
    int* slot = !strcmp(v->string, "cpus")       ? &s->cpus
                : !strcmp(v->string, "time_min") ? &s->time_min
                : !strcmp(v->string, "mem_mb")   ? &s->mem_mb
                                                 : NULL;
    if (slot && cJSON_IsNumber(v) && v->valuedouble >= 1 && v->valuedouble <= 1e7 &&
        v->valuedouble == floor(v->valuedouble)) {
      *slot = (int)v->valuedouble;
    } else if (!strcmp(v->string, "partition") && cJSON_IsString(v) &&
               strlen(v->valuestring) < sizeof(s->partition)) {
      snprintf(s->partition, sizeof(s->partition), "%s", v->valuestring);
    } else {
      gs_error_set(err, errsz, "%s.%s: %s", field, v->string,
                   slot || !strcmp(v->string, "partition")
                       ? "a positive integer (cpus, time_min, mem_mb) or a name (partition) "
                         "expected"
                       : "unknown (cpus, time_min, mem_mb, partition)");
      return -1;
    }
  }
  return 0;
}

// an option's integer value in s's words (e.g. --nodes 20), or dflt
static int arg_int(const gsBatchSolve* s, const char* flag, int dflt) {
  for (int k = 0; k + 1 < s->nargs; k++)
    if (strcmp(s->args[k], flag) == 0) return atoi(s->args[k + 1]);
  return dflt;
}

// fill solve s (entry e of the plan, index idx, speed v for a predict) apart from references
static int fill_solve(gsBatchPlan* p, const cJSON* root, const cJSON* e, int idx, gsBatchSolve* s,
                      const char* name, double v, const char** init, char* err, int errsz) {
  int cap = 0;
  snprintf(s->name, sizeof(s->name), "%s", name);
  s->index = idx;
  s->from = -1;
  s->speed = v;
  const cJSON* model = cJSON_GetObjectItemCaseSensitive(root, "model");
  if (cJSON_IsString(model)) absolute(p->base, model->valuestring, s->model);
  // the plan's options that the solve does not set itself, then the solve's
  const cJSON* po = cJSON_GetObjectItemCaseSensitive(root, "options");
  const cJSON* so = cJSON_GetObjectItemCaseSensitive(e, "options");
  const cJSON* o;
  cJSON_ArrayForEach(o, po) {
    if (!cJSON_GetObjectItemCaseSensitive(so, o->string) && add_option(s, &cap, o, p->base, init))
      goto oom;
  }
  cJSON_ArrayForEach(o, so) {
    if (add_option(s, &cap, o, p->base, init)) goto oom;
  }
  if (s->model[0] && (push_arg(s, &cap, "--model") || push_arg(s, &cap, s->model))) goto oom;
  // Slurm: CPUs from --threads (the commands' default 2); time from the iterations and nodes at
  // 0.05 s per node and iteration (the full-body tracking solve's 1.0 s per iteration at 80
  // nodes, docs/BENCHMARKS.md, with a margin), at least 10 min; memory 1 GB plus 20 MB per node
  // (measured peak of the full-body track with L-BFGS: 120 MB at 20 nodes, 238 MB at 80; the
  // exact-Hessian refinement's factorisation needs more, a margin left for it, not measured)
  s->cpus = arg_int(s, "--threads", 2);
  // (a prediction without --nodes solves on its guess's mesh: the tracking default bounds it)
  int nodes = arg_int(s, "--nodes", GO_NODES_TRACK);
  // iterations: a prediction's own limit (predict's default GO_MAX_ITER); for a track 1000, within
  // which its 60 Gauss-Newton iterations and its refinement (60 Gauss-Newton, up to 150 Newton
  // iterations at about 6 times a Gauss-Newton one's cost) stay
  int iter = arg_int(s, "--max-iter", s->speed > 0 ? GO_MAX_ITER : 1000);
  s->time_min = 10 + (int)(0.05 * nodes * iter / 60);
  s->mem_mb = 1024 + 20 * nodes;
  if (slurm_resources(cJSON_GetObjectItemCaseSensitive(root, "slurm"), s, "slurm", err, errsz))
    return -1;
  char field[64];
  snprintf(field, sizeof(field), "solves[%d].slurm", idx);
  return slurm_resources(cJSON_GetObjectItemCaseSensitive(e, "slurm"), s, field, err, errsz);
oom:
  gs_error_set(err, errsz, "out of memory");
  return -1;
}

// the plan document (already parsed) into p; 0 or -1 and err
static int load(gsBatchPlan* p, const cJSON* root, char* err, int errsz) {
  const cJSON* solves = cJSON_GetObjectItemCaseSensitive(root, "solves");
  if (!cJSON_IsObject(root) || !cJSON_IsArray(solves) || cJSON_GetArraySize(solves) == 0) {
    gs_error_set(err, errsz, "solves: a non-empty list of solves expected");
    return -1;
  }
  const cJSON* v;
  cJSON_ArrayForEach(v, root) {
    if (strcmp(v->string, "model") && strcmp(v->string, "options") &&
        strcmp(v->string, "slurm") && strcmp(v->string, "solves") &&
        strcmp(v->string, "base_dir")) {
      gs_error_set(err, errsz, "%s: unknown key (model, options, slurm, solves)", v->string);
      return -1;
    }
  }
  const cJSON* model = cJSON_GetObjectItemCaseSensitive(root, "model");
  char path[GS_BATCH_PATH_MAX];
  if (model) {
    if (cJSON_IsString(model)) absolute(p->base, model->valuestring, path);
    if (!cJSON_IsString(model) || !is_file(path)) {
      gs_error_set(err, errsz, "model: no such file \"%s\"",
                   cJSON_IsString(model) ? path : "(not a string)");
      return -1;
    }
  }
  if (check_options(cJSON_GetObjectItemCaseSensitive(root, "options"), 0, "options", p->base,
                    err, errsz))
    return -1;
  // each entry: its name, one of track / predict / sweep, its options; count the solves
  int n = 0, idx = 0;
  const cJSON* e;
  char field[64];
  cJSON_ArrayForEach(e, solves) {
    const cJSON* nm = cJSON_GetObjectItemCaseSensitive(e, "name");
    if (!cJSON_IsObject(e) || !cJSON_IsString(nm) || !valid_name(nm->valuestring)) {
      gs_error_set(err, errsz, "solves[%d].name: a name of letters, digits, '_', '-', '.' "
                   "expected (it names the solve's folder; not logs, slurm, plan.json, "
                   "batch.csv, batch.md)", idx);
      return -1;
    }
    const cJSON* tr = cJSON_GetObjectItemCaseSensitive(e, "track");
    const cJSON* pr = cJSON_GetObjectItemCaseSensitive(e, "predict");
    const cJSON* sw = cJSON_GetObjectItemCaseSensitive(e, "sweep");
    if ((tr != NULL) + (pr != NULL) + (sw != NULL) != 1) {
      gs_error_set(err, errsz, "solves[%d]: exactly one of \"track\" (a trial folder), "
                   "\"predict\" (a speed) or \"sweep\" (speeds) expected", idx);
      return -1;
    }
    cJSON_ArrayForEach(v, e) {
      static const char* keys[] = {"name", "track", "predict", "sweep", "start", "guess",
                                   "depends", "options", "slurm"};
      int known = 0;
      for (int k = 0; k < 9; k++) known |= !strcmp(v->string, keys[k]);
      if (!known) {
        gs_error_set(err, errsz, "solves[%d].%s: unknown key (name, track, predict, sweep, "
                     "start, guess, depends, options, slurm)", idx, v->string);
        return -1;
      }
    }
    const cJSON* st = cJSON_GetObjectItemCaseSensitive(e, "start");
    if (st && (!sw || !cJSON_IsString(st) || (strcmp(st->valuestring, "guess") &&
                                              strcmp(st->valuestring, "neighbour")))) {
      gs_error_set(err, errsz, "solves[%d].start: \"guess\" or \"neighbour\" expected, with a "
                   "\"sweep\"", idx);
      return -1;
    }
    snprintf(field, sizeof(field), "solves[%d].options", idx);
    if (check_options(cJSON_GetObjectItemCaseSensitive(e, "options"),
                      tr ? KIND_TRACK : KIND_PREDICT, field, p->base, err, errsz))
      return -1;
    if (tr) {
      if (cJSON_IsString(tr)) absolute(p->base, tr->valuestring, path);
      if (!cJSON_IsString(tr) || !file_in(path, "coordinates.mot") || !file_in(path, "grf.mot")) {
        gs_error_set(err, errsz, "solves[%d].track: no trial folder (coordinates.mot, grf.mot) "
                     "\"%s\"", idx, cJSON_IsString(tr) ? tr->valuestring : "(not a string)");
        return -1;
      }
    }
    const cJSON* g = cJSON_GetObjectItemCaseSensitive(e, "guess");
    if (tr && g) {
      gs_error_set(err, errsz, "solves[%d].guess: a track starts from options.init, not a guess",
                   idx);
      return -1;
    }
    if (!tr && !cJSON_IsString(g)) {
      gs_error_set(err, errsz, "solves[%d].guess: a solve's name or a solution folder expected",
                   idx);
      return -1;
    }
    if (pr && !(cJSON_IsNumber(pr) && pr->valuedouble > 0 && pr->valuedouble < 10)) {
      gs_error_set(err, errsz, "solves[%d].predict: a speed in m/s (0-10) expected", idx);
      return -1;
    }
    if (sw) {
      int ok = cJSON_IsArray(sw) && cJSON_GetArraySize(sw) > 0;
      cJSON_ArrayForEach(v, sw) ok = ok && cJSON_IsNumber(v) && v->valuedouble > 0 &&
                                     v->valuedouble < 10;
      if (!ok) {
        gs_error_set(err, errsz, "solves[%d].sweep: a list of speeds in m/s (0-10) expected",
                     idx);
        return -1;
      }
    }
    n += sw ? cJSON_GetArraySize(sw) : 1;
    idx++;
  }
  p->solve = (gsBatchSolve*)calloc((size_t)n, sizeof(gsBatchSolve));
  if (!p->solve) {
    gs_error_set(err, errsz, "out of memory");
    return -1;
  }
  // the solves, a sweep's speeds in its order; names unique
  const char** init = (const char**)calloc((size_t)n, sizeof(char*));
  int k = 0, rc = -1;
  idx = 0;
  cJSON_ArrayForEach(e, solves) {
    const char* name = cJSON_GetObjectItemCaseSensitive(e, "name")->valuestring;
    const cJSON* tr = cJSON_GetObjectItemCaseSensitive(e, "track");
    const cJSON* sw = cJSON_GetObjectItemCaseSensitive(e, "sweep");
    const cJSON* pr = cJSON_GetObjectItemCaseSensitive(e, "predict");
    int m = sw ? cJSON_GetArraySize(sw) : 1;
    for (int q = 0; q < m; q++, k++) {
      gsBatchSolve* s = &p->solve[k];
      char nm[GS_BATCH_NAME_MAX];
      double speed = sw ? cJSON_GetArrayItem(sw, q)->valuedouble : pr ? pr->valuedouble : 0;
      if (sw) snprintf(nm, sizeof(nm), "%s_%.4g", name, speed);
      else snprintf(nm, sizeof(nm), "%s", name);
      s->kind = tr ? GS_BATCH_TRACK : GS_BATCH_PREDICT;
      p->nsolve = k + 1;
      if (gs_batch_plan_find(p, nm) >= 0 && gs_batch_plan_find(p, nm) < k) {
        gs_error_set(err, errsz, "solves[%d].name: \"%s\" names two solves", idx, nm);
        goto done;
      }
      if (fill_solve(p, root, e, idx, s, nm, speed, &init[k], err, errsz)) goto done;
      if (tr) absolute(p->base, tr->valuestring, s->input);
    }
    idx++;
  }
  // references: guess / init (a solve of the plan or a folder; every speed of a sweep from its
  // guess, or with "start": "neighbour" each from the speed before), depends
  k = 0;
  idx = 0;
  cJSON_ArrayForEach(e, solves) {
    const cJSON* sw = cJSON_GetObjectItemCaseSensitive(e, "sweep");
    const cJSON* g = cJSON_GetObjectItemCaseSensitive(e, "guess");
    const cJSON* dep = cJSON_GetObjectItemCaseSensitive(e, "depends");
    const cJSON* st = cJSON_GetObjectItemCaseSensitive(e, "start");
    int chained = cJSON_IsString(st) && !strcmp(st->valuestring, "neighbour");
    int m = sw ? cJSON_GetArraySize(sw) : 1;
    if (dep && !cJSON_IsArray(dep)) {
      gs_error_set(err, errsz, "solves[%d].depends: a list of solve names expected", idx);
      goto done;
    }
    for (int q = 0; q < m; q++, k++) {
      gsBatchSolve* s = &p->solve[k];
      if (q > 0 && chained) {  // "start": "neighbour": from the speed before
        s->from = k - 1;
        if (add_dep(s, k - 1)) goto done;
      } else if (g && resolve_from(p, solves, s, g->valuestring, "guess", err, errsz)) {
        goto done;
      }
      if (init[k] && resolve_from(p, solves, s, init[k], "options.init", err, errsz)) goto done;
      if (init[k] && cJSON_IsString(cJSON_GetObjectItemCaseSensitive(
                         cJSON_GetObjectItemCaseSensitive(e, "options"), "guess-method")) &&
          !strcmp(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(e, "options"),
                                                   "guess-method")->valuestring, "static")) {
        gs_error_set(err, errsz, "solves[%d].options: init and guess-method \"static\" exclude "
                     "each other", idx);
        goto done;
      }
      const cJSON* d;
      cJSON_ArrayForEach(d, dep) {
        int first, c = cJSON_IsString(d) ? lookup(p, solves, d->valuestring, &first) : 0;
        if (c == 0) {
          gs_error_set(err, errsz, "solves[%d].depends: unknown solve \"%s\"", idx,
                       cJSON_IsString(d) ? d->valuestring : "(not a string)");
          goto done;
        }
        for (int j = first; j < first + c; j++)
          if (add_dep(s, j)) goto done;
      }
    }
    idx++;
  }
  // no cycles, then dependencies first
  char* mark = (char*)calloc((size_t)n, 1);
  int* stack = (int*)malloc(sizeof(int) * (size_t)(n + 1));
  int len = 0, cyc = 0;
  for (int i = 0; mark && stack && i < n && !cyc; i++)
    if (!mark[i]) cyc = find_cycle(p, i, mark, stack, 0, &len);
  if (cyc) {
    // the cycle is the path from the first appearance of its last solve
    int start = 0;
    while (stack[start] != stack[len - 1]) start++;
    char chain[1024] = "";
    for (int q = start; q < len; q++)
      snprintf(chain + strlen(chain), sizeof(chain) - strlen(chain), "%s%s", q > start ? " -> " : "",
               p->solve[stack[q]].name);
    gs_error_set(err, errsz, "solves[%d].depends: a cycle: %s (each waits for the next)",
                 p->solve[stack[start]].index, chain);
  }
  free(mark);
  free(stack);
  if (!cyc && topological(p) == 0) rc = 0;
done:
  free(init);
  return rc;
}

int gs_batch_plan_load(const char* path, const char* base, gsBatchPlan* plan, char* err,
                       int errsz) {
  memset(plan, 0, sizeof(*plan));
  snprintf(plan->path, sizeof(plan->path), "%s", path);
  FILE* f = fopen(path, "rb");
  if (!f) {
    gs_error_set(err, errsz, "cannot open the plan");
    return -1;
  }
  char* text = NULL;
  size_t len = 0, cap = 0, got;
  char chunk[65536];
  while ((got = fread(chunk, 1, sizeof(chunk), f)) > 0) {
    if (len + got + 1 > cap) {
      cap = 2 * (len + got + 1);
      char* t = (char*)realloc(text, cap);
      if (!t) break;
      text = t;
    }
    memcpy(text + len, chunk, got);
    len += got;
  }
  fclose(f);
  cJSON* root = text ? (text[len] = 0, cJSON_Parse(text)) : NULL;
  free(text);
  if (!root) {
    gs_error_set(err, errsz, "not a JSON document");
    return -1;
  }
  // relative paths: from base, the plan's "base_dir" (a copy in a batch folder), or its folder
  const cJSON* bd = cJSON_GetObjectItemCaseSensitive(root, "base_dir");
  char real[PATH_MAX];
  if (base) snprintf(plan->base, sizeof(plan->base), "%s", base);
  else if (cJSON_IsString(bd)) snprintf(plan->base, sizeof(plan->base), "%s", bd->valuestring);
  else if (realpath(path, real)) {
    *strrchr(real, '/') = 0;
    snprintf(plan->base, sizeof(plan->base), "%s", real[0] ? real : "/");
  }
  int rc = load(plan, root, err, errsz);
  cJSON_Delete(root);
  if (rc != 0) {
    char p[GS_BATCH_PATH_MAX];
    snprintf(p, sizeof(p), "%s", plan->path);
    gs_batch_plan_free(plan);
    snprintf(plan->path, sizeof(plan->path), "%s", p);
  }
  return rc;
}

char** gs_batch_argv(const gsBatchPlan* plan, int i, const char* exe, const char* dir) {
  const gsBatchSolve* s = &plan->solve[i];
  char** a = (char**)calloc((size_t)s->nargs + 12, sizeof(char*));
  if (!a) return NULL;
  char out[2 * GS_BATCH_PATH_MAX], from[2 * GS_BATCH_PATH_MAX], speed[32];
  snprintf(out, sizeof(out), "%s/%s", dir, s->name);
  if (s->from >= 0) snprintf(from, sizeof(from), "%s/%s", dir, plan->solve[s->from].name);
  snprintf(speed, sizeof(speed), "%.4g", s->speed);
  int n = 0;
  a[n++] = gs_string_dup(exe);
  if (s->kind == GS_BATCH_TRACK) {
    a[n++] = gs_string_dup("track");
    a[n++] = gs_string_dup(s->input);
    if (s->from >= 0) {
      a[n++] = gs_string_dup("--init");
      a[n++] = gs_string_dup(from);
    }
  } else {
    a[n++] = gs_string_dup("predict");
    a[n++] = gs_string_dup("--guess");
    a[n++] = gs_string_dup(s->from >= 0 ? from : s->input);
    a[n++] = gs_string_dup("--speed");
    a[n++] = gs_string_dup(speed);
  }
  a[n++] = gs_string_dup("--out");
  a[n++] = gs_string_dup(out);
  for (int k = 0; k < s->nargs; k++) a[n++] = gs_string_dup(s->args[k]);
  for (int k = 0; k < n; k++)
    if (!a[k]) {
      gs_batch_argv_free(a);
      return NULL;
    }
  return a;
}

void gs_batch_argv_free(char** argv) {
  for (int k = 0; argv && argv[k]; k++) free(argv[k]);
  free(argv);
}

// FNV-1a, 64 bits
static uint64_t fnv(uint64_t h, const void* data, size_t n) {
  const unsigned char* b = (const unsigned char*)data;
  for (size_t k = 0; k < n; k++) h = (h ^ b[k]) * 1099511628211ULL;
  return h;
}

static uint64_t fnv_file(uint64_t h, const char* dir, const char* name) {
  char p[2 * GS_BATCH_PATH_MAX + 64], buf[65536];
  if (name) snprintf(p, sizeof(p), "%s/%s", dir, name);
  else snprintf(p, sizeof(p), "%s", dir);
  FILE* f = fopen(p, "rb");
  if (!f) return fnv(h, "missing", 7);
  size_t got;
  while ((got = fread(buf, 1, sizeof(buf), f)) > 0) h = fnv(h, buf, got);
  fclose(f);
  return h;
}

uint64_t gs_batch_fingerprint(const gsBatchPlan* plan, int i, const char* dir) {
  const gsBatchSolve* s = &plan->solve[i];
  uint64_t h = 14695981039346656037ULL;
  char** a = gs_batch_argv(plan, i, "", dir);
  for (int k = 1; a && a[k]; k++) h = fnv(h, a[k], strlen(a[k]) + 1);
  gs_batch_argv_free(a);
  if (s->kind == GS_BATCH_TRACK) {
    h = fnv_file(h, s->input, "coordinates.mot");
    h = fnv_file(h, s->input, "grf.mot");
  }
  char from[2 * GS_BATCH_PATH_MAX];
  if (s->from >= 0) snprintf(from, sizeof(from), "%s/%s", dir, plan->solve[s->from].name);
  else snprintf(from, sizeof(from), "%s", s->input);
  if (s->kind == GS_BATCH_PREDICT || s->from >= 0) h = fnv_file(h, from, "summary.json");
  if (s->model[0]) h = fnv_file(h, s->model, NULL);
  return h;
}
