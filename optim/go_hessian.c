// go_hessian.c: partitioned quasi-Newton Hessian of the collocation Lagrangian (go_hessian.h).
#include "optim/go_hessian.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "optim/go_jacobian.h"
#include "optim/go_nlp_internal.h"

struct go_hess {
  go_nlp* nlp;          // the NLP (not owned)
  int n_elem;           // elements per node
  int* var_ptr;         // element variables (n_elem + 1), copied
  int* vars;            // (var_ptr[n_elem])
  int* ent_ptr;         // Jacobian entries of element e: ent_*[ent_ptr[e] .. ent_ptr[e+1])
  int* ent_p;           // entry in the node's path block (0 .. nnz_p-1)
  int* ent_row;         // its path row (0 .. n_path-1)
  int* ent_var;         // its element-local variable (0 .. |V(e)|-1)
  int* emap;            // element e's lower triangle (i >= j, row-major) -> node-local Hessian
                        // entry, starting at emap_off[e]
  int* emap_off;        // (n_elem)
  int* diag;            // node variable j -> node-local Hessian entry of (j, j)   (nz)
  int nnz_node;         // Hessian entries per node
  int nnz;              // all entries (N nnz_node, + 1 for T)
  int* hrow;            // pattern (nnz)
  int* hcol;
  int* b_off;           // element e's dense block B at b_off[e] within a node     (n_elem)
  int b_node;           // doubles of all element blocks of one node
  double* B;            // element blocks, node-major, each |V| x |V| row-major   (N b_node)
  unsigned char* b_init;// element block initialised (N n_elem)
  double* xp;           // previous update point (n)
  double* Jp;           // path Jacobian blocks at xp (N nnz_p)
  double* xj;           // point of the noted Jacobian (n)
  double* Jc;           // noted path Jacobian blocks (N nnz_p)
  double* jfull;        // whole Jacobian, when x's was not noted (nele)
  double* hdiag;        // objective diagonal (n)
  double* s;            // scratch (max |V|)
  double* y;
  int vmax;             // largest element
  int have_prev, have_jac;
  long updates, skipped;
};

static int fail(char* err, int errsz, const char* msg, int a) {
  snprintf(err, (size_t)errsz, "hessian: %s %d", msg, a);
  return -1;
}

void go_hess_free(go_hess* h) {
  if (!h) return;
  void* arrays[] = {h->var_ptr, h->vars,  h->ent_ptr, h->ent_p, h->ent_row, h->ent_var,
                    h->emap,    h->emap_off, h->diag, h->hrow,  h->hcol,    h->b_off,
                    h->B,       h->b_init, h->xp,    h->Jp,    h->xj,      h->Jc,
                    h->jfull,   h->hdiag,  h->s,     h->y};
  for (size_t i = 0; i < sizeof(arrays) / sizeof(arrays[0]); i++) free(arrays[i]);
  free(h);
}

int go_hess_create(go_hess** out, go_nlp* nlp, const go_elements* el, char* err, int errsz) {
  *out = NULL;
  int nz = nlp->nz, np = nlp->np, N = nlp->N, E = el->n_elem;
  if (E < 0 || (E > 0 && (!el->row_ptr || !el->rows || !el->var_ptr || !el->vars)))
    return fail(err, errsz, "bad element description, elements", E);
  go_hess* h = calloc(1, sizeof(go_hess));
  if (!h) return fail(err, errsz, "out of memory", 0);
  h->nlp = nlp;
  h->n_elem = E;
  int nv_all = E > 0 ? el->var_ptr[E] : 0;
  h->var_ptr = malloc(sizeof(int) * (size_t)(E + 1));
  h->vars = malloc(sizeof(int) * (size_t)(nv_all + 1));
  int* row_elem = malloc(sizeof(int) * (size_t)(np + 1));
  unsigned char* mark = calloc((size_t)nz * (size_t)nz, 1);
  int* local = malloc(sizeof(int) * (size_t)nz * (size_t)nz);
  h->diag = malloc(sizeof(int) * (size_t)nz);
  h->emap_off = malloc(sizeof(int) * (size_t)(E + 1));
  h->b_off = malloc(sizeof(int) * (size_t)(E + 1));
  if (!h->var_ptr || !h->vars || !row_elem || !mark || !local || !h->diag || !h->emap_off ||
      !h->b_off) {
    free(row_elem), free(mark), free(local), go_hess_free(h);
    return fail(err, errsz, "out of memory", 1);
  }
  if (E > 0) memcpy(h->var_ptr, el->var_ptr, sizeof(int) * (size_t)(E + 1));
  else h->var_ptr[0] = 0;
  if (nv_all > 0) memcpy(h->vars, el->vars, sizeof(int) * (size_t)nv_all);
  int rc = 0;

  // rows -> element; variables valid and increasing; block offsets
  for (int r = 0; r < np; r++) row_elem[r] = -1;
  int emap_len = 0, b_len = 0;
  h->vmax = 1;
  for (int e = 0; e < E && !rc; e++) {
    for (int q = el->row_ptr[e]; q < el->row_ptr[e + 1] && !rc; q++) {
      int r = el->rows[q];
      if (r < 0 || r >= np || row_elem[r] >= 0) rc = fail(err, errsz, "path row out of range or in two elements:", r);
      else row_elem[r] = e;
    }
    int v = h->var_ptr[e + 1] - h->var_ptr[e];
    for (int i = 0; i < v && !rc; i++) {
      int j = h->vars[h->var_ptr[e] + i];
      if (j < 0 || j >= nz || (i > 0 && j <= h->vars[h->var_ptr[e] + i - 1]))
        rc = fail(err, errsz, "element variables out of range or not increasing, element", e);
    }
    h->emap_off[e] = emap_len;
    h->b_off[e] = b_len;
    emap_len += v * (v + 1) / 2;
    b_len += v * v;
    if (v > h->vmax) h->vmax = v;
  }
  h->emap_off[E] = emap_len;
  h->b_node = b_len;

  // node pattern: element lower triangles and every diagonal, numbered row-major
  if (!rc) {
    for (int e = 0; e < E; e++) {
      const int* V = h->vars + h->var_ptr[e];
      int v = h->var_ptr[e + 1] - h->var_ptr[e];
      for (int i = 0; i < v; i++)
        for (int j = 0; j <= i; j++) mark[(size_t)V[i] * nz + V[j]] = 1;
    }
    int cnt = 0;
    for (int i = 0; i < nz; i++) {
      mark[(size_t)i * nz + i] = 1;
      for (int j = 0; j <= i; j++)
        if (mark[(size_t)i * nz + j]) local[(size_t)i * nz + j] = cnt++;
    }
    h->nnz_node = cnt;
    h->nnz = N * cnt + (nlp->free_time ? 1 : 0);
    h->emap = malloc(sizeof(int) * (size_t)(emap_len + 1));
    h->hrow = malloc(sizeof(int) * (size_t)h->nnz);
    h->hcol = malloc(sizeof(int) * (size_t)h->nnz);
    if (!h->emap || !h->hrow || !h->hcol) rc = fail(err, errsz, "out of memory", 2);
  }
  if (!rc) {
    for (int i = 0; i < nz; i++) h->diag[i] = local[(size_t)i * nz + i];
    for (int e = 0; e < E; e++) {
      const int* V = h->vars + h->var_ptr[e];
      int v = h->var_ptr[e + 1] - h->var_ptr[e], q = h->emap_off[e];
      for (int i = 0; i < v; i++)
        for (int j = 0; j <= i; j++) h->emap[q++] = local[(size_t)V[i] * nz + V[j]];
    }
    for (int k = 0; k < N; k++)
      for (int i = 0; i < nz; i++)
        for (int j = 0; j <= i; j++)
          if (mark[(size_t)i * nz + j]) {
            int t = k * h->nnz_node + local[(size_t)i * nz + j];
            h->hrow[t] = k * nz + i;
            h->hcol[t] = k * nz + j;
          }
    if (nlp->free_time) h->hrow[h->nnz - 1] = h->hcol[h->nnz - 1] = N * nz;
  }

  // Jacobian entries of each element: node-local pattern entries with row and column in it
  if (!rc) {
    h->ent_ptr = calloc((size_t)(E + 1), sizeof(int));
    int total = 0;
    for (int col = 0; col < nz; col++)
      for (int p = nlp->p_colptr[col]; p < nlp->p_colptr[col + 1]; p++)
        if (row_elem[nlp->p_row[p]] >= 0) total++;
    h->ent_p = malloc(sizeof(int) * (size_t)(total + 1));
    h->ent_row = malloc(sizeof(int) * (size_t)(total + 1));
    h->ent_var = malloc(sizeof(int) * (size_t)(total + 1));
    if (!h->ent_ptr || !h->ent_p || !h->ent_row || !h->ent_var) rc = fail(err, errsz, "out of memory", 3);
    int t = 0;
    for (int e = 0; e < E && !rc; e++) {
      h->ent_ptr[e] = t;
      int v = h->var_ptr[e + 1] - h->var_ptr[e];
      for (int i = 0; i < v; i++) {
        int col = h->vars[h->var_ptr[e] + i];
        for (int p = nlp->p_colptr[col]; p < nlp->p_colptr[col + 1]; p++) {
          if (row_elem[nlp->p_row[p]] != e) continue;
          h->ent_p[t] = p;
          h->ent_row[t] = nlp->p_row[p];
          h->ent_var[t] = i;
          t++;
        }
      }
    }
    if (!rc) h->ent_ptr[E] = t;
  }
  free(row_elem);
  free(mark);
  free(local);

  // values and scratch
  if (!rc) {
    size_t npath = (size_t)N * (size_t)nlp->nnz_p;
    h->B = calloc((size_t)N * (size_t)(h->b_node + 1), sizeof(double));
    h->b_init = calloc((size_t)N * (size_t)(E + 1), 1);
    h->xp = malloc(sizeof(double) * (size_t)nlp->n);
    h->xj = malloc(sizeof(double) * (size_t)nlp->n);
    h->Jp = malloc(sizeof(double) * (npath + 1));
    h->Jc = malloc(sizeof(double) * (npath + 1));
    h->jfull = malloc(sizeof(double) * ((size_t)nlp->nele + 1));
    h->hdiag = malloc(sizeof(double) * (size_t)nlp->n);
    h->s = malloc(sizeof(double) * (size_t)h->vmax);
    h->y = malloc(sizeof(double) * (size_t)h->vmax);
    if (!h->B || !h->b_init || !h->xp || !h->xj || !h->Jp || !h->Jc || !h->jfull || !h->hdiag ||
        !h->s || !h->y)
      rc = fail(err, errsz, "out of memory", 4);
  }
  if (rc) {
    go_hess_free(h);
    return -1;
  }
  *out = h;
  return 0;
}

int go_hess_nnz(const go_hess* h) { return h->nnz; }

void go_hess_structure(const go_hess* h, int* irow, int* jcol) {
  memcpy(irow, h->hrow, sizeof(int) * (size_t)h->nnz);
  memcpy(jcol, h->hcol, sizeof(int) * (size_t)h->nnz);
}

void go_hess_note_jacobian(go_hess* h, const double* x, const double* jac) {
  const go_nlp* nlp = h->nlp;
  memcpy(h->xj, x, sizeof(double) * (size_t)nlp->n);
  memcpy(h->Jc, jac + nlp->off_path, sizeof(double) * (size_t)nlp->N * (size_t)nlp->nnz_p);
  h->have_jac = 1;
}

void go_hess_counts(const go_hess* h, long* updates, long* skipped) {
  *updates = h->updates;
  *skipped = h->skipped;
}

// symmetric rank-one update of the v x v block B with the pair (s, y) (Conn, Gould & Toint
// 1991): B += r r' / (r's), r = y - B s, skipped when |r's| <= 1e-8 |s| |r|; the first pair sets
// B0 = gamma I with the Shanno-Phua scaling gamma = y'y / s'y (|y| / |s| when s'y <= 0). y is
// overwritten with r.
static void sr1_update(go_hess* h, double* B, unsigned char* init, int v, const double* s,
                       double* y) {
  double sts = 0, sty = 0, yty = 0;
  for (int i = 0; i < v; i++) sts += s[i] * s[i], sty += s[i] * y[i], yty += y[i] * y[i];
  if (!(sts > 1e-24) || !isfinite(sty) || !isfinite(yty)) {
    h->skipped++;
    return;
  }
  if (!*init) {
    double gamma = sty > 1e-12 * sqrt(sts * yty) ? yty / sty : sqrt(yty / sts);
    gamma = fmin(fmax(gamma, 1e-6), 1e6);
    memset(B, 0, sizeof(double) * (size_t)v * (size_t)v);
    for (int i = 0; i < v; i++) B[i * v + i] = gamma;
    *init = 1;
  }
  double rs = 0, rr = 0;
  for (int i = 0; i < v; i++) {
    double bs = 0;
    for (int j = 0; j < v; j++) bs += B[i * v + j] * s[j];
    y[i] -= bs;
    rs += y[i] * s[i];
    rr += y[i] * y[i];
  }
  if (!(fabs(rs) > 1e-8 * sqrt(sts * rr))) {
    h->skipped++;
    return;
  }
  for (int i = 0; i < v; i++)
    for (int j = 0; j < v; j++) B[i * v + j] += y[i] * y[j] / rs;
  h->updates++;
}

int go_hess_values(go_hess* h, const double* x, double obj_factor, const double* lambda,
                   double* vals) {
  go_nlp* nlp = h->nlp;
  int N = nlp->N, nz = nlp->nz, np = nlp->np, nnz_p = nlp->nnz_p, n = nlp->n;
  // the Jacobian at x: noted by the caller, else evaluated here
  if (!h->have_jac || memcmp(h->xj, x, sizeof(double) * (size_t)n) != 0) {
    if (go_nlp_eval_jac(nlp, x, h->jfull)) return -1;
    go_hess_note_jacobian(h, x, h->jfull);
  }
  // secant update of every element since the previous point
  if (h->have_prev && memcmp(h->xp, x, sizeof(double) * (size_t)n) != 0) {
    for (int k = 0; k < N; k++) {
      const double* lam = lambda + nlp->row_path + (size_t)k * np;
      const double* Jc = h->Jc + (size_t)k * nnz_p;
      const double* Jp = h->Jp + (size_t)k * nnz_p;
      for (int e = 0; e < h->n_elem; e++) {
        const int* V = h->vars + h->var_ptr[e];
        int v = h->var_ptr[e + 1] - h->var_ptr[e];
        for (int i = 0; i < v; i++) {
          size_t j = (size_t)k * nz + V[i];
          h->s[i] = x[j] - h->xp[j];
          h->y[i] = 0;
        }
        for (int t = h->ent_ptr[e]; t < h->ent_ptr[e + 1]; t++) {
          int p = h->ent_p[t];
          h->y[h->ent_var[t]] += lam[h->ent_row[t]] * (Jc[p] - Jp[p]);
        }
        sr1_update(h, h->B + (size_t)k * h->b_node + h->b_off[e],
                    h->b_init + (size_t)k * h->n_elem + e, v, h->s, h->y);
      }
    }
  }
  if (!h->have_prev || memcmp(h->xp, x, sizeof(double) * (size_t)n) != 0) {
    memcpy(h->xp, x, sizeof(double) * (size_t)n);
    memcpy(h->Jp, h->Jc, sizeof(double) * (size_t)N * (size_t)nnz_p);
    h->have_prev = 1;
  }
  // values: element blocks (lower triangles) and the objective's diagonal
  memset(vals, 0, sizeof(double) * (size_t)h->nnz);
  for (int k = 0; k < N; k++) {
    double* vk = vals + (size_t)k * h->nnz_node;
    for (int e = 0; e < h->n_elem; e++) {
      if (!h->b_init[(size_t)k * h->n_elem + e]) continue;
      const double* B = h->B + (size_t)k * h->b_node + h->b_off[e];
      int v = h->var_ptr[e + 1] - h->var_ptr[e], q = h->emap_off[e];
      for (int i = 0; i < v; i++)
        for (int j = 0; j <= i; j++) vk[h->emap[q++]] += B[i * v + j];
    }
  }
  if (go_nlp_has_hess_diag(nlp)) {
    if (go_nlp_eval_hess_diag(nlp, x, obj_factor, h->hdiag)) return -1;
    for (int k = 0; k < N; k++)
      for (int j = 0; j < nz; j++)
        vals[(size_t)k * h->nnz_node + h->diag[j]] += h->hdiag[(size_t)k * nz + j];
  }
  return 0;
}
