// gs_knee.c: surrogate knee contact, ligaments and the reference elastic foundation (gs_knee.h).
#include "callbacks/gs_knee.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GS_KNEE_LIG_RAMP 0.05      // width of the ligament ramps in x = e/et   (-)
#define GS_KNEE_MIN_LENGTH 1e-9    // guard for divisions by a length          (m)

static const char* const kKneeJoints[6] = {"knee_flexion", "knee_adduction", "knee_rotation",
                                           "knee_tx", "knee_ty", "knee_tz"};

// write a reason into err if there is room
static void set_err(char* err, int errlen, const char* reason) {
  if (err && errlen > 0) {
    snprintf(err, (size_t)errlen, "gs_knee: %s", reason);
  }
}

// numeric by name: data pointer and size, NULL when absent
static const mjtNum* numeric(const mjModel* m, const char* name, int* size) {
  int id = mj_name2id(m, mjOBJ_NUMERIC, name);
  if (id < 0) {
    *size = 0;
    return NULL;
  }
  *size = m->numeric_size[id];
  return m->numeric_data + m->numeric_adr[id];
}

// chunked numeric NAME_0, NAME_1, ... (contiguous in numeric_data): start and total size; NULL
// when NAME_0 is absent or a chunk is not contiguous with the previous one
static const mjtNum* numeric_chunks(const mjModel* m, const char* name, int* size) {
  char buf[64];
  int total = 0;
  const mjtNum* start = NULL;
  for (int k = 0;; k++) {
    int n;
    snprintf(buf, sizeof(buf), "%s_%d", name, k);
    const mjtNum* p = numeric(m, buf, &n);
    if (!p) {
      break;
    }
    if (k == 0) {
      start = p;
    } else if (p != start + total) {
      *size = 0;
      return NULL;
    }
    total += n;
  }
  *size = total;
  return start;
}

void gs_knee_pose(const mjtNum q[6], mjtNum R[9], mjtNum t[3]) {
  mjtNum cf = cos(q[GS_KNEE_FLEX]), sf = sin(q[GS_KNEE_FLEX]);
  mjtNum ca = cos(q[GS_KNEE_ADD]), sa = sin(q[GS_KNEE_ADD]);
  mjtNum cr = cos(q[GS_KNEE_ROT]), sr = sin(q[GS_KNEE_ROT]);

  // Rx(add) * Ry(-rot), then Rz(flex) * that (OpenSim body-fixed rotation order)
  mjtNum A[9] = {cr, 0, -sr, -sa * sr, ca, -sa * cr, ca * sr, sa, ca * cr};
  for (int j = 0; j < 3; j++) {
    R[0 + j] = cf * A[0 + j] - sf * A[3 + j];
    R[3 + j] = sf * A[0 + j] + cf * A[3 + j];
    R[6 + j] = A[6 + j];
  }
  t[0] = q[GS_KNEE_TX];
  t[1] = q[GS_KNEE_TY];
  t[2] = q[GS_KNEE_TZ];
}

mjtNum gs_knee_ramp(mjtNum x, mjtNum eps) {
  return 0.5 * (x + sqrt(x * x + eps * eps));
}

int gs_knee_model_init(const mjModel* m, gsKneeModel* km, char* err, int errlen) {
  int n_info, n_layer, n_torus, n_elem, n_lig;
  const mjtNum* info = numeric(m, "gs_knee_info", &n_info);
  memset(km, 0, sizeof(*km));
  if (!info) {
    return 0;
  }

  // sizes and version
  const mjtNum* layer = numeric(m, "gs_knee_layer", &n_layer);
  const mjtNum* torus = numeric(m, "gs_knee_torus", &n_torus);
  const mjtNum* elem = numeric_chunks(m, "gs_knee_elements", &n_elem);
  const mjtNum* lig = numeric_chunks(m, "gs_knee_ligaments", &n_lig);
  if (n_info != 4 || info[0] != 1.0) {
    set_err(err, errlen, "gs_knee_info must be (1, n_medial, n_lateral, n_ligaments)");
    return -1;
  }
  km->nelem[0] = (int)info[1];
  km->nelem[1] = (int)info[2];
  km->nlig = (int)info[3];
  if (!layer || n_layer != 2 || !torus || n_torus != 2 * GS_KNEE_NTORUS || !elem ||
      km->nelem[0] < 0 || km->nelem[1] < 0 || km->nlig < 0 ||
      n_elem != GS_KNEE_NELEM * (km->nelem[0] + km->nelem[1]) ||
      (km->nlig > 0 && (!lig || n_lig != GS_KNEE_NLIG * km->nlig))) {
    set_err(err, errlen, "gs_knee numerics missing or of the wrong size");
    return -1;
  }
  if (!(layer[0] > 0.0) || !(layer[1] > 0.0)) {
    set_err(err, errlen, "gs_knee_layer: K/h and eps must be > 0");
    return -1;
  }
  km->k_over_h = layer[0];
  km->ramp_eps = layer[1];
  km->torus[0] = torus;
  km->torus[1] = torus + GS_KNEE_NTORUS;
  km->elem[0] = elem;
  km->elem[1] = elem + GS_KNEE_NELEM * km->nelem[0];
  km->lig = km->nlig > 0 ? lig : NULL;

  // joints and bodies by name
  for (int i = 0; i < 6; i++) {
    km->jnt[i] = mj_name2id(m, mjOBJ_JOINT, kKneeJoints[i]);
    if (km->jnt[i] < 0) {
      set_err(err, errlen, "a knee joint (knee_flexion ... knee_tz) is missing");
      return -1;
    }
  }
  km->body_fem = mj_name2id(m, mjOBJ_BODY, "femoral_component");
  km->body_tib = mj_name2id(m, mjOBJ_BODY, "tibial_tray");
  if (km->body_fem < 0 || km->body_tib < 0) {
    set_err(err, errlen, "bodies femoral_component and tibial_tray are required");
    return -1;
  }
  for (int i = 0; i < 6; i++) {
    if (m->jnt_bodyid[km->jnt[i]] != km->body_tib) {
      set_err(err, errlen, "the six knee joints must belong to body tibial_tray");
      return -1;
    }
  }
  return 1;
}

void gs_knee_surrogate(const gsKneeModel* km, const mjtNum q[6], gsKneeContact* out) {
  mjtNum R[9], t[3];
  mjtNum th = q[GS_KNEE_FLEX];
  mjtNum eps2 = km->ramp_eps * km->ramp_eps;
  gs_knee_pose(q, R, t);
  memset(out, 0, sizeof(*out));

  for (int c = 0; c < 2; c++) {
    // torus of this compartment at this flexion
    const mjtNum* p = km->torus[c];
    mjtNum cx = p[0] + th * (p[1] + th * p[2]);
    mjtNum cy = p[3] + th * (p[4] + th * p[5]);
    mjtNum cz = p[6] + th * p[7], rmaj = p[8] + th * p[9], rmin = p[10];
    mjtNum scale = 0.5 * p[11] * km->k_over_h;
    mjtNum f[3] = {0, 0, 0}, mo[3] = {0, 0, 0};
    const mjtNum* e = km->elem[c];

    // one pass over the tibial elements
    for (int j = 0; j < km->nelem[c]; j++, e += GS_KNEE_NELEM) {
      mjtNum d0 = e[0] - t[0], d1 = e[1] - t[1], d2 = e[2] - t[2];
      mjtNum px = R[0] * d0 + R[3] * d1 + R[6] * d2 - cx;
      mjtNum py = R[1] * d0 + R[4] * d1 + R[7] * d2 - cy;
      mjtNum pz = R[2] * d0 + R[5] * d1 + R[8] * d2 - cz;
      mjtNum u = sqrt(px * px + py * py) - rmaj;
      mjtNum pen = rmin - sqrt(u * u + pz * pz);
      mjtNum w = scale * (pen + sqrt(pen * pen + eps2)) * e[6];
      f[0] -= w * e[3];
      f[1] -= w * e[4];
      f[2] -= w * e[5];
      mo[0] -= w * (e[1] * e[5] - e[2] * e[4]);
      mo[1] -= w * (e[2] * e[3] - e[0] * e[5]);
      mo[2] -= w * (e[0] * e[4] - e[1] * e[3]);
    }
    for (int i = 0; i < 3; i++) {
      out->force[c][i] = f[i];
      out->moment[c][i] = mo[i];
    }
    out->magnitude[c] = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  }

  // total
  mjtNum s[3];
  for (int i = 0; i < 3; i++) {
    s[i] = out->force[0][i] + out->force[1][i];
  }
  out->total = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
}

mjtNum gs_knee_ligament_force(const mjtNum row[GS_KNEE_NLIG], mjtNum length, mjtNum speed) {
  mjtNum k = row[6], l0 = row[7], et = row[8], c = row[9];
  if (l0 < GS_KNEE_MIN_LENGTH) {
    l0 = GS_KNEE_MIN_LENGTH;
  }
  if (et < 1e-6) {
    et = 1e-6;
  }

  // smooth toe + linear spring: k et [r(x)^2 - r(x-1)^2] / 2
  mjtNum e = length / l0 - 1.0;
  mjtNum x = e / et;
  mjtNum r0 = gs_knee_ramp(x, GS_KNEE_LIG_RAMP);
  mjtNum r1 = gs_knee_ramp(x - 1.0, GS_KNEE_LIG_RAMP);
  mjtNum spring = 0.5 * k * et * (r0 * r0 - r1 * r1);

  // damping while taut: c de/dt s(e)
  mjtNum w = GS_KNEE_LIG_RAMP * et;
  mjtNum step = 0.5 * (1.0 + e / sqrt(e * e + w * w));
  return spring + c * (speed / l0) * step;
}

// add the generalized forces of a force F (world) at world point p on the tibia to the six knee
// dofs: hinge a.((p - anchor) x F), slide a.F (MuJoCo joint axes and anchors of the tibia body)
static void add_point_force(const gsKneeModel* km, const mjModel* m, const mjData* d,
                            const mjtNum p[3], const mjtNum F[3], mjtNum Q[6]) {
  for (int i = 0; i < 6; i++) {
    int j = km->jnt[i];
    const mjtNum* a = d->xaxis + 3 * j;
    if (m->jnt_type[j] == mjJNT_HINGE) {
      const mjtNum* o = d->xanchor + 3 * j;
      mjtNum r[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
      mjtNum mx = r[1] * F[2] - r[2] * F[1];
      mjtNum my = r[2] * F[0] - r[0] * F[2];
      mjtNum mz = r[0] * F[1] - r[1] * F[0];
      Q[i] += a[0] * mx + a[1] * my + a[2] * mz;
    } else {
      Q[i] += a[0] * F[0] + a[1] * F[1] + a[2] * F[2];
    }
  }
}

// add a pure moment (world) on the tibia: hinge a.M, slide 0
static void add_moment(const gsKneeModel* km, const mjModel* m, const mjData* d,
                       const mjtNum M[3], mjtNum Q[6]) {
  for (int i = 0; i < 6; i++) {
    int j = km->jnt[i];
    if (m->jnt_type[j] == mjJNT_HINGE) {
      const mjtNum* a = d->xaxis + 3 * j;
      Q[i] += a[0] * M[0] + a[1] * M[1] + a[2] * M[2];
    }
  }
}

// velocity (world) of world point p fixed to body b: v = v_origin + w x (p - xpos)
static void point_velocity(const mjModel* m, const mjData* d, int b, const mjtNum p[3],
                           mjtNum v[3]) {
  mjtNum vel[6];
  mj_objectVelocity(m, d, mjOBJ_BODY, b, vel, 0);
  const mjtNum* x = d->xpos + 3 * b;
  mjtNum r[3] = {p[0] - x[0], p[1] - x[1], p[2] - x[2]};
  v[0] = vel[3] + vel[1] * r[2] - vel[2] * r[1];
  v[1] = vel[4] + vel[2] * r[0] - vel[0] * r[2];
  v[2] = vel[5] + vel[0] * r[1] - vel[1] * r[0];
}

void gs_knee_passive_model(const gsKneeModel* km, const mjModel* m, mjData* d, gsKneeLoads* out) {
  mjtNum q[6], Q[6] = {0, 0, 0, 0, 0, 0};
  gsKneeLoads loads;
  const mjtNum* xt = d->xpos + 3 * km->body_tib;
  const mjtNum* Rt = d->xmat + 9 * km->body_tib;
  const mjtNum* xf = d->xpos + 3 * km->body_fem;
  const mjtNum* Rf = d->xmat + 9 * km->body_fem;
  memset(&loads, 0, sizeof(loads));

  // coordinates by name
  for (int i = 0; i < 6; i++) {
    q[i] = d->qpos[m->jnt_qposadr[km->jnt[i]]];
  }

  // contact: per compartment the force at the tibial_tray origin plus its moment, in world
  gs_knee_surrogate(km, q, &loads.contact);
  for (int c = 0; c < 2; c++) {
    mjtNum F[3], M[3];
    mju_mulMatVec(F, Rt, loads.contact.force[c], 3, 3);
    mju_mulMatVec(M, Rt, loads.contact.moment[c], 3, 3);
    add_point_force(km, m, d, xt, F, Q);
    add_moment(km, m, d, M, Q);
  }

  // ligaments: tension along the line tibial point -> femoral point, on the tibia
  for (int b = 0; b < km->nlig; b++) {
    const mjtNum* row = km->lig + GS_KNEE_NLIG * b;
    mjtNum pf[3], pt[3], u[3], vf[3], vt[3];
    mju_mulMatVec(pf, Rf, row, 3, 3);
    mju_mulMatVec(pt, Rt, row + 3, 3, 3);
    for (int i = 0; i < 3; i++) {
      pf[i] += xf[i];
      pt[i] += xt[i];
      u[i] = pf[i] - pt[i];
    }
    mjtNum len = mju_norm3(u);
    if (len < GS_KNEE_MIN_LENGTH) {
      continue;
    }
    mju_scl3(u, u, 1.0 / len);
    point_velocity(m, d, km->body_fem, pf, vf);
    point_velocity(m, d, km->body_tib, pt, vt);
    mjtNum speed = u[0] * (vf[0] - vt[0]) + u[1] * (vf[1] - vt[1]) + u[2] * (vf[2] - vt[2]);
    mjtNum ten = gs_knee_ligament_force(row, len, speed);
    mjtNum F[3] = {ten * u[0], ten * u[1], ten * u[2]};
    add_point_force(km, m, d, pt, F, Q);
    loads.ligament_force += ten;
  }

  // accumulate
  for (int i = 0; i < 6; i++) {
    d->qfrc_passive[m->jnt_dofadr[km->jnt[i]]] += Q[i];
    loads.qfrc[i] = Q[i];
  }
  if (out) {
    *out = loads;
  }
}

int gs_knee_passive(const mjModel* m, mjData* d, gsKneeLoads* out) {
  gsKneeModel km;
  int rc = gs_knee_model_init(m, &km, NULL, 0);
  if (rc != 1) {
    return rc;
  }
  gs_knee_passive_model(&km, m, d, out);
  return 1;
}

// ---- reference elastic foundation ---------------------------------------------------------

double gs_knee_ef_layer_modulus(double young, double poisson) {
  return (1.0 - poisson) * young / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
}

void gs_knee_ef_free(gsKneeEf* ef) {
  free(ef->cell_start);
  free(ef->cell_elem);
  free(ef->vt);
  free(ef->depth);
  ef->cell_start = ef->cell_elem = NULL;
  ef->vt = ef->depth = NULL;
}

int gs_knee_ef_build(gsKneeEf* ef, char* err, int errlen) {
  double xmin = 1e30, xmax = -1e30, zmin = 1e30, zmax = -1e30;
  ef->cell_start = ef->cell_elem = NULL;
  ef->vt = ef->depth = NULL;
  if (ef->nv <= 0 || ef->nf <= 0 || ef->ne <= 0 || !ef->v || !ef->f || !ef->ec || !ef->en ||
      !ef->ea || !ef->ecomp || !(ef->k_over_h > 0.0) || !(ef->reach > 0.0)) {
    set_err(err, errlen, "elastic foundation: empty surface or bad parameters");
    return -1;
  }
  for (int i = 0; i < 3 * ef->nf; i++) {
    if (ef->f[i] < 0 || ef->f[i] >= ef->nv) {
      set_err(err, errlen, "elastic foundation: face index out of range");
      return -1;
    }
  }

  // grid over the elements' x-z extent, cells about 2 mm
  for (int j = 0; j < ef->ne; j++) {
    double x = ef->ec[3 * j], z = ef->ec[3 * j + 2];
    xmin = x < xmin ? x : xmin;
    xmax = x > xmax ? x : xmax;
    zmin = z < zmin ? z : zmin;
    zmax = z > zmax ? z : zmax;
  }
  ef->cell = 0.002;
  ef->x0 = xmin - 1e-6;
  ef->z0 = zmin - 1e-6;
  ef->gx = (int)((xmax - ef->x0) / ef->cell) + 1;
  ef->gz = (int)((zmax - ef->z0) / ef->cell) + 1;
  int ncell = ef->gx * ef->gz;
  ef->cell_start = calloc((size_t)ncell + 1, sizeof(int));
  ef->cell_elem = malloc(sizeof(int) * (size_t)ef->ne);
  ef->vt = malloc(sizeof(double) * 3 * (size_t)ef->nv);
  ef->depth = malloc(sizeof(double) * (size_t)ef->ne);
  if (!ef->cell_start || !ef->cell_elem || !ef->vt || !ef->depth) {
    gs_knee_ef_free(ef);
    set_err(err, errlen, "elastic foundation: out of memory");
    return -1;
  }

  // counting sort of the elements into cells (CSR)
  for (int j = 0; j < ef->ne; j++) {
    int cx = (int)((ef->ec[3 * j] - ef->x0) / ef->cell);
    int cz = (int)((ef->ec[3 * j + 2] - ef->z0) / ef->cell);
    ef->cell_start[cx * ef->gz + cz + 1]++;
  }
  for (int c = 0; c < ncell; c++) {
    ef->cell_start[c + 1] += ef->cell_start[c];
  }
  int* fill = calloc((size_t)ncell, sizeof(int));
  if (!fill) {
    gs_knee_ef_free(ef);
    set_err(err, errlen, "elastic foundation: out of memory");
    return -1;
  }
  for (int j = 0; j < ef->ne; j++) {
    int cx = (int)((ef->ec[3 * j] - ef->x0) / ef->cell);
    int cz = (int)((ef->ec[3 * j + 2] - ef->z0) / ef->cell);
    int c = cx * ef->gz + cz;
    ef->cell_elem[ef->cell_start[c] + fill[c]++] = j;
  }
  free(fill);
  return 0;
}

int gs_knee_ef_eval(gsKneeEf* ef, const double R[9], const double t[3], gsKneeContact* out) {
  double ymax = -1e30;
  int ncontact = 0;
  memset(out, 0, sizeof(*out));

  // femoral vertices into the tibial frame
  for (int i = 0; i < ef->nv; i++) {
    const double* p = ef->v + 3 * i;
    double* q = ef->vt + 3 * i;
    for (int r = 0; r < 3; r++) {
      q[r] = t[r] + R[3 * r] * p[0] + R[3 * r + 1] * p[1] + R[3 * r + 2] * p[2];
    }
  }
  for (int j = 0; j < ef->ne; j++) {
    ef->depth[j] = -1.0;
    ymax = ef->ec[3 * j + 1] > ymax ? ef->ec[3 * j + 1] : ymax;
  }

  // every femoral face that faces the tibia and reaches down to the insert
  for (int fi = 0; fi < ef->nf; fi++) {
    const double* a = ef->vt + 3 * ef->f[3 * fi];
    const double* b = ef->vt + 3 * ef->f[3 * fi + 1];
    const double* c = ef->vt + 3 * ef->f[3 * fi + 2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double ny = e1[2] * e2[0] - e1[0] * e2[2];
    double ylo = fmin(a[1], fmin(b[1], c[1]));
    if (ny >= 0.0 || ylo > ymax + ef->reach) {
      continue;
    }

    // grid cells under the face's x-z box, widened by the reach (tilted normals)
    double m = ef->reach;
    int cx0 = (int)floor((fmin(a[0], fmin(b[0], c[0])) - m - ef->x0) / ef->cell);
    int cx1 = (int)floor((fmax(a[0], fmax(b[0], c[0])) + m - ef->x0) / ef->cell);
    int cz0 = (int)floor((fmin(a[2], fmin(b[2], c[2])) - m - ef->z0) / ef->cell);
    int cz1 = (int)floor((fmax(a[2], fmax(b[2], c[2])) + m - ef->z0) / ef->cell);
    cx0 = cx0 < 0 ? 0 : cx0;
    cz0 = cz0 < 0 ? 0 : cz0;
    cx1 = cx1 >= ef->gx ? ef->gx - 1 : cx1;
    cz1 = cz1 >= ef->gz ? ef->gz - 1 : cz1;
    for (int gx = cx0; gx <= cx1; gx++) {
      for (int gz = cz0; gz <= cz1; gz++) {
        int cell = gx * ef->gz + gz;
        for (int k = ef->cell_start[cell]; k < ef->cell_start[cell + 1]; k++) {
          // Moller-Trumbore: element centre o + s n meets the face
          int j = ef->cell_elem[k];
          const double* o = ef->ec + 3 * j;
          const double* n = ef->en + 3 * j;
          double h[3] = {n[1] * e2[2] - n[2] * e2[1], n[2] * e2[0] - n[0] * e2[2],
                         n[0] * e2[1] - n[1] * e2[0]};
          double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
          if (fabs(det) < 1e-14) {
            continue;
          }
          double inv = 1.0 / det;
          double s[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
          double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) * inv;
          if (u < 0.0 || u > 1.0) {
            continue;
          }
          double qv[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                          s[0] * e1[1] - s[1] * e1[0]};
          double v = (n[0] * qv[0] + n[1] * qv[1] + n[2] * qv[2]) * inv;
          if (v < 0.0 || u + v > 1.0) {
            continue;
          }
          double dist = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
          if (fabs(dist) < ef->reach && -dist > ef->depth[j]) {
            ef->depth[j] = -dist;
          }
        }
      }
    }
  }

  // pressure p = K/h max(d, 0) on every element, summed per compartment
  for (int j = 0; j < ef->ne; j++) {
    double dpen = ef->depth[j];
    if (dpen <= 0.0) {
      continue;
    }
    ncontact++;
    int c = ef->ecomp[j] ? 1 : 0;
    double w = ef->k_over_h * dpen * ef->ea[j];
    const double* p = ef->ec + 3 * j;
    const double* n = ef->en + 3 * j;
    double f[3] = {-w * n[0], -w * n[1], -w * n[2]};
    for (int i = 0; i < 3; i++) {
      out->force[c][i] += f[i];
    }
    out->moment[c][0] += p[1] * f[2] - p[2] * f[1];
    out->moment[c][1] += p[2] * f[0] - p[0] * f[2];
    out->moment[c][2] += p[0] * f[1] - p[1] * f[0];
  }
  double s[3];
  for (int c = 0; c < 2; c++) {
    const double* f = out->force[c];
    out->magnitude[c] = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  }
  for (int i = 0; i < 3; i++) {
    s[i] = out->force[0][i] + out->force[1][i];
  }
  out->total = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  return ncontact;
}
