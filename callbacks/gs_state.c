// gs_state.c: model state <-> OpenSim storage tables (see gs_state.h).
#include "callbacks/gs_state.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_coupling.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_physics.h"

enum { kLabelMax = 256 };

const char* const gs_grf_labels[GS_GRF_NCOL] = {
    "ground_force_r_vx", "ground_force_r_vy", "ground_force_r_vz", "ground_force_r_px",
    "ground_force_r_py", "ground_force_r_pz", "ground_torque_r_x", "ground_torque_r_y",
    "ground_torque_r_z", "ground_force_l_vx", "ground_force_l_vy", "ground_force_l_vz",
    "ground_force_l_px", "ground_force_l_py", "ground_force_l_pz", "ground_torque_l_x",
    "ground_torque_l_y", "ground_torque_l_z"};

// label with a suffix removed, or NULL when label does not end in suffix
static const char* strip_suffix(const char* label, const char* suffix, char* buf) {
  size_t n = strlen(label), k = strlen(suffix);
  if (n <= k || n - k >= kLabelMax || strcmp(label + n - k, suffix) != 0) {
    return NULL;
  }
  memcpy(buf, label, n - k);
  buf[n - k] = '\0';
  return buf;
}

int gs_state_is_angle(const char* label, void* user) {
  const mjModel* m = (const mjModel*)user;
  char buf[kLabelMax];
  const char* name = strip_suffix(label, "_u", buf);
  int j = mj_name2id(m, mjOBJ_JOINT, label);
  if (j < 0 && name) {
    j = mj_name2id(m, mjOBJ_JOINT, name);
  }
  return j >= 0 && m->jnt_type[j] == mjJNT_HINGE;
}

// set slot[idx] = col, failing on a second column for the same quantity
static int claim(int* slot, int col, const gsTable* t, char* err, int errsz) {
  if (*slot >= 0) {
    snprintf(err, errsz, "columns '%s' and '%s' both give the same model quantity",
             t->labels[*slot], t->labels[col]);
    return -1;
  }
  *slot = col;
  return 0;
}

static int* new_index(int n) {
  int* v = (int*)malloc(sizeof(int) * (n > 0 ? n : 1));
  for (int i = 0; v && i < n; i++) {
    v[i] = -1;
  }
  return v;
}

void gs_state_map_free(gsStateMap* map) {
  free(map->qpos_col);
  free(map->qvel_col);
  free(map->act_col);
  free(map->fT_col);
  free(map->ctrl_col);
  memset(map, 0, sizeof(*map));
}

int gs_state_map(const mjModel* m, const gsTable* t, gsStateMap* map, char* err, int errsz) {
  memset(map, 0, sizeof(*map));
  map->qpos_col = new_index(m->nq);
  map->qvel_col = new_index(m->nv);
  map->act_col = new_index(m->na);
  map->fT_col = new_index(m->nu);
  map->ctrl_col = new_index(m->nu);
  if (!map->qpos_col || !map->qvel_col || !map->act_col || !map->fT_col || !map->ctrl_col) {
    gs_state_map_free(map);
    snprintf(err, errsz, "out of memory");
    return -1;
  }
  char buf[kLabelMax];
  for (int c = 0; c < t->ncol; c++) {
    const char* label = t->labels[c];
    const char* base;
    int id, status = 0;
    if ((id = mj_name2id(m, mjOBJ_JOINT, label)) >= 0 && m->jnt_type[id] != mjJNT_FREE &&
        m->jnt_type[id] != mjJNT_BALL) {
      status = claim(&map->qpos_col[m->jnt_qposadr[id]], c, t, err, errsz);
    } else if ((base = strip_suffix(label, "_u", buf)) &&
               (id = mj_name2id(m, mjOBJ_JOINT, base)) >= 0 && m->jnt_type[id] != mjJNT_FREE &&
               m->jnt_type[id] != mjJNT_BALL) {
      status = claim(&map->qvel_col[m->jnt_dofadr[id]], c, t, err, errsz);
    } else if ((base = strip_suffix(label, ".activation", buf)) &&
               (id = mj_name2id(m, mjOBJ_ACTUATOR, base)) >= 0 && id >= m->nu - m->na) {
      status = claim(&map->act_col[id - (m->nu - m->na)], c, t, err, errsz);
    } else if ((base = strip_suffix(label, ".normalized_tendon_force", buf)) &&
               (id = mj_name2id(m, mjOBJ_ACTUATOR, base)) >= 0) {
      status = claim(&map->fT_col[id], c, t, err, errsz);
    } else if ((base = strip_suffix(label, ".excitation", buf)) &&
               (id = mj_name2id(m, mjOBJ_ACTUATOR, base)) >= 0) {
      status = claim(&map->ctrl_col[id], c, t, err, errsz);
    } else if ((id = mj_name2id(m, mjOBJ_ACTUATOR, label)) >= 0) {
      status = claim(&map->ctrl_col[id], c, t, err, errsz);
    }
    if (status != 0) {
      gs_state_map_free(map);
      return -1;
    }
  }
  for (int i = 0; i < m->nq; i++) map->nq_found += map->qpos_col[i] >= 0;
  for (int i = 0; i < m->nv; i++) map->nv_found += map->qvel_col[i] >= 0;
  for (int i = 0; i < m->na; i++) map->na_found += map->act_col[i] >= 0;
  for (int i = 0; i < m->nu; i++) map->nfT_found += map->fT_col[i] >= 0;
  for (int i = 0; i < m->nu; i++) map->nctrl_found += map->ctrl_col[i] >= 0;
  return 0;
}

// column c of t at `time`, linear interpolation, clamped to the time range

void gs_state_apply(const mjModel* m, const gsTable* t, const gsStateMap* map, double time,
                    mjData* d) {
  for (int i = 0; i < m->nq; i++) {
    if (map->qpos_col[i] >= 0) d->qpos[i] = gs_table_value_at(t, map->qpos_col[i], time);
  }
  for (int i = 0; i < m->nv; i++) {
    if (map->qvel_col[i] >= 0) d->qvel[i] = gs_table_value_at(t, map->qvel_col[i], time);
  }
  for (int i = 0; i < m->na; i++) {
    if (map->act_col[i] >= 0) d->act[i] = gs_table_value_at(t, map->act_col[i], time);
  }
  for (int i = 0; i < m->nu; i++) {
    if (map->fT_col[i] >= 0) d->userdata[i] = gs_table_value_at(t, map->fT_col[i], time);
    if (map->ctrl_col[i] >= 0) d->ctrl[i] = gs_table_value_at(t, map->ctrl_col[i], time);
  }
  // coupled coordinates the table lacks (a trial's coordinates have no patella) follow their
  // driver (gs_coupling.h)
  gs_coupling_follow(m, d->qpos, d->qvel, map->qpos_col, map->qvel_col);
}

int gs_state_table_create(const mjModel* m, int nrow, gsTable* t, char* err, int errsz) {
  int ncol = 0;
  char** labels = (char**)calloc((size_t)(2 * m->njnt + 2 * m->nu + 1), sizeof(char*));
  if (!labels) {
    snprintf(err, errsz, "out of memory");
    return -1;
  }
  char buf[kLabelMax];
  for (int j = 0; j < m->njnt; j++) {  // hinge and slide joints: one coordinate each
    if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) {
      labels[ncol++] = strdup(mj_id2name(m, mjOBJ_JOINT, j));
    }
  }
  for (int j = 0; j < m->njnt; j++) {
    if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) {
      snprintf(buf, sizeof(buf), "%s_u", mj_id2name(m, mjOBJ_JOINT, j));
      labels[ncol++] = strdup(buf);
    }
  }
  for (int i = m->nu - m->na; i < m->nu; i++) {
    snprintf(buf, sizeof(buf), "%s.activation", mj_id2name(m, mjOBJ_ACTUATOR, i));
    labels[ncol++] = strdup(buf);
  }
  for (int i = 0; i < m->nu; i++) {
    if (gs_actuator_has_elastic_tendon(m, i)) {
      snprintf(buf, sizeof(buf), "%s.normalized_tendon_force", mj_id2name(m, mjOBJ_ACTUATOR, i));
      labels[ncol++] = strdup(buf);
    }
  }
  int status = gs_table_create(t, nrow, ncol, (const char* const*)labels, err, errsz);
  for (int c = 0; c < ncol; c++) {
    free(labels[c]);
  }
  free(labels);
  return status;
}

void gs_state_table_set_row(const mjModel* m, const mjData* d, double time, gsTable* t, int row) {
  double* r = t->data + (size_t)row * t->ncol;
  int c = 0;
  t->time[row] = time;
  for (int j = 0; j < m->njnt; j++) {
    if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) {
      r[c++] = d->qpos[m->jnt_qposadr[j]];
    }
  }
  for (int j = 0; j < m->njnt; j++) {
    if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) {
      r[c++] = d->qvel[m->jnt_dofadr[j]];
    }
  }
  for (int i = 0; i < m->na; i++) {
    r[c++] = d->act[i];
  }
  for (int i = 0; i < m->nu; i++) {
    if (gs_actuator_has_elastic_tendon(m, i)) {
      r[c++] = d->userdata[i];
    }
  }
}

int gs_grf_table_create(int nrow, gsTable* t, char* err, int errsz) {
  return gs_table_create(t, nrow, GS_GRF_NCOL, gs_grf_labels, err, errsz);
}

// world (Z up) vector -> OpenSim ground frame (Y up): (x, z, -y)
static void to_opensim(const double w[3], double* os) {
  os[0] = w[0];
  os[1] = w[2];
  os[2] = -w[1];
}

void gs_grf_table_set_row(const mjModel* m, const mjData* d, double time, gsTable* t, int row) {
  double* r = t->data + (size_t)row * t->ncol;
  t->time[row] = time;
  for (int s = 0; s < 2; s++) {
    gsFootGrf grf;
    gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &grf);
    double free_moment[3] = {0, 0, grf.free_moment};
    to_opensim(grf.force, r + 9 * s);
    to_opensim(grf.cop, r + 9 * s + 3);
    to_opensim(free_moment, r + 9 * s + 6);
  }
}
