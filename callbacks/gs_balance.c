// gs_balance.c: frontal-plane balance by inverse dynamics (equations in gs_balance.h).
#include "callbacks/gs_balance.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_model_info.h"
#include "callbacks/gs_tendon_paths.h"

static int find(const mjModel* m, int type, const char* name, int* id, char* err, int errsz) {
  *id = mj_name2id(m, type, name);
  if (*id < 0) snprintf(err, (size_t)errsz, "no %s \"%s\" (the balance needs it)",
                        type == mjOBJ_BODY ? "body" : "joint", name);
  return *id < 0 ? -1 : 0;
}

int gs_balance_spec(const mjModel* m, gsBalanceSpec* spec, char* err, int errsz) {
  if (find(m, mjOBJ_BODY, "pelvis", &spec->root_body, err, errsz) ||
      find(m, mjOBJ_BODY, "torso", &spec->trunk_body, err, errsz) ||
      find(m, mjOBJ_JOINT, "hip_adduction", &spec->hip_joint[0], err, errsz) ||
      find(m, mjOBJ_JOINT, "hip_adduction_l", &spec->hip_joint[1], err, errsz))
    return -1;
  spec->lumbar_bending = mj_name2id(m, mjOBJ_JOINT, "lumbar_bending");
  spec->knee_adduction[0] = mj_name2id(m, mjOBJ_JOINT, "knee_adduction");
  spec->knee_adduction[1] = mj_name2id(m, mjOBJ_JOINT, "knee_adduction_l");
  spec->ankle_joint[0] = mj_name2id(m, mjOBJ_JOINT, "ankle_angle");
  spec->ankle_joint[1] = mj_name2id(m, mjOBJ_JOINT, "ankle_angle_l");
  for (int s = 0; s < 2; s++) {
    spec->foot_body[s] = -1;
    for (int g = 0; g < m->ngeom && spec->foot_body[s] < 0; g++)
      if (gs_geom_contact_side(m, g) == (s == 0 ? 'r' : 'l')) spec->foot_body[s] = m->geom_bodyid[g];
    if (spec->foot_body[s] < 0) {
      snprintf(err, (size_t)errsz, "no contact sphere on the %s foot (contact_%c_<k>)",
               s == 0 ? "right" : "left", s == 0 ? 'r' : 'l');
      return -1;
    }
  }
  return 0;
}

void gs_balance_from_opensim(const double os[3], double world[3]) {
  double x = os[0], y = os[1], z = os[2];
  world[0] = x;
  world[1] = -z;
  world[2] = y;
}

// the ground reaction's part of knee s's moment and its pieces in the knee's frame (gs_balance.h)
static void knee_frame(const mjData* d, const gsBalanceSpec* spec, int s, const gsFootLoad* load,
                       const mjtNum* ext, const mjModel* m, gsBalance* out) {
  out->knee_grf_moment[s] = out->cop_lateral_knee[s] = out->knee_lateral_force[s] = NAN;
  out->knee_axial_force[s] = out->knee_lateral_tilt[s] = NAN;
  int knee = spec->knee_adduction[s], ankle = spec->ankle_joint[s];
  if (knee < 0 || ankle < 0 || !load->loaded) return;
  const double* a = d->xaxis + 3 * knee;
  const double* k = d->xanchor + 3 * knee;
  double u[3], l[3], r[3];
  mju_sub3(u, k, d->xanchor + 3 * ankle);
  mju_addToScl3(u, a, -mju_dot3(u, a));
  mju_normalize3(u);
  mju_cross(l, a, u);
  if ((s == 0 ? -l[1] : l[1]) < 0) mju_scl3(l, l, -1);  // lateral: -y right, +y left
  mju_sub3(r, load->cop, k);
  out->knee_grf_moment[s] = -ext[m->jnt_dofadr[knee]];
  out->cop_lateral_knee[s] = mju_dot3(r, l);
  out->knee_lateral_force[s] = mju_dot3(load->force, l);
  out->knee_axial_force[s] = mju_dot3(load->force, u);
  out->knee_lateral_tilt[s] = asin(l[2]);
}

void gs_balance_eval(const mjModel* m, mjData* d, const gsBalanceSpec* spec, const double* qacc,
                     const gsFootLoad load[2], gsBalance* out) {
  gs_balance_eval_tau(m, d, spec, qacc, load, out, NULL);
}

void gs_balance_eval_tau(const mjModel* m, mjData* d, const gsBalanceSpec* spec,
                         const double* qacc, const gsFootLoad load[2], gsBalance* out,
                         double* tau_out) {
  gs_fwd_position(m, d);  // kinematics, centres of mass, M (d->qM); tendons finite
  mj_fwdVelocity(m, d);  // c (d->qfrc_bias), body velocities
  mj_subtreeVel(m, d);
  const double* com = d->subtree_com + 3 * spec->root_body;
  mju_copy3(out->com, com);
  mju_copy3(out->angmom, d->subtree_angmom + 3 * spec->root_body);

  // tau = M qdd + c - sum J^T [F; T]
  mjMARKSTACK;
  mjtNum* tau = mj_stackAlloc(d, m->nv);
  mjtNum* ext = mj_stackAlloc(d, m->nv);
  mju_copy(d->qacc, qacc, m->nv);
  mj_mulM(m, d, tau, d->qacc);
  mju_addTo(tau, d->qfrc_bias, m->nv);
  mju_zero(ext, m->nv);
  mju_zero3(out->grf_moment);
  for (int s = 0; s < 2; s++) {
    const double* hip = d->xanchor + 3 * spec->hip_joint[s];
    double side = s == 0 ? -1.0 : 1.0;  // lateral: -y right, +y left
    out->cop_lateral_hip[s] = out->cop_lateral_com[s] = NAN;
    out->cop_foot_forward[s] = out->cop_foot_lateral[s] = NAN;
    if (!load[s].loaded) continue;
    const double* xmat = d->xmat + 9 * spec->foot_body[s];
    double rf[3], fwd[3] = {xmat[0], xmat[3], xmat[6]}, lat[3] = {xmat[2], xmat[5], xmat[8]};
    mju_sub3(rf, load[s].cop, d->xpos + 3 * spec->foot_body[s]);
    out->cop_foot_forward[s] = (fwd[0] < 0 ? -1 : 1) * mju_dot3(rf, fwd);
    out->cop_foot_lateral[s] = (side * lat[1] < 0 ? -1 : 1) * mju_dot3(rf, lat);
    mj_applyFT(m, d, load[s].force, load[s].torque, load[s].cop, spec->foot_body[s], ext);
    double r[3], rxf[3];
    mju_sub3(r, load[s].cop, com);
    mju_cross(rxf, r, load[s].force);
    for (int k = 0; k < 3; k++) out->grf_moment[k] += rxf[k] + load[s].torque[k];
    out->cop_lateral_hip[s] = side * (load[s].cop[1] - hip[1]);
    out->cop_lateral_com[s] = side * (load[s].cop[1] - com[1]);
  }
  for (int s = 0; s < 2; s++) knee_frame(d, spec, s, &load[s], ext, m, out);
  mju_subFrom(tau, ext, m->nv);
  for (int s = 0; s < 2; s++) {
    out->hip_adduction_moment[s] = tau[m->jnt_dofadr[spec->hip_joint[s]]];
    int knee = spec->knee_adduction[s];
    out->knee_adduction_moment[s] = knee >= 0 ? tau[m->jnt_dofadr[knee]] : NAN;
  }
  if (tau_out) mju_copy(tau_out, tau, m->nv);
  // the root's six dofs: pelvis_tx, _ty, _tz (slides) then pelvis_rz, _rx, _ry (hinges)
  int r0 = m->body_dofadr[spec->root_body], six = m->body_dofnum[spec->root_body] == 6;
  for (int k = 0; k < 3; k++) {
    out->residual_force[k] = six ? tau[r0 + k] : NAN;
    out->residual_moment[k] = six ? tau[r0 + 3 + k] : NAN;
  }
  mjFREESTACK;
  out->trunk_lateral = d->subtree_com[3 * spec->trunk_body + 1] - com[1];
  out->lumbar_bending =
      spec->lumbar_bending >= 0 ? d->qpos[m->jnt_qposadr[spec->lumbar_bending]] : NAN;
}

int gs_balance_grf_columns(const gsTable* g, int col[GS_GRF_NCOL], char* err, int errsz) {
  for (int k = 0; k < GS_GRF_NCOL; k++) {
    col[k] = gs_table_column(g, gs_grf_labels[k]);
    if (col[k] < 0) {
      snprintf(err, (size_t)errsz, "no column %s (OpenSim ExternalLoads names expected)",
               gs_grf_labels[k]);
      return -1;
    }
  }
  return 0;
}

void gs_balance_loads_at(const gsTable* g, const int col[GS_GRF_NCOL], double time,
                         double stance_n, gsFootLoad load[2]) {
  for (int s = 0; s < 2; s++) {
    double v[9];
    for (int k = 0; k < 9; k++) v[k] = gs_table_value_at(g, col[9 * s + k], time);
    gs_balance_from_opensim(v, load[s].force);
    gs_balance_from_opensim(v + 3, load[s].cop);
    gs_balance_from_opensim(v + 6, load[s].torque);
    load[s].loaded = load[s].force[2] > stance_n;
  }
}

