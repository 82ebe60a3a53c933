// test_knee_reaction.c: knee joint reaction (callbacks/gs_knee_reaction.h) on jw_fullbody:
// (a) standing still on the left foot with the left leg vertical and every muscle at zero force,
//     the reaction is the weight above the knee, (m_total - m_shank+foot) g, straight down;
// (b) one known muscle force added: the reaction moves by minus that force along the muscle's
//     crossing segment, from the site positions by hand; a muscle with both ends below the knee
//     changes nothing;
// (c) at nodes of the trial's initial guess: finite everywhere, compressive (0.5-8 BW) at the
//     node of largest left vertical GRF; F_int equals the subtree's momentum rate minus its weight
//     by central differences;
// (d) the right knee (tibial_tray, the placeholder's six dofs): the muscles' net force on the
//     subtree along knee_tx/ty/tz equals minus the actuator moments times the tensions (MuJoCo's
//     tendon Jacobian, wrapping included); at a trial node the reaction along knee_ty equals the
//     placeholder's spring-damper force plus the knee_ty equation-of-motion residual, so the two
//     agree wherever the dynamics hold; at a static pose standing on the right leg with knee_ty in
//     equilibrium they agree to 1e-6 BW.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "app/gs_app_model.h"
#include "callbacks/gs_knee_reaction.h"
#include "callbacks/gs_physics.h"
#include "optim/go_gait.h"
#include "optim/go_gait_guess.h"
#include "tests/gs_test.h"

#define TRIAL GAITSIM_SOURCE_DIR "/mjmodels/trials/jw_ngait_og5"
static const double kG = 9.80665;  // m/s^2, the model's gravity

static void set_joint(const mjModel* m, mjData* d, const char* name, double v) {
  int j = mj_name2id(m, mjOBJ_JOINT, name);
  if (j >= 0) d->qpos[m->jnt_qposadr[j]] = v;
}

// OpenSim's zero pose (every hinge 0, the knee slides at their rest), standing at pelvis height
// h, still; right leg lifted when lift_right, else the left one; muscle states zero
static void static_pose(const mjModel* m, mjData* d, double h, int lift_right) {
  mj_resetData(m, d);
  for (int j = 0; j < m->njnt; j++)
    if (m->jnt_type[j] == mjJNT_HINGE) d->qpos[m->jnt_qposadr[j]] = 0;
  set_joint(m, d, "pelvis_tx", 0);
  set_joint(m, d, "pelvis_tz", 0);
  set_joint(m, d, "pelvis_ty", h);
  set_joint(m, d, lift_right ? "hip_flexion" : "hip_flexion_l", 0.6);
  set_joint(m, d, lift_right ? "knee_flexion" : "knee_flexion_l", -1.2);
  mju_zero(d->qvel, m->nv);
  mju_zero(d->qacc, m->nv);
  mju_zero(d->act, m->na);
  mju_zero(d->ctrl, m->nu);
  mju_zero(d->userdata, m->nuserdata);
  mj_inverse(m, d);
}

// pelvis height at which the standing foot carries the whole weight W (bisection)
static double stand(const mjModel* m, mjData* d, int lift_right, double W) {
  double lo = 0.7, hi = 1.1;
  for (int it = 0; it < 80; it++) {
    double h = 0.5 * (lo + hi);
    static_pose(m, d, h, lift_right);
    gsFootGrf fg;
    gs_physics_foot_grf(m, d, lift_right ? 'l' : 'r', 5.0, &fg);
    if (fg.force[2] > W) lo = h;
    else hi = h;
  }
  static_pose(m, d, 0.5 * (lo + hi), lift_right);
  return 0.5 * (lo + hi);
}

// (a), (b): static, on the left foot
static void static_left(const mjModel* m, mjData* d, const gsKneeReactionSpec* sp) {
  double W = mj_getTotalmass(m) * kG;
  stand(m, d, 1, W);
  gsFootGrf fl, fr;
  gs_physics_foot_grf(m, d, 'l', 5.0, &fl);
  gs_physics_foot_grf(m, d, 'r', 5.0, &fr);
  EXPECT_NEAR(W, fl.force[2], 1e-6 * W);
  EXPECT_NEAR(0, fabs(fr.force[0]) + fabs(fr.force[1]) + fabs(fr.force[2]), 1e-3);
  // the mass below the knee, by name, and what it leaves above
  static const char* below[] = {"tibia_l", "talus_l", "calcaneus_l", "toes_l", "patella_l"};
  double ms = 0;
  for (int k = 0; k < 5; k++) ms += m->body_mass[mj_name2id(m, mjOBJ_BODY, below[k])];
  EXPECT_NEAR(ms, m->body_subtreemass[sp->body], 1e-12);
  double above = (mj_getTotalmass(m) - ms) * kG;

  double* zero = (double*)calloc((size_t)m->nu, sizeof(double));
  gsKneeReaction r0;
  EXPECT_EQ_INT(0, gs_knee_reaction(m, d, sp, zero, &r0));
  printf("(a) static on the left foot: weight %.3f N, above the knee %.3f N (m_S %.4f kg); "
         "F_J = (%.6f, %.6f, %.6f) N, axis z %.9f, compression %.6f N, %d crossing muscles\n",
         W, above, ms, r0.force[0], r0.force[1], r0.force[2], r0.axis[2], r0.compression,
         r0.ncross);
  EXPECT_NEAR(0, r0.force[0], 1e-6 * W);
  EXPECT_NEAR(0, r0.force[1], 1e-6 * W);
  EXPECT_NEAR(-above, r0.force[2], 1e-6 * W);
  EXPECT_NEAR(ms * kG, r0.inertial[2], 1e-9 * W);  // still: F_int = -m_S g
  EXPECT_TRUE(r0.axis[2] > 0.999);                 // the left leg is vertical
  EXPECT_NEAR(above, r0.compression, 1e-3 * above);
  EXPECT_NEAR(above * r0.axis[2], r0.compression, 1e-6 * W);
  // the axis (ankle -> knee centre) is tibia_l's y axis in this model
  const mjtNum* R = d->xmat + 9 * sp->body;
  for (int c = 0; c < 3; c++) EXPECT_NEAR(R[3 * c + 1], r0.axis[c], 1e-9);
  // semimem, semiten, bifemlh, bifemsh, sar, tfl, grac, rect_fem, vasti (3), gastrocnemii (2)
  EXPECT_EQ_INT(13, r0.ncross);

  // (b) one muscle at 800 N: vas_int_l crosses from vas_int_l-P2 (femur_l) to -P4 (tibia_l)
  struct { const char* muscle; const char* out; const char* in; } one[] = {
      {"vas_int_l", "vas_int_l-P2", "vas_int_l-P4"},
      {"med_gas_l", "med_gas_l-P2", "med_gas_l-P3"},
      {"soleus_l", NULL, NULL}};
  for (int q = 0; q < 3; q++) {
    int i = mj_name2id(m, mjOBJ_ACTUATOR, one[q].muscle);
    EXPECT_TRUE(i >= 0);
    if (i < 0) continue;
    double* T = (double*)calloc((size_t)m->nu, sizeof(double));
    T[i] = 800.0;
    double expect[3] = {r0.force[0], r0.force[1], r0.force[2]};
    if (one[q].out) {
      const mjtNum* po = d->site_xpos + 3 * mj_name2id(m, mjOBJ_SITE, one[q].out);
      const mjtNum* pi = d->site_xpos + 3 * mj_name2id(m, mjOBJ_SITE, one[q].in);
      double u[3] = {po[0] - pi[0], po[1] - pi[1], po[2] - pi[2]};
      double len = mju_norm3(u);
      for (int c = 0; c < 3; c++) expect[c] -= 800.0 * u[c] / len;
    }
    gsKneeReaction r1;
    EXPECT_EQ_INT(0, gs_knee_reaction(m, d, sp, T, &r1));
    for (int c = 0; c < 3; c++) EXPECT_NEAR(expect[c], r1.force[c], 1e-9 * W);
    double ce = -(expect[0] * r1.axis[0] + expect[1] * r1.axis[1] + expect[2] * r1.axis[2]);
    EXPECT_NEAR(ce, r1.compression, 1e-9 * W);
    printf("(b) %s at 800 N: compression %.4f N (by hand %.4f N), %+.4f N from (a)\n",
           one[q].muscle, r1.compression, ce, r1.compression - r0.compression);
    if (q == 0) EXPECT_TRUE(r1.compression > r0.compression + 700);  // vasti press the knee
    free(T);
  }
  free(zero);
}

static go_gait* make_gait(const mjModel* m, const gsTable* coords, int N) {
  go_gait_opts o;
  go_gait_opts_default(&o);
  o.N = N;
  o.coords = coords;
  char err[512];
  go_gait* g = NULL;
  if (go_gait_create(&g, m, &o, err, sizeof(err)) != 0) fprintf(stderr, "create: %s\n", err);
  return g;
}

// m_S times the subtree com velocity at (q, qdot) (N s)
static void subtree_momentum(const mjModel* m, mjData* d, int body, const double* q,
                             const double* qd, double P[3]) {
  mju_copy(d->qpos, q, m->nq);
  mju_copy(d->qvel, qd, m->nv);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  mj_subtreeVel(m, d);
  for (int c = 0; c < 3; c++) P[c] = m->body_subtreemass[body] * d->subtree_linvel[3 * body + c];
}

// (c), (d): nodes of the trial's initial guess
static void trial_nodes(const mjModel* m, const gsKneeReactionSpec* left,
                        const gsKneeReactionSpec* right) {
  gsTable coords;
  gs_table_init(&coords);
  EXPECT_EQ_INT(0, gs_app_read_table(m, TRIAL "/coordinates.mot", &coords));
  int N = 21;
  go_gait* g = make_gait(m, &coords, N);
  EXPECT_TRUE(g != NULL);
  if (!g) return;
  const go_gait_layout* L = go_gait_layout_get(g);
  double* z = (double*)calloc((size_t)N * L->nz + 1, sizeof(double));
  char err[512];
  EXPECT_EQ_INT(0, go_gait_guess_from_trial(g, &coords, 0.05, z, err, sizeof(err)));
  mjData* d = mj_makeData(m);
  mjData* d2 = mj_makeData(m);
  double W = go_gait_weight(g);
  int finite = 1, kmax = -1;
  double fz_max = -1, c_at_max = NAN;
  for (int k = 0; k < N; k++) {
    go_gait_load_node(g, d, z + (size_t)k * L->nz);
    gsKneeReaction r;
    finite &= gs_knee_reaction(m, d, left, NULL, &r) == 0;
    gsFootGrf fl;
    gs_physics_foot_grf(m, d, 'l', 5.0, &fl);
    if (fl.force[2] > fz_max) fz_max = fl.force[2], kmax = k, c_at_max = r.compression;
  }
  EXPECT_TRUE(finite);
  printf("(c) trial guess, %d nodes: largest left vertical GRF %.3f BW at node %d, left knee "
         "compression there %.3f BW\n", N, fz_max / W, kmax, c_at_max / W);
  EXPECT_TRUE(c_at_max > 0.5 * W && c_at_max < 8 * W);

  // F_int = dP/dt - m_S g, dP/dt by central differences along (qdot, qddot)
  const double* zk = z + (size_t)kmax * L->nz;
  go_gait_load_node(g, d, zk);
  gsKneeReaction r;
  gs_knee_reaction(m, d, left, NULL, &r);
  int nv = m->nv;
  double h = 1e-5, *qp = (double*)malloc(sizeof(double) * 4 * nv);
  double *qdp = qp + nv, *qm = qp + 2 * nv, *qdm = qp + 3 * nv, Pp[3], Pm[3];
  for (int j = 0; j < nv; j++) {
    qp[j] = zk[L->x_q + j] + h * zk[L->x_qd + j];
    qm[j] = zk[L->x_q + j] - h * zk[L->x_qd + j];
    qdp[j] = zk[L->x_qd + j] + h * zk[L->xd_qdd + j];
    qdm[j] = zk[L->x_qd + j] - h * zk[L->xd_qdd + j];
  }
  subtree_momentum(m, d2, left->body, qp, qdp, Pp);
  subtree_momentum(m, d2, left->body, qm, qdm, Pm);
  for (int c = 0; c < 3; c++) {
    double fd = (Pp[c] - Pm[c]) / (2 * h) - m->body_subtreemass[left->body] * m->opt.gravity[c];
    EXPECT_NEAR(fd, r.inertial[c], 1e-5 * W);
    if (c == 2) printf("(c) F_int z %.6f N, momentum rate - weight %.6f N\n", r.inertial[c], fd);
  }
  free(qp);

  // (d) right knee: the muscles' force on the subtree through the tendon Jacobian, and the
  // knee_ty balance, at a mid-stance node of the right leg (node 3)
  const double* z3 = z + (size_t)3 * L->nz;
  go_gait_load_node(g, d, z3);
  double* T = (double*)malloc(sizeof(double) * m->nu);
  for (int i = 0; i < m->nu; i++) T[i] = gs_physics_muscle_tension(m, d, i, NULL);
  gsKneeReaction rr;
  EXPECT_EQ_INT(0, gs_knee_reaction(m, d, right, T, &rr));
  static const char* slides[3] = {"knee_tx", "knee_ty", "knee_tz"};
  for (int s = 0; s < 3; s++) {
    int j = mj_name2id(m, mjOBJ_JOINT, slides[s]), v = m->jnt_dofadr[j], qa = m->jnt_qposadr[j];
    const mjtNum* n = d->xaxis + 3 * j;
    double mus = 0, gen = 0;
    for (int i = 0; i < m->nu; i++) gen -= d->actuator_moment[i * nv + v] * T[i];
    mus = n[0] * rr.muscle[0] + n[1] * rr.muscle[1] + n[2] * rr.muscle[2];
    EXPECT_NEAR(gen, mus, 1e-9 * W);
    // n.F_J = EOM residual + spring-damper + limit force of the slide
    double eom = d->qfrc_inverse[v] - gen;
    double spring = -m->jnt_stiffness[j] * (d->qpos[qa] - m->qpos_spring[qa]) -
                    m->dof_damping[v] * d->qvel[v];
    double fj = n[0] * rr.force[0] + n[1] * rr.force[1] + n[2] * rr.force[2];
    EXPECT_NEAR(eom + spring + d->qfrc_constraint[v], fj, 1e-6 * W);
    if (s == 1) {
      printf("(d) right knee at node 3: %d crossing muscles; along knee_ty: reaction %.3f N = "
             "spring-damper %.3f N + EOM residual %.3f N + limit %.3f N; compression %.3f N\n",
             rr.ncross, fj, spring, eom, d->qfrc_constraint[v], rr.compression);
      EXPECT_NEAR(fj, rr.compression, 1e-9 * W);  // the axis is the tray's y axis = -knee_ty
    }
  }
  free(T);
  free(z);
  mj_deleteData(d);
  mj_deleteData(d2);
  go_gait_free(g);
  gs_table_free(&coords);
}

// (d) static on the right foot, knee_ty where its spring holds the load: the method and the
// placeholder's spring force agree
static void static_right(const mjModel* m, mjData* d, const gsKneeReactionSpec* sp) {
  double W = mj_getTotalmass(m) * kG;
  int j = mj_name2id(m, mjOBJ_JOINT, "knee_ty"), v = m->jnt_dofadr[j], qa = m->jnt_qposadr[j];
  double* zero = (double*)calloc((size_t)m->nu, sizeof(double));
  double ty = m->qpos_spring[qa], h = 0;
  gsKneeReaction r;
  for (int it = 0; it < 8; it++) {
    // pelvis height for the whole weight on the right foot at this knee_ty, then knee_ty where
    // the spring balances the load along the slide (qfrc_inverse[ty] = 0)
    double lo = 0.7, hi = 1.1;
    for (int b = 0; b < 80; b++) {
      h = 0.5 * (lo + hi);
      static_pose(m, d, h, 0);
      d->qpos[qa] = ty;
      mj_inverse(m, d);
      gsFootGrf fg;
      gs_physics_foot_grf(m, d, 'r', 5.0, &fg);
      if (fg.force[2] > W) lo = h;
      else hi = h;
    }
    ty -= d->qfrc_inverse[v] / m->jnt_stiffness[j];
  }
  static_pose(m, d, h, 0);
  d->qpos[qa] = ty;
  mj_inverse(m, d);
  EXPECT_EQ_INT(0, gs_knee_reaction(m, d, sp, zero, &r));
  double spring = -m->jnt_stiffness[j] * (d->qpos[qa] - m->qpos_spring[qa]);
  printf("(d) static on the right foot: axis z %.6f, knee_ty %.6f mm from rest, placeholder "
         "spring %.4f N, reaction method %.4f N, knee_ty residual %.2e N\n", r.axis[2],
         1e3 * (ty - m->qpos_spring[qa]), spring, r.compression, d->qfrc_inverse[v]);
  EXPECT_NEAR(spring, r.compression, 1e-6 * W + fabs(d->qfrc_inverse[v]));
  EXPECT_TRUE(fabs(d->qfrc_inverse[v]) < 1e-6 * W);
  // the weight above the knee, along the tibia axis (4.7 deg off vertical: the implant's
  // frames), compresses it
  double above = (mj_getTotalmass(m) - m->body_subtreemass[sp->body]) * kG;
  EXPECT_NEAR(above * r.axis[2], r.compression, 1e-6 * W);
  EXPECT_TRUE(r.axis[2] > 0.99);
  free(zero);
}

int main(void) {
  mjModel* m = gs_app_load_model(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody.xml");
  EXPECT_TRUE(m != NULL);
  if (!m) return GS_TEST_RESULT();
  char err[256];
  gsKneeReactionSpec left, right;
  EXPECT_EQ_INT(0, gs_knee_reaction_spec_left(m, &left, err, sizeof(err)));
  EXPECT_EQ_INT(0, gs_knee_reaction_spec(m, "tibial_tray", "knee_flexion", "ankle_angle", &right,
                                         err, sizeof(err)));
  EXPECT_TRUE(left.ground_l && !left.ground_r && right.ground_r && !right.ground_l);
  // bad names: one reason naming the object
  gsKneeReactionSpec bad;
  EXPECT_EQ_INT(-1, gs_knee_reaction_spec(m, "shin", "knee_flexion_l", "ankle_angle_l", &bad, err,
                                          sizeof(err)));
  EXPECT_TRUE(strstr(err, "shin") != NULL);
  EXPECT_EQ_INT(-1, gs_knee_reaction_spec(m, "tibia_l", "knee_flexion_l", "ankle_angle", &bad, err,
                                          sizeof(err)));
  EXPECT_TRUE(strstr(err, "ankle_angle") != NULL);
  mjData* d = mj_makeData(m);
  static_left(m, d, &left);
  static_right(m, d, &right);
  trial_nodes(m, &left, &right);
  mj_deleteData(d);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
