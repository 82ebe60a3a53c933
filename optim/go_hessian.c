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
  struct go_hess_fd* fd;  // finite-difference mode (go_hess_create_fd), NULL: SR1 updates
};

// --- finite-difference mode (go_hess_create_fd) -------------------------------------------------
// Reads: Hessian entry `ent` (node-local) += weight * lambda_r / pscale_r * zscale_col *
// d(analytic partial at pattern entry p, row r) / d z~_var.
typedef struct {
  int p, r, col, ent;
  double weight;
} fd_read;

typedef struct {
  double *zs, *z, *g0, *gp, *gn, *gq, *mu, *J0, *J1, *J2;  // gp, gn: nf x np
  double* hobj;  // the integrand's node Hessian (nz x nz), when the problem gives it
} fd_scratch;

typedef struct go_hess_fd {
  int nf;            // finite-difference variables in some element
  int* fvar;         // their node variables (nf)
  int* fdiag;        // node-local entry of (fvar[a], fvar[a])
  int* drow_ptr;     // rows of the elements holding fvar[a]: drow[drow_ptr[a] .. ) (nf + 1)
  int* drow;
  int npair;         // pairs (a, b), a > b, sharing an element
  int *pa, *pb, *pent;  // list positions and node-local entry (npair)
  int* prow_ptr;     // rows of the elements holding both (npair + 1)
  int* prow;
  int* bread_ptr;    // (B) reads of fd variable a: bread[bread_ptr[a] .. ) (nf + 1)
  fd_read* bread;
  int ncol;          // (C) colour groups of analytic variables with curvature
  int* cvar_ptr;     // variables of colour c: cvar[cvar_ptr[c] .. ) (ncol + 1)
  int* cvar;
  int* cread_ptr;    // reads of colour c, `col` of a read is the perturbed variable (ncol + 1)
  fd_read* cread;
  int* cread_pert;   // perturbed variable of each (C) read
  int nobj;          // the integrand's node Hessian (integrand_hess_block): entries (oi >= oj)
  int *oi, *oj, *oent;  // of its mask's lower triangle and their node-local entries (nobj)
  fd_scratch* ws;    // per worker
  int nthreads;
  // current task
  double obj_c;      // obj_factor dJ/dI h / obj_scale (the node weight left out); 0: no objective
  const double* x;
  const double* lambda;
  double* vals;
  int* status;
} go_hess_fd;

static int fd_values(go_hess* h, const double* x, double obj_factor, const double* lambda,
                     double* vals);

// obj_factor times the objective's exact diagonal (go_nlp_eval_hess_diag) added to vals, when
// the problem has one (else its curvature is left out). 0, or -1 when it failed.
static int add_objective_diagonal(go_hess* h, const double* x, double obj_factor, double* vals) {
  go_nlp* nlp = h->nlp;
  if (!go_nlp_has_hess_diag(nlp)) return 0;
  if (go_nlp_eval_hess_diag(nlp, x, obj_factor, h->hdiag)) return -1;
  for (int k = 0; k < nlp->N; k++)
    for (int j = 0; j < nlp->nz; j++)
      vals[(size_t)k * h->nnz_node + h->diag[j]] += h->hdiag[(size_t)k * nlp->nz + j];
  return 0;
}

static int fail(char* err, int errsz, const char* msg, int a) {
  snprintf(err, (size_t)errsz, "hessian: %s %d", msg, a);
  return -1;
}

static void fd_free(go_hess_fd* f) {
  if (!f) return;
  void* arrays[] = {f->oi,     f->oj,        f->oent,   f->fvar,      f->fdiag,  f->drow_ptr,
                    f->drow,   f->pa,        f->pb,     f->pent,      f->prow_ptr, f->prow, f->bread_ptr, f->bread, f->cvar_ptr, f->cvar, f->cread_ptr, f->cread,
                    f->cread_pert, f->status};
  for (size_t i = 0; i < sizeof(arrays) / sizeof(arrays[0]); i++) free(arrays[i]);
  for (int w = 0; f->ws && w < f->nthreads; w++) free(f->ws[w].zs), free(f->ws[w].hobj);
  free(f->ws);
  free(f);
}

void go_hess_free(go_hess* h) {
  if (!h) return;
  fd_free(h->fd);
  void* arrays[] = {h->var_ptr, h->vars,  h->ent_ptr, h->ent_p, h->ent_row, h->ent_var,
                    h->emap,    h->emap_off, h->diag, h->hrow,  h->hcol,    h->b_off,
                    h->B,       h->b_init, h->xp,    h->Jp,    h->xj,      h->Jc,
                    h->jfull,   h->hdiag,  h->s,     h->y};
  for (size_t i = 0; i < sizeof(arrays) / sizeof(arrays[0]); i++) free(arrays[i]);
  free(h);
}

// the element structure and pattern; with secant != 0 also the state of the SR1 updates (the
// element blocks, the previous point and Jacobians), which the finite-difference mode does not use
static int hess_create(go_hess** out, go_nlp* nlp, const go_elements* el, int secant, char* err,
                       int errsz) {
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
  h->hdiag = malloc(sizeof(double) * (size_t)nlp->n);
  if (!rc && !h->hdiag) rc = fail(err, errsz, "out of memory", 4);
  if (!rc && secant) {
    size_t npath = (size_t)N * (size_t)nlp->nnz_p;
    h->B = calloc((size_t)N * (size_t)(h->b_node + 1), sizeof(double));
    h->b_init = calloc((size_t)N * (size_t)(E + 1), 1);
    h->xp = malloc(sizeof(double) * (size_t)nlp->n);
    h->xj = malloc(sizeof(double) * (size_t)nlp->n);
    h->Jp = malloc(sizeof(double) * (npath + 1));
    h->Jc = malloc(sizeof(double) * (npath + 1));
    h->jfull = malloc(sizeof(double) * ((size_t)nlp->nele + 1));
    h->s = malloc(sizeof(double) * (size_t)h->vmax);
    h->y = malloc(sizeof(double) * (size_t)h->vmax);
    if (!h->B || !h->b_init || !h->xp || !h->xj || !h->Jp || !h->Jc || !h->jfull || !h->s ||
        !h->y)
      rc = fail(err, errsz, "out of memory", 5);
  }
  if (rc) {
    go_hess_free(h);
    return -1;
  }
  *out = h;
  return 0;
}

int go_hess_create(go_hess** out, go_nlp* nlp, const go_elements* el, char* err, int errsz) {
  return hess_create(out, nlp, el, 1, err, errsz);
}

int go_hess_nnz(const go_hess* h) { return h->nnz; }

void go_hess_structure(const go_hess* h, int* irow, int* jcol) {
  memcpy(irow, h->hrow, sizeof(int) * (size_t)h->nnz);
  memcpy(jcol, h->hcol, sizeof(int) * (size_t)h->nnz);
}

void go_hess_note_jacobian(go_hess* h, const double* x, const double* jac) {
  if (h->fd) return;  // the finite-difference mode evaluates its own partials
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
  if (h->fd) return fd_values(h, x, obj_factor, lambda, vals);
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
  return add_objective_diagonal(h, x, obj_factor, vals);
}

// --- finite-difference mode -------------------------------------------------------------------

// growable int / read arrays for the create step
typedef struct {
  int* v;
  int n, cap;
} ivec;
static int ipush(ivec* a, int x) {
  if (a->n == a->cap) {
    int cap = a->cap ? 2 * a->cap : 256;
    int* v = realloc(a->v, sizeof(int) * (size_t)cap);
    if (!v) return -1;
    a->v = v, a->cap = cap;
  }
  a->v[a->n++] = x;
  return 0;
}
typedef struct {
  fd_read* v;
  int* pert;
  int n, cap;
} rvec;
static int rpush(rvec* a, fd_read x, int pert) {
  if (a->n == a->cap) {
    int cap = a->cap ? 2 * a->cap : 1024;
    fd_read* v = realloc(a->v, sizeof(fd_read) * (size_t)cap);
    if (!v) return -1;
    a->v = v;
    int* q = realloc(a->pert, sizeof(int) * (size_t)cap);
    if (!q) return -1;
    a->pert = q, a->cap = cap;
  }
  a->pert[a->n] = pert;
  a->v[a->n++] = x;
  return 0;
}

int go_hess_create_fd(go_hess** out, go_nlp* nlp, const go_elements* el, char* err, int errsz) {
  if (errsz > 0) err[0] = 0;
  if (hess_create(out, nlp, el, 0, err, errsz) != 0) return -1;
  go_hess* h = *out;
  int nz = nlp->nz, np = nlp->np, N = nlp->N, E = h->n_elem, rc = 0;
  go_hess_fd* f = calloc(1, sizeof(go_hess_fd));
  unsigned char* has = calloc((size_t)(E + 1) * (size_t)nz, 1);  // 1 member, 2 member with curvature
  int* row_elem = malloc(sizeof(int) * (size_t)(np + 1));
  unsigned char* mark = calloc((size_t)nz * (size_t)nz, 1);
  int* local = malloc(sizeof(int) * (size_t)nz * (size_t)nz);
  int* color = malloc(sizeof(int) * (size_t)nz);
  ivec drow = {0}, pa = {0}, pb = {0}, prow = {0}, prow_ptr = {0}, bptr = {0}, cptr = {0},
       cvar = {0}, cvptr = {0};
  rvec bread = {0}, cread = {0};
  h->fd = f;
  if (!f || !has || !row_elem || !mark || !local || !color) {
    rc = fail(err, errsz, "out of memory (finite-difference Hessian)", 0);
    goto done;
  }
  for (int r = 0; r < np; r++) row_elem[r] = -1;
  for (int e = 0; e < E; e++) {
    for (int q = el->row_ptr[e]; q < el->row_ptr[e + 1]; q++) row_elem[el->rows[q]] = e;
    for (int q = el->var_ptr[e]; q < el->var_ptr[e + 1]; q++)
      has[(size_t)e * nz + el->vars[q]] = (el->lin && el->lin[q]) ? 1 : 2;
  }
#define HAS(e, j) has[(size_t)(e) * nz + (j)]
#define MARK(i, j) mark[(size_t)((i) > (j) ? (i) : (j)) * nz + ((i) > (j) ? (j) : (i))] = 1
  // finite-difference variables
  f->fvar = malloc(sizeof(int) * (size_t)(nz + 1));
  if (!f->fvar) rc = fail(err, errsz, "out of memory (finite-difference Hessian)", 1);
  for (int j = 0; j < nz && !rc; j++) {
    if (nlp->analytic[j]) continue;
    int in = 0;
    for (int e = 0; e < E && !in; e++) in = HAS(e, j) != 0;
    if (in) f->fvar[f->nf++] = j;
  }
  for (int j = 0; j < nz; j++) mark[(size_t)j * nz + j] = 1;
  // (A) diagonal rows
  for (int a = 0; a < f->nf && !rc; a++) {
    int i = f->fvar[a];
    rc |= ipush(&bptr, drow.n);
    for (int r = 0; r < np; r++)
      if (row_elem[r] >= 0 && HAS(row_elem[r], i)) rc |= ipush(&drow, r);
  }
  // ... and pairs (a, b), a > b, with b the outer loop: the pairs that share their lower
  // variable come one after the other. For the gait problem, whose variables start with the
  // coordinates, the pairs of a coordinate with each speed then share their coordinates, and its
  // path evaluation reuses MuJoCo's position stage between them (go_gait.c, node_inverse); each
  // entry is still written once, so the order changes no value
  for (int b = 0; b < f->nf && !rc; b++) {
    int j = f->fvar[b];
    for (int a = b + 1; a < f->nf && !rc; a++) {
      int i = f->fvar[a];
      if (el->fd_pairs && !el->fd_pairs[(size_t)i * nz + j] && !el->fd_pairs[(size_t)j * nz + i])
        continue;
      int start = prow.n;
      for (int r = 0; r < np; r++) {
        int e = row_elem[r];
        if (e >= 0 && HAS(e, i) && HAS(e, j)) rc |= ipush(&prow, r);
      }
      if (prow.n == start) continue;
      rc |= ipush(&prow_ptr, start) | ipush(&pa, a) | ipush(&pb, b);
      MARK(i, j);
    }
  }
  rc |= ipush(&bptr, drow.n) | ipush(&prow_ptr, prow.n);
  f->drow_ptr = bptr.v, f->drow = drow.v, f->npair = pa.n, f->pa = pa.v, f->pb = pb.v;
  f->prow_ptr = prow_ptr.v, f->prow = prow.v;
  bptr = (ivec){0}, drow = (ivec){0}, pa = (ivec){0}, pb = (ivec){0}, prow = (ivec){0};
  prow_ptr = (ivec){0};
  // (B) fd variable x analytic column, rows of an element holding both
  ivec bp = {0};
  for (int a = 0; a < f->nf && !rc; a++) {
    int i = f->fvar[a];
    rc |= ipush(&bp, bread.n);
    for (int w = 0; w < nz; w++) {
      if (!nlp->analytic[w]) continue;
      for (int p = nlp->p_colptr[w]; p < nlp->p_colptr[w + 1]; p++) {
        int r = nlp->p_row[p], e = row_elem[r];
        if (e < 0 || !HAS(e, i) || !HAS(e, w)) continue;
        rc |= rpush(&bread, (fd_read){p, r, w, 0, 1.0}, i);
        MARK(i, w);
      }
    }
  }
  rc |= ipush(&bp, bread.n);
  f->bread_ptr = bp.v;
  // (C) colours of the analytic variables with curvature in some element
  for (int j = 0; j < nz; j++) color[j] = -1;
  int ncol = 0;
  for (int w = 0; w < nz && !rc; w++) {
    if (!nlp->analytic[w]) continue;
    int curv = 0;
    for (int e = 0; e < E && !curv; e++) curv = HAS(e, w) == 2;
    if (!curv) continue;
    unsigned long long forbid[4] = {0};  // up to 256 colours
    for (int e = 0; e < E; e++) {
      if (!HAS(e, w)) continue;
      for (int q = el->var_ptr[e]; q < el->var_ptr[e + 1]; q++) {
        int v = el->vars[q];
        if (v == w || color[v] < 0) continue;
        if (HAS(e, w) == 2 || HAS(e, v) == 2) forbid[color[v] / 64] |= 1ull << (color[v] % 64);
      }
    }
    int c = 0;
    while (c < 256 && (forbid[c / 64] >> (c % 64) & 1)) c++;
    if (c == 256) {
      rc = fail(err, errsz, "finite-difference Hessian: more than 256 colours at variable", w);
      break;
    }
    color[w] = c;
    if (c + 1 > ncol) ncol = c + 1;
  }
  for (int c = 0; c < ncol && !rc; c++) {
    rc |= ipush(&cvptr, cvar.n) | ipush(&cptr, cread.n);
    for (int w = 0; w < nz; w++) {
      if (color[w] != c) continue;
      rc |= ipush(&cvar, w);
      for (int e = 0; e < E; e++) {
        if (HAS(e, w) != 2) continue;
        for (int q = el->var_ptr[e]; q < el->var_ptr[e + 1]; q++) {
          int v = el->vars[q];
          if (!nlp->analytic[v]) continue;
          double weight = (v != w && HAS(e, v) == 2) ? 0.5 : 1.0;
          for (int p = nlp->p_colptr[v]; p < nlp->p_colptr[v + 1]; p++) {
            if (row_elem[nlp->p_row[p]] != e) continue;
            rc |= rpush(&cread, (fd_read){p, nlp->p_row[p], v, 0, weight}, w);
            MARK(w, v);
          }
        }
      }
    }
  }
  rc |= ipush(&cvptr, cvar.n) | ipush(&cptr, cread.n);
  f->ncol = ncol, f->cvar_ptr = cvptr.v, f->cvar = cvar.v, f->cread_ptr = cptr.v;
  f->cread = cread.v, f->cread_pert = cread.pert;
  cvptr = (ivec){0}, cvar = (ivec){0}, cptr = (ivec){0}, cread = (rvec){0};
  if (rc) {
    if (!err[0]) fail(err, errsz, "out of memory (finite-difference Hessian)", 2);
    goto done;
  }
  // the integrand's node Hessian, when the problem gives one: every entry of its mask
  const unsigned char* omask = nlp->prob.integrand_hess_block && nlp->prob.integrand
                                   ? nlp->prob.integrand_hess_mask : NULL;
  if (nlp->prob.integrand_hess_block && nlp->prob.integrand && !omask) {
    rc = fail(err, errsz, "integrand_hess_block without integrand_hess_mask", 0);
    goto done;
  }
  for (int i = 0; omask && i < nz; i++)
    for (int j = 0; j <= i; j++)
      if (omask[(size_t)i * nz + j] || omask[(size_t)j * nz + i]) {
        MARK(i, j);
        f->nobj++;
      }
  // the pattern of the entries produced, numbered row-major within a node
  int cnt = 0;
  for (int i = 0; i < nz; i++)
    for (int j = 0; j <= i; j++)
      if (mark[(size_t)i * nz + j]) local[(size_t)i * nz + j] = cnt++;
#define LOCAL(i, j) local[(size_t)((i) > (j) ? (i) : (j)) * nz + ((i) > (j) ? (j) : (i))]
  for (int j = 0; j < nz; j++) h->diag[j] = local[(size_t)j * nz + j];
  f->fdiag = malloc(sizeof(int) * (size_t)(f->nf + 1));
  f->pent = malloc(sizeof(int) * (size_t)(f->npair + 1));
  free(h->hrow), free(h->hcol);
  h->nnz_node = cnt;
  h->nnz = N * cnt + (nlp->free_time ? 1 : 0);
  h->hrow = malloc(sizeof(int) * (size_t)h->nnz);
  h->hcol = malloc(sizeof(int) * (size_t)h->nnz);
  f->nthreads = nlp->nthreads;
  f->ws = calloc((size_t)f->nthreads, sizeof(fd_scratch));
  f->status = calloc((size_t)N, sizeof(int));
  if (!f->fdiag || !f->pent || !h->hrow || !h->hcol || !f->ws || !f->status) {
    rc = fail(err, errsz, "out of memory (finite-difference Hessian)", 3);
    goto done;
  }
  for (int a = 0; a < f->nf; a++) f->fdiag[a] = LOCAL(f->fvar[a], f->fvar[a]);
  if (f->nobj > 0) {
    f->oi = malloc(sizeof(int) * (size_t)f->nobj);
    f->oj = malloc(sizeof(int) * (size_t)f->nobj);
    f->oent = malloc(sizeof(int) * (size_t)f->nobj);
    if (!f->oi || !f->oj || !f->oent) {
      rc = fail(err, errsz, "out of memory (finite-difference Hessian)", 5);
      goto done;
    }
    int t = 0;
    for (int i = 0; i < nz; i++)
      for (int j = 0; j <= i; j++)
        if (omask[(size_t)i * nz + j] || omask[(size_t)j * nz + i])
          f->oi[t] = i, f->oj[t] = j, f->oent[t++] = LOCAL(i, j);
  }
  for (int t = 0; t < f->npair; t++) f->pent[t] = LOCAL(f->fvar[f->pa[t]], f->fvar[f->pb[t]]);
  for (int t = 0; t < bread.n; t++) {
    fd_read* rd = &bread.v[t];
    rd->ent = LOCAL(bread.pert[t], rd->col);
  }
  for (int t = 0; t < f->cread_ptr[f->ncol]; t++) {
    fd_read* rd = &f->cread[t];
    rd->ent = LOCAL(f->cread_pert[t], rd->col);
  }
  f->bread = bread.v;
  free(bread.pert);
  bread = (rvec){0};
  for (int k = 0; k < N; k++)
    for (int i = 0; i < nz; i++)
      for (int j = 0; j <= i; j++)
        if (mark[(size_t)i * nz + j]) {
          int t = k * cnt + local[(size_t)i * nz + j];
          h->hrow[t] = k * nz + i;
          h->hcol[t] = k * nz + j;
        }
  if (nlp->free_time) h->hrow[h->nnz - 1] = h->hcol[h->nnz - 1] = N * nz;
  // per-worker scratch
  for (int w = 0; w < f->nthreads && !rc; w++) {
    fd_scratch* s = &f->ws[w];
    size_t len = 2 * (size_t)nz + (size_t)np * (3 + 2 * (size_t)f->nf) + 3 * (size_t)nlp->nnz_p;
    s->zs = malloc(sizeof(double) * (len + 1));
    if (!s->zs) {
      rc = fail(err, errsz, "out of memory (finite-difference Hessian)", 4);
      break;
    }
    s->z = s->zs + nz;
    s->g0 = s->z + nz;
    s->gq = s->g0 + np;
    s->mu = s->gq + np;
    s->J0 = s->mu + np;
    s->J1 = s->J0 + nlp->nnz_p;
    s->J2 = s->J1 + nlp->nnz_p;
    s->gp = s->J2 + nlp->nnz_p;  // nf x np
    s->gn = s->gp + (size_t)f->nf * np;
    if (f->nobj > 0 && !(s->hobj = malloc(sizeof(double) * (size_t)nz * (size_t)nz)))
      rc = fail(err, errsz, "out of memory (finite-difference Hessian)", 6);
  }
#undef HAS
#undef MARK
#undef LOCAL
done:
  free(has), free(row_elem), free(mark), free(local), free(color);
  free(drow.v), free(pa.v), free(pb.v), free(prow.v), free(prow_ptr.v), free(bptr.v);
  free(cptr.v), free(cvar.v), free(cvptr.v), free(bread.v), free(bread.pert), free(cread.v);
  free(cread.pert);
  if (rc) {
    go_hess_free(h);
    *out = NULL;
    return -1;
  }
  return 0;
}

// physical path values at the scaled node point zs
static int fd_path(go_nlp* nlp, int w, int k, const double* zs, double* z, double* g) {
  for (int j = 0; j < nlp->nz; j++) z[j] = zs[j] * nlp->zscale[j];
  nlp->workers[w].path_evals++;
  if (nlp->prob.path(go_nlp_ctx(nlp, w), k, z, g) != 0) return -1;
  for (int r = 0; r < nlp->np; r++)
    if (!isfinite(g[r])) return -1;
  return 0;
}

// physical analytic partials at the scaled node point zs
static int fd_jac(go_nlp* nlp, int w, int k, const double* zs, double* z, double* J) {
  for (int j = 0; j < nlp->nz; j++) z[j] = zs[j] * nlp->zscale[j];
  nlp->workers[w].path_jac_calls++;
  return nlp->prob.path_jac(go_nlp_ctx(nlp, w), k, z, J) != 0 ? -1 : 0;
}

static double step(double zs, double rel) { return rel * fmax(1.0, fabs(zs)); }

// the node block of the Lagrangian's constraint part into vals (node k's nnz_node entries)
static int fd_node(go_hess* h, int w, int k) {
  go_nlp* nlp = h->nlp;
  go_hess_fd* f = h->fd;
  fd_scratch* s = &f->ws[w];
  int nz = nlp->nz, np = nlp->np;
  const double* x = f->x + (size_t)k * nz;
  const double* lam = f->lambda + nlp->row_path + (size_t)k * np;
  double* H = f->vals + (size_t)k * h->nnz_node;
  memset(H, 0, sizeof(double) * (size_t)h->nnz_node);
  for (int r = 0; r < np; r++) s->mu[r] = lam[r] / nlp->pscale[r];
  memcpy(s->zs, x, sizeof(double) * (size_t)nz);
  // (A) second differences of phi over the finite-difference variables
  if (fd_path(nlp, w, k, s->zs, s->z, s->g0)) return -1;
  const double rel_a = 1e-5;
  for (int a = 0; a < f->nf; a++) {
    int i = f->fvar[a];
    double hi = step(x[i], rel_a), *gp = s->gp + (size_t)a * np;
    s->zs[i] = x[i] + hi;
    if (fd_path(nlp, w, k, s->zs, s->z, gp)) return -1;
    double* gn = s->gn + (size_t)a * np;
    s->zs[i] = x[i] - hi;
    if (fd_path(nlp, w, k, s->zs, s->z, gn)) return -1;
    s->zs[i] = x[i];
    double acc = 0;
    for (int q = f->drow_ptr[a]; q < f->drow_ptr[a + 1]; q++) {
      int r = f->drow[q];
      acc += s->mu[r] * (gp[r] - 2 * s->g0[r] + gn[r]);
    }
    H[f->fdiag[a]] += acc / (hi * hi);
  }
  for (int t = 0; t < f->npair; t++) {
    int a = f->pa[t], b = f->pb[t], i = f->fvar[a], j = f->fvar[b];
    double hi = step(x[i], rel_a), hj = step(x[j], rel_a);
    s->zs[i] = x[i] + hi;
    s->zs[j] = x[j] + hj;
    int bad = fd_path(nlp, w, k, s->zs, s->z, s->gq);
    s->zs[i] = x[i];
    s->zs[j] = x[j];
    if (bad) return -1;
    const double *gpa = s->gp + (size_t)a * np, *gpb = s->gp + (size_t)b * np;
    double acc = 0;
    for (int q = f->prow_ptr[t]; q < f->prow_ptr[t + 1]; q++) {
      int r = f->prow[q];
      acc += s->mu[r] * (s->gq[r] - gpa[r] - gpb[r] + s->g0[r]);
    }
    H[f->pent[t]] += acc / (hi * hj);
  }
  // (B) forward differences of the analytic partials along the finite-difference variables
  if (f->bread_ptr[f->nf] > 0) {
    if (fd_jac(nlp, w, k, s->zs, s->z, s->J0)) return -1;
    const double rel_b = 1e-7;
    for (int a = 0; a < f->nf; a++) {
      if (f->bread_ptr[a + 1] == f->bread_ptr[a]) continue;
      int i = f->fvar[a];
      double hi = step(x[i], rel_b);
      s->zs[i] = x[i] + hi;
      int bad = fd_jac(nlp, w, k, s->zs, s->z, s->J1);
      s->zs[i] = x[i];
      if (bad) return -1;
      for (int q = f->bread_ptr[a]; q < f->bread_ptr[a + 1]; q++) {
        const fd_read* rd = &f->bread[q];
        H[rd->ent] += s->mu[rd->r] * nlp->zscale[rd->col] * (s->J1[rd->p] - s->J0[rd->p]) / hi;
      }
    }
  }
  // (C) central differences of the analytic partials, one colour group at a time
  const double rel_c = 6.0554544523933395e-06;
  for (int c = 0; c < f->ncol; c++) {
    for (int q = f->cvar_ptr[c]; q < f->cvar_ptr[c + 1]; q++) {
      int v = f->cvar[q];
      s->zs[v] = x[v] + step(x[v], rel_c);
    }
    int bad = fd_jac(nlp, w, k, s->zs, s->z, s->J1);
    for (int q = f->cvar_ptr[c]; q < f->cvar_ptr[c + 1]; q++) {
      int v = f->cvar[q];
      s->zs[v] = x[v] - step(x[v], rel_c);
    }
    bad |= fd_jac(nlp, w, k, s->zs, s->z, s->J2);
    for (int q = f->cvar_ptr[c]; q < f->cvar_ptr[c + 1]; q++) s->zs[f->cvar[q]] = x[f->cvar[q]];
    if (bad) return -1;
    for (int q = f->cread_ptr[c]; q < f->cread_ptr[c + 1]; q++) {
      const fd_read* rd = &f->cread[q];
      double hv = step(x[f->cread_pert[q]], rel_c);
      H[rd->ent] += rd->weight * s->mu[rd->r] * nlp->zscale[rd->col] *
                    (s->J1[rd->p] - s->J2[rd->p]) / (2 * hv);
    }
  }
  // the integrand's node block, obj_factor dJ/dI h w_k / obj_scale times its physical Hessian
  if (f->nobj > 0 && f->obj_c != 0) {
    for (int j = 0; j < nz; j++) s->z[j] = x[j] * nlp->zscale[j];
    if (nlp->prob.integrand_hess_block(go_nlp_ctx(nlp, w), k, s->z, s->hobj) != 0) return -1;
    double c = f->obj_c * go_nlp_weight(nlp, k);
    for (int t = 0; t < f->nobj; t++) {
      int i = f->oi[t], j = f->oj[t];
      H[f->oent[t]] += c * nlp->zscale[i] * nlp->zscale[j] * s->hobj[(size_t)i * nz + j];
    }
  }
  for (int t = 0; t < h->nnz_node; t++)
    if (!isfinite(H[t])) return -1;
  return 0;
}

static void fd_task(void* arg, int w, int k) {
  go_hess* h = arg;
  h->fd->status[k] = fd_node(h, w, k);
}

static int fd_values(go_hess* h, const double* x, double obj_factor, const double* lambda,
                     double* vals) {
  go_nlp* nlp = h->nlp;
  go_hess_fd* f = h->fd;
  f->x = x, f->lambda = lambda, f->vals = vals, f->obj_c = 0;
  if (f->nobj > 0 && obj_factor != 0) {  // obj_factor dJ/dI h / obj_scale (node weight apart)
    double step, dJdI;
    if (go_nlp_integrand_factor(nlp, x, "hessian", &step, &dJdI)) return -1;
    f->obj_c = obj_factor * dJdI * step / nlp->obj_scale;
  }
  go_pool_run(nlp->pool, nlp->N, fd_task, h);
  for (int k = 0; k < nlp->N; k++) {
    if (f->status[k]) {
      snprintf(nlp->err, sizeof(nlp->err), "hessian: a path or integrand evaluation failed at node %d", k);
      return -1;
    }
  }
  if (nlp->free_time) vals[h->nnz - 1] = 0;
  if (f->nobj == 0 && add_objective_diagonal(h, x, obj_factor, vals)) return -1;
  h->updates++;
  return 0;
}
