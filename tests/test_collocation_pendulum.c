// test_collocation_pendulum.c: end-to-end solves with known answers through Ipopt.
//
// 1. Minimum effort double integrator: x'' = u, x: 0 -> 1, v: 0 -> 0 in T = 1, J = int u^2 dt.
//    Analytic optimum u(t) = 6 - 12 t, J = 12. Trapezoidal collocation, N = 41, bounds on the end
//    nodes through overrides.
// 2. Pendulum swing-up: theta'' = u - 9.81 sin(theta), from hanging at rest to upright at rest in
//    T = 2 s, J = int u^2 dt, end state through boundary constraints; N = 51, 2 threads.
// Ipopt must print nothing on stdout (no banner) and report success.
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "optim/go_collocation.h"
#include "optim/go_hessian.h"
#include "optim/go_ipopt.h"
#include "tests/gs_test.h"

// --- shared pieces: node z = [x v | x' v' | u] ---------------------------------------------------

static int integrand(void* ctx, int k, const double* z, double* L) {
  *L = z[4] * z[4];
  return 0;
}
static const int ivars[1] = {4};
static int integrand_hess(void* ctx, int k, const double* z, double* d2L) {
  memset(d2L, 0, 5 * sizeof(double));
  d2L[4] = 2.0;
  return 0;
}

// run go_ipopt_solve with fd 1 sent to a file; returns the bytes written to stdout
static long solve_quiet(go_nlp* nlp, go_ipopt_opts* o, double* z, double* zb, go_solve_result* r,
                        int* rc) {
  char path[] = "/tmp/gs_test_stdout_XXXXXX";
  int fd = mkstemp(path);
  fflush(stdout);
  int saved = dup(1);
  dup2(fd, 1);
  char err[256] = "";
  *rc = go_ipopt_solve(nlp, o, z, zb, NULL, r, err, sizeof(err));
  fflush(stdout);
  dup2(saved, 1);
  close(saved);
  long bytes = (long)lseek(fd, 0, SEEK_END);
  close(fd);
  unlink(path);
  if (*rc) fprintf(stderr, "solve: %s\n", err);
  return bytes;
}

static int count_lines(FILE* f) {
  rewind(f);
  int n = 0, ch;
  while ((ch = fgetc(f)) != EOF) n += ch == '\n';
  return n;
}

// --- 1. double integrator ------------------------------------------------------------------------

static int di_path(void* ctx, int k, const double* z, double* g) {
  g[0] = z[2] - z[1];  // x' - v
  g[1] = z[3] - z[4];  // v' - u
  return 0;
}
static const int di_pcol[6] = {0, 0, 1, 2, 3, 4};
static const int di_prow[4] = {0, 0, 1, 1};

static void test_double_integrator(void) {
  enum { N = 41, NZ = 5 };
  go_bound_override ov[4] = {{0, 0, 0.0, 0.0}, {0, 1, 0.0, 0.0}, {-1, 0, 1.0, 1.0}, {-1, 1, 0.0, 0.0}};
  go_problem p;
  memset(&p, 0, sizeof(p));
  p.dims = (go_dims){N, 2, 1, 2, 0, 0};
  p.T = 1.0;
  p.overrides = ov;
  p.n_overrides = 4;
  p.path = di_path;
  p.path_col_ptr = di_pcol;
  p.path_row_idx = di_prow;
  p.integrand = integrand;
  p.integrand_vars = ivars;
  p.n_integrand_vars = 1;
  p.obj_scale = 10.0;
  p.nthreads = 1;
  go_nlp* nlp = NULL;
  char err[256];
  EXPECT_EQ_INT(0, go_nlp_create(&nlp, &p, err, sizeof(err)));
  if (!nlp) return;
  double z[N * NZ], zb[N * NZ];
  for (int k = 0; k < N; k++) {
    double t = (double)k / (N - 1);
    double g[NZ] = {t, 1.0, 1.0, 0.0, 0.0};
    memcpy(z + k * NZ, g, sizeof(g));
  }
  go_ipopt_opts o;
  go_ipopt_opts_default(&o);
  o.progress = tmpfile();
  go_solve_result r;
  int rc;
  long out = solve_quiet(nlp, &o, z, zb, &r, &rc);
  EXPECT_EQ_INT(0, rc);
  EXPECT_EQ_INT(0, out);  // no banner, nothing on stdout
  EXPECT_EQ_INT(GO_SOLVE_SUCCESS, r.status);
  EXPECT_NEAR(12.0, r.objective, 0.005 * 12.0);
  // u(t) against 6 - 12 t: interior nodes within 0.02 (0.33 % of max |u|); the two end nodes,
  // whose controls enter the trapezoidal defects and integral with half weight, within 0.2
  double worst = 0, worst_end = 0;
  for (int k = 0; k < N; k++) {
    double t = (double)k / (N - 1), e = fabs(z[k * NZ + 4] - (6.0 - 12.0 * t));
    double* w = (k == 0 || k == N - 1) ? &worst_end : &worst;
    if (e > *w) *w = e;
  }
  EXPECT_NEAR(0.0, worst, 0.02);
  EXPECT_NEAR(0.0, worst_end, 0.2);
  EXPECT_EQ_INT(r.iterations + 1, count_lines(o.progress));  // iterations 0..iter
  EXPECT_TRUE(r.max_viol < 1e-8);
  printf("double integrator: %s, %d iterations, J = %.8f, max |u - (6-12t)| = %.2e interior, "
         "%.2e end nodes, %.3f s\n",
         go_solve_status_str(r.status), r.iterations, r.objective, worst, worst_end, r.wall_s);
  fclose(o.progress);
  go_nlp_free(nlp);
}

// --- 2. pendulum swing-up ------------------------------------------------------------------------

static int pe_path(void* ctx, int k, const double* z, double* g) {
  g[0] = z[2] - z[1];                        // theta' - omega
  g[1] = z[3] + 9.81 * sin(z[0]) - z[4];     // omega' + g sin(theta) - u
  return 0;
}
static const int pe_pcol[6] = {0, 1, 2, 3, 4, 5};
static const int pe_prow[5] = {1, 0, 0, 1, 1};

static int pe_boundary(void* ctx, const double* z0, const double* z1, double T, double* b) {
  b[0] = z1[0] - M_PI;
  b[1] = z1[1];
  return 0;
}
// columns [z_first 0..4 | z_last 5..9 | T 10]: theta_last -> row 0, omega_last -> row 1
static const int pe_bcol[12] = {0, 0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2};
static const int pe_brow[2] = {0, 1};

// swing-up with Ipopt's L-BFGS (pqn = 0), the partitioned quasi-Newton Hessian (pqn = 1, one
// element: the dynamics row omega' + g sin(theta) - u over theta) or that element's exact Hessian
// by finite differences (pqn = 2, go_hess_create_fd); returns the iterations
static int test_swing_up(int pqn) {
  enum { N = 51, NZ = 5 };
  go_bound_override ov[2] = {{0, 0, 0.0, 0.0}, {0, 1, 0.0, 0.0}};
  double lb[NZ] = {-10, -30, -30, -200, -50}, ub[NZ] = {10, 30, 30, 200, 50};
  double sc[NZ] = {1, 3, 3, 10, 10};
  void* ctx[2] = {NULL, NULL};
  go_problem p;
  memset(&p, 0, sizeof(p));
  p.dims = (go_dims){N, 2, 1, 2, 2, 0};
  p.T = 2.0;
  p.z_lb = lb;
  p.z_ub = ub;
  p.z_scale = sc;
  p.overrides = ov;
  p.n_overrides = 2;
  p.path = pe_path;
  p.path_col_ptr = pe_pcol;
  p.path_row_idx = pe_prow;
  p.integrand = integrand;
  p.integrand_vars = ivars;
  p.n_integrand_vars = 1;
  p.obj_scale = 100.0;
  p.boundary = pe_boundary;
  p.bnd_col_ptr = pe_bcol;
  p.bnd_row_idx = pe_brow;
  p.thread_ctx = ctx;
  p.nthreads = 2;
  if (pqn) p.integrand_hess = integrand_hess;
  go_nlp* nlp = NULL;
  char err[256];
  EXPECT_EQ_INT(0, go_nlp_create(&nlp, &p, err, sizeof(err)));
  if (!nlp) return -1;
  static const int el_rows[1] = {1}, el_vars[1] = {0}, el_ptr[2] = {0, 1};
  go_elements el = {1, el_ptr, el_rows, el_ptr, el_vars, NULL, NULL};
  go_hess* hess = NULL;
  if (pqn == 1) EXPECT_EQ_INT(0, go_hess_create(&hess, nlp, &el, err, sizeof(err)));
  if (pqn == 2) EXPECT_EQ_INT(0, go_hess_create_fd(&hess, nlp, &el, err, sizeof(err)));
  double z[N * NZ];
  for (int k = 0; k < N; k++) {
    double t = 2.0 * k / (N - 1);
    double g[NZ] = {M_PI * t / 2.0, M_PI / 2.0, M_PI / 2.0, 0.0, 9.81 * sin(M_PI * t / 2.0)};
    memcpy(z + k * NZ, g, sizeof(g));
  }
  go_ipopt_opts o;
  go_ipopt_opts_default(&o);
  o.tol = 1e-9;
  o.hess = hess;
  EXPECT_EQ_INT(0, go_ipopt_opts_add(&o, "constr_viol_tol=1e-10", err, sizeof(err)));
  go_solve_result r;
  int rc;
  long out = solve_quiet(nlp, &o, z, NULL, &r, &rc);
  EXPECT_EQ_INT(0, rc);
  EXPECT_EQ_INT(0, out);
  EXPECT_EQ_INT(GO_SOLVE_SUCCESS, r.status);
  EXPECT_NEAR(M_PI, z[(N - 1) * NZ + 0], 1e-6);
  EXPECT_NEAR(0.0, z[(N - 1) * NZ + 1], 1e-6);
  EXPECT_NEAR(0.0, z[0], 1e-12);
  go_eval_counts c;
  go_nlp_counts(nlp, &c);
  printf("swing-up (%s): %s, %d iterations, J = %.6f, theta_end - pi = %.2e, omega_end = %.2e, "
         "%.3f s, %ld path evaluations (%ld per Jacobian), %ld Jacobians\n",
         pqn == 2 ? "finite-difference Hessian" : pqn ? "partitioned quasi-Newton" : "L-BFGS", go_solve_status_str(r.status), r.iterations,
         r.objective, z[(N - 1) * NZ] - M_PI, z[(N - 1) * NZ + 1], r.wall_s, c.path_evals,
         c.path_evals_last_jac, c.jac_evals);
  go_hess_free(hess);
  go_nlp_free(nlp);
  return r.iterations;
}

int main(void) {
  test_double_integrator();
  int it_lbfgs = test_swing_up(0);
  int it_pqn = test_swing_up(1);
  int it_fd = test_swing_up(2);
  // the element Hessian learns the one nonlinear term; it must not need more iterations. The
  // exact (finite-difference) Hessian takes Ipopt to another local optimum (J = 65.84 against
  // 68.24, measured): no more iterations than L-BFGS asked of it (its values: test_gait_problem)
  EXPECT_TRUE(it_pqn > 0 && it_pqn <= it_lbfgs);
  EXPECT_TRUE(it_fd > 0 && it_fd <= it_lbfgs);
  return GS_TEST_RESULT();
}
