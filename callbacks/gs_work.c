// gs_work.c: the mechanical power budget at one instant. Equations and sources in gs_work.h.
#include "callbacks/gs_work.h"

#include <string.h>

#include "callbacks/gs_coupling.h"
#include "callbacks/gs_joint_limits.h"
#include "callbacks/gs_knee.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_physics.h"

static void split(double x, double* pos, double* neg) {
  if (x > 0) {
    *pos += x;
  } else {
    *neg += x;
  }
}

// power of the generalised force d->qfrc_passive, then zeroes it for the next piece
static double take_passive(const mjModel* m, mjData* d) {
  double p = mju_dot(d->qfrc_passive, d->qvel, m->nv);
  mju_zero(d->qfrc_passive, m->nv);
  return p;
}

void gs_work_powers(const mjModel* m, mjData* d, gsPowers* p) {
  memset(p, 0, sizeof(*p));
  int nv = m->nv;
  mjMARKSTACK;

  // actuators: P = actuator_force * actuator_velocity, the same as qfrc_actuator . qvel
  for (int i = 0; i < m->nu; i++) {
    double pu = d->actuator_force[i] * d->actuator_velocity[i];
    if (!gs_actuator_is_gaitsim_muscle(m, i)) {
      p->other_actuators += pu;
      continue;
    }
    gsMuscleOut mo;
    gs_physics_muscle_tension(m, d, i, &mo);
    double ce = -mo.f_active * mo.vM;
    double pe = -(mo.f_passive + mo.f_damping) * mo.vM;
    split(pu, &p->mtu_pos, &p->mtu_neg);
    split(ce, &p->ce_pos, &p->ce_neg);
    p->fibre_passive += pe;
    p->tendon += pu - ce - pe;
  }

  // passive pieces: each of gaitsim's callbacks alone on a zeroed qfrc_passive; MuJoCo's own
  // passive forces are what remains of the whole
  mjtNum* whole = mj_stackAlloc(d, nv);
  mju_copy(whole, d->qfrc_passive, nv);
  double all = mju_dot(whole, d->qvel, nv), ours = 0;
  mju_zero(d->qfrc_passive, nv);
  // each foot: its spheres' forces applied as gs_physics_contact_passive applies them, and
  // their normal forces' power -Fn d' from the same evaluation
  const int sides[2] = {'r', 'l'};
  const mjtNum zero[3] = {0, 0, 0};
  for (int s = 0; s < 2; s++) {
    double normal = 0;
    for (int g = 0; g < m->ngeom; g++) {
      gsContactOut co;
      if (gs_geom_contact_side(m, g) != sides[s] || !gs_physics_sphere_contact(m, d, g, &co))
        continue;
      mjtNum force[3] = {co.force[0], co.force[1], co.force[2]};
      mjtNum point[3] = {co.point[0], co.point[1], co.point[2]};
      mj_applyFT(m, d, force, zero, point, m->geom_bodyid[g], d->qfrc_passive);
      double pn = -co.normal_force * co.depth_rate;
      split(pn, &p->foot_normal_pos, &p->foot_normal_neg);
      normal += pn;
    }
    double pf = take_passive(m, d);
    split(pf, &p->foot_pos, &p->foot_neg);
    ours += pf;
    p->foot_friction += pf - normal;
  }
  gs_knee_passive(m, d, NULL);
  p->knee = take_passive(m, d);
  gs_joint_limits_passive(m, d);
  p->joint_limits = take_passive(m, d);
  gs_coupling_passive(m, d);
  p->couplings = take_passive(m, d);
  ours += p->knee + p->joint_limits + p->couplings;
  p->mujoco_passive = all - ours;
  mju_copy(d->qfrc_passive, whole, nv);

  p->constraint = mju_dot(d->qfrc_constraint, d->qvel, nv);
  // applied forces: qfrc_applied plus xfrc_applied mapped to joint space
  mjtNum* applied = mj_stackAlloc(d, nv);
  mju_copy(applied, d->qfrc_applied, nv);
  for (int b = 1; b < m->nbody; b++) {
    const mjtNum* f = d->xfrc_applied + 6 * b;
    if (f[0] || f[1] || f[2] || f[3] || f[4] || f[5]) {
      mj_applyFT(m, d, f, f + 3, d->xipos + 3 * b, b, applied);
    }
  }
  p->applied = mju_dot(applied, d->qvel, nv);

  // energies: KE = qdot' M qdot / 2 (qM from mj_crb), PE = -m_total g . c_com (world subtree)
  mjtNum* mv = mj_stackAlloc(d, nv);
  mj_mulM(m, d, mv, d->qvel);
  p->kinetic = 0.5 * mju_dot(mv, d->qvel, nv);
  mj_subtreeVel(m, d);
  double mass = m->body_subtreemass[0];
  p->potential = -mass * mju_dot3(m->opt.gravity, d->subtree_com);
  p->gravity = mass * mju_dot3(m->opt.gravity, d->subtree_linvel);
  mjFREESTACK;
}

double gs_work_total(const gsPowers* p) {
  return p->mtu_pos + p->mtu_neg + p->foot_pos + p->foot_neg + p->knee + p->joint_limits +
         p->couplings + p->mujoco_passive + p->other_actuators + p->constraint + p->applied;
}

void gs_work_dof_muscle_powers(const mjModel* m, const mjData* d, double* power) {
  // each muscle's generalised force is its moment-arm row times its force (actuator_moment)
  for (int k = 0; k < m->nv; k++) power[k] = 0;
  for (int i = 0; i < m->nu; i++) {
    if (!gs_actuator_is_gaitsim_muscle(m, i)) continue;
    for (int k = 0; k < m->nv; k++)
      power[k] += d->actuator_moment[i * m->nv + k] * d->actuator_force[i] * d->qvel[k];
  }
}

// 1 when body b is body a or hangs below it
static int below(const mjModel* m, int b, int a) {
  for (; b > 0; b = m->body_parentid[b])
    if (b == a) return 1;
  return a == 0;
}

int gs_work_dof_side(const mjModel* m, int k) {
  int body = m->dof_bodyid[k], side = 0;
  for (int g = 0; g < m->ngeom; g++) {
    int s = gs_geom_contact_side(m, g);
    if (!s || !below(m, m->geom_bodyid[g], body)) continue;
    if (side && side != s) return 0;
    side = s;
  }
  return side;
}
