// test_contact.c: smooth Hunt-Crossley sphere-plane contact and foot GRF aggregation
// (callbacks/gs_contact.h).
#include <math.h>
#include <string.h>

#include "callbacks/gs_contact.h"
#include "callbacks/gs_model_layout.h"
#include "tests/gs_test.h"

// sphere of a typical foot model: E 2 MPa, c 1 s/m, mus 0.9, mud 0.8, muv 0, vt 0.1 m/s, R 3 cm
static gsContactParams sphere(void) {
  gsContactParams p;
  p.stiffness = 2e6;
  p.dissipation = 1.0;
  p.mu_static = 0.9;
  p.mu_dynamic = 0.8;
  p.mu_viscous = 0.0;
  p.v_transition = 0.1;
  p.radius = 0.03;
  return p;
}

// Hertz elastic force 4/3 E sqrt(R) d^1.5 (N), the unsmoothed reference
static double hertz(const gsContactParams* p, double d) {
  return 4.0 / 3.0 * p->stiffness * sqrt(p->radius) * pow(d, 1.5);
}

// one evaluation on the floor (z = 0, +z) with centre height z, centre velocity v; which selects
// the returned quantity: 0 Fn, 1 Ft_x, 2 Fz
static double eval(const gsContactParams* p, double z, const double v[3], int which) {
  gsContactOut out;
  double pos[3] = {0.1, -0.2, z};
  gs_contact_sphere(p, NULL, NULL, NULL, pos, v, NULL, &out);
  if (which == 0) {
    return out.normal_force;
  }
  return which == 1 ? out.force[0] : out.force[2];
}

// one-sided finite-difference slopes of f at x0 (step h): left and right
typedef double (*scalarFn)(double x, const void* ctx);

static void one_sided(scalarFn f, const void* ctx, double x0, double h, double* left,
                      double* right) {
  double f0 = f(x0, ctx);
  *left = (f0 - f(x0 - h, ctx)) / h;
  *right = (f(x0 + h, ctx) - f0) / h;
}

typedef struct probe_ {
  gsContactParams prm;
  double z;       // centre height (m)
  double v[3];    // centre velocity (m/s)
  int var;        // 0: vary z, 1: vary v_x, 2: vary v_z
  int which;      // quantity as in eval()
} probe;

static double probe_fn(double x, const void* ctx) {
  const probe* pr = (const probe*)ctx;
  double z = pr->z, v[3] = {pr->v[0], pr->v[1], pr->v[2]};
  if (pr->var == 0) {
    z = x;
  } else if (pr->var == 1) {
    v[0] = x;
  } else {
    v[2] = x;
  }
  return eval(&pr->prm, z, v, pr->which);
}

static double friction_exact_fn(double vs, const void* ctx) {
  return gs_contact_friction_exact((const gsContactParams*)ctx, vs);
}

static double friction_smooth_fn(double vs, const void* ctx) {
  return gs_contact_friction_smooth((const gsContactParams*)ctx, vs, 0.1);
}

static void static_sphere_should_give_hertz_force(void) {
  gsContactParams p = sphere();
  double v0[3] = {0.0, 0.0, 0.0};
  double depths[3] = {1e-3, 3e-3, 5e-3};

  // error bound 3/8 (ed/d)^2 + eg^2/4 = 3.75e-5 + 2.5e-5 at d = 1 mm (defaults ed 1e-5, eg 1e-2)
  for (int i = 0; i < 3; i++) {
    double d = depths[i];
    gsContactOut out;
    double pos[3] = {0.1, -0.2, p.radius - d};
    gs_contact_sphere(&p, NULL, NULL, NULL, pos, v0, NULL, &out);
    EXPECT_REL(hertz(&p, d), out.normal_force, 1e-4, 1e-9);
    EXPECT_REL(hertz(&p, d), out.force[2], 1e-4, 1e-9);
    EXPECT_NEAR(0.0, out.force[0], 1e-12);
    EXPECT_NEAR(0.0, out.force[1], 1e-12);
    EXPECT_NEAR(d, out.depth, 1e-15);
    // contact point: centre projected on the floor
    EXPECT_NEAR(0.1, out.point[0], 1e-15);
    EXPECT_NEAR(-0.2, out.point[1], 1e-15);
    EXPECT_NEAR(0.0, out.point[2], 1e-15);
  }

  // approaching at 0.1 m/s: Fn = Fh (1 + 1.5 c d'), d' = 0.1 m/s -> factor 1.15
  {
    double v[3] = {0.0, 0.0, -0.1};
    EXPECT_REL(hertz(&p, 2e-3) * 1.15, eval(&p, p.radius - 2e-3, v, 0), 1e-4, 1e-9);
  }
}

static void tilted_plane_should_match_floor(void) {
  gsContactParams p = sphere();
  double th = 0.3, d = 2e-3;
  double n[3] = {0.0, sin(th), cos(th)};
  double p0[3] = {0.5, 0.2, 0.1};
  double pos[3], v0[3] = {0.0, 0.0, 0.0};
  gsContactOut out;

  // centre at p0 + (R - d) n: the same penetration as on the floor, force along n
  for (int k = 0; k < 3; k++) {
    pos[k] = p0[k] + (p.radius - d) * n[k];
  }
  gs_contact_sphere(&p, NULL, p0, n, pos, v0, NULL, &out);
  EXPECT_NEAR(d, out.depth, 1e-14);
  EXPECT_REL(hertz(&p, d), out.normal_force, 1e-4, 1e-9);
  for (int k = 0; k < 3; k++) {
    EXPECT_REL(out.normal_force * n[k], out.force[k], 1e-12, 1e-9);
    EXPECT_NEAR(p0[k], out.point[k], 1e-14);
  }
}

static void separated_sphere_should_give_tiny_force(void) {
  gsContactParams p = sphere();
  double v0[3] = {0.0, 0.0, 0.0};
  double vapart[3] = {0.0, 0.0, 1.0};
  double e = 1e-5;

  // 1 cm apart: (ed^2 / (4 * 0.01))^1.5 * 4/3 E sqrt(R) = 5.8e-8 N
  EXPECT_TRUE(eval(&p, p.radius + 0.01, v0, 0) > 0.0);
  EXPECT_TRUE(eval(&p, p.radius + 0.01, v0, 0) < 1e-6);

  // touching: 4/3 E sqrt(R) (ed/2)^1.5 = 5.2e-3 N (times g+ = 1 + 2.5e-5)
  EXPECT_REL(hertz(&p, 0.5 * e), eval(&p, p.radius, v0, 0), 1e-4, 1e-12);

  // leaving fast (1 + 1.5 c d' = -0.5): Fn stays >= 0, about Fh * eg^2 / (4 * 0.5) = 5e-5 Fh
  EXPECT_TRUE(eval(&p, p.radius - 1e-3, vapart, 0) >= 0.0);
  EXPECT_TRUE(eval(&p, p.radius - 1e-3, vapart, 0) < 1e-4 * hertz(&p, 1e-3));
}

static void contact_should_be_c1_across_switches(void) {
  probe pr;
  double l, r;
  pr.prm = sphere();
  pr.v[0] = 0.5;
  pr.v[1] = 0.0;
  pr.v[2] = 0.0;

  // across d = 0 (z = R), Fn and Ft_x w.r.t. z; step 1e-9 m << eps_depth 1e-5 m
  pr.z = pr.prm.radius;
  pr.var = 0;
  for (int w = 0; w < 2; w++) {
    pr.which = w;
    one_sided(probe_fn, &pr, pr.prm.radius, 1e-9, &l, &r);
    EXPECT_TRUE(fabs(l) > 1.0);  // the slope is not trivially zero
    EXPECT_REL(l, r, 1e-3, 1e-6);
  }

  // across 1 + 1.5 c d' = 0 (v_z = 1/(1.5 c)), Fn w.r.t. v_z at d = 2 mm
  pr.z = pr.prm.radius - 2e-3;
  pr.var = 2;
  pr.which = 0;
  one_sided(probe_fn, &pr, 1.0 / (1.5 * pr.prm.dissipation), 1e-8, &l, &r);
  EXPECT_TRUE(fabs(l) > 1.0);
  EXPECT_REL(l, r, 1e-3, 1e-6);

  // across zero slip (v_x = 0) and the friction knee (v_x = vt), Ft_x w.r.t. v_x at d = 2 mm
  pr.v[2] = 0.0;
  pr.var = 1;
  pr.which = 1;
  one_sided(probe_fn, &pr, 0.0, 1e-7, &l, &r);
  EXPECT_TRUE(fabs(l) > 1.0);
  EXPECT_REL(l, r, 1e-3, 1e-6);
  // knee: vs = sqrt(v_x^2 + eps_slip^2) = vt at v_x = sqrt(vt^2 - 1e-6)
  one_sided(probe_fn, &pr, sqrt(pr.prm.v_transition * pr.prm.v_transition - 1e-6), 1e-7, &l, &r);
  EXPECT_REL(l, r, 1e-3, 1e-3);

  // the same check detects the kink of the unsmoothed Simbody law at vs = vt
  one_sided(friction_exact_fn, &pr.prm, pr.prm.v_transition, 1e-7, &l, &r);
  EXPECT_TRUE(fabs(l - r) > 0.1 * fabs(l));
  one_sided(friction_smooth_fn, &pr.prm, pr.prm.v_transition, 1e-7, &l, &r);
  EXPECT_REL(l, r, 1e-3, 1e-3);
}

static void friction_should_saturate_vanish_and_be_odd(void) {
  gsContactParams p = sphere();
  double z = p.radius - 2e-3;
  double fn, v[3] = {0.0, 0.0, 0.0};

  // zero slip: no tangential force
  fn = eval(&p, z, v, 0);
  EXPECT_NEAR(0.0, eval(&p, z, v, 1), 1e-12);

  // large slip (100 vt, muv = 0): |Ft| -> mud Fn, opposing the slip
  v[0] = 100.0 * p.v_transition;
  EXPECT_REL(-p.mu_dynamic * fn, eval(&p, z, v, 1), 1e-3, 1e-9);

  // odd in the slip velocity, at small, knee and large slip
  {
    double speeds[4] = {1e-4, 0.03, 0.1, 2.0};
    for (int i = 0; i < 4; i++) {
      double vp[3] = {speeds[i], 0.0, 0.0}, vm[3] = {-speeds[i], 0.0, 0.0};
      double fp = eval(&p, z, vp, 1);
      EXPECT_TRUE(fp < 0.0);
      EXPECT_REL(-fp, eval(&p, z, vm, 1), 1e-12, 1e-12);
    }
  }

  // smoothed law within 1 % of Simbody's away from the knee (vs <= vt/2 or >= 2 vt), within
  // 6 % at the knee (width 0.1: sat(1) = 0.95); viscous term as in Simbody
  {
    double vs_list[6] = {0.01, 0.03, 0.05, 0.2, 0.5, 3.0};
    for (int i = 0; i < 6; i++) {
      EXPECT_REL(gs_contact_friction_exact(&p, vs_list[i]),
                 gs_contact_friction_smooth(&p, vs_list[i], 0.1), 1e-2, 1e-9);
    }
    EXPECT_REL(p.mu_static, gs_contact_friction_smooth(&p, p.v_transition, 0.1), 6e-2, 1e-9);
    p.mu_viscous = 0.5;
    EXPECT_REL(gs_contact_friction_exact(&p, 1.0), gs_contact_friction_smooth(&p, 1.0, 0.1), 1e-3,
               1e-9);
    EXPECT_REL(p.mu_dynamic + 2.0 * (p.mu_static - p.mu_dynamic) / 101.0 + 0.5,
               gs_contact_friction_exact(&p, 1.0), 1e-12, 1e-9);
  }
}

static void params_should_be_read_from_user_row(void) {
  double user[GS_GEOM_NUSER];
  gsContactParams p;
  char err[128] = "";

  user[GS_GEOM_STIFFNESS] = 2e6;
  user[GS_GEOM_DISSIPATION] = 1.0;
  user[GS_GEOM_STATIC_FRICTION] = 0.9;
  user[GS_GEOM_DYNAMIC_FRICTION] = 0.8;
  user[GS_GEOM_VISCOUS_FRICTION] = 0.5;
  user[GS_GEOM_TRANSITION_VEL] = 0.1;
  EXPECT_EQ_INT(0, gs_contact_params_from_user(user, 0.03, &p, err, sizeof err));
  EXPECT_NEAR(2e6, p.stiffness, 0.0);
  EXPECT_NEAR(0.5, p.mu_viscous, 0.0);
  EXPECT_NEAR(0.03, p.radius, 0.0);

  // a zero transition velocity is rejected with a reason
  user[GS_GEOM_TRANSITION_VEL] = 0.0;
  EXPECT_EQ_INT(-1, gs_contact_params_from_user(user, 0.03, &p, err, sizeof err));
  EXPECT_TRUE(strstr(err, "transition") != NULL);
}

static void cop_of_two_equal_spheres_should_be_midpoint(void) {
  gsContactParams p = sphere();
  double v[3] = {0.3, 0.1, 0.0};
  double centres[2][3] = {{0.0, 0.0, 0.0}, {0.2, 0.1, 0.0}};
  double forces[6], points[6];
  gsFootGrf grf;

  // two identical spheres, same depth and slip: COP midway, no free moment
  for (int i = 0; i < 2; i++) {
    gsContactOut out;
    double pos[3] = {centres[i][0], centres[i][1], p.radius - 2e-3};
    gs_contact_sphere(&p, NULL, NULL, NULL, pos, v, NULL, &out);
    memcpy(forces + 3 * i, out.force, sizeof out.force);
    memcpy(points + 3 * i, out.point, sizeof out.point);
  }
  gs_contact_foot_grf(2, forces, points, NULL, NULL, 1.0, &grf);
  EXPECT_EQ_INT(1, grf.loaded);
  EXPECT_NEAR(0.1, grf.cop[0], 1e-12);
  EXPECT_NEAR(0.05, grf.cop[1], 1e-12);
  EXPECT_NEAR(0.0, grf.cop[2], 1e-12);
  EXPECT_NEAR(0.0, grf.free_moment, 1e-9);
  EXPECT_REL(2.0 * forces[2], grf.force[2], 1e-12, 1e-9);

  // unequal loads 100 N at x = 0 and 300 N at x = 0.2: COP at 0.15
  {
    double f2[6] = {0, 0, 100, 0, 0, 300};
    double p2[6] = {0, 0, 0, 0.2, 0, 0};
    gs_contact_foot_grf(2, f2, p2, NULL, NULL, 1.0, &grf);
    EXPECT_NEAR(0.15, grf.cop[0], 1e-12);
    EXPECT_NEAR(0.0, grf.cop[1], 1e-12);
  }
}

static void pure_couple_should_give_free_moment(void) {
  // (10, 0, 50) N at y = -0.05 and (-10, 0, 50) N at y = +0.05: net (0, 0, 100) N at the origin,
  // free moment 2 * 0.05 m * 10 N = 1 N m about +z
  double f[6] = {10, 0, 50, -10, 0, 50};
  double pts[6] = {0, -0.05, 0, 0, 0.05, 0};
  double p0[3] = {0.3, 0.4, 0.0};
  double fz[6] = {0, 0, 0, 0, 0, 0};
  gsFootGrf grf;

  gs_contact_foot_grf(2, f, pts, NULL, NULL, 1.0, &grf);
  EXPECT_EQ_INT(1, grf.loaded);
  EXPECT_NEAR(0.0, grf.cop[0], 1e-12);
  EXPECT_NEAR(0.0, grf.cop[1], 1e-12);
  EXPECT_NEAR(1.0, grf.free_moment, 1e-12);
  EXPECT_NEAR(0.0, grf.force[0], 1e-12);

  // the answer does not depend on the plane point chosen
  gs_contact_foot_grf(2, f, pts, p0, NULL, 1.0, &grf);
  EXPECT_NEAR(0.0, grf.cop[0], 1e-12);
  EXPECT_NEAR(0.0, grf.cop[1], 1e-12);
  EXPECT_NEAR(1.0, grf.free_moment, 1e-12);

  // unloaded foot: COP at the plane point, flagged
  gs_contact_foot_grf(2, fz, pts, p0, NULL, 1.0, &grf);
  EXPECT_EQ_INT(0, grf.loaded);
  EXPECT_NEAR(0.3, grf.cop[0], 0.0);
  EXPECT_NEAR(0.4, grf.cop[1], 0.0);
}

int main(void) {
  static_sphere_should_give_hertz_force();
  tilted_plane_should_match_floor();
  separated_sphere_should_give_tiny_force();
  contact_should_be_c1_across_switches();
  friction_should_saturate_vanish_and_be_odd();
  params_should_be_read_from_user_row();
  cop_of_two_equal_spheres_should_be_midpoint();
  pure_couple_should_give_free_moment();
  return GS_TEST_RESULT();
}
