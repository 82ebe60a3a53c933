// gs_app_model.c: model preparation and table I/O shared by the subcommands.
#include "app/gs_app_model.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "callbacks/gs_balance.h"
#include "callbacks/gs_coupling.h"
#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "io/gs_storage.h"

// the whole file at path, NUL-terminated (caller frees), or NULL when it cannot be read
static char* read_text(const char* path) {
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  char* text = NULL;
  size_t len = 0, got;
  char buf[8192];
  while ((got = fread(buf, 1, sizeof(buf), f)) > 0) {
    char* t = (char*)realloc(text, len + got + 1);
    if (!t) {
      free(text);
      fclose(f);
      return NULL;
    }
    text = t;
    memcpy(text + len, buf, got);
    len += got;
  }
  fclose(f);
  if (text) text[len] = 0;
  return text;
}

// An MJCF file must say <compiler angle="radian">: gaitsim's numbers (joint ranges, keyframes,
// storage files converted from degrees) are radians, and MuJoCo's default is degrees, which
// would silently turn a range of 1.5 into 1.5 degrees. 0, or -1 with err. Binary models (.mjb)
// are compiled already.
static int check_radians(const char* path, char* err, int errsz) {
  size_t n = strlen(path);
  if (n < 4 || strcmp(path + n - 4, ".xml") != 0) return 0;
  char* text = read_text(path);
  if (!text) return 0;  // gs_model_load reports it
  int radian = 0, degree = 0;
  for (const char* c = strstr(text, "<compiler"); c; c = strstr(c + 1, "<compiler")) {
    const char* end = strchr(c, '>');
    const char* a = strstr(c, "angle=");
    if (!end || !a || a > end) continue;
    a += 6;
    char q = *a == '"' || *a == '\'' ? *a++ : 0;
    radian |= strncmp(a, "radian", 6) == 0 && (!q || a[6] == q);
    degree |= strncmp(a, "degree", 6) == 0 && (!q || a[6] == q);
  }
  free(text);
  if (radian && !degree) return 0;
  snprintf(err, (size_t)errsz, "angles must be in radians: <compiler angle=\"radian\"> %s",
           degree ? "(the model says degree)" : "is missing (MuJoCo's default is degree)");
  return -1;
}

mjModel* gs_app_load_model(const char* path) {
  char err[1024];
  if (check_radians(path, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    return NULL;
  }
  mjModel* m = gs_model_load(path, err, sizeof(err));
  if (!m) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    return NULL;
  }
  if (gs_physics_prepare(m, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    mj_deleteModel(m);
    return NULL;
  }
  gs_physics_install();
  return m;
}

int gs_app_read_table(const mjModel* m, const char* path, gsTable* t) {
  char err[1024];
  gs_table_init(t);
  if (gs_storage_read(path, t, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    return -1;
  }
  gs_table_to_radians(t, gs_state_is_angle, (void*)m);
  return 0;
}

int gs_app_write_table(const char* dir, const char* name, const gsTable* t) {
  char path[4096], err[1024];
  snprintf(path, sizeof(path), "%s/%s", dir, name);
  const char* header[] = {"gaitsim_version=" GAITSIM_VERSION};
  if (gs_storage_write(path, t, header, 1, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    return -1;
  }
  return 0;
}

cJSON* gs_app_read_json(const char* path) {
  char* text = read_text(path);
  if (!text) return NULL;
  cJSON* j = cJSON_Parse(text);
  free(text);
  return j;
}

const char* gs_app_solution_model(const char* dir, char* buf, int n) {
  char path[4096];
  snprintf(path, sizeof(path), "%s/summary.json", dir);
  cJSON* j = gs_app_read_json(path);
  const cJSON* model = j ? cJSON_GetObjectItemCaseSensitive(j, "model") : NULL;
  const char* found = NULL;
  if (cJSON_IsString(model) && model->valuestring[0] &&
      snprintf(buf, (size_t)n, "%s", model->valuestring) < n) {
    FILE* f = fopen(buf, "rb");
    if (f) {
      fclose(f);
      found = buf;
    }
  }
  cJSON_Delete(j);
  return found;
}

// the "nodes" of a parsed summary.json: 1 with *nodes set when it is a node count (an integer
// in [1, 1e6]), 0 when absent, -1 when present but not a node count
static int summary_nodes(const cJSON* summary, int* nodes) {
  const cJSON* n = cJSON_GetObjectItemCaseSensitive(summary, "nodes");
  if (!n) return 0;
  double v = cJSON_IsNumber(n) ? n->valuedouble : 0;
  if (!(cJSON_IsNumber(n) && v >= 1 && v <= 1e6 && v == floor(v))) return -1;
  *nodes = (int)v;
  return 1;
}

int gs_app_solution_nodes(const char* dir) {
  char path[4096];
  snprintf(path, sizeof(path), "%s/summary.json", dir);
  cJSON* j = gs_app_read_json(path);
  int n = -1;
  if (!j || summary_nodes(j, &n) != 1) n = -1;
  cJSON_Delete(j);
  return n;
}

int gs_app_check_solution(const char* dir, int require_summary) {
  char path[4096], err[1024];
  struct stat st;
  if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
    fprintf(stderr, "gaitsim: %s: %s\n", dir,
            stat(dir, &st) != 0 ? strerror(errno) : "not a folder");
    return -1;
  }
  // summary.json: valid when present; its node count
  snprintf(path, sizeof(path), "%s/summary.json", dir);
  int nodes = -1;
  if (access(path, F_OK) == 0) {
    cJSON* j = gs_app_read_json(path);
    if (!j) {
      fprintf(stderr, "gaitsim: %s: unreadable or not valid JSON (an incomplete solution "
              "folder?)\n", path);
      return -1;
    }
    if (summary_nodes(j, &nodes) < 0) {
      fprintf(stderr, "gaitsim: %s: \"nodes\" is not a node count\n", path);
      cJSON_Delete(j);
      return -1;
    }
    cJSON_Delete(j);
  } else if (require_summary) {
    fprintf(stderr, "gaitsim: %s: no summary.json: not a complete solution folder\n", dir);
    return -1;
  }
  // every storage file reads; the node tables agree
  static const char* files[] = {"states.sto", "controls.sto", "variables.sto", "grf.mot",
                                "muscle_forces.sto", "metabolics.sto", "knee_contact.sto"};
  int rows = nodes, rows_from = -1;  // rows_from: files[] index that set rows, -1 summary
  for (int i = 0; i < (int)(sizeof(files) / sizeof(files[0])); i++) {
    snprintf(path, sizeof(path), "%s/%s", dir, files[i]);
    if (access(path, F_OK) != 0) {
      if (i > 0) continue;
      fprintf(stderr, "gaitsim: %s: missing: not a complete solution folder\n", path);
      return -1;
    }
    gsTable t;
    gs_table_init(&t);
    if (gs_storage_read(path, &t, err, sizeof(err)) != 0) {
      fprintf(stderr, "gaitsim: %s\n", err);
      return -1;
    }
    int n = t.nrow;
    gs_table_free(&t);
    if (i > 2) continue;
    if (rows >= 0 && n != rows) {
      fprintf(stderr, "gaitsim: %s: %d rows, but %s %d: files of different solutions\n", path,
              n, rows_from < 0 ? "summary.json says nodes =" : files[rows_from], rows);
      return -1;
    }
    if (rows < 0) rows = n, rows_from = i;
  }
  return 0;
}

int gs_app_require_coordinates(const mjModel* m, const gsTable* t, const char* path) {
  char list[512] = "";
  int missing = 0, total = 0;
  size_t len = 0;
  for (int j = 0; j < m->njnt; j++) {
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) continue;
    total++;
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    if (name && gs_table_column(t, name) >= 0) continue;
    if (gs_coupling_joint_follows(m, j)) continue;  // follows its driver (gs_state_apply)
    if (missing < 6 && len < sizeof(list)) {
      len += (size_t)snprintf(list + len, sizeof(list) - len, "%s%s", missing ? ", " : "",
                              name ? name : "(unnamed)");
    } else if (missing == 6 && len < sizeof(list)) {
      len += (size_t)snprintf(list + len, sizeof(list) - len, ", ...");
    }
    missing++;
  }
  if (missing == 0) return 0;
  fprintf(stderr, "gaitsim: %s: no column for %d of the model's %d coordinates: %s\n", path,
          missing, total, list);
  return -1;
}

int gs_app_check_pose_file(const mjModel* m, const char* path) {
  char err[1024];
  gsTable t;
  gs_table_init(&t);
  int rc = gs_storage_read(path, &t, err, sizeof(err));
  if (rc != 0) fprintf(stderr, "gaitsim: %s\n", err);
  else rc = gs_app_require_coordinates(m, &t, path);
  gs_table_free(&t);
  return rc;
}

const char* gs_app_model_for_solution(const char* dir, const char* given, char* buf, int n) {
  if (given) return given;
  return gs_app_solution_model(dir, buf, n) ? buf : GS_DEFAULT_MODEL;
}

int gs_app_read_pose_and_loads(const mjModel* m, const char* pose, const char* grf, gsTable* t,
                               gsStateMap* map, gsTable* g, int col[GS_GRF_NCOL]) {
  char err[512];
  if (gs_app_read_table(m, pose, t) != 0 || gs_app_require_coordinates(m, t, pose) != 0)
    return -1;
  if (gs_state_map(m, t, map, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", pose, err);
    return -1;
  }
  if (t->nrow < 3) {
    fprintf(stderr, "gaitsim: %s: %d rows; the differences need at least 3\n", pose, t->nrow);
    return -1;
  }
  if (gs_app_read_table(m, grf, g) != 0) return -1;
  if (gs_balance_grf_columns(g, col, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", grf, err);
    return -1;
  }
  return 0;
}

int gs_app_pose_kinematics(const mjModel* m, mjData* d, const gsTable* t,
                           const gsStateMap* map, double* q, double* v, double* a) {
  int n = t->nrow, nq = m->nq, nv = m->nv;
  for (int i = 0; i < n; i++) {
    mj_resetData(m, d);
    gs_state_apply(m, t, map, t->time[i], d);
    mju_copy(q + i * nq, d->qpos, nq);
    mju_copy(v + i * nv, d->qvel, nv);
  }
  // central differences between the neighbouring rows (one-sided at the ends)
  int speeds = map->nv_found == nv;
  for (int i = 0; !speeds && i < n; i++) {
    int i0 = i > 0 ? i - 1 : 0, i1 = i < n - 1 ? i + 1 : n - 1;
    mj_differentiatePos(m, v + i * nv, t->time[i1] - t->time[i0], q + i0 * nq, q + i1 * nq);
  }
  for (int i = 0; i < n; i++) {
    int i0 = i > 0 ? i - 1 : 0, i1 = i < n - 1 ? i + 1 : n - 1;
    for (int k = 0; k < nv; k++)
      a[i * nv + k] = (v[i1 * nv + k] - v[i0 * nv + k]) / (t->time[i1] - t->time[i0]);
  }
  return speeds;
}

