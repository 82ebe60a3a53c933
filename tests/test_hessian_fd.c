// test_hessian_fd.c: the finite-difference Hessian of the Lagrangian (go_hess_create_fd) on the
// full-body gait problem against brute force: central differences of the Lagrangian gradient
// J^T lambda (structured Jacobian, go_nlp_eval_jac) along single variables.
//
// Problem: jw_fullbody.xml, N = 2 nodes, the default trial's guess (activation 0.05), multipliers
// pseudo-random in [-1, 1] on every path row, 0 on defects and boundary rows (linear), objective
// factor 0. Brute-force columns: every q and qdot of node 0 (the finite-difference variables) and
// every 7th other variable of node 0. Asserted:
//   - every brute-force entry above 1e-5 of its column's largest and above the noise 1e-4 lies
//     in the declared pattern (the element structure, its `lin` marks and the tree-pair mask
//     leave out no curvature);
//   - pattern entries agree with brute force to 5e-3 of the largest entry of their column or 5e-3
//     relative, whichever is larger, plus the noise 1e-4 (measured worst 9.8e-4: the one-sided
//     mixed differences err by O(h), the brute force by O(h^2), where the foot contact curves
//     sharply);
//   - the values do not depend on the number of threads (bitwise).
#include <math.h>
#include <mujoco/mujoco.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/gs_app_model.h"
#include "io/gs_table.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "optim/go_hessian.h"
#include "optim/go_jacobian.h"
#include "tests/gs_test.h"
#include "tests/gs_test_trial.h"

// noise of the brute force: Jacobian entries up to 1e3 from central differences with step 6e-6
// carry about 2e-8, divided by the brute-force step 2e-4
static const double kNoise = 1e-4;

static go_gait* make(const mjModel* m, const gsTable* coords, const gsTable* grf, int nthreads) {
  go_gait_opts o;
  go_gait_opts_default(&o);
  o.N = 2;
  o.nthreads = nthreads;
  o.coords = coords;
  o.grf = grf;
  return gs_test_gait_create(m, &o);
}

// J^T lambda (n) from the Jacobian values in pattern order
static void jt_lambda(int nele, const int* ir, const int* jc, const double* J, const double* lam,
                      int n, double* out) {
  memset(out, 0, sizeof(double) * (size_t)n);
  for (int e = 0; e < nele; e++) out[jc[e]] += J[e] * lam[ir[e]];
}

int main(void) {
  gsTable coords, grf;
  mjModel* m = gs_test_load_trial(&coords, &grf);
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  go_gait* g1 = make(m, &coords, &grf, 1);
  go_gait* g2 = make(m, &coords, &grf, 2);
  EXPECT_TRUE(g1 && g2);
  if (!(g1 && g2)) return GS_TEST_RESULT();
  const go_gait_layout* L = go_gait_layout_get(g1);
  go_nlp* nlp = go_gait_nlp(g1);
  int n, mm, nele, nz = L->nz;
  go_nlp_sizes(nlp, &n, &mm, &nele);
  char err[512];
  double* z = malloc(sizeof(double) * (size_t)n);
  double* zs = malloc(sizeof(double) * (size_t)n);
  double* lam = calloc((size_t)mm, sizeof(double));
  EXPECT_EQ_INT(0, go_gait_guess_from_trial(g1, &coords, 0.05, z, err, sizeof(err)));
  go_nlp_scale_z(nlp, z, zs);
  unsigned long seed = 12345;
  for (int k = 0; k < 2; k++)
    for (int r = 0; r < L->n_path; r++) {
      seed = seed * 6364136223846793005ul + 1442695040888963407ul;
      lam[go_nlp_row_path(nlp, k, r)] = 2.0 * ((seed >> 11) * (1.0 / 9007199254740992.0)) - 1.0;
    }

  go_hess *h1 = NULL, *h2 = NULL;
  EXPECT_EQ_INT(0, go_hess_create_fd(&h1, nlp, go_gait_elements(g1), err, sizeof(err)));
  EXPECT_EQ_INT(0, go_hess_create_fd(&h2, go_gait_nlp(g2), go_gait_elements(g2), err, sizeof(err)));
  if (!h1 || !h2) {
    fprintf(stderr, "%s\n", err);
    return GS_TEST_RESULT();
  }
  int nh = go_hess_nnz(h1);
  int* hr = malloc(sizeof(int) * (size_t)nh);
  int* hc = malloc(sizeof(int) * (size_t)nh);
  double* hv = malloc(sizeof(double) * (size_t)nh);
  double* hv2 = malloc(sizeof(double) * (size_t)nh);
  go_hess_structure(h1, hr, hc);
  EXPECT_EQ_INT(nh, go_hess_nnz(h2));
  long reused0 = go_gait_position_reuses(g1);
  EXPECT_EQ_INT(0, go_hess_values(h1, zs, 0.0, lam, hv));
  long reused = go_gait_position_reuses(g1) - reused0;
  EXPECT_EQ_INT(0, go_hess_values(h2, zs, 0.0, lam, hv2));
  EXPECT_TRUE(memcmp(hv, hv2, sizeof(double) * (size_t)nh) == 0);
  go_eval_counts c;
  go_nlp_counts(nlp, &c);
  printf("fd Hessian: %d entries per node (nz %d), %ld path evaluations and %ld path_jac calls "
         "for 2 nodes, %ld of them on the position stage of the one before\n", nh / 2, nz,
         c.path_evals, c.path_jac_calls, reused);
  // every evaluation at the node's own coordinates but the first, and every pair of a speed with
  // a coordinate but the first of each coordinate, reuses the position stage: over half of all
  EXPECT_TRUE(2 * reused > c.path_evals + c.path_jac_calls);

  // dense node-0 block of the FD Hessian (symmetric) and its pattern
  double* H = calloc((size_t)nz * nz, sizeof(double));
  unsigned char* pat = calloc((size_t)nz * nz, 1);
  for (int t = 0; t < nh; t++) {
    if (hr[t] >= nz || hc[t] >= nz) continue;
    H[(size_t)hr[t] * nz + hc[t]] = H[(size_t)hc[t] * nz + hr[t]] = hv[t];
    pat[(size_t)hr[t] * nz + hc[t]] = pat[(size_t)hc[t] * nz + hr[t]] = 1;
  }
  // brute force
  int* ir = malloc(sizeof(int) * (size_t)nele);
  int* jc = malloc(sizeof(int) * (size_t)nele);
  double* J = malloc(sizeof(double) * (size_t)nele);
  double* gp = malloc(sizeof(double) * (size_t)n);
  double* gm = malloc(sizeof(double) * (size_t)n);
  go_nlp_jac_structure(nlp, ir, jc);
  int cols = 0, outside = 0, bad = 0;
  double worst_out = 0, worst_rel = 0, hmax_all = 0;
  for (int v = 0; v < nz; v++) {
    int fdvar = v < L->x_a;  // q and qdot
    if (!fdvar && v % 7) continue;
    double hs = 1e-4 * fmax(1.0, fabs(zs[v])), x0 = zs[v];
    zs[v] = x0 + hs;
    EXPECT_EQ_INT(0, go_nlp_eval_jac(nlp, zs, J));
    jt_lambda(nele, ir, jc, J, lam, n, gp);
    zs[v] = x0 - hs;
    EXPECT_EQ_INT(0, go_nlp_eval_jac(nlp, zs, J));
    jt_lambda(nele, ir, jc, J, lam, n, gm);
    zs[v] = x0;
    cols++;
    double colmax = 0;
    for (int i = 0; i < nz; i++) colmax = fmax(colmax, fabs((gp[i] - gm[i]) / (2 * hs)));
    hmax_all = fmax(hmax_all, colmax);
    for (int i = 0; i < nz; i++) {
      double bf = (gp[i] - gm[i]) / (2 * hs), fd = H[(size_t)i * nz + v];
      if (!pat[(size_t)i * nz + v]) {
        if (fabs(bf) > 1e-5 * colmax && fabs(bf) > kNoise) {
          if (outside < 10)
            fprintf(stderr, "outside the pattern: (%d, %d) brute force %.3e (column max %.3e)\n",
                    i, v, bf, colmax);
          outside++;
          worst_out = fmax(worst_out, fabs(bf) / colmax);
        }
        continue;
      }
      double tol = 5e-3 * fmax(colmax, fabs(bf)) + kNoise;
      if (fabs(bf) > kNoise) worst_rel = fmax(worst_rel, fabs(fd - bf) / fmax(colmax, fabs(bf)));
      if (fabs(fd - bf) > tol) {
        if (bad < 10)
          fprintf(stderr, "(%d, %d): finite-difference Hessian %.6e, brute force %.6e\n", i, v,
                  fd, bf);
        bad++;
      }
    }
  }
  printf("brute force: %d columns, largest entry %.3e; entries outside the pattern %d (worst "
         "%.2e of its column max); disagreeing %d; worst error %.2e of the column max (entries above the noise)\n",
         cols, hmax_all, outside, worst_out, bad, worst_rel);
  EXPECT_EQ_INT(0, outside);
  EXPECT_EQ_INT(0, bad);
  EXPECT_TRUE(hmax_all > 0);

  go_hess_free(h1);
  go_hess_free(h2);
  go_gait_free(g1);
  go_gait_free(g2);
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  free(z), free(zs), free(lam), free(hr), free(hc), free(hv), free(hv2), free(H), free(pat);
  free(ir), free(jc), free(J), free(gp), free(gm);
  return GS_TEST_RESULT();
}
