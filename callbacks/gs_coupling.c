// gs_coupling.c: coordinate couplings as stiff spring-dampers (gs_coupling.h).
#include "callbacks/gs_coupling.h"

#include <stdio.h>

static int adopted(const mjModel* m, int e) {
  return m->eq_type[e] == mjEQ_JOINT && m->eq_data[e * mjNEQDATA + GS_COUPLING_MARK] == 1;
}

static int slidehinge(const mjModel* m, int j) {
  return j >= 0 && (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE);
}

int gs_coupling_adopt(mjModel* m, char* err, int errsz) {
  int n = 0;
  for (int e = 0; e < m->neq; e++) {
    if (m->eq_type[e] != mjEQ_JOINT) continue;
    if (adopted(m, e)) {
      n++;
      continue;
    }
    if (!m->eq_active[e]) continue;
    if (!slidehinge(m, m->eq_obj1id[e]) || !slidehinge(m, m->eq_obj2id[e])) {
      const char* name = mj_id2name(m, mjOBJ_EQUALITY, e);
      snprintf(err, errsz, "joint equality %s: gaitsim holds only couplings of one hinge or "
               "slide joint to another", name ? name : "(unnamed)");
      return -1;
    }
    m->eq_active[e] = 0;
    m->eq_data[e * mjNEQDATA + GS_COUPLING_MARK] = 1;
    n++;
  }
  return n;
}

// the follower's target of equality e for driver value qd, and d target / d qd
static double target_of(const mjModel* m, int e, double qd, double* slope) {
  const mjtNum* a = m->eq_data + e * mjNEQDATA;
  double x = qd - m->qpos0[m->jnt_qposadr[m->eq_obj2id[e]]];
  double y = a[0] + x * (a[1] + x * (a[2] + x * (a[3] + x * a[4])));
  if (slope) *slope = a[1] + x * (2 * a[2] + x * (3 * a[3] + x * 4 * a[4]));
  return m->qpos0[m->jnt_qposadr[m->eq_obj1id[e]]] + y;
}

int gs_coupling_count(const mjModel* m) {
  int n = 0;
  for (int e = 0; e < m->neq; e++) n += adopted(m, e);
  return n;
}

// the equality of the c-th adopted coupling
static int nth(const mjModel* m, int c) {
  for (int e = 0; e < m->neq; e++) {
    if (adopted(m, e) && c-- == 0) return e;
  }
  return -1;
}

void gs_coupling_get(const mjModel* m, int c, int* follower, int* driver) {
  int e = nth(m, c);
  *follower = m->eq_obj1id[e];
  *driver = m->eq_obj2id[e];
}

double gs_coupling_target(const mjModel* m, int c, double qd, double* slope) {
  return target_of(m, nth(m, c), qd, slope);
}

void gs_coupling_passive(const mjModel* m, mjData* d) {
  for (int e = 0; e < m->neq; e++) {
    if (!adopted(m, e)) continue;
    int f = m->eq_obj1id[e], dr = m->eq_obj2id[e];
    double slope;
    double target = target_of(m, e, d->qpos[m->jnt_qposadr[dr]], &slope);
    int vf = m->jnt_dofadr[f], vd = m->jnt_dofadr[dr];
    double r = d->qpos[m->jnt_qposadr[f]] - target;
    double rdot = d->qvel[vf] - slope * d->qvel[vd];
    double s = GS_COUPLING_STIFFNESS * r + GS_COUPLING_DAMPING * rdot;
    d->qfrc_passive[vf] -= s;
    d->qfrc_passive[vd] += s * slope;
  }
}

void gs_coupling_follow(const mjModel* m, mjtNum* qpos, mjtNum* qvel, const int* given_qpos,
                        const int* given_qvel) {
  for (int e = 0; e < m->neq; e++) {
    if (!adopted(m, e)) continue;
    int f = m->eq_obj1id[e], dr = m->eq_obj2id[e];
    int pf = m->jnt_qposadr[f], vf = m->jnt_dofadr[f];
    double slope;
    double target = target_of(m, e, qpos[m->jnt_qposadr[dr]], &slope);
    if (!given_qpos || given_qpos[pf] < 0) qpos[pf] = target;
    if (qvel && (!given_qvel || given_qvel[vf] < 0)) qvel[vf] = slope * qvel[m->jnt_dofadr[dr]];
  }
}

int gs_coupling_joint_follows(const mjModel* m, int jnt) {
  for (int e = 0; e < m->neq; e++) {
    if (m->eq_type[e] == mjEQ_JOINT && (m->eq_active[e] || adopted(m, e)) &&
        m->eq_obj1id[e] == jnt && m->eq_obj2id[e] >= 0)
      return 1;
  }
  return 0;
}
