// gs_contact.h: smooth Hunt-Crossley sphere-plane contact with smoothed Coulomb/Stribeck/viscous
// friction, and the per-foot aggregation of sphere forces into a ground reaction (force, centre of
// pressure, free moment).
//
// Pure functions on plain doubles; nothing here knows about MuJoCo. The caller (mjcb_passive)
// reads the parameters from the geom `user` row (callbacks/gs_model_layout.h, gsGeomUser), the
// sphere centre and the velocities from mjData, and applies the returned force at the returned
// point.
//
// Model (normal force): Hunt & Crossley 1975, J Appl Mech 42:440, as in Simbody's
// HuntCrossleyForce (OpenSim HuntCrossleyForce) for one compliant sphere on a rigid plane:
//   Fn = 4/3 E sqrt(R) d^(3/2) (1 + 3/2 c d')
// Model (friction): Simbody's HuntCrossleyForce friction law
//   mu(vs) = min(vs/vt, 1) (mud + 2 (mus - mud) / (1 + (vs/vt)^2)) + muv vs,  Ft = -mu Fn vt_dir.
// Smoothing: every kink of the original (max(d,0), the damping sign, min(., 1), the slip
// direction) is replaced by an infinitely differentiable blend, in the spirit of Serrancoli et al.
// 2019 (IEEE Trans Neural Syst Rehabil Eng) and Falisse et al. 2019 (J R Soc Interface 16:20190402)
// SmoothSphereHalfSpaceForce, so the force is C-infinity (in particular C1) in position and
// velocity, as direct collocation with finite-difference Jacobians requires. No analytic partials
// are provided: optim/ differentiates these functions by finite differences.
#ifndef GAITSIM_CALLBACKS_GS_CONTACT_H_
#define GAITSIM_CALLBACKS_GS_CONTACT_H_

// Parameters of one contact sphere (OpenSim HuntCrossleyForce, one geom user row + radius).
typedef struct gsContactParams_ {
  double stiffness;     // plane-strain modulus E                             (N/m^2)
  double dissipation;   // Hunt-Crossley dissipation c                        (s/m)
  double mu_static;     // static friction coefficient mus                    (-)
  double mu_dynamic;    // dynamic friction coefficient mud                   (-)
  double mu_viscous;    // viscous friction coefficient muv                   (s/m)
  double v_transition;  // transition velocity vt of the friction law         (m/s)
  double radius;        // sphere radius R                                    (m)
} gsContactParams;

// Widths of the smooth approximations; gs_contact_smoothing_default() gives the defaults below.
typedef struct gsContactSmoothing_ {
  double eps_depth;     // width of max(d,0) ~ (d + sqrt(d^2 + e^2))/2        (m),   1e-5
  double eps_damping;   // width of max(1 + 1.5 c d', 0), same form           (-),   1e-2
  double eps_slip;      // slip speed regulariser vs = sqrt(|v_t|^2 + e^2)    (m/s), 1e-3
  double knee_friction; // width of min(vs/vt, 1) near vs = vt                (-),   0.1
} gsContactSmoothing;

// Result of one sphere-plane evaluation. force and point are what the caller applies; the rest is
// for inspection and output.
typedef struct gsContactOut_ {
  double force[3];      // force on the sphere, world frame                   (N)
  double point[3];      // contact point: sphere centre projected on the plane (m)
  double depth;         // penetration d = R - (p - p0).n, negative when apart (m)
  double depth_smooth;  // smoothed penetration d+ > 0                        (m)
  double depth_rate;    // penetration rate d' = -v.n                         (m/s)
  double normal_force;  // Fn >= 0 along the plane normal                     (N)
  double slip_speed;    // regularised slip speed vs                          (m/s)
  double mu;            // friction coefficient of the smoothed law           (-)
} gsContactOut;

// Fill s with the default smoothing widths (the values listed in gsContactSmoothing).
void gs_contact_smoothing_default(gsContactSmoothing* s);

// Fill prm from one geom user row (GS_GEOM_NUSER entries, order of gsGeomUser) and the sphere
// radius (m). Returns 0, or -1 with a reason in err (errlen bytes, may be NULL) when a parameter
// is out of range (E < 0, c < 0, a friction coefficient < 0, vt <= 0, R <= 0).
int gs_contact_params_from_user(const double* user, double radius, gsContactParams* prm,
                                char* err, int errlen);

// Smooth Hunt-Crossley force of one sphere on a static plane.
//   prm           sphere parameters
//   sm            smoothing widths; NULL: defaults
//   plane_point   a point of the plane (3, world, m); NULL: origin
//   plane_normal  plane normal pointing out of the ground (3, world, -); NULL: +z. Normalised here.
//   pos           sphere centre (3, world, m)
//   vel           sphere centre velocity (3, world, m/s); its normal part gives d' = -vel.n
//   vel_contact   velocity of the body-fixed point at out->point (3, world, m/s), computed by the
//                 caller from the body's twist (v + w x r); its tangential part is the slip
//                 velocity. NULL: vel (a non-rotating sphere).
// Equations (smoothed forms, widths from sm):
//   d+ = (d + sqrt(d^2 + ed^2)) / 2                             smooth max(d, 0)
//   g  = 1 + 1.5 c d',  g+ = (g + sqrt(g^2 + eg^2)) / 2         smooth max(g, 0)
//   Fn = 4/3 E sqrt(R) d+^(3/2) g+                             Hunt & Crossley 1975
//   vs = sqrt(|v_t|^2 + ev^2),  s = vs / vt
//   mu = sat(s) (mud + 2 (mus - mud) / (1 + s^2)) + muv vs      Simbody HuntCrossleyForce
//   sat(s) = (s - r(s - 1) + r(-1)) / (1 + r(-1)),  r(x) = (x + sqrt(x^2 + w^2)) / 2
//   F  = Fn n - mu Fn v_t / vs
// Accuracy: Fn/Fn_exact - 1 ~ 3/8 (ed/d)^2 + (eg/g)^2/4 for d >> ed, g >> eg (static, d = 1 mm:
// 3.75e-5 + 2.5e-5). At d = 0 the elastic force is 4/3 E sqrt(R) (ed/2)^(3/2) (E = 1e6 N/m^2,
// R = 0.03 m: 2.6e-3 N) and falls as (ed^2/(4|d|))^(3/2) with separation |d|. sat(s) equals
// min(s, 1) at s = 0 and s -> inf exactly and is within w/2 of it at the knee s = 1.
void gs_contact_sphere(const gsContactParams* prm, const gsContactSmoothing* sm,
                       const double plane_point[3], const double plane_normal[3],
                       const double pos[3], const double vel[3], const double vel_contact[3],
                       gsContactOut* out);

// Friction coefficient of Simbody's HuntCrossleyForce at slip speed vs (m/s), unsmoothed (a kink
// at vs = vt): min(vs/vt, 1) (mud + 2 (mus - mud) / (1 + (vs/vt)^2)) + muv vs. Reference for the
// smoothed law.
double gs_contact_friction_exact(const gsContactParams* prm, double vs);

// Friction coefficient of the smoothed law at slip speed vs (m/s), knee width w (-), see
// gs_contact_sphere.
double gs_contact_friction_smooth(const gsContactParams* prm, double vs, double w);

// Ground reaction of one foot: the resultant of n sphere forces and its centre of pressure.
typedef struct gsFootGrf_ {
  double force[3];      // total force on the foot, world                     (N)
  double moment[3];     // total moment about the plane point, world          (N m)
  double cop[3];        // centre of pressure, on the plane                   (m)
  double free_moment;   // moment about the plane normal at the COP           (N m)
  int loaded;           // 1 when the normal force exceeded the threshold, else 0
} gsFootGrf;

// Aggregate n sphere forces (n x 3, world, N) applied at points (n x 3, world, m) into the
// resultant force, the moment about the plane point p0, the centre of pressure and the free
// moment. The COP is the point of the plane about which the resultant moment is parallel to the
// plane normal n (no moment about in-plane axes):
//   M = sum (r_i - p0) x F_i,  Fn = F.n,  cop = p0 + (n x M) / Fn,  T = (M - (cop - p0) x F).n
// Guard (thresholded, documented): when Fn <= fn_min (N) the COP is undefined; then cop = p0,
// T = M.n and loaded = 0. Use fn_min of a few newtons for output (a few tenths of a percent of body
// weight); the result is exact whenever loaded = 1. plane_point/plane_normal as in
// gs_contact_sphere (NULL: origin, +z).
void gs_contact_foot_grf(int n, const double* forces, const double* points,
                         const double plane_point[3], const double plane_normal[3],
                         double fn_min, gsFootGrf* out);

#endif  // GAITSIM_CALLBACKS_GS_CONTACT_H_
