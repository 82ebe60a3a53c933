// go_jacobian.c: constraint Jacobian and objective gradient of the collocation NLP: analytic
// defects, per-node sparse central differences (column groups) or analytic path columns, the
// dense baseline, and the parallel node loop (see go_jacobian.h).
#include "optim/go_jacobian.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "optim/go_nlp_internal.h"

// --- per-node work ------------------------------------------------------------------------------

// path Jacobian block of node k by worker w, scaled, into vals (nnz_p, compressed-column order)
static int node_jac(go_nlp* nlp, int w, int k, const double* zs, double* vals) {
  go_worker* wk = &nlp->workers[w];
  void* ctx = go_nlp_ctx(nlp, w);
  int nz = nlp->nz;
  const double* zk = zs + (size_t)k * (size_t)nz;
  const int* cp = nlp->p_colptr;
  const int* ri = nlp->p_row;
  for (int j = 0; j < nz; j++) wk->z[j] = zk[j] * nlp->zscale[j];

  // analytic columns, physical
  if (nlp->prob.path_jac) {
    wk->path_jac_calls++;
    if (nlp->prob.path_jac(ctx, k, wk->z, wk->jv) != 0) return 1;
    for (int j = 0; j < nz; j++)
      if (nlp->analytic[j])
        for (int p = cp[j]; p < cp[j + 1]; p++) vals[p] = wk->jv[p];
  }

  // per colour group (its columns share no row) a pair of evaluations, z + h and z - h (central
  // differences), or one, z + h, against the base point z evaluated once (forward differences;
  // zm stays z). Forward, the groups go last first: the groups of speeds and other
  // non-coordinate columns come last in the layout, so they follow the base point at its
  // coordinates and reuse its position stage (go_gait.c, node_inverse)
  int fwd = nlp->mode == GO_JAC_SPARSE_FORWARD;
  memcpy(wk->zp, wk->z, sizeof(double) * (size_t)nz);
  memcpy(wk->zm, wk->z, sizeof(double) * (size_t)nz);
  if (fwd && nlp->ngroup > 0) {
    wk->path_evals++;
    if (nlp->prob.path(ctx, k, wk->z, wk->gm) != 0) return 1;
  }
  for (int i = 0; i < nlp->ngroup; i++) {
    int g = fwd ? nlp->ngroup - 1 - i : i;
    int c0 = nlp->grp_ptr[g], c1 = nlp->grp_ptr[g + 1];
    for (int q = c0; q < c1; q++) {
      int j = nlp->grp_col[q];
      // step in physical units
      double hs = (fwd ? go_fd_step_forward(zk[j]) : go_fd_step(zk[j])) * nlp->zscale[j];
      wk->zp[j] = wk->z[j] + hs;
      if (!fwd) wk->zm[j] = wk->z[j] - hs;
    }
    wk->path_evals += fwd ? 1 : 2;
    if (nlp->prob.path(ctx, k, wk->zp, wk->gp) != 0) return 1;
    if (!fwd && nlp->prob.path(ctx, k, wk->zm, wk->gm) != 0) return 1;
    for (int q = c0; q < c1; q++) {
      int j = nlp->grp_col[q];
      double inv = 1.0 / (wk->zp[j] - wk->zm[j]);  // exact representable step
      for (int p = cp[j]; p < cp[j + 1]; p++) vals[p] = (wk->gp[ri[p]] - wk->gm[ri[p]]) * inv;
      wk->zp[j] = wk->z[j];
      wk->zm[j] = wk->z[j];
    }
  }

  // scale: d(g/s_r) / d(z/s_j) = dg/dz * s_j / s_r
  for (int j = 0; j < nz; j++) {
    for (int p = cp[j]; p < cp[j + 1]; p++) {
      vals[p] *= nlp->zscale[j] / nlp->pscale[ri[p]];
      if (!isfinite(vals[p])) return 2;
    }
  }
  return 0;
}

// integrand and its physical gradient at node k by worker w into Lk[k], dLk[k nz ..]
static int node_dL(go_nlp* nlp, int w, int k, const double* zs) {
  go_worker* wk = &nlp->workers[w];
  void* ctx = go_nlp_ctx(nlp, w);
  int nz = nlp->nz;
  double* dL = nlp->dLk + (size_t)k * (size_t)nz;
  const double* zk = zs + (size_t)k * (size_t)nz;
  int s = go_nlp_node_L(nlp, w, k, zs, &nlp->Lk[k]);  // leaves wk->z = physical z_k
  if (s) return s;
  for (int j = 0; j < nz; j++) dL[j] = 0.0;
  if (!nlp->prob.integrand) return 0;
  if (nlp->prob.integrand_grad) {
    if (nlp->prob.integrand_grad(ctx, k, wk->z, dL) != 0) return 1;
  } else {
    memcpy(wk->zp, wk->z, sizeof(double) * (size_t)nz);
    for (int i = 0; i < nlp->n_ivars; i++) {
      int j = nlp->ivars[i];
      double hs = go_fd_step(zk[j]) * nlp->zscale[j], Lp, Lm;
      wk->zp[j] = wk->z[j] + hs;
      double zpj = wk->zp[j];
      wk->integrand_evals += 2;
      if (nlp->prob.integrand(ctx, k, wk->zp, &Lp) != 0) return 1;
      wk->zp[j] = wk->z[j] - hs;
      double zmj = wk->zp[j];
      if (nlp->prob.integrand(ctx, k, wk->zp, &Lm) != 0) return 1;
      wk->zp[j] = wk->z[j];
      dL[j] = (Lp - Lm) / (zpj - zmj);
    }
  }
  for (int j = 0; j < nz; j++)
    if (!isfinite(dL[j])) return 2;
  return 0;
}

// dense baseline: Jacobian column v by central differences of the whole constraint vector
static int dense_jac_col(go_nlp* nlp, int w, int v, const double* zs, double* vals) {
  go_worker* wk = &nlp->workers[w];
  memcpy(wk->fz, zs, sizeof(double) * (size_t)nlp->n);
  double h = go_fd_step(zs[v]);
  wk->fz[v] = zs[v] + h;
  double zp = wk->fz[v];
  if (go_nlp_eval_g_serial(nlp, w, wk->fz, wk->fgp)) return 1;
  wk->fz[v] = zs[v] - h;
  double zm = wk->fz[v];
  if (go_nlp_eval_g_serial(nlp, w, wk->fz, wk->fgm)) return 1;
  double inv = 1.0 / (zp - zm);
  for (int q = nlp->jc_ptr[v]; q < nlp->jc_ptr[v + 1]; q++) {
    int e = nlp->jc_ent[q], r = nlp->irow[e];
    vals[e] = (wk->fgp[r] - wk->fgm[r]) * inv;
  }
  return 0;
}

// dense baseline: gradient entry v by central differences of the whole objective
static int dense_grad_entry(go_nlp* nlp, int w, int v, const double* zs, double* grad) {
  go_worker* wk = &nlp->workers[w];
  memcpy(wk->fz, zs, sizeof(double) * (size_t)nlp->n);
  double h = go_fd_step(zs[v]), fp, fm;
  wk->fz[v] = zs[v] + h;
  double zp = wk->fz[v];
  if (go_nlp_eval_f_serial(nlp, w, wk->fz, &fp)) return 1;
  wk->fz[v] = zs[v] - h;
  double zm = wk->fz[v];
  if (go_nlp_eval_f_serial(nlp, w, wk->fz, &fm)) return 1;
  grad[v] = (fp - fm) / (zp - zm);
  return 0;
}

// the body of every parallel loop: item is a node (or a variable for the dense baseline);
// results go to the item's own slots only
void go_nlp_task(void* arg, int w, int item) {
  go_nlp* nlp = arg;
  const double* zs = nlp->task_zs;
  int s = 0;
  switch (nlp->task) {
    case GO_TASK_G:
      s = go_nlp_node_g(nlp, w, item, zs, nlp->task_out + nlp->row_path + item * nlp->np);
      break;
    case GO_TASK_JAC:
      s = node_jac(nlp, w, item, zs, nlp->task_out + nlp->off_path + item * nlp->nnz_p);
      break;
    case GO_TASK_L:
      s = go_nlp_node_L(nlp, w, item, zs, &nlp->Lk[item]);
      break;
    case GO_TASK_DL:
      s = node_dL(nlp, w, item, zs);
      break;
    case GO_TASK_DENSE_JAC:
      s = dense_jac_col(nlp, w, item, zs, nlp->task_out);
      break;
    case GO_TASK_DENSE_GRAD:
      s = dense_grad_entry(nlp, w, item, zs, nlp->task_out);
      break;
  }
  nlp->status[item] = s;
}

// --- Jacobian -----------------------------------------------------------------------------------

void go_nlp_jac_structure(const go_nlp* nlp, int* irow, int* jcol) {
  memcpy(irow, nlp->irow, sizeof(int) * (size_t)nlp->nele);
  memcpy(jcol, nlp->jcol, sizeof(int) * (size_t)nlp->nele);
}

// analytic defect entries (scaled), order of go_jacobian.h
static void defect_jac(const go_nlp* nlp, const double* zs, double* vals) {
  int nz = nlp->nz, nx = nlp->nx, e = 0;
  double h = go_nlp_time(nlp, zs) / (nlp->N - 1);
  for (int k = 0; k + 1 < nlp->N; k++) {
    const double* a = zs + (size_t)k * (size_t)nz;
    const double* b = a + nz;
    for (int i = 0; i < nx; i++) {
      double s = nlp->zscale[i], sd = nlp->zscale[nx + i];
      vals[e++] = -1.0;                 // x_{k,i}
      vals[e++] = 1.0;                  // x_{k+1,i}
      vals[e++] = -0.5 * h * sd / s;    // xdot_{k,i}
      vals[e++] = -0.5 * h * sd / s;    // xdot_{k+1,i}
      if (nlp->free_time)               // T: -(xdot_k + xdot_{k+1}) / (2 (N-1)), scaled
        vals[e++] = -0.5 * (a[nx + i] + b[nx + i]) * sd * nlp->T_scale / ((nlp->N - 1) * s);
    }
  }
}

// boundary entries by central differences, one column at a time (worker 0 scratch, serial)
static int boundary_jac(go_nlp* nlp, const double* zs, double* vals) {
  go_worker* wk = &nlp->workers[0];
  void* ctx = go_nlp_ctx(nlp, 0);
  int nz = nlp->nz, e = nlp->off_bnd;
  const double* z0 = zs;
  const double* z1 = zs + (size_t)(nlp->N - 1) * (size_t)nz;
  double* bz = wk->bz;
  for (int j = 0; j < nz; j++) {
    bz[j] = z0[j] * nlp->zscale[j];
    bz[nz + j] = z1[j] * nlp->zscale[j];
  }
  bz[2 * nz] = go_nlp_time(nlp, zs);
  for (int cb = 0; cb < 2 * nz + 1; cb++) {
    if (cb == 2 * nz && !nlp->free_time) break;
    if (nlp->b_colptr[cb] == nlp->b_colptr[cb + 1]) continue;
    double zsj = cb < nz ? z0[cb] : (cb < 2 * nz ? z1[cb - nz] : zs[nlp->N * nz]);
    double sc = cb < 2 * nz ? nlp->zscale[cb % nz] : nlp->T_scale;
    double base = bz[cb], hs = go_fd_step(zsj) * sc;
    bz[cb] = base + hs;
    double zp = bz[cb];
    wk->boundary_evals += 2;
    if (nlp->prob.boundary(ctx, bz, bz + nz, bz[2 * nz], nlp->bp) != 0) return 1;
    bz[cb] = base - hs;
    double zm = bz[cb];
    if (nlp->prob.boundary(ctx, bz, bz + nz, bz[2 * nz], nlp->bm) != 0) return 1;
    bz[cb] = base;
    for (int p = nlp->b_colptr[cb]; p < nlp->b_colptr[cb + 1]; p++) {
      int r = nlp->b_row[p];
      vals[e] = (nlp->bp[r] - nlp->bm[r]) / (zp - zm) * sc / nlp->bscale[r];
      if (!isfinite(vals[e])) return 2;
      e++;
    }
  }
  return 0;
}

static long total_path_evals(const go_nlp* nlp) {
  long s = 0;
  for (int w = 0; w < nlp->nthreads; w++) s += nlp->workers[w].path_evals;
  return s;
}

int go_nlp_eval_jac(go_nlp* nlp, const double* zs, double* vals) {
  nlp->jac_evals++;
  long before = total_path_evals(nlp);
  int rc = 0;
  nlp->task_zs = zs;
  nlp->task_out = vals;
  if (nlp->mode == GO_JAC_DENSE) {
    nlp->task = GO_TASK_DENSE_JAC;
    go_pool_run(nlp->pool, nlp->n, go_nlp_task, nlp);
    rc = go_nlp_check_status(nlp, nlp->n, "dense finite differences, variable");
  } else {
    defect_jac(nlp, zs, vals);
    if (nlp->np > 0) {
      nlp->task = GO_TASK_JAC;
      go_pool_run(nlp->pool, nlp->N, go_nlp_task, nlp);
      rc = go_nlp_check_status(nlp, nlp->N, "path Jacobian at node");
    }
    if (!rc && nlp->nb > 0) {
      int s = boundary_jac(nlp, zs, vals);
      if (s) {
        snprintf(nlp->err, sizeof(nlp->err), "boundary Jacobian: %s",
                 s == 2 ? "non-finite value" : "callback failed");
        rc = -1;
      }
    }
  }
  nlp->path_evals_last_jac = total_path_evals(nlp) - before;
  return rc;
}

// --- objective gradient -------------------------------------------------------------------------

int go_nlp_eval_grad_f(go_nlp* nlp, const double* zs, double* grad) {
  int nz = nlp->nz, N = nlp->N;
  nlp->task_zs = zs;
  if (nlp->mode == GO_JAC_DENSE) {
    nlp->task = GO_TASK_DENSE_GRAD;
    nlp->task_out = grad;
    go_pool_run(nlp->pool, nlp->n, go_nlp_task, nlp);
    return go_nlp_check_status(nlp, nlp->n, "dense objective gradient, variable");
  }
  nlp->task = GO_TASK_DL;
  go_pool_run(nlp->pool, N, go_nlp_task, nlp);
  if (go_nlp_check_status(nlp, N, "integrand gradient at node")) return -1;

  // reduce in node order
  double T = go_nlp_time(nlp, zs), h = T / (N - 1), S = 0.0, J, dJdI, dJdT;
  for (int k = 0; k < N; k++) S += go_nlp_weight(nlp, k) * nlp->Lk[k];
  if (!nlp->prob.outer) {
    dJdI = 1.0;
    dJdT = 0.0;
  } else if (nlp->prob.outer(go_nlp_ctx(nlp, 0), S * h, T, &J, &dJdI, &dJdT) != 0 ||
             !isfinite(dJdI) || !isfinite(dJdT)) {
    snprintf(nlp->err, sizeof(nlp->err), "objective outer(): failed or non-finite");
    return -1;
  }
  for (int k = 0; k < N; k++) {
    double c = dJdI * go_nlp_weight(nlp, k) * h / nlp->obj_scale;
    const double* dL = nlp->dLk + (size_t)k * (size_t)nz;
    for (int j = 0; j < nz; j++) grad[k * nz + j] = c * dL[j] * nlp->zscale[j];
  }
  // dI/dT = sum_k w_k L_k / (N-1)
  if (nlp->free_time)
    grad[N * nz] = (dJdI * S / (N - 1) + dJdT) * nlp->T_scale / nlp->obj_scale;
  return 0;
}

// --- Gauss-Newton Hessian ---------------------------------------------------------------------

int go_nlp_has_hess_diag(const go_nlp* nlp) {
  return nlp->prob.integrand != NULL && nlp->prob.integrand_hess != NULL;
}

int go_nlp_integrand_factor(go_nlp* nlp, const double* zs, const char* who, double* h,
                            double* dJdI) {
  int N = nlp->N;
  // integrand at every node for outer()'s dJ/dI (serial: N cheap evaluations)
  double T = go_nlp_time(nlp, zs), S = 0.0, J, dJdT;
  *h = T / (N - 1);
  *dJdI = 1.0;
  for (int k = 0; k < N; k++) {
    double L;
    if (go_nlp_node_L(nlp, 0, k, zs, &L)) {
      snprintf(nlp->err, sizeof(nlp->err), "%s: integrand failed at node %d", who, k);
      return -1;
    }
    S += go_nlp_weight(nlp, k) * L;
  }
  if (nlp->prob.outer &&
      (nlp->prob.outer(go_nlp_ctx(nlp, 0), S * *h, T, &J, dJdI, &dJdT) != 0 || !isfinite(*dJdI))) {
    snprintf(nlp->err, sizeof(nlp->err), "objective outer(): failed or non-finite");
    return -1;
  }
  return 0;
}

int go_nlp_eval_hess_diag(go_nlp* nlp, const double* zs, double obj_factor, double* diag) {
  int nz = nlp->nz, N = nlp->N;
  if (!go_nlp_has_hess_diag(nlp)) {
    snprintf(nlp->err, sizeof(nlp->err), "Gauss-Newton Hessian: the problem has no integrand_hess");
    return -1;
  }
  double h, dJdI;
  if (go_nlp_integrand_factor(nlp, zs, "Gauss-Newton Hessian", &h, &dJdI)) return -1;
  // node diagonals, in the solver's scaling
  go_worker* wk = &nlp->workers[0];
  for (int k = 0; k < N; k++) {
    const double* zk = zs + (size_t)k * (size_t)nz;
    for (int j = 0; j < nz; j++) wk->z[j] = zk[j] * nlp->zscale[j];
    double* dk = diag + (size_t)k * (size_t)nz;
    if (nlp->prob.integrand_hess(go_nlp_ctx(nlp, 0), k, wk->z, dk) != 0) {
      snprintf(nlp->err, sizeof(nlp->err), "Gauss-Newton Hessian: integrand_hess failed at node %d", k);
      return -1;
    }
    double c = obj_factor * dJdI * go_nlp_weight(nlp, k) * h / nlp->obj_scale;
    for (int j = 0; j < nz; j++) {
      dk[j] *= c * nlp->zscale[j] * nlp->zscale[j];
      if (!isfinite(dk[j])) {
        snprintf(nlp->err, sizeof(nlp->err), "Gauss-Newton Hessian: non-finite at node %d", k);
        return -1;
      }
    }
  }
  if (nlp->free_time) diag[N * nz] = 0.0;
  return 0;
}

void go_nlp_set_jac_mode(go_nlp* nlp, go_jac_mode mode) { nlp->mode = mode; }

int go_nlp_path_groups(const go_nlp* nlp) { return nlp->ngroup; }
