// go_collocation.c: description checks, memory layout, bounds, scaling and function values of the
// collocation NLP (go_collocation.h). Derivatives are in go_jacobian.c.
#include "optim/go_collocation.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "optim/go_coloring.h"
#include "optim/go_jacobian.h"
#include "optim/go_nlp_internal.h"

// --- single allocation ------------------------------------------------------------------------

typedef struct {
  char* base;   // NULL while measuring
  size_t off;   // bytes used so far
} carve;

static void* take(carve* c, size_t count, size_t size) {
  size_t o = (c->off + 63) & ~(size_t)63;
  c->off = o + count * size;
  return c->base ? (void*)(c->base + o) : NULL;
}

// carve every array of nlp from c (sizes from the dims already in nlp)
static void layout(go_nlp* nlp, carve* c, int nnz_b, int nthreads) {
  int nz = nlp->nz, n = nlp->n, m = nlp->m, np = nlp->np, nb = nlp->nb;
  nlp->zl = take(c, (size_t)n, sizeof(double));
  nlp->zu = take(c, (size_t)n, sizeof(double));
  nlp->zscale = take(c, (size_t)nz, sizeof(double));
  nlp->pscale = take(c, (size_t)np, sizeof(double));
  nlp->plb = take(c, (size_t)np, sizeof(double));
  nlp->pub = take(c, (size_t)np, sizeof(double));
  nlp->bscale = take(c, (size_t)nb, sizeof(double));
  nlp->blb = take(c, (size_t)nb, sizeof(double));
  nlp->bub = take(c, (size_t)nb, sizeof(double));
  nlp->p_colptr = take(c, (size_t)nz + 1, sizeof(int));
  nlp->p_row = take(c, (size_t)nlp->nnz_p, sizeof(int));
  nlp->analytic = take(c, (size_t)nz, 1);
  nlp->grp_ptr = take(c, (size_t)nz + 1, sizeof(int));
  nlp->grp_col = take(c, (size_t)nz, sizeof(int));
  nlp->ivars = take(c, (size_t)nz, sizeof(int));
  nlp->b_colptr = take(c, (size_t)2 * nz + 2, sizeof(int));
  nlp->b_row = take(c, (size_t)nnz_b, sizeof(int));
  nlp->bp = take(c, (size_t)nb, sizeof(double));
  nlp->bm = take(c, (size_t)nb, sizeof(double));
  nlp->irow = take(c, (size_t)nlp->nele, sizeof(int));
  nlp->jcol = take(c, (size_t)nlp->nele, sizeof(int));
  nlp->jc_ptr = take(c, (size_t)n + 1, sizeof(int));
  nlp->jc_ent = take(c, (size_t)nlp->nele, sizeof(int));
  nlp->Lk = take(c, (size_t)nlp->N, sizeof(double));
  nlp->dLk = take(c, (size_t)nlp->N * (size_t)nz, sizeof(double));
  nlp->status = take(c, (size_t)(n > nlp->N ? n : nlp->N), sizeof(int));
  nlp->workers = take(c, (size_t)nthreads, sizeof(go_worker));
  for (int w = 0; w < nthreads; w++) {
    go_worker* wk = c->base ? &nlp->workers[w] : NULL;
    double* p[10];
    p[0] = take(c, (size_t)nz, sizeof(double));
    p[1] = take(c, (size_t)nz, sizeof(double));
    p[2] = take(c, (size_t)nz, sizeof(double));
    p[3] = take(c, (size_t)np, sizeof(double));
    p[4] = take(c, (size_t)np, sizeof(double));
    p[5] = take(c, (size_t)nlp->nnz_p, sizeof(double));
    p[6] = take(c, (size_t)n, sizeof(double));
    p[7] = take(c, (size_t)m, sizeof(double));
    p[8] = take(c, (size_t)m, sizeof(double));
    p[9] = take(c, (size_t)2 * nz + 1, sizeof(double));
    if (wk) {
      memset(wk, 0, sizeof(*wk));
      wk->z = p[0];
      wk->zp = p[1];
      wk->zm = p[2];
      wk->gp = p[3];
      wk->gm = p[4];
      wk->jv = p[5];
      wk->fz = p[6];
      wk->fgp = p[7];
      wk->fgm = p[8];
      wk->bz = p[9];
    }
  }
}

static int fail(char* err, int errsz, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, (size_t)errsz, fmt, ap);
  va_end(ap);
  return -1;
}

static int positive_or_default(const double* a, int i, double* out) {
  double v = a ? a[i] : 1.0;
  if (!(v > 0) || !isfinite(v)) return -1;
  *out = v;
  return 0;
}

// --- create -----------------------------------------------------------------------------------

int go_nlp_create(go_nlp** out, const go_problem* prob, char* err, int errsz) {
  *out = NULL;
  const go_dims* d = &prob->dims;
  int nz = 2 * d->nx + d->nu;

  // dims and callbacks
  if (d->N < 2 || d->nx < 0 || d->nu < 0 || nz < 1 || d->n_path < 0 || d->n_boundary < 0)
    return fail(err, errsz, "collocation: bad dims (N=%d nx=%d nu=%d n_path=%d n_boundary=%d)",
                d->N, d->nx, d->nu, d->n_path, d->n_boundary);
  if (prob->nthreads < 1) return fail(err, errsz, "collocation: nthreads %d < 1", prob->nthreads);
  if (d->n_path > 0 && (!prob->path || !prob->path_col_ptr || !prob->path_row_idx))
    return fail(err, errsz, "collocation: n_path > 0 needs path() and its pattern");
  if (d->n_boundary > 0 && (!prob->boundary || !prob->bnd_col_ptr || !prob->bnd_row_idx))
    return fail(err, errsz, "collocation: n_boundary > 0 needs boundary() and its pattern");
  if (prob->path_analytic && !prob->path_jac)
    return fail(err, errsz, "collocation: path_analytic given without path_jac");
  if (!d->free_time && !(prob->T > 0))
    return fail(err, errsz, "collocation: fixed final time T = %g must be > 0", prob->T);
  if (d->free_time && !(prob->T_lb <= prob->T_ub))
    return fail(err, errsz, "collocation: T bounds [%g, %g] empty", prob->T_lb, prob->T_ub);

  // pattern sizes
  int nnz_p = 0;
  if (d->n_path > 0) {
    if (prob->path_col_ptr[0] != 0) return fail(err, errsz, "path pattern: col_ptr[0] != 0");
    for (int j = 0; j < nz; j++)
      if (prob->path_col_ptr[j + 1] < prob->path_col_ptr[j])
        return fail(err, errsz, "path pattern: col_ptr decreases at column %d", j);
    nnz_p = prob->path_col_ptr[nz];
  }
  int nnz_b = 0, nnz_bT = 0;
  if (d->n_boundary > 0) {
    if (prob->bnd_col_ptr[0] != 0) return fail(err, errsz, "boundary pattern: col_ptr[0] != 0");
    for (int j = 0; j < 2 * nz + 1; j++)
      if (prob->bnd_col_ptr[j + 1] < prob->bnd_col_ptr[j])
        return fail(err, errsz, "boundary pattern: col_ptr decreases at column %d", j);
    nnz_b = prob->bnd_col_ptr[2 * nz + 1];
    nnz_bT = prob->bnd_col_ptr[2 * nz + 1] - prob->bnd_col_ptr[2 * nz];
  }

  // sizes of the NLP
  go_nlp tmp;
  memset(&tmp, 0, sizeof(tmp));
  tmp.N = d->N;
  tmp.nx = d->nx;
  tmp.nu = d->nu;
  tmp.nz = nz;
  tmp.np = d->n_path;
  tmp.nb = d->n_boundary;
  tmp.free_time = d->free_time ? 1 : 0;
  tmp.n = d->N * nz + tmp.free_time;
  tmp.m = (d->N - 1) * d->nx + d->N * d->n_path + d->n_boundary;
  tmp.nnz_p = nnz_p;
  tmp.row_path = (d->N - 1) * d->nx;
  tmp.row_bnd = tmp.row_path + d->N * d->n_path;
  tmp.off_path = (d->N - 1) * d->nx * (4 + tmp.free_time);
  tmp.off_bnd = tmp.off_path + d->N * nnz_p;
  tmp.nele = tmp.off_bnd + nnz_b - (tmp.free_time ? 0 : nnz_bT);
  tmp.nthreads = prob->nthreads;

  // one allocation
  carve c = {NULL, 0};
  layout(&tmp, &c, nnz_b, prob->nthreads);
  size_t bytes = c.off + 64;
  void* mem = calloc(1, bytes);
  go_nlp* nlp = calloc(1, sizeof(go_nlp));
  if (!mem || !nlp) {
    free(mem);
    free(nlp);
    return fail(err, errsz, "collocation: out of memory (%zu bytes)", bytes);
  }
  *nlp = tmp;
  nlp->prob = *prob;
  nlp->mem = mem;
  c.base = (char*)(((size_t)mem + 63) & ~(size_t)63);
  c.off = 0;
  layout(nlp, &c, nnz_b, prob->nthreads);
  nlp->mode = prob->jac_mode;
  nlp->T_fixed = prob->T;

  // scales
  int rc = 0;
  for (int j = 0; j < nz && !rc; j++)
    if (positive_or_default(prob->z_scale, j, &nlp->zscale[j]))
      rc = fail(err, errsz, "collocation: z_scale[%d] must be finite and > 0", j);
  for (int r = 0; r < nlp->np && !rc; r++)
    if (positive_or_default(prob->path_scale, r, &nlp->pscale[r]))
      rc = fail(err, errsz, "collocation: path_scale[%d] must be finite and > 0", r);
  for (int r = 0; r < nlp->nb && !rc; r++)
    if (positive_or_default(prob->boundary_scale, r, &nlp->bscale[r]))
      rc = fail(err, errsz, "collocation: boundary_scale[%d] must be finite and > 0", r);
  nlp->T_scale = prob->T_scale > 0 ? prob->T_scale : 1.0;
  nlp->obj_scale = prob->obj_scale > 0 ? prob->obj_scale : 1.0;

  // variable bounds: every node, then overrides, then T
  for (int k = 0; k < nlp->N && !rc; k++) {
    for (int j = 0; j < nz; j++) {
      nlp->zl[k * nz + j] = prob->z_lb ? prob->z_lb[j] : -GO_INF;
      nlp->zu[k * nz + j] = prob->z_ub ? prob->z_ub[j] : GO_INF;
    }
  }
  for (int i = 0; i < prob->n_overrides && !rc; i++) {
    const go_bound_override* o = &prob->overrides[i];
    int k = o->node < 0 ? nlp->N + o->node : o->node;
    if (k < 0 || k >= nlp->N || o->var < 0 || o->var >= nz) {
      rc = fail(err, errsz, "collocation: bound override %d (node %d, var %d) out of range", i,
                o->node, o->var);
      break;
    }
    nlp->zl[k * nz + o->var] = o->lb;
    nlp->zu[k * nz + o->var] = o->ub;
  }
  if (nlp->free_time) {
    nlp->zl[nlp->N * nz] = prob->T_lb;
    nlp->zu[nlp->N * nz] = prob->T_ub;
  }
  for (int v = 0; v < nlp->n && !rc; v++)
    if (nlp->zl[v] > nlp->zu[v] || isnan(nlp->zl[v]) || isnan(nlp->zu[v]))
      rc = fail(err, errsz, "collocation: empty bounds [%g, %g] on variable %d", nlp->zl[v],
                nlp->zu[v], v);

  // constraint bounds
  for (int r = 0; r < nlp->np; r++) {
    nlp->plb[r] = prob->path_lb ? prob->path_lb[r] : 0.0;
    nlp->pub[r] = prob->path_ub ? prob->path_ub[r] : 0.0;
  }
  for (int r = 0; r < nlp->nb; r++) {
    nlp->blb[r] = prob->boundary_lb ? prob->boundary_lb[r] : 0.0;
    nlp->bub[r] = prob->boundary_ub ? prob->boundary_ub[r] : 0.0;
  }

  // path pattern, analytic columns, colour groups
  if (!rc && nlp->np > 0) {
    memcpy(nlp->p_colptr, prob->path_col_ptr, sizeof(int) * (size_t)(nz + 1));
    memcpy(nlp->p_row, prob->path_row_idx, sizeof(int) * (size_t)nnz_p);
    for (int j = 0; j < nz; j++) nlp->analytic[j] = prob->path_analytic ? prob->path_analytic[j] : 0;
    int* color = nlp->grp_col;  // temporary: colours, regrouped below
    int ng = go_color_columns(nlp->np, nz, nlp->p_colptr, nlp->p_row, nlp->analytic, color, err,
                              errsz);
    if (ng < 0) {
      rc = -1;
    } else {
      // counting sort of the columns by colour (ascending column within a group)
      int* col_of = malloc(sizeof(int) * (size_t)nz);
      if (!col_of) {
        rc = fail(err, errsz, "collocation: out of memory");
      } else {
        memcpy(col_of, color, sizeof(int) * (size_t)nz);
        for (int g = 0; g <= ng; g++) nlp->grp_ptr[g] = 0;
        for (int j = 0; j < nz; j++)
          if (col_of[j] >= 0) nlp->grp_ptr[col_of[j] + 1]++;
        for (int g = 0; g < ng; g++) nlp->grp_ptr[g + 1] += nlp->grp_ptr[g];
        for (int g = 0; g < ng; g++) {
          int pos = nlp->grp_ptr[g];
          for (int j = 0; j < nz; j++)
            if (col_of[j] == g) nlp->grp_col[pos++] = j;
        }
        free(col_of);
        nlp->ngroup = ng;
      }
    }
  } else if (!rc) {
    nlp->p_colptr[0] = 0;
    for (int j = 0; j < nz; j++) nlp->p_colptr[j + 1] = 0;
    nlp->grp_ptr[0] = 0;
    nlp->ngroup = 0;
  }

  // integrand variables
  if (!rc && prob->integrand) {
    if (prob->n_integrand_vars < 0 || prob->n_integrand_vars > nz ||
        (prob->n_integrand_vars > 0 && !prob->integrand_vars)) {
      rc = fail(err, errsz, "collocation: bad integrand_vars (%d)", prob->n_integrand_vars);
    } else {
      for (int i = 0; i < prob->n_integrand_vars && !rc; i++) {
        int j = prob->integrand_vars[i];
        if (j < 0 || j >= nz) rc = fail(err, errsz, "collocation: integrand var %d out of range", j);
        for (int i2 = 0; i2 < i && !rc; i2++)
          if (prob->integrand_vars[i2] == j)
            rc = fail(err, errsz, "collocation: integrand var %d listed twice", j);
        nlp->ivars[i] = j;
      }
      nlp->n_ivars = prob->n_integrand_vars;
    }
  }

  // boundary pattern (validated by the colouring routine; colours unused)
  if (!rc && nlp->nb > 0) {
    memcpy(nlp->b_colptr, prob->bnd_col_ptr, sizeof(int) * (size_t)(2 * nz + 2));
    memcpy(nlp->b_row, prob->bnd_row_idx, sizeof(int) * (size_t)nnz_b);
    int* color = malloc(sizeof(int) * (size_t)(2 * nz + 1));
    if (!color) {
      rc = fail(err, errsz, "collocation: out of memory");
    } else {
      char e2[200];
      if (go_color_columns(nlp->nb, 2 * nz + 1, nlp->b_colptr, nlp->b_row, NULL, color, e2,
                           (int)sizeof(e2)) < 0)
        rc = fail(err, errsz, "boundary %s", e2);
      free(color);
    }
  } else if (!rc) {
    for (int j = 0; j < 2 * nz + 2; j++) nlp->b_colptr[j] = 0;
  }

  // Jacobian pattern: defects, path blocks, boundary (see go_jacobian.h)
  if (!rc) {
    int e = 0, N = nlp->N, nx = nlp->nx, Tcol = N * nz;
    for (int k = 0; k + 1 < N; k++) {
      for (int i = 0; i < nx; i++) {
        int row = k * nx + i;
        int cols[5] = {k * nz + i, (k + 1) * nz + i, k * nz + nx + i, (k + 1) * nz + nx + i, Tcol};
        for (int q = 0; q < 4 + nlp->free_time; q++) {
          nlp->irow[e] = row;
          nlp->jcol[e] = cols[q];
          e++;
        }
      }
    }
    if (e != nlp->off_path) rc = fail(err, errsz, "collocation: defect entries %d != %d", e, nlp->off_path);
    for (int k = 0; k < N && !rc; k++) {
      for (int j = 0; j < nz; j++) {
        for (int p = nlp->p_colptr[j]; p < nlp->p_colptr[j + 1]; p++) {
          nlp->irow[e] = nlp->row_path + k * nlp->np + nlp->p_row[p];
          nlp->jcol[e] = k * nz + j;
          e++;
        }
      }
    }
    if (!rc && e != nlp->off_bnd) rc = fail(err, errsz, "collocation: path entries %d != %d", e, nlp->off_bnd);
    for (int cb = 0; cb < 2 * nz + 1 && !rc && nlp->nb > 0; cb++) {
      if (cb == 2 * nz && !nlp->free_time) break;
      int col = cb < nz ? cb : (cb < 2 * nz ? (N - 1) * nz + (cb - nz) : Tcol);
      for (int p = nlp->b_colptr[cb]; p < nlp->b_colptr[cb + 1]; p++) {
        nlp->irow[e] = nlp->row_bnd + nlp->b_row[p];
        nlp->jcol[e] = col;
        e++;
      }
    }
    // the count must be exactly nele_jac
    if (!rc && e != nlp->nele)
      rc = fail(err, errsz, "collocation: Jacobian pattern filled %d entries, nele_jac %d", e,
                nlp->nele);
  }

  // entries by column (dense baseline)
  if (!rc) {
    for (int v = 0; v <= nlp->n; v++) nlp->jc_ptr[v] = 0;
    for (int e = 0; e < nlp->nele; e++) nlp->jc_ptr[nlp->jcol[e] + 1]++;
    for (int v = 0; v < nlp->n; v++) nlp->jc_ptr[v + 1] += nlp->jc_ptr[v];
    int* cur = nlp->status;  // scratch of size >= n
    for (int v = 0; v < nlp->n; v++) cur[v] = nlp->jc_ptr[v];
    for (int e = 0; e < nlp->nele; e++) nlp->jc_ent[cur[nlp->jcol[e]]++] = e;
  }

  // threads
  if (!rc && go_pool_create(&nlp->pool, prob->nthreads, err, errsz) != 0) rc = -1;
  if (rc) {
    go_nlp_free(nlp);
    return -1;
  }
  *out = nlp;
  return 0;
}

void go_nlp_free(go_nlp* nlp) {
  if (!nlp) return;
  go_pool_free(nlp->pool);
  free(nlp->mem);
  free(nlp);
}

// --- sizes, indices, scaling, bounds ----------------------------------------------------------

void go_nlp_sizes(const go_nlp* nlp, int* n, int* m, int* nele_jac) {
  if (n) *n = nlp->n;
  if (m) *m = nlp->m;
  if (nele_jac) *nele_jac = nlp->nele;
}

int go_nlp_nz(const go_nlp* nlp) { return nlp->nz; }
int go_nlp_var(const go_nlp* nlp, int k, int j) { return k * nlp->nz + j; }
int go_nlp_row_defect(const go_nlp* nlp, int k, int i) { return k * nlp->nx + i; }
int go_nlp_row_path(const go_nlp* nlp, int k, int r) { return nlp->row_path + k * nlp->np + r; }
int go_nlp_row_boundary(const go_nlp* nlp, int b) { return nlp->row_bnd + b; }

void go_nlp_scale_z(const go_nlp* nlp, const double* z, double* zs) {
  for (int k = 0; k < nlp->N; k++)
    for (int j = 0; j < nlp->nz; j++) zs[k * nlp->nz + j] = z[k * nlp->nz + j] / nlp->zscale[j];
  if (nlp->free_time) zs[nlp->N * nlp->nz] = z[nlp->N * nlp->nz] / nlp->T_scale;
}

void go_nlp_unscale_z(const go_nlp* nlp, const double* zs, double* z) {
  for (int k = 0; k < nlp->N; k++)
    for (int j = 0; j < nlp->nz; j++) z[k * nlp->nz + j] = zs[k * nlp->nz + j] * nlp->zscale[j];
  if (nlp->free_time) z[nlp->N * nlp->nz] = zs[nlp->N * nlp->nz] * nlp->T_scale;
}

double go_nlp_time(const go_nlp* nlp, const double* zs) {
  return nlp->free_time ? zs[nlp->N * nlp->nz] * nlp->T_scale : nlp->T_fixed;
}

// scale a bound, keeping infinities infinite
static double scale_bound(double b, double s) {
  if (b <= -1e19) return -GO_INF;
  if (b >= 1e19) return GO_INF;
  return b / s;
}

void go_nlp_bounds(const go_nlp* nlp, double* zl, double* zu, double* gl, double* gu) {
  int nz = nlp->nz;
  for (int v = 0; v < nlp->N * nz; v++) {
    if (zl) zl[v] = scale_bound(nlp->zl[v], nlp->zscale[v % nz]);
    if (zu) zu[v] = scale_bound(nlp->zu[v], nlp->zscale[v % nz]);
  }
  if (nlp->free_time) {
    if (zl) zl[nlp->N * nz] = scale_bound(nlp->zl[nlp->N * nz], nlp->T_scale);
    if (zu) zu[nlp->N * nz] = scale_bound(nlp->zu[nlp->N * nz], nlp->T_scale);
  }
  for (int r = 0; r < nlp->row_path; r++) {
    if (gl) gl[r] = 0.0;
    if (gu) gu[r] = 0.0;
  }
  for (int k = 0; k < nlp->N; k++) {
    for (int r = 0; r < nlp->np; r++) {
      if (gl) gl[nlp->row_path + k * nlp->np + r] = scale_bound(nlp->plb[r], nlp->pscale[r]);
      if (gu) gu[nlp->row_path + k * nlp->np + r] = scale_bound(nlp->pub[r], nlp->pscale[r]);
    }
  }
  for (int r = 0; r < nlp->nb; r++) {
    if (gl) gl[nlp->row_bnd + r] = scale_bound(nlp->blb[r], nlp->bscale[r]);
    if (gu) gu[nlp->row_bnd + r] = scale_bound(nlp->bub[r], nlp->bscale[r]);
  }
}

// --- function values --------------------------------------------------------------------------

// scaled path values of node k by worker w into g (n_path); 0, 1: callback failed, 2: non-finite
int go_nlp_node_g(go_nlp* nlp, int w, int k, const double* zs, double* g) {
  go_worker* wk = &nlp->workers[w];
  const double* zk = zs + (size_t)k * (size_t)nlp->nz;
  for (int j = 0; j < nlp->nz; j++) wk->z[j] = zk[j] * nlp->zscale[j];
  wk->path_evals++;
  if (nlp->prob.path(go_nlp_ctx(nlp, w), k, wk->z, g) != 0) return 1;
  for (int r = 0; r < nlp->np; r++) {
    g[r] /= nlp->pscale[r];
    if (!isfinite(g[r])) return 2;
  }
  return 0;
}

// integrand of node k (physical) by worker w
int go_nlp_node_L(go_nlp* nlp, int w, int k, const double* zs, double* L) {
  go_worker* wk = &nlp->workers[w];
  *L = 0.0;
  if (!nlp->prob.integrand) return 0;
  const double* zk = zs + (size_t)k * (size_t)nlp->nz;
  for (int j = 0; j < nlp->nz; j++) wk->z[j] = zk[j] * nlp->zscale[j];
  wk->integrand_evals++;
  if (nlp->prob.integrand(go_nlp_ctx(nlp, w), k, wk->z, L) != 0) return 1;
  return isfinite(*L) ? 0 : 2;
}

// scaled defects into g[0 .. (N-1) nx)
void go_nlp_defects(const go_nlp* nlp, const double* zs, double* g) {
  int nz = nlp->nz, nx = nlp->nx;
  double h = go_nlp_time(nlp, zs) / (nlp->N - 1);
  for (int k = 0; k + 1 < nlp->N; k++) {
    const double* a = zs + (size_t)k * (size_t)nz;
    const double* b = a + nz;
    for (int i = 0; i < nx; i++) {
      double s = nlp->zscale[i], sd = nlp->zscale[nx + i];
      double d = (b[i] - a[i]) * s - 0.5 * h * (a[nx + i] + b[nx + i]) * sd;
      g[k * nx + i] = d / s;
    }
  }
}

// scaled boundary values by worker w into b (n_boundary); 0, 1, 2 as go_nlp_node_g
int go_nlp_boundary(go_nlp* nlp, int w, const double* zs, double* b) {
  go_worker* wk = &nlp->workers[w];
  int nz = nlp->nz;
  const double* z0 = zs;
  const double* z1 = zs + (size_t)(nlp->N - 1) * (size_t)nz;
  for (int j = 0; j < nz; j++) {
    wk->bz[j] = z0[j] * nlp->zscale[j];
    wk->bz[nz + j] = z1[j] * nlp->zscale[j];
  }
  wk->bz[2 * nz] = go_nlp_time(nlp, zs);
  wk->boundary_evals++;
  if (nlp->prob.boundary(go_nlp_ctx(nlp, w), wk->bz, wk->bz + nz, wk->bz[2 * nz], b) != 0) return 1;
  for (int r = 0; r < nlp->nb; r++) {
    b[r] /= nlp->bscale[r];
    if (!isfinite(b[r])) return 2;
  }
  return 0;
}

// first failed item of the last parallel loop -> err; 0 if none
int go_nlp_check_status(go_nlp* nlp, int nitems, const char* what) {
  for (int i = 0; i < nitems; i++) {
    if (nlp->status[i]) {
      snprintf(nlp->err, sizeof(nlp->err), "%s %d: %s", what, i,
               nlp->status[i] == 2 ? "non-finite value" : "callback failed");
      return -1;
    }
  }
  return 0;
}

// the whole scaled constraint vector by worker w alone (dense baseline)
int go_nlp_eval_g_serial(go_nlp* nlp, int w, const double* zs, double* g) {
  go_nlp_defects(nlp, zs, g);
  for (int k = 0; k < nlp->N; k++)
    if (nlp->np > 0 && go_nlp_node_g(nlp, w, k, zs, g + nlp->row_path + k * nlp->np)) return -1;
  if (nlp->nb > 0 && go_nlp_boundary(nlp, w, zs, g + nlp->row_bnd)) return -1;
  return 0;
}

// J from the integral and T through outer(); physical
static int outer(go_nlp* nlp, int w, double I, double T, double* J, double* dJdI, double* dJdT) {
  if (!nlp->prob.outer) {
    *J = I;
    *dJdI = 1.0;
    *dJdT = 0.0;
    return 0;
  }
  if (nlp->prob.outer(go_nlp_ctx(nlp, w), I, T, J, dJdI, dJdT) != 0) return 1;
  return (isfinite(*J) && isfinite(*dJdI) && isfinite(*dJdT)) ? 0 : 2;
}

// scaled objective by worker w alone, nodes in order
int go_nlp_eval_f_serial(go_nlp* nlp, int w, const double* zs, double* f) {
  double T = go_nlp_time(nlp, zs), h = T / (nlp->N - 1), I = 0.0, L, J, a, b;
  for (int k = 0; k < nlp->N; k++) {
    if (go_nlp_node_L(nlp, w, k, zs, &L)) return -1;
    I += go_nlp_weight(nlp, k) * L;
  }
  if (outer(nlp, w, I * h, T, &J, &a, &b)) return -1;
  *f = J / nlp->obj_scale;
  return 0;
}

int go_nlp_eval_g(go_nlp* nlp, const double* zs, double* g) {
  nlp->g_evals++;
  go_nlp_defects(nlp, zs, g);
  if (nlp->np > 0) {
    nlp->task = GO_TASK_G;
    nlp->task_zs = zs;
    nlp->task_out = g;
    go_pool_run(nlp->pool, nlp->N, go_nlp_task, nlp);
    if (go_nlp_check_status(nlp, nlp->N, "path constraints at node")) return -1;
  }
  if (nlp->nb > 0) {
    int s = go_nlp_boundary(nlp, 0, zs, g + nlp->row_bnd);
    if (s) {
      snprintf(nlp->err, sizeof(nlp->err), "boundary constraints: %s",
               s == 2 ? "non-finite value" : "callback failed");
      return -1;
    }
  }
  return 0;
}

int go_nlp_eval_f(go_nlp* nlp, const double* zs, double* f) {
  double T = go_nlp_time(nlp, zs), h = T / (nlp->N - 1), I = 0.0, J, a, b;
  if (nlp->prob.integrand) {
    nlp->task = GO_TASK_L;
    nlp->task_zs = zs;
    go_pool_run(nlp->pool, nlp->N, go_nlp_task, nlp);
    if (go_nlp_check_status(nlp, nlp->N, "integrand at node")) return -1;
    // reduce in node order: independent of the number of threads
    for (int k = 0; k < nlp->N; k++) I += go_nlp_weight(nlp, k) * nlp->Lk[k];
  }
  if (outer(nlp, 0, I * h, T, &J, &a, &b)) {
    snprintf(nlp->err, sizeof(nlp->err), "objective outer(): failed or non-finite");
    return -1;
  }
  *f = J / nlp->obj_scale;
  return 0;
}

// --- misc ---------------------------------------------------------------------------------------

double go_nlp_objective_phys(const go_nlp* nlp, double f_scaled) { return f_scaled * nlp->obj_scale; }

double go_nlp_violation(const go_nlp* nlp, const double* g) {
  double v = 0.0;
  for (int r = 0; r < nlp->m; r++) {
    double lo, hi;
    if (r < nlp->row_path) {
      lo = hi = 0.0;
    } else if (r < nlp->row_bnd) {
      int q = (r - nlp->row_path) % nlp->np;
      lo = scale_bound(nlp->plb[q], nlp->pscale[q]);
      hi = scale_bound(nlp->pub[q], nlp->pscale[q]);
    } else {
      int q = r - nlp->row_bnd;
      lo = scale_bound(nlp->blb[q], nlp->bscale[q]);
      hi = scale_bound(nlp->bub[q], nlp->bscale[q]);
    }
    if (!isfinite(g[r])) return INFINITY;
    if (lo - g[r] > v) v = lo - g[r];
    if (g[r] - hi > v) v = g[r] - hi;
  }
  return v;
}

void go_nlp_counts(const go_nlp* nlp, go_eval_counts* c) {
  memset(c, 0, sizeof(*c));
  for (int w = 0; w < nlp->nthreads; w++) {
    c->path_evals += nlp->workers[w].path_evals;
    c->path_jac_calls += nlp->workers[w].path_jac_calls;
    c->integrand_evals += nlp->workers[w].integrand_evals;
    c->boundary_evals += nlp->workers[w].boundary_evals;
  }
  c->boundary_evals += nlp->boundary_evals;
  c->g_evals = nlp->g_evals;
  c->jac_evals = nlp->jac_evals;
  c->path_evals_last_jac = nlp->path_evals_last_jac;
}

void go_nlp_reset_counts(go_nlp* nlp) {
  for (int w = 0; w < nlp->nthreads; w++) {
    nlp->workers[w].path_evals = 0;
    nlp->workers[w].path_jac_calls = 0;
    nlp->workers[w].integrand_evals = 0;
    nlp->workers[w].boundary_evals = 0;
  }
  nlp->boundary_evals = 0;
  nlp->g_evals = 0;
  nlp->jac_evals = 0;
  nlp->path_evals_last_jac = 0;
}

const char* go_nlp_last_error(const go_nlp* nlp) { return nlp->err; }

int go_refine_trapezoid(int nx, int nu, int N0, const double* z0, double T, int N, double* z) {
  int nz = 2 * nx + nu;
  if (N0 < 2 || N < N0 || (N - 1) % (N0 - 1) != 0 || !(T > 0)) return -1;
  int r = (N - 1) / (N0 - 1);
  double hf = T / (N - 1);  // fine step (s)
  for (int i = 0; i + 1 < N0; i++) {
    const double* a = z0 + (size_t)i * nz;
    const double* b = a + nz;
    for (int q = 0; q <= r; q++) {
      double s = (double)q / r;
      double* zk = z + ((size_t)i * r + q) * nz;
      // derivatives and controls: linear in time
      for (int j = nx; j < nz; j++) zk[j] = (1 - s) * a[j] + s * b[j];
      // states: the interval's first node, then trapezoid steps
      for (int j = 0; j < nx; j++)
        zk[j] = q == 0 ? a[j] : zk[j - nz] + 0.5 * hf * (zk[j - nz + nx] + zk[nx + j]);
    }
  }
  return 0;
}
