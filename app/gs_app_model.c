// gs_app_model.c: model preparation and table I/O shared by the subcommands.
#include "app/gs_app_model.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "io/gs_storage.h"

mjModel* gs_app_load_model(const char* path) {
  char err[1024];
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
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  char* text = NULL;
  size_t len = 0, got;
  char buf[4096];
  while ((got = fread(buf, 1, sizeof(buf), f)) > 0) {
    char* t = (char*)realloc(text, len + got + 1);
    if (!t) break;
    text = t;
    memcpy(text + len, buf, got);
    len += got;
  }
  fclose(f);
  if (!text) return NULL;
  text[len] = 0;
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

const char* gs_app_model_for_solution(const char* dir, const char* given, char* buf, int n) {
  if (given) return given;
  return gs_app_solution_model(dir, buf, n) ? buf : GS_DEFAULT_MODEL;
}
