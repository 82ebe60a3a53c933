// test_static_guess.c: the static-optimisation initial guess (optim/go_gait_guess.h,
// go_gait_guess_static; Anderson & Pandy 2001, Crowninshield & Brand 1981).
//   1. The bounded least-squares solver (go_static_opt_solve) against hand-computed optima of
//      one dof with one or two muscles: interior, upper-bound and lower-bound cases.
//   2. The inverse dynamics with replaced foot contact (go_gait_inverse_dynamics): given the
//      model's own foot wrenches (resultant force and moment about the origin, gs_physics_foot_grf)
//      it reproduces mj_inverse's qfrc_inverse with the sphere contact, on every dof.
//   3. The guess on jw_fullbody and the bundled trial, N = 10: 15 matched dofs, no QP at its step
//      limit, activations = excitations within [0.001, 1], adot = 0, tendon forces in [0, 5];
//      the muscles' generalized forces (gs_physics_muscle_tension at the guess's state: Fmax fT
//      elastic, the rigid force rigid) minus the inverse-dynamics ones over the matched dofs:
//      rms equal to the guess's own report (5 %), below half the trial guess's (measured 8.3 vs
//      22 N m), and at every one of the 10 nodes a sum of squares below half the trial guess's
//      at that node (measured ratios 0.42 at node 0, the worst, down to 1e-5 at node 6; JW's
//      model is too weak in left hip flexion at push-off, so 5-15 muscles sit at a = 1 at the
//      ends of the stride); the largest scaled row of the equations of motion in the NLP below
//      half the trial guess's (measured 0.63 vs 1.74; the NLP's whole violation, 3.89 for both,
//      is a defect row no guess from the trial changes, so it cannot tell them apart).
//   4. jw_fullbody_knee6: 15 matched dofs too (the implant knee's five secondary dofs are held by
//      the contact surrogate and ligaments; matching them by muscles left a residual of 1.1e4 N m).
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "app/gs_app_model.h"
#include "callbacks/gs_physics.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "tests/gs_test.h"
#include "tests/gs_test_trial.h"

#define STATIC_TOL_NM 0.5  // N m (N on slides): linearisation of the elastic muscles, converged

static void solver_cases(void) {
  double a[2];
  // one muscle, interior: a = w b c / (1 + w b^2) = 100 * 50 * 0.2 / (1 + 100 * 2500)
  {
    double B[1] = {50}, c[1] = {20};
    EXPECT_TRUE(go_static_opt_solve(1, 1, B, c, 100, 0.001, 1, a) >= 0);
    EXPECT_NEAR(100.0 * 50 * 20 / (1 + 100.0 * 2500), a[0], 1e-12);  // 0.3999984
  }
  // two muscles, interior: minimum-norm ridge a = w c b / (1 + w |b|^2)
  {
    double B[2] = {2, 1}, c[1] = {0.5};
    EXPECT_TRUE(go_static_opt_solve(2, 1, B, c, 100, 0.001, 1, a) >= 0);
    EXPECT_NEAR(100 * 0.5 * 2 / 501.0, a[0], 1e-12);  // 0.1996008
    EXPECT_NEAR(100 * 0.5 * 1 / 501.0, a[1], 1e-12);  // 0.0998004
  }
  // two muscles, the strong one saturates: a1 = 1, a2 = w b2 (c - b1) / (1 + w b2^2)
  {
    double B[2] = {2, 1}, c[1] = {3};
    EXPECT_TRUE(go_static_opt_solve(2, 1, B, c, 100, 0.001, 1, a) >= 0);
    EXPECT_NEAR(1.0, a[0], 1e-15);
    EXPECT_NEAR(100.0 / 101.0, a[1], 1e-12);  // 0.990099
  }
  // antagonist at its lower bound: a1 = 0.001, a2 = w b2 (c - b1 0.001) / (1 + w b2^2)
  {
    double B[2] = {1, -1}, c[1] = {-0.5};
    EXPECT_TRUE(go_static_opt_solve(2, 1, B, c, 100, 0.001, 1, a) >= 0);
    EXPECT_NEAR(0.001, a[0], 1e-15);
    EXPECT_NEAR(100 * -1 * (-0.5 - 0.001) / 101.0, a[1], 1e-12);  // 0.4960396
  }
  // no reachable target (c of the wrong sign for both): both at the lower bound
  {
    double B[2] = {1, 2}, c[1] = {-10};
    EXPECT_TRUE(go_static_opt_solve(2, 1, B, c, 100, 0.001, 1, a) >= 0);
    EXPECT_NEAR(0.001, a[0], 1e-15);
    EXPECT_NEAR(0.001, a[1], 1e-15);
  }
}

// largest |row| of the equations of motion (the path rows the guess sets out to satisfy: muscle
// generalized forces against inverse dynamics; scaled) over all nodes
static double eom_violation(go_gait* g, const double* z) {
  go_nlp* nlp = go_gait_nlp(g);
  const go_gait_layout* L = go_gait_layout_get(g);
  int n, mm, ne;
  go_nlp_sizes(nlp, &n, &mm, &ne);
  double* zs = (double*)malloc(sizeof(double) * (size_t)n);
  double* gv = (double*)malloc(sizeof(double) * (size_t)mm);
  go_nlp_scale_z(nlp, z, zs);
  double v = INFINITY;
  if (go_nlp_eval_g(nlp, zs, gv) == 0) {
    v = 0;
    for (int k = 0; k < go_gait_nodes(g); k++)
      for (int r = L->r_eom; r < L->r_hill; r++) v = fmax(v, fabs(gv[go_nlp_row_path(nlp, k, r)]));
  }
  free(zs), free(gv);
  return v;
}

int main(void) {
  solver_cases();
  gsTable coords, grf;
  mjModel* m = gs_test_load_trial(&coords, &grf);
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  const int N = 10;
  go_gait_opts opts = gs_test_tracking_opts(&coords, &grf, N);
  go_gait* g = gs_test_gait_create(m, &opts);
  EXPECT_TRUE(g != NULL);
  if (!g) return GS_TEST_RESULT();
  const go_gait_layout* L = go_gait_layout_get(g);
  const mjModel* gm = go_gait_model(g);
  int nv = L->nv, na = L->na, nz = L->nz;
  double* z = (double*)calloc((size_t)N * nz, sizeof(double));
  double* zt = (double*)calloc((size_t)N * nz, sizeof(double));
  double* tau = (double*)calloc((size_t)nv, sizeof(double));
  double* ref = (double*)calloc((size_t)nv, sizeof(double));
  mjData* d = mj_makeData(gm);
  char err[512];

  // 2. inverse dynamics with the model's own foot wrenches = mj_inverse with the spheres
  EXPECT_EQ_INT(0, go_gait_guess_from_trial(g, &coords, 0.05, zt, err, sizeof(err)));
  for (int k = 0; k < N; k += 3) {
    const double* zk = zt + (size_t)k * nz;
    go_gait_load_node(g, d, zk);
    mju_copy(ref, d->qfrc_inverse, nv);
    go_foot_wrench w[2];
    for (int s = 0; s < 2; s++) {
      gsFootGrf fg;
      gs_physics_foot_grf(gm, d, s == 0 ? 'r' : 'l', 5.0, &fg);
      for (int c = 0; c < 3; c++) {
        w[s].force[c] = fg.force[c];
        w[s].point[c] = 0;  // fg.moment is about the plane point, the origin
        w[s].torque[c] = fg.moment[c];
      }
    }
    EXPECT_EQ_INT(0, go_gait_inverse_dynamics(g, d, zk, w, tau));
    double worst = 0;
    for (int j = 0; j < nv; j++) worst = fmax(worst, fabs(tau[j] - ref[j]) / (1 + fabs(ref[j])));
    EXPECT_NEAR(0, worst, 1e-9);
  }

  // 3. the static guess
  go_static_report rep;
  EXPECT_EQ_INT(0, go_gait_guess_static(g, &coords, &grf, z, &rep, err, sizeof(err)));
  printf("static guess: %d matched dofs, residual rms %.3g max %.3g, mean a %.3f, %d at a = 1, "
         "%d steps, %d failed\n", rep.n_matched, rep.rms_residual, rep.max_residual,
         rep.mean_activation, rep.n_at_upper, rep.steps, rep.failed_nodes);
  EXPECT_EQ_INT(15, rep.n_matched);  // 26 dofs - 6 pelvis - 5 spring-held right-knee dofs
  EXPECT_EQ_INT(0, rep.failed_nodes);
  int bad_bounds = 0, bad_ft = 0;
  for (int k = 0; k < N; k++) {
    const double* zk = z + (size_t)k * nz;
    for (int i = 0; i < na; i++) {
      double a = zk[L->x_a + i];
      if (!(a >= 0.001 && a <= 1) || zk[L->u_e + i] != a || zk[L->xd_a + i] != 0) bad_bounds++;
    }
    for (int e = 0; e < L->ne; e++) {
      if (!(zk[L->x_ft + e] >= 0 && zk[L->x_ft + e] <= 5)) bad_ft++;
    }
  }
  EXPECT_EQ_INT(0, bad_bounds);
  EXPECT_EQ_INT(0, bad_ft);
  go_foot_wrench* w = (go_foot_wrench*)calloc((size_t)N * 2, sizeof(go_foot_wrench));
  EXPECT_EQ_INT(0, go_gait_measured_wrenches(g, &grf, w, err, sizeof(err)));
  int matched_nodes = 0, n_res = 0, better_nodes = 0;
  double sum_s = 0, sum_t = 0;  // squared residuals, static and trial guesses ((N m)^2)
  for (int k = 0; k < N; k++) {
    double node_s = 0, node_t = 0;  // this node's squared residuals
    const double* zk = z + (size_t)k * nz;
    int sat = 0;
    for (int i = 0; i < na; i++) sat += zk[L->x_a + i] >= 1;
    EXPECT_EQ_INT(0, go_gait_inverse_dynamics(g, d, zk, w + 2 * k, tau));
    // muscle generalized forces at the guess's state, from the physics
    mju_zero(ref, nv);
    for (int i = 0; i < na; i++) {
      double F = gs_physics_muscle_tension(gm, d, i, NULL);
      for (int j = 0; j < nv; j++) ref[j] -= d->actuator_moment[i * nv + j] * F;
    }
    double worst = 0;
    for (int j = 0; j < nv; j++) {
      if (!go_static_dof_matched(gm, j)) continue;
      worst = fmax(worst, fabs(ref[j] - tau[j]));
      node_s += (ref[j] - tau[j]) * (ref[j] - tau[j]);
      n_res++;
    }
    // the same for the trial guess (a = 0.05, tendons in static equilibrium)
    const double* ztk = zt + (size_t)k * nz;
    EXPECT_EQ_INT(0, go_gait_inverse_dynamics(g, d, ztk, w + 2 * k, tau));
    for (int j = 0; j < nv; j++) ref[j] = 0;
    for (int i = 0; i < na; i++) {
      double F = gs_physics_muscle_tension(gm, d, i, NULL);
      for (int j = 0; j < nv; j++) ref[j] -= d->actuator_moment[i * nv + j] * F;
    }
    for (int j = 0; j < nv; j++) {
      if (go_static_dof_matched(gm, j)) node_t += (ref[j] - tau[j]) * (ref[j] - tau[j]);
    }
    printf("node %d: %d muscles at a = 1, max |muscle - inverse dynamics| %.3g N m (N); sum of "
           "squares %.4g (static) vs %.4g (trial)\n", k, sat, worst, node_s, node_t);
    if (worst < STATIC_TOL_NM) matched_nodes++;
    better_nodes += node_s < 0.5 * node_t;
    sum_s += node_s;
    sum_t += node_t;
  }
  double rms_s = sqrt(sum_s / n_res), rms_t = sqrt(sum_t / n_res);
  printf("muscle - inverse dynamics, matched dofs: rms %.3g (static), %.3g (trial) N m; %d nodes "
         "within %.2g N m\n", rms_s, rms_t, matched_nodes, STATIC_TOL_NM);
  EXPECT_NEAR(rep.rms_residual, rms_s, 0.05 * rep.rms_residual);  // the report's own figure
  printf("nodes where the static guess halves the trial guess's squared residual: %d of %d\n",
         better_nodes, N);
  EXPECT_EQ_INT(N, better_nodes);
  EXPECT_TRUE(matched_nodes >= 1);
  EXPECT_TRUE(rms_s < 0.5 * rms_t);
  // the equations of motion, as the NLP scales them (the whole-NLP violation is a defect row,
  // which no guess from the trial changes)
  double vs = eom_violation(g, z), vt = eom_violation(g, zt);
  printf("equations of motion, largest scaled row: static %.3g, trial %.3g\n", vs, vt);
  EXPECT_TRUE(vs < 0.5 * vt);

  // 4. the six-DOF implant knee: its five secondary dofs are held by the contact surrogate and
  // the ligaments (no joint spring), and are not matched either: 15 of 26 dofs
  mjModel* m6 = gs_app_load_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml");
  EXPECT_TRUE(m6 != NULL);
  if (m6) {
    int matched6 = 0;
    for (int j = 0; j < m6->nv; j++) matched6 += go_static_dof_matched(m6, j);
    EXPECT_EQ_INT(15, matched6);
    int flexion = m6->jnt_dofadr[mj_name2id(m6, mjOBJ_JOINT, "knee_flexion")];
    int tx = m6->jnt_dofadr[mj_name2id(m6, mjOBJ_JOINT, "knee_tx")];
    EXPECT_TRUE(go_static_dof_matched(m6, flexion));
    EXPECT_TRUE(!go_static_dof_matched(m6, tx));
    mj_deleteModel(m6);
  }

  free(w), free(z), free(zt), free(tau), free(ref);
  mj_deleteData(d);
  go_gait_free(g);
  gs_table_free(&coords);
  gs_table_free(&grf);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
