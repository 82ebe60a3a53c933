// test_collocation_jacobian.c: the collocation NLP's Jacobian and objective gradient against dense
// central differences, pattern exactness, evaluation counts, and bitwise equality across threads.
//
// Problem: implicit double pendulum (point masses 1 kg, links 1 m, absolute angles), N = 6 nodes,
// free T, nonuniform scaling, node z = [q1 q2 w1 w2 | q1' q2' w1' w2' | u1 u2]; path rows
//   0: q1' - w1   1: q2' - w2   2,3: M(q) w' + C(q, w) + G(q) - u   4: -cos q1 - cos q2 >= -1.9
// boundary: q2, w1, w2 periodic; (q1_last - q1_first) / T = 0.5 (a speed);
// objective J = I / T with L = u1^2 + u2^2 + 0.1 (w1 w1')^2.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "optim/go_collocation.h"
#include "optim/go_jacobian.h"
#include "tests/gs_test.h"
#include "tests/gs_test_nlp.h"

#define NN 6
#define NX 4
#define NU 2
#define NZ 10
#define NP 5
#define NB 4

typedef struct {
  volatile int in_use;  // set while a callback runs with this context
  int shared;           // times a second thread entered while in_use (must stay 0)
} pctx;

static void enter(pctx* c) {
  if (c->in_use) __atomic_add_fetch(&c->shared, 1, __ATOMIC_RELAXED);
  c->in_use = 1;
}

static int path(void* vctx, int k, const double* z, double* g) {
  pctx* c = vctx;
  enter(c);
  double q1 = z[0], q2 = z[1], w1 = z[2], w2 = z[3], a1 = z[6], a2 = z[7];
  double cd = cos(q1 - q2), sd = sin(q1 - q2), gr = 9.81;
  g[0] = z[4] - w1;
  g[1] = z[5] - w2;
  g[2] = 2.0 * a1 + cd * a2 + sd * w2 * w2 + 2.0 * gr * sin(q1) - z[8];
  g[3] = cd * a1 + a2 - sd * w1 * w1 + gr * sin(q2) - z[9];
  g[4] = -cos(q1) - cos(q2);
  c->in_use = 0;
  return 0;
}

// pattern (compressed columns over the 10 node variables)
static const int pcol[NZ + 1] = {0, 3, 6, 8, 10, 11, 12, 14, 16, 17, 18};
static const int prow[18] = {2, 3, 4, 2, 3, 4, 0, 3, 1, 2, 0, 1, 2, 3, 2, 3, 2, 3};

// analytic columns w1', w2', u1, u2 (mass matrix and -1): entries 12..17 of the pattern
static const unsigned char analytic[NZ] = {0, 0, 0, 0, 0, 0, 1, 1, 1, 1};
static int path_jac(void* vctx, int k, const double* z, double* vals) {
  double cd = cos(z[0] - z[1]);
  vals[12] = 2.0;  // d g2 / d w1'
  vals[13] = cd;   // d g3 / d w1'
  vals[14] = cd;   // d g2 / d w2'
  vals[15] = 1.0;  // d g3 / d w2'
  vals[16] = -1.0; // d g2 / d u1
  vals[17] = -1.0; // d g3 / d u2
  return 0;
}

static int integrand(void* vctx, int k, const double* z, double* L) {
  pctx* c = vctx;
  enter(c);
  *L = z[8] * z[8] + z[9] * z[9] + 0.1 * (z[2] * z[6]) * (z[2] * z[6]);
  c->in_use = 0;
  return 0;
}
static const int ivars[4] = {2, 6, 8, 9};

// exact diagonal of the integrand's Hessian (the z2 z6 product contributes to both diagonals)
static int integrand_hess(void* vctx, int k, const double* z, double* d2L) {
  pctx* c = vctx;
  enter(c);
  memset(d2L, 0, sizeof(double) * NZ);
  d2L[8] = d2L[9] = 2.0;
  d2L[2] = 0.2 * z[6] * z[6];
  d2L[6] = 0.2 * z[2] * z[2];
  c->in_use = 0;
  return 0;
}

static int outer(void* ctx, double I, double T, double* J, double* dJdI, double* dJdT) {
  *J = I / T;
  *dJdI = 1.0 / T;
  *dJdT = -I / (T * T);
  return 0;
}

static int boundary(void* ctx, const double* z0, const double* z1, double T, double* b) {
  b[0] = z1[1] - z0[1];
  b[1] = z1[2] - z0[2];
  b[2] = z1[3] - z0[3];
  b[3] = (z1[0] - z0[0]) / T - 0.5;
  return 0;
}
// columns [z_first 0..9 | z_last 10..19 | T 20]
static const int bcol[2 * NZ + 2] = {0, 1, 2, 3, 4, 4, 4, 4, 4, 4, 4,
                                     5, 6, 7, 8, 8, 8, 8, 8, 8, 8, 9};
static const int brow[9] = {3, 0, 1, 2, 3, 0, 1, 2, 3};

static const double zscale[NZ] = {1, 1, 3, 3, 3, 3, 10, 10, 20, 20};
static const double pscale[NP] = {3, 3, 10, 10, 1};
static const double bscale[NB] = {1, 3, 3, 0.5};
static const double plb[NP] = {0, 0, 0, 0, -1.9};
static const double pub[NP] = {0, 0, 0, 0, GO_INF};

static pctx ctxs[4][2];

static go_nlp* make(int nthreads, int with_jac, int set) {
  go_problem p;
  memset(&p, 0, sizeof(p));
  p.dims = (go_dims){NN, NX, NU, NP, NB, 1};
  p.T_lb = 0.1;
  p.T_ub = 10;
  p.z_scale = zscale;
  p.T_scale = 2.0;
  p.path_scale = pscale;
  p.boundary_scale = bscale;
  p.obj_scale = 50.0;
  p.path = path;
  p.path_lb = plb;
  p.path_ub = pub;
  p.path_col_ptr = pcol;
  p.path_row_idx = prow;
  if (with_jac) {
    p.path_jac = path_jac;
    p.path_analytic = analytic;
    p.integrand_hess = integrand_hess;
  }
  p.integrand = integrand;
  p.integrand_vars = ivars;
  p.n_integrand_vars = 4;
  p.outer = outer;
  p.boundary = boundary;
  p.bnd_col_ptr = bcol;
  p.bnd_row_idx = brow;
  p.nthreads = nthreads;
  static void* keep[4][2];  // the NLP keeps the pointer: static storage
  keep[set][0] = &ctxs[set][0];
  keep[set][1] = &ctxs[set][1];
  p.thread_ctx = keep[set];
  char err[256];
  go_nlp* nlp = NULL;
  if (go_nlp_create(&nlp, &p, err, sizeof(err))) fprintf(stderr, "create: %s\n", err);
  return nlp;
}

static int cmp_pair(const void* a, const void* b) {
  const int* x = a;
  const int* y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return x[1] < y[1] ? -1 : (x[1] > y[1]);
}

// go_refine_trapezoid: a coarse trajectory that satisfies its trapezoidal defects (random
// derivatives and controls, states integrated) refined 4x: the coarse nodes are kept, every fine
// defect is below 1e-12, derivatives and controls are linear between coarse nodes.
static void test_refine_keeps_defects(void) {
  enum { NXr = 3, NUr = 2, NZr = 2 * NXr + NUr, N0 = 6, R = 4, N1 = (N0 - 1) * R + 1 };
  double T = 1.7, h0 = T / (N0 - 1), h1 = T / (N1 - 1);
  double z0[N0 * NZr], z1[N1 * NZr];
  srand(11);
  for (int k = 0; k < N0; k++)
    for (int j = NXr; j < NZr; j++) z0[k * NZr + j] = (double)rand() / RAND_MAX * 4 - 2;
  for (int j = 0; j < NXr; j++) z0[j] = 0.3 * j;
  for (int k = 1; k < N0; k++)
    for (int j = 0; j < NXr; j++)
      z0[k * NZr + j] = z0[(k - 1) * NZr + j] +
                        0.5 * h0 * (z0[(k - 1) * NZr + NXr + j] + z0[k * NZr + NXr + j]);
  EXPECT_EQ_INT(-1, go_refine_trapezoid(NXr, NUr, N0, z0, T, N1 + 1, z1));
  EXPECT_EQ_INT(0, go_refine_trapezoid(NXr, NUr, N0, z0, T, N1, z1));
  double worst = 0, worst_node = 0, worst_lin = 0;
  for (int k = 0; k + 1 < N1; k++)
    for (int j = 0; j < NXr; j++) {
      double d = z1[(k + 1) * NZr + j] - z1[k * NZr + j] -
                 0.5 * h1 * (z1[k * NZr + NXr + j] + z1[(k + 1) * NZr + NXr + j]);
      worst = fmax(worst, fabs(d));
    }
  for (int k = 0; k < N0; k++)
    for (int j = 0; j < NZr; j++) worst_node = fmax(worst_node, fabs(z1[k * R * NZr + j] - z0[k * NZr + j]));
  for (int j = NXr; j < NZr; j++)  // a quarter into the second coarse interval
    worst_lin = fmax(worst_lin, fabs(z1[(R + 1) * NZr + j] -
                                     (0.75 * z0[NZr + j] + 0.25 * z0[2 * NZr + j])));
  EXPECT_NEAR(0.0, worst, 1e-12);
  EXPECT_NEAR(0.0, worst_node, 1e-12);
  EXPECT_NEAR(0.0, worst_lin, 1e-12);
}

int main(void) {
  test_refine_keeps_defects();
  go_nlp* a = make(1, 0, 0);  // 1 thread, all finite differences
  go_nlp* b = make(2, 0, 1);  // 2 threads
  go_nlp* c = make(1, 1, 2);  // 1 thread, analytic columns
  go_nlp* d = make(2, 1, 3);  // 2 threads, analytic columns
  EXPECT_TRUE(a && b && c && d);
  if (!(a && b && c && d)) return GS_TEST_RESULT();

  int n, m, ne;
  go_nlp_sizes(a, &n, &m, &ne);
  EXPECT_EQ_INT(NN * NZ + 1, n);
  EXPECT_EQ_INT((NN - 1) * NX + NN * NP + NB, m);
  EXPECT_EQ_INT((NN - 1) * NX * 5 + NN * 18 + 9, ne);
  EXPECT_EQ_INT(6, go_nlp_path_groups(a));
  EXPECT_EQ_INT(3, go_nlp_path_groups(c));

  // a deterministic, non-feasible point
  double* z = malloc(sizeof(double) * (size_t)n);
  double* zs = malloc(sizeof(double) * (size_t)n);
  srand(7);
  for (int v = 0; v < n; v++) z[v] = ((double)rand() / RAND_MAX * 2 - 1) * zscale[v % NZ];
  z[n - 1] = 1.3;
  go_nlp_scale_z(a, z, zs);

  // pattern: in range, no duplicates, count
  int* ir = malloc(sizeof(int) * (size_t)ne);
  int* jc = malloc(sizeof(int) * (size_t)ne);
  int* pairs = malloc(sizeof(int) * 2 * (size_t)ne);
  go_nlp_jac_structure(a, ir, jc);
  int bad_range = 0, dups = 0;
  for (int e = 0; e < ne; e++) {
    if (ir[e] < 0 || ir[e] >= m || jc[e] < 0 || jc[e] >= n) bad_range++;
    pairs[2 * e] = ir[e];
    pairs[2 * e + 1] = jc[e];
  }
  qsort(pairs, (size_t)ne, 2 * sizeof(int), cmp_pair);
  for (int e = 1; e < ne; e++)
    if (pairs[2 * e] == pairs[2 * e - 2] && pairs[2 * e + 1] == pairs[2 * e - 1]) dups++;
  EXPECT_EQ_INT(0, bad_range);
  EXPECT_EQ_INT(0, dups);

  // engine values
  double* g = malloc(sizeof(double) * (size_t)m);
  double* J = malloc(sizeof(double) * (size_t)ne);
  double* grad = malloc(sizeof(double) * (size_t)n);
  double f;
  EXPECT_EQ_INT(0, go_nlp_eval_g(a, zs, g));
  go_nlp_reset_counts(a);
  EXPECT_EQ_INT(0, go_nlp_eval_jac(a, zs, J));
  go_eval_counts cnt;
  go_nlp_counts(a, &cnt);
  long sparse_evals = cnt.path_evals_last_jac;
  EXPECT_EQ_INT(2 * 6 * NN, sparse_evals);
  EXPECT_EQ_INT(0, go_nlp_eval_f(a, zs, &f));
  EXPECT_EQ_INT(0, go_nlp_eval_grad_f(a, zs, grad));

  // dense central differences of the whole constraint vector and objective (independent code)
  double* D = calloc((size_t)m * (size_t)n, sizeof(double));
  double* Dg = malloc(sizeof(double) * (size_t)n);
  gs_test_dense_fd(a, zs, m, n, D, Dg);

  // every engine entry matches; every dense nonzero lies in the pattern
  unsigned char* inpat = calloc((size_t)m * (size_t)n, 1);
  int bad_val = 0, bad_out = 0;
  double worst = 0;
  for (int e = 0; e < ne; e++) {
    double ex = D[(size_t)ir[e] * n + jc[e]];
    inpat[(size_t)ir[e] * n + jc[e]] = 1;
    double err = fabs(ex) > 1e-6 ? fabs(J[e] - ex) / fabs(ex) : fabs(J[e] - ex);
    double tol = fabs(ex) > 1e-6 ? 1e-4 : 1e-8;
    if (err > worst && fabs(ex) > 1e-6) worst = err;
    if (err > tol) {
      if (bad_val++ < 5)
        fprintf(stderr, "jac entry %d (row %d col %d): expected %.10g actual %.10g\n", e, ir[e],
                jc[e], ex, J[e]);
    }
  }
  for (size_t q = 0; q < (size_t)m * (size_t)n; q++) {
    if (!inpat[q] && fabs(D[q]) >= 1e-8) {
      if (bad_out++ < 5)
        fprintf(stderr, "dense FD nonzero outside pattern: row %zu col %zu value %g\n", q / n,
                q % n, D[q]);
    }
  }
  EXPECT_EQ_INT(0, bad_val);
  EXPECT_EQ_INT(0, bad_out);
  printf("jacobian: %d entries, worst relative error %.2e\n", ne, worst);
  int bad_grad = 0;
  for (int v = 0; v < n; v++) {
    double ex = Dg[v];
    double err = fabs(ex) > 1e-6 ? fabs(grad[v] - ex) / fabs(ex) : fabs(grad[v] - ex);
    if (err > (fabs(ex) > 1e-6 ? 1e-4 : 1e-8)) {
      if (bad_grad++ < 5) fprintf(stderr, "grad %d: expected %.10g actual %.10g\n", v, ex, grad[v]);
    }
  }
  EXPECT_EQ_INT(0, bad_grad);

  // analytic columns agree with finite differences
  double* Jc = malloc(sizeof(double) * (size_t)ne);
  go_nlp_reset_counts(c);
  EXPECT_EQ_INT(0, go_nlp_eval_jac(c, zs, Jc));
  go_nlp_counts(c, &cnt);
  EXPECT_EQ_INT(2 * 3 * NN, cnt.path_evals_last_jac);
  EXPECT_EQ_INT(NN, cnt.path_jac_calls);
  for (int e = 0; e < ne; e++) EXPECT_REL(J[e], Jc[e], 1e-6, 1e-6);

  // Gauss-Newton Hessian: the objective's exact Hessian diagonal (J is linear in I and, with
  // h = T/(N-1) and J = I/T, independent of T), against central differences of the gradient with
  // step 1e-4 (scaled); relative 1e-4 with floor 1e-6. T column 0. Absent without integrand_hess.
  {
    double* H = malloc(sizeof(double) * (size_t)n);
    double* gp = malloc(sizeof(double) * (size_t)n);
    double* gm = malloc(sizeof(double) * (size_t)n);
    EXPECT_EQ_INT(0, go_nlp_has_hess_diag(a));
    EXPECT_EQ_INT(-1, go_nlp_eval_hess_diag(a, zs, 1.0, H));
    EXPECT_EQ_INT(1, go_nlp_has_hess_diag(c));
    EXPECT_EQ_INT(0, go_nlp_eval_hess_diag(c, zs, 0.5, H));
    int bad_h = 0;
    for (int v = 0; v + 1 < n; v++) {
      double x0 = zs[v], hstep = 1e-4;
      zs[v] = x0 + hstep;
      go_nlp_eval_grad_f(c, zs, gp);
      zs[v] = x0 - hstep;
      go_nlp_eval_grad_f(c, zs, gm);
      zs[v] = x0;
      double ex = 0.5 * (gp[v] - gm[v]) / (2 * hstep);
      double err = fabs(H[v] - ex) / fmax(fabs(ex), 1e-6);
      if (err > 1e-4 && bad_h++ < 5)
        fprintf(stderr, "hess diag %d: expected %.10g actual %.10g\n", v, ex, H[v]);
    }
    EXPECT_EQ_INT(0, bad_h);
    EXPECT_NEAR(0.0, H[n - 1], 0.0);
    free(H);
    free(gp);
    free(gm);
  }

  // 1 and 2 threads: bitwise identical values
  double* J2 = malloc(sizeof(double) * (size_t)ne);
  double* g2 = malloc(sizeof(double) * (size_t)m);
  double* grad2 = malloc(sizeof(double) * (size_t)n);
  double f2;
  for (int rep = 0; rep < 20; rep++) {  // repeat: thread interleavings vary
    EXPECT_EQ_INT(0, go_nlp_eval_jac(b, zs, J2));
    EXPECT_EQ_INT(0, go_nlp_eval_g(b, zs, g2));
    EXPECT_EQ_INT(0, go_nlp_eval_grad_f(b, zs, grad2));
    EXPECT_EQ_INT(0, go_nlp_eval_f(b, zs, &f2));
    EXPECT_TRUE(memcmp(J, J2, sizeof(double) * (size_t)ne) == 0);
    EXPECT_TRUE(memcmp(g, g2, sizeof(double) * (size_t)m) == 0);
    EXPECT_TRUE(memcmp(grad, grad2, sizeof(double) * (size_t)n) == 0);
    EXPECT_TRUE(memcmp(&f, &f2, sizeof(double)) == 0);
    EXPECT_EQ_INT(0, go_nlp_eval_jac(d, zs, J2));
    EXPECT_TRUE(memcmp(Jc, J2, sizeof(double) * (size_t)ne) == 0);
  }

  // dense baseline (the paper's method): same values, 2 n N path evaluations
  go_nlp_set_jac_mode(a, GO_JAC_DENSE);
  go_nlp_set_jac_mode(b, GO_JAC_DENSE);
  EXPECT_EQ_INT(0, go_nlp_eval_jac(a, zs, J2));
  go_nlp_counts(a, &cnt);
  long dense_evals = cnt.path_evals_last_jac;
  EXPECT_EQ_INT(2L * n * NN, dense_evals);
  for (int e = 0; e < ne; e++) EXPECT_REL(J[e], J2[e], 1e-5, 1e-6);
  EXPECT_EQ_INT(0, go_nlp_eval_grad_f(a, zs, grad2));
  for (int v = 0; v < n; v++) EXPECT_REL(grad[v], grad2[v], 1e-5, 1e-4);
  double* J3 = malloc(sizeof(double) * (size_t)ne);
  EXPECT_EQ_INT(0, go_nlp_eval_jac(b, zs, J3));
  EXPECT_TRUE(memcmp(J2, J3, sizeof(double) * (size_t)ne) == 0);
  printf("path evaluations per Jacobian: sparse %ld (analytic columns: %d), dense %ld\n",
         sparse_evals, 2 * 3 * NN, dense_evals);

  // no worker context was ever used by two threads at once
  int shared = 0;
  for (int s = 0; s < 4; s++) shared += ctxs[s][0].shared + ctxs[s][1].shared;
  EXPECT_EQ_INT(0, shared);

  // a malformed pattern is refused with a reason
  {
    static const int badrow[18] = {2, 2, 4, 2, 3, 4, 0, 3, 1, 2, 0, 1, 2, 3, 2, 3, 2, 3};
    go_problem p;
    memset(&p, 0, sizeof(p));
    p.dims = (go_dims){NN, NX, NU, NP, 0, 0};
    p.T = 1.0;
    p.path = path;
    p.path_col_ptr = pcol;
    p.path_row_idx = badrow;
    p.nthreads = 1;
    go_nlp* bad = NULL;
    char err[256] = "";
    EXPECT_EQ_INT(-1, go_nlp_create(&bad, &p, err, sizeof(err)));
    EXPECT_TRUE(bad == NULL && strstr(err, "repeated") != NULL);
  }

  go_nlp_free(a);
  go_nlp_free(b);
  go_nlp_free(c);
  go_nlp_free(d);
  free(z), free(zs), free(ir), free(jc), free(pairs), free(g), free(J), free(grad), free(D);
  free(Dg), free(inpat), free(Jc), free(J2), free(g2), free(grad2), free(J3);
  return GS_TEST_RESULT();
}
