// go_gait_guess.c: initial guess of the gait problem from a measured trial (go_gait_guess.h).
#include "optim/go_gait_guess.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_muscle.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"

// periodic central difference of y (n samples at times t, y[n-1] the same phase as y[0]) into dy
static void periodic_diff(const double* t, const double* y, int n, int stride, double* dy) {
  double shift = y[(n - 1) * stride] - y[0];
  for (int r = 0; r < n; r++) {
    double yp, ym, tp, tm;
    if (r == 0 || r == n - 1) {
      yp = y[stride];
      tp = t[1] - t[0];
      ym = y[(n - 2) * stride] - shift;
      tm = t[n - 2] - t[n - 1];
    } else {
      yp = y[(r + 1) * stride];
      ym = y[(r - 1) * stride];
      tp = t[r + 1] - t[r];
      tm = t[r - 1] - t[r];
    }
    dy[r * stride] = (yp - ym) / (tp - tm);
  }
}

int go_gait_guess_from_trial(const go_gait* g, const gsTable* coords, double activation,
                             double* z, char* err, int errsz) {
  const mjModel* m = go_gait_model(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int nv = L->nv, nz = L->nz, R = coords->nrow;
  double T = go_gait_stride_time(g);
  int N = go_gait_nodes(g), n = N * nz;
  if (R < 3 || activation < 0.001 || activation > 1) {
    snprintf(err, errsz, "go_gait_guess: need 3 coordinate rows or more and an activation in "
             "[0.001, 1]");
    return -1;
  }
  // q, qdot, qddot on the table's grid
  gsTable fine, rs;
  gs_table_init(&fine);
  gs_table_init(&rs);
  if (gs_table_create(&fine, R, 3 * nv, NULL, err, errsz) != 0) {
    return -1;
  }
  memcpy(fine.time, coords->time, sizeof(double) * (size_t)R);
  for (int j = 0; j < nv; j++) {
    int c = gs_table_column(coords, mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[j]));
    for (int r = 0; r < R; r++) {
      fine.data[r * fine.ncol + j] = c >= 0 ? coords->data[r * coords->ncol + c] : m->qpos0[j];
    }
    periodic_diff(fine.time, fine.data + j, R, fine.ncol, fine.data + nv + j);
    periodic_diff(fine.time, fine.data + nv + j, R, fine.ncol, fine.data + 2 * nv + j);
  }
  double* times = (double*)calloc((size_t)N, sizeof(double));
  for (int k = 0; k < N; k++) {
    times[k] = coords->time[0] + T * k / (N - 1);
  }
  int status = gs_table_resample(&fine, times, N, &rs, err, errsz);
  free(times);
  gs_table_free(&fine);
  if (status != 0) {
    return -1;
  }
  mjData* d = mj_makeData(m);
  for (int k = 0; k < N; k++) {
    double* zk = z + (size_t)k * nz;
    memset(zk, 0, sizeof(double) * (size_t)nz);
    for (int j = 0; j < nv; j++) {
      zk[L->x_q + j] = rs.data[k * rs.ncol + j];
      zk[L->x_qd + j] = zk[L->xd_q + j] = rs.data[k * rs.ncol + nv + j];
      zk[L->xd_qdd + j] = rs.data[k * rs.ncol + 2 * nv + j];
    }
    for (int i = 0; i < L->na; i++) {
      zk[L->x_a + i] = zk[L->u_e + i] = activation;
    }
    mju_copy(d->qpos, zk + L->x_q, nv);
    mju_copy(d->qvel, zk + L->x_qd, nv);
    mj_fwdPosition(m, d);
    mj_fwdVelocity(m, d);
    for (int e = 0; e < L->ne; e++) {
      int i = L->elastic[e];
      gsMuscleParams p;
      gs_muscle_params_from_user(m->actuator_user + i * m->nuser_actuator, &p, NULL, 0);
      double fT = 0;
      gs_muscle_equilibrium_fT(&p, activation, d->actuator_length[i], &fT, NULL);
      zk[L->x_ft + e] = fmin(fmax(fT, 0.0), 5.0);
    }
    for (int s = 0; s < 2; s++) {
      gsFootGrf fg;
      gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &fg);
      for (int c = 0; c < 3; c++) {
        zk[L->u_grf + 3 * s + c] = fg.force[c];
      }
    }
  }
  mj_deleteData(d);
  gs_table_free(&rs);
  // fT' by periodic differences over the nodes
  double* t = (double*)calloc((size_t)N, sizeof(double));
  for (int k = 0; k < N; k++) {
    t[k] = T * k / (N - 1);
  }
  for (int e = 0; e < L->ne && N >= 3; e++) {
    periodic_diff(t, z + L->x_ft + e, N, nz, z + L->xd_ft + e);
  }
  free(t);
  for (int v = 0; v < n; v++) {
    if (!isfinite(z[v])) {
      snprintf(err, errsz, "go_gait_guess: non-finite value at variable %d", v);
      return -1;
    }
  }
  return 0;
}

// ground reaction variables of node z_k from the model's contact at its q, qdot (d scratch)
static void node_grf(const mjModel* m, const go_gait_layout* L, mjData* d, double* zk) {
  mju_copy(d->qpos, zk + L->x_q, L->nv);
  mju_copy(d->qvel, zk + L->x_qd, L->nv);
  mj_fwdPosition(m, d);
  mj_fwdVelocity(m, d);
  for (int s = 0; s < 2; s++) {
    gsFootGrf fg;
    gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &fg);
    for (int c = 0; c < 3; c++) zk[L->u_grf + 3 * s + c] = fg.force[c];
  }
}

int go_gait_guess_from_solution(const go_gait* g, const gsTable* states, const gsTable* controls,
                                double time_scale, double activation, double* z, char* err,
                                int errsz) {
  const mjModel* m = go_gait_model(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int nv = L->nv, nz = L->nz, N = go_gait_nodes(g);
  if (states->nrow < 2 || !(time_scale > 0) || activation < 0.001 || activation > 1) {
    snprintf(err, errsz, "go_gait_guess: need 2 state rows or more, a positive time scale and "
             "an activation in [0.001, 1]");
    return -1;
  }
  gsStateMap smap, cmap;
  memset(&cmap, 0, sizeof(cmap));
  if (gs_state_map(m, states, &smap, err, errsz) != 0) return -1;
  if (smap.nq_found < nv) {
    snprintf(err, errsz, "go_gait_guess: the states hold %d of the model's %d coordinates",
             smap.nq_found, nv);
    gs_state_map_free(&smap);
    return -1;
  }
  if (controls && gs_state_map(m, controls, &cmap, err, errsz) != 0) {
    gs_state_map_free(&smap);
    return -1;
  }
  double t0 = states->time[0], span = states->time[states->nrow - 1] - t0;
  double* t = (double*)calloc((size_t)N, sizeof(double));
  mjData* d = mj_makeData(m);
  for (int k = 0; k < N; k++) {
    double ts = t0 + span * k / (N - 1);  // time in the source solution
    t[k] = span * time_scale * k / (N - 1);
    for (int i = 0; i < L->na; i++) d->act[i] = d->ctrl[i] = activation;
    mju_zero(d->userdata, m->nuserdata);
    mju_zero(d->qvel, nv);
    gs_state_apply(m, states, &smap, ts, d);
    if (controls) gs_state_apply(m, controls, &cmap, ts, d);
    double* zk = z + (size_t)k * nz;
    memset(zk, 0, sizeof(double) * (size_t)nz);
    for (int j = 0; j < nv; j++) {
      zk[L->x_q + j] = d->qpos[j];
      zk[L->x_qd + j] = zk[L->xd_q + j] = d->qvel[j] / time_scale;
    }
    for (int i = 0; i < L->na; i++) {
      zk[L->x_a + i] = fmin(fmax(d->act[i], 0.001), 1.0);
      zk[L->u_e + i] = fmin(fmax(controls && cmap.ctrl_col[i] >= 0 ? d->ctrl[i] : d->act[i],
                                 0.001), 1.0);
    }
    mj_fwdPosition(m, d);
    for (int e = 0; e < L->ne; e++) {
      int i = L->elastic[e];
      double fT = d->userdata[i];
      if (smap.fT_col[i] < 0) {
        gsMuscleParams p;
        gs_muscle_params_from_user(m->actuator_user + i * m->nuser_actuator, &p, NULL, 0);
        gs_muscle_equilibrium_fT(&p, zk[L->x_a + i], d->actuator_length[i], &fT, NULL);
      }
      zk[L->x_ft + e] = fmin(fmax(fT, 0.0), 5.0);
    }
    node_grf(m, L, d, zk);
  }
  mj_deleteData(d);
  gs_state_map_free(&smap);
  if (controls) gs_state_map_free(&cmap);
  // derivatives by periodic differences over the nodes
  for (int j = 0; j < nv && N >= 3; j++) periodic_diff(t, z + L->x_qd + j, N, nz, z + L->xd_qdd + j);
  for (int i = 0; i < L->na && N >= 3; i++) periodic_diff(t, z + L->x_a + i, N, nz, z + L->xd_a + i);
  for (int e = 0; e < L->ne && N >= 3; e++) periodic_diff(t, z + L->x_ft + e, N, nz, z + L->xd_ft + e);
  free(t);
  for (int v = 0; v < N * nz; v++) {
    if (!isfinite(z[v])) {
      snprintf(err, errsz, "go_gait_guess: non-finite value at variable %d", v);
      return -1;
    }
  }
  return 0;
}
