// go_gait.c: the gait collocation problem (see go_gait.h).
#include "optim/go_gait.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_activation.h"
#include "callbacks/gs_metabolics.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_muscle.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_tendon_paths.h"
#include "optim/go_defaults.h"
#include "optim/go_jacobian.h"

// variable scales (physical units per solver unit)
#define SC_Q 1.0
#define SC_QD 5.0
#define SC_QDD 50.0
#define SC_ADOT 20.0
#define SC_FTDOT 10.0
// tracking error scales
#define TR_ROT (5.0 * M_PI / 180.0)  // rad
#define TR_TRANS 0.02                // m
#define TR_GRF 0.1                   // body weights
// moment arm magnitude that counts as crossing (m or m/rad)
#define CROSS_TOL 1e-9
#define CROSS_RANDOM_POSES 64

// per-worker context: one mjData and scratch
typedef struct {
  const go_gait* g;   // the problem (read only)
  mjData* d;          // this worker's data
  double* M;          // full mass matrix (nv x nv)
  double* P;          // muscle powers (na)
  double* Pm;         // muscle powers, - perturbation (na)
  double* zp;         // perturbed node variables (nz)
  double* mus;        // per-muscle scratch of the metabolic gradient (4 na)
  double* mom;        // actuator moment arms at the node (na x nv, m or m/rad)
  double* dmom;       // their derivative along qdot (na x nv, m/s or m/(rad s))
  double* pos_q;      // the coordinates d's position stage was computed at (nv, m or rad)
  double* hz;         // the metabolic Hessian's perturbed node variables and the gradients at
                      // z +- h e_j (3 nz; integrand_hess_block_cb)
  int pos_valid;      // 1: d's position stage is that of pos_q (see node_inverse)
  long pos_reused;    // node_inverse calls that reused it
} gait_ctx;

#define GO_GAIT_MAX_MUSCLES 512

struct go_gait {
  mjModel* m;                 // private copy, constraint stage off
  go_gait_layout L;           // layout
  int N;                      // nodes
  double T;                   // stride time (s)
  double weight;              // m g (N)
  gsMuscleParams* mprm;       // muscle parameters (na)
  gsActivationParams* aprm;   // activation parameters (na)
  int* elastic;               // (ne)
  int* elastic_of;            // (na)
  unsigned char* cross;       // muscle i crosses dof j: cross[i nv + j] (na x nv)
  unsigned char* tree;        // dofs i, j on one branch: tree[i nv + j] (nv x nv)
  unsigned char* foot;        // dof j moves foot s: foot[s nv + j] (2 x nv)
  int* col_ptr;               // path pattern (nz + 1)
  int* row_idx;               // (nnz)
  unsigned char* analytic;    // (nz)
  double* z_lb;               // (nz)
  double* z_ub;               // (nz)
  double* z_scale;            // (nz)
  double* path_scale;         // (n_path)
  int n_bnd;                  // boundary rows
  int* bnd_var;               // periodic node variable of boundary row b (n_bnd; -1: speed)
  int* bnd_col_ptr;           // (2 nz + 2)
  int* bnd_row_idx;           // (2 n_bnd)
  double* bnd_scale;          // (n_bnd)
  double speed;               // speed constraint (m/s), 0: none
  double* q_ref;              // measured coordinates (N x nv), NAN when absent
  double* grf_ref;            // measured grf, world (N x GO_GAIT_NGRF), NAN when absent
  double* q_wt;               // tracking weight / scale^2 / count per dof (nv)
  double grf_wt[GO_GAIT_NGRF]; // per grf component: its goal weight / scale^2 / GO_GAIT_NGRF
  double w_effort;            // effort weight / na
  double w_accel;             // acceleration weight / GO_GAIT_ACCEL_SCALE^2 / nv  (s^4, s^4/m^2)
  double* path_lb;            // path row bounds, physical (n_path): 0, fibre rows fibre_lo,
                              // walk row min_vgrf m g
  double* path_ub;            // (n_path): 0, fibre rows fibre_hi, walk row none (1e19)
  int* ivars;                 // integrand variables
  int n_ivars;
  double cot_scale;           // w_cot / (m V): metabolic integrand factor      (s / (kg m))
  gsUmbergerMuscle* umus;     // metabolic parameters (na)
  gsUmbergerSmoothing umb_smooth;  // widths of the smooth Umberger 2010 rates
  int free_time;              // T is the last NLP variable
  go_bound_override* band;    // eq. 3 bounds as node overrides (n_band)
  int n_band;
  double* prox_z0;            // proximal target z0 (N nz, physical) while polishing, else NULL
  double* prox_w;             // proximal weights 1 / z_scale^2 (nz)
  go_elements el;             // Hessian elements of a node (go_gait_elements)
  int* el_mem;                // their arrays, one allocation
  unsigned char* el_lin;      // per element variable: 1 where the element is linear (go_elements)
  unsigned char* el_pairs;    // nz x nz: q/qdot pairs with possible mixed curvature (go_elements)
  unsigned char* obj_mask;    // nz x nz: the integrand's possible Hessian entries (prediction)
  gait_ctx* ctx;              // (nthreads)
  void** ctx_ptr;             // (nthreads)
  int nthreads;
  go_nlp* nlp;                // the NLP
};

void go_gait_opts_default(go_gait_opts* o) {
  memset(o, 0, sizeof(*o));
  o->N = GO_NODES_TRACK;
  o->nthreads = 1;
  o->w_pelvis_rot = 1.0;
  o->w_pelvis_trans = 1.0;
  o->w_joint = 1.0;
  o->w_grf = 1.0;
  o->w_grm = 0.0;
  o->w_effort = 0.1;
  o->periodic = 1;
  o->fibre_lo = 0.25;
  o->fibre_hi = 1.5;
  o->metabolic_smoothing = 1.0;
}

go_nlp* go_gait_nlp(go_gait* g) { return g->nlp; }
const go_gait_layout* go_gait_layout_get(const go_gait* g) { return &g->L; }
const mjModel* go_gait_model(const go_gait* g) { return g->m; }
int go_gait_nodes(const go_gait* g) { return g->N; }
int go_gait_threads(const go_gait* g) { return g->nthreads; }
double go_gait_stride_time(const go_gait* g) { return g->T; }
double go_gait_weight(const go_gait* g) { return g->weight; }
double go_gait_q_ref(const go_gait* g, int k, int j) { return g->q_ref[k * g->L.nv + j]; }
double go_gait_grf_ref(const go_gait* g, int k, int c) {
  return g->grf_ref[k * GO_GAIT_NGRF + c];
}

// --- evaluation -------------------------------------------------------------------------------

// node z's inputs of the inverse dynamics into d: coordinates, speeds, accelerations,
// activations, excitations and (userdata) normalised tendon forces
static void set_node_inputs(const go_gait* g, mjData* d, const double* z) {
  const go_gait_layout* L = &g->L;
  const mjModel* m = g->m;
  mju_copy(d->qpos, z + L->x_q, L->nv);
  mju_copy(d->qvel, z + L->x_qd, L->nv);
  mju_copy(d->qacc, z + L->xd_qdd, L->nv);
  mju_copy(d->act, z + L->x_a, L->na);
  mju_copy(d->ctrl, z + L->u_e, L->na);
  mju_zero(d->userdata, m->nuserdata);
  for (int e = 0; e < L->ne; e++) {
    d->userdata[L->elastic[e]] = z[L->x_ft + e];
  }
}

void go_gait_load_node(const go_gait* g, mjData* d, const double* z) {
  set_node_inputs(g, d, z);
  gs_inverse(g->m, d);
}

// go_gait_load_node on the worker's data, reusing its position stage when z's coordinates equal
// (bitwise) those it was computed at. MuJoCo's position stage (kinematics, tendon paths, moment
// arms, mass matrix) depends on qpos alone and the velocity and acceleration stages only read it,
// so mj_inverseSkip(mjSTAGE_POS) then gives the same numbers as mj_inverse, bitwise
// (tests/test_gait_problem.c checks it). Finite differences in the speeds, activations,
// excitations and tendon forces of one node hit it: about half the path evaluations of a
// Jacobian, over two thirds of an exact Hessian's (docs/BENCHMARKS.md, "The position stage
// reused").
static void node_inverse(gait_ctx* c, const double* z) {
  const go_gait* g = c->g;
  mjData* d = c->d;
  int nv = g->L.nv;
  set_node_inputs(g, d, z);
  if (c->pos_valid && memcmp(c->pos_q, z + g->L.x_q, sizeof(double) * (size_t)nv) == 0) {
    mj_inverseSkip(g->m, d, mjSTAGE_POS, 0);
    c->pos_reused++;
    return;
  }
  gs_inverse(g->m, d);
  memcpy(c->pos_q, z + g->L.x_q, sizeof(double) * (size_t)nv);
  c->pos_valid = 1;
}

// d's position stage is about to be changed by something else than node_inverse
static void forget_position(gait_ctx* c) { c->pos_valid = 0; }

long go_gait_position_reuses(const go_gait* g) {
  long s = 0;
  for (int w = 0; w < g->nthreads; w++) s += g->ctx[w].pos_reused;
  return s;
}

// tension (N) of muscle i at the loaded state; dF/da into *dFda for rigid tendons (else 0)
static double tension(const go_gait* g, const mjData* d, const double* z, int i, double* dFda) {
  const gsMuscleParams* p = &g->mprm[i];
  int e = g->L.elastic_of[i];
  if (e >= 0) {
    *dFda = 0;
    return p->fmax * z[g->L.x_ft + e];
  }
  gsMuscleGrad gr;
  double F = gs_muscle_rigid_force(p, z[g->L.x_a + i], d->actuator_length[i],
                                   d->actuator_velocity[i], &gr, NULL);
  *dFda = gr.a;
  return F;
}

// normalised fibre length lM / lopt (-) of muscle i at the loaded state (Lin, Walter & Pandy
// 2018, eq. 2's bounded quantity): tendon length lts fT^-1(fT) (elastic) or lts (rigid), fibre
// at constant thickness (gs_muscle_fibre_length); d/dfT (-) into *dfT (elastic, else 0)
static double fibre_norm(const go_gait* g, const mjData* d, const double* z, int i, double* dfT) {
  const gsMuscleParams* p = &g->mprm[i];
  int e = g->L.elastic_of[i];
  double lT = p->lts, dlT = 0, c;
  if (e >= 0) {
    lT = p->lts * gs_muscle_ft_inverse(z[g->L.x_ft + e], p->kT, &dlT);
    dlT *= p->lts;  // m per unit fT
  }
  double lM = gs_muscle_fibre_length(p, d->actuator_length[i], lT, &c, NULL);
  if (dfT) *dfT = -c * dlT / p->lopt;  // dlM/dlT = -cos(alpha)
  return lM / p->lopt;
}

void go_gait_fibre_lengths(const go_gait* g, mjData* d, const double* z, double* lm_norm) {
  go_gait_load_node(g, d, z);
  for (int i = 0; i < g->L.na; i++) lm_norm[i] = fibre_norm(g, d, z, i, NULL);
}

// the path rows at node z from d loaded with z (go_gait_load_node or node_inverse)
static int path_rows(const go_gait* g, mjData* d, const double* z, double* res) {
  const go_gait_layout* L = &g->L;
  const mjModel* m = g->m;
  int nv = L->nv;
  // link rows
  for (int j = 0; j < nv; j++) {
    res[L->r_link + j] = z[L->x_qd + j] - z[L->xd_q + j];
  }
  // equations of motion: inverse dynamics minus muscle generalized forces
  double* eom = res + L->r_eom;
  mju_copy(eom, d->qfrc_inverse, nv);
  for (int i = 0; i < L->na; i++) {
    double dFda;
    double F = tension(g, d, z, i, &dFda);
    const mjtNum* mom = d->actuator_moment + i * nv;
    for (int j = 0; j < nv; j++) {
      if (g->cross[i * nv + j]) {
        eom[j] += mom[j] * F;
      }
    }
  }
  // Hill equilibrium of elastic muscles
  for (int e = 0; e < L->ne; e++) {
    int i = L->elastic[e];
    res[L->r_hill + e] = gs_muscle_equilibrium_residual(
        &g->mprm[i], z[L->x_a + i], d->actuator_length[i], d->actuator_velocity[i],
        z[L->x_ft + e], z[L->xd_ft + e], NULL, NULL);
  }
  // activation dynamics
  for (int i = 0; i < L->na; i++) {
    res[L->r_act + i] = z[L->xd_a + i] -
                        gs_activation_dot(&g->aprm[i], z[L->u_e + i], z[L->x_a + i], NULL, NULL);
  }
  // ground reactions
  for (int s = 0; s < 2; s++) {
    gsFootGrf fg;
    gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &fg);
    for (int c = 0; c < 3; c++) {
      res[L->r_grf + 3 * s + c] = z[L->u_grf + 3 * s + c] - fg.force[c];
      if (L->ngrf > GO_GAIT_GRM_OFFSET) {
        res[L->r_grf + GO_GAIT_GRM_OFFSET + 3 * s + c] =
            z[L->u_grf + GO_GAIT_GRM_OFFSET + 3 * s + c] - fg.moment[c];
      }
    }
  }
  // normalised fibre lengths (bounded by path_lb, path_ub)
  for (int i = 0; L->r_fib >= 0 && i < L->na; i++) {
    res[L->r_fib + i] = fibre_norm(g, d, z, i, NULL);
  }
  // summed vertical ground reaction (bounded below by path_lb: no flight phase)
  if (L->r_walk >= 0) res[L->r_walk] = z[L->u_grf + 2] + z[L->u_grf + 5];
  for (int r = 0; r < L->n_path; r++) {
    if (!isfinite(res[r])) {
      return -1;
    }
  }
  return 0;
}

int go_gait_path_eval(const go_gait* g, mjData* d, const double* z, double* res) {
  go_gait_load_node(g, d, z);
  return path_rows(g, d, z, res);
}

static int path_cb(void* vctx, int k, const double* z, double* res) {
  gait_ctx* c = (gait_ctx*)vctx;
  node_inverse(c, z);
  return path_rows(c->g, c->d, z, res);
}

// analytic columns: q', qddot, a, fT, adot, fT', e, grf
static int path_jac_cb(void* vctx, int k, const double* z, double* vals) {
  gait_ctx* c = (gait_ctx*)vctx;
  const go_gait* g = c->g;
  const go_gait_layout* L = &g->L;
  int nv = L->nv;
  mjData* d = c->d;
  node_inverse(c, z);
  mj_fullM(g->m, c->M, d->qM);
  for (int col = 0; col < L->nz; col++) {
    if (!g->analytic[col]) {
      continue;
    }
    int p0 = g->col_ptr[col], p1 = g->col_ptr[col + 1];
    if (col >= L->xd_q && col < L->xd_q + nv) {  // q': link row
      vals[p0] = -1.0;
    } else if (col >= L->xd_qdd && col < L->xd_qdd + nv) {  // qddot: mass matrix
      int j = col - L->xd_qdd;
      for (int p = p0; p < p1; p++) {
        vals[p] = c->M[(g->row_idx[p] - L->r_eom) * nv + j];
      }
    } else if (col >= L->x_a && col < L->x_a + L->na) {  // activation
      int i = col - L->x_a;
      int e = L->elastic_of[i];
      double dFda = 0, dda = 0;
      tension(g, d, z, i, &dFda);
      gs_activation_dot(&g->aprm[i], z[L->u_e + i], z[L->x_a + i], NULL, &dda);
      gsMuscleGrad gr = {0};
      if (e >= 0) {
        gs_muscle_equilibrium_residual(&g->mprm[i], z[col], d->actuator_length[i],
                                       d->actuator_velocity[i], z[L->x_ft + e], z[L->xd_ft + e],
                                       &gr, NULL);
      }
      for (int p = p0; p < p1; p++) {
        int r = g->row_idx[p];
        if (r < L->r_hill) {
          vals[p] = d->actuator_moment[i * nv + r - L->r_eom] * dFda;
        } else if (r < L->r_act) {
          vals[p] = gr.a;
        } else {
          vals[p] = -dda;
        }
      }
    } else if (col >= L->x_ft && col < L->x_ft + L->ne) {  // tendon force
      int e = col - L->x_ft, i = L->elastic[e];
      gsMuscleGrad gr;
      gs_muscle_equilibrium_residual(&g->mprm[i], z[L->x_a + i], d->actuator_length[i],
                                     d->actuator_velocity[i], z[col], z[L->xd_ft + e], &gr, NULL);
      double dfib = 0;
      if (L->r_fib >= 0) fibre_norm(g, d, z, i, &dfib);
      for (int p = p0; p < p1; p++) {
        int r = g->row_idx[p];
        vals[p] = r < L->r_hill   ? d->actuator_moment[i * nv + r - L->r_eom] * g->mprm[i].fmax
                  : r < L->r_act ? gr.fT
                                 : dfib;  // the fibre row
      }
    } else if (col >= L->xd_a && col < L->xd_a + L->na) {  // adot
      vals[p0] = 1.0;
    } else if (col >= L->xd_ft && col < L->xd_ft + L->ne) {  // fT'
      int e = col - L->xd_ft, i = L->elastic[e];
      gsMuscleGrad gr;
      gs_muscle_equilibrium_residual(&g->mprm[i], z[L->x_a + i], d->actuator_length[i],
                                     d->actuator_velocity[i], z[L->x_ft + e], z[col], &gr, NULL);
      vals[p0] = gr.fT_dot;
    } else if (col >= L->u_e && col < L->u_e + L->na) {  // excitation
      int i = col - L->u_e;
      double ddu = 0;
      gs_activation_dot(&g->aprm[i], z[col], z[L->x_a + i], &ddu, NULL);
      vals[p0] = -ddu;
    } else {  // grf variable: its grf row and, vertical forces, the walk row
      for (int p = p0; p < p1; p++) vals[p] = 1.0;
    }
  }
  for (int col = 0; col < L->nz; col++) {
    for (int p = g->col_ptr[col]; g->analytic[col] && p < g->col_ptr[col + 1]; p++) {
      if (!isfinite(vals[p])) {
        return -1;
      }
    }
  }
  return 0;
}

// --- objective --------------------------------------------------------------------------------

// proximal integrand of the feasibility polish: sum_j ((z_j - z0_kj) / z_scale_j)^2
static double proximal(const go_gait* g, int k, const double* z, double* dL, double* d2L) {
  const double* z0 = g->prox_z0 + (size_t)k * g->L.nz;
  double s = 0;
  for (int j = 0; j < g->L.nz; j++) {
    double e = z[j] - z0[j];
    s += g->prox_w[j] * e * e;
    if (dL) dL[j] = 2 * g->prox_w[j] * e;
    if (d2L) d2L[j] = 2 * g->prox_w[j];
  }
  return s;
}

// muscle metabolic powers P (na, W) at the node state z: smooth Umberger 2010
// (gs_umberger2010_smooth) with the fibre state of gs_physics_muscle_tension; position stage
// recomputed only when `kinematics` (q or qdot changed)
static void muscle_powers(const go_gait* g, mjData* d, const double* z, int kinematics,
                          double* P) {
  const go_gait_layout* L = &g->L;
  const mjModel* m = g->m;
  if (kinematics) {
    mju_copy(d->qpos, z + L->x_q, L->nv);
    mju_copy(d->qvel, z + L->x_qd, L->nv);
    gs_fwd_position(m, d);
    mj_fwdVelocity(m, d);
  }
  mju_copy(d->act, z + L->x_a, L->na);
  mju_copy(d->ctrl, z + L->u_e, L->na);
  for (int e = 0; e < L->ne; e++) d->userdata[L->elastic[e]] = z[L->x_ft + e];
  for (int i = 0; i < L->na; i++) {
    gsMuscleOut out;
    gs_physics_muscle_tension(m, d, i, &out);
    gsUmbergerInput in = {d->ctrl[i], d->act[i], out.lM_norm, out.vM, out.f_active, out.fL};
    P[i] = gs_umberger2010_smooth(&g->umus[i], &in, &g->umb_smooth, NULL);
  }
}

static double sum(const double* x, int n) {
  double s = 0;
  for (int i = 0; i < n; i++) s += x[i];
  return s;
}

// metabolic integrand cot_scale * sum_i P_i and its gradient (dL, added; NULL: none).
// Muscle i's power depends on its excitation e_i, activation a_i and tendon force fT_i, and on
// q and qdot only through its actuator's length l_i(q) and velocity v_i = sum_j r_ij(q) qdot_j
// (r = actuator_moment = dl/dq; nq == nv, go_gait_create), so by the chain rule
//   dP/dqdot_j = sum_i dP_i/dv_i r_ij
//   dP/dq_j    = sum_i (dP_i/dl_i r_ij + dP_i/dv_i dv_i/dq_j),
//   dv_i/dq_j  = sum_k (d2 l_i / dq_j dq_k) qdot_k = d/de r_ij(q + e qdot)   (d2 l_i symmetric).
// The partials in e, a, fT, l and v are central differences, each perturbed for all muscles at
// once (2 muscle evaluations each, no kinematics); d r / de is a central difference of the
// position stage at q +- e qdot (2 evaluations). 14 muscle sweeps and 3 position stages per
// node, where differencing every q_j and qdot_j took 4 nv full kinematics.
static double metabolic(const go_gait* g, gait_ctx* c, const double* z, double* dL) {
  const go_gait_layout* L = &g->L;
  const mjModel* m = g->m;
  mjData* d = c->d;
  int na = L->na, nv = L->nv, nz = L->nz;
  double* P = c->P;
  forget_position(c);
  muscle_powers(g, d, z, 1, P);
  double val = g->cot_scale * sum(P, na);
  if (!dL) return val;
  double* zp = c->zp;
  double* Pm = c->Pm;
  double* len0 = c->mus;            // actuator lengths at z (na)
  double* vel0 = c->mus + na;       // actuator velocities at z (na)
  double* dPdl = c->mus + 2 * na;   // dP_i/dl_i (W/m)
  double* dPdv = c->mus + 3 * na;   // dP_i/dv_i (W s/m)
  double* r = c->mom;               // actuator moment arms at z (na x nv)
  double* dr = c->dmom;             // d r / de along qdot (na x nv)
  mju_copy(len0, d->actuator_length, na);
  mju_copy(vel0, d->actuator_velocity, na);
  mju_copy(r, d->actuator_moment, na * nv);
  memcpy(zp, z, sizeof(double) * (size_t)nz);
  // per-muscle variables, all muscles at once (kinematics of z still in d)
  const int blocks[3][2] = {{L->x_a, na}, {L->u_e, na}, {L->x_ft, L->ne}};
  for (int b = 0; b < 3; b++) {
    int off = blocks[b][0], cnt = blocks[b][1];
    double hs[GO_GAIT_MAX_MUSCLES];
    for (int i = 0; i < cnt; i++) {
      hs[i] = 1e-6 * fmax(1.0, fabs(z[off + i]));
      zp[off + i] = z[off + i] + hs[i];
    }
    muscle_powers(g, d, zp, 0, P);
    for (int i = 0; i < cnt; i++) zp[off + i] = z[off + i] - hs[i];
    muscle_powers(g, d, zp, 0, Pm);
    for (int i = 0; i < cnt; i++) {
      int mi = b == 2 ? L->elastic[i] : i;
      dL[off + i] += g->cot_scale * (P[mi] - Pm[mi]) / (2 * hs[i]);
      zp[off + i] = z[off + i];
    }
  }
  // actuator lengths, then velocities, all muscles at once
  for (int b = 0; b < 2; b++) {
    double* x = b == 0 ? d->actuator_length : d->actuator_velocity;
    const double* x0 = b == 0 ? len0 : vel0;
    double* dPdx = b == 0 ? dPdl : dPdv;
    double hs[GO_GAIT_MAX_MUSCLES];
    for (int i = 0; i < na; i++) {
      hs[i] = 1e-6 * fmax(1.0, fabs(x0[i]));
      x[i] = x0[i] + hs[i];
    }
    muscle_powers(g, d, z, 0, P);
    for (int i = 0; i < na; i++) x[i] = x0[i] - hs[i];
    muscle_powers(g, d, z, 0, Pm);
    for (int i = 0; i < na; i++) {
      dPdx[i] = (P[i] - Pm[i]) / (2 * hs[i]);
      x[i] = x0[i];
    }
  }
  // moment arms along qdot: r(q + e qdot) - r(q - e qdot), a step of 1e-6 in the largest q_j
  const double* q = z + L->x_q;
  const double* qd = z + L->x_qd;
  double qd_max = 0;
  for (int j = 0; j < nv; j++) qd_max = fmax(qd_max, fabs(qd[j]));
  memset(dr, 0, sizeof(double) * (size_t)na * nv);
  if (qd_max > 0) {
    double eps = 1e-6 / qd_max;
    for (int s = 0; s < 2; s++) {
      for (int j = 0; j < nv; j++) d->qpos[j] = q[j] + (s == 0 ? eps : -eps) * qd[j];
      mj_kinematics(m, d);
      mj_comPos(m, d);
      mj_tendon(m, d);
      mj_transmission(m, d);
      gs_tendon_repair(m, d);
      mju_addToScl(dr, d->actuator_moment, s == 0 ? 1.0 / (2 * eps) : -1.0 / (2 * eps),
                   na * nv);
    }
    mju_copy(d->qpos, q, nv);  // d's position stage is now stale; callers recompute it
  }
  double* dq = dL + L->x_q;
  double* dqd = dL + L->x_qd;
  for (int i = 0; i < na; i++) {
    double gl = g->cot_scale * dPdl[i], gv = g->cot_scale * dPdv[i];
    const double* ri = r + (size_t)i * nv;
    const double* dri = dr + (size_t)i * nv;
    for (int j = 0; j < nv; j++) {
      dq[j] += gl * ri[j] + gv * dri[j];
      dqd[j] += gv * ri[j];
    }
  }
  return val;
}

static int integrand_cb(void* vctx, int k, const double* z, double* out) {
  const go_gait* g = ((gait_ctx*)vctx)->g;
  const go_gait_layout* L = &g->L;
  if (g->prox_z0) {
    *out = proximal(g, k, z, NULL, NULL);
    return isfinite(*out) ? 0 : -1;
  }
  double s = g->cot_scale > 0 ? metabolic(g, (gait_ctx*)vctx, z, NULL) : 0;
  for (int j = 0; j < L->nv; j++) {
    if (g->q_wt[j] > 0) {
      double err = z[L->x_q + j] - g->q_ref[k * L->nv + j];
      s += g->q_wt[j] * err * err;
    }
  }
  for (int c = 0; c < L->ngrf; c++) {
    if (g->grf_wt[c] > 0) {
      double err = z[L->u_grf + c] - g->grf_ref[k * GO_GAIT_NGRF + c];
      s += g->grf_wt[c] * err * err;
    }
  }
  for (int i = 0; i < L->na; i++) {
    s += g->w_effort * z[L->u_e + i] * z[L->u_e + i];
  }
  for (int j = 0; g->w_accel > 0 && j < L->nv; j++) {
    s += g->w_accel * z[L->xd_qdd + j] * z[L->xd_qdd + j];
  }
  *out = s;
  return isfinite(s) ? 0 : -1;
}

static int integrand_grad_cb(void* vctx, int k, const double* z, double* dL) {
  const go_gait* g = ((gait_ctx*)vctx)->g;
  const go_gait_layout* L = &g->L;
  if (g->prox_z0) {
    proximal(g, k, z, dL, NULL);
    return 0;
  }
  memset(dL, 0, sizeof(double) * (size_t)L->nz);
  if (g->cot_scale > 0) metabolic(g, (gait_ctx*)vctx, z, dL);
  for (int j = 0; j < L->nv; j++) {
    if (g->q_wt[j] > 0) {
      dL[L->x_q + j] += 2 * g->q_wt[j] * (z[L->x_q + j] - g->q_ref[k * L->nv + j]);
    }
  }
  for (int c = 0; c < L->ngrf; c++) {
    if (g->grf_wt[c] > 0) {
      dL[L->u_grf + c] += 2 * g->grf_wt[c] * (z[L->u_grf + c] - g->grf_ref[k * GO_GAIT_NGRF + c]);
    }
  }
  for (int i = 0; i < L->na; i++) {
    dL[L->u_e + i] += 2 * g->w_effort * z[L->u_e + i];
  }
  for (int j = 0; g->w_accel > 0 && j < L->nv; j++) {
    dL[L->xd_qdd + j] += 2 * g->w_accel * z[L->xd_qdd + j];
  }
  return 0;
}

// diagonal Hessian of the integrand (it is a sum of squares of single variables)
static int integrand_hess_cb(void* vctx, int k, const double* z, double* d2L) {
  const go_gait* g = ((gait_ctx*)vctx)->g;
  const go_gait_layout* L = &g->L;
  if (g->prox_z0) {
    proximal(g, k, z, NULL, d2L);
    return 0;
  }
  memset(d2L, 0, sizeof(double) * (size_t)L->nz);
  for (int j = 0; j < L->nv; j++) d2L[L->x_q + j] = 2 * g->q_wt[j];
  for (int c = 0; c < L->ngrf; c++) d2L[L->u_grf + c] = 2 * g->grf_wt[c];
  for (int i = 0; i < L->na; i++) d2L[L->u_e + i] = 2 * g->w_effort;
  for (int j = 0; j < L->nv; j++) d2L[L->xd_qdd + j] = 2 * g->w_accel;
  return 0;
}

// The integrand's whole Hessian at node k (go_integrand_hess_block_fn): the squares' diagonal
// (integrand_hess_cb) plus the metabolic power's Hessian, by central differences of its
// chain-rule gradient (metabolic) with a step of 1e-4 max(z_scale_j, |z_j|) (step_of):
//   - a column for each coordinate and speed of a dof some muscle crosses (2 gradients each);
//   - one perturbation of every muscle's activation at once, one of every excitation, one of
//     every tendon force: muscle i's power reads only its own a_i, e_i and fT_i besides q and
//     qdot, so the entries among those three of one muscle come out of the same gradients; the
//     entries between them and q or qdot are read from the q and qdot columns.
// Entries read from two columns (q and qdot among themselves) are averaged, so H is symmetric.
// Cost per node: 2 (2 n_crossed + 3) gradients of 14 muscle sweeps and 3 position stages each.
// a finite-difference step in node variable j: rel times its scale, or |z_j| when larger
static double step_of(const go_gait* g, const double* z, int j, double rel) {
  return rel * fmax(g->z_scale[j], fabs(z[j]));
}

static int integrand_hess_block_cb(void* vctx, int k, const double* z, double* H) {
  gait_ctx* c = (gait_ctx*)vctx;
  const go_gait* g = c->g;
  const go_gait_layout* L = &g->L;
  int nz = L->nz, nv = L->nv, na = L->na;
  memset(H, 0, sizeof(double) * (size_t)nz * (size_t)nz);
  double* diag = c->hz;  // the squares' diagonal first (hz is free until the metabolic part)
  integrand_hess_cb(vctx, k, z, diag);
  for (int j = 0; j < nz; j++) H[(size_t)j * nz + j] = diag[j];
  if (g->prox_z0 || !(g->cot_scale > 0)) return 0;
  double *zp = c->hz, *gp = c->hz + nz, *gm = c->hz + 2 * nz;
  const double rel = 1e-4;
  memcpy(zp, z, sizeof(double) * (size_t)nz);
  // columns of the coordinates and speeds
  for (int col = 0; col < 2 * nv; col++) {
    int j = col < nv ? L->x_q + col : L->x_qd + col - nv, dof = col < nv ? col : col - nv;
    int crossed = 0;
    for (int i = 0; i < na && !crossed; i++) crossed = g->cross[i * nv + dof];
    if (!crossed) continue;
    double hj = step_of(g, z, j, rel);
    memset(gp, 0, sizeof(double) * (size_t)nz);
    memset(gm, 0, sizeof(double) * (size_t)nz);
    zp[j] = z[j] + hj;
    metabolic(g, c, zp, gp);
    zp[j] = z[j] - hj;
    metabolic(g, c, zp, gm);
    zp[j] = z[j];
    for (int r = 0; r < nz; r++) {
      if (!g->obj_mask[(size_t)r * nz + j]) continue;
      double v = (gp[r] - gm[r]) / (2 * hj);
      if (r >= L->x_q && r < L->x_qd + nv) {  // q or qdot: the other column gives it too
        H[(size_t)r * nz + j] += 0.5 * v;
        H[(size_t)j * nz + r] += 0.5 * v;
      } else {
        H[(size_t)r * nz + j] += v;
        H[(size_t)j * nz + r] += v;
      }
    }
  }
  // every muscle's a, e, fT at once: the entries among one muscle's own three
  const int blocks[3][2] = {{L->x_a, na}, {L->u_e, na}, {L->x_ft, L->ne}};
  for (int b = 0; b < 3; b++) {
    int off = blocks[b][0], cnt = blocks[b][1];
    memset(gp, 0, sizeof(double) * (size_t)nz);
    memset(gm, 0, sizeof(double) * (size_t)nz);
    for (int t = 0; t < cnt; t++) zp[off + t] = z[off + t] + step_of(g, z, off + t, rel);
    metabolic(g, c, zp, gp);
    for (int t = 0; t < cnt; t++) zp[off + t] = z[off + t] - step_of(g, z, off + t, rel);
    metabolic(g, c, zp, gm);
    for (int t = 0; t < cnt; t++) zp[off + t] = z[off + t];
    for (int t = 0; t < cnt; t++) {
      int i = b == 2 ? L->elastic[t] : t, j = off + t;
      double hj = step_of(g, z, j, rel);
      int own[3] = {L->x_a + i, L->u_e + i, L->elastic_of[i] >= 0 ? L->x_ft + L->elastic_of[i] : -1};
      for (int o = 0; o < 3; o++) {
        int r = own[o];
        if (r < 0 || r < j) continue;  // each pair once, from its lower variable's block
        double v = (gp[r] - gm[r]) / (2 * hj);
        if (r == j) {
          H[(size_t)r * nz + j] += v;
        } else {
          H[(size_t)r * nz + j] += v;
          H[(size_t)j * nz + r] += v;
        }
      }
    }
  }
  return 0;
}

static int outer_cb(void* ctx, double I, double T, double* J, double* dJdI, double* dJdT) {
  *J = I / T;
  *dJdI = 1.0 / T;
  *dJdT = -I / (T * T);
  return 0;
}

// --- boundary ---------------------------------------------------------------------------------

static int boundary_cb(void* vctx, const double* z0, const double* z1, double T, double* b) {
  const go_gait* g = ((gait_ctx*)vctx)->g;
  for (int r = 0; r < g->n_bnd; r++) {
    int v = g->bnd_var[r];
    b[r] = v >= 0 ? z1[v] - z0[v]
                  : (z1[g->L.x_q + g->L.tx] - z0[g->L.x_q + g->L.tx]) / T - g->speed;
  }
  return 0;
}

// --- set-up -----------------------------------------------------------------------------------

// 1 if dof a is dof b or one of its ancestors
static int dof_ancestor(const mjModel* m, int a, int b) {
  for (int x = b; x >= 0; x = m->dof_parentid[x]) {
    if (x == a) {
      return 1;
    }
  }
  return 0;
}

// deterministic uniform in [-1, 1]
static double lcg(unsigned long long* s) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return ((double)(*s >> 11) / 9007199254740992.0) * 2.0 - 1.0;
}

// crossing matrix over the trial poses and random poses around them; 0, or -1 when out of
// memory
static int crossing(go_gait* g, const gsTable* coords, const int* qcol) {
  const mjModel* m = g->m;
  int nv = m->nv, na = g->L.na;
  mjData* d = mj_makeData(m);
  if (!d) return -1;
  int nrow = coords ? coords->nrow : 1;
  unsigned long long seed = 12345;
  for (int pose = 0; pose < nrow + CROSS_RANDOM_POSES; pose++) {
    int row = pose < nrow ? pose : (int)((lcg(&seed) + 1) * 0.5 * (nrow - 1) + 0.5);
    mju_copy(d->qpos, m->qpos0, m->nq);
    for (int j = 0; coords && j < nv; j++) {
      if (qcol[j] >= 0) {
        d->qpos[j] = coords->data[row * coords->ncol + qcol[j]];
      }
    }
    if (pose >= nrow) {
      for (int j = 0; j < nv; j++) {
        int jnt = m->dof_jntid[j];
        d->qpos[j] += (m->jnt_type[jnt] == mjJNT_SLIDE ? 0.03 : 0.35) * lcg(&seed);
      }
    }
    gs_fwd_position(m, d);
    for (int i = 0; i < na; i++) {
      for (int j = 0; j < nv; j++) {
        if (fabs(d->actuator_moment[i * nv + j]) > CROSS_TOL) {
          g->cross[i * nv + j] = 1;
        }
      }
    }
  }
  mj_deleteData(d);
  return 0;
}

// the path pattern (compressed columns); returns the number of entries, writes them when the
// arrays are not NULL
static int pattern(const go_gait* g, int* col_ptr, int* row_idx) {
  const go_gait_layout* L = &g->L;
  int nv = L->nv, n = 0;
#define PUT(r)                 \
  do {                         \
    if (row_idx) row_idx[n] = (r); \
    n++;                       \
  } while (0)
  for (int col = 0; col < L->nz; col++) {
    if (col_ptr) col_ptr[col] = n;
    if (col < L->x_qd + nv) {  // q or qdot of dof j
      int j = col < L->x_qd ? col : col - L->x_qd;
      if (col >= L->x_qd) PUT(L->r_link + j);
      for (int r = 0; r < nv; r++) PUT(L->r_eom + r);
      for (int e = 0; e < L->ne; e++) {
        if (g->cross[L->elastic[e] * nv + j]) PUT(L->r_hill + e);
      }
      for (int s = 0; s < 2; s++) {
        if (g->foot[s * nv + j]) {
          for (int c = 0; c < 3; c++) PUT(L->r_grf + 3 * s + c);
          for (int c = 0; L->ngrf > GO_GAIT_GRM_OFFSET && c < 3; c++)
            PUT(L->r_grf + GO_GAIT_GRM_OFFSET + 3 * s + c);
        }
      }
      for (int i = 0; L->r_fib >= 0 && col < L->x_qd && i < L->na; i++) {
        if (g->cross[i * nv + j]) PUT(L->r_fib + i);  // lM(lMT(q))
      }
    } else if (col < L->x_ft) {  // a
      int i = col - L->x_a;
      if (L->elastic_of[i] < 0) {
        for (int r = 0; r < nv; r++) {
          if (g->cross[i * nv + r]) PUT(L->r_eom + r);
        }
      } else {
        PUT(L->r_hill + L->elastic_of[i]);
      }
      PUT(L->r_act + i);
    } else if (col < L->xd_q) {  // fT
      int e = col - L->x_ft, i = L->elastic[e];
      for (int r = 0; r < nv; r++) {
        if (g->cross[i * nv + r]) PUT(L->r_eom + r);
      }
      PUT(L->r_hill + e);
      if (L->r_fib >= 0) PUT(L->r_fib + i);  // lM(lT(fT))
    } else if (col < L->xd_qdd) {  // q'
      PUT(L->r_link + col - L->xd_q);
    } else if (col < L->xd_a) {  // qddot
      int j = col - L->xd_qdd;
      for (int r = 0; r < nv; r++) {
        if (g->tree[r * nv + j]) PUT(L->r_eom + r);
      }
    } else if (col < L->xd_ft) {  // adot
      PUT(L->r_act + col - L->xd_a);
    } else if (col < L->u_e) {  // fT'
      PUT(L->r_hill + col - L->xd_ft);
    } else if (col < L->u_grf) {  // excitation
      PUT(L->r_act + col - L->u_e);
    } else {  // grf
      PUT(L->r_grf + col - L->u_grf);
      int c = col - L->u_grf;
      if (L->r_walk >= 0 && (c == 2 || c == 5)) PUT(L->r_walk);  // vertical forces
    }
  }
  if (col_ptr) col_ptr[L->nz] = n;
#undef PUT
  return n;
}

int go_gait_dof_is_root(const mjModel* m, int j) {
  int top = j;
  while (m->dof_parentid[top] >= 0) {
    top = m->dof_parentid[top];
  }
  return m->dof_bodyid[top] == m->dof_bodyid[j];
}

static void* zalloc(size_t n, size_t size) { return calloc(n > 0 ? n : 1, size); }

void go_gait_free(go_gait* g) {
  if (!g) {
    return;
  }
  go_nlp_free(g->nlp);
  for (int w = 0; g->ctx && w < g->nthreads; w++) {
    if (g->ctx[w].d) mj_deleteData(g->ctx[w].d);
    free(g->ctx[w].M), free(g->ctx[w].P), free(g->ctx[w].Pm), free(g->ctx[w].zp);
    free(g->ctx[w].mus), free(g->ctx[w].mom), free(g->ctx[w].dmom);
    free(g->ctx[w].pos_q), free(g->ctx[w].hz);
  }
  free(g->ctx);
  free(g->ctx_ptr);
  if (g->m) mj_deleteModel(g->m);
  free(g->mprm), free(g->aprm), free(g->elastic), free(g->elastic_of), free(g->cross);
  free(g->tree), free(g->foot), free(g->col_ptr), free(g->row_idx), free(g->analytic);
  free(g->z_lb), free(g->z_ub), free(g->z_scale), free(g->path_scale), free(g->bnd_var);
  free(g->bnd_col_ptr), free(g->bnd_row_idx), free(g->bnd_scale), free(g->q_ref);
  free(g->grf_ref), free(g->q_wt), free(g->ivars), free(g->el_mem), free(g->el_lin);
  free(g->el_pairs), free(g->obj_mask), free(g->prox_z0);
  free(g->prox_w), free(g->umus), free(g->band), free(g->path_lb), free(g->path_ub);
  free(g);
}

// Hessian elements of a node (go_hessian.h), variables in increasing node-variable order:
//   dynamics      eom and grf rows (and the fibre rows of rigid muscles) over q, qdot, a (rigid
//                 muscles), fT, qddot
//   tendon e      hill row e (and muscle i's fibre row) over q and qdot of the dofs muscle i
//                 crosses, a_i, fT_e, fT'_e
//   activation i  act row i over a_i, e_i
// (link rows and the walk row are linear; the grf variables, q' and adot enter linearly).
// Left out of the dynamics element: the coordinates of root slides along a horizontal axis (the
// pelvis' fore-aft and sideways translations) when there are no ground-moment rows. Every other
// path row is invariant under a horizontal translation of the whole body: the inverse dynamics
// and the muscle paths depend on relative positions only, and gaitsim's floor is the plane z = 0
// (gs_physics.c), so the foot contact depends on heights alone. Those rows are then linear (zero)
// in these coordinates and have no curvature in them; the moment rows (about the world origin)
// are not, being r x F.
static int horizontal_translations(const mjModel* m, unsigned char* flat);
static int build_elements(go_gait* g) {
  const go_gait_layout* L = &g->L;
  int nv = L->nv, na = L->na, ne = L->ne, E = 1 + ne + na;
  unsigned char* flat = (unsigned char*)calloc((size_t)nv, 1);  // dofs left out (above)
  if (!flat) return -1;
  if (L->ngrf <= GO_GAIT_GRM_OFFSET && horizontal_translations(g->m, flat) != 0) {
    free(flat);
    return -1;
  }
  int nrows = 2 * nv + 2 * 0 + nv + L->ngrf + ne + 2 * na;  // generous
  int nvars = (3 * nv + na + ne) + ne * (2 * nv + 3) + 2 * na;
  int* mem = (int*)malloc(sizeof(int) * (size_t)(2 * (E + 1) + nrows + nvars));
  if (!mem) {
    free(flat);
    return -1;
  }
  int *row_ptr = mem, *var_ptr = mem + E + 1, *rows = var_ptr + E + 1, *vars = rows + nrows;
  int nr = 0, nvv = 0, e = 0;
  // dynamics
  row_ptr[0] = var_ptr[0] = 0;
  for (int j = 0; j < nv; j++) rows[nr++] = L->r_eom + j;
  for (int c = 0; c < L->ngrf; c++) rows[nr++] = L->r_grf + c;
  for (int i = 0; L->r_fib >= 0 && i < na; i++)
    if (L->elastic_of[i] < 0) rows[nr++] = L->r_fib + i;
  for (int j = 0; j < nv; j++)
    if (!flat[j]) vars[nvv++] = L->x_q + j;
  free(flat);
  for (int j = 0; j < nv; j++) vars[nvv++] = L->x_qd + j;
  for (int i = 0; i < na; i++)
    if (L->elastic_of[i] < 0) vars[nvv++] = L->x_a + i;
  for (int t = 0; t < ne; t++) vars[nvv++] = L->x_ft + t;
  for (int j = 0; j < nv; j++) vars[nvv++] = L->xd_qdd + j;
  row_ptr[++e] = nr;
  var_ptr[e] = nvv;
  // tendons
  for (int t = 0; t < ne; t++) {
    int i = L->elastic[t];
    rows[nr++] = L->r_hill + t;
    if (L->r_fib >= 0) rows[nr++] = L->r_fib + i;
    for (int j = 0; j < nv; j++)
      if (g->cross[i * nv + j]) vars[nvv++] = L->x_q + j;
    for (int j = 0; j < nv; j++)
      if (g->cross[i * nv + j]) vars[nvv++] = L->x_qd + j;
    vars[nvv++] = L->x_a + i;
    vars[nvv++] = L->x_ft + t;
    vars[nvv++] = L->xd_ft + t;
    row_ptr[++e] = nr;
    var_ptr[e] = nvv;
  }
  // activations
  for (int i = 0; i < na; i++) {
    rows[nr++] = L->r_act + i;
    vars[nvv++] = L->x_a + i;
    vars[nvv++] = L->u_e + i;
    row_ptr[++e] = nr;
    var_ptr[e] = nvv;
  }
  g->el_mem = mem;
  // for the finite-difference Hessian: the dynamics rows are jointly linear in a (rigid), fT and
  // qddot (M(q) qddot + moment(q) F(q, qdot) a + moment(q) Fmax fT); two coordinates (or speeds)
  // have mixed curvature only on one branch of the kinematic tree or when a muscle crosses both
  g->el_lin = (unsigned char*)calloc((size_t)nvv + 1, 1);
  g->el_pairs = (unsigned char*)calloc((size_t)L->nz * (size_t)L->nz, 1);
  if (!g->el_lin || !g->el_pairs) return -1;
  for (int q = var_ptr[0]; q < var_ptr[1]; q++) g->el_lin[q] = vars[q] >= L->x_a;
  for (int a = 0; a < nv; a++) {
    for (int b = 0; b < nv; b++) {
      int related = g->tree[a * nv + b];
      for (int i = 0; i < na && !related; i++) related = g->cross[i * nv + a] && g->cross[i * nv + b];
      if (!related) continue;
      int va[2] = {L->x_q + a, L->x_qd + a}, vb[2] = {L->x_q + b, L->x_qd + b};
      for (int s = 0; s < 2; s++)
        for (int t = 0; t < 2; t++) g->el_pairs[(size_t)va[s] * L->nz + vb[t]] = 1;
    }
  }
  g->el = (go_elements){E, row_ptr, rows, var_ptr, vars, g->el_lin, g->el_pairs};
  return 0;
}

// flat[j] = 1 for every dof j that is a slide whose ancestors are all slides (so its axis is fixed
// in the world) and whose axis is horizontal (perpendicular to the world z axis, the floor's
// normal, to 1e-9), else 0 (nv). 0, or -1 out of memory.
static int horizontal_translations(const mjModel* m, unsigned char* flat) {
  mjData* d = mj_makeData(m);
  if (!d) return -1;
  mj_kinematics(m, d);  // at qpos0; such axes do not depend on the slides' positions
  for (int j = 0; j < m->nv; j++) {
    int slides = 1;
    for (int a = j; a >= 0 && slides; a = m->dof_parentid[a])
      slides = m->jnt_type[m->dof_jntid[a]] == mjJNT_SLIDE;
    flat[j] = slides && fabs(d->xaxis[3 * m->dof_jntid[j] + 2]) < 1e-9;
  }
  mj_deleteData(d);
  return 0;
}

const go_elements* go_gait_elements(const go_gait* g) { return &g->el; }

double go_gait_time_of(const go_gait* g, const double* z) {
  return g->free_time ? z[(size_t)g->N * g->L.nz] : g->T;
}

double go_gait_cot(const go_gait* g, const double* z) {
  const go_gait_layout* L = &g->L;
  if (L->tx < 0) return NAN;
  double T = go_gait_time_of(g, z), h = T / (g->N - 1), E = 0;
  gait_ctx* c = &g->ctx[0];
  forget_position(c);
  for (int k = 0; k < g->N; k++) {
    muscle_powers(g, c->d, z + (size_t)k * L->nz, 1, c->P);
    E += (k == 0 || k == g->N - 1 ? 0.5 : 1.0) * h * sum(c->P, L->na);
  }
  double dx = z[(size_t)(g->N - 1) * L->nz + L->x_q + L->tx] - z[L->x_q + L->tx];
  return E / (mj_getTotalmass(g->m) * dx);
}

int go_gait_objective_terms(const go_gait* g, const double* z, double* terms) {
  const go_gait_layout* L = &g->L;
  double T = go_gait_time_of(g, z), h = T / (g->N - 1);
  for (int t = 0; t < GO_GAIT_NTERMS; t++) terms[t] = 0;
  for (int k = 0; k < g->N; k++) {
    const double* zk = z + (size_t)k * L->nz;
    double w = (k == 0 || k == g->N - 1 ? 0.5 : 1.0) * h / T, v[GO_GAIT_NTERMS] = {0};
    for (int j = 0; j < L->nv; j++) {
      if (!(g->q_wt[j] > 0)) continue;
      double err = zk[L->x_q + j] - g->q_ref[k * L->nv + j];
      v[go_gait_dof_is_root(g->m, j) ? GO_GAIT_TERM_PELVIS : GO_GAIT_TERM_JOINTS] +=
          g->q_wt[j] * err * err;
    }
    for (int c = 0; c < L->ngrf; c++) {
      if (!(g->grf_wt[c] > 0)) continue;
      double err = zk[L->u_grf + c] - g->grf_ref[k * GO_GAIT_NGRF + c];
      v[GO_GAIT_TERM_GRF] += g->grf_wt[c] * err * err;
    }
    for (int i = 0; i < L->na; i++)
      v[GO_GAIT_TERM_EFFORT] += g->w_effort * zk[L->u_e + i] * zk[L->u_e + i];
    if (g->cot_scale > 0) v[GO_GAIT_TERM_COT] = metabolic(g, &g->ctx[0], zk, NULL);
    for (int j = 0; g->w_accel > 0 && j < L->nv; j++)
      v[GO_GAIT_TERM_ACCEL] += g->w_accel * zk[L->xd_qdd + j] * zk[L->xd_qdd + j];
    for (int t = 0; t < GO_GAIT_NTERMS; t++) terms[t] += w * v[t];
  }
  for (int t = 0; t < GO_GAIT_NTERMS; t++)
    if (!isfinite(terms[t])) return -1;
  return 0;
}

int go_gait_set_proximal(go_gait* g, const double* z0) {
  int n = g->N * g->L.nz;
  if (!z0) {
    free(g->prox_z0);
    g->prox_z0 = NULL;
    return 0;
  }
  if (!g->prox_z0) g->prox_z0 = (double*)malloc(sizeof(double) * (size_t)n);
  if (!g->prox_w) g->prox_w = (double*)malloc(sizeof(double) * (size_t)g->L.nz);
  if (!g->prox_z0 || !g->prox_w) return -1;
  memcpy(g->prox_z0, z0, sizeof(double) * (size_t)n);
  for (int j = 0; j < g->L.nz; j++) g->prox_w[j] = 1.0 / (g->z_scale[j] * g->z_scale[j]);
  return 0;
}

// coordinate column of each dof in t (-1: absent)
static void coord_columns(const mjModel* m, const gsTable* t, int* col) {
  for (int j = 0; j < m->nv; j++) {
    col[j] = t ? gs_table_column(t, mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[j])) : -1;
  }
}

// resample the measured data at the node times
static int references(go_gait* g, const go_gait_opts* o, const int* qcol, char* err, int errsz) {
  int N = g->N, nv = g->L.nv;
  for (int q = 0; q < N * nv; q++) g->q_ref[q] = NAN;
  for (int q = 0; q < N * GO_GAIT_NGRF; q++) g->grf_ref[q] = NAN;
  double* times = (double*)zalloc((size_t)N, sizeof(double));
  if (!times) {
    snprintf(err, (size_t)errsz, "go_gait_create: out of memory (references)");
    return -1;
  }
  gsTable rs;
  gs_table_init(&rs);
  int status = 0;
  if (o->coords) {
    double t0 = o->coords->time[0];
    for (int k = 0; k < N; k++) times[k] = t0 + g->T * k / (N - 1);
    if (gs_table_resample(o->coords, times, N, &rs, err, errsz) != 0) {
      status = -1;
    }
    for (int k = 0; status == 0 && k < N; k++) {
      for (int j = 0; j < nv; j++) {
        if (qcol[j] >= 0) g->q_ref[k * nv + j] = rs.data[k * rs.ncol + qcol[j]];
      }
    }
  }
  if (status == 0 && o->grf) {
    // per foot: force (3), centre of pressure (3), torque at the COP (3); OpenSim frame
    enum { kCols = 18 };
    static const char* names[kCols] = {
        "ground_force_r_vx", "ground_force_r_vy", "ground_force_r_vz", "ground_force_r_px",
        "ground_force_r_py", "ground_force_r_pz", "ground_torque_r_x", "ground_torque_r_y",
        "ground_torque_r_z", "ground_force_l_vx", "ground_force_l_vy", "ground_force_l_vz",
        "ground_force_l_px", "ground_force_l_py", "ground_force_l_pz", "ground_torque_l_x",
        "ground_torque_l_y", "ground_torque_l_z"};
    gsTable sel;
    gs_table_init(&sel);
    double t0 = o->grf->time[0];
    for (int k = 0; k < N; k++) times[k] = t0 + g->T * k / (N - 1);
    if (gs_table_select(o->grf, names, kCols, &sel, err, errsz) != 0 ||
        gs_table_resample(&sel, times, N, &rs, err, errsz) != 0) {
      status = -1;
    }
    for (int k = 0; status == 0 && k < N; k++) {
      for (int s = 0; s < 2; s++) {  // OpenSim (x, y up, z) -> world (x, -z, y)
        const double* v = rs.data + k * kCols + 9 * s;
        double f[3] = {v[0], -v[2], v[1]}, p[3] = {v[3], -v[5], v[4]}, tq[3] = {v[6], -v[8], v[7]};
        double* w = g->grf_ref + k * GO_GAIT_NGRF;
        double mom[3];
        mju_cross(mom, p, f);  // moment about the world origin: p x F + torque at the COP
        for (int c = 0; c < 3; c++) {
          w[3 * s + c] = f[c];
          w[GO_GAIT_GRM_OFFSET + 3 * s + c] = mom[c] + tq[c];
        }
      }
    }
    gs_table_free(&sel);
  }
  gs_table_free(&rs);
  free(times);
  return status;
}

// go_gait_create's phases. Each fills its part of g from the options and returns 0, or -1 with
// the reason in err; what it allocated stays in g, which go_gait_free releases.

// "out of memory" for phase what; -1
static int out_of_memory(char* err, int errsz, const char* what) {
  snprintf(err, (size_t)errsz, "go_gait_create: out of memory (%s)", what);
  return -1;
}

// the options and the model a problem can be built from
static int check_inputs(const mjModel* m0, const go_gait_opts* o, char* err, int errsz) {
  if (o->N < 2 || o->nthreads < 1) {
    snprintf(err, (size_t)errsz, "go_gait_create: need N >= 2 and nthreads >= 1");
    return -1;
  }
  if (m0->nq != m0->nv || m0->na != m0->nu || m0->nu == 0) {
    snprintf(err, (size_t)errsz, "go_gait_create: need nq == nv (no free or ball joints) and an "
             "activation state for every actuator (nq %d nv %d nu %d na %d)", m0->nq, m0->nv,
             m0->nu, m0->na);
    return -1;
  }
  if (m0->nuserdata < GS_USERDATA_SIZE(m0)) {
    snprintf(err, (size_t)errsz, "go_gait_create: model not prepared (gs_physics_prepare)");
    return -1;
  }
  if (o->coords && o->coords->nrow < 2) {
    snprintf(err, (size_t)errsz, "go_gait_create: coordinate table needs 2 rows or more");
    return -1;
  }
  if (m0->na > GO_GAIT_MAX_MUSCLES || (o->w_cot > 0 && !(o->speed > 0)) ||
      (o->free_time && !(o->T_lb > 0 && o->T_ub >= o->T_lb))) {
    snprintf(err, (size_t)errsz, "go_gait_create: at most %d muscles; a cost-of-transport goal "
             "needs a speed; free time needs 0 < T_lb <= T_ub (equal: Ipopt fixes T)",
             GO_GAIT_MAX_MUSCLES);
    return -1;
  }
  if (!(o->metabolic_smoothing > 0 && isfinite(o->metabolic_smoothing))) {
    snprintf(err, (size_t)errsz, "go_gait_create: metabolic_smoothing must be > 0");
    return -1;
  }
  if (o->fibre_bounds && !(o->fibre_lo >= 0 && o->fibre_hi > o->fibre_lo)) {
    snprintf(err, (size_t)errsz, "go_gait_create: fibre bounds need 0 <= fibre_lo < fibre_hi");
    return -1;
  }
  if (o->min_vgrf > 0 && !(o->min_vgrf < 10)) {
    snprintf(err, (size_t)errsz, "go_gait_create: min_vgrf must be below 10 body weights");
    return -1;
  }
  return 0;
}

// the private model copy (constraint stage off), stride time, weight, speed
static int setup_model(go_gait* g, const mjModel* m0, const go_gait_opts* o, char* err,
                       int errsz) {
  g->m = mj_copyModel(NULL, m0);
  if (!g->m) return out_of_memory(err, errsz, "model copy");
  g->m->opt.disableflags |= mjDSBL_CONSTRAINT;
  g->N = o->N;
  g->T = o->T > 0 ? o->T
                  : (o->coords ? o->coords->time[o->coords->nrow - 1] - o->coords->time[0] : 1.0);
  g->weight = mj_getTotalmass(g->m) * mju_norm3(g->m->opt.gravity);
  g->speed = o->speed > 0 ? o->speed : 0;
  g->nthreads = o->nthreads;
  g->free_time = o->free_time;
  return 0;
}

// muscle, activation and metabolic parameters, the elastic-tendon muscles
static int setup_muscles(go_gait* g, const go_gait_opts* o, char* err, int errsz) {
  const mjModel* m = g->m;
  int na = m->na;
  // cost of transport: integrand w_cot Edot / (m V); with J = I / T that is w_cot COT
  g->cot_scale = o->w_cot > 0 ? o->w_cot / (mj_getTotalmass(m) * g->speed) : 0;
  g->umus = (gsUmbergerMuscle*)zalloc((size_t)na, sizeof(gsUmbergerMuscle));
  g->mprm = (gsMuscleParams*)zalloc((size_t)na, sizeof(gsMuscleParams));
  g->aprm = (gsActivationParams*)zalloc((size_t)na, sizeof(gsActivationParams));
  g->elastic = (int*)zalloc((size_t)na, sizeof(int));
  g->elastic_of = (int*)zalloc((size_t)na, sizeof(int));
  if (!g->umus || !g->mprm || !g->aprm || !g->elastic || !g->elastic_of)
    return out_of_memory(err, errsz, "muscles");
  gs_umberger_smoothing_default(&g->umb_smooth);
  g->umb_smooth.w_excitation *= o->metabolic_smoothing;
  g->umb_smooth.w_length *= o->metabolic_smoothing;
  g->umb_smooth.w_velocity *= o->metabolic_smoothing;
  g->umb_smooth.w_cap *= o->metabolic_smoothing;
  g->umb_smooth.w_heat *= o->metabolic_smoothing;
  g->umb_smooth.w_force *= o->metabolic_smoothing;
  for (int i = 0; i < na; i++) {
    if (gs_umberger_muscle_from_user(m->actuator_user + i * m->nuser_actuator, &g->umus[i], NULL,
                                     0) != 0 && g->cot_scale > 0) {
      snprintf(err, (size_t)errsz, "go_gait_create: actuator %s has no metabolic parameters",
               mj_id2name(m, mjOBJ_ACTUATOR, i));
      return -1;
    }
  }
  int ne = 0;
  for (int i = 0; i < na; i++) {
    const double* user = m->actuator_user + i * m->nuser_actuator;
    char why[256];
    if (!gs_actuator_is_gaitsim_muscle(m, i) ||
        gs_muscle_params_from_user(user, &g->mprm[i], why, sizeof(why)) != 0 ||
        gs_activation_params_from_user(user, &g->aprm[i], why, sizeof(why)) != 0) {
      snprintf(err, (size_t)errsz, "go_gait_create: actuator %s is not a valid gaitsim muscle",
               mj_id2name(m, mjOBJ_ACTUATOR, i));
      return -1;
    }
    g->elastic_of[i] = g->mprm[i].elastic ? ne : -1;
    if (g->mprm[i].elastic) g->elastic[ne++] = i;
  }
  g->L.ne = ne;
  return 0;
}

// where everything sits in z_k and in the path rows (go_gait_layout); the ground reaction
// moments are variables (and rows) only when tracked
static int setup_layout(go_gait* g, const go_gait_opts* o, char* err, int errsz) {
  const mjModel* m = g->m;
  go_gait_layout* L = &g->L;
  int nv = m->nv, na = m->na, ne = L->ne;
  L->ngrf = o->grf && o->w_grm > 0 ? GO_GAIT_NGRF : GO_GAIT_GRM_OFFSET;
  L->nv = nv;
  L->na = na;
  L->nx = 2 * nv + na + ne;
  L->x_q = 0;
  L->x_qd = nv;
  L->x_a = 2 * nv;
  L->x_ft = 2 * nv + na;
  L->xd_q = L->nx;
  L->xd_qdd = L->nx + nv;
  L->xd_a = L->nx + 2 * nv;
  L->xd_ft = L->nx + 2 * nv + na;
  L->u_e = 2 * L->nx;
  L->u_grf = 2 * L->nx + na;
  L->nz = 2 * L->nx + na + L->ngrf;
  L->r_link = 0;
  L->r_eom = nv;
  L->r_hill = 2 * nv;
  L->r_act = 2 * nv + ne;
  L->r_grf = 2 * nv + ne + na;
  L->n_path = 2 * nv + ne + na + L->ngrf;
  L->r_fib = -1;
  if (o->fibre_bounds) {
    L->r_fib = L->n_path;
    L->n_path += na;
  }
  L->r_walk = -1;
  if (o->min_vgrf > 0) {
    L->r_walk = L->n_path;
    L->n_path += 1;
  }
  L->elastic = g->elastic;
  L->elastic_of = g->elastic_of;
  L->tx = -1;
  int jtx = mj_name2id(m, mjOBJ_JOINT, "pelvis_tx");
  if (jtx >= 0) L->tx = m->jnt_dofadr[jtx];
  if (g->speed > 0 && L->tx < 0) {
    snprintf(err, (size_t)errsz, "go_gait_create: a speed constraint needs a pelvis_tx coordinate");
    return -1;
  }
  return 0;
}

// structure: which dofs each muscle crosses, mass matrix branches, foot chains, and the path
// pattern they give (columns x_a and beyond analytic)
static int setup_structure(go_gait* g, const go_gait_opts* o, const int* qcol, char* err,
                           int errsz) {
  const mjModel* m = g->m;
  int nv = m->nv, na = m->na, nz = g->L.nz;
  g->cross = (unsigned char*)zalloc((size_t)na * nv, 1);
  g->tree = (unsigned char*)zalloc((size_t)nv * nv, 1);
  g->foot = (unsigned char*)zalloc((size_t)2 * nv, 1);
  if (!g->cross || !g->tree || !g->foot || crossing(g, o->coords, qcol) != 0)
    return out_of_memory(err, errsz, "structure");
  for (int a = 0; a < nv; a++) {
    for (int b = 0; b < nv; b++) {
      g->tree[a * nv + b] = dof_ancestor(m, a, b) || dof_ancestor(m, b, a);
    }
  }
  for (int geom = 0; geom < m->ngeom; geom++) {
    int side = gs_geom_contact_side(m, geom);
    if (!side) continue;
    for (int b = m->geom_bodyid[geom]; b > 0; b = m->body_parentid[b]) {
      for (int j = m->body_dofadr[b]; j < m->body_dofadr[b] + m->body_dofnum[b]; j++) {
        g->foot[(side == 'r' ? 0 : 1) * nv + j] = 1;
      }
    }
  }
  int nnz = pattern(g, NULL, NULL);
  g->col_ptr = (int*)zalloc((size_t)nz + 1, sizeof(int));
  g->row_idx = (int*)zalloc((size_t)nnz, sizeof(int));
  g->analytic = (unsigned char*)zalloc((size_t)nz, 1);
  if (!g->col_ptr || !g->row_idx || !g->analytic) return out_of_memory(err, errsz, "pattern");
  pattern(g, g->col_ptr, g->row_idx);
  for (int c = g->L.x_a; c < nz; c++) {
    g->analytic[c] = 1;
  }
  return 0;
}

// the measured data at the node times, the tracking weights and the integrand's variables
static int setup_tracking(go_gait* g, const go_gait_opts* o, const int* qcol, char* err,
                          int errsz) {
  const mjModel* m = g->m;
  const go_gait_layout* L = &g->L;
  int nv = L->nv, na = L->na, nz = L->nz;
  g->q_ref = (double*)zalloc((size_t)g->N * nv, sizeof(double));
  g->grf_ref = (double*)zalloc((size_t)g->N * GO_GAIT_NGRF, sizeof(double));
  g->q_wt = (double*)zalloc((size_t)nv, sizeof(double));
  g->ivars = (int*)zalloc((size_t)nz, sizeof(int));
  if (!g->q_ref || !g->grf_ref || !g->q_wt || !g->ivars)
    return out_of_memory(err, errsz, "tracking data");
  if (references(g, o, qcol, err, errsz) != 0) return -1;
  int count[3] = {0, 0, 0};  // pelvis rotations, pelvis translations, others
  for (int j = 0; j < nv; j++) {
    if (qcol[j] < 0) continue;
    int slide = m->jnt_type[m->dof_jntid[j]] == mjJNT_SLIDE;
    count[go_gait_dof_is_root(m, j) ? (slide ? 1 : 0) : 2]++;
  }
  for (int j = 0; j < nv; j++) {
    if (qcol[j] < 0) continue;
    int slide = m->jnt_type[m->dof_jntid[j]] == mjJNT_SLIDE;
    int grp = go_gait_dof_is_root(m, j) ? (slide ? 1 : 0) : 2;
    double w = grp == 0 ? o->w_pelvis_rot : grp == 1 ? o->w_pelvis_trans : o->w_joint;
    double sc = slide ? TR_TRANS : TR_ROT;
    g->q_wt[j] = w / (sc * sc) / count[grp];
  }
  double grf_sc = TR_GRF * g->weight;
  double grm_sc = grf_sc * GO_GAIT_GRM_LENGTH;
  for (int c = 0; c < GO_GAIT_NGRF; c++) {
    int moment = c >= GO_GAIT_GRM_OFFSET;
    double w = moment ? o->w_grm : o->w_grf, sc = moment ? grm_sc : grf_sc;
    g->grf_wt[c] = o->grf && w > 0 && c < L->ngrf ? w / (sc * sc) / L->ngrf : 0;
  }
  g->w_effort = o->w_effort / na;
  g->w_accel = o->w_accel > 0 ? o->w_accel / (GO_GAIT_ACCEL_SCALE * GO_GAIT_ACCEL_SCALE) / nv : 0;
  for (int j = 0; j < nv; j++) {
    if (g->q_wt[j] > 0) g->ivars[g->n_ivars++] = L->x_q + j;
  }
  if (g->cot_scale > 0) {  // the metabolic integrand reads q, qdot, a and fT as well
    for (int j = 0; j < nv; j++)
      if (!(g->q_wt[j] > 0)) g->ivars[g->n_ivars++] = L->x_q + j;
    for (int j = 0; j < nv; j++) g->ivars[g->n_ivars++] = L->x_qd + j;
    for (int i = 0; i < na; i++) g->ivars[g->n_ivars++] = L->x_a + i;
    for (int e = 0; e < L->ne; e++) g->ivars[g->n_ivars++] = L->x_ft + e;
  }
  for (int i = 0; i < na; i++) g->ivars[g->n_ivars++] = L->u_e + i;
  for (int c = 0; c < L->ngrf; c++) {
    if (g->grf_wt[c] > 0) g->ivars[g->n_ivars++] = L->u_grf + c;
  }
  if (g->w_accel > 0) {
    for (int j = 0; j < nv; j++) g->ivars[g->n_ivars++] = L->xd_qdd + j;
  }
  return 0;
}

// variable bounds and scales, path row scales and bounds
static int setup_bounds(go_gait* g, const go_gait_opts* o, char* err, int errsz) {
  const mjModel* m = g->m;
  const go_gait_layout* L = &g->L;
  int nv = L->nv, na = L->na, ne = L->ne, nz = L->nz;
  g->z_lb = (double*)zalloc((size_t)nz, sizeof(double));
  g->z_ub = (double*)zalloc((size_t)nz, sizeof(double));
  g->z_scale = (double*)zalloc((size_t)nz, sizeof(double));
  g->path_scale = (double*)zalloc((size_t)L->n_path, sizeof(double));
  g->path_lb = (double*)zalloc((size_t)L->n_path, sizeof(double));
  g->path_ub = (double*)zalloc((size_t)L->n_path, sizeof(double));
  if (!g->z_lb || !g->z_ub || !g->z_scale || !g->path_scale || !g->path_lb || !g->path_ub)
    return out_of_memory(err, errsz, "bounds");
  for (int j = 0; j < nv; j++) {
    int jnt = m->dof_jntid[j];
    int slide = m->jnt_type[jnt] == mjJNT_SLIDE;
    double lo = -M_PI, hi = M_PI;
    if (m->jnt_limited[jnt]) {
      lo = m->jnt_range[2 * jnt];
      hi = m->jnt_range[2 * jnt + 1];
    } else if (go_gait_dof_is_root(m, j)) {
      double mn = HUGE_VAL, mx = -HUGE_VAL;
      for (int k = 0; k < g->N; k++) {
        double v = g->q_ref[k * nv + j];
        if (isfinite(v)) {
          mn = fmin(mn, v);
          mx = fmax(mx, v);
        }
      }
      double margin = 0.5;
      lo = isfinite(mn) ? mn - margin : (slide ? -10 : -M_PI);
      hi = isfinite(mx) ? mx + margin : (slide ? 10 : M_PI);
    }
    g->z_lb[L->x_q + j] = lo;
    g->z_ub[L->x_q + j] = hi;
    g->z_scale[L->x_q + j] = SC_Q;
    g->z_lb[L->x_qd + j] = g->z_lb[L->xd_q + j] = -20;
    g->z_ub[L->x_qd + j] = g->z_ub[L->xd_q + j] = 20;
    g->z_scale[L->x_qd + j] = g->z_scale[L->xd_q + j] = SC_QD;
    g->z_lb[L->xd_qdd + j] = -500;
    g->z_ub[L->xd_qdd + j] = 500;
    g->z_scale[L->xd_qdd + j] = SC_QDD;
  }
  for (int i = 0; i < na; i++) {
    g->z_lb[L->x_a + i] = g->z_lb[L->u_e + i] = GS_ACTIVATION_MIN;
    g->z_ub[L->x_a + i] = g->z_ub[L->u_e + i] = GS_ACTIVATION_MAX;
    g->z_scale[L->x_a + i] = g->z_scale[L->u_e + i] = 1;
    g->z_lb[L->xd_a + i] = -1000;
    g->z_ub[L->xd_a + i] = 1000;
    g->z_scale[L->xd_a + i] = SC_ADOT;
  }
  for (int e = 0; e < ne; e++) {
    g->z_lb[L->x_ft + e] = 0;
    g->z_ub[L->x_ft + e] = 5;
    g->z_scale[L->x_ft + e] = 1;
    g->z_lb[L->xd_ft + e] = -1000;
    g->z_ub[L->xd_ft + e] = 1000;
    g->z_scale[L->xd_ft + e] = SC_FTDOT;
  }
  for (int c = 0; c < L->ngrf; c++) {  // forces: m g; moments: m g x 1 m
    g->z_lb[L->u_grf + c] = -10 * g->weight;
    g->z_ub[L->u_grf + c] = 10 * g->weight;
    g->z_scale[L->u_grf + c] = g->weight;
  }
  for (int j = 0; j < nv; j++) {
    g->path_scale[L->r_link + j] = SC_QD;
    g->path_scale[L->r_eom + j] = g->weight;  // m g x 1 m (N m), or N for slides
  }
  for (int e = 0; e < ne; e++) g->path_scale[L->r_hill + e] = 1;
  for (int i = 0; i < na; i++) g->path_scale[L->r_act + i] = SC_ADOT;
  for (int c = 0; c < L->ngrf; c++) g->path_scale[L->r_grf + c] = g->weight;
  for (int i = 0; L->r_fib >= 0 && i < na; i++) {
    g->path_scale[L->r_fib + i] = 1;  // lM / lopt: O(1)
    g->path_lb[L->r_fib + i] = o->fibre_lo;
    g->path_ub[L->r_fib + i] = o->fibre_hi;
  }
  if (L->r_walk >= 0) {
    g->path_scale[L->r_walk] = g->weight;
    g->path_lb[L->r_walk] = o->min_vgrf * g->weight;
    g->path_ub[L->r_walk] = 1e19;  // none (scale_bound: Ipopt's infinity)
  }
  return 0;
}

// boundary rows and their pattern: periodic states (but pelvis_tx and free coordinates),
// excitations, speed; periodic (nz) is scratch
static int setup_boundary(go_gait* g, const go_gait_opts* o, unsigned char* periodic, char* err,
                          int errsz) {
  const mjModel* m = g->m;
  const go_gait_layout* L = &g->L;
  int na = L->na, nz = L->nz;
  if (o->periodic) {
    for (int v = 0; v < L->nx; v++) periodic[v] = 1;
    for (int i = 0; i < na; i++) periodic[L->u_e + i] = 1;
    if (L->tx >= 0) periodic[L->x_q + L->tx] = 0;
    for (int f = 0; o->free_coords && o->free_coords[f]; f++) {
      int jnt = mj_name2id(m, mjOBJ_JOINT, o->free_coords[f]);
      if (jnt < 0) {
        snprintf(err, (size_t)errsz, "go_gait_create: free coordinate %s is not in the model",
                 o->free_coords[f]);
        return -1;
      }
      periodic[L->x_q + m->jnt_dofadr[jnt]] = 0;
    }
  }
  int nb = 0;
  for (int v = 0; v < nz; v++) nb += periodic[v];
  g->n_bnd = nb + (g->speed > 0);
  g->bnd_var = (int*)zalloc((size_t)g->n_bnd, sizeof(int));
  g->bnd_scale = (double*)zalloc((size_t)g->n_bnd, sizeof(double));
  g->bnd_col_ptr = (int*)zalloc((size_t)2 * nz + 2, sizeof(int));
  g->bnd_row_idx = (int*)zalloc((size_t)2 * g->n_bnd + 2, sizeof(int));
  int* row_of = (int*)zalloc((size_t)nz, sizeof(int));
  if (!g->bnd_var || !g->bnd_scale || !g->bnd_col_ptr || !g->bnd_row_idx || !row_of) {
    free(row_of);
    return out_of_memory(err, errsz, "boundary");
  }
  nb = 0;
  for (int v = 0; v < nz; v++) {
    row_of[v] = -1;
    if (periodic[v]) {
      row_of[v] = nb;
      g->bnd_var[nb] = v;
      g->bnd_scale[nb++] = g->z_scale[v];
    }
  }
  if (g->speed > 0) {
    g->bnd_var[nb] = -1;
    g->bnd_scale[nb] = 1.0;
  }
  int nbe = 0;
  for (int half = 0; half < 2; half++) {
    for (int v = 0; v < nz; v++) {
      g->bnd_col_ptr[half * nz + v] = nbe;
      if (row_of[v] >= 0) g->bnd_row_idx[nbe++] = row_of[v];
      if (g->speed > 0 && v == L->x_q + L->tx) g->bnd_row_idx[nbe++] = nb;
    }
  }
  g->bnd_col_ptr[2 * nz] = nbe;
  if (g->free_time && g->speed > 0) g->bnd_row_idx[nbe++] = nb;  // speed row: T column
  g->bnd_col_ptr[2 * nz + 1] = nbe;
  free(row_of);
  return 0;
}

// worker contexts: one mjData and scratch per engine worker
static int setup_workers(go_gait* g, char* err, int errsz) {
  int nv = g->L.nv, na = g->L.na, nz = g->L.nz;
  g->ctx = (gait_ctx*)zalloc((size_t)g->nthreads, sizeof(gait_ctx));
  g->ctx_ptr = (void**)zalloc((size_t)g->nthreads, sizeof(void*));
  if (!g->ctx || !g->ctx_ptr) return out_of_memory(err, errsz, "workers");
  for (int w = 0; w < g->nthreads; w++) {
    g->ctx[w].g = g;
    g->ctx[w].d = mj_makeData(g->m);
    g->ctx[w].M = (double*)zalloc((size_t)nv * nv, sizeof(double));
    g->ctx[w].P = (double*)zalloc((size_t)na, sizeof(double));
    g->ctx[w].Pm = (double*)zalloc((size_t)na, sizeof(double));
    g->ctx[w].zp = (double*)zalloc((size_t)nz, sizeof(double));
    g->ctx[w].mus = (double*)zalloc((size_t)4 * na, sizeof(double));
    g->ctx[w].mom = (double*)zalloc((size_t)na * nv, sizeof(double));
    g->ctx[w].dmom = (double*)zalloc((size_t)na * nv, sizeof(double));
    g->ctx[w].pos_q = (double*)zalloc((size_t)nv, sizeof(double));
    g->ctx[w].hz = (double*)zalloc((size_t)3 * nz, sizeof(double));
    g->ctx_ptr[w] = &g->ctx[w];
    if (!g->ctx[w].d || !g->ctx[w].M || !g->ctx[w].P || !g->ctx[w].Pm || !g->ctx[w].zp ||
        !g->ctx[w].mus || !g->ctx[w].mom || !g->ctx[w].dmom || !g->ctx[w].pos_q || !g->ctx[w].hz)
      return out_of_memory(err, errsz, "workers");
  }
  return 0;
}

// g->obj_mask: the metabolic power's possible Hessian entries, both triangles. Muscle i's power
// reads its a_i, e_i, fT_i (elastic tendon) and the coordinates and speeds of the dofs it
// crosses, so every pair among those. 0, or -1 out of memory.
static int metabolic_mask(go_gait* g) {
  const go_gait_layout* L = &g->L;
  int nz = L->nz, nv = L->nv;
  g->obj_mask = (unsigned char*)zalloc((size_t)nz * (size_t)nz, 1);
  int* V = (int*)zalloc((size_t)(2 * nv + 3), sizeof(int));
  if (!g->obj_mask || !V) {
    free(V);
    return -1;
  }
  for (int j = 0; j < nz; j++) g->obj_mask[(size_t)j * nz + j] = 1;  // the squares
  for (int i = 0; i < L->na; i++) {
    int n = 0;
    for (int j = 0; j < nv; j++)
      if (g->cross[i * nv + j]) V[n++] = L->x_q + j, V[n++] = L->x_qd + j;
    V[n++] = L->x_a + i;
    V[n++] = L->u_e + i;
    if (L->elastic_of[i] >= 0) V[n++] = L->x_ft + L->elastic_of[i];
    for (int a = 0; a < n; a++)
      for (int b = 0; b < n; b++) g->obj_mask[(size_t)V[a] * nz + V[b]] = 1;
  }
  free(V);
  return 0;
}

// eq. 3's band [centre - half, centre + half] of variable var at node k intersected with the
// variable's bounds z_lb, z_ub (setup_bounds: the joint ranges); the bounds alone where the two
// do not overlap (a centre more than half outside its range)
static go_bound_override band_within_bounds(const go_gait* g, int k, int var, double centre,
                                           double half) {
  double lo = fmax(centre - half, g->z_lb[var]), hi = fmin(centre + half, g->z_ub[var]);
  if (lo > hi) lo = g->z_lb[var], hi = g->z_ub[var];
  return (go_bound_override){k, var, lo, hi};
}

// the NLP (go_collocation.h) with eq. 3's band as bound overrides, and the Hessian elements
static int setup_nlp(go_gait* g, const go_gait_opts* o, char* err, int errsz) {
  const go_gait_layout* L = &g->L;
  int nv = L->nv, na = L->na, nz = L->nz;
  go_problem p;
  memset(&p, 0, sizeof(p));
  p.dims = (go_dims){g->N, L->nx, na + L->ngrf, L->n_path, g->n_bnd, g->free_time};
  p.z_lb = g->z_lb;
  p.z_ub = g->z_ub;
  p.T = g->T;
  p.T_lb = o->T_lb;
  p.T_ub = o->T_ub;
  p.T_scale = g->T;
  // eq. 3 of Lin, Walter & Pandy 2018: q and qdot within a band around a given solution, and
  // within the variable's own bounds (the joint ranges of setup_bounds): each override is the
  // band intersected with them, or the bounds alone where the band lies outside them
  if (o->band_z) {
    g->band = (go_bound_override*)zalloc((size_t)4 * g->N * nv, sizeof(go_bound_override));
    if (!g->band) return out_of_memory(err, errsz, "band");
    for (int k = 0; k < g->N; k++) {
      const double* zk = o->band_z + (size_t)k * nz;
      for (int j = 0; j < nv; j++) {
        if (o->band_q && o->band_q[j] > 0 && j != L->tx)
          g->band[g->n_band++] = band_within_bounds(g, k, L->x_q + j, zk[L->x_q + j], o->band_q[j]);
        if (o->band_qd && o->band_qd[j] > 0)
          g->band[g->n_band++] =
              band_within_bounds(g, k, L->x_qd + j, zk[L->x_qd + j], o->band_qd[j]);
      }
    }
    p.overrides = g->band;
    p.n_overrides = g->n_band;
  }
  p.z_scale = g->z_scale;
  p.path_scale = g->path_scale;
  p.boundary_scale = g->bnd_scale;
  p.obj_scale = 1.0;
  p.path = path_cb;
  p.path_lb = g->path_lb;
  p.path_ub = g->path_ub;
  p.path_col_ptr = g->col_ptr;
  p.path_row_idx = g->row_idx;
  p.path_jac = path_jac_cb;
  p.path_analytic = g->analytic;
  p.integrand = integrand_cb;
  p.integrand_vars = g->ivars;
  p.n_integrand_vars = g->n_ivars;
  p.integrand_grad = integrand_grad_cb;
  p.integrand_hess = integrand_hess_cb;
  if (g->cot_scale > 0) {  // the metabolic power's mixed curvature, for the exact Hessian
    if (metabolic_mask(g) != 0) return out_of_memory(err, errsz, "metabolic Hessian pattern");
    p.integrand_hess_block = integrand_hess_block_cb;
    p.integrand_hess_mask = g->obj_mask;
  }
  p.outer = outer_cb;
  p.boundary = g->n_bnd > 0 ? boundary_cb : NULL;
  p.bnd_col_ptr = g->bnd_col_ptr;
  p.bnd_row_idx = g->bnd_row_idx;
  p.thread_ctx = g->ctx_ptr;
  p.nthreads = g->nthreads;
  if (go_nlp_create(&g->nlp, &p, err, errsz) != 0) return -1;
  if (build_elements(g) != 0) return out_of_memory(err, errsz, "Hessian elements");
  return 0;
}

int go_gait_create(go_gait** out, const mjModel* m0, const go_gait_opts* o, char* err,
                   int errsz) {
  *out = NULL;
  if (check_inputs(m0, o, err, errsz) != 0) return -1;
  go_gait* g = (go_gait*)calloc(1, sizeof(go_gait));
  if (!g) return out_of_memory(err, errsz, "problem");
  // scratch of the phases: the coordinate column of each dof (nv), the periodic variables (nz)
  int* qcol = NULL;
  unsigned char* periodic = NULL;
  int rc = setup_model(g, m0, o, err, errsz);
  if (rc == 0) rc = setup_muscles(g, o, err, errsz);
  if (rc == 0) rc = setup_layout(g, o, err, errsz);
  if (rc == 0) {
    qcol = (int*)zalloc((size_t)g->L.nv, sizeof(int));
    periodic = (unsigned char*)zalloc((size_t)g->L.nz, 1);
    if (!qcol || !periodic) rc = out_of_memory(err, errsz, "scratch");
    else coord_columns(g->m, o->coords, qcol);
  }
  if (rc == 0) rc = setup_structure(g, o, qcol, err, errsz);
  if (rc == 0) rc = setup_tracking(g, o, qcol, err, errsz);
  if (rc == 0) rc = setup_bounds(g, o, err, errsz);
  if (rc == 0) rc = setup_boundary(g, o, periodic, err, errsz);
  if (rc == 0) rc = setup_workers(g, err, errsz);
  if (rc == 0) rc = setup_nlp(g, o, err, errsz);
  free(qcol);
  free(periodic);
  if (rc != 0) {
    go_gait_free(g);
    return -1;
  }
  *out = g;
  return 0;
}
