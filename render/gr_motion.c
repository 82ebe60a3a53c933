// gr_motion.c: solution folders and pose files -> model poses, forces and colours per frame.
#include "render/gr_motion.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "io/gs_storage.h"

#define SET_ERR(...)                                                 \
  do {                                                               \
    if (err && errsz > 0) snprintf(err, (size_t)errsz, __VA_ARGS__); \
  } while (0)

static const double kGrfThreshold = 5.0;  // a foot carries load above this vertical force (N)

// column c of t at `time`, linear interpolation, clamped to the time range

// read path into t (angles to radians for model m); a missing file is an error naming it
static int read_table(const mjModel* m, const char* path, gsTable* t, char* err, int errsz) {
  struct stat st;
  if (stat(path, &st) != 0) {
    SET_ERR("%s: %s", path, strerror(errno));
    return -1;
  }
  if (!S_ISREG(st.st_mode)) {
    SET_ERR("%s: not a regular file", path);
    return -1;
  }
  if (gs_storage_read(path, t, err, errsz) != 0) return -1;
  gs_table_to_radians(t, gs_state_is_angle, (void*)m);
  return 0;
}

// the table's time range must cover the stride [t0, t1] (tolerance 0.1 % of the stride + 1 us)
static int check_covers(const gsTable* t, const grMotion* mo, const char* path, char* err,
                        int errsz) {
  double tol = 1e-3 * (mo->t1 - mo->t0) + 1e-6;
  if (t->time[0] > mo->t0 + tol || t->time[t->nrow - 1] < mo->t1 - tol) {
    SET_ERR("%s: time %g..%g s does not cover the stride %g..%g s of states.sto", path,
            t->time[0], t->time[t->nrow - 1], mo->t0, mo->t1);
    return -1;
  }
  return 0;
}

// map the states table and derive the stride, forward coordinate and body weight
static int setup_states(const mjModel* m, grMotion* mo, const char* path, char* err, int errsz) {
  char why[512];
  if (gs_state_map(m, &mo->states, &mo->smap, why, sizeof(why)) != 0) {
    SET_ERR("%s: %s", path, why);
    return -1;
  }
  for (int i = 0; i < m->nu; i++) mo->smap.fT_col[i] = -1;  // tendon states are not drawn
  if (mo->smap.nq_found == 0) {
    SET_ERR("%s: no column names a joint of the model", path);
    return -1;
  }
  mo->t0 = mo->states.time[0];
  mo->t1 = mo->states.time[mo->states.nrow - 1];
  int j = mj_name2id(m, mjOBJ_JOINT, "pelvis_tx");
  mo->advance_qpos = (j >= 0 && m->jnt_type[j] == mjJNT_SLIDE) ? m->jnt_qposadr[j] : -1;
  if (mo->advance_qpos >= 0 && mo->smap.qpos_col[mo->advance_qpos] >= 0) {
    int c = mo->smap.qpos_col[mo->advance_qpos];
    mo->advance = gs_table_value_at(&mo->states, c, mo->t1) - gs_table_value_at(&mo->states, c, mo->t0);
  }
  mo->body_weight = mj_getTotalmass(m) * mju_norm3(m->opt.gravity);
  if (mo->body_weight <= 0) mo->body_weight = 1;
  return 0;
}

static void init_motion(const mjModel* m, grMotion* mo) {
  memset(mo, 0, sizeof(*mo));
  gs_table_init(&mo->states);
  gs_table_init(&mo->controls);
  gs_table_init(&mo->grf);
  gs_table_init(&mo->knee);
  for (int f = 0; f < 2; f++) {
    mo->knee_col[f] = -1;
    for (int k = 0; k < 3; k++) mo->foot[f].force[k] = mo->foot[f].cop[k] = -1;
  }
  mo->advance_qpos = -1;
  (void)m;
}

int gr_motion_load_pose(const mjModel* m, const char* path, grMotion* mo, char* err, int errsz) {
  init_motion(m, mo);
  if (read_table(m, path, &mo->states, err, errsz) != 0 ||
      setup_states(m, mo, path, err, errsz) != 0) {
    gr_motion_free(mo);
    return -1;
  }
  return 0;
}

int gr_motion_load_solution(const mjModel* m, const char* dir, grMotion* mo, char* err,
                            int errsz) {
  init_motion(m, mo);
  char path[4096], why[512];
  struct stat st;
  if (stat(dir, &st) != 0) {
    SET_ERR("%s: %s", dir, strerror(errno));
    return -1;
  }
  if (!S_ISDIR(st.st_mode)) {
    SET_ERR("%s: not a solution folder", dir);
    return -1;
  }
  // required files first, so a missing one is reported before anything else is read
  static const char* const required[] = {"states.sto", "controls.sto", "grf.mot"};
  for (int i = 0; i < 3; i++) {
    snprintf(path, sizeof(path), "%s/%s", dir, required[i]);
    if (stat(path, &st) != 0) {
      SET_ERR("%s: missing (a solution folder holds states.sto, controls.sto and grf.mot)",
              path);
      return -1;
    }
  }
  // states: the pose, the stride, maybe activations
  snprintf(path, sizeof(path), "%s/states.sto", dir);
  if (read_table(m, path, &mo->states, err, errsz) != 0 ||
      setup_states(m, mo, path, err, errsz) != 0) {
    goto fail;
  }
  if (mo->states.nrow < 2) {
    SET_ERR("%s: %d row: a solution needs at least two", path, mo->states.nrow);
    goto fail;
  }
  // controls: excitations by muscle name
  snprintf(path, sizeof(path), "%s/controls.sto", dir);
  if (read_table(m, path, &mo->controls, err, errsz) != 0) goto fail;
  if (gs_state_map(m, &mo->controls, &mo->cmap, why, sizeof(why)) != 0) {
    SET_ERR("%s: %s", path, why);
    goto fail;
  }
  for (int i = 0; i < m->nq; i++) mo->cmap.qpos_col[i] = -1;  // only excitations from here
  for (int i = 0; i < m->nv; i++) mo->cmap.qvel_col[i] = -1;
  for (int i = 0; i < m->na; i++) mo->cmap.act_col[i] = -1;
  for (int i = 0; i < m->nu; i++) mo->cmap.fT_col[i] = -1;
  if (m->nu > 0 && mo->cmap.nctrl_found == 0) {
    SET_ERR("%s: no column names an actuator of the model", path);
    goto fail;
  }
  if (check_covers(&mo->controls, mo, path, err, errsz) != 0) goto fail;
  mo->has_controls = 1;
  // ground reactions: both feet, all six columns each
  snprintf(path, sizeof(path), "%s/grf.mot", dir);
  if (read_table(m, path, &mo->grf, err, errsz) != 0) goto fail;
  static const char side[2] = {'r', 'l'};
  for (int f = 0; f < 2; f++) {
    for (int k = 0; k < 3; k++) {
      char label[64];
      snprintf(label, sizeof(label), "ground_force_%c_v%c", side[f], "xyz"[k]);
      mo->foot[f].force[k] = gs_table_column(&mo->grf, label);
      if (mo->foot[f].force[k] < 0) {
        SET_ERR("%s: no column %s", path, label);
        goto fail;
      }
      snprintf(label, sizeof(label), "ground_force_%c_p%c", side[f], "xyz"[k]);
      mo->foot[f].cop[k] = gs_table_column(&mo->grf, label);
      if (mo->foot[f].cop[k] < 0) {
        SET_ERR("%s: no column %s", path, label);
        goto fail;
      }
    }
  }
  if (check_covers(&mo->grf, mo, path, err, errsz) != 0) goto fail;
  mo->has_grf = 1;
  // knee contact: optional; when present it must be well formed
  snprintf(path, sizeof(path), "%s/knee_contact.sto", dir);
  if (stat(path, &st) == 0) {
    if (read_table(m, path, &mo->knee, err, errsz) != 0) goto fail;
    mo->knee_col[0] = gs_table_column(&mo->knee, "contact_total_r");
    mo->knee_col[1] = gs_table_column(&mo->knee, "contact_total_l");
    if (mo->knee_col[0] < 0 && mo->knee_col[1] < 0) {
      SET_ERR("%s: no column contact_total_r or contact_total_l", path);
      goto fail;
    }
    if (check_covers(&mo->knee, mo, path, err, errsz) != 0) goto fail;
  }
  return 0;
fail:
  gr_motion_free(mo);
  return -1;
}

double gr_motion_stride_time(const grMotion* mo) { return mo->t1 - mo->t0; }

void gr_motion_apply(const mjModel* m, const grMotion* mo, double t, mjData* d,
                     grFrameForces* out) {
  memset(out, 0, sizeof(*out));
  double T = gr_motion_stride_time(mo);
  int cycle = 0;
  double tau = 0;
  if (T > 0) {
    cycle = (int)floor(t / T + 1e-9);
    if (cycle < 0) cycle = 0;
    tau = t - cycle * T;
    if (tau < 0) tau = 0;
    if (tau > T) tau = T;
  }
  double ts = mo->t0 + tau;  // time in the files
  out->time = tau;
  out->phase = T > 0 ? tau / T : 0;
  out->cycle = cycle;

  // pose, activations, excitations; the forward coordinate advances per cycle
  gs_state_apply(m, &mo->states, &mo->smap, ts, d);
  if (mo->has_controls) gs_state_apply(m, &mo->controls, &mo->cmap, ts, d);
  double shift = cycle * mo->advance;
  if (mo->advance_qpos >= 0) d->qpos[mo->advance_qpos] += shift;
  out->colour_source = mo->smap.na_found > 0 ? 1 : (mo->has_controls ? 2 : 0);

  // ground reactions: OpenSim ground (x fwd, y up, z right) -> world (x, -z, y)
  if (mo->has_grf) {
    for (int f = 0; f < 2; f++) {
      double v[3], p[3];
      for (int k = 0; k < 3; k++) {
        v[k] = gs_table_value_at(&mo->grf, mo->foot[f].force[k], ts);
        p[k] = gs_table_value_at(&mo->grf, mo->foot[f].cop[k], ts);
      }
      out->grf[f][0] = v[0];
      out->grf[f][1] = -v[2];
      out->grf[f][2] = v[1];
      out->cop[f][0] = p[0] + shift;
      out->cop[f][1] = -p[2];
      out->cop[f][2] = p[1];
      out->grf_on[f] = v[1] > kGrfThreshold;
    }
  }
  for (int f = 0; f < 2; f++) {
    if (mo->knee_col[f] >= 0) {
      out->knee[f] = gs_table_value_at(&mo->knee, mo->knee_col[f], ts);
      out->knee_on[f] = 1;
    }
  }
}

void gr_motion_free(grMotion* mo) {
  gs_state_map_free(&mo->smap);
  gs_state_map_free(&mo->cmap);
  gs_table_free(&mo->states);
  gs_table_free(&mo->controls);
  gs_table_free(&mo->grf);
  gs_table_free(&mo->knee);
}
