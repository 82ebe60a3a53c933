#!/usr/bin/python3
"""prepare_knee.py: JW's implant knee: elastic-foundation contact, ligaments and a smooth surrogate.

Reads the Knee Grand Challenge JW prosthesis surfaces (femPoints_188/facesFem_188,
tibPoints_100/facesTib1_100/facesTib2_100, placed by KneeProsthesis.osim), the ligament bundles of
subject DM's TKA knee (DM_tka_ligaments.osim, Blankevoort1991Ligament) and JW_AllBody_scaled.osim
(frames), and writes

  mjmodels/knee/jw_knee.json          surrogate coefficients, ligament bundles, held-out accuracy,
                                      provenance (the parameter file; committed)
  mjmodels/knee/jw_knee_heldout.csv   a small table of held-out poses with elastic-foundation
                                      forces (for tests/test_knee.c)
  mjmodels/knee/jw_knee_ef_mesh.txt   the refined surfaces the elastic foundation uses (for the C
                                      elastic foundation in the benchmark and tests)
  tests/fixtures/knee6.xml            fixture: fixed femoral component + tibial tray with the six
                                      knee joints of jw_fullbody.xml and the gs_knee numerics

Model (documented in mjmodels/knee/README.md):
- Elastic foundation (Blankevoort et al. 1991, J Biomech 24:1019; Bei & Fregly 2004, Med Eng Phys
  26:777, eq. 1, linear form): each tibial element carries p = K d / h with
  K = (1 - nu) E / ((1 + nu)(1 - 2 nu)), d the penetration of the femoral surface along the
  element normal; E = 46.3 MPa, nu = 0.46, h = 5 mm (DM_tka_ligaments.osim Smith2018ContactMesh
  tibia_implant, the Grand Challenge insert's UHMWPE).
- Surrogate: the real femoral geometry, per compartment the condyle as a smooth radial height
  field rho = G(w, z) about an axis parallel to the flexion axis, with a smooth mask at the edge
  of the femoral mesh (both partitions of unity of local polynomials fitted by linear least
  squares to rays cast on the refined femur), pressed into the once-refined tibial elements
  (aggregated from the reference elements) with the same linear foundation law, a compactly
  supported C-infinity ramp and one fitted gain per compartment; a cull table makes skipping
  elements out of reach exact (section "surrogate" below).
- Ligaments: Blankevoort & Huiskes 1991 (J Biomech Eng 113:263) as OpenSim's
  Blankevoort1991Ligament, with a smooth toe region (see gs_knee.h).

Python 3 standard library + numpy + scipy (Debian python3-numpy, python3-scipy). Deterministic
(fixed random seed).

Usage:
  /usr/bin/python3 scripts/prepare_knee.py --data /work/shared/data [--out-dir mjmodels/knee]
      [--fixture tests/fixtures/knee6.xml] [--samples 1000] [--cache /tmp/knee_samples.npz]
"""
import argparse
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import PrepError, write_atomic  # noqa: E402

SCRIPT = "scripts/prepare_knee.py"

# insert material (DM_tka_ligaments.osim, Smith2018ContactMesh "tibia_implant")
E_INSERT = 46.3e6        # Pa
NU_INSERT = 0.46         # -
H_INSERT = 0.005         # m
K_LAYER = (1.0 - NU_INSERT) * E_INSERT / ((1.0 + NU_INSERT) * (1.0 - 2.0 * NU_INSERT))  # Pa

# sampling range (knee coordinates, OpenSim meaning; flexion < 0 is flexion)
FLEX_RANGE = (-1.22, 0.12)       # rad: ngait_og1 6-DOF kinematics span -1.157 .. 0.112
ROT_RANGE = (-0.10, 0.10)        # rad, internal-external rotation
TX_RANGE = (-0.004, 0.004)       # m, anterior-posterior
TZ_RANGE = (-0.003, 0.003)       # m, medial-lateral
DEPTH_RANGE = (-0.03e-3, 0.15e-3)  # m, target largest penetration per compartment
MAX_FORCE = 3000.0               # N, samples with a larger compartment force are redrawn

RAMP_EPS = 5e-6                  # m, width of the surrogate's smooth ramp
SEED = 20240607
LIGAMENT_GROUPS = ("MCLd", "MCLs", "LCL", "PCLal", "PCLpm", "pCAP")
TRANSITION_STRAIN = 0.06         # -, Blankevoort 1991 / OpenSim default
DAMPING = 0.003                  # N s / strain, OpenSim Blankevoort1991Ligament default


# ------------------------------------------------------------------------------------------------
# geometry helpers
# ------------------------------------------------------------------------------------------------

def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def body_xyz(o):
    """OpenSim orientation: body-fixed X-Y-Z Euler angles."""
    return rot_x(o[0]) @ rot_y(o[1]) @ rot_z(o[2])


def knee_pose(q):
    """JW knee (JW_AllBody_scaled.osim CustomJoint "knee" = KneeProsthesis.osim "knee_joint"):
    p_tibial_tray = t + R p_femoral_component, t = (tx, ty, tz), R = Rz(flex) Rx(add) R_{-y}(rot).
    q = (flex, add, rot, tx, ty, tz)."""
    R = rot_z(q[0]) @ rot_x(q[1]) @ rot_y(-q[2])
    return R, np.array(q[3:6], dtype=float)


def read_csv(path, dtype=float):
    try:
        return np.loadtxt(path, delimiter=",", dtype=dtype, ndmin=2)
    except (OSError, ValueError) as e:
        raise PrepError(path, str(e))


def loop_subdivide(V, F):
    """One step of Loop subdivision (Loop 1987) with crease rules on boundary edges."""
    edges = {}
    for f in F:
        for a, b, c in ((f[0], f[1], f[2]), (f[1], f[2], f[0]), (f[2], f[0], f[1])):
            key = (min(a, b), max(a, b))
            edges.setdefault(key, []).append(c)
    nV = len(V)
    neigh = [set() for _ in range(nV)]
    bnd_neigh = [[] for _ in range(nV)]
    for (a, b), opp in edges.items():
        neigh[a].add(b)
        neigh[b].add(a)
        if len(opp) == 1:
            bnd_neigh[a].append(b)
            bnd_neigh[b].append(a)
    # new even vertices
    Vn = np.zeros_like(V)
    for i in range(nV):
        if bnd_neigh[i]:
            if len(bnd_neigh[i]) == 2:
                Vn[i] = 0.75 * V[i] + 0.125 * (V[bnd_neigh[i][0]] + V[bnd_neigh[i][1]])
            else:
                Vn[i] = V[i]
        elif not neigh[i]:
            Vn[i] = V[i]
        else:
            n = len(neigh[i])
            beta = (0.625 - (0.375 + 0.25 * math.cos(2 * math.pi / n)) ** 2) / n
            Vn[i] = (1 - n * beta) * V[i] + beta * V[list(neigh[i])].sum(0)
    # odd (edge) vertices
    eidx = {}
    newV = [Vn]
    k = nV
    odd = []
    for (a, b), opp in sorted(edges.items()):
        if len(opp) == 2:
            p = 0.375 * (V[a] + V[b]) + 0.125 * (V[opp[0]] + V[opp[1]])
        else:
            p = 0.5 * (V[a] + V[b])
        eidx[(a, b)] = k
        odd.append(p)
        k += 1
    newV.append(np.array(odd))
    Vout = np.vstack(newV)

    def e(a, b):
        return eidx[(min(a, b), max(a, b))]
    Fout = []
    for a, b, c in F:
        ab, bc, ca = e(a, b), e(b, c), e(c, a)
        Fout += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return Vout, np.array(Fout, dtype=int)


def orient_faces(V, F, centre):
    """Make the triangle orientation consistent across shared edges (breadth-first), then point
    the normals away from centre by majority (area-weighted)."""
    F = F.copy()
    owner = {}
    for i, f in enumerate(F):
        for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            owner.setdefault((min(a, b), max(a, b)), []).append(i)
    done = np.zeros(len(F), bool)
    for seed in range(len(F)):
        if done[seed]:
            continue
        done[seed] = True
        queue = [seed]
        while queue:
            i = queue.pop()
            f = F[i]
            for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
                for j in owner[(min(a, b), max(a, b))]:
                    if done[j]:
                        continue
                    g = list(F[j])
                    # consistent: the shared edge runs b -> a in the neighbour
                    same = any(g[k] == a and g[(k + 1) % 3] == b for k in range(3))
                    if same:
                        F[j] = F[j][[0, 2, 1]]
                    done[j] = True
                    queue.append(j)
    c, n, a = tri_props(V, F)
    if (((c - centre) * n).sum(1) * a).sum() < 0:
        F = F[:, [0, 2, 1]]
    return F


def tri_props(V, F):
    P = V[F]
    c = P.mean(1)
    n = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    a2 = np.linalg.norm(n, axis=1)
    return c, n / a2[:, None], 0.5 * a2


# ------------------------------------------------------------------------------------------------
# elastic foundation (reference)
# ------------------------------------------------------------------------------------------------

class ElasticFoundation:
    """Tibial elements (centroid, outward normal, area; tibial_tray frame) against the femoral
    triangle surface (femoral_component frame). Penetration along each element normal by
    ray-triangle intersection (Moller & Trumbore 1997); p = K d / h (Bei & Fregly 2004 eq. 1)."""

    def __init__(self, tib_c, tib_n, tib_a, tib_comp, fem_V, fem_F):
        self.c, self.n, self.a, self.comp = tib_c, tib_n, tib_a, tib_comp
        self.V, self.F = fem_V, fem_F
        self.tree = cKDTree(tib_c[:, [0, 2]])

    def depths(self, q, reach=0.003):
        """Signed penetration along each element normal (m; positive = overlap); -inf where the
        ray meets no femoral face within reach."""
        R, t = knee_pose(q)
        V = self.V @ R.T + t
        P = V[self.F]
        e1 = P[:, 1] - P[:, 0]
        e2 = P[:, 2] - P[:, 0]
        nf = np.cross(e1, e2)
        ymin = P[:, :, 1].min(1)
        keep = (nf[:, 1] < 0) & (ymin < self.c[:, 1].max() + reach)
        idx = np.nonzero(keep)[0]
        d = np.full(len(self.c), -np.inf)
        if len(idx) == 0:
            return d
        cen = P[idx].mean(1)
        rad = np.linalg.norm(P[idx] - cen[:, None, :], axis=2).max(1) + 0.002
        pairs_f, pairs_t = [], []
        for fi, lst in zip(idx, self.tree.query_ball_point(cen[:, [0, 2]], rad)):
            pairs_f.extend([fi] * len(lst))
            pairs_t.extend(lst)
        if not pairs_f:
            return d
        pf = np.array(pairs_f)
        pt = np.array(pairs_t)
        o = self.c[pt]
        dirn = self.n[pt]
        a1, b1 = e1[pf], e2[pf]
        h = np.cross(dirn, b1)
        det = (a1 * h).sum(1)
        ok = np.abs(det) > 1e-14
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = o - P[pf, 0]
        u = (s * h).sum(1) * inv
        qv = np.cross(s, a1)
        v = (dirn * qv).sum(1) * inv
        tt = (b1 * qv).sum(1) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (np.abs(tt) < reach)
        # overlap = femoral surface below the tibial element along its normal
        np.maximum.at(d, pt[hit], -tt[hit])
        return d

    def loads(self, q):
        """Per compartment (0 medial, 1 lateral): force on the tibia (N, tibial_tray frame) and
        moment about the tibial_tray origin (N m)."""
        d = self.depths(q)
        p = K_LAYER * np.maximum(d, 0.0) / H_INSERT
        f = -(p * self.a)[:, None] * self.n
        m = np.cross(self.c, f)
        out = np.zeros((2, 6))
        for k in (0, 1):
            sel = self.comp == k
            out[k, :3] = f[sel].sum(0)
            out[k, 3:] = m[sel].sum(0)
        return out, d


# ------------------------------------------------------------------------------------------------
# surrogate: the femoral condyles as smooth radial height fields, the tibia as area elements
# ------------------------------------------------------------------------------------------------
#
# Per compartment, in the femoral_component frame: an axis parallel to z through (ax, ay) (the
# sagittal centre of the condyle); a point p has v = (p_x - ax, p_y - ay), rho = |v|, the unit
# direction (ux, uy) = (v_x, -v_y) / rho (sagittal angle phi from -y towards +x: ux = sin phi,
# uy = cos phi), w = sin(phi - PHI_MID), c = cos(phi - PHI_MID). The condyle surface is
# rho = G(w, z) and its edge (where the reference femoral mesh ends) is E(w, z) = 0 (E: signed
# distance to the edge along the surface, > 0 on it). G and E are partitions of unity of local
# polynomials: NCW x NCZ cells of a uniform grid over [W0, W1] x [Z0, Z1], each with a total-
# degree-DEG polynomial in local coordinates, blended across each interior knot over +-OVL of a
# cell by the C-infinity step S(t) = 1 / (1 + exp((1 - 2t) / (t (1 - t)))) (0 for t <= 0, 1 for
# t >= 1). A tibial element (centre c, normal n, area A) at p = R^T (c - t), n' = R^T n gets
#   g = G - rho (radial overlap), f = -(v . n'_xy) / rho (cosine of the element normal to the
#   radial direction; g f is the overlap along n for a locally flat surface),
#   p = gain K/h r(g) f_+ M,  r(g) = (g + sqrt(g^2 + eps^2)) / 2 * S((g + 2 b) / b),
#   M = S((w - W0) / TAU_W) S((W1 - w) / TAU_W) S((c - C0) / TAU_C) S((z - Z0) / TAU_Z)
#       S((Z1 - z) / TAU_Z) S(E / EDGE_WIDTH + 1/2),  f_+ = f S(f / TAU_F),
# force -p A n on the tibia. r, M and f_+ are exactly 0 for g <= -2 b, outside the domain or
# beyond the edge, so skipping such elements is exact: an element is skipped when rho exceeds
# 2 b plus the cull table's bound of G over its (s, z) bin, s = tan(phi - phi_mid) (cull_table).
# Everything is C-infinity.
PHI_MID = math.radians(10.0)            # rad, middle of the sagittal range
PHI_RANGE = (math.radians(-65.0), math.radians(85.0))   # rad, contact spans -47 .. 65 deg
Z_DOMAIN = ((0.0015, 0.0405), (-0.0405, -0.0010))       # m, femoral z per compartment
GRID_DPHI = math.radians(0.5)           # rad, radial ray grid for the fits
GRID_DZ = 0.00025                       # m
PU_NCW, PU_NCZ, PU_DEG = 8, 4, 4        # cells along w, z; polynomial degree
PU_OVL = 0.1                            # blend half-width, fraction of a cell
EDGE_CLIP = 0.004                       # m, edge distance fitted up to +-4 mm
RAMP_CUT = 20e-6                        # m, b: r(g) = 0 for g <= -2 b
EDGE_WIDTH = 0.0005                     # m, edge mask S(E / EDGE_WIDTH + 1/2)
TAU_W, TAU_Z, TAU_C, C0, TAU_F = 0.02, 0.0005, 0.1, 0.05, 0.2   # domain mask and f_+ widths
CULL_NTW, CULL_NTZ = 96, 48             # cull table bins per compartment
NHEAD = 16                              # header numbers per compartment in gs_knee_femur


def sstep(t):
    """C-infinity step: 0 for t <= 0, 1 for t >= 1, 1 / (1 + exp((1 - 2t) / (t (1 - t))))."""
    t = np.asarray(t, dtype=float)
    out = np.where(t >= 1.0, 1.0, 0.0)
    mid = (t > 0.0) & (t < 1.0)
    tm = t[mid]
    with np.errstate(over="ignore"):   # exp overflow gives exactly 0, as in C
        out[mid] = 1.0 / (1.0 + np.exp((1.0 - 2.0 * tm) / (tm * (1.0 - tm))))
    return out


class PUGrid:
    """Partition of unity of local polynomials on a uniform NCW x NCZ cell grid (see above)."""

    def __init__(self, w0, w1, z0, z1, ncw=PU_NCW, ncz=PU_NCZ, deg=PU_DEG, ovl=PU_OVL,
                 spacing=None):
        self.w0, self.z0, self.ncw, self.ncz, self.deg = w0, z0, ncw, ncz, deg
        if spacing is None:
            self.hw, self.hz = (w1 - w0) / ncw, (z1 - z0) / ncz
            self.dw, self.dz = ovl * self.hw, ovl * self.hz
        else:
            self.hw, self.hz, self.dw, self.dz = spacing
        self.nt = (deg + 1) * (deg + 2) // 2

    @staticmethod
    def _axis(x, x0, h, d, nc):
        """per point: two cells and their weights (the second weight 0 outside blends)"""
        i = np.clip(np.floor((x - x0) / h).astype(int), 0, nc - 1)
        s = x - (x0 + i * h)
        i0, i1 = i.copy(), i.copy()
        a1 = np.zeros(len(x))
        lo = (i > 0) & (s < d)
        hi = (i < nc - 1) & (s > h - d) & ~lo
        up = sstep((s[lo] + d) / (2 * d))
        i0[lo] = i[lo] - 1
        a1[lo] = up
        up = sstep((s[hi] - h + d) / (2 * d))
        i1[hi] = i[hi] + 1
        a1[hi] = up
        return i0, i1, 1.0 - a1, a1

    def _terms(self, w, z, iw, iz):
        u = (w - (self.w0 + (iw + 0.5) * self.hw)) / (0.5 * self.hw)
        v = (z - (self.z0 + (iz + 0.5) * self.hz)) / (0.5 * self.hz)
        cols = []
        for i in range(self.deg + 1):
            for j in range(self.deg + 1 - i):
                cols.append(u ** i * v ** j)
        return np.array(cols).T

    def pieces(self, w, z):
        """[(cell index, weight, monomials)] for the up to 4 cells of each point"""
        wi0, wi1, wa0, wa1 = self._axis(w, self.w0, self.hw, self.dw, self.ncw)
        zi0, zi1, za0, za1 = self._axis(z, self.z0, self.hz, self.dz, self.ncz)
        out = []
        for iw, aw in ((wi0, wa0), (wi1, wa1)):
            for iz, az in ((zi0, za0), (zi1, za1)):
                out.append((iw * self.ncz + iz, aw * az, self._terms(w, z, iw, iz)))
        return out

    def design(self, w, z):
        X = np.zeros((len(w), self.ncw * self.ncz * self.nt))
        rows = np.arange(len(w))
        for cell, wt, T in self.pieces(w, z):
            for k in range(self.nt):
                np.add.at(X, (rows, cell * self.nt + k), wt * T[:, k])
        return X

    def fit(self, w, z, y, ridge=1e-10):
        X = self.design(w, z)
        nrm = np.sqrt((X ** 2).sum(0)) + 1e-300
        Xs = X / nrm
        A = Xs.T @ Xs + ridge * len(w) * np.eye(X.shape[1])
        coef = np.linalg.solve(A, Xs.T @ y) / nrm
        return coef, X @ coef - y

    def eval(self, coef, w, z):
        C = coef.reshape(-1, self.nt)
        out = np.zeros(len(w))
        for cell, wt, T in self.pieces(w, z):
            out += wt * (T * C[cell]).sum(1)
        return out


def radial_grid(fV, fF, axis, zrange):
    """Femoral surface radius along rays from the axis (ax, ay, z) in direction (sin phi, -cos phi,
    0) on a phi-z grid (outermost hit on the refined mesh; NaN where the ray misses it)."""
    ax, ay = axis
    phis = np.arange(PHI_RANGE[0] - math.radians(10), PHI_RANGE[1] + math.radians(10) + 1e-9,
                     GRID_DPHI)
    zs = np.arange(zrange[0], zrange[1] + 1e-9, GRID_DZ)
    P = fV[fF]
    tphi = np.arctan2(P[:, :, 0] - ax, -(P[:, :, 1] - ay))
    tz = P[:, :, 2]
    keep = np.abs(tphi).max(1) < 2.0
    d = np.stack([np.sin(phis), -np.cos(phis), np.zeros_like(phis)], 1)
    G = np.full((len(phis), len(zs)), np.nan)
    for iz, z in enumerate(zs):
        T = P[keep & (tz.min(1) <= z) & (tz.max(1) >= z)]
        if len(T) == 0:
            continue
        a0 = T[:, 0]
        e1 = T[:, 1] - a0
        e2 = T[:, 2] - a0
        h = np.cross(d[:, None, :], e2[None, :, :])
        det = (e1[None] * h).sum(2)
        ok = np.abs(det) > 1e-16
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = np.array([ax, ay, z]) - a0
        u = (s[None] * h).sum(2) * inv
        qv = np.cross(s, e1)
        v = (d[:, None, :] * qv[None]).sum(2) * inv
        tt = (e2 * qv).sum(1)[None] * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (tt > 0)
        far = np.where(hit, tt, -np.inf).max(1)
        G[:, iz] = np.where(np.isfinite(far), far, np.nan)
    return phis, zs, G


def edge_distance(inside, phis, zs, inner_side):
    """Signed distance (m, along the surface: rho ~ 0.03 m per radian) to the edge of the mesh
    region on the grid, > 0 inside; the inner z side of the domain (towards the other
    compartment) is padded, because the surface continues there."""
    from scipy import ndimage
    pad = 40
    ins = inside.copy()
    if inner_side == 0:
        ins = np.concatenate([np.repeat(ins[:, :1], pad, 1), ins], 1)
    else:
        ins = np.concatenate([ins, np.repeat(ins[:, -1:], pad, 1)], 1)
    ins = np.concatenate([np.repeat(ins[:1], pad, 0), ins, np.repeat(ins[-1:], pad, 0)], 0)
    samp = (GRID_DPHI * 0.03, GRID_DZ)
    sd = (ndimage.distance_transform_edt(ins, sampling=samp) -
          ndimage.distance_transform_edt(~ins, sampling=samp))
    sd = sd[pad:-pad]
    sd = sd[:, pad:] if inner_side == 0 else sd[:, :-pad]
    return sd - 0.5 * GRID_DZ * np.sign(sd)


def polar(p, fem):
    """(v_x, v_y, rho, w, c, z) of femoral-frame points p (n, 3) for compartment model fem"""
    vx = p[:, 0] - fem["axis"][0]
    vy = p[:, 1] - fem["axis"][1]
    rho = np.sqrt(vx * vx + vy * vy)
    ux, uy = vx / rho, -vy / rho
    cm, sm = fem.get("cs_mid", (math.cos(PHI_MID), math.sin(PHI_MID)))
    return vx, vy, rho, ux * cm - uy * sm, uy * cm + ux * sm, p[:, 2]


def domain_mask(fem, w, c, z):
    return (sstep((w - fem["W0"]) / TAU_W) * sstep((fem["W1"] - w) / TAU_W) *
            sstep((c - C0) / TAU_C) * sstep((z - fem["Z0"]) / TAU_Z) *
            sstep((fem["Z1"] - z) / TAU_Z))


def fit_femur(fV, fF, k, hits):
    """Compartment k: axis (circle fit to the contact points), radial grid, G and E fits."""
    x, y = hits[:, 0], hits[:, 1]
    sol = np.linalg.lstsq(np.c_[2 * x, 2 * y, np.ones_like(x)], x * x + y * y, rcond=None)[0]
    axis = (float(sol[0]), float(sol[1]))
    phis, zs, G = radial_grid(fV, fF, axis, Z_DOMAIN[k])
    W0 = math.sin(PHI_RANGE[0] - PHI_MID)
    W1 = math.sin(PHI_RANGE[1] - PHI_MID)
    Z0, Z1 = Z_DOMAIN[k]
    pu = PUGrid(W0, W1, Z0, Z1)
    PP, ZZ = np.meshgrid(phis, zs, indexing="ij")
    WW = np.sin(PP - PHI_MID)
    inside = np.isfinite(G)
    dom = (PP > PHI_RANGE[0]) & (PP < PHI_RANGE[1])
    m = inside & dom
    gcoef, gres = pu.fit(WW[m], ZZ[m], G[m])
    sd = edge_distance(inside, phis, zs, 0 if k == 0 else 1)
    ecoef, _ = pu.fit(WW[dom], ZZ[dom], np.clip(sd, -EDGE_CLIP, EDGE_CLIP)[dom])
    near = dom & (np.abs(sd) < 0.0015)
    eres = pu.eval(ecoef, WW[near], ZZ[near]) - sd[near]
    fem = dict(axis=axis, W0=W0, W1=W1, Z0=Z0, Z1=Z1, pu=pu, gcoef=gcoef, ecoef=ecoef, gain=1.0,
               fit=dict(surface_rms=float(gres.std()), edge_rms=float(eres.std()),
                        edge_max=float(np.abs(eres).max())))
    return fem


def element_loads(fem, c, n, a, q, cull=False):
    """Surrogate loads of one compartment at pose q: force (3) and moment (3) on the tibia about
    the tibial_tray origin. cull: skip elements by the cull table as the C code does (exact)."""
    R, t = knee_pose(q)
    out = np.zeros(6)
    p = (c - t) @ R
    nf = n @ R
    vx, vy, rho, w, cc, z = polar(p, fem)
    Md = domain_mask(fem, w, cc, z)
    live = Md > 0
    inner = None
    if cull:
        skip, inner = table_skipped(fem, vx, vy, z)
        live &= ~skip
    g = np.full(len(p), -1.0)
    g[live] = fem["pu"].eval(fem["gcoef"], w[live], z[live]) - rho[live]
    live &= g > -2 * RAMP_CUT
    if not live.any():
        return out
    E = fem["pu"].eval(fem["ecoef"], w[live], z[live])
    M = Md[live] * sstep(E / EDGE_WIDTH + 0.5)
    if inner is not None and not np.all(M[inner[live]] == 1.0):
        raise PrepError(SCRIPT, "cull table: a bin flagged mask = 1 has a mask < 1")
    gl = g[live]
    r = 0.5 * (gl + np.sqrt(gl * gl + RAMP_EPS * RAMP_EPS)) * sstep((gl + 2 * RAMP_CUT) / RAMP_CUT)
    f = -(vx[live] * nf[live, 0] + vy[live] * nf[live, 1]) / rho[live]
    f = f * sstep(f / TAU_F)
    wgt = fem["gain"] * (K_LAYER / H_INSERT) * r * f * M * a[live]
    fo = -wgt[:, None] * n[live]
    out[:3] = fo.sum(0)
    out[3:] = np.cross(c[live], fo).sum(0)
    return out


def surrogate_loads(fems, elem, Q, cull=False):
    """(m, 2, 6) loads as ElasticFoundation.loads; elem[k] = (c, n, a)."""
    out = np.zeros((len(Q), 2, 6))
    for i, q in enumerate(Q):
        for k in (0, 1):
            out[i, k] = element_loads(fems[k], *elem[k], q, cull)
    return out


def cull_bins(fem):
    """The cull table's variable along w: s = tan(phi - phi_mid) = w / c (one division, no square
    root in the C code), bins uniform over (S0, S1) = the domain's w range."""
    return math.tan(math.asin(fem["W0"])), math.tan(math.asin(fem["W1"]))


def cull_table(fem):
    """Per bin of a CULL_NTW x CULL_NTZ grid over (s, z) (cull_bins): +-(B + 2 b)^2, B an upper
    bound of G over the points of the bin where the mask can be > 0 (the largest G sampled on an
    8x finer grid there plus twice the largest change between neighbouring samples there: a
    smooth function exceeds its samples by less), rounded up to 1 um; negative where the mask is
    exactly 1 throughout the bin (domain masks 1, E >= EDGE_WIDTH / 2 with the same kind of
    margin), so that the C code skips the masks there; 0 where no point of the bin can carry
    load. An element with rho^2 above |value| carries no load."""
    pu = fem["pu"]
    S0, S1 = cull_bins(fem)
    ss = np.linspace(S0, S1, 8 * CULL_NTW + 1)
    zs = np.linspace(fem["Z0"], fem["Z1"], 8 * CULL_NTZ + 1)
    SS, ZZ = np.meshgrid(ss, zs, indexing="ij")
    WW = SS / np.sqrt(1.0 + SS * SS)
    G = pu.eval(fem["gcoef"], WW.ravel(), ZZ.ravel()).reshape(WW.shape)
    E = pu.eval(fem["ecoef"], WW.ravel(), ZZ.ravel()).reshape(WW.shape)
    # the mask can be > 0 where E > -EDGE_WIDTH / 2; E changes between samples by at most twice
    # its largest neighbouring difference
    emarg = 2.0 * (np.abs(np.diff(E, axis=0)).max() + np.abs(np.diff(E, axis=1)).max())
    valid = E > -0.5 * EDGE_WIDTH - emarg
    slope = np.zeros_like(G)
    dgw = np.where(valid[1:] | valid[:-1], np.abs(np.diff(G, axis=0)), 0.0)
    dgz = np.where(valid[:, 1:] | valid[:, :-1], np.abs(np.diff(G, axis=1)), 0.0)
    slope[1:] = np.maximum(slope[1:], dgw)
    slope[:-1] = np.maximum(slope[:-1], dgw)
    slope[:, 1:] = np.maximum(slope[:, 1:], dgz)
    slope[:, :-1] = np.maximum(slope[:, :-1], dgz)
    bound = np.where(valid, G + 2.0 * slope, -np.inf)
    # mask exactly 1: w within [W0 + TAU_W, W1 - TAU_W], c >= C0 + TAU_C, z within
    # [Z0 + TAU_Z, Z1 - TAU_Z] and E >= EDGE_WIDTH / 2 at every point of the bin
    inner = ((WW >= fem["W0"] + TAU_W) & (WW <= fem["W1"] - TAU_W) &
             (1.0 / np.sqrt(1.0 + SS * SS) >= C0 + TAU_C) &
             (ZZ >= fem["Z0"] + TAU_Z) & (ZZ <= fem["Z1"] - TAU_Z) &
             (E - emarg >= 0.5 * EDGE_WIDTH))
    tab = np.zeros((CULL_NTW, CULL_NTZ))
    for i in range(CULL_NTW):
        si = slice(8 * i, 8 * i + 9)   # samples of bin i, its edges included
        for j in range(CULL_NTZ):
            sj = slice(8 * j, 8 * j + 9)
            v = bound[si, sj].max()
            if np.isfinite(v):
                b2 = (math.ceil((v + 1e-6) * 1e6) / 1e6 + 2.0 * RAMP_CUT) ** 2
                # rounded up to 6 significant digits (shorter MJCF text; 2e-8 m in rho)
                q = 10.0 ** (math.floor(math.log10(b2)) - 5)
                tab[i, j] = math.ceil(b2 / q) * q
                if inner[si, sj].all():
                    tab[i, j] = -tab[i, j]
    return tab


def table_skipped(fem, vx, vy, z):
    """The C code's exact skip for elements with z inside the domain: behind the axis (c <= 0),
    s outside (S0, S1), or rho^2 above the bin's value."""
    cm, sm = fem.get("cs_mid", (math.cos(PHI_MID), math.sin(PHI_MID)))
    A = vx * cm + vy * sm
    C = vx * sm - vy * cm
    S0, S1 = fem.get("cull_s", cull_bins(fem))
    with np.errstate(divide="ignore", invalid="ignore"):
        sv = np.where(C > 0, A / np.where(C > 0, C, 1.0), np.nan)
    out = ~((C > 0) & (sv > S0) & (sv < S1))
    i = np.clip(np.nan_to_num((sv - S0) * (CULL_NTW / (S1 - S0))), 0, CULL_NTW - 1).astype(int)
    j = np.clip((z - fem["Z0"]) * (CULL_NTZ / (fem["Z1"] - fem["Z0"])), 0,
                CULL_NTZ - 1).astype(int)
    return out | (vx * vx + vy * vy > np.abs(fem["table"][i, j])), fem["table"][i, j] < 0


def femur_block(fem):
    """gs_knee_femur numbers of one compartment (layout in callbacks/gs_knee.h), rounded as
    written to the MJCF (fmt)"""
    pu = fem["pu"]
    head = [fem["axis"][0], fem["axis"][1], math.cos(PHI_MID), math.sin(PHI_MID), fem["W0"],
            fem["W1"], fem["Z0"], fem["Z1"], pu.hw, pu.hz, pu.dw, pu.dz, fem["gain"]]
    head += list(cull_bins(fem)) + [0.0]
    assert len(head) == NHEAD
    vals = head + list(fem["gcoef"]) + list(fem["ecoef"]) + list(np.ravel(fem["table"]))
    return [float(fmt(v)) for v in vals]


def femur_from_block(b, ncw=PU_NCW, ncz=PU_NCZ, deg=PU_DEG):
    """inverse of femur_block: the model the C code evaluates"""
    nt = (deg + 1) * (deg + 2) // 2
    ncoef = ncw * ncz * nt
    assert len(b) == NHEAD + 2 * ncoef + CULL_NTW * CULL_NTZ
    pu = PUGrid(b[4], b[5], b[6], b[7], ncw, ncz, deg, spacing=(b[8], b[9], b[10], b[11]))
    return dict(axis=(b[0], b[1]), cs_mid=(b[2], b[3]), W0=b[4], W1=b[5], Z0=b[6], Z1=b[7], pu=pu,
                gain=b[12], cull_s=(b[13], b[14]), gcoef=np.array(b[NHEAD:NHEAD + ncoef]),
                ecoef=np.array(b[NHEAD + ncoef:NHEAD + 2 * ncoef]),
                table=np.array(b[NHEAD + 2 * ncoef:]).reshape(CULL_NTW, CULL_NTZ))


def aggregated_elements(tibV, faces):
    """Surrogate elements: the tibia refined once (Loop), each element the aggregate of its four
    children on the reference (twice refined) surface: area-weighted centre, normalised sum of
    area-weighted normals, summed area (the children's centres lie on the finer surface, so the
    parents carry no faceting sag of their own)."""
    V1, F1 = loop_subdivide(tibV, faces)
    V2, F2 = loop_subdivide(V1, F1)
    c2, n2, a2 = tri_props(V2, F2)
    if n2[:, 1].mean() < 0:
        n2 = -n2
    a = a2.reshape(-1, 4).sum(1)
    c = (c2 * a2[:, None]).reshape(-1, 4, 3).sum(1) / a[:, None]
    nn = (n2 * a2[:, None]).reshape(-1, 4, 3).sum(1)
    return c, nn / np.linalg.norm(nn, axis=1)[:, None], a


# ------------------------------------------------------------------------------------------------
# ligaments
# ------------------------------------------------------------------------------------------------

def osim_offset(root, body, frame):
    for b in root.iter("Body"):
        if b.get("name") == body:
            for f in b.iter("PhysicalOffsetFrame"):
                if f.get("name") == frame:
                    tr = [float(v) for v in f.find("translation").text.split()]
                    o = [float(v) for v in f.find("orientation").text.split()]
                    return np.array(tr), body_xyz(o)
    raise PrepError(body, "offset frame %s not found" % frame)


def dm_knee_default(root, path):
    """DM knee_r: p_femur = off + t + Rz(-flex) Rx(add) Ry(rot) p_tibia at the defaults."""
    for j in root.iter("CustomJoint"):
        if j.get("name") == "knee_r":
            vals = {c.get("name"): float(c.find("default_value").text)
                    for c in j.iter("Coordinate")}
            off = None
            for f in j.iter("PhysicalOffsetFrame"):
                if f.get("name") == "femur_r_offset":
                    off = np.array([float(v) for v in f.find("translation").text.split()])
            R = rot_z(-vals["knee_flex_r"]) @ rot_x(vals["knee_add_r"]) @ rot_y(vals["knee_rot_r"])
            t = np.array([vals["knee_tx_r"], vals["knee_ty_r"], vals["knee_tz_r"]])
            return off + t, R
    raise PrepError(path, "CustomJoint knee_r not found")


def read_ligaments(path, scale):
    """MCL, LCL, PCL, posterior capsule bundles of DM, mapped to JW's implant frames."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        raise PrepError(path, str(e))
    tf, Rf = osim_offset(root, "femur_r", "femur_implant")
    tt, Rt = osim_offset(root, "tibia_r", "tibia_implant")
    tk, Rk = dm_knee_default(root, path)
    # DM tibia_implant frame seen from DM femur_implant frame at DM's default pose
    R_rel = Rf.T @ Rk @ Rt
    t_rel = Rf.T @ (tk + Rk @ tt - tf)
    out = []
    for lig in root.iter("Blankevoort1991Ligament"):
        name = lig.get("name")
        grp = next((g for g in LIGAMENT_GROUPS if name.startswith(g)
                    and name[len(g):].isdigit()), None)
        if grp is None:
            continue
        pts = lig.findall(".//PathPoint")
        if len(pts) != 2:
            raise PrepError(path, "%s: %d path points, expected 2" % (name, len(pts)))
        loc = {}
        for p in pts:
            body = p.find("socket_parent_frame").text.split("/")[-1]
            loc[body] = np.array([float(v) for v in p.find("location").text.split()])
        if set(loc) != {"femur_r", "tibia_r"}:
            raise PrepError(path, "%s: not femur_r-tibia_r" % name)
        k = float(lig.find("linear_stiffness").text)
        l0 = float(lig.find("slack_length").text)
        pf = Rf.T @ (loc["femur_r"] - tf)     # DM femur_implant frame
        pt = Rt.T @ (loc["tibia_r"] - tt)     # DM tibia_implant frame
        L_dm = float(np.linalg.norm(R_rel @ pt + t_rel - pf))
        eps_ref = L_dm / l0 - 1.0
        out.append(dict(name=name, group=grp, k=k, l0_dm=l0, L_dm=L_dm, eps_ref=eps_ref,
                        pf=scale * pf, pt=scale * pt))
    return out, R_rel, t_rel


# ------------------------------------------------------------------------------------------------
# MJCF snippet (used by osim2mjcf.py --knee-params and the fixture)
# ------------------------------------------------------------------------------------------------

def fmt(v):
    return "%.9g" % v


# MuJoCo 2.2.2's XML reader overruns the stack on long numeric data (700 values crash, 500 do
# not): long arrays are split into consecutive numerics NAME_0, NAME_1, ... of at most this many
# values, which the compiler stores contiguously (gs_knee.c checks that).
NUMERIC_CHUNK = 280


def knee_custom_numerics(params):
    """The <numeric> entries (name, list of numbers) that callbacks/gs_knee.c reads (layout in
    callbacks/gs_knee.h, version 2)."""
    sur = params["surrogate"]
    pu, cull = sur["partition_of_unity"], sur["cull"]
    elems, femur = [], []
    for k in (0, 1):
        rows = sur["elements"][k]
        for col in range(7):   # per compartment column by column (px..., py..., ..., area...)
            elems += [e[col] for e in rows]
        femur += sur["compartments"][k]["femur_block"]
    ligs = []
    for b in params["ligaments"]["bundles"]:
        ligs += b["femoral_point"] + b["tibial_point"] + [b["linear_stiffness"], b["slack_length"],
                                                          b["transition_strain"],
                                                          b["damping_coefficient"]]
    out = [
        ("gs_knee_info", [2, len(sur["elements"][0]), len(sur["elements"][1]),
                          len(params["ligaments"]["bundles"]), pu["cells_w"], pu["cells_z"],
                          pu["degree"], cull["table_bins_w"], cull["table_bins_z"]]),
        ("gs_knee_layer", [sur["layer_modulus_over_thickness"], sur["ramp_eps"], sur["ramp_cut"],
                           sur["edge_width"], sur["tau_w"], sur["tau_z"], sur["tau_c"], sur["c0"],
                           sur["tau_f"]]),
    ]
    for name, data in (("gs_knee_femur", femur), ("gs_knee_elements", elems),
                       ("gs_knee_ligaments", ligs)):
        for k in range(0, max(len(data), 1), NUMERIC_CHUNK):
            out.append(("%s_%d" % (name, k // NUMERIC_CHUNK), data[k:k + NUMERIC_CHUNK]))
    return out


def knee_custom_snippet(params, indent="  "):
    """The <custom> block (MJCF text) with the gs_knee numerics."""
    lines = [indent + "<custom>"]
    for name, data in knee_custom_numerics(params):
        lines.append('%s  <numeric name="%s" size="%d" data="%s"/>' % (
            indent, name, len(data), " ".join(fmt(v) for v in data)))
    lines.append(indent + "</custom>")
    return "\n".join(lines) + "\n"


def fixture_xml(params):
    """tests/fixtures/knee6.xml: femoral_component fixed, tibial_tray with the six knee joints of
    jw_fullbody.xml (same order, axes, anchors; no placeholder springs), gravity off, flexion held
    by an equality constraint, and the gs_knee numerics."""
    return """<!-- knee6.xml: gaitsim test fixture (generated by %s; do not edit).
     Femoral component fixed in the world (its frame = world), tibial tray below with the six
     right-knee joints of mjmodels/jw_fullbody.xml (order knee_rotation, knee_adduction,
     knee_flexion, knee_tx, knee_ty, knee_tz; axes and anchors as there), gravity off, tibia mass
     3.1 kg (about JW's tibia), joint damping for settling, knee_flexion held by a joint equality
     (polycoef[0] = the held angle). -->
<mujoco model="knee6">
  <compiler angle="radian"/>
  <option timestep="0.0002" gravity="0 0 0"/>
%s  <worldbody>
    <body name="femoral_component">
      <geom type="sphere" size="0.01" contype="0" conaffinity="0" mass="0.009"/>
      <body name="tibial_tray" pos="0 -0.041999991 0">
        <joint name="knee_rotation" type="hinge" axis="0 1 0" pos="0 0.041999991 0" damping="2"/>
        <joint name="knee_adduction" type="hinge" axis="-1 0 0" pos="0 0.041999991 0" damping="2"/>
        <joint name="knee_flexion" type="hinge" axis="0 0 -1" pos="0 0.041999991 0" damping="2"/>
        <joint name="knee_tx" type="slide" axis="-1 0 0" damping="2000"/>
        <joint name="knee_ty" type="slide" axis="0 -1 0" ref="0.041999991" damping="2000"/>
        <joint name="knee_tz" type="slide" axis="0 0 -1" damping="2000"/>
        <inertial pos="0 -0.18 0" mass="3.1" diaginertia="0.04 0.004 0.04"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint name="hold_flexion" joint1="knee_flexion" polycoef="0 0 0 0 0"/>
  </equality>
</mujoco>
""" % (SCRIPT, knee_custom_snippet(params))


# ------------------------------------------------------------------------------------------------
# main
# ------------------------------------------------------------------------------------------------

def load_surfaces(pros):
    femV = read_csv(os.path.join(pros, "femPoints_188.csv"))
    femF = read_csv(os.path.join(pros, "facesFem_188.csv"), int) - 1
    tibV = read_csv(os.path.join(pros, "tibPoints_100.csv"))
    t1 = read_csv(os.path.join(pros, "facesTib1_100.csv"), int) - 1
    t2 = read_csv(os.path.join(pros, "facesTib2_100.csv"), int) - 1
    for F, V, nm in ((femF, femV, "facesFem_188.csv"), (t1, tibV, "facesTib1_100.csv"),
                     (t2, tibV, "facesTib2_100.csv")):
        if F.min() < 0 or F.max() >= len(V):
            raise PrepError(os.path.join(pros, nm), "face index out of range")
    femF = orient_faces(femV, femF, np.array([0.0, 0.01, 0.0]))
    return femV, femF, tibV, t1, t2


def tib_elements(tibV, faces, levels):
    V, F = tibV, faces
    for _ in range(levels):
        V, F = loop_subdivide(V, F)
    c, n, a = tri_props(V, F)
    if n[:, 1].mean() < 0:
        n = -n
    return c, n, a


def sample_poses(ef, rng, count):
    """Poses over the gait range with targeted per-compartment penetration: flexion, rotation,
    tx, tz uniform; ty and adduction solved (linearised) for a target largest penetration per
    compartment drawn from DEPTH_RANGE."""
    Q = []
    while len(Q) < count:
        q = np.array([rng.uniform(*FLEX_RANGE), 0.0, rng.uniform(*ROT_RANGE),
                      rng.uniform(*TX_RANGE), 0.046, rng.uniform(*TZ_RANGE)])

        def maxd(qq):
            d = ef.depths(qq, reach=0.008)
            return np.array([d[ef.comp == k].max() for k in (0, 1)])
        d0 = maxd(q)
        if not np.all(np.isfinite(d0)):
            continue
        J = np.zeros((2, 2))
        for col, (i, h) in enumerate(((4, 1e-4), (1, 2e-3))):
            qq = q.copy()
            qq[i] += h
            dd = maxd(qq)
            if not np.all(np.isfinite(dd)):
                break
            J[:, col] = (dd - d0) / h
        else:
            target = rng.uniform(*DEPTH_RANGE, size=2)
            try:
                step = np.linalg.solve(J, target - d0)
            except np.linalg.LinAlgError:
                continue
            q[4] += step[0]
            q[1] += step[1]
            if abs(q[1]) < 0.08 and 0.02 < q[4] < 0.06:
                f = ef.loads(q)[0]
                if np.linalg.norm(f[:, :3], axis=1).max() <= MAX_FORCE:
                    Q.append(q)
    return np.array(Q)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", required=True, help="shared data folder (holds jw/, ligaments/)")
    ap.add_argument("--out-dir", default="mjmodels/knee")
    ap.add_argument("--fixture", default="tests/fixtures/knee6.xml")
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--cache", default=None,
                    help="npz file: reuse the sampled poses and loads if present, else write them")
    args = ap.parse_args()
    pros = os.path.join(args.data, "jw", "prosthesis")
    jw_osim = os.path.join(args.data, "jw", "model", "JW_AllBody_scaled.osim")
    dm_osim = os.path.join(args.data, "ligaments", "DM_tka_ligaments.osim")
    for p in (pros, jw_osim, dm_osim):
        if not os.path.exists(p):
            raise PrepError(p, "missing")
    rng = np.random.default_rng(SEED)

    # surfaces: femur Loop x3, tibia Loop x2 (reference), tibia Loop x1 (surrogate elements)
    femV, femF, tibV, t1, t2 = load_surfaces(pros)
    fV, fF = femV, femF
    for _ in range(3):
        fV, fF = loop_subdivide(fV, fF)
    ref = [tib_elements(tibV, f, 2) for f in (t1, t2)]
    comp = np.concatenate([np.full(len(ref[0][0]), 0), np.full(len(ref[1][0]), 1)])
    ef = ElasticFoundation(np.vstack([r[0] for r in ref]), np.vstack([r[1] for r in ref]),
                           np.concatenate([r[2] for r in ref]), comp, fV, fF)
    print("elastic foundation: %d tibial elements, %d femoral faces, K/h = %.4g Pa/m" % (
        len(comp), len(fF), K_LAYER / H_INSERT))

    # samples
    if args.cache and os.path.exists(args.cache):
        Q = np.load(args.cache)["Q"]
    else:
        Q = sample_poses(ef, rng, args.samples)
        if args.cache:
            np.savez(args.cache, Q=Q)
    loads = np.zeros((len(Q), 2, 6))
    contact_pts = [[], []]
    for i, q in enumerate(Q):
        loads[i], d = ef.loads(q)
        R, t = knee_pose(q)
        for k in (0, 1):
            sel = (comp == k) & (d > 0)
            if sel.any():
                # where the element normals meet the femoral surface (femoral frame)
                contact_pts[k].append((ef.c[sel] - d[sel, None] * ef.n[sel] - t) @ R)
    ntest = len(Q) // 5
    train, test = slice(ntest, None), slice(0, ntest)
    print("samples: %d (%d held out); peak |F| medial %.0f N lateral %.0f N" % (
        len(Q), ntest, np.abs(loads[:, 0, :3]).max(), np.abs(loads[:, 1, :3]).max()))

    # surrogate: femoral condyles as fitted radial height fields (axis from the contact points),
    # aggregated once-refined tibial elements, one gain per compartment
    fems, sur_elem = [], []
    for k, f in enumerate((t1, t2)):
        fem = fit_femur(fV, fF, k, np.vstack(contact_pts[k]))
        fem["table"] = cull_table(fem)
        fems.append(fem)
        sur_elem.append(aggregated_elements(tibV, f))
        print("femur %s: axis (%.4f, %.4f) m, surface fit RMS %.1f um, edge fit RMS %.3f mm (max "
              "%.3f mm) within 1.5 mm of the edge; %d elements" % (
                  ("medial", "lateral")[k], fem["axis"][0], fem["axis"][1],
                  1e6 * fem["fit"]["surface_rms"], 1e3 * fem["fit"]["edge_rms"],
                  1e3 * fem["fit"]["edge_max"], len(sur_elem[k][0])))
    # gain per compartment: linear least squares of the scaled load components on the training set
    scale = np.maximum(np.abs(loads[train]).max(0), 1e-9)   # (2, 6)
    pred1 = surrogate_loads(fems, sur_elem, Q[train])
    for k in (0, 1):
        x = (pred1[:, k] / scale[k]).ravel()
        y = (loads[train][:, k] / scale[k]).ravel()
        fems[k]["gain"] = float(x @ y / (x @ x))
    # from here on: the numbers as written (what the C code evaluates)
    blocks = [femur_block(fem) for fem in fems]
    fits = [fem["fit"] for fem in fems]
    fems = [femur_from_block(b) for b in blocks]
    sur_elem = [tuple(np.array([[float(fmt(v)) for v in row] for row in x]) for x in
                      (c, n, a[:, None])) for c, n, a in sur_elem]
    sur_elem = [(c, n, a[:, 0]) for c, n, a in sur_elem]
    pred = surrogate_loads(fems, sur_elem, Q, cull=True)
    full = surrogate_loads(fems, sur_elem, Q)
    cull_diff = float(np.abs(full - pred).max())
    print("gains %.4f %.4f; skipping by the cull table changes the loads by %.3g (must be 0)" % (
        fems[0]["gain"], fems[1]["gain"], cull_diff))
    if cull_diff != 0.0:
        raise PrepError(SCRIPT, "skipping by the cull table is not exact (%.3g)" % cull_diff)
    labels = ["Fx", "Fy", "Fz", "Mx", "My", "Mz"]
    acc = {}
    for k, cname in enumerate(("medial", "lateral")):
        for j, lab in enumerate(labels):
            peak = float(np.abs(loads[:, k, j]).max())
            rms_test = float(np.sqrt(np.mean((pred[test, k, j] - loads[test, k, j]) ** 2)))
            rms_train = float(np.sqrt(np.mean((pred[train, k, j] - loads[train, k, j]) ** 2)))
            acc["%s_%s" % (cname, lab)] = dict(peak=peak, rms_heldout=rms_test,
                                               rms_heldout_pct_of_peak=100 * rms_test / peak,
                                               rms_train_pct_of_peak=100 * rms_train / peak)
            print("%-8s %s peak %9.3f  held-out RMS %7.3f (%.2f %% of peak), train %.2f %%" % (
                cname, lab, peak, rms_test, 100 * rms_test / peak, 100 * rms_train / peak))
    nf = [np.linalg.norm(loads[:, k, :3], axis=1) for k in (0, 1)]
    nfp = [np.linalg.norm(pred[:, k, :3], axis=1) for k in (0, 1)]
    for k, cname in enumerate(("medial", "lateral")):
        peak = float(nf[k].max())
        rms = float(np.sqrt(np.mean((nfp[k][test] - nf[k][test]) ** 2)))
        acc["%s_magnitude" % cname] = dict(peak=peak, rms_heldout=rms,
                                           rms_heldout_pct_of_peak=100 * rms / peak)
        print("%-8s |F| peak %.1f N held-out RMS %.2f N (%.2f %%)" % (cname, peak, rms,
                                                                       100 * rms / peak))

    # ligaments
    jw_root = ET.parse(jw_osim).getroot()
    dm_root = ET.parse(dm_osim).getroot()
    # bone-size scale: JW femoral component below JW's hip centre vs DM's femur_implant
    jw_knee_y = None
    for j in jw_root.iter("WeldJoint"):
        if j.get("name") == "femoral_component_weld":
            for f in j.iter("PhysicalOffsetFrame"):
                if f.get("name") == "femur_offset":
                    jw_knee_y = float(f.find("translation").text.split()[1])
    if jw_knee_y is None:
        raise PrepError(jw_osim, "femoral_component_weld not found")
    dm_tf, _ = osim_offset(dm_root, "femur_r", "femur_implant")
    size_scale = jw_knee_y / dm_tf[1]
    bundles, R_rel, t_rel = read_ligaments(dm_osim, size_scale)
    R0, t0 = knee_pose([0, 0, 0, 0, 0.042, 0])
    lig_out = []
    for b in bundles:
        L_jw = float(np.linalg.norm(b["pt"] - (R0 @ b["pf"] + t0)))
        l0 = L_jw / (1.0 + b["eps_ref"])
        lig_out.append(dict(name=b["name"], group=b["group"],
                            femoral_point=[round(float(v), 7) for v in b["pf"]],
                            tibial_point=[round(float(v), 7) for v in b["pt"]],
                            linear_stiffness=b["k"], slack_length=round(l0, 7),
                            reference_strain=round(b["eps_ref"], 5),
                            transition_strain=TRANSITION_STRAIN, damping_coefficient=DAMPING))
    print("ligaments: %d bundles, DM->JW scale %.4f; DM implant frames at DM default: "
          "t = %s mm, rotation %.2f deg" % (
              len(lig_out), size_scale, np.round(1e3 * t_rel, 2),
              math.degrees(math.acos(max(-1, min(1, (np.trace(R_rel) - 1) / 2))))))

    # parameter file
    params = dict(
        about="JW right (implant) knee: surrogate contact and ligaments for callbacks/gs_knee.c",
        generated_by="/usr/bin/python3 %s --data %s --out-dir %s --fixture %s --samples %d" % (
            SCRIPT, "/work/shared/data", args.out_dir, args.fixture, args.samples),
        sources=dict(
            surfaces="Knee Grand Challenge JW (Fregly et al. 2012, J Orthop Res 30:503): "
                     "femPoints_188.csv, facesFem_188.csv, tibPoints_100.csv, facesTib1_100.csv "
                     "(medial), facesTib2_100.csv (lateral), KneeProsthesis.osim (CC BY 3.0, "
                     "OpenSim team), redistributed by gilserrancoli/ReducePoly_forMSK (MIT)",
            frames="JW_AllBody_scaled.osim (knee: parent tibial_tray, child femoral_component; "
                   "same SpatialTransform as KneeProsthesis.osim knee_joint)",
            material="DM_tka_ligaments.osim Smith2018ContactMesh tibia_implant: E 46.3 MPa, "
                     "nu 0.46, thickness 5 mm (opensim-org/jam-resources, Apache-2.0)",
            ligaments="DM_tka_ligaments.osim Blankevoort1991Ligament MCLd*, MCLs*, LCL*, "
                      "PCLal*, PCLpm*, pCAP* (opensim-org/jam-resources, Apache-2.0); "
                      "transition strain 0.06 and damping 0.003 N s/strain: OpenSim "
                      "Blankevoort1991Ligament defaults (Blankevoort & Huiskes 1991)"),
        frames="femoral_point in the femoral_component frame, tibial_point and all contact "
               "quantities in the tibial_tray frame; pose p_tib = t + Rz(flex) Rx(add) "
               "R_{-y}(rot) p_fem, t = (knee_tx, knee_ty, knee_tz)",
        elastic_foundation=dict(
            model="linear thin layer p = K d / h, K = (1-nu)E/((1+nu)(1-2nu)) "
                  "(Blankevoort 1991; Bei & Fregly 2004 eq. 1)",
            E=E_INSERT, nu=NU_INSERT, h=H_INSERT, K=K_LAYER,
            tibial_elements=int(len(comp)), femoral_faces=int(len(fF)),
            refinement="Loop subdivision: femur 3 levels, tibia 2 levels"),
        sampling=dict(count=int(len(Q)), heldout=int(ntest), seed=SEED,
                      flexion=FLEX_RANGE, rotation=ROT_RANGE, tx=TX_RANGE, tz=TZ_RANGE,
                      target_depth=DEPTH_RANGE, max_compartment_force=MAX_FORCE,
                      adduction_and_ty="solved for the target penetration per compartment"),
        surrogate=dict(
            form="per compartment: the femoral condyle as a radial height field rho = G(w, z) "
                 "about an axis parallel to the femoral z axis through (ax, ay), w = sin(phi - "
                 "phi_mid), phi the sagittal angle from -y towards +x, with its edge E(w, z) = 0 "
                 "(E the signed distance to the edge of the reference femoral mesh along the "
                 "surface); G and E partitions of unity of local polynomials (C-infinity "
                 "blends); each tibial element (once-refined insert, aggregated from its four "
                 "reference children) gets p = gain K/h r(g) f_+ M with g = G - rho the radial "
                 "overlap at its centre, f the cosine between its normal and the radial "
                 "direction, M the domain and edge masks; all exactly 0 far from contact, so "
                 "elements out of reach (cull table) are skipped (exact). Details: "
                 "scripts/prepare_knee.py, callbacks/gs_knee.h",
            layer_modulus_over_thickness=K_LAYER / H_INSERT, ramp_eps=RAMP_EPS,
            ramp_cut=RAMP_CUT, edge_width=EDGE_WIDTH, tau_w=TAU_W, tau_z=TAU_Z, tau_c=TAU_C,
            c0=C0, tau_f=TAU_F, phi_mid_deg=math.degrees(PHI_MID),
            phi_range_deg=[math.degrees(v) for v in PHI_RANGE],
            partition_of_unity=dict(cells_w=PU_NCW, cells_z=PU_NCZ, degree=PU_DEG,
                                    blend_half_width=PU_OVL,
                                    term_order="u^i v^j, i = 0..deg, j = 0..deg-i (i outer)"),
            cull=dict(table_bins_w=CULL_NTW, table_bins_z=CULL_NTZ),
            compartments=[dict(name=nm, femur_block=blocks[k], fit=fits[k],
                               block_layout="16 header (ax ay cos(phi_mid) sin(phi_mid) W0 W1 Z0 "
                                            "Z1 hw hz dw dz gain S0 S1 0), G coefficients, E "
                                            "coefficients, cull table")
                          for k, nm in enumerate(("medial", "lateral"))],
            elements=[[[float(v) for v in list(c) + list(n) + [a]]
                       for c, n, a in zip(*sur_elem[k])] for k in (0, 1)],
            element_layout="px py pz (m) nx ny nz (-) area (m^2), tibial_tray frame",
            accuracy=acc,
            accuracy_note="rms_heldout_pct_of_peak: RMS over the 200 held-out poses in % of the "
                          "component's peak over all samples (tests/test_knee.c normalises by the "
                          "held-out peak instead)",
            previous="replaces the torus surrogate of 2026-12-01 (per compartment a torus about "
                     "the femoral z axis with flexion-dependent centre, 24 numbers, Loop-1 "
                     "tibial elements): held-out |F| RMS 7.07 % (medial) / 6.96 % (lateral) of "
                     "peak, components 3.7-10.7 %, 2.95 us per evaluation"),
        ligaments=dict(
            model="Blankevoort & Huiskes 1991 with smooth toe: F = k eps_t [r(x)^2 - "
                  "r(x-1)^2]/2, x = eps/eps_t, plus damping c deps/dt s(eps)",
            mapping="DM insertions expressed in DM's femur_implant / tibia_implant frames, "
                    "scaled by %.4f (JW hip-to-femoral-component distance / DM hip-to-"
                    "femur_implant distance) and placed in JW's femoral_component / tibial_tray "
                    "frames; slack length = JW length at the default pose / (1 + DM reference "
                    "strain at DM's default pose)" % size_scale,
            scale=size_scale, bundles=lig_out),
    )
    os.makedirs(args.out_dir, exist_ok=True)
    write_atomic(os.path.join(args.out_dir, "jw_knee.json"), json.dumps(params, indent=1) + "\n")

    # held-out table (every held-out pose)
    rows = ["# held-out poses: knee_flexion knee_adduction knee_rotation (rad) knee_tx knee_ty "
            "knee_tz (m); elastic-foundation loads on the tibia, tibial_tray frame: medial Fx Fy "
            "Fz (N) Mx My Mz (N m about the tibial_tray origin), lateral the same. Generated by "
            + SCRIPT]
    for i in range(ntest):
        rows.append(",".join(["%.9g" % v for v in Q[i]] + ["%.6g" % v for v in loads[i].ravel()]))
    write_atomic(os.path.join(args.out_dir, "jw_knee_heldout.csv"), "\n".join(rows) + "\n")

    # refined reference surfaces
    lines = ["# gs_knee elastic-foundation surfaces (refined by Loop subdivision; %s)" % SCRIPT,
             "# femur: nv nf, then nv lines x y z (m, femoral_component frame), nf lines i j k",
             "# tibia: ne, then ne lines px py pz nx ny nz area compartment(0 medial 1 lateral) "
             "(tibial_tray frame)",
             "%d %d" % (len(fV), len(fF))]
    lines += ["%.8g %.8g %.8g" % tuple(v) for v in fV]
    lines += ["%d %d %d" % tuple(f) for f in fF]
    lines.append("%d" % len(comp))
    lines += ["%.8g %.8g %.8g %.8g %.8g %.8g %.8g %d" % (tuple(ef.c[i]) + tuple(ef.n[i]) +
                                                         (ef.a[i], comp[i]))
              for i in range(len(comp))]
    write_atomic(os.path.join(args.out_dir, "jw_knee_ef_mesh.txt"), "\n".join(lines) + "\n")
    write_atomic(args.fixture, fixture_xml(params))
    print("wrote %s/jw_knee.json, jw_knee_heldout.csv, jw_knee_ef_mesh.txt and %s" % (
        args.out_dir, args.fixture))


if __name__ == "__main__":
    try:
        main()
    except PrepError as e:
        print("prepare_knee.py: %s" % e, file=sys.stderr)
        sys.exit(1)
