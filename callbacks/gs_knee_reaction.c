// gs_knee_reaction.c: knee joint reaction from the multibody dynamics (see gs_knee_reaction.h).
#include "callbacks/gs_knee_reaction.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "callbacks/gs_model_info.h"
#include "callbacks/gs_physics.h"

// shortest path segment that carries a direction (m); shorter ones are skipped
#define GS_KNEE_REACTION_MIN_SEGMENT 1e-12

// 1 if body b lies in the subtree rooted at body root (root included)
static int in_subtree(const mjModel* m, int b, int root) {
  while (b > 0 && b != root) {
    b = m->body_parentid[b];
  }
  return b == root;
}

int gs_knee_reaction_spec(const mjModel* m, const char* tibia, const char* knee,
                          const char* ankle, gsKneeReactionSpec* spec, char* err, int errsz) {
  memset(spec, 0, sizeof(*spec));
  spec->body = mj_name2id(m, mjOBJ_BODY, tibia);
  spec->knee_joint = mj_name2id(m, mjOBJ_JOINT, knee);
  spec->ankle_joint = mj_name2id(m, mjOBJ_JOINT, ankle);
  if (spec->body <= 0) {
    snprintf(err, errsz, "knee reaction: no body %s", tibia);
    return -1;
  }
  if (spec->knee_joint < 0 || spec->ankle_joint < 0) {
    snprintf(err, errsz, "knee reaction: no joint %s", spec->knee_joint < 0 ? knee : ankle);
    return -1;
  }
  if (!in_subtree(m, m->jnt_bodyid[spec->ankle_joint], spec->body) ||
      m->jnt_bodyid[spec->ankle_joint] == spec->body) {
    snprintf(err, errsz, "knee reaction: joint %s is not below body %s", ankle, tibia);
    return -1;
  }
  // every foot: all its contact spheres inside the subtree, or none
  for (int s = 0; s < 2; s++) {
    int side = s == 0 ? 'r' : 'l', n = 0, inside = 0;
    for (int g = 0; g < m->ngeom; g++) {
      if (gs_geom_contact_side(m, g) != side) continue;
      n++;
      inside += in_subtree(m, m->geom_bodyid[g], spec->body);
    }
    if (inside > 0 && inside < n) {
      snprintf(err, errsz, "knee reaction: %d of the %d contact spheres of foot %c are below "
               "body %s", inside, n, side, tibia);
      return -1;
    }
    if (s == 0) spec->ground_r = inside > 0;
    else spec->ground_l = inside > 0;
  }
  return 0;
}

int gs_knee_reaction_spec_left(const mjModel* m, gsKneeReactionSpec* spec, char* err, int errsz) {
  return gs_knee_reaction_spec(m, "tibia_l", "knee_flexion_l", "ankle_angle_l", spec, err, errsz);
}

// Net force (world, N) of tendon t's path on the subtree of root at tension T (N, pulling): the
// sum over the segments that cross the subtree's boundary of T/divisor times the unit vector from
// the inside point to the outside one. *crossed = number of crossing segments. Returns 0, or -1
// when a path point cannot be matched to the tendon's model elements.
static int tendon_force_on_subtree(const mjModel* m, const mjData* d, int t, int root, double T,
                                   double force[3], int* crossed) {
  force[0] = force[1] = force[2] = 0;
  *crossed = 0;
  int adr = d->ten_wrapadr[t], num = d->ten_wrapnum[t];
  int j = m->tendon_adr[t], jend = m->tendon_adr[t] + m->tendon_num[t];
  if (m->tendon_num[t] < 1 || m->wrap_type[j] == mjWRAP_JOINT) {
    return 0;  // fixed tendon: acts in joint space, no path
  }
  double divisor = 1;
  int prev_body = -1;  // body of the previous point of this branch, -1 at a branch start
  const mjtNum* prev = NULL;
  for (int p = adr; p < adr + num; p++) {
    int obj = d->wrap_obj[p], body;
    if (obj == -1) {  // a site: the next site element of the model's list
      while (j < jend && m->wrap_type[j] != mjWRAP_SITE) j++;
      if (j == jend) return -1;
      body = m->site_bodyid[m->wrap_objid[j++]];
    } else if (obj == -2) {  // a pulley: a new branch, its tension divided
      while (j < jend && m->wrap_type[j] != mjWRAP_PULLEY) j++;
      if (j == jend) return -1;
      divisor = m->wrap_prm[j++];
      prev_body = -1;
      continue;
    } else if (obj >= 0 && obj < m->ngeom) {  // a tangent point on a wrap geom
      body = m->geom_bodyid[obj];
    } else {
      return -1;
    }
    const mjtNum* x = d->wrap_xpos + 3 * p;
    if (prev_body >= 0) {
      int in0 = in_subtree(m, prev_body, root), in1 = in_subtree(m, body, root);
      if (in0 != in1) {
        // the inside point is pulled towards the outside one
        const mjtNum* pin = in1 ? x : prev;
        const mjtNum* pout = in1 ? prev : x;
        double u[3] = {pout[0] - pin[0], pout[1] - pin[1], pout[2] - pin[2]};
        double len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        if (len > GS_KNEE_REACTION_MIN_SEGMENT && divisor > 0) {
          for (int c = 0; c < 3; c++) force[c] += T / divisor * u[c] / len;
          (*crossed)++;
        }
      }
    }
    prev_body = body;
    prev = x;
  }
  return 0;
}

int gs_knee_reaction(const mjModel* m, mjData* d, const gsKneeReactionSpec* spec,
                     const double* tension, gsKneeReaction* out) {
  memset(out, 0, sizeof(*out));
  int rc = 0, root = spec->body;
  // F_int: force part of the subtree's com-based interaction force [torque(3), force(3)]
  mj_rnePostConstraint(m, d);
  for (int c = 0; c < 3; c++) out->inertial[c] = d->cfrc_int[6 * root + 3 + c];
  // F_ground: the feet inside the subtree
  for (int s = 0; s < 2; s++) {
    if (!(s == 0 ? spec->ground_r : spec->ground_l)) continue;
    gsFootGrf fg;
    gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &fg);
    for (int c = 0; c < 3; c++) out->ground[c] += fg.force[c];
  }
  // sum_m F_m u_m: muscles crossing the boundary of the subtree
  for (int i = 0; i < m->nu; i++) {
    if (m->actuator_trntype[i] != mjTRN_TENDON) continue;
    double T = tension                             ? tension[i]
               : gs_actuator_is_gaitsim_muscle(m, i) ? gs_physics_muscle_tension(m, d, i, NULL)
                                                     : 0;
    T *= m->actuator_gear[6 * i];  // tendon tension = gear x muscle tension
    double f[3];
    int crossed = 0;
    if (tendon_force_on_subtree(m, d, m->actuator_trnid[2 * i], root, T, f, &crossed) != 0) {
      rc = -1;
      continue;
    }
    for (int c = 0; c < 3; c++) out->muscle[c] += f[c];
    out->ncross += crossed > 0;
  }
  // F_J and its component along the tibia's long axis (ankle -> knee joint centre)
  const mjtNum* knee = d->xanchor + 3 * spec->knee_joint;
  const mjtNum* ankle = d->xanchor + 3 * spec->ankle_joint;
  double a[3] = {knee[0] - ankle[0], knee[1] - ankle[1], knee[2] - ankle[2]};
  double len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  double dot = 0;
  for (int c = 0; c < 3; c++) {
    out->axis[c] = len > 0 ? a[c] / len : NAN;
    out->force[c] = out->inertial[c] - out->ground[c] - out->muscle[c];
    dot += out->force[c] * out->axis[c];
  }
  out->compression = -dot;
  return rc == 0 && isfinite(out->compression) ? 0 : -1;
}
