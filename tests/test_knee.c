// test_knee.c: implant-knee contact and ligaments (callbacks/gs_knee.h): elastic foundation
// against the analytic sphere on a thin layer, C elastic foundation against the Python reference,
// surrogate against the elastic foundation on held-out poses, finite-difference smoothness of the
// surrogate, the per-model cache (gs_knee_register / gs_knee_lookup, also from several threads),
// ligament lengthening speeds against finite differences, and the knee fixture loaded by 2 BW
// compression settling to a plausible pose.
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_knee.h"
#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "tests/gs_test.h"
#include "tests/gs_test_csv.h"

#define FIXTURE GAITSIM_SOURCE_DIR "/tests/fixtures/knee6.xml"
#define HELDOUT GAITSIM_SOURCE_DIR "/mjmodels/knee/jw_knee_heldout.csv"
#define EF_MESH GAITSIM_SOURCE_DIR "/mjmodels/knee/jw_knee_ef_mesh.txt"
#define MAXROWS 256             // the held-out table has 200 rows
#define BW 614.25               // JW's body weight, 62.636 kg x 9.80665 m/s^2   (N)

// insert material of the Grand Challenge TKA (DM_tka_ligaments.osim): E, nu, h
#define E_INSERT 46.3e6
#define NU_INSERT 0.46
#define H_INSERT 0.005

// held-out table: q (6) then medial F M, lateral F M (12)
static int read_heldout(double rows[MAXROWS][18]) {
  return gs_test_read_csv_rows(HELDOUT, 18, 18, &rows[0][0], MAXROWS);
}

// ---- elastic foundation: sphere of radius R pressed by depth d into a layer on a rigid base ----
//
// Thin layer (Blankevoort 1991): p(r) = K/h delta(r), delta(r) = sqrt(R^2 - r^2) - (R - d) over
// the contact circle a^2 = R^2 - (R - d)^2. F = K/h * (volume of the spherical cap of height d)
// = K/h * pi d^2 (3R - d) / 3 = pi K d^2 R / h * (1 - d / (3R)); for d << R, F = pi K d^2 R / h
// (the paraboloid delta = d - r^2/(2R) integrates to 2 pi K/h (R d^2 - R d^2/2) exactly that).
static void test_ef_sphere_on_thin_layer(void) {
  const double R = 0.03;
  const int nth = 60, nph = 180;
  const double th_max = 15.0 * M_PI / 180.0;
  const int ng = 97;
  const double half = 0.006;
  int nv = 1 + nth * nph, nf = nph + 2 * nph * (nth - 1), ne = ng * ng;
  double* v = malloc(sizeof(double) * 3 * (size_t)nv);
  int* f = malloc(sizeof(int) * 3 * (size_t)nf);
  double* ec = malloc(sizeof(double) * 3 * (size_t)ne);
  double* en = malloc(sizeof(double) * 3 * (size_t)ne);
  double* ea = malloc(sizeof(double) * (size_t)ne);
  int* comp = malloc(sizeof(int) * (size_t)ne);

  // lower spherical cap (centre at the femoral origin), outward normals facing -y
  v[0] = 0;
  v[1] = -R;
  v[2] = 0;
  for (int i = 1; i <= nth; i++) {
    double th = th_max * i / nth;
    for (int j = 0; j < nph; j++) {
      double ph = 2 * M_PI * j / nph;
      double* p = v + 3 * (1 + (i - 1) * nph + j);
      p[0] = R * sin(th) * cos(ph);
      p[1] = -R * cos(th);
      p[2] = R * sin(th) * sin(ph);
    }
  }
  int k = 0;
  for (int j = 0; j < nph; j++) {
    int a = 1 + j, b = 1 + (j + 1) % nph;
    f[k++] = 0;
    f[k++] = a;
    f[k++] = b;
  }
  for (int i = 1; i < nth; i++) {
    for (int j = 0; j < nph; j++) {
      int a = 1 + (i - 1) * nph + j, b = 1 + (i - 1) * nph + (j + 1) % nph;
      int c = a + nph, e = b + nph;
      f[k++] = a;
      f[k++] = c;
      f[k++] = e;
      f[k++] = a;
      f[k++] = e;
      f[k++] = b;
    }
  }

  // flat layer y = 0, normal +y, square elements of 0.125 mm, split between "compartments"
  double dx = 2 * half / ng;
  for (int i = 0; i < ng; i++) {
    for (int j = 0; j < ng; j++) {
      int e = i * ng + j;
      ec[3 * e] = -half + (i + 0.5) * dx;
      ec[3 * e + 1] = 0;
      ec[3 * e + 2] = -half + (j + 0.5) * dx;
      en[3 * e] = 0;
      en[3 * e + 1] = 1;
      en[3 * e + 2] = 0;
      ea[e] = dx * dx;
      comp[e] = ec[3 * e + 2] > 0;
    }
  }

  // orientation check: the cap's face normals point down (towards the layer)
  {
    const double* a = v + 3 * f[3];
    const double* b = v + 3 * f[4];
    const double* c = v + 3 * f[5];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    EXPECT_TRUE(e1[2] * e2[0] - e1[0] * e2[2] < 0);
  }

  gsKneeEf ef;
  memset(&ef, 0, sizeof(ef));
  double K = gs_knee_ef_layer_modulus(E_INSERT, NU_INSERT);
  ef.nv = nv;
  ef.v = v;
  ef.nf = nf;
  ef.f = f;
  ef.ne = ne;
  ef.ec = ec;
  ef.en = en;
  ef.ea = ea;
  ef.ecomp = comp;
  ef.k_over_h = K / H_INSERT;
  // reach: the search margin; 0.5 mm covers the depths tested (<= 0.2 mm) and keeps the grid
  // search small (3 mm made this test take about 1 s)
  ef.reach = 0.0005;
  char err[200];
  EXPECT_EQ_INT(0, gs_knee_ef_build(&ef, err, sizeof(err)));

  // K for E 46.3 MPa, nu 0.46: 0.54 x 46.3e6 / (1.46 x 0.08) = 214.06 MPa
  EXPECT_NEAR(214.058e6, K, 0.01e6);

  // depths 0.05, 0.1, 0.2 mm: force within 1 % of the cap formula, and the small-depth law
  double Rm[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double depths[3] = {0.05e-3, 0.1e-3, 0.2e-3};
  for (int i = 0; i < 3; i++) {
    double d = depths[i];
    double t[3] = {0.0, R - d, 0.0};
    gsKneeContact out;
    int n = gs_knee_ef_eval(&ef, Rm, t, &out);
    double exact = M_PI * K * d * d * (3 * R - d) / (3 * H_INSERT);
    double small = M_PI * K * d * d * R / H_INSERT;
    double fy = out.force[0][1] + out.force[1][1];
    printf("sphere on layer: d %.2f mm, %d elements, Fy %.2f N, cap %.2f N, pi K d^2 R/h %.2f N\n",
           1e3 * d, n, -fy, exact, small);
    EXPECT_REL(exact, -fy, 0.01, 1.0);
    EXPECT_REL(small, -fy, 0.01 + d / (3 * R), 1.0);
    EXPECT_NEAR(0.0, out.force[0][0] + out.force[1][0], 1e-3 * exact);
    EXPECT_NEAR(0.0, out.force[0][2] + out.force[1][2], 1e-3 * exact);
  }

  // apart: no force
  {
    double t[3] = {0.0, R + 1e-4, 0.0};
    gsKneeContact out;
    EXPECT_EQ_INT(0, gs_knee_ef_eval(&ef, Rm, t, &out));
    EXPECT_NEAR(0.0, out.total, 0.0);
  }
  gs_knee_ef_free(&ef);
  free(v);
  free(f);
  free(ec);
  free(en);
  free(ea);
  free(comp);
}

// ---- C elastic foundation on JW's refined surfaces against the Python reference ------------
static int load_ef_mesh(gsKneeEf* ef, double** v, int** f, double** ec, double** en,
                        double** ea, int** comp) {
  FILE* fp = fopen(EF_MESH, "r");
  char line[512];
  int nv = 0, nf = 0, ne = 0;
  if (!fp) {
    return -1;
  }
  while (fgets(line, sizeof(line), fp) && line[0] == '#') {
  }
  if (sscanf(line, "%d %d", &nv, &nf) != 2 || nv <= 0 || nf <= 0) {
    fclose(fp);
    return -1;
  }
  *v = malloc(sizeof(double) * 3 * (size_t)nv);
  *f = malloc(sizeof(int) * 3 * (size_t)nf);
  int ok = *v && *f;
  for (int i = 0; ok && i < nv; i++) {
    ok = fscanf(fp, "%lf %lf %lf", *v + 3 * i, *v + 3 * i + 1, *v + 3 * i + 2) == 3;
  }
  for (int i = 0; ok && i < nf; i++) {
    ok = fscanf(fp, "%d %d %d", *f + 3 * i, *f + 3 * i + 1, *f + 3 * i + 2) == 3;
  }
  ok = ok && fscanf(fp, "%d", &ne) == 1 && ne > 0;
  if (ok) {
    *ec = malloc(sizeof(double) * 3 * (size_t)ne);
    *en = malloc(sizeof(double) * 3 * (size_t)ne);
    *ea = malloc(sizeof(double) * (size_t)ne);
    *comp = malloc(sizeof(int) * (size_t)ne);
    ok = *ec && *en && *ea && *comp;
  }
  for (int i = 0; ok && i < ne; i++) {
    double* c = *ec + 3 * i;
    double* n = *en + 3 * i;
    ok = fscanf(fp, "%lf %lf %lf %lf %lf %lf %lf %d", c, c + 1, c + 2, n, n + 1, n + 2,
                *ea + i, *comp + i) == 8;
  }
  fclose(fp);
  if (!ok) {
    return -1;
  }
  memset(ef, 0, sizeof(*ef));
  ef->nv = nv;
  ef->v = *v;
  ef->nf = nf;
  ef->f = *f;
  ef->ne = ne;
  ef->ec = *ec;
  ef->en = *en;
  ef->ea = *ea;
  ef->ecomp = *comp;
  ef->k_over_h = gs_knee_ef_layer_modulus(E_INSERT, NU_INSERT) / H_INSERT;
  ef->reach = 0.003;
  return 0;
}

static void test_ef_matches_python_reference(double rows[MAXROWS][18], int nrows) {
  gsKneeEf ef;
  double *v = NULL, *ec = NULL, *en = NULL, *ea = NULL;
  int *f = NULL, *comp = NULL;
  char err[200];
  EXPECT_EQ_INT(0, load_ef_mesh(&ef, &v, &f, &ec, &en, &ea, &comp));
  if (!v || !ec) {
    free(v);
    free(f);
    return;
  }
  EXPECT_EQ_INT(0, gs_knee_ef_build(&ef, err, sizeof(err)));
  double worst = 0.0;
  for (int r = 0; r < nrows; r++) {
    double R[9], t[3];
    gsKneeContact out;
    gs_knee_pose(rows[r], R, t);
    gs_knee_ef_eval(&ef, R, t, &out);
    for (int c = 0; c < 2; c++) {
      for (int i = 0; i < 3; i++) {
        double e = rows[r][6 + 6 * c + i], a = out.force[c][i];
        double rel = fabs(a - e) / fmax(fabs(e), 1.0);
        worst = rel > worst ? rel : worst;
        EXPECT_REL(e, a, 1e-4, 1.0);
      }
    }
  }
  printf("C elastic foundation vs Python: worst relative force difference %.2e over %d poses\n",
         worst, nrows);
  gs_knee_ef_free(&ef);
  free(v);
  free(f);
  free(ec);
  free(en);
  free(ea);
  free(comp);
}

// ---- surrogate against the elastic foundation on held-out poses ---------------------------
static void test_surrogate_heldout(const gsKneeModel* km, double rows[MAXROWS][18], int nrows) {
  double peak[12] = {0}, ss[12] = {0}, peak_mag[2] = {0}, ss_mag[2] = {0};
  for (int r = 0; r < nrows; r++) {
    gsKneeContact out;
    gs_knee_surrogate(km, rows[r], &out);
    for (int c = 0; c < 2; c++) {
      double me = 0.0;
      for (int i = 0; i < 6; i++) {
        double e = rows[r][6 + 6 * c + i];
        double a = i < 3 ? out.force[c][i] : out.moment[c][i - 3];
        peak[6 * c + i] = fmax(peak[6 * c + i], fabs(e));
        ss[6 * c + i] += (a - e) * (a - e);
        if (i < 3) {
          me += e * e;
        }
      }
      me = sqrt(me);
      peak_mag[c] = fmax(peak_mag[c], me);
      ss_mag[c] += (out.magnitude[c] - me) * (out.magnitude[c] - me);
    }
  }

  // RMS per component as % of its peak over the held-out table. Issue #7 targets <= 3 %. Reached
  // (2026-12-01, mjmodels/knee/README.md): |F| 0.48 % medial, 0.50 % lateral; components
  // 0.39-1.31 % (the largest: lateral Fx and My, whose held-out peaks are small). These bounds
  // guard what was reached: |F| within 0.75 %, every component within 1.5 %.
  const char* names[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
  for (int c = 0; c < 2; c++) {
    double pct = 100.0 * sqrt(ss_mag[c] / nrows) / peak_mag[c];
    printf("surrogate %s |F|: RMS %.2f %% of peak %.0f N (%d held-out poses)\n",
           c ? "lateral" : "medial", pct, peak_mag[c], nrows);
    EXPECT_TRUE(pct <= 0.75);
    for (int i = 0; i < 6; i++) {
      double p = 100.0 * sqrt(ss[6 * c + i] / nrows) / peak[6 * c + i];
      printf("  %s: RMS %.2f %% of peak %.3g\n", names[i], p, peak[6 * c + i]);
      EXPECT_TRUE(p <= 1.5);
    }
  }
}

// ---- finite-difference smoothness of the surrogate ----------------------------------------
// central differences with steps h and h/2 agree (the derivative exists and is continuous at the
// scale of the steps): |D(h) - D(h/2)| <= 2 % of max(|D|, floor), for all 6 x 6 force/moment
// derivatives at 20 held-out poses; h = 2e-5 rad, 1e-6 m (below the 5 um ramp width). floor: 1 %
// of the coordinate's largest derivative, and at least a change of 0.01 N (0.5 mN m for moments)
// per 1 um of motion (per 2.5e-5 rad, 1 um at 40 mm): at poses without contact the surrogate's
// compactly supported ramp leaves forces of 1e-4 N whose relative derivatives are large but
// physically nil (3e-6 of the peak loads).
static void fd_derivs(const gsKneeModel* km, const double q0[6], int i, double h, double D[12]) {
  double qp[6], qm[6];
  gsKneeContact op, om;
  memcpy(qp, q0, sizeof(qp));
  memcpy(qm, q0, sizeof(qm));
  qp[i] += h;
  qm[i] -= h;
  gs_knee_surrogate(km, qp, &op);
  gs_knee_surrogate(km, qm, &om);
  for (int c = 0; c < 2; c++) {
    for (int k = 0; k < 3; k++) {
      D[6 * c + k] = (op.force[c][k] - om.force[c][k]) / (2 * h);
      D[6 * c + 3 + k] = (op.moment[c][k] - om.moment[c][k]) / (2 * h);
    }
  }
}

static void test_surrogate_fd_smooth(const gsKneeModel* km, double rows[MAXROWS][18],
                                     int nrows) {
  int bad = 0, checked = 0;
  double worst = 0.0;
  for (int r = 0; r < nrows && r < 20; r++) {
    for (int i = 0; i < 6; i++) {
      double h = i < 3 ? 2e-5 : 1e-6;
      double D1[12], D2[12];
      fd_derivs(km, rows[r], i, h, D1);
      fd_derivs(km, rows[r], i, 0.5 * h, D2);
      // floor: 1 % of the largest derivative of this coordinate, and the absolute floor above
      double floor = 0.0;
      for (int k = 0; k < 12; k++) {
        floor = fmax(floor, 0.01 * fabs(D2[k]));
      }
      double abs_floor = i < 3 ? 0.01 / 2.5e-5 : 0.01 / 1e-6;   // N/rad, N/m
      for (int k = 0; k < 12; k++) {
        double fl = fmax(floor, (k % 6) < 3 ? abs_floor : 0.05 * abs_floor);
        double rel = fabs(D1[k] - D2[k]) / fmax(fabs(D2[k]), fl);
        worst = rel > worst ? rel : worst;
        bad += rel > 0.02;
        checked++;
      }
    }
  }
  printf("surrogate FD smoothness: worst |D(h)-D(h/2)| / max(|D|, floor) = %.2e (%d checks)\n",
         worst, checked);
  EXPECT_EQ_INT(0, bad);

  // onset of contact: sweep knee_ty through first contact in 0.25 um steps; the stiffness
  // dFy/dty changes by less than 2 % of its final value between neighbouring steps (no kink)
  double q[6];
  memcpy(q, rows[0], sizeof(q));
  gsKneeContact o;
  double ty_hi = q[GS_KNEE_TY] + 2e-4, ty_lo = q[GS_KNEE_TY];
  for (int it = 0; it < 60; it++) {
    double mid = 0.5 * (ty_hi + ty_lo);
    q[GS_KNEE_TY] = mid;
    gs_knee_surrogate(km, q, &o);
    if (o.total > 1.0) {
      ty_lo = mid;
    } else {
      ty_hi = mid;
    }
  }
  double prev = NAN, kmax = 0.0, jump = 0.0;
  for (int s = -40; s <= 80; s++) {
    double D[12];
    q[GS_KNEE_TY] = ty_lo + 0.25e-6 * (40 - s);
    fd_derivs(km, q, GS_KNEE_TY, 0.1e-6, D);
    double kk = D[1] + D[7];
    if (s > -40) {
      jump = fmax(jump, fabs(kk - prev));
    }
    kmax = fmax(kmax, fabs(kk));
    prev = kk;
  }
  printf("contact onset: stiffness up to %.3g N/m, largest step-to-step change %.2f %%\n", kmax,
         100.0 * jump / kmax);
  EXPECT_TRUE(jump <= 0.05 * kmax);
}

// ---- fixture: pose formula, generalized forces, 2 BW compression -------------------------
static gsKneeModel g_km;        // filled once for the passive callback (no name look-ups)

static void knee_passive_cb(const mjModel* m, mjData* d) {
  gs_knee_passive_model(&g_km, m, d, NULL);
}

static void test_fixture(const mjModel* m, const gsKneeModel* km) {
  mjData* d = mj_makeData(m);
  int qa[6];
  for (int i = 0; i < 6; i++) {
    qa[i] = m->jnt_qposadr[km->jnt[i]];
  }

  // the pose formula reproduces MuJoCo's kinematics of the reversed joints
  double qtest[6] = {-0.7, 0.03, -0.08, 0.002, 0.041, -0.0015};
  for (int i = 0; i < 6; i++) {
    d->qpos[qa[i]] = qtest[i];
  }
  mj_kinematics(m, d);
  {
    double R[9], t[3];
    gs_knee_pose(qtest, R, t);
    const double* xf = d->xpos + 3 * km->body_fem;
    const double* Rf = d->xmat + 9 * km->body_fem;
    const double* xt = d->xpos + 3 * km->body_tib;
    const double* Rt = d->xmat + 9 * km->body_tib;
    // femoral origin in the tibial frame = t, femoral axes in the tibial frame = columns of R
    double dp[3] = {xf[0] - xt[0], xf[1] - xt[1], xf[2] - xt[2]}, tt[3], Rrel[9];
    mju_mulMatTVec(tt, Rt, dp, 3, 3);
    mju_mulMatTMat(Rrel, Rt, Rf, 3, 3, 3);
    for (int i = 0; i < 3; i++) {
      EXPECT_NEAR(t[i], tt[i], 1e-12);
    }
    for (int i = 0; i < 9; i++) {
      EXPECT_NEAR(R[i], Rrel[i], 1e-12);
    }
  }

  // generalized forces: what gs_knee_passive reports is what it adds to qfrc_passive
  mj_resetData(m, d);
  mj_forward(m, d);
  gsKneeLoads loads;
  mju_zero(d->qfrc_passive, m->nv);
  EXPECT_EQ_INT(1, gs_knee_passive(m, d, &loads));
  for (int i = 0; i < 6; i++) {
    EXPECT_NEAR(loads.qfrc[i], d->qfrc_passive[m->jnt_dofadr[km->jnt[i]]], 1e-9);
  }

  // 2 BW compression along the tibial axis (a generalized force on knee_ty, whose axis is the
  // tibial_tray y axis: a pure force pushing the tibia up into the femur, no moment), flexion
  // held at 0, -30 and -60 deg by the fixture's joint equality; start 4 mm apart, no contact.
  // (A world-vertical force at the tibial centre of mass, 0.18 m below the knee, is compression
  // only at 0 deg: at -30 deg it adds about 1 BW of anterior-posterior shear and a 110 N m
  // flexion moment, which the unloaded secondary dofs cannot hold, and the tibia ran away.)
  const double holds[3] = {0.0, -30.0 * M_PI / 180.0, -60.0 * M_PI / 180.0};
  // settled femoral origin along the tibial x axis: roll-back grows with flexion (mm, band)
  const double tx_lo[3] = {-3.0, -2.0, 2.0}, tx_hi[3] = {4.0, 6.0, 12.0};
  const int nstep = 6000, tail = 500;   // 1.2 s at 0.2 ms; the last 0.1 s must be at rest
  g_km = *km;
  mjcb_passive = knee_passive_cb;
  for (int h = 0; h < 3; h++) {
    mjModel* mm = mj_copyModel(NULL, m);
    mm->eq_data[0] = holds[h];
    mjData* dd = mj_makeData(mm);
    dd->qpos[qa[GS_KNEE_FLEX]] = holds[h];
    dd->qpos[qa[GS_KNEE_TY]] = 0.046;
    dd->qfrc_applied[mm->jnt_dofadr[km->jnt[GS_KNEE_TY]]] = -2.0 * BW;
    int nan = 0;
    double vmax = 0.0;
    for (int s = 0; s < nstep; s++) {
      mj_step(mm, dd);
      for (int i = 0; i < mm->nv; i++) {
        nan |= !isfinite(dd->qvel[i]);
      }
      if (s >= nstep - tail) {
        for (int i = 0; i < mm->nv; i++) {
          vmax = fmax(vmax, fabs(dd->qvel[i]));
        }
      }
    }
    EXPECT_EQ_INT(0, nan);
    mju_zero(dd->qfrc_passive, mm->nv);
    gs_knee_passive(mm, dd, &loads);
    double* q = dd->qpos;
    printf("2 BW axial at flexion %.0f deg: flex %.2f deg, add %.2f deg, rot %.2f deg, tx %.2f mm, "
           "ty %.3f mm, tz %.2f mm; contact medial %.0f N lateral %.0f N total %.0f N (%.2f BW), "
           "ligaments %.0f N; max |qvel| over the last 0.1 s %.2e\n",
           holds[h] * 180 / M_PI, q[qa[0]] * 180 / M_PI, q[qa[1]] * 180 / M_PI,
           q[qa[2]] * 180 / M_PI, 1e3 * q[qa[3]], 1e3 * q[qa[4]], 1e3 * q[qa[5]],
           loads.contact.magnitude[0], loads.contact.magnitude[1], loads.contact.total,
           loads.contact.total / BW, loads.ligament_force, vmax);
    // settled
    EXPECT_TRUE(vmax < 5e-3);
    // plausible pose: flexion held within 1 deg, secondary rotations within 5 deg, tz within
    // 3 mm, tx in its band (roll-back), knee_ty within 41-46 mm (42 mm at the default pose; the
    // femoral origin rises as the posterior condyles take over)
    EXPECT_NEAR(holds[h], q[qa[0]], 1.0 * M_PI / 180.0);
    EXPECT_NEAR(0.0, q[qa[1]], 5.0 * M_PI / 180.0);
    EXPECT_NEAR(0.0, q[qa[2]], 5.0 * M_PI / 180.0);
    EXPECT_TRUE(1e3 * q[qa[3]] >= tx_lo[h] && 1e3 * q[qa[3]] <= tx_hi[h]);
    EXPECT_TRUE(q[qa[4]] >= 0.041 && q[qa[4]] <= 0.046);
    EXPECT_NEAR(0.0, q[qa[5]], 0.003);
    // the contact carries the 2 BW plus what the ligaments add (<= 0.5 BW here), both
    // compartments load, and it pushes the tibia away along its axis
    EXPECT_TRUE(loads.contact.total >= 1.95 * BW && loads.contact.total <= 2.6 * BW);
    EXPECT_TRUE(loads.ligament_force <= 0.5 * BW);
    EXPECT_TRUE(loads.contact.magnitude[0] > 0.25 * loads.contact.total);
    EXPECT_TRUE(loads.contact.magnitude[1] > 0.25 * loads.contact.total);
    EXPECT_TRUE(loads.contact.force[0][1] + loads.contact.force[1][1] < -1.9 * BW);
    mj_deleteData(dd);
    mj_deleteModel(mm);
  }
  mjcb_passive = NULL;
  mj_deleteData(d);
}

// ---- per-model cache (gs_knee_register, gs_knee_lookup) ----------------------------------
// Not registered: lookup NULL; gs_knee_passive registers it on its first call. Registered: lookup
// returns the entry and gs_knee_passive gives exactly what gs_knee_passive_model gives with a
// fresh gs_knee_model_init. A copy of the model (another pointer) is not found until used. A
// model without the numerics registers as 0. Several threads evaluating one model with their own
// mjData while the main thread registers other models (evicting slots, so that the threads
// re-register it) get the serial result bit for bit.
#define CACHE_THREADS 3
#define CACHE_EVALS 300
typedef struct {
  const mjModel* m;
  const double* qpos;
  const double* qvel;
  double expect[6];
  int mismatches;
} cacheJob;

static void* cache_worker(void* arg) {
  cacheJob* job = arg;
  mjData* d = mj_makeData(job->m);
  mju_copy(d->qpos, job->qpos, job->m->nq);
  mju_copy(d->qvel, job->qvel, job->m->nv);
  mj_kinematics(job->m, d);
  mj_comPos(job->m, d);
  mj_comVel(job->m, d);
  for (int k = 0; k < CACHE_EVALS; k++) {
    gsKneeLoads loads;
    if (gs_knee_passive(job->m, d, &loads) != 1) {
      job->mismatches++;
      continue;
    }
    for (int i = 0; i < 6; i++) {
      job->mismatches += loads.qfrc[i] != job->expect[i];
    }
  }
  mj_deleteData(d);
  return NULL;
}

// A fresh copy of a model is not registered, unless the allocator placed it where an equal model
// was registered and then freed (test_fixture's copies of the same model are): the cache then
// keeps that entry, which must describe the copy exactly, pointers into it included.
static void expect_unregistered_or_same(const mjModel* m) {
  char err[300];
  gsKneeModel km;
  const gsKneeModel* e = gs_knee_lookup(m);
  EXPECT_EQ_INT(1, gs_knee_model_init(m, &km, err, sizeof(err)));
  if (!e) {
    return;
  }
  EXPECT_TRUE(e->elem[0] == km.elem[0] && e->elem[1] == km.elem[1] && e->lig == km.lig);
  EXPECT_TRUE(e->nelem[0] == km.nelem[0] && e->nelem[1] == km.nelem[1] && e->nlig == km.nlig);
  EXPECT_TRUE(e->body_fem == km.body_fem && e->body_tib == km.body_tib);
  for (int i = 0; i < 6; i++) {
    EXPECT_TRUE(e->jnt[i] == km.jnt[i] && e->qadr[i] == km.qadr[i] && e->dadr[i] == km.dadr[i]);
  }
  EXPECT_NEAR(km.k_over_h, e->k_over_h, 0.0);
}

static void test_cache(const mjModel* m0) {
  char err[300];
  mjModel* m = mj_copyModel(NULL, m0);
  mjData* d = mj_makeData(m);
  const gsKneeModel* km_reg;
  gsKneeModel km;
  expect_unregistered_or_same(m);
  EXPECT_EQ_INT(1, gs_knee_model_init(m, &km, err, sizeof(err)));

  // a loaded pose with velocities: contact, ligaments and damping all act
  d->qpos[km.qadr[GS_KNEE_FLEX]] = -0.4;
  d->qpos[km.qadr[GS_KNEE_TY]] = 0.0428;
  for (int i = 0; i < 6; i++) {
    d->qvel[km.dadr[i]] = 0.3 * (i - 2.5);
  }
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  gsKneeLoads by_name, by_model, cached;
  mju_zero(d->qfrc_passive, m->nv);
  gs_knee_passive_model(&km, m, d, &by_model);
  EXPECT_EQ_INT(1, gs_knee_passive(m, d, &by_name));   // registers m
  EXPECT_TRUE(gs_knee_lookup(m) != NULL);
  EXPECT_TRUE(by_name.contact.total > 100.0);
  EXPECT_TRUE(by_name.ligament_force > 1.0);

  EXPECT_EQ_INT(1, gs_knee_register(m, err, sizeof(err)));
  km_reg = gs_knee_lookup(m);
  EXPECT_TRUE(km_reg != NULL);
  EXPECT_EQ_INT(1, gs_knee_passive(m, d, &cached));
  for (int i = 0; i < 6; i++) {
    EXPECT_NEAR(by_model.qfrc[i], by_name.qfrc[i], 0.0);
    EXPECT_NEAR(by_model.qfrc[i], cached.qfrc[i], 0.0);
  }
  // registering again replaces the entry; a copy is another model
  EXPECT_EQ_INT(1, gs_knee_register(m, err, sizeof(err)));
  EXPECT_TRUE(gs_knee_lookup(m) != NULL);
  mjModel* copy = mj_copyModel(NULL, m);
  expect_unregistered_or_same(copy);

  // a cached number changed in place (the medial gain, gs_knee_femur header index 12): the entry
  // no longer matches, the next call re-registers and uses the new number
  {
    mjData* dc = mj_makeData(copy);
    mju_copy(dc->qpos, d->qpos, m->nq);
    mj_kinematics(copy, dc);
    mj_comPos(copy, dc);
    EXPECT_EQ_INT(1, gs_knee_register(copy, err, sizeof(err)));
    EXPECT_TRUE(gs_knee_lookup(copy) != NULL);
    gsKneeLoads l1, l2;
    EXPECT_EQ_INT(1, gs_knee_passive(copy, dc, &l1));
    int id = mj_name2id(copy, mjOBJ_NUMERIC, "gs_knee_femur_0");
    EXPECT_TRUE(id >= 0);
    if (id >= 0) {
      copy->numeric_data[copy->numeric_adr[id] + 12] *= 2.0;
      EXPECT_TRUE(gs_knee_lookup(copy) == NULL);
      EXPECT_EQ_INT(1, gs_knee_passive(copy, dc, &l2));
      EXPECT_TRUE(gs_knee_lookup(copy) != NULL);
      EXPECT_TRUE(l1.contact.magnitude[0] > 10.0);
      EXPECT_REL(2.0 * l1.contact.magnitude[0], l2.contact.magnitude[0], 1e-12, 1e-9);
      EXPECT_REL(l1.contact.magnitude[1], l2.contact.magnitude[1], 1e-12, 1e-9);
    }
    mj_deleteData(dc);
  }

  // a model without the numerics
  mjModel* plain = mj_loadXML(GAITSIM_SOURCE_DIR "/tests/fixtures/one_muscle.xml", NULL, err,
                              sizeof(err));
  if (plain) {
    EXPECT_EQ_INT(0, gs_knee_register(plain, err, sizeof(err)));
    EXPECT_TRUE(gs_knee_lookup(plain) == NULL);
  }

  // threads: evaluate m while other models are registered (and evict slots)
  cacheJob jobs[CACHE_THREADS];
  pthread_t th[CACHE_THREADS];
  for (int k = 0; k < CACHE_THREADS; k++) {
    jobs[k].m = m;
    jobs[k].qpos = d->qpos;
    jobs[k].qvel = d->qvel;
    memcpy(jobs[k].expect, cached.qfrc, sizeof(jobs[k].expect));
    jobs[k].mismatches = 0;
    EXPECT_EQ_INT(0, pthread_create(&th[k], NULL, cache_worker, &jobs[k]));
  }
  mjModel* others[GS_KNEE_CACHE_SLOTS + 2];
  for (int k = 0; k < GS_KNEE_CACHE_SLOTS + 2; k++) {
    others[k] = mj_copyModel(NULL, m0);
    EXPECT_EQ_INT(1, gs_knee_register(others[k], err, sizeof(err)));
  }
  for (int k = 0; k < CACHE_THREADS; k++) {
    pthread_join(th[k], NULL);
    EXPECT_EQ_INT(0, jobs[k].mismatches);
  }
  // the newest registration is found; m, evicted or re-registered by the threads, gives the
  // same loads and is found afterwards
  EXPECT_TRUE(gs_knee_lookup(others[GS_KNEE_CACHE_SLOTS + 1]) != NULL);
  EXPECT_EQ_INT(1, gs_knee_passive(m, d, &by_name));
  EXPECT_TRUE(gs_knee_lookup(m) != NULL);
  for (int i = 0; i < 6; i++) {
    EXPECT_NEAR(cached.qfrc[i], by_name.qfrc[i], 0.0);
  }
  for (int k = 0; k < GS_KNEE_CACHE_SLOTS + 2; k++) {
    mj_deleteModel(others[k]);
  }
  if (plain) {
    mj_deleteModel(plain);
  }
  mj_deleteModel(copy);
  mj_deleteData(d);
  mj_deleteModel(m);
}

// ---- ligament lengthening speeds ------------------------------------------------------------
// The damping part of the summed bundle tension, ligament_force(qvel) - ligament_force(0),
// equals sum_b c_b (dL_b/dt / l0_b) s(e_b) with dL/dt from central differences of the bundle
// lengths along qvel (mj_integratePos), to 1e-6 relative.
static double bundle_length(const mjModel* m, const mjData* d, const gsKneeModel* km, int b) {
  const mjtNum* row = km->lig + GS_KNEE_NLIG * b;
  mjtNum pf[3], pt[3];
  mju_mulMatVec(pf, d->xmat + 9 * km->body_fem, row, 3, 3);
  mju_mulMatVec(pt, d->xmat + 9 * km->body_tib, row + 3, 3, 3);
  for (int i = 0; i < 3; i++) {
    pf[i] += d->xpos[3 * km->body_fem + i];
    pt[i] += d->xpos[3 * km->body_tib + i];
  }
  return mju_dist3(pf, pt);
}

static void test_ligament_speed(const mjModel* m, const gsKneeModel* km) {
  mjData* d = mj_makeData(m);
  mjData* dp = mj_makeData(m);
  mjData* dm = mj_makeData(m);
  d->qpos[km->qadr[GS_KNEE_FLEX]] = -0.5;
  d->qpos[km->qadr[GS_KNEE_TY]] = 0.0432;   // ligaments taut around the default pose
  const double v[6] = {0.8, -0.3, 0.5, 0.02, -0.05, 0.03};
  for (int i = 0; i < 6; i++) {
    d->qvel[km->dadr[i]] = v[i];
  }
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  gsKneeLoads moving, still;
  gs_knee_passive_model(km, m, d, &moving);
  mju_zero(d->qvel, m->nv);
  mj_comVel(m, d);
  gs_knee_passive_model(km, m, d, &still);
  for (int i = 0; i < 6; i++) {
    d->qvel[km->dadr[i]] = v[i];
  }
  const double dt = 1e-6;
  mju_copy(dp->qpos, d->qpos, m->nq);
  mju_copy(dm->qpos, d->qpos, m->nq);
  mj_integratePos(m, dp->qpos, d->qvel, 0.5 * dt);
  mj_integratePos(m, dm->qpos, d->qvel, -0.5 * dt);
  mj_kinematics(m, dp);
  mj_kinematics(m, dm);
  double expect = 0.0, scale = 0.0;
  for (int b = 0; b < km->nlig; b++) {
    const mjtNum* row = km->lig + GS_KNEE_NLIG * b;
    double len = bundle_length(m, d, km, b);
    double speed = (bundle_length(m, dp, km, b) - bundle_length(m, dm, km, b)) / dt;
    double e = len / row[7] - 1.0, wdt = 0.05 * row[8];
    double term = row[9] * (speed / row[7]) * 0.5 * (1.0 + e / sqrt(e * e + wdt * wdt));
    expect += term;
    scale += fabs(term);
  }
  double got = moving.ligament_force - still.ligament_force;
  printf("ligament damping: %.6g N from the callback, %.6g N from finite-difference speeds\n",
         got, expect);
  EXPECT_TRUE(scale > 1e-3);
  EXPECT_NEAR(expect, got, 1e-6 * scale + 1e-12);
  mj_deleteData(dm);
  mj_deleteData(dp);
  mj_deleteData(d);
}

// ---- ligament law -------------------------------------------------------------------------
static void test_ligament_law(void) {
  // k 2000 N/strain, l0 0.05 m, et 0.06, c 0.003: slack, toe, linear against the hard law
  double row[GS_KNEE_NLIG] = {0, 0, 0, 0, 0, 0, 2000.0, 0.05, 0.06, 0.003};
  double l0 = 0.05, k = 2000.0, et = 0.06;
  EXPECT_NEAR(0.0, gs_knee_ligament_force(row, 0.045, 0.0), 1e-3);
  double e = 0.03;
  EXPECT_REL(k * e * e / (2 * et), gs_knee_ligament_force(row, l0 * (1 + e), 0.0), 0.01, 1.0);
  e = 0.12;
  EXPECT_REL(k * (e - et / 2), gs_knee_ligament_force(row, l0 * (1 + e), 0.0), 0.001, 1.0);
  // damping while taut: c de/dt
  double f0 = gs_knee_ligament_force(row, l0 * 1.1, 0.0);
  double f1 = gs_knee_ligament_force(row, l0 * 1.1, 0.05);
  EXPECT_REL(0.003 * 0.05 / l0, f1 - f0, 1e-3, 1e-9);
  // C1 across the transition strain (slopes from both sides agree)
  double hh = 1e-7, lt = l0 * (1 + et);
  double sl = (gs_knee_ligament_force(row, lt, 0) - gs_knee_ligament_force(row, lt - hh, 0)) / hh;
  double sr = (gs_knee_ligament_force(row, lt + hh, 0) - gs_knee_ligament_force(row, lt, 0)) / hh;
  EXPECT_REL(sl, sr, 1e-3, 1.0);
}

// The full model with the surrogate (mjmodels/jw_fullbody_knee6.xml, gaitsim's physics
// installed): mjcb_passive applies the knee loads. With knee_ty 1 mm below its default the
// tibia is pressed into the femoral component, so the knee_ty generalized force pushes the two
// apart (> 0 along the axis, which points from the femoral component to the tibial tray) and
// equals the generalized force gs_knee_passive reports (1e-9 N); with knee_ty 10 mm above
// (distraction) the contact force is exactly 0 (the surrogate's ramp vanishes below -40 um).
// Foot contact is far off the floor (pelvis raised).
static void test_full_model_passive(void) {
  char err[300];
  mjModel* m = gs_model_load(GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml", err,
                             sizeof(err));
  EXPECT_TRUE(m != NULL);
  if (!m) {
    fprintf(stderr, "test_knee: %s\n", err);
    return;
  }
  EXPECT_EQ_INT(0, gs_physics_prepare(m, err, sizeof(err)));
  gs_physics_install();
  mjData* d = mj_makeData(m);
  int ty = m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "knee_ty")];
  int tz = m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "pelvis_ty")];
  double offsets[2] = {-0.001, 0.010};
  for (int c = 0; c < 2; c++) {
    mj_resetData(m, d);
    d->qpos[tz] += 1.0;
    d->qpos[ty] += offsets[c];
    mj_forward(m, d);
    double applied = d->qfrc_passive[ty];
    gsKneeLoads loads;
    mju_zero(d->qfrc_passive, m->nv);
    EXPECT_EQ_INT(1, gs_knee_passive(m, d, &loads));
    if (c == 0) {
      EXPECT_TRUE(applied > 10.0);
      EXPECT_NEAR(loads.qfrc[GS_KNEE_TY], applied, 1e-9);
      EXPECT_TRUE(loads.contact.magnitude[0] + loads.contact.magnitude[1] > 10.0);
    } else {
      EXPECT_NEAR(0.0, loads.contact.magnitude[0] + loads.contact.magnitude[1], 0.0);
    }
  }
  mj_deleteData(d);
  mj_deleteModel(m);
}

int main(void) {
  char err[300];
  mjModel* m = mj_loadXML(FIXTURE, NULL, err, sizeof(err));
  if (!m) {
    fprintf(stderr, "test_knee: %s: %s\n", FIXTURE, err);
    return 1;
  }
  gsKneeModel km;
  EXPECT_EQ_INT(1, gs_knee_model_init(m, &km, err, sizeof(err)));
  double(*rows)[18] = malloc(sizeof(double) * 18 * MAXROWS);
  int nrows = read_heldout(rows);
  EXPECT_TRUE(nrows >= 20);

  test_ef_sphere_on_thin_layer();
  test_ligament_law();
  if (nrows >= 20) {
    test_ef_matches_python_reference(rows, nrows);
    test_surrogate_heldout(&km, rows, nrows);
    test_surrogate_fd_smooth(&km, rows, nrows);
  }
  test_fixture(m, &km);
  test_cache(m);
  test_ligament_speed(m, &km);

  // a model without the numerics is left alone
  {
    mjModel* m0 = mj_loadXML(GAITSIM_SOURCE_DIR "/tests/fixtures/one_muscle.xml", NULL, err,
                             sizeof(err));
    if (m0) {
      mjData* d0 = mj_makeData(m0);
      EXPECT_EQ_INT(0, gs_knee_passive(m0, d0, NULL));
      mj_deleteData(d0);
      mj_deleteModel(m0);
    }
  }
  test_full_model_passive();
  free(rows);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
