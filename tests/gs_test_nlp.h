// gs_test_nlp.h: the reference every NLP derivative test compares the engine against: dense
// central differences of the whole constraint vector and the objective, written independently
// of the engine's own sparse finite differences (optim/go_jacobian.c).
#ifndef GAITSIM_TESTS_GS_TEST_NLP_H_
#define GAITSIM_TESTS_GS_TEST_NLP_H_

#include <math.h>
#include <stdlib.h>

#include "optim/go_collocation.h"

// Dense central differences at the scaled point zs (n variables, restored on return) of the
// scaled constraints g (m rows) into D (m x n, row-major) and of the objective into Dg (n).
// Step h = cbrt(eps) max(1, |z|), divided by the step actually taken (xp - xm).
static void gs_test_dense_fd(go_nlp* nlp, double* zs, int m, int n, double* D, double* Dg) {
  double* gp = malloc(sizeof(double) * (size_t)m);
  double* gm = malloc(sizeof(double) * (size_t)m);
  for (int v = 0; v < n; v++) {
    double x0 = zs[v], h = 6.0554544523933395e-06 * fmax(1.0, fabs(x0)), fp, fm;
    zs[v] = x0 + h;
    double xp = zs[v];
    go_nlp_eval_g(nlp, zs, gp);
    go_nlp_eval_f(nlp, zs, &fp);
    zs[v] = x0 - h;
    double xm = zs[v];
    go_nlp_eval_g(nlp, zs, gm);
    go_nlp_eval_f(nlp, zs, &fm);
    zs[v] = x0;
    for (int r = 0; r < m; r++) D[(size_t)r * n + v] = (gp[r] - gm[r]) / (xp - xm);
    Dg[v] = (fp - fm) / (xp - xm);
  }
  free(gp);
  free(gm);
}

#endif  // GAITSIM_TESTS_GS_TEST_NLP_H_
