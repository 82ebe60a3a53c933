// gs_knee.h: the six-DOF implant knee of subject JW (right leg): smooth surrogate of the
// elastic-foundation contact between femoral component and tibial insert, the knee ligaments, and
// the reference elastic-foundation model itself.
//
// Frames and coordinates. q = (knee_flexion, knee_adduction, knee_rotation, knee_tx, knee_ty,
// knee_tz) in OpenSim meaning (JW_AllBody_scaled.osim CustomJoint "knee", parent tibial_tray,
// child femoral_component):  p_tib = t + R p_fem,  R = Rz(flex) Rx(add) R_{-y}(rot),
// t = (tx, ty, tz). "fem" is the femoral_component frame, "tib" the tibial_tray frame; in
// jw_fullbody.xml the same six joints sit in body tibial_tray (reversed, mjmodels/README.md), and
// gs_knee_model_init finds them by name. Loads are on the tibia, in the tibial_tray frame, moments
// about the tibial_tray origin.
//
// Parameters come only from the mjModel (<custom><numeric name="gs_knee_*">, written by
// scripts/prepare_knee.py knee_custom_snippet, layout version 2; mjmodels/knee/README.md):
//   gs_knee_info     (9)   2, elements medial, elements lateral, ligament bundles, cells along w
//                          (ncw), cells along z (ncz), polynomial degree D, cull-table bins along
//                          w (ntw), along z (ntz)
//   gs_knee_layer    (9)   K/h (Pa/m), ramp eps (m), ramp cut-off b (m), edge width (m), tau_w (-),
//                          tau_z (m), tau_c (-), c0 (-), tau_f (-)
//   gs_knee_femur    per compartment (medial first) a block of GS_KNEE_NHEAD header numbers
//                          ax ay (m) cos(phi_mid) sin(phi_mid) W0 W1 (-) Z0 Z1 (m) hw (-) hz (m)
//                          dw (-) dz (m) gain (-) S0 S1 (-) 0, then ncw ncz T coefficients of G
//                          (m), ncw ncz T of E (m), ntw ntz cull-table values (m^2, see
//                          gs_knee_surrogate);
//                          T = (D+1)(D+2)/2, cell (i, j) at index i ncz + j, terms u^a v^b for
//                          a = 0..D, b = 0..D-a (a outer), table bin (i, j) at i ntz + j, bins
//                          uniform in s = tan(phi - phi_mid) over (S0, S1) and z over (Z0, Z1)
//   gs_knee_elements (7 n) per compartment (medial first) and column by column: the n_c centres
//                          px of its tibial elements (m), then py, pz (m), the normals nx, ny,
//                          nz (-), the areas (m^2)
//   gs_knee_ligaments (10 b) femoral point (3, m, fem), tibial point (3, m, tib), linear
//                           stiffness k (N/strain), slack length l0 (m), transition strain (-),
//                           damping coefficient c (N s/strain)
// gs_knee_femur, gs_knee_elements and gs_knee_ligaments are split into
// consecutive numerics NAME_0, NAME_1, ... of at most 280 values (MuJoCo 2.2.2's XML reader
// crashes on long numeric data); the compiler stores them contiguously and gs_knee_model_init
// checks that.
//
// Everything is C-infinity in q and qdot (the NLP differentiates by finite differences); no
// analytic partials are provided.
#ifndef GAITSIM_CALLBACKS_GS_KNEE_H_
#define GAITSIM_CALLBACKS_GS_KNEE_H_

#include <mujoco/mujoco.h>

#define GS_KNEE_NHEAD 16        // header numbers per compartment in gs_knee_femur
#define GS_KNEE_NELEM 7         // numbers per tibial element in gs_knee_elements
#define GS_KNEE_NLIG 10         // numbers per ligament bundle in gs_knee_ligaments

// Indices of the six knee coordinates in every q[6] array of this module.
typedef enum gsKneeCoord_ {
  GS_KNEE_FLEX = 0,             // knee_flexion, rotation about tib z (rad; < 0 is flexion)
  GS_KNEE_ADD,                  // knee_adduction, then about x (rad)
  GS_KNEE_ROT,                  // knee_rotation, then about -y (rad)
  GS_KNEE_TX,                   // knee_tx, along tib x (m)
  GS_KNEE_TY,                   // knee_ty, along tib y (m; 0.042 at the default pose)
  GS_KNEE_TZ                    // knee_tz, along tib z (m)
} gsKneeCoord;

// One compartment's femoral condyle (gs_knee_femur block), with derived constants.
typedef struct gsKneeFemur_ {
  const mjtNum* gcoef;          // coefficients of G, T per cell                        (m)
  const mjtNum* ecoef;          // coefficients of E, T per cell                        (m)
  const mjtNum* table;          // cull table, ntw x ntz, signed (gs_knee_surrogate)    (m^2)
  mjtNum ax, ay;                // axis position in the femoral x-y plane              (m)
  mjtNum cm, sm;                // cos, sin of phi_mid                                  (-)
  mjtNum w0, w1, z0, z1;        // domain                                               (-, m)
  mjtNum hw, hz, dw, dz;        // cell sizes and blend half-widths                     (-, m)
  mjtNum ihw, ihz;              // 1 / hw, 1 / hz                                       (-, 1/m)
  mjtNum s0, s1;                // cull-table range of s = tan(phi - phi_mid)           (-)
  mjtNum ts, tz;                // cull-table bins per unit s, per m                    (-, 1/m)
  mjtNum scale;                 // gain K/h                                              (Pa/m)
} gsKneeFemur;

// Parameters and model indices, filled by gs_knee_model_init; pointers point into the mjModel.
typedef struct gsKneeModel_ {
  int nelem[2];                 // tibial elements: medial, lateral                    (-)
  const mjtNum* elem[2];        // element columns px py pz nx ny nz area, nelem each   (7 x nelem)
  gsKneeFemur fem[2];           // femoral condyles: medial, lateral                   (see above)
  int ncw, ncz, deg, nterm;     // partition-of-unity cells, degree, terms per cell    (-)
  int ntw, ntz;                 // cull-table bins                                      (-)
  mjtNum k_over_h;              // layer modulus over thickness K/h                     (Pa/m)
  mjtNum ramp_eps;              // width of the smooth ramp                            (m)
  mjtNum ramp_cut;              // b: the ramp is 0 for overlaps <= -2 b               (m)
  mjtNum edge_width;            // width of the femoral edge mask                      (m)
  mjtNum tau_w, tau_z, tau_c;   // widths of the domain masks in w (-), z (m), c (-)
  mjtNum c0;                    // smallest cos(phi - phi_mid) of the domain            (-)
  mjtNum tau_f;                 // width of the smooth clamp of the normal cosine       (-)
  mjtNum itau_w, itau_z, itau_c, itau_f, iedge, icut;   // reciprocals of the widths above
  int nlig;                     // ligament bundles                                     (-)
  const mjtNum* lig;            // bundle rows, GS_KNEE_NLIG each                       (nlig x 10)
  int jnt[6];                   // joint ids in gsKneeCoord order                       (-)
  int qadr[6];                  // their qpos addresses                                 (-)
  int dadr[6];                  // their dof addresses                                  (-)
  int hinge[6];                 // 1 hinge, 0 slide                                     (-)
  int body_fem;                 // body id of femoral_component                        (-)
  int body_tib;                 // body id of tibial_tray                              (-)
} gsKneeModel;

// Contact loads on the tibia (tibial_tray frame).
typedef struct gsKneeContact_ {
  mjtNum force[2][3];           // force per compartment (medial, lateral)             (N)
  mjtNum moment[2][3];          // moment about the tibial_tray origin per compartment (N m)
  mjtNum magnitude[2];          // |force| per compartment                             (N)
  mjtNum total;                 // |medial + lateral force|                            (N)
} gsKneeContact;

// What gs_knee_passive applied, for output (knee_contact.sto).
typedef struct gsKneeLoads_ {
  gsKneeContact contact;        // surrogate contact loads                             (see above)
  mjtNum ligament_force;        // sum of bundle tensions                              (N)
  mjtNum qfrc[6];               // generalized forces added, gsKneeCoord order         (N m or N)
} gsKneeLoads;

// Pose of the femoral component in the tibial_tray frame from q (gsKneeCoord order):
// p_tib = t + R p_fem, R row-major (3 x 3). OpenSim SpatialTransform of JW's knee.
void gs_knee_pose(const mjtNum q[6], mjtNum R[9], mjtNum t[3]);

// Smooth ramp r(x) = (x + sqrt(x^2 + eps^2)) / 2, the C-infinity stand-in for max(x, 0).
mjtNum gs_knee_ramp(mjtNum x, mjtNum eps);

// Fill km from m. Returns 1 when m has the gs_knee numerics and the six knee joints and two
// bodies, 0 when it has no gs_knee_info numeric (not a knee model), -1 with a reason in err
// (errlen bytes, may be NULL) when the numerics are inconsistent.
int gs_knee_model_init(const mjModel* m, gsKneeModel* km, char* err, int errlen);

// Surrogate contact (mjmodels/knee/README.md; elastic foundation of Blankevoort et al. 1991,
// J Biomech 24:1019, and Bei & Fregly 2004, Med Eng Phys 26:777, eq. 1, on the real femoral
// geometry). Per compartment, in the femoral frame: v = (p'x - ax, p'y - ay), rho = |v|,
// (ux, uy) = (vx, -vy) / rho, w = ux cos(phi_mid) - uy sin(phi_mid), c = uy cos(phi_mid) +
// ux sin(phi_mid); the condyle is rho = G(w, z), its edge E(w, z) = 0, G and E partitions of unity
// of local polynomials: cell (i, j) of the uniform grid W0 + i hw, Z0 + j hz carries P_ij(u, v),
// u = (w - W0 - (i + 1/2) hw) / (hw / 2), v likewise, blended across each interior knot over
// +-dw (+-dz) by S((s + dw) / (2 dw)) with S(t) = 1 / (1 + exp((1 - 2t) / (t (1 - t)))) on (0, 1),
// 0 below, 1 above. Tibial element j (centre p_j, normal n_j, area A_j), p' = R^T (p_j - t),
// n' = R^T n_j:  g = G - rho,  f = -(vx n'x + vy n'y) / rho,  f+ = f S(f / tau_f),
//   r = (g + sqrt(g^2 + eps^2)) / 2 S((g + 2 b) / b),
//   M = S((w - W0) / tau_w) S((W1 - w) / tau_w) S((c - c0) / tau_c) S((z - Z0) / tau_z)
//       S((Z1 - z) / tau_z) S(E / edge_width + 1/2),
//   f_j = -gain K/h r f+ M A_j n_j.
// r and M vanish exactly far from contact: an element is skipped when it lies outside the domain
// or rho^2 > |table(s, z)|, s = tan(phi - phi_mid) (the table holds +-(B + 2 b)^2 with B a bound
// of G over each bin where M can be > 0, so the skip is exact; it needs one division and no
// square root, and about 40 of the 400 elements get the full evaluation at the held-out poses;
// 0 where nothing in the bin can carry load). A negative entry marks a bin where M is exactly 1
// throughout, so M is not evaluated there. out: forces, moments, magnitudes.
void gs_knee_surrogate(const gsKneeModel* km, const mjtNum q[6], gsKneeContact* out);

// Ligament bundle tension (N) of Blankevoort & Huiskes 1991 (J Biomech Eng 113:263, eq. 7, as in
// OpenSim's Blankevoort1991Ligament) with a smooth toe: strain e = l/l0 - 1, x = e/et,
//   F = k et [r(x)^2 - r(x - 1)^2] / 2 + c de/dt s(e),
// r the smooth ramp of width 0.05 (in x) and s(e) = (1 + e / sqrt(e^2 + (0.05 et)^2)) / 2;
// with hard ramps this is exactly 0 (e < 0), k e^2/(2 et) (0 <= e <= et), k (e - et/2) (e > et).
// row: one gs_knee_ligaments row; length l (m), lengthening speed (m/s).
mjtNum gs_knee_ligament_force(const mjtNum row[GS_KNEE_NLIG], mjtNum length, mjtNum speed);

// Per-model cache. gs_knee_register fills a gsKneeModel for m once (gs_physics_prepare calls it)
// and keeps it in a small process-wide table keyed on the mjModel pointer; gs_knee_lookup returns
// it without name look-ups, or NULL when m is not in the table (the table holds the
// GS_KNEE_CACHE_SLOTS most recently registered models). gs_knee_passive registers a model it
// does not find (a copy of a prepared model, e.g. the optimizer's mj_copyModel, or an unprepared
// one) on that first call, at most GS_KNEE_CACHE_LAZY_MAX times per process (beyond, it
// initialises by name on every call: about 6 us more for jw_fullbody_knee6.xml).
// Thread-safe: registering takes a lock and publishes an immutable entry with an atomic store;
// lookups are lock-free (atomic loads) and may run concurrently with registrations; replaced
// entries stay allocated for the life of the process (a concurrent lookup may still read them).
// Because a freed mjModel's address can be reused, every lookup also checks in O(1) that the
// entry still describes m (array pointers, counts, the names, addresses and sizes of the cached
// joints, bodies and numerics, and the numbers it copied from them); a mismatch returns NULL. gs_knee_register returns as
// gs_knee_model_init (1 registered, 0 not a knee model, -1 inconsistent).
#define GS_KNEE_CACHE_SLOTS 16
#define GS_KNEE_CACHE_LAZY_MAX 256
int gs_knee_register(const mjModel* m, char* err, int errlen);
const gsKneeModel* gs_knee_lookup(const mjModel* m);

// Add the surrogate contact and ligament generalized forces of the right knee to
// d->qfrc_passive (the six knee dofs only: the loads are internal to the knee, so they cancel on
// every other dof). Needs d->xpos, xmat, xanchor, xaxis, cvel, subtree_com (valid inside
// mjcb_passive). Uses the cached gsKneeModel of m (gs_knee_lookup; registered on the first call
// when missing, see above). out may be NULL. Returns 1 when applied, 0 when m has no gs_knee
// numerics (nothing done), -1 when they are inconsistent.
int gs_knee_passive(const mjModel* m, mjData* d, gsKneeLoads* out);

// As gs_knee_passive with a km filled once by gs_knee_model_init (no name look-ups).
void gs_knee_passive_model(const gsKneeModel* km, const mjModel* m, mjData* d, gsKneeLoads* out);

// ---- reference elastic foundation (Bei & Fregly 2004 eq. 1; linear thin layer) -------------

// Femoral triangle surface and tibial elements for gs_knee_ef_eval. Caller fills the input
// fields; gs_knee_ef_build allocates the search grid and work space; gs_knee_ef_free frees them.
typedef struct gsKneeEf_ {
  // input
  int nv;                       // femoral vertices                                    (-)
  const double* v;              // femoral vertices, fem frame                         (nv x 3, m)
  int nf;                       // femoral triangles (outward = towards the tibia)    (-)
  const int* f;                 // femoral triangle vertex indices                     (nf x 3)
  int ne;                       // tibial elements                                     (-)
  const double* ec;             // element centres, tib frame                          (ne x 3, m)
  const double* en;             // element unit normals (towards the femur)            (ne x 3)
  const double* ea;             // element areas                                       (ne, m^2)
  const int* ecomp;             // element compartment 0 medial, 1 lateral             (ne)
  double k_over_h;              // layer modulus over thickness K/h                    (Pa/m)
  double reach;                 // largest |distance| along the normal searched        (m)
  // built by gs_knee_ef_build
  double cell;                  // grid cell size in the tib x-z plane                 (m)
  double x0, z0;                // grid origin                                         (m)
  int gx, gz;                   // grid cells along x, z                               (-)
  int* cell_start;              // CSR start per cell                                  (gx*gz+1)
  int* cell_elem;               // element ids per cell                                (ne)
  double* vt;                   // work: femoral vertices in the tib frame             (nv x 3, m)
  double* depth;                // work: penetration per element (m; -1 = no surface)  (ne)
} gsKneeEf;

// K = (1 - nu) E / ((1 + nu)(1 - 2 nu)) (Pa): the thin-layer modulus of Blankevoort 1991 / Bei &
// Fregly 2004 eq. 1 for Young's modulus E (Pa) and Poisson's ratio nu (< 0.5).
double gs_knee_ef_layer_modulus(double young, double poisson);

// Allocate the grid and work arrays of ef (inputs filled). Returns 0, -1 on bad input or
// allocation failure with a reason in err. Caller frees with gs_knee_ef_free.
int gs_knee_ef_build(gsKneeEf* ef, char* err, int errlen);
void gs_knee_ef_free(gsKneeEf* ef);

// Elastic foundation at pose (R, t) (p_tib = t + R p_fem): each tibial element's penetration d
// is the distance, along its normal, by which the femoral surface lies beyond it (ray-triangle
// intersection, Moller & Trumbore 1997), p = K/h max(d, 0), f = -p A n on the tibia. Writes
// ef->depth. Returns the number of elements in contact.
int gs_knee_ef_eval(gsKneeEf* ef, const double R[9], const double t[3], gsKneeContact* out);

#endif  // GAITSIM_CALLBACKS_GS_KNEE_H_
