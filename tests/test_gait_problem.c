// test_gait_problem.c: the gait collocation problem (optim/go_gait.h) on jw_fullbody at N = 4:
// the engine's Jacobian (analytic columns: mass matrix, moment arms x muscle partials, Hill and
// activation partials; finite differences for q, qdot) against dense central differences of the
// whole constraint vector, every nonzero inside the declared pattern, the objective gradient,
// bitwise equality with 1 and 2 threads, and the guess satisfying its exact rows. The problem
// checked carries the predictive extras too: the acceleration goal (w_accel 2), the ground
// reaction moment goal (w_grm 1.5; its reference's centre of pressure against the measured one)
// and the fibre
// rows 0.25 <= lM/lopt <= 1.5 (their q and fT columns inside the pattern, FD agreement); the
// Gauss-Newton Hessian diagonal against differences of the gradient; the objective's goals
// (go_gait_objective_terms) summing to J; the fibre rows equal to the muscle model's own fibre
// length (gs_physics_muscle_tension).
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/gs_app_model.h"
#include "callbacks/gs_physics.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "optim/go_hessian.h"
#include "optim/go_jacobian.h"
#include "tests/gs_test.h"
#include "tests/gs_test_trial.h"
#include "tests/gs_test_nlp.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

#define W_ACCEL 2.0
#define W_GRM 1.5

// extras: the acceleration goal, the fibre-length rows and the walk row (floor MIN_VGRF BW)
#define MIN_VGRF 0.1
static go_gait_opts opts_of(const gsTable* coords, const gsTable* grf, int nthreads, int extras) {
  go_gait_opts o = gs_test_tracking_opts(coords, grf, 4);
  o.w_accel = extras ? W_ACCEL : 0;
  o.w_grm = extras ? W_GRM : 0;
  o.fibre_bounds = extras;
  o.min_vgrf = extras ? MIN_VGRF : 0;
  o.nthreads = nthreads;
  o.speed = 1.27;
  return o;
}

static go_gait* make(const mjModel* m, const gsTable* coords, const gsTable* grf, int nthreads,
                     int extras) {
  go_gait_opts o = opts_of(coords, grf, nthreads, extras);
  return gs_test_gait_create(m, &o);
}

int main(void) {
  gsTable coords, grf;
  mjModel* m = gs_test_load_trial(&coords, &grf);
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  go_gait* g0 = make(m, &coords, &grf, 1, 0);  // the tracking problem as it was
  go_gait* g1 = make(m, &coords, &grf, 1, 1);
  go_gait* g2 = make(m, &coords, &grf, 2, 1);
  EXPECT_TRUE(g0 && g1 && g2);
  if (!(g0 && g1 && g2)) return GS_TEST_RESULT();
  const go_gait_layout* L = go_gait_layout_get(g1);
  const go_gait_layout* L0 = go_gait_layout_get(g0);
  go_nlp* a = go_gait_nlp(g1);
  go_nlp* b = go_gait_nlp(g2);
  int n, mm, ne;
  go_nlp_sizes(a, &n, &mm, &ne);
  // the fibre rows: na more rows per node, after the grf rows, nonzero only in q columns and
  // the muscle's own fT column (which every elastic muscle's row has)
  {
    int n0, m0, ne0, bad_col = 0, ft_cols = 0, fib_nnz = 0, grm_nnz = 0, walk_nnz = 0;
    int walk_bad = 0;
    go_nlp_sizes(go_gait_nlp(g0), &n0, &m0, &ne0);
    // g1 also tracks the ground reaction moments: 6 more variables and rows per node
    int dgrf = GO_GAIT_NGRF - GO_GAIT_GRM_OFFSET;
    EXPECT_EQ_INT(GO_GAIT_GRM_OFFSET, L0->ngrf);
    EXPECT_EQ_INT(GO_GAIT_NGRF, L->ngrf);
    EXPECT_EQ_INT(-1, L0->r_fib);
    EXPECT_EQ_INT(L0->n_path + dgrf, L->r_fib);
    EXPECT_EQ_INT(-1, L0->r_walk);
    EXPECT_EQ_INT(L0->n_path + dgrf + L->na, L->r_walk);  // the walk row last
    EXPECT_EQ_INT(L0->n_path + dgrf + L->na + 1, L->n_path);
    EXPECT_EQ_INT(n0 + 4 * dgrf, n);
    EXPECT_EQ_INT(m0 + 4 * (L->na + dgrf + 1), mm);
    int* ir0 = malloc(sizeof(int) * (size_t)ne);
    int* jc0 = malloc(sizeof(int) * (size_t)ne);
    go_nlp_jac_structure(a, ir0, jc0);
    for (int e = 0; e < ne; e++) {
      int row = ir0[e] - go_nlp_row_path(a, 0, 0);
      if (row >= 0 && row < 4 * L->n_path && row % L->n_path >= L->r_grf + GO_GAIT_GRM_OFFSET &&
          row % L->n_path < L->r_grf + L->ngrf)
        grm_nnz++;  // same pattern as the force rows: q, qdot on the path to the foot, own var
      if (row >= 0 && row < 4 * L->n_path && row % L->n_path == L->r_walk) {
        int v = jc0[e] % L->nz;  // the two vertical forces of its own node only
        walk_nnz++;
        walk_bad += (v != L->u_grf + 2 && v != L->u_grf + 5) || jc0[e] / L->nz != row / L->n_path;
        continue;
      }
      if (row < 0 || row >= 4 * L->n_path || row % L->n_path < L->r_fib) continue;
      int i = row % L->n_path - L->r_fib, v = jc0[e] % L->nz;
      fib_nnz++;
      if (L->elastic_of[i] >= 0 && v == L->x_ft + L->elastic_of[i]) ft_cols++;
      else if (!(v >= L->x_q && v < L->x_q + L->nv)) bad_col++;
    }
    EXPECT_EQ_INT(0, bad_col);
    EXPECT_EQ_INT(4 * L->ne, ft_cols);
    EXPECT_EQ_INT(4 * 2, walk_nnz);
    EXPECT_EQ_INT(0, walk_bad);
    EXPECT_EQ_INT(ne0 + fib_nnz + grm_nnz + walk_nnz, ne);
    EXPECT_TRUE(grm_nnz > 0);
    printf("fibre rows: %d muscles (%d elastic), %d nonzeros per node\n", L->na, L->ne,
           fib_nnz / 4);
    free(ir0);
    free(jc0);
  }
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
    for (int c = 0; c < L->ngrf; c++)
      grfr = fmax(grfr, fabs(g[go_nlp_row_path(a, k, L->r_grf + c)]));
    for (int i = 0; i < L->na; i++) act = fmax(act, fabs(g[go_nlp_row_path(a, k, L->r_act + i)]));
  }
  EXPECT_NEAR(0, link, 1e-12);
  EXPECT_NEAR(0, grfr, 1e-12);
  EXPECT_NEAR(0, act, 1e-12);
  // the walk row is the summed vertical force of both feet, scaled by m g, bounded below by
  // MIN_VGRF (scaled: MIN_VGRF) and not above
  {
    double worst_walk = 0, bw = go_gait_weight(g1);
    double* gl = malloc(sizeof(double) * (size_t)mm);
    double* gu = malloc(sizeof(double) * (size_t)mm);
    go_nlp_bounds(a, NULL, NULL, gl, gu);
    for (int k = 0; k < 4; k++) {
      const double* zk = z + (size_t)k * L->nz;
      int r = go_nlp_row_path(a, k, L->r_walk);
      worst_walk = fmax(worst_walk, fabs(g[r] - (zk[L->u_grf + 2] + zk[L->u_grf + 5]) / bw));
      EXPECT_NEAR(MIN_VGRF, gl[r], 1e-15);
      EXPECT_TRUE(gu[r] >= 1e19);
    }
    EXPECT_NEAR(0, worst_walk, 1e-15);
    free(gl), free(gu);
  }
  // the moment reference about the world origin gives back the measured centre of pressure on
  // the floor (z = 0): x = -M_y / F_z, y = M_x / F_z (world; OpenSim px and -pz) where loaded
  {
    int px = gs_table_column(&grf, "ground_force_r_px"), pz = gs_table_column(&grf, "ground_force_r_pz");
    double T = coords.time[coords.nrow - 1] - coords.time[0], worst = 0;
    int loaded = 0;
    for (int k = 0; k < 4; k++) {
      double fz = go_gait_grf_ref(g1, k, 2), mx = go_gait_grf_ref(g1, k, GO_GAIT_GRM_OFFSET);
      double my = go_gait_grf_ref(g1, k, GO_GAIT_GRM_OFFSET + 1);
      if (!(fz > 100)) continue;
      double t = coords.time[0] + T * k / 3.0;
      worst = fmax(worst, fabs(-my / fz - gs_table_value_at(&grf, px, t)));
      worst = fmax(worst, fabs(mx / fz + gs_table_value_at(&grf, pz, t)));
      loaded++;
    }
    EXPECT_TRUE(px >= 0 && pz >= 0 && loaded >= 1);
    EXPECT_NEAR(0, worst, 1e-9);  // m
  }
  // fibre rows (scale 1) are the muscle model's own lM / lopt: elastic tendons from the fT state
  // through the forward model's fibre kinematics, rigid ones from lts
  {
    const mjModel* gm = go_gait_model(g1);
    mjData* d = mj_makeData(gm);
    double worst_fib = 0, lo = 1e9, hi = -1e9;
    int outside = 0;
    for (int k = 0; k < 4; k++) {
      go_gait_load_node(g1, d, z + (size_t)k * L->nz);
      for (int i = 0; i < L->na; i++) {
        gsMuscleOut out;
        gs_physics_muscle_tension(gm, d, i, &out);
        double row = g[go_nlp_row_path(a, k, L->r_fib + i)];
        worst_fib = fmax(worst_fib, fabs(row - out.lM_norm));
        lo = fmin(lo, row), hi = fmax(hi, row);
        outside += row < 0.25 || row > 1.5;
      }
    }
    printf("fibre rows at the trial guess: lM/lopt in [%.3f, %.3f], %d of %d outside [0.25, 1.5], "
           "largest difference from gs_physics_muscle_tension %.1e\n", lo, hi, outside,
           4 * L->na, worst_fib);
    EXPECT_NEAR(0, worst_fib, 1e-12);
    mj_deleteData(d);
  }

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
  long reused0 = go_gait_position_reuses(g1);
  t0 = now();
  EXPECT_EQ_INT(0, go_nlp_eval_jac(a, zs, J));
  double t_j = now() - t0;
  go_eval_counts cnt;
  go_nlp_counts(a, &cnt);
  EXPECT_EQ_INT(2L * 2 * L->nv * 4, cnt.path_evals_last_jac);
  // the position stage reused: per node, the analytic columns and the 2 nv evaluations of the q
  // colour groups compute it, the first qdot group's + evaluation computes it again at the
  // node's own q, and its - evaluation and the other nv - 1 qdot groups' 2 (nv - 1) reuse it
  long reused_jac = go_gait_position_reuses(g1) - reused0;
  EXPECT_EQ_INT(4L * (2 * L->nv - 1), reused_jac);
  // ... and gives the path rows bitwise: node 1's rows with node 0 at node 1's coordinates (node
  // 1 reuses node 0's stage) equal those with node 0 elsewhere (node 1 computes its own)
  {
    double* zA = malloc(sizeof(double) * (size_t)n);
    double* zsA = malloc(sizeof(double) * (size_t)n);
    double* gA = malloc(sizeof(double) * (size_t)mm);
    double* gB = malloc(sizeof(double) * (size_t)mm);
    memcpy(zA, z, sizeof(double) * (size_t)n);
    memcpy(zA + L->x_q, z + L->nz + L->x_q, sizeof(double) * (size_t)L->nv);
    go_nlp_scale_z(a, zA, zsA);
    long r0 = go_gait_position_reuses(g1);
    EXPECT_EQ_INT(0, go_nlp_eval_g(a, zsA, gA));
    long hitA = go_gait_position_reuses(g1) - r0;
    zA[L->x_q + 2] += 1e-3;  // node 0 a millimetre higher
    go_nlp_scale_z(a, zA, zsA);
    r0 = go_gait_position_reuses(g1);
    EXPECT_EQ_INT(0, go_nlp_eval_g(a, zsA, gB));
    long hitB = go_gait_position_reuses(g1) - r0;
    EXPECT_TRUE(hitA >= 1);
    EXPECT_EQ_INT(0, hitB);
    int r1 = go_nlp_row_path(a, 1, 0);
    EXPECT_EQ_INT(0, memcmp(gA + r1, gB + r1, sizeof(double) * (size_t)L->n_path));
    printf("position stage reused by %ld of %ld Jacobian path evaluations; node 1's rows "
           "bitwise equal with and without reuse: %s\n", reused_jac, cnt.path_evals_last_jac,
           memcmp(gA + r1, gB + r1, sizeof(double) * (size_t)L->n_path) == 0 ? "yes" : "no");
    free(zA), free(zsA), free(gA), free(gB);
  }
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
  double worst = 0, worst_fib = 0;
  int n_fib = 0;
  for (int e = 0; e < ne; e++) {
    double ex = D[(size_t)ir[e] * n + jc[e]];
    inpat[(size_t)ir[e] * n + jc[e]] = 1;
    double rel = fabs(ex) > 1e-6 ? fabs(J[e] - ex) / fabs(ex) : fabs(J[e] - ex);
    double tol = fabs(ex) > 1e-6 ? 1e-4 : 1e-7;
    if (fabs(ex) > 1e-6 && rel > worst) worst = rel;
    int prow = ir[e] - go_nlp_row_path(a, 0, 0);
    if (prow >= 0 && prow < 4 * L->n_path && prow % L->n_path >= L->r_fib &&
        prow % L->n_path < L->r_fib + L->na) {
      n_fib++;
      if (fabs(ex) > 1e-6 && rel > worst_fib) worst_fib = rel;
    }
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
         "pattern %.1e; fibre rows: %d entries, worst relative error %.2e\n", ne, worst, worst_out,
         n_fib, worst_fib);

  // forward differences (GO_JAC_SPARSE_FORWARD, a prediction's main solve): per node one
  // evaluation at the base point and one per colour group, 2 nv + 1 instead of 4 nv. The base
  // point and the nv qdot groups, evaluated first, run at the node's own coordinates, where the
  // analytic columns left the position stage: nv + 1 reuses per node. Accuracy against the same
  // dense central differences: 3e-4 relative (its truncation error, h |g''| / 2: up to 1.4e-4 seen,
  // in a pelvis coordinate's column) plus 1e-6 absolute, its rounding noise (eps |g| / sqrt(eps) =
  // 1.5e-8 |g|; 3e-7 seen)
  {
    double* Jf = malloc(sizeof(double) * (size_t)ne);
    go_nlp_set_jac_mode(a, GO_JAC_SPARSE_FORWARD);
    go_nlp_reset_counts(a);
    long r0 = go_gait_position_reuses(g1);
    EXPECT_EQ_INT(0, go_nlp_eval_jac(a, zs, Jf));
    go_eval_counts cf;
    go_nlp_counts(a, &cf);
    EXPECT_EQ_INT(4L * (2 * L->nv + 1), cf.path_evals_last_jac);
    EXPECT_EQ_INT(4L * (L->nv + 1), go_gait_position_reuses(g1) - r0);
    go_nlp_set_jac_mode(a, GO_JAC_SPARSE);
    int bad_fwd = 0;
    double worst_fwd = 0, worst_fwd_abs = 0;
    for (int e = 0; e < ne; e++) {
      double ex = D[(size_t)ir[e] * n + jc[e]];
      double dev = fabs(Jf[e] - ex);
      if (fabs(ex) > 1e-2) worst_fwd = fmax(worst_fwd, dev / fabs(ex));
      worst_fwd_abs = fmax(worst_fwd_abs, dev);
      if (dev > 3e-4 * fabs(ex) + 1e-6 && bad_fwd++ < 8)
        fprintf(stderr, "forward jac entry %d (row %d, col %d = var %d): expected %.10g actual "
                "%.10g\n", e, ir[e], jc[e], jc[e] % L->nz, ex, Jf[e]);
    }
    EXPECT_EQ_INT(0, bad_fwd);
    printf("forward-difference Jacobian: %ld path evaluations (central %ld), worst relative error "
           "of entries > 1e-2 %.2e, worst absolute error %.1e\n", cf.path_evals_last_jac,
           cnt.path_evals_last_jac, worst_fwd, worst_fwd_abs);
    free(Jf);
  }
  int bad_grad = 0;
  for (int v = 0; v < n; v++) {
    double ex = Dg[v];
    // tolerance: 1e-4 relative plus the central difference's rounding noise on f
    double tol = 1e-4 * fabs(ex) + 100 * 2.2e-16 * fmax(1.0, fabs(f)) / 6.0554544523933395e-06;
    if (fabs(grad[v] - ex) > tol && bad_grad++ < 5)
      fprintf(stderr, "grad %d: expected %.10g actual %.10g\n", v, ex, grad[v]);
  }
  EXPECT_EQ_INT(0, bad_grad);

  // Gauss-Newton Hessian: without cost of transport the integrand is a sum of squares of single
  // variables (tracking, effort, acceleration), so the diagonal is exact: against central
  // differences of the analytic gradient, step 1e-4 (scaled), relative 1e-4 with floor 1e-6 (the
  // collocation test's rule); the qddot entries carry the acceleration goal and are nonzero.
  {
    double* H = malloc(sizeof(double) * (size_t)n);
    double* gp = malloc(sizeof(double) * (size_t)n);
    double* gm = malloc(sizeof(double) * (size_t)n);
    EXPECT_EQ_INT(1, go_nlp_has_hess_diag(a));
    EXPECT_EQ_INT(0, go_nlp_eval_hess_diag(a, zs, 0.5, H));
    int bad_h = 0;
    double worst_h = 0, accel_h = 0;
    for (int v = 0; v < n; v++) {
      double x0 = zs[v], hstep = 1e-4;
      zs[v] = x0 + hstep;
      go_nlp_eval_grad_f(a, zs, gp);
      zs[v] = x0 - hstep;
      go_nlp_eval_grad_f(a, zs, gm);
      zs[v] = x0;
      double ex = 0.5 * (gp[v] - gm[v]) / (2 * hstep);
      double rel = fabs(H[v] - ex) / fmax(fabs(ex), 1e-6);
      if (fabs(ex) > 1e-6) worst_h = fmax(worst_h, rel);
      int var = v % L->nz;
      if (var >= L->xd_qdd && var < L->xd_qdd + L->nv) accel_h = fmax(accel_h, H[v]);
      if (rel > 1e-4 && bad_h++ < 5)
        fprintf(stderr, "hess diag %d (var %d): expected %.10g actual %.10g\n", v, var, ex, H[v]);
    }
    EXPECT_EQ_INT(0, bad_h);
    EXPECT_TRUE(accel_h > 1e-6);
    printf("gauss-newton diagonal: worst relative error %.2e; largest qddot entry %.3g\n", worst_h,
           accel_h);
    free(H);
    free(gp);
    free(gm);
  }

  // the goals sum to J; the acceleration goal is its definition: the trapezoid over T of
  // W_ACCEL mean_j (qddot_j / 50)^2
  {
    double terms[GO_GAIT_NTERMS], sum = 0, acc = 0, T = go_gait_time_of(g1, z), h = T / 3, fq;
    double* zq = malloc(sizeof(double) * (size_t)n);  // q off the measured ones: tracking > 0
    memcpy(zq, z, sizeof(double) * (size_t)n);
    for (int k = 0; k < 4; k++)
      for (int j = 0; j < L->nv; j++) zq[(size_t)k * L->nz + L->x_q + j] += 0.01 * (j % 3 - 1);
    go_nlp_scale_z(a, zq, zs);
    EXPECT_EQ_INT(0, go_nlp_eval_f(a, zs, &fq));
    go_nlp_scale_z(a, z, zs);
    EXPECT_EQ_INT(0, go_gait_objective_terms(g1, zq, terms));
    free(zq);
    for (int t = 0; t < GO_GAIT_NTERMS; t++) sum += terms[t];
    for (int k = 0; k < 4; k++) {
      double s2 = 0;
      for (int j = 0; j < L->nv; j++) s2 += pow(z[(size_t)k * L->nz + L->xd_qdd + j] / 50.0, 2);
      acc += (k == 0 || k == 3 ? 0.5 : 1.0) * h * W_ACCEL * s2 / L->nv / T;
    }
    double Jphys = go_nlp_objective_phys(a, fq);
    static const char* names[GO_GAIT_NTERMS] = GO_GAIT_TERM_NAMES;
    printf("objective %.6g =", Jphys);
    for (int t = 0; t < GO_GAIT_NTERMS; t++) printf(" %s %.4g", names[t], terms[t]);
    printf("\n");
    EXPECT_REL(Jphys, sum, 1e-12, 1e-14);
    EXPECT_REL(acc, terms[GO_GAIT_TERM_ACCEL], 1e-12, 1e-14);
    EXPECT_TRUE(terms[GO_GAIT_TERM_PELVIS] > 0 && terms[GO_GAIT_TERM_JOINTS] > 0 &&
                terms[GO_GAIT_TERM_GRF] > 0 && terms[GO_GAIT_TERM_EFFORT] > 0 &&
                terms[GO_GAIT_TERM_ACCEL] > 0);
    EXPECT_NEAR(0, terms[GO_GAIT_TERM_COT], 0);
    // with a cost-of-transport goal (its integrand w_cot Edot / (m V)) the goals still sum to J
    go_gait_opts o;
    go_gait_opts_default(&o);
    o.N = 4;
    o.coords = &coords;
    o.speed = 1.27;
    o.w_cot = 1.0;
    o.w_accel = W_ACCEL;
    go_gait* gc = NULL;
    EXPECT_EQ_INT(0, go_gait_create(&gc, m, &o, err, sizeof(err)));
    if (gc) {
      double fc, tc[GO_GAIT_NTERMS], sc = 0;
      go_nlp_scale_z(go_gait_nlp(gc), z, zs);
      EXPECT_EQ_INT(0, go_nlp_eval_f(go_gait_nlp(gc), zs, &fc));
      EXPECT_EQ_INT(0, go_gait_objective_terms(gc, z, tc));
      for (int t = 0; t < GO_GAIT_NTERMS; t++) sc += tc[t];
      EXPECT_REL(go_nlp_objective_phys(go_gait_nlp(gc), fc), sc, 1e-12, 1e-14);
      EXPECT_TRUE(tc[GO_GAIT_TERM_COT] > 0 && tc[GO_GAIT_TERM_GRF] == 0);
      // the metabolic gradient (chain rule through the actuator lengths and velocities and the
      // moment arms' derivative along qdot, optim/go_gait.c metabolic) against differences of f
      // over every variable: 1e-3 relative plus f's rounding over the step (the gradient's own
      // central differences in l, v, a, e, fT are 1e-6 wide, the reference's about 6e-6; at the
      // knee's flexion the two differ by 3e-4, a missing chain-rule term by O(1))
      go_nlp* nc = go_gait_nlp(gc);
      int nn, mc, ec;
      go_nlp_sizes(nc, &nn, &mc, &ec);
      double* gc_grad = malloc(sizeof(double) * (size_t)nn);
      EXPECT_EQ_INT(0, go_nlp_eval_grad_f(nc, zs, gc_grad));
      const go_gait_layout* Lc = go_gait_layout_get(gc);
      int bad_cot = 0, n_q = 0;
      double worst_cot = 0;
      for (int v = 0; v < nn; v++) {
        // Richardson's extrapolation of central differences at steps hv and hv / 2 (error
        // O(hv^4): the knee's translations curve P within the plain difference's step)
        double x0 = zs[v], hv = 6.0554544523933395e-06 * fmax(1.0, fabs(x0)), dv[2];
        for (int s2 = 0; s2 < 2; s2++) {
          double fp, fm, hs = s2 ? hv / 2 : hv;
          zs[v] = x0 + hs;
          double xp = zs[v];
          go_nlp_eval_f(nc, zs, &fp);
          zs[v] = x0 - hs;
          double xm = zs[v];
          go_nlp_eval_f(nc, zs, &fm);
          zs[v] = x0;
          dv[s2] = (fp - fm) / (xp - xm);
        }
        double ex = (4 * dv[1] - dv[0]) / 3;
        double noise = 100 * 2.2e-16 * fmax(1.0, fabs(fc)) / hv, tol = 1e-3 * fabs(ex) + noise;
        if (fabs(ex) > 1e3 * noise) worst_cot = fmax(worst_cot, fabs(gc_grad[v] - ex) / fabs(ex));
        int j = v % Lc->nz;
        if (v < 4 * Lc->nz && j >= Lc->x_q && j < Lc->x_q + 2 * Lc->nv && fabs(ex) > 1e-3) n_q++;
        if (fabs(gc_grad[v] - ex) > tol && bad_cot++ < 5)
          fprintf(stderr, "cot grad %d (node %d var %d): expected %.10g actual %.10g\n", v,
                  v / Lc->nz, j, ex, gc_grad[v]);
      }
      printf("cost-of-transport gradient: worst relative error %.2e (entries above 1e3 times "
             "the rounding noise); %d entries above 1e-3 in q, qdot\n", worst_cot, n_q);
      EXPECT_EQ_INT(0, bad_cot);
      EXPECT_TRUE(n_q > 20);
      free(gc_grad);
      go_nlp_scale_z(a, z, zs);
      go_gait_free(gc);
    }
  }

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

  // eq. 3's band within the joint ranges: a 0.05 rad band around the guess, intersected with each
  // limited joint's range; a centre moved 1 rad past its joint's upper limit gets the range alone
  {
    const mjModel* gm = go_gait_model(g1);
    int jq = -1;  // the first limited dof whose guess lies inside its range
    for (int j = 0; j < L->nv && jq < 0; j++) {
      int jnt = gm->dof_jntid[j];
      double v = z[L->x_q + j];
      if (gm->jnt_limited[jnt] && v > gm->jnt_range[2 * jnt] && v < gm->jnt_range[2 * jnt + 1])
        jq = j;
    }
    EXPECT_TRUE(jq >= 0);
    double* zc = malloc(sizeof(double) * (size_t)n);
    double* half = malloc(sizeof(double) * (size_t)L->nv);
    double* zl = malloc(sizeof(double) * (size_t)n);
    double* zu = malloc(sizeof(double) * (size_t)n);
    double* zlp = malloc(sizeof(double) * (size_t)n);
    double* zup = malloc(sizeof(double) * (size_t)n);
    memcpy(zc, z, sizeof(double) * (size_t)n);
    int jnt_q = jq >= 0 ? gm->dof_jntid[jq] : 0;
    if (jq >= 0) zc[(size_t)2 * L->nz + L->x_q + jq] = gm->jnt_range[2 * jnt_q + 1] + 1.0;
    for (int j = 0; j < L->nv; j++) half[j] = 0.05;
    go_gait_opts o = opts_of(&coords, &grf, 1, 1);  // g1's problem (and layout), with the band
    o.band_z = zc;
    o.band_q = half;
    go_gait* gb = NULL;
    EXPECT_EQ_INT(0, go_gait_create(&gb, m, &o, err, sizeof(err)));
    if (gb && jq >= 0) {
      go_nlp_bounds(go_gait_nlp(gb), zl, zu, NULL, NULL);
      go_nlp_unscale_z(go_gait_nlp(gb), zl, zlp);
      go_nlp_unscale_z(go_gait_nlp(gb), zu, zup);
      int outside = 0, wrong = 0;
      for (int k = 0; k < 4; k++)
        for (int j = 0; j < L->nv; j++) {
          if (j == L->tx) continue;
          size_t v = (size_t)k * L->nz + L->x_q + j;
          int jnt = gm->dof_jntid[j];
          double lo = zc[v] - 0.05, hi = zc[v] + 0.05;
          if (gm->jnt_limited[jnt]) {
            outside += zlp[v] < gm->jnt_range[2 * jnt] - 1e-12 ||
                       zup[v] > gm->jnt_range[2 * jnt + 1] + 1e-12;
            lo = fmax(lo, gm->jnt_range[2 * jnt]);
            hi = fmin(hi, gm->jnt_range[2 * jnt + 1]);
            if (lo > hi) lo = gm->jnt_range[2 * jnt], hi = gm->jnt_range[2 * jnt + 1];
          }
          wrong += fabs(zlp[v] - lo) > 1e-9 * fmax(1, fabs(lo)) ||
                   fabs(zup[v] - hi) > 1e-9 * fmax(1, fabs(hi));
        }
      EXPECT_EQ_INT(0, outside);
      EXPECT_EQ_INT(0, wrong);
      size_t v2 = (size_t)2 * L->nz + L->x_q + jq;  // the moved centre: the whole range
      EXPECT_NEAR(gm->jnt_range[2 * jnt_q], zlp[v2], 1e-9);
      EXPECT_NEAR(gm->jnt_range[2 * jnt_q + 1], zup[v2], 1e-9);
      printf("band within ranges: dof %d at node 2 gets its range [%g, %g] rad\n", jq, zlp[v2],
             zup[v2]);
    }
    go_gait_free(gb);
    free(zc), free(half), free(zl), free(zu), free(zlp), free(zup);
  }

  // the partitioned quasi-Newton Hessian accepts the elements (fibre rows: rigid muscles in the
  // dynamics element, elastic ones in their tendon element, every fibre row in exactly one)
  {
    const go_elements* el = go_gait_elements(g1);
    int fib_rows = 0;
    for (int q = 0; q < el->row_ptr[el->n_elem]; q++) fib_rows += el->rows[q] >= L->r_fib;
    EXPECT_EQ_INT(L->na, fib_rows);
    go_hess* hs = NULL;
    EXPECT_EQ_INT(0, go_hess_create(&hs, a, el, err, sizeof(err)));
    go_hess_free(hs);
  }

  go_gait_free(g0);
  go_gait_free(g1);
  go_gait_free(g2);
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  free(z), free(zs), free(g), free(ir), free(jc), free(J), free(grad), free(D), free(Dg);
  free(inpat), free(J2), free(gv2), free(grad2);
  return GS_TEST_RESULT();
}
