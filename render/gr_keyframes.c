// gr_keyframes.c: a solution's states.sto -> an MJCF that includes the model and holds one
// keyframe per row (gr_keyframes.h).
#include "render/gr_keyframes.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_coupling.h"
#include "callbacks/gs_state.h"
#include "io/gs_atomic.h"
#include "io/gs_storage.h"
#include "io/gs_table.h"
#include "io/gs_text.h"

// folder part of path ("." when it has none), into out (n bytes)
static void folder_of(const char* path, char* out, int n) {
  const char* slash = strrchr(path, '/');
  if (!slash) {
    snprintf(out, (size_t)n, ".");
  } else if (slash == path) {
    snprintf(out, (size_t)n, "/");
  } else {
    snprintf(out, (size_t)n, "%.*s", (int)(slash - path), path);
  }
}

int gr_keyframes_relative_path(const char* target, const char* from_dir, char* out, int n,
                               char* err, int errsz) {
  char t[PATH_MAX], f[PATH_MAX];
  if (!realpath(target, t)) {
    gs_error_set(err, errsz, "%s: %s", target, strerror(errno));
    return -1;
  }
  if (!realpath(from_dir, f)) {
    gs_error_set(err, errsz, "%s: %s", from_dir, strerror(errno));
    return -1;
  }
  // longest common prefix that ends at a component boundary
  size_t common = 0;
  for (size_t i = 0; t[i] && t[i] == f[i]; i++) {
    if (t[i] == '/') common = i;
  }
  size_t flen = strlen(f);
  if (strncmp(t, f, flen) == 0 && t[flen] == '/') common = flen;  // target inside from_dir
  // one ".." per component of from_dir below the common prefix, then the rest of target
  int used = 0;
  out[0] = '\0';
  for (size_t i = common; i < flen; i++) {
    if (f[i] == '/' && used < n) {
      used += snprintf(out + used, (size_t)(n - used), "../");
    }
  }
  if (used < n) used += snprintf(out + used, (size_t)(n - used), "%s", t + common + 1);
  if (used >= n) {
    gs_error_set(err, errsz, "%s: relative path longer than %d bytes", target, n - 1);
    return -1;
  }
  return 0;
}

// s with the five XML special characters escaped, as an attribute value
static void put_xml_attr(FILE* f, const char* s) {
  for (; *s; s++) {
    switch (*s) {
      case '&': fputs("&amp;", f); break;
      case '<': fputs("&lt;", f); break;
      case '>': fputs("&gt;", f); break;
      case '"': fputs("&quot;", f); break;
      case '\'': fputs("&apos;", f); break;
      default: fputc(*s, f);
    }
  }
}

// one attribute of n numbers (17 significant digits: stock MuJoCo reads back the same doubles)
static void put_numbers(FILE* f, const char* name, const double* v, int n) {
  fprintf(f, " %s=\"", name);
  for (int i = 0; i < n; i++) fprintf(f, i ? " %.17g" : "%.17g", v[i]);
  fputc('"', f);
}

// the first hinge/slide joint of m without a column in map, or -1
static int missing_coordinate(const mjModel* m, const gsStateMap* map) {
  for (int j = 0; j < m->njnt; j++) {
    int type = m->jnt_type[j];
    if ((type == mjJNT_HINGE || type == mjJNT_SLIDE) && map->qpos_col[m->jnt_qposadr[j]] < 0 &&
        !gs_coupling_joint_follows(m, j)) {  // a follower takes its driver's (gs_state_apply)
      return j;
    }
  }
  return -1;
}

// The value of attribute `name` (e.g. "meshdir") of the model file's first <compiler> element
// into out (size n): 1 found, 0 not (no such file, element or attribute, or too long).
static int compiler_attr(const char* model_path, const char* name, char* out, int n) {
  FILE* f = fopen(model_path, "rb");
  if (!f) return 0;
  char text[8192];  // the <compiler> element sits in the file's head
  size_t len = fread(text, 1, sizeof(text) - 1, f);
  fclose(f);
  text[len] = 0;
  const char* c = strstr(text, "<compiler");
  const char* end = c ? strchr(c, '>') : NULL;
  if (!end) return 0;
  char key[64];
  snprintf(key, sizeof(key), " %s=\"", name);
  const char* a = strstr(c, key);
  if (!a || a > end) return 0;
  a += strlen(key);
  const char* q = strchr(a, '"');
  if (!q || q > end || q - a >= n) return 0;
  snprintf(out, (size_t)n, "%.*s", (int)(q - a), a);
  return 1;
}

// The model's asset folders (meshdir, texturedir) relative to the exported file's folder dir, as
// the attributes of a <compiler> element that follows the include (MuJoCo 2.2 resolves asset
// files from the top-level file's folder, and the last <compiler> setting wins), into out (size
// n); "" when the model names none. 0, or -1 with the reason in err.
static int asset_dirs(const char* model_path, const char* dir, char* out, int n, char* err,
                      int errsz) {
  static const char* names[] = {"meshdir", "texturedir"};
  char mdir[PATH_MAX], value[1024], target[PATH_MAX + 1100], rel[PATH_MAX];
  folder_of(model_path, mdir, (int)sizeof(mdir));
  out[0] = 0;
  size_t used = 0;
  for (int i = 0; i < 2; i++) {
    if (!compiler_attr(model_path, names[i], value, (int)sizeof(value))) continue;
    if (value[0] == '/') snprintf(target, sizeof(target), "%s", value);
    else snprintf(target, sizeof(target), "%s/%s", mdir, value);
    if (gr_keyframes_relative_path(target, dir, rel, (int)sizeof(rel), err, errsz) != 0) return -1;
    int w = snprintf(out + used, (size_t)n - used, " %s=\"%s/\"", names[i], rel);
    if (w < 0 || (size_t)w >= (size_t)n - used) {
      gs_error_set(err, errsz, "%s: %s path too long", model_path, names[i]);
      return -1;
    }
    used += (size_t)w;
  }
  return 0;
}

// the MJCF text: include, the model's asset folders seen from the exported file, then one key
// per row of t (radians) mapped by map
static void write_mjcf(FILE* f, const mjModel* m, const char* include, const char* assets,
                       const char* states_path, const gsTable* t, const gsStateMap* map,
                       double* qpos, double* qvel, double* act) {
  fputs("<!-- gaitsim export: the solved gait of ", f);
  for (const char* s = states_path; *s; s++) {
    fputc(*s == '-' && s > states_path && s[-1] == '-' ? '_' : *s, f);  // "--" ends a comment
  }
  fputs(" as keyframes gait_000... (time s, qpos rad/m, qvel rad/s or m/s, act -). -->\n", f);
  fputs("<mujoco model=\"gaitsim export\">\n  <include file=\"", f);
  put_xml_attr(f, include);
  fputs("\"/>\n", f);
  if (assets[0]) fprintf(f, "  <compiler%s/>\n", assets);
  fputs("  <keyframe>\n", f);
  for (int r = 0; r < t->nrow; r++) {
    const double* row = t->data + (size_t)r * (size_t)t->ncol;
    for (int i = 0; i < m->nq; i++) {
      qpos[i] = map->qpos_col[i] >= 0 ? row[map->qpos_col[i]] : m->qpos0[i];
    }
    for (int i = 0; i < m->nv; i++) qvel[i] = map->qvel_col[i] >= 0 ? row[map->qvel_col[i]] : 0;
    for (int i = 0; i < m->na; i++) act[i] = map->act_col[i] >= 0 ? row[map->act_col[i]] : 0;
    fprintf(f, "    <key name=\"gait_%03d\" time=\"%.17g\"", r, t->time[r]);
    put_numbers(f, "qpos", qpos, m->nq);
    put_numbers(f, "qvel", qvel, m->nv);
    if (m->na > 0) put_numbers(f, "act", act, m->na);
    fputs("/>\n", f);
  }
  fputs("  </keyframe>\n</mujoco>\n", f);
}

// compile the written file with stock MuJoCo and check its sizes
static int check_loads(const mjModel* m, const char* path, int nkey, char* err, int errsz) {
  char why[1024] = "";
  mjModel* back = mj_loadXML(path, NULL, why, (int)sizeof(why));
  if (!back) {
    gs_error_set(err, errsz, "stock MuJoCo does not load the export: %s", why);
    return -1;
  }
  int ok = back->nq == m->nq && back->nv == m->nv && back->na == m->na &&
           back->nkey == m->nkey + nkey;
  if (!ok) {
    gs_error_set(err, errsz, "the export loads with nq %d, nv %d, na %d, nkey %d; expected %d, %d, "
                 "%d, %d", back->nq, back->nv, back->na, back->nkey, m->nq, m->nv, m->na,
                 m->nkey + nkey);
  }
  mj_deleteModel(back);
  return ok ? 0 : -1;
}

int gr_keyframes_export(const mjModel* m, const char* model_path, const char* states_path,
                        const char* out_path, grKeyframesInfo* info, char* err, int errsz) {
  grKeyframesInfo local;
  if (!info) info = &local;
  memset(info, 0, sizeof(*info));
  char why[1024];

  // states.sto in radians, mapped by name; every coordinate must be there
  gsTable t;
  gs_table_init(&t);
  if (gs_storage_read(states_path, &t, err, errsz) != 0) return -1;
  gs_table_to_radians(&t, gs_state_is_angle, (void*)m);
  gsStateMap map;
  if (gs_state_map(m, &t, &map, why, (int)sizeof(why)) != 0) {
    gs_error_set(err, errsz, "%s: %s", states_path, why);
    gs_table_free(&t);
    return -1;
  }
  int status = -1;
  int j = missing_coordinate(m, &map);
  if (t.nrow < 1) {
    gs_error_set(err, errsz, "%s: no rows", states_path);
    goto done;
  }
  if (j >= 0) {
    gs_error_set(err, errsz, "%s: no column for coordinate %s of %s", states_path,
                 mj_id2name(m, mjOBJ_JOINT, j), model_path);
    goto done;
  }

  // the include path, relative to the output folder (created when missing)
  char dir[PATH_MAX];
  folder_of(out_path, dir, (int)sizeof(dir));
  if (gs_mkdir_p(dir, err, errsz) != 0) goto done;
  if (gr_keyframes_relative_path(model_path, dir, info->include, (int)sizeof(info->include), err,
                                 errsz) != 0) {
    goto done;
  }
  char assets[2 * PATH_MAX + 64];
  if (asset_dirs(model_path, dir, assets, (int)sizeof(assets), err, errsz) != 0) goto done;
  char real_out[PATH_MAX], real_model[PATH_MAX];
  if (realpath(out_path, real_out) && realpath(model_path, real_model) &&
      strcmp(real_out, real_model) == 0) {
    gs_error_set(err, errsz, "%s: is the model itself; give another --out", out_path);
    goto done;
  }

  // write beside the target, load the temporary file with stock MuJoCo, then publish
  double* buf = malloc(sizeof(double) * (size_t)(m->nq + m->nv + m->na + 1));
  if (!buf) {
    gs_error_set(err, errsz, "%s: out of memory", out_path);
    goto done;
  }
  gsAtomicFile a;
  if (gs_atomic_open(&a, out_path, err, errsz) != 0) {
    free(buf);
    goto done;
  }
  write_mjcf(a.f, m, info->include, assets, states_path, &t, &map, buf, buf + m->nq,
             buf + m->nq + m->nv);
  free(buf);
  if (fflush(a.f) != 0 || ferror(a.f)) {
    gs_error_set(err, errsz, "%s: %s", out_path, strerror(errno));
    gs_atomic_abort(&a);
    goto done;
  }
  if (check_loads(m, a.tmppath, t.nrow, why, (int)sizeof(why)) != 0) {
    gs_error_set(err, errsz, "%s: %s", out_path, why);
    gs_atomic_abort(&a);
    goto done;
  }
  if (gs_atomic_commit(&a, err, errsz) != 0) goto done;
  info->nkey = t.nrow;
  info->first_key = m->nkey;
  info->nq_found = map.nq_found;
  info->nv_found = map.nv_found;
  info->na_found = map.na_found;
  status = 0;

done:
  gs_state_map_free(&map);
  gs_table_free(&t);
  return status;
}
