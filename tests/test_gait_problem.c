// test_gait_problem.c: the gait collocation problem (optim/go_gait.h) on jw_fullbody at N = 4:
// the engine's Jacobian (analytic columns: mass matrix, moment arms x muscle partials, Hill and
// activation partials; finite differences for q, qdot) against dense central differences of the
// whole constraint vector, every nonzero inside the declared pattern, the objective gradient,
// bitwise equality with 1 and 2 threads, and the guess satisfying its exact rows.
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/gs_app_model.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "optim/go_jacobian.h"
#include "tests/gs_test.h"
#include "tests/gs_test_nlp.h"

#define TRIAL GAITSIM_SOURCE_DIR "/mjmodels/trials/jw_ngait_og5"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static go_gait* make(const mjModel* m, const gsTable* coords, const gsTable* grf, int nthreads) {
  go_gait_opts o;
  go_gait_opts_default(&o);
  o.N = 4;
  o.nthreads = nthreads;
  o.coords = coords;
  o.grf = grf;
  o.speed = 1.27;
  static const char* free_coords[] = {"pelvis_tz", NULL};
  o.free_coords = free_coords;
  char err[512];
  go_gait* g = NULL;
  if (go_gait_create(&g, m, &o, err, sizeof(err)) != 0) fprintf(stderr, "create: %s\n", err);
  return g;
}

int main(void) {
  mjModel* m = gs_app_load_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody.xml");
  gsTable coords, grf;
  gs_table_init(&coords);
  gs_table_init(&grf);
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  EXPECT_EQ_INT(0, gs_app_read_table(m, TRIAL "/coordinates.mot", &coords));
  EXPECT_EQ_INT(0, gs_app_read_table(m, TRIAL "/grf.mot", &grf));
  go_gait* g1 = make(m, &coords, &grf, 1);
  go_gait* g2 = make(m, &coords, &grf, 2);
  EXPECT_TRUE(g1 && g2);
  if (!(g1 && g2)) return GS_TEST_RESULT();
  const go_gait_layout* L = go_gait_layout_get(g1);
  go_nlp* a = go_gait_nlp(g1);
  go_nlp* b = go_gait_nlp(g2);
  int n, mm, ne;
  go_nlp_sizes(a, &n, &mm, &ne);
  printf("gait N=4: nz %d, n %d, m %d, nele_jac %d, path rows/node %d, groups %d\n", L->nz, n, mm,
         ne, L->n_path, go_nlp_path_groups(a));
  EXPECT_EQ_INT(2 * L->nv, go_nlp_path_groups(a));

  // guess: the rows it satisfies by construction (link, grf) are zero
  double* z = malloc(sizeof(double) * (size_t)n);
  double* zs = malloc(sizeof(double) * (size_t)n);
  double* g = malloc(sizeof(double) * (size_t)mm);
  char err[512];
  EXPECT_EQ_INT(0, go_gait_guess_from_trial(g1, &coords, 0.05, z, err, sizeof(err)));
  go_nlp_scale_z(a, z, zs);
  EXPECT_EQ_INT(0, go_nlp_eval_g(a, zs, g));
  double link = 0, grfr = 0, act = 0;
  for (int k = 0; k < 4; k++) {
    for (int j = 0; j < L->nv; j++) link = fmax(link, fabs(g[go_nlp_row_path(a, k, L->r_link + j)]));
    for (int c = 0; c < 6; c++) grfr = fmax(grfr, fabs(g[go_nlp_row_path(a, k, L->r_grf + c)]));
    for (int i = 0; i < L->na; i++) act = fmax(act, fabs(g[go_nlp_row_path(a, k, L->r_act + i)]));
  }
  EXPECT_NEAR(0, link, 1e-12);
  EXPECT_NEAR(0, grfr, 1e-12);
  EXPECT_NEAR(0, act, 1e-12);

  // a deterministic point around the guess, muscles active and tendons moving
  srand(11);
  for (int k = 0; k < 4; k++) {
    double* zk = z + (size_t)k * L->nz;
    for (int j = 0; j < L->nv; j++) {
      zk[L->x_qd + j] += 0.2 * ((double)rand() / RAND_MAX - 0.5);
      zk[L->xd_qdd + j] += 5.0 * ((double)rand() / RAND_MAX - 0.5);
    }
    for (int i = 0; i < L->na; i++) {
      zk[L->x_a + i] = 0.05 + 0.4 * rand() / RAND_MAX;
      zk[L->u_e + i] = 0.05 + 0.4 * rand() / RAND_MAX;
      zk[L->xd_a + i] = 2.0 * ((double)rand() / RAND_MAX - 0.5);
    }
    for (int e = 0; e < L->ne; e++) {
      zk[L->x_ft + e] += 0.1 * rand() / RAND_MAX;
      zk[L->xd_ft + e] = 2.0 * ((double)rand() / RAND_MAX - 0.5);
    }
  }
  go_nlp_scale_z(a, z, zs);

  // engine Jacobian, timing
  int* ir = malloc(sizeof(int) * (size_t)ne);
  int* jc = malloc(sizeof(int) * (size_t)ne);
  double* J = malloc(sizeof(double) * (size_t)ne);
  double* grad = malloc(sizeof(double) * (size_t)n);
  double f;
  go_nlp_jac_structure(a, ir, jc);
  double t0 = now();
  EXPECT_EQ_INT(0, go_nlp_eval_g(a, zs, g));
  double t_g = now() - t0;
  go_nlp_reset_counts(a);
  t0 = now();
  EXPECT_EQ_INT(0, go_nlp_eval_jac(a, zs, J));
  double t_j = now() - t0;
  go_eval_counts cnt;
  go_nlp_counts(a, &cnt);
  EXPECT_EQ_INT(2L * 2 * L->nv * 4, cnt.path_evals_last_jac);
  printf("per-node path evaluation %.1f us; Jacobian (N=4, 1 thread) %.2f ms, %ld path evals + %ld "
         "analytic calls\n", 1e6 * t_g / 4, 1e3 * t_j, cnt.path_evals_last_jac, cnt.path_jac_calls);
  EXPECT_EQ_INT(0, go_nlp_eval_f(a, zs, &f));
  EXPECT_EQ_INT(0, go_nlp_eval_grad_f(a, zs, grad));

  // dense central differences of g and f over every variable (independent of the engine's FD)
  double* D = calloc((size_t)mm * (size_t)n, sizeof(double));
  double* Dg = malloc(sizeof(double) * (size_t)n);
  gs_test_dense_fd(a, zs, mm, n, D, Dg);
  unsigned char* inpat = calloc((size_t)mm * (size_t)n, 1);
  int bad_val = 0, bad_out = 0;
  double worst = 0;
  for (int e = 0; e < ne; e++) {
    double ex = D[(size_t)ir[e] * n + jc[e]];
    inpat[(size_t)ir[e] * n + jc[e]] = 1;
    double rel = fabs(ex) > 1e-6 ? fabs(J[e] - ex) / fabs(ex) : fabs(J[e] - ex);
    double tol = fabs(ex) > 1e-6 ? 1e-4 : 1e-7;
    if (fabs(ex) > 1e-6 && rel > worst) worst = rel;
    if (rel > tol && bad_val++ < 8) {
      int node = jc[e] / L->nz;
      fprintf(stderr, "jac entry %d (row %d, col %d = node %d var %d): expected %.10g actual %.10g\n",
              e, ir[e], jc[e], node, jc[e] % L->nz, ex, J[e]);
    }
  }
  // outside the pattern: exact zeros up to rounding noise. Muscle lengths are computed in world
  // coordinates (through wrapping geometry), so a pelvis perturbation changes lMT of a muscle
  // that does not cross it by rounding only: up to ~1e-13 m, which over the ~6e-6 step and the
  // stiff tendon (dr/dlMT up to a few hundred 1/m, scaled) gives up to ~1e-5 in a Hill row's
  // central difference (1.3e-6 seen at the tilted standing pose). Real dependencies are moment
  // arms times such slopes, >= 1e-3; the threshold 1e-5 separates the two.
  double worst_out = 0;
  for (size_t q = 0; q < (size_t)mm * (size_t)n; q++) {
    if (!inpat[q]) worst_out = fmax(worst_out, fabs(D[q]));
    if (!inpat[q] && fabs(D[q]) >= 1e-5 && bad_out++ < 8) {
      fprintf(stderr, "dense FD nonzero outside the pattern: row %zu col %zu (var %zu) value %g\n",
              q / n, q % n, (q % n) % L->nz, D[q]);
    }
  }
  EXPECT_EQ_INT(0, bad_val);
  EXPECT_EQ_INT(0, bad_out);
  printf("jacobian: %d entries, worst relative error %.2e, largest dense FD value outside the "
         "pattern %.1e\n", ne, worst, worst_out);
  int bad_grad = 0;
  for (int v = 0; v < n; v++) {
    double ex = Dg[v];
    // tolerance: 1e-4 relative plus the central difference's rounding noise on f
    double tol = 1e-4 * fabs(ex) + 100 * 2.2e-16 * fmax(1.0, fabs(f)) / 6.0554544523933395e-06;
    if (fabs(grad[v] - ex) > tol && bad_grad++ < 5)
      fprintf(stderr, "grad %d: expected %.10g actual %.10g\n", v, ex, grad[v]);
  }
  EXPECT_EQ_INT(0, bad_grad);

  // 1 and 2 threads: bitwise identical
  double* J2 = malloc(sizeof(double) * (size_t)ne);
  double* gv2 = malloc(sizeof(double) * (size_t)mm);
  double* grad2 = malloc(sizeof(double) * (size_t)n);
  double f2;
  EXPECT_EQ_INT(0, go_nlp_eval_g(a, zs, g));
  for (int rep = 0; rep < 3; rep++) {
    EXPECT_EQ_INT(0, go_nlp_eval_jac(b, zs, J2));
    EXPECT_EQ_INT(0, go_nlp_eval_g(b, zs, gv2));
    EXPECT_EQ_INT(0, go_nlp_eval_grad_f(b, zs, grad2));
    EXPECT_EQ_INT(0, go_nlp_eval_f(b, zs, &f2));
    EXPECT_TRUE(memcmp(J, J2, sizeof(double) * (size_t)ne) == 0);
    EXPECT_TRUE(memcmp(g, gv2, sizeof(double) * (size_t)mm) == 0);
    EXPECT_TRUE(memcmp(grad, grad2, sizeof(double) * (size_t)n) == 0);
    EXPECT_TRUE(memcmp(&f, &f2, sizeof(double)) == 0);
  }

  go_gait_free(g1);
  go_gait_free(g2);
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  free(z), free(zs), free(g), free(ir), free(jc), free(J), free(grad), free(D), free(Dg);
  free(inpat), free(J2), free(gv2), free(grad2);
  return GS_TEST_RESULT();
}
