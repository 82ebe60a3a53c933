// go_gait_guess.c: initial guess of the gait problem from a measured trial (go_gait_guess.h).
#include "optim/go_gait_guess.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_coupling.h"
#include "callbacks/gs_knee.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_muscle.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "callbacks/gs_tendon_paths.h"

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
  // the trial's column of each coordinate (nq == nv here: hinge and slide joints only)
  int* col = (int*)malloc(sizeof(int) * (size_t)nv);
  if (!col) {
    gs_table_free(&fine);
    snprintf(err, errsz, "go_gait_guess: out of memory");
    return -1;
  }
  for (int j = 0; j < nv; j++) {
    int c = col[j] = gs_table_column(coords, mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[j]));
    for (int r = 0; r < R; r++) {
      fine.data[r * fine.ncol + j] = c >= 0 ? coords->data[r * coords->ncol + c] : m->qpos0[j];
    }
  }
  // coupled coordinates the trial lacks (the patella) follow their driver (gs_coupling.h)
  for (int r = 0; r < R; r++) gs_coupling_follow(m, fine.data + r * fine.ncol, NULL, col, NULL);
  free(col);
  for (int j = 0; j < nv; j++) {
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
    gs_fwd_position(m, d);
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
        if (L->ngrf > GO_GAIT_GRM_OFFSET) zk[L->u_grf + GO_GAIT_GRM_OFFSET + 3 * s + c] = fg.moment[c];
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
  gs_fwd_position(m, d);
  mj_fwdVelocity(m, d);
  for (int s = 0; s < 2; s++) {
    gsFootGrf fg;
    gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &fg);
    for (int c = 0; c < 3; c++) {
      zk[L->u_grf + 3 * s + c] = fg.force[c];
      if (L->ngrf > GO_GAIT_GRM_OFFSET) zk[L->u_grf + GO_GAIT_GRM_OFFSET + 3 * s + c] = fg.moment[c];
    }
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
    gs_fwd_position(m, d);
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

// --- static-optimisation guess ------------------------------------------------------------

int go_gait_measured_wrenches(const go_gait* g, const gsTable* grf, go_foot_wrench* w, char* err,
                              int errsz) {
  int N = go_gait_nodes(g);
  double T = go_gait_stride_time(g);
  if (!grf || grf->nrow < 2) {
    snprintf(err, errsz, "go_gait_guess: static: need a ground reaction table of 2 rows or more");
    return -1;
  }
  gsTable sel, rs;
  gs_table_init(&sel);
  gs_table_init(&rs);
  double* times = (double*)calloc((size_t)N, sizeof(double));
  for (int k = 0; k < N; k++) times[k] = grf->time[0] + T * k / (N - 1);
  int status = -1;
  if (times && gs_table_select(grf, gs_grf_labels, GS_GRF_NCOL, &sel, err, errsz) == 0 &&
      gs_table_resample(&sel, times, N, &rs, err, errsz) == 0) {
    for (int k = 0; k < N; k++) {
      for (int s = 0; s < 2; s++) {  // OpenSim (x, y up, z) -> world (x, -z, y)
        const double* v = rs.data + k * rs.ncol + 9 * s;
        go_foot_wrench* o = w + 2 * k + s;
        for (int b = 0; b < 3; b++) {
          double* dst = b == 0 ? o->force : b == 1 ? o->point : o->torque;
          dst[0] = v[3 * b];
          dst[1] = -v[3 * b + 2];
          dst[2] = v[3 * b + 1];
        }
      }
    }
    status = 0;
  }
  free(times);
  gs_table_free(&sel);
  gs_table_free(&rs);
  return status;
}

// body carrying side's contact spheres (the first sphere's), -1 if none
static int foot_body(const mjModel* m, int side) {
  for (int i = 0; i < m->ngeom; i++) {
    if (gs_geom_contact_side(m, i) == side) return m->geom_bodyid[i];
  }
  return -1;
}

int go_gait_inverse_dynamics(const go_gait* g, mjData* d, const double* z_k,
                             const go_foot_wrench* w, double* tau) {
  const mjModel* m = go_gait_model(g);
  int nv = m->nv;
  int body[2] = {foot_body(m, 'r'), foot_body(m, 'l')};
  if (body[0] < 0 || body[1] < 0) return -1;
  go_gait_load_node(g, d, z_k);  // mj_inverse: qfrc_inverse = M qacc + bias - passive
  mju_copy(tau, d->qfrc_inverse, nv);
  // the model's sphere contact, which qfrc_passive (hence qfrc_inverse) holds: added back
  mjMARKSTACK;
  mjtNum* passive = mj_stackAlloc(d, nv);
  mju_copy(passive, d->qfrc_passive, nv);
  mju_zero(d->qfrc_passive, nv);
  gs_physics_contact_passive(m, d);
  mju_addTo(tau, d->qfrc_passive, nv);
  // the measured wrenches, applied to the feet: the actuators need J^T w less
  mju_zero(d->qfrc_passive, nv);
  for (int s = 0; s < 2; s++) {
    mjtNum f[3], t[3], p[3];
    for (int c = 0; c < 3; c++) f[c] = w[s].force[c], t[c] = w[s].torque[c], p[c] = w[s].point[c];
    mj_applyFT(m, d, f, t, p, body[s], d->qfrc_passive);
  }
  mju_subFrom(tau, d->qfrc_passive, nv);
  mju_copy(d->qfrc_passive, passive, nv);
  mjFREESTACK;
  return 0;
}

// the secondary dofs of the six-DOF implant knee (gs_knee: all but flexion) are held by the
// articular contact surrogate and the ligaments, not by muscles, as spring-held dofs are by their
// springs. Matching their moments by muscle forces left the static guess of jw_fullbody_knee6
// with a residual of 1.1e4 N m RMS and 393 node-muscle pairs at a = 1 (20 nodes); with the 15
// dofs matched: 17.3 N m RMS, 231 pairs at a = 1
static int held_by_knee_model(const mjModel* m, int j) {
  const gsKneeModel* km = gs_knee_lookup(m);
  for (int c = 0; km && c < 6; c++)
    if (c != GS_KNEE_FLEX && km->dadr[c] == j) return 1;
  return 0;
}

int go_static_dof_matched(const mjModel* m, int j) {
  return !go_gait_dof_is_root(m, j) && !(m->jnt_stiffness[m->dof_jntid[j]] > 0) &&
         !held_by_knee_model(m, j) && !gs_coupling_joint_follows(m, m->dof_jntid[j]);
}

// Cholesky factorisation of the SPD matrix A (n x n, row-major, lower triangle overwritten) and
// solve A x = b in place (b becomes x). 0, or -1 when A is not positive definite.
static int chol_solve(double* A, int n, double* b) {
  for (int j = 0; j < n; j++) {
    double s = A[j * n + j];
    for (int k = 0; k < j; k++) s -= A[j * n + k] * A[j * n + k];
    if (!(s > 0)) return -1;
    double l = sqrt(s);
    A[j * n + j] = l;
    for (int i = j + 1; i < n; i++) {
      double t = A[i * n + j];
      for (int k = 0; k < j; k++) t -= A[i * n + k] * A[j * n + k];
      A[i * n + j] = t / l;
    }
  }
  for (int i = 0; i < n; i++) {  // L y = b
    double t = b[i];
    for (int k = 0; k < i; k++) t -= A[i * n + k] * b[k];
    b[i] = t / A[i * n + i];
  }
  for (int i = n - 1; i >= 0; i--) {  // L^T x = y
    double t = b[i];
    for (int k = i + 1; k < n; k++) t -= A[k * n + i] * b[k];
    b[i] = t / A[i * n + i];
  }
  return 0;
}

// Primal active-set method for min 1/2 a^T H a + g0^T a, lo <= a <= hi, H = I + w B^T B (SPD),
// g0 = -w B^T c: the halved objective of go_static_opt_solve.
int go_static_opt_solve(int n, int m, const double* B, const double* c, double w, double lo,
                        double hi, double* a) {
  double* H = (double*)calloc((size_t)n * n, sizeof(double));
  double* g0 = (double*)calloc((size_t)n, sizeof(double));
  double* Hf = (double*)calloc((size_t)n * n, sizeof(double));
  double* rhs = (double*)calloc((size_t)n, sizeof(double));
  double* cand = (double*)calloc((size_t)n, sizeof(double));
  int* st = (int*)calloc((size_t)n, sizeof(int));   // 0 free, -1 at lo, +1 at hi
  int* fr = (int*)calloc((size_t)n, sizeof(int));   // free indices
  int steps = -1;
  if (!H || !g0 || !Hf || !rhs || !cand || !st || !fr) goto out;
  for (int i = 0; i < n; i++) {
    for (int k = i; k < n; k++) {
      double s = 0;
      for (int r = 0; r < m; r++) s += B[r * n + i] * B[r * n + k];
      H[i * n + k] = H[k * n + i] = w * s + (i == k ? 1.0 : 0.0);
    }
    double s = 0;
    for (int r = 0; r < m; r++) s += B[r * n + i] * c[r];
    g0[i] = -w * s;
  }
  double gscale = 1;
  for (int i = 0; i < n; i++) gscale = fmax(gscale, fabs(g0[i]));
  double tol = 1e-12 * gscale;
  for (int i = 0; i < n; i++) a[i] = lo, st[i] = -1;  // start: every variable at its lower bound
  int limit = 20 * n + 20;
  for (int it = 0; it < limit; it++) {
    // minimiser over the free variables, the bound ones fixed
    int nf = 0;
    for (int i = 0; i < n; i++) if (st[i] == 0) fr[nf++] = i;
    for (int p = 0; p < nf; p++) {
      int i = fr[p];
      double s = -g0[i];
      for (int k = 0; k < n; k++) if (st[k] != 0) s -= H[i * n + k] * a[k];
      rhs[p] = s;
      for (int q = 0; q < nf; q++) Hf[p * nf + q] = H[i * n + fr[q]];
    }
    if (nf > 0 && chol_solve(Hf, nf, rhs) != 0) goto out;
    for (int i = 0; i < n; i++) cand[i] = a[i];
    for (int p = 0; p < nf; p++) cand[fr[p]] = rhs[p];
    // longest feasible step towards it
    double alpha = 1;
    int block = -1;
    for (int p = 0; p < nf; p++) {
      int i = fr[p];
      double dlt = cand[i] - a[i];
      if (cand[i] < lo && dlt < 0 && (lo - a[i]) / dlt < alpha) alpha = (lo - a[i]) / dlt, block = i;
      if (cand[i] > hi && dlt > 0 && (hi - a[i]) / dlt < alpha) alpha = (hi - a[i]) / dlt, block = i;
    }
    for (int p = 0; p < nf; p++) a[fr[p]] += alpha * (cand[fr[p]] - a[fr[p]]);
    if (block >= 0) {  // a bound became active
      st[block] = a[block] - lo < hi - a[block] ? -1 : 1;
      a[block] = st[block] < 0 ? lo : hi;
      continue;
    }
    // optimal on this face: release the bound with the most negative multiplier, if any
    int worst = -1;
    double most = -tol;
    for (int i = 0; i < n; i++) {
      if (st[i] == 0) continue;
      double gi = g0[i];
      for (int k = 0; k < n; k++) gi += H[i * n + k] * a[k];
      double mult = st[i] < 0 ? gi : -gi;  // >= 0 at the optimum
      if (mult < most) most = mult, worst = i;
    }
    if (worst < 0) {
      steps = it + 1;
      goto out;
    }
    st[worst] = 0;
  }
out:
  free(H), free(g0), free(Hf), free(rhs), free(cand), free(st), free(fr);
  return steps;
}

// Normalised tendon force fT (-) of an elastic unit in Hill equilibrium at activation a (-),
// lMT (m), vMT (m/s) and a given fT' (1/s): the root of gs_muscle_equilibrium_residual in fT,
// bracketed between -c3 (+1e-6: the tendon at its shortest, residual > 0 since the fibre force
// there exceeds -0.03) and an upper end doubled until the residual is negative; Illinois
// regula falsi to |r| < 1e-12 or 100 steps. Returns the root (the bracket's better end if it
// did not converge).
static double elastic_fT(const gsMuscleParams* p, double a, double lMT, double vMT, double fTd) {
  double lo = -GS_MUSCLE_C3 + 1e-6, hi = 1.0;
  double rlo = gs_muscle_equilibrium_residual(p, a, lMT, vMT, lo, fTd, NULL, NULL);
  double rhi = gs_muscle_equilibrium_residual(p, a, lMT, vMT, hi, fTd, NULL, NULL);
  for (int i = 0; i < 8 && rhi > 0; i++) {
    lo = hi, rlo = rhi;
    hi *= 2;
    rhi = gs_muscle_equilibrium_residual(p, a, lMT, vMT, hi, fTd, NULL, NULL);
  }
  if (!(rlo > 0 && rhi < 0)) return fabs(rlo) < fabs(rhi) ? lo : hi;
  int side = 0;
  for (int it = 0; it < 100; it++) {
    double x = (lo * rhi - hi * rlo) / (rhi - rlo);
    double r = gs_muscle_equilibrium_residual(p, a, lMT, vMT, x, fTd, NULL, NULL);
    if (fabs(r) < 1e-12 || hi - lo < 1e-14) return x;
    if (r > 0) {
      lo = x, rlo = r;
      if (side == 1) rhi *= 0.5;
      side = 1;
    } else {
      hi = x, rhi = r;
      if (side == -1) rlo *= 0.5;
      side = -1;
    }
  }
  return 0.5 * (lo + hi);
}

// F_i(a) ~ P + G a of muscle i at lMT, vMT (and, elastic, fT'): rigid tendon exactly
// (gs_muscle_rigid_force is affine in a); elastic tendon the tangent at a0 of the Hill
// equilibrium force Fmax fT(a): dfT/da = -(dr/da) / (dr/dfT) (implicit function theorem).
static void muscle_affine(const gsMuscleParams* p, double a0, double lMT, double vMT, double fTd,
                          double* P, double* G) {
  gsMuscleGrad gr;
  if (!p->elastic) {
    *P = gs_muscle_rigid_force(p, 0.0, lMT, vMT, &gr, NULL);
    *G = gr.a;
    return;
  }
  double fT = elastic_fT(p, a0, lMT, vMT, fTd);
  gs_muscle_equilibrium_residual(p, a0, lMT, vMT, fT, fTd, &gr, NULL);
  double dfda = fabs(gr.fT) > 1e-9 ? -gr.a / gr.fT : 0.0;
  *G = p->fmax * fmax(dfda, 0.0);
  *P = p->fmax * fmin(fmax(fT, 0.0), 5.0) - *G * a0;  // the NLP's bounds on fT, as the guess sets it
}

int go_gait_guess_static(const go_gait* g, const gsTable* coords, const gsTable* grf, double* z,
                         go_static_report* report, char* err, int errsz) {
  const mjModel* m = go_gait_model(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int nv = L->nv, na = L->na, ne = L->ne, nz = L->nz, N = go_gait_nodes(g);
  go_static_report rep;
  memset(&rep, 0, sizeof(rep));
  if (report) *report = rep;
  if (go_gait_guess_from_trial(g, coords, 0.05, z, err, errsz) != 0) return -1;
  size_t nN = (size_t)N;
  go_foot_wrench* w = (go_foot_wrench*)calloc(nN * 2, sizeof(go_foot_wrench));
  int* dofs = (int*)calloc((size_t)nv, sizeof(int));
  double* tau = (double*)calloc(nN * nv, sizeof(double));       // per node (N m, N)
  double* mom = (double*)calloc(nN * na * nv, sizeof(double));  // actuator_moment per node (m)
  double* lmt = (double*)calloc(nN * na, sizeof(double));       // lMT per node (m)
  double* vmt = (double*)calloc(nN * na, sizeof(double));       // vMT per node (m/s)
  double* P = (double*)calloc((size_t)na, sizeof(double));      // F at a = 0 (N)
  double* G = (double*)calloc((size_t)na, sizeof(double));      // dF/da (N)
  double* B = (double*)calloc((size_t)nv * na, sizeof(double)); // (N m per unit a)
  double* c = (double*)calloc((size_t)nv, sizeof(double));      // (N m)
  double* a = (double*)calloc((size_t)na, sizeof(double));
  double* t = (double*)calloc(nN, sizeof(double));              // node times (s)
  gsMuscleParams* prm = (gsMuscleParams*)calloc((size_t)na, sizeof(gsMuscleParams));
  mjData* d = mj_makeData(m);
  int status = -1, nm = 0;
  double sum_r2 = 0, sum_a = 0;
  if (!w || !dofs || !tau || !mom || !lmt || !vmt || !P || !G || !B || !c || !a || !t || !prm ||
      !d) {
    snprintf(err, errsz, "go_gait_guess: static: out of memory");
    goto done;
  }
  if (go_gait_measured_wrenches(g, grf, w, err, errsz) != 0) goto done;
  for (int j = 0; j < nv; j++) if (go_static_dof_matched(m, j)) dofs[nm++] = j;
  rep.n_matched = nm;
  for (int i = 0; i < na; i++) {
    gs_muscle_params_from_user(m->actuator_user + i * m->nuser_actuator, &prm[i], NULL, 0);
  }
  for (int k = 0; k < N; k++) {
    double* zk = z + (size_t)k * nz;
    t[k] = go_gait_stride_time(g) * k / (N - 1);
    if (go_gait_inverse_dynamics(g, d, zk, w + 2 * k, tau + (size_t)k * nv) != 0) {
      snprintf(err, errsz, "go_gait_guess: static: a foot has no contact spheres");
      goto done;
    }
    mju_copy(mom + (size_t)k * na * nv, d->actuator_moment, na * nv);
    mju_copy(lmt + (size_t)k * na, d->actuator_length, na);
    mju_copy(vmt + (size_t)k * na, d->actuator_velocity, na);
  }
  // passes over all nodes: linearise each muscle force at the previous pass's activation (0.05
  // first) and fT' (0 first), solve the node's QP, set fT in equilibrium, then fT' by periodic
  // differences
  for (int pass = 0; pass < GO_STATIC_PASSES; pass++) {
    for (int k = 0; k < N; k++) {
      double* zk = z + (size_t)k * nz;
      const double* R = mom + (size_t)k * na * nv;
      for (int i = 0; i < na; i++) {
        muscle_affine(&prm[i], zk[L->x_a + i], lmt[k * na + i], vmt[k * na + i],
                      0.0, &P[i], &G[i]);
      }
      for (int r = 0; r < nm; r++) {
        int j = dofs[r];
        c[r] = tau[(size_t)k * nv + j];
        for (int i = 0; i < na; i++) {
          B[r * na + i] = -R[i * nv + j] * G[i];
          c[r] += R[i * nv + j] * P[i];
        }
      }
      int st = go_static_opt_solve(na, nm, B, c, GO_STATIC_W_RES, GO_STATIC_A_MIN,
                                   GO_STATIC_A_MAX, a);
      if (st < 0) rep.failed_nodes++;
      else rep.steps += st;
      for (int i = 0; i < na; i++) zk[L->x_a + i] = zk[L->u_e + i] = a[i];
      for (int e = 0; e < ne; e++) {
        int i = L->elastic[e];
        double fT = elastic_fT(&prm[i], a[i], lmt[k * na + i], vmt[k * na + i], 0.0);
        zk[L->x_ft + e] = fmin(fmax(fT, 0.0), 5.0);
      }
    }
    for (int e = 0; e < ne && N >= 3; e++) {
      periodic_diff(t, z + L->x_ft + e, N, nz, z + L->xd_ft + e);
    }
  }
  // periodicity: the last node is the first's phase; activations, excitations and tendon forces
  // there set to the mean of the two (the measured trial is not exactly periodic)
  for (int v = L->x_a; v < L->x_a + na + ne; v++) {
    double mean = 0.5 * (z[v] + z[(size_t)(N - 1) * nz + v]);
    z[v] = z[(size_t)(N - 1) * nz + v] = mean;
  }
  for (int i = 0; i < na; i++) z[L->u_e + i] = z[(size_t)(N - 1) * nz + L->u_e + i] = z[L->x_a + i];
  for (int e = 0; e < ne && N >= 3; e++) periodic_diff(t, z + L->x_ft + e, N, nz, z + L->xd_ft + e);
  // spring-held dofs (not matched): shift q_j by -eom_j / k_j, twice, so the joint spring
  // balances the node's equation of motion (model contact, the guess's muscle forces; a few mm
  // on the knee translations), then their speeds and accelerations by periodic differences
  double* prow = (double*)calloc((size_t)L->n_path, sizeof(double));
  if (!prow) {
    snprintf(err, errsz, "go_gait_guess: static: out of memory");
    goto done;
  }
  for (int it = 0; it < 2; it++) {
    for (int k = 0; k < N; k++) {
      double* zk = z + (size_t)k * nz;
      go_gait_path_eval(g, d, zk, prow);
      for (int j = 0; j < nv; j++) {
        double kj = m->jnt_stiffness[m->dof_jntid[j]];
        if (go_gait_dof_is_root(m, j) || !(kj > 0) || !isfinite(prow[L->r_eom + j])) continue;
        zk[L->x_q + j] -= prow[L->r_eom + j] / kj;
      }
    }
  }
  free(prow);
  for (int j = 0; j < nv && N >= 3; j++) {
    if (go_gait_dof_is_root(m, j) || !(m->jnt_stiffness[m->dof_jntid[j]] > 0)) continue;
    periodic_diff(t, z + L->x_q + j, N, nz, z + L->x_qd + j);
    periodic_diff(t, z + L->x_qd + j, N, nz, z + L->xd_qdd + j);
    for (int k = 0; k < N; k++) z[(size_t)k * nz + L->xd_q + j] = z[(size_t)k * nz + L->x_qd + j];
  }
  for (int k = 0; k < N; k++) node_grf(m, L, d, z + (size_t)k * nz);  // grf rows hold again
  // residuals with the muscles' actual forces (elastic Fmax fT, as the eom rows)
  for (int k = 0; k < N; k++) {
    const double* zk = z + (size_t)k * nz;
    const double* R = mom + (size_t)k * na * nv;
    for (int i = 0; i < na; i++) {
      int e = L->elastic_of[i];
      P[i] = e >= 0 ? prm[i].fmax * zk[L->x_ft + e]
                    : gs_muscle_rigid_force(&prm[i], zk[L->x_a + i], lmt[k * na + i],
                                            vmt[k * na + i], NULL, NULL);
      sum_a += zk[L->x_a + i];
      if (zk[L->x_a + i] >= GO_STATIC_A_MAX) rep.n_at_upper++;
    }
    for (int r = 0; r < nm; r++) {
      int j = dofs[r];
      double res = -tau[(size_t)k * nv + j];
      for (int i = 0; i < na; i++) res -= R[i * nv + j] * P[i];
      rep.max_residual = fmax(rep.max_residual, fabs(res));
      sum_r2 += res * res;
    }
  }
  rep.rms_residual = nm > 0 ? sqrt(sum_r2 / ((double)N * nm)) : 0;
  rep.mean_activation = sum_a / ((double)N * na);
  status = 0;
  for (int v = 0; v < N * nz; v++) {
    if (!isfinite(z[v])) {
      snprintf(err, errsz, "go_gait_guess: static: non-finite value at variable %d", v);
      status = -1;
      break;
    }
  }
done:
  if (report) *report = rep;
  if (d) mj_deleteData(d);
  free(w), free(dofs), free(tau), free(mom), free(lmt), free(vmt), free(P), free(G), free(B);
  free(c), free(a), free(t), free(prm);
  return status;
}
