// gs_tendon_paths.c: MuJoCo's position stage with tendon paths that are finite and continuous
// at grazing wraps (gs_tendon_paths.h).
#include "callbacks/gs_tendon_paths.h"

#include <math.h>

// point x (world) in geom g's frame
static void to_geom(const mjData* d, int g, const mjtNum* x, mjtNum* out) {
  mjtNum v[3];
  mju_sub3(v, x, d->geom_xpos + 3 * g);
  mju_mulMatTVec(out, d->geom_xmat + 9 * g, v, 3, 3);
}

// Wrap w of the path (a cylinder or sphere between two sites): 1 when the site segment passes
// inside the geom by less than GS_TENDON_GRAZE_REL of its radius and MuJoCo would wrap it there
// (mju_wrap's test: the segment's nearest point to the axis or centre within the radius, and no
// side site or the side site outside the geom on the nearest point's side); then `away` (world,
// unit) moves the geom off the segment.
static int grazes(const mjModel* m, const mjData* d, int w, mjtNum away[3]) {
  int type = m->wrap_type[w];
  if (type != mjWRAP_CYLINDER && type != mjWRAP_SPHERE) return 0;
  int w0 = w - 1, w1 = w + 1;  // the sites before and after it in the path
  if (w0 < 0 || w1 >= m->nwrap || m->wrap_type[w0] != mjWRAP_SITE ||
      m->wrap_type[w1] != mjWRAP_SITE)
    return 0;
  int g = m->wrap_objid[w];
  mjtNum r = m->geom_size[3 * g], p0[3], p1[3], dif[3], near[3];
  to_geom(d, g, d->site_xpos + 3 * m->wrap_objid[w0], p0);
  to_geom(d, g, d->site_xpos + 3 * m->wrap_objid[w1], p1);
  if (type == mjWRAP_CYLINDER) p0[2] = p1[2] = 0;  // the circle of the cylinder's cross-section
  mju_sub3(dif, p1, p0);
  mjtNum dd = mju_dot3(dif, dif);
  if (dd < mjMINVAL) return 0;
  mjtNum a = fmin(fmax(-mju_dot3(dif, p0) / dd, 0), 1);
  mju_addScl3(near, p0, dif, a);
  mjtNum dist = mju_norm3(near);
  if (!(dist <= r && dist > r * (1 - GS_TENDON_GRAZE_REL))) return 0;
  int side = (int)m->wrap_prm[w];
  if (side >= 0) {  // the side site in the plane of the wrap
    mjtNum s[3], n[3];
    to_geom(d, g, d->site_xpos + 3 * side, s);
    if (type == mjWRAP_CYLINDER) {
      s[2] = 0;
    } else {
      mju_cross(n, p0, p1);
      if (mju_normalize3(n) < mjMINVAL) return 0;
      mju_addToScl3(s, n, -mju_dot3(s, n));
    }
    if (mju_norm3(s) < r || mju_dot3(s, near) < 0) return 0;  // inside wrap; wraps the far side
  }
  mjtNum u[3];
  mju_scl3(u, near, -1 / dist);
  mju_mulMatVec(away, d->geom_xmat + 9 * g, u, 3, 3);
  return 1;
}

// move geom g by GS_TENDON_GRAZE_REL x 2 x radius along the world direction u
static void move_geom(const mjModel* m, mjData* d, int g, const mjtNum u[3]) {
  mju_addToScl3(d->geom_xpos + 3 * g, u, 2 * GS_TENDON_GRAZE_REL * m->geom_size[3 * g]);
}

int gs_tendon_repair(const mjModel* m, mjData* d) {
  int nt = m->ntendon, nv = m->nv, dense = !mj_isSparse(m);
  int mark = d->pstack;
  // per tendon: 0 as MuJoCo gave it; 1 grazing (geoms moved off the segment); 2 non-finite
  // without a graze (geoms moved across the axis, direction by direction)
  mjtNum* how = mj_stackAlloc(d, nt);
  mjtNum* away = mj_stackAlloc(d, 3 * m->nwrap);  // per wrap: the move off a graze, or 0
  int todo = 0;
  mju_zero(away, 3 * m->nwrap);
  for (int t = 0; t < nt; t++) {
    how[t] = 0;
    for (int w = m->tendon_adr[t]; w < m->tendon_adr[t] + m->tendon_num[t]; w++)
      if (grazes(m, d, w, away + 3 * w)) how[t] = 1;
    if (how[t] == 0 && !isfinite(d->ten_length[t])) how[t] = 2;
    todo += how[t] != 0;
  }
  if (todo == 0) {
    d->pstack = mark;
    return 0;
  }
  mjtNum* len = mj_stackAlloc(d, nt);      // the result's lengths
  mjtNum* J = mj_stackAlloc(d, nt * nv);   // and Jacobian rows (dense)
  mjtNum* xpos = mj_stackAlloc(d, 3 * m->ngeom);
  mjtNum* dir = mj_stackAlloc(d, nt);      // non-finite without a graze: direction found, or -1
  mju_copy(len, d->ten_length, nt);
  if (dense) mju_copy(J, d->ten_J, nt * nv);
  mju_copy(xpos, d->geom_xpos, 3 * m->ngeom);
  for (int t = 0; t < nt; t++) dir[t] = -1;
  for (int k = 0; k < 4; k++) {
    int unresolved = 0;
    for (int t = 0; t < nt; t++) unresolved += how[t] == 2 && dir[t] < 0;
    if (k > 0 && unresolved == 0) break;
    mju_copy(d->geom_xpos, xpos, 3 * m->ngeom);
    for (int t = 0; t < nt; t++) {
      for (int w = m->tendon_adr[t]; how[t] != 0 && w < m->tendon_adr[t] + m->tendon_num[t]; w++) {
        if (m->wrap_type[w] != mjWRAP_CYLINDER && m->wrap_type[w] != mjWRAP_SPHERE) continue;
        int g = m->wrap_objid[w];
        if (how[t] == 1) {
          if (mju_norm3(away + 3 * w) > 0) move_geom(m, d, g, away + 3 * w);
        } else {  // across the axis: the geom's local x, -x, y, -y
          int i = dir[t] >= 0 ? (int)dir[t] : k;
          const mjtNum* R = d->geom_xmat + 9 * g;  // row-major: local axis c is column c
          mjtNum u[3];
          for (int c = 0; c < 3; c++) u[c] = (i & 1 ? -1 : 1) * R[3 * c + (i >> 1)];
          move_geom(m, d, g, u);
        }
      }
    }
    mj_tendon(m, d);
    for (int t = 0; t < nt; t++) {
      if (how[t] == 0 || (how[t] == 2 && dir[t] >= 0) || !isfinite(d->ten_length[t])) continue;
      if (how[t] == 2) dir[t] = k;
      len[t] = d->ten_length[t];
      if (dense) mju_copy(J + t * nv, d->ten_J + t * nv, nv);
    }
  }
  // the geoms back; the wrap points are those of the last mj_tendon
  mju_copy(d->geom_xpos, xpos, 3 * m->ngeom);
  if (dense) {
    mju_copy(d->ten_length, len, nt);
    mju_copy(d->ten_J, J, nt * nv);
  }
  int bad = 0;
  for (int t = 0; t < nt; t++) bad |= !isfinite(d->ten_length[t]);
  d->pstack = mark;
  mj_transmission(m, d);  // the actuators' lengths and moment arms from the recomputed tendons
  return bad ? -1 : todo;
}

int gs_fwd_position(const mjModel* m, mjData* d) {
  mj_fwdPosition(m, d);
  return gs_tendon_repair(m, d);
}

// the repaired position stage, then the position-stage sensors and energy that mj_forwardSkip
// and mj_inverseSkip leave out when told to skip it: their own sequence, the position stage done
// once (mj_forward twice would also warm-start the constraint solver from NaN accelerations)
static int position_stage(const mjModel* m, mjData* d) {
  int r = gs_fwd_position(m, d);
  mj_sensorPos(m, d);
  if (mjENABLED(mjENBL_ENERGY)) mj_energyPos(m, d);
  return r;
}

int gs_inverse(const mjModel* m, mjData* d) {
  int r = position_stage(m, d);
  mj_inverseSkip(m, d, mjSTAGE_POS, 0);
  return r;
}

int gs_forward(const mjModel* m, mjData* d) {
  int r = position_stage(m, d);
  mj_forwardSkip(m, d, mjSTAGE_POS, 0);
  return r;
}
