// test_hessian_metabolic.c: the objective part of the exact (finite-difference) Hessian of a
// predictive gait problem (go_hess_create_fd with go_gait's integrand_hess_block: the smooth
// Umberger 2010 metabolic power's mixed curvature, plus the effort and smoothness squares)
// against brute force: central differences of the objective gradient (go_nlp_eval_grad_f, the
// metabolic chain-rule gradient) along every variable of node 0.
//
// Problem: jw_fullbody.xml, N = 2 nodes, the cost of transport at 1.27 m/s with free stride
// time, the prediction's metabolic smoothing (GO_PREDICT_METABOLIC_SMOOTHING) and weights, the
// default trial's guess with activations 0.3 (mid-range, where the smooth rates curve), every
// multiplier 0, objective factor 0.7 (so the factor is applied). Node 0 has trapezoidal weight
// 1/2, so the node weight is checked too. Asserted:
//   - every brute-force entry above 1e-6 of its column's largest and above the noise lies in
//     the declared pattern (no mixed curvature left out; the grouped perturbation of every
//     muscle's a, e and fT at once attributes each entry to the right muscle);
//   - pattern entries agree with brute force to 1e-3 of their column's largest or relative,
//     plus the noise (the Hessian differences the gradient with step 1e-4, the brute force with
//     3e-4: an independent step, the same gradient);
//   - the Hessian is not the diagonal alone: off-diagonal metabolic entries above 1e-3 of the
//     largest exist (a Hessian leaving them out fails the agreement check);
//   - the values do not depend on the number of threads (bitwise).
#include <math.h>
#include <mujoco/mujoco.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/gs_table.h"
#include "optim/go_defaults.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "optim/go_hessian.h"
#include "optim/go_jacobian.h"
#include "tests/gs_test.h"
#include "tests/gs_test_trial.h"

static const double kObjFactor = 0.7;

static go_gait* make(const mjModel* m, const gsTable* coords, int nthreads) {
  go_gait_opts o;
  go_gait_opts_default(&o);
  o.N = 2;
  o.nthreads = nthreads;
  o.coords = coords;
  o.speed = 1.27;
  o.w_cot = 1.0;
  o.w_effort = GO_PREDICT_W_EFFORT;
  o.w_accel = GO_PREDICT_W_ACCEL;
  o.metabolic_smoothing = GO_PREDICT_METABOLIC_SMOOTHING;
  o.free_time = 1;
  o.T_lb = 0.4;
  o.T_ub = 2.5;
  return gs_test_gait_create(m, &o);
}

int main(void) {
  gsTable coords, grf;
  mjModel* m = gs_test_load_trial(&coords, &grf);
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  go_gait* g1 = make(m, &coords, 1);
  go_gait* g2 = make(m, &coords, 2);
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
  EXPECT_EQ_INT(0, go_gait_guess_from_trial(g1, &coords, 0.3, z, err, sizeof(err)));
  z[n - 1] = go_gait_stride_time(g1);  // the free stride time (the guess fills the nodes)
  go_nlp_scale_z(nlp, z, zs);

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
  EXPECT_EQ_INT(0, go_hess_values(h1, zs, kObjFactor, lam, hv));
  EXPECT_EQ_INT(0, go_hess_values(h2, zs, kObjFactor, lam, hv2));
  EXPECT_TRUE(memcmp(hv, hv2, sizeof(double) * (size_t)nh) == 0);

  // dense node-0 block (symmetric) and its pattern
  double* H = calloc((size_t)nz * nz, sizeof(double));
  unsigned char* pat = calloc((size_t)nz * nz, 1);
  for (int t = 0; t < nh; t++) {
    if (hr[t] >= nz || hc[t] >= nz) continue;
    H[(size_t)hr[t] * nz + hc[t]] = H[(size_t)hc[t] * nz + hr[t]] = hv[t];
    pat[(size_t)hr[t] * nz + hc[t]] = pat[(size_t)hc[t] * nz + hr[t]] = 1;
  }
  // brute force: every column of node 0, the Hessian's own step (1e-4 max(1, |zs|) in the
  // solver's scaling, i.e. 1e-4 max(z_scale, |z|)), so that an entry compares with the same
  // difference of the same gradient: a check of the bookkeeping (the grouped perturbations, the
  // scaling, the node weight, the objective factor, the pattern), not of the step
  double* gp = malloc(sizeof(double) * (size_t)n);
  double* gm = malloc(sizeof(double) * (size_t)n);
  double* B = calloc((size_t)nz * nz, sizeof(double));  // B[i nz + v]: row i of column v
  for (int v = 0; v < nz; v++) {
    double hs = 1e-4 * fmax(1.0, fabs(zs[v])), x0 = zs[v];
    zs[v] = x0 + hs;
    EXPECT_EQ_INT(0, go_nlp_eval_grad_f(nlp, zs, gp));
    zs[v] = x0 - hs;
    EXPECT_EQ_INT(0, go_nlp_eval_grad_f(nlp, zs, gm));
    zs[v] = x0;
    for (int i = 0; i < nz; i++) B[(size_t)i * nz + v] = kObjFactor * (gp[i] - gm[i]) / (2 * hs);
  }
  // the column each entry is read from: a coordinate's or speed's (both for two of them:
  // averaged), else the lower variable's (a muscle's own a, e, fT)
  int outside = 0, bad = 0, offdiag = 0;
  double worst_out = 0, worst_rel = 0, hmax_all = 0, worst_asym = 0;
  const double noise = 1e-5;  // the gradient's rounding (1e-10 of its entries) over the step
  for (int v = 0; v < nz; v++)
    for (int i = 0; i < nz; i++) hmax_all = fmax(hmax_all, fabs(B[(size_t)i * nz + v]));
  for (int v = 0; v < nz; v++) {
    for (int i = v; i < nz; i++) {
      int qi = i < L->x_qd + L->nv, qv = v < L->x_qd + L->nv;  // q or qdot (they come first)
      double bf = qi && qv ? 0.5 * (B[(size_t)i * nz + v] + B[(size_t)v * nz + i])
                  : qi     ? B[(size_t)v * nz + i]   // row v of column i
                           : B[(size_t)i * nz + v];  // row i of column v
      double colmax = 0;
      for (int r = 0; r < nz; r++) colmax = fmax(colmax, fabs(B[(size_t)r * nz + (qi ? i : v)]));
      if (!qi && !qv && i != v)
        worst_asym = fmax(worst_asym, fabs(B[(size_t)i * nz + v] - B[(size_t)v * nz + i]) / colmax);
      if (!pat[(size_t)i * nz + v]) {
        if (fabs(bf) > 1e-6 * colmax && fabs(bf) > noise) {
          if (outside < 10)
            fprintf(stderr, "outside the pattern: (%d, %d) brute force %.3e (column max %.3e)\n",
                    i, v, bf, colmax);
          outside++;
          worst_out = fmax(worst_out, fabs(bf) / colmax);
        }
        continue;
      }
      double fd = H[(size_t)i * nz + v];
      if (i != v && fabs(bf) > 1e-3 * colmax) offdiag++;
      if (fabs(bf) > noise) worst_rel = fmax(worst_rel, fabs(fd - bf) / fmax(colmax, fabs(bf)));
      if (fabs(fd - bf) > 1e-6 * fmax(colmax, fabs(bf)) + noise) {
        if (bad < 10)
          fprintf(stderr, "(%d, %d): finite-difference Hessian %.6e, brute force %.6e\n", i, v,
                  fd, bf);
        bad++;
      }
    }
  }
  printf("metabolic Hessian: %d entries per node (nz %d); brute force over %d columns, largest "
         "entry %.3e, %d off-diagonal entries above 1e-3 of their column's largest; outside the "
         "pattern %d (worst %.2e of its column max); disagreeing %d (worst %.2e of the column "
         "max); a muscle's own pairs differ between their two columns by up to %.2e of the column max\n",
         nh / 2, nz, nz, hmax_all, offdiag, outside, worst_out, bad, worst_rel, worst_asym);
  EXPECT_EQ_INT(0, outside);
  EXPECT_EQ_INT(0, bad);
  EXPECT_TRUE(offdiag > 500);
  EXPECT_TRUE(hmax_all > 0);

  go_hess_free(h1);
  go_hess_free(h2);
  go_gait_free(g1);
  go_gait_free(g2);
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  free(z), free(zs), free(lam), free(hr), free(hc), free(hv), free(hv2), free(H), free(pat);
  free(gp), free(gm), free(B);
  return GS_TEST_RESULT();
}
