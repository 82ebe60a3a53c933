// gs_contact.c: smooth Hunt-Crossley sphere-plane contact and foot ground-reaction aggregation.
// Equations, sources and accuracy are documented in gs_contact.h.
#include "callbacks/gs_contact.h"

#include <math.h>
#include <stdio.h>

#include "callbacks/gs_model_layout.h"

// smallest norm accepted for a plane normal (-) and smallest slip speed / transition speed (m/s)
#define GS_CONTACT_MIN_NORM 1e-12
#define GS_CONTACT_MIN_SPEED 1e-12

// default smoothing widths (see gsContactSmoothing)
#define GS_CONTACT_EPS_DEPTH 1e-5
#define GS_CONTACT_EPS_DAMPING 1e-2
#define GS_CONTACT_EPS_SLIP 1e-3
#define GS_CONTACT_KNEE_FRICTION 0.1

// smooth max(x, 0) = (x + sqrt(x^2 + e^2)) / 2: C-infinity, > 0, error e^2 / (4|x|) far from 0
static double smooth_pos(double x, double e) {
  return 0.5 * (x + sqrt(x * x + e * e));
}

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(double res[3], const double a[3], const double b[3]) {
  res[0] = a[1] * b[2] - a[2] * b[1];
  res[1] = a[2] * b[0] - a[0] * b[2];
  res[2] = a[0] * b[1] - a[1] * b[0];
}

// plane point and unit normal with the documented NULL defaults (origin, +z)
static void plane_frame(const double plane_point[3], const double plane_normal[3],
                        double p0[3], double n[3]) {
  double len;
  for (int k = 0; k < 3; k++) {
    p0[k] = plane_point ? plane_point[k] : 0.0;
  }
  if (!plane_normal) {
    n[0] = 0.0;
    n[1] = 0.0;
    n[2] = 1.0;
    return;
  }
  len = sqrt(dot3(plane_normal, plane_normal));
  if (len < GS_CONTACT_MIN_NORM) {
    n[0] = 0.0;
    n[1] = 0.0;
    n[2] = 1.0;
    return;
  }
  for (int k = 0; k < 3; k++) {
    n[k] = plane_normal[k] / len;
  }
}

void gs_contact_smoothing_default(gsContactSmoothing* s) {
  s->eps_depth = GS_CONTACT_EPS_DEPTH;
  s->eps_damping = GS_CONTACT_EPS_DAMPING;
  s->eps_slip = GS_CONTACT_EPS_SLIP;
  s->knee_friction = GS_CONTACT_KNEE_FRICTION;
}

int gs_contact_params_from_user(const double* user, double radius, gsContactParams* prm,
                                char* err, int errlen) {
  const char* reason = NULL;

  // copy in gsGeomUser order
  prm->stiffness = user[GS_GEOM_STIFFNESS];
  prm->dissipation = user[GS_GEOM_DISSIPATION];
  prm->mu_static = user[GS_GEOM_STATIC_FRICTION];
  prm->mu_dynamic = user[GS_GEOM_DYNAMIC_FRICTION];
  prm->mu_viscous = user[GS_GEOM_VISCOUS_FRICTION];
  prm->v_transition = user[GS_GEOM_TRANSITION_VEL];
  prm->radius = radius;

  // range checks (negated comparisons also reject NaN)
  if (!(prm->stiffness >= 0.0)) {
    reason = "stiffness must be >= 0 N/m^2";
  } else if (!(prm->dissipation >= 0.0)) {
    reason = "dissipation must be >= 0 s/m";
  } else if (!(prm->mu_static >= 0.0) || !(prm->mu_dynamic >= 0.0) ||
             !(prm->mu_viscous >= 0.0)) {
    reason = "friction coefficients must be >= 0";
  } else if (!(prm->v_transition > 0.0)) {
    reason = "transition velocity must be > 0 m/s";
  } else if (!(radius > 0.0)) {
    reason = "radius must be > 0 m";
  }
  if (reason) {
    if (err && errlen > 0) {
      snprintf(err, (size_t)errlen, "contact sphere: %s", reason);
    }
    return -1;
  }
  return 0;
}

double gs_contact_friction_exact(const gsContactParams* prm, double vs) {
  double vt = prm->v_transition > GS_CONTACT_MIN_SPEED ? prm->v_transition : GS_CONTACT_MIN_SPEED;
  double s = vs / vt;
  double sat = s < 1.0 ? s : 1.0;

  // Simbody HuntCrossleyForce: Stribeck peak mus at vs = vt, mud for vs >> vt, plus viscous
  return sat * (prm->mu_dynamic + 2.0 * (prm->mu_static - prm->mu_dynamic) / (1.0 + s * s)) +
         prm->mu_viscous * vs;
}

double gs_contact_friction_smooth(const gsContactParams* prm, double vs, double w) {
  double vt = prm->v_transition > GS_CONTACT_MIN_SPEED ? prm->v_transition : GS_CONTACT_MIN_SPEED;
  double s = vs / vt;

  // sat(s) = (s - r(s-1) + r(-1)) / (1 + r(-1)): min(s,1) with a smooth knee, sat(0) = 0,
  // sat(inf) = 1, increasing, C-infinity
  double r0 = smooth_pos(-1.0, w);
  double sat = (s - smooth_pos(s - 1.0, w) + r0) / (1.0 + r0);

  return sat * (prm->mu_dynamic + 2.0 * (prm->mu_static - prm->mu_dynamic) / (1.0 + s * s)) +
         prm->mu_viscous * vs;
}

void gs_contact_sphere(const gsContactParams* prm, const gsContactSmoothing* sm,
                       const double plane_point[3], const double plane_normal[3],
                       const double pos[3], const double vel[3], const double vel_contact[3],
                       gsContactOut* out) {
  gsContactSmoothing def;
  double p0[3], n[3], rel[3], vt[3];
  double height, depth, depth_rate, dplus, g, gplus, fn, vn_c, vs, mu, radius;
  const double* vc = vel_contact ? vel_contact : vel;

  if (!sm) {
    gs_contact_smoothing_default(&def);
    sm = &def;
  }
  plane_frame(plane_point, plane_normal, p0, n);
  radius = prm->radius > 0.0 ? prm->radius : 0.0;

  // penetration d = R - (p - p0).n (m) and its rate d' = -v.n (m/s); the plane is static
  for (int k = 0; k < 3; k++) {
    rel[k] = pos[k] - p0[k];
  }
  height = dot3(rel, n);
  depth = radius - height;
  depth_rate = -dot3(vel, n);

  // contact point: centre projected on the plane, p - ((p - p0).n) n (m)
  for (int k = 0; k < 3; k++) {
    out->point[k] = pos[k] - height * n[k];
  }

  // normal force, Hunt & Crossley 1975 (Simbody HuntCrossleyForce):
  // Fn = 4/3 E sqrt(R) d+^(3/2) g+, d+ = smooth max(d,0), g+ = smooth max(1 + 1.5 c d', 0)
  dplus = smooth_pos(depth, sm->eps_depth);
  g = 1.0 + 1.5 * prm->dissipation * depth_rate;
  gplus = smooth_pos(g, sm->eps_damping);
  fn = (4.0 / 3.0) * prm->stiffness * sqrt(radius) * dplus * sqrt(dplus) * gplus;

  // slip velocity: tangential part of the contact point velocity, v_t = vc - (vc.n) n (m/s)
  vn_c = dot3(vc, n);
  for (int k = 0; k < 3; k++) {
    vt[k] = vc[k] - vn_c * n[k];
  }
  vs = sqrt(dot3(vt, vt) + sm->eps_slip * sm->eps_slip);
  if (vs < GS_CONTACT_MIN_SPEED) {
    vs = GS_CONTACT_MIN_SPEED;
  }

  // friction: Ft = -mu(vs) Fn v_t / vs, smoothed Simbody law
  mu = gs_contact_friction_smooth(prm, vs, sm->knee_friction);
  for (int k = 0; k < 3; k++) {
    out->force[k] = fn * n[k] - mu * fn * vt[k] / vs;
  }

  out->depth = depth;
  out->depth_smooth = dplus;
  out->depth_rate = depth_rate;
  out->normal_force = fn;
  out->slip_speed = vs;
  out->mu = mu;
}

void gs_contact_foot_grf(int n, const double* forces, const double* points,
                         const double plane_point[3], const double plane_normal[3],
                         double fn_min, gsFootGrf* out) {
  double p0[3], nrm[3], r[3], rxf[3], nxm[3], copxf[3], fn;

  plane_frame(plane_point, plane_normal, p0, nrm);

  // resultant force and moment about p0: M = sum (r_i - p0) x F_i
  for (int k = 0; k < 3; k++) {
    out->force[k] = 0.0;
    out->moment[k] = 0.0;
  }
  for (int i = 0; i < n; i++) {
    for (int k = 0; k < 3; k++) {
      out->force[k] += forces[3 * i + k];
      r[k] = points[3 * i + k] - p0[k];
    }
    cross3(rxf, r, forces + 3 * i);
    for (int k = 0; k < 3; k++) {
      out->moment[k] += rxf[k];
    }
  }

  // unloaded: COP undefined, report the plane point and the whole normal moment
  fn = dot3(out->force, nrm);
  if (!(fn > fn_min) || fn <= 0.0) {
    for (int k = 0; k < 3; k++) {
      out->cop[k] = p0[k];
    }
    out->free_moment = dot3(out->moment, nrm);
    out->loaded = 0;
    return;
  }

  // COP on the plane: cop - p0 = (n x M) / Fn; free moment T = (M - (cop - p0) x F).n
  cross3(nxm, nrm, out->moment);
  for (int k = 0; k < 3; k++) {
    r[k] = nxm[k] / fn;
    out->cop[k] = p0[k] + r[k];
  }
  cross3(copxf, r, out->force);
  out->free_moment = dot3(out->moment, nrm) - dot3(copxf, nrm);
  out->loaded = 1;
}
