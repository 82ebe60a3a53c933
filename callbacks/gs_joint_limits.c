// gs_joint_limits.c: passive joint-limit moments (see gs_joint_limits.h).
#include "callbacks/gs_joint_limits.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

double gs_joint_limit_moment(const double k[4], const double theta[2], double q, double* dtau_dq) {
  // Anderson & Pandy 1999; Falisse et al. 2019:
  // tau = k1 e^(k2 (q - theta2)) + k3 e^(k4 (q - theta1))
  double upper = k[0] * exp(k[1] * (q - theta[1]));
  double lower = k[2] * exp(k[3] * (q - theta[0]));
  if (dtau_dq) *dtau_dq = k[1] * upper + k[3] * lower;
  return upper + lower;
}

// joint id of numeric n when it is a gs_limit_ numeric (-2 when it is not one, -1 when its joint
// does not exist)
static int limit_joint(const mjModel* m, int n) {
  const char* name = mj_id2name(m, mjOBJ_NUMERIC, n);
  size_t len = strlen(GS_JOINT_LIMIT_PREFIX);
  if (!name || strncmp(name, GS_JOINT_LIMIT_PREFIX, len) != 0) return -2;
  return mj_name2id(m, mjOBJ_JOINT, name + len);
}

int gs_joint_limits_check(const mjModel* m, char* err, int errsz) {
  int count = 0;
  for (int n = 0; n < m->nnumeric; n++) {
    int j = limit_joint(m, n);
    if (j == -2) continue;
    const char* name = mj_id2name(m, mjOBJ_NUMERIC, n);
    if (j < 0) {
      snprintf(err, errsz, "numeric %s: no joint %s", name, name + strlen(GS_JOINT_LIMIT_PREFIX));
      return -1;
    }
    if (m->jnt_type[j] != mjJNT_HINGE) {
      snprintf(err, errsz, "numeric %s: joint limit moments need a hinge joint", name);
      return -1;
    }
    if (m->numeric_size[n] != GS_JOINT_LIMIT_SIZE) {
      snprintf(err, errsz, "numeric %s: size %d, need %d (k1 k2 k3 k4 theta1 theta2)", name,
               m->numeric_size[n], GS_JOINT_LIMIT_SIZE);
      return -1;
    }
    const mjtNum* v = m->numeric_data + m->numeric_adr[n];
    for (int i = 0; i < GS_JOINT_LIMIT_SIZE; i++) {
      if (!isfinite(v[i])) {
        snprintf(err, errsz, "numeric %s: value %d is not finite", name, i + 1);
        return -1;
      }
    }
    if (!(v[0] <= 0 && v[1] >= 0 && v[2] >= 0 && v[3] <= 0 && v[4] < v[5])) {
      snprintf(err, errsz,
               "numeric %s: need k1 <= 0 <= k2, k3 >= 0 >= k4 and theta1 < theta2 (limits that "
               "push back into the range)",
               name);
      return -1;
    }
    count++;
  }
  return count;
}

void gs_joint_limits_passive(const mjModel* m, mjData* d) {
  for (int n = 0; n < m->nnumeric; n++) {
    int j = limit_joint(m, n);
    if (j < 0) continue;
    const mjtNum* v = m->numeric_data + m->numeric_adr[n];
    double k[4] = {v[0], v[1], v[2], v[3]}, theta[2] = {v[4], v[5]};
    d->qfrc_passive[m->jnt_dofadr[j]] +=
        gs_joint_limit_moment(k, theta, d->qpos[m->jnt_qposadr[j]], NULL);
  }
}
