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
- Surrogate: per compartment a torus (femoral condyle) whose generating circle centre moves with
  knee_flexion (quadratic), pressed into the tibial elements with the same linear foundation law
  and a C-infinity ramp r(d) = (d + sqrt(d^2 + eps^2)) / 2 in place of max(d, 0).
- Ligaments: Blankevoort & Huiskes 1991 (J Biomech Eng 113:263) as OpenSim's
  Blankevoort1991Ligament, with a smooth toe region (see gs_knee.h).

Python 3 standard library + numpy + scipy (Debian python3-numpy, python3-scipy). Deterministic
(fixed random seed).

Usage:
  /usr/bin/python3 scripts/prepare_knee.py --data /work/shared/data [--out-dir mjmodels/knee]
      [--fixture tests/fixtures/knee6.xml] [--samples 1600]
"""
import argparse
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np
from scipy.optimize import least_squares
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
# surrogate
# ------------------------------------------------------------------------------------------------

# parameters per compartment: cx0 cx1 cx2 cy0 cy1 cy2 cz0 cz1 R0 R1 rmin gain
NPC = 12


def ramp(x):
    return 0.5 * (x + np.sqrt(x * x + RAMP_EPS * RAMP_EPS))


def surrogate_loads(prm, elem, Q):
    """prm (2, NPC); elem: dict of per-compartment arrays c (n,3), n (n,3), a (n,); Q (m,6)
    coordinates. Returns (m, 2, 6) loads as ElasticFoundation.loads."""
    out = np.zeros((len(Q), 2, 6))
    for i, q in enumerate(Q):
        R, t = knee_pose(q)
        th = q[0]
        for k in (0, 1):
            c, n, a = elem[k]
            pk = prm[k]
            cx = pk[0] + pk[1] * th + pk[2] * th * th
            cy = pk[3] + pk[4] * th + pk[5] * th * th
            pf = (c - t) @ R               # R^T (c - t), femoral frame
            dx = pf[:, 0] - cx
            dy = pf[:, 1] - cy
            dz = pf[:, 2] - (pk[6] + pk[7] * th)
            rho = np.sqrt(dx * dx + dy * dy)
            dist = np.sqrt((rho - (pk[8] + pk[9] * th)) ** 2 + dz * dz) - pk[10]
            pr = pk[11] * K_LAYER / H_INSERT * ramp(-dist)
            f = -(pr * a)[:, None] * n
            out[i, k, :3] = f.sum(0)
            out[i, k, 3:] = np.cross(c, f).sum(0)
    return out


def fit_torus_geometric(pts):
    """Initial torus (axis femoral z) through femoral contact points: circle fit in x-y
    (centre, sagittal radius) and z-centre; minor radius from the z spread."""
    x, y, z = pts[:, 0], pts[:, 1], pts[:, 2]
    A = np.c_[2 * x, 2 * y, np.ones_like(x)]
    sol = np.linalg.lstsq(A, x * x + y * y, rcond=None)[0]
    cx, cy = sol[0], sol[1]
    Rs = math.sqrt(sol[2] + cx * cx + cy * cy)
    cz = float(np.median(z))
    rmin = 0.03
    return np.array([cx, 0, 0, cy, 0, 0, cz, 0, Rs - rmin, 0, rmin, 1.0])


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
    """The <numeric> entries (name, list of numbers) that callbacks/gs_knee.c reads."""
    sur = params["surrogate"]
    elems = []
    for comp in sur["elements"]:
        for e in comp:
            elems += e
    prm = []
    for k in (0, 1):
        prm += sur["compartments"][k]["params"]
    ligs = []
    for b in params["ligaments"]["bundles"]:
        ligs += b["femoral_point"] + b["tibial_point"] + [b["linear_stiffness"], b["slack_length"],
                                                          b["transition_strain"],
                                                          b["damping_coefficient"]]
    out = [
        ("gs_knee_info", [1, len(sur["elements"][0]), len(sur["elements"][1]),
                          len(params["ligaments"]["bundles"])]),
        ("gs_knee_layer", [sur["layer_modulus_over_thickness"], sur["ramp_eps"]]),
        ("gs_knee_torus", prm),
    ]
    for name, data in (("gs_knee_elements", elems), ("gs_knee_ligaments", ligs)):
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
                contact_pts[k].append((ef.c[sel] - t) @ R)
    ntest = len(Q) // 5
    train, test = slice(ntest, None), slice(0, ntest)
    print("samples: %d (%d held out); peak |F| medial %.0f N lateral %.0f N" % (
        len(Q), ntest, np.abs(loads[:, 0, :3]).max(), np.abs(loads[:, 1, :3]).max()))

    # surrogate elements: tibia Loop x1 restricted to elements that come within 0.5 mm
    sur_elem = []
    for k, f in enumerate((t1, t2)):
        c, n, a = tib_elements(tibV, f, 1)
        sur_elem.append((c, n, a))
    prm0 = np.array([fit_torus_geometric(np.vstack(contact_pts[k])) for k in (0, 1)])
    scale = np.maximum(np.abs(loads[train]).max(0), 1e-9)   # (2, 6)

    def resid(x, sl):
        p = x.reshape(2, NPC)
        return ((surrogate_loads(p, sur_elem, Q[sl]) - loads[sl]) / scale).ravel()
    x_scale = np.array([1e-3] * 11 + [0.1] + [1e-3] * 11 + [0.1])
    sol = least_squares(resid, prm0.ravel(), args=(train,), x_scale=x_scale, method="trf",
                        max_nfev=80, verbose=0)
    prm = sol.x.reshape(2, NPC)
    # prune elements that never come within 1 mm over all samples
    for k in (0, 1):
        c, n, a = sur_elem[k]
        best = np.full(len(c), -np.inf)
        for q in Q:
            R, t = knee_pose(q)
            pk = prm[k]
            th = q[0]
            pf = (c - t) @ R
            dx = pf[:, 0] - (pk[0] + pk[1] * th + pk[2] * th * th)
            dy = pf[:, 1] - (pk[3] + pk[4] * th + pk[5] * th * th)
            rho = np.sqrt(dx * dx + dy * dy)
            dist = np.sqrt((rho - (pk[8] + pk[9] * th)) ** 2 +
                           (pf[:, 2] - (pk[6] + pk[7] * th)) ** 2) - pk[10]
            best = np.maximum(best, -dist)
        keep = best > -1e-3
        sur_elem[k] = (c[keep], n[keep], a[keep])
    pred = surrogate_loads(prm, sur_elem, Q)
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
            form="per compartment: torus about the femoral z axis, generating-circle centre "
                 "(cx, cy) quadratic and cz, Rmaj linear in knee_flexion; each tibial element j gets "
                 "p = gain K/h r(-dist), r(x) = (x + sqrt(x^2+eps^2))/2",
            param_order="cx0 cx1 cx2 cy0 cy1 cy2 cz0 cz1 R0 R1 rmin gain: cx = cx0 + cx1 th + "
                        "cx2 th^2, cy likewise, cz = cz0 + cz1 th, Rmaj = R0 + R1 th, th = "
                        "knee_flexion (m, m/rad, m/rad^2; gain -)",
            layer_modulus_over_thickness=K_LAYER / H_INSERT, ramp_eps=RAMP_EPS,
            compartments=[dict(name=n, params=[float("%.10g" % v) for v in prm[k]])
                          for k, n in enumerate(("medial", "lateral"))],
            elements=[[[float("%.8g" % v) for v in list(c) + list(n) + [a]]
                       for c, n, a in zip(*sur_elem[k])] for k in (0, 1)],
            element_layout="px py pz (m) nx ny nz (-) area (m^2), tibial_tray frame",
            accuracy=acc),
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

    # held-out table (first 40 held-out poses)
    rows = ["# held-out poses: knee_flexion knee_adduction knee_rotation (rad) knee_tx knee_ty "
            "knee_tz (m); elastic-foundation loads on the tibia, tibial_tray frame: medial Fx Fy "
            "Fz (N) Mx My Mz (N m about the tibial_tray origin), lateral the same. Generated by "
            + SCRIPT]
    for i in range(min(40, ntest)):
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
