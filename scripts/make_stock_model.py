#!/usr/bin/env python3
"""Generate mjmodels/jw_fullbody_mujoco.xml: JW's full-body model for stock MuJoCo 2.2.2.

gaitsim's own physics (Hill muscle-tendon units, Hunt-Crossley foot spheres, the implant knee's
surrogate contact) runs in MuJoCo callbacks; stock MuJoCo ignores the `user` rows that carry its
parameters. This script writes a model whose MuJoCo-native elements are FITTED, by least squares,
to gaitsim's physics, so that the model behaves like gaitsim's in any MuJoCo program:

- muscles: MuJoCo's <muscle> (mju_muscleGain/Bias/Dynamics of engine_util_misc.c, MuJoCo 2.2.2):
  tension = force (act FL(L) FV(V) + fpmax FP(L)), L = range0 + (len - lengthrange0) / L0,
  L0 = (lengthrange1 - lengthrange0) / (range1 - range0), V = vel / (L0 vmax). Per muscle, force,
  the map L(len) (range, with lengthrange kept from the source), lmin, lmax and fpmax are fitted to
  gaitsim's isometric tendon force (`gaitsim inspect` on the --hill-model: gs_muscle_rigid_force,
  or gs_muscle_equilibrium_fT for elastic tendons: the rigid-tendon equivalent at the static
  equilibrium) over the trial's poses at activations 0.05, 0.5 and 1. fvmax and the velocity
  scale are fitted once to De Groote's force-velocity curve (vmax per muscle from gaitsim's vmax,
  lopt and pennation); timeconst to gaitsim's activation dynamics (gs_activation.h).
- contact: the 12 foot spheres keep their geometry; solref (direct stiffness and damping) and
  solimp are fitted per sphere so that MuJoCo's static force at a penetration d, the force with
  which the contact holds a still foot (efc_aref / efc_R), equals gaitsim's Hunt-Crossley
  4/3 E sqrt(R) d^1.5 for d in 2-15 mm; damping matches dFn/dd' = 1.5 c Fn at 5 mm. Needs the
  contact's inverse weight (body_invweight0 of the foot body), read from `mujoco-compile`'s text
  dump of the source model. Elliptic friction cone, sliding friction = gaitsim's dynamic mu.
- every other segment gets a collision capsule or sphere that touches only the floor.
- knee: the source's placeholder springs on the five secondary right-knee coordinates (1-DOF
  knee in effect, qpos identical to gaitsim's models).

Usage (after building gaitsim; about 30 s):
  /usr/bin/python3 scripts/make_stock_model.py [--source mjmodels/jw_fullbody.xml]
      [--hill-model mjmodels/jw_fullbody_knee6.xml] [--trial mjmodels/trials/jw_ngait_og5]
      [--poses mjmodels/reference/jw_poses.csv] [--gaitsim build/gaitsim]
      [--out mjmodels/jw_fullbody_mujoco.xml | --check mjmodels/jw_fullbody_mujoco.xml]
Python standard library + python3-numpy/scipy; runs build/gaitsim and mujoco-compile
(libmujoco-samples). Output written atomically; the same on one machine run after run, while the
muscle fits' last digits (and, for a poorly determined muscle, its local minimum) move between
machines with their floating point: --check therefore asks every committed muscle to fit
gaitsim's forces within CHECK_RMS_TOL of this run's fit and everything else to be equal.
"""
import argparse
import math
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
from scipy.optimize import least_squares

from gs_scriptlib import PrepError, inspect_muscles, read_storage, storage_text, write_atomic

ACTIVATIONS = (0.05, 0.5, 1.0)

# gaitsim curve constants (callbacks/gs_muscle.h, gs_activation.h)
D1, D2, D3, D4 = -0.3211346127989808, -8.149, -0.374, 0.8825327733249912
ACT_SMOOTHING = 10.0

# gsActUser / gsGeomUser indices (callbacks/gs_model_layout.h)
U_FMAX, U_LOPT, U_LTS, U_PENN, U_VMAX, U_TAU_ACT, U_TAU_DEACT = 0, 1, 2, 3, 4, 9, 10
G_E, G_C, G_MUS, G_MUD = 0, 1, 2, 3

# --check: muscle attributes set by the non-convex fit, and how much worse (RMS / Fmax, -) a
# committed muscle may fit gaitsim's forces than this run's fit does
CHECK_FITTED = ("force", "range", "lmin", "lmax", "fpmax", "vmax")
CHECK_RMS_TOL = 0.005

# contact fit: penetration grid (m) and the depth at which the damping is matched (m)
DEPTHS = np.geomspace(0.002, 0.015, 40)
DAMPING_DEPTH = 0.005

# collision geoms: body -> list of (type, size, fromto or pos); body frames are OpenSim's (Y along
# the bone). "child:NAME" ends a capsule at 90 % of the way to that child body's origin.
SEGMENTS = {
    "pelvis": [("capsule", 0.07, "-0.07 -0.06 -0.085 -0.07 -0.06 0.085")],
    "femur": [("capsule", 0.06, "child:femoral_component")],
    "femur_l": [("capsule", 0.06, "child:tibia_l")],
    "femoral_component": [("sphere", 0.045, "0 0 0")],
    "tibial_tray": [("sphere", 0.035, "0 0 0")],
    "tibia": [("capsule", 0.045, "child:talus")],
    "tibia_l": [("capsule", 0.045, "child:talus_l")],
    "talus": [("sphere", 0.025, "0 0 0")],
    "talus_l": [("sphere", 0.025, "0 0 0")],
    "patella": [("sphere", 0.02, "0 0 0")],
    "patella_l": [("sphere", 0.02, "0 0 0")],
    "torso": [("capsule", 0.11, "-0.03 0.05 0 -0.03 0.42 0"), ("sphere", 0.095, "-0.01 0.62 0")],
    "humerus_r": [("capsule", 0.04, "child:ulna_r")],
    "humerus_l": [("capsule", 0.04, "child:ulna_l")],
    "ulna_r": [("capsule", 0.03, "0 0 0 0 -0.24 0")],
    "ulna_l": [("capsule", 0.03, "0 0 0 0 -0.24 0")],
    "radius_r": [("capsule", 0.03, "child:hand_r")],
    "radius_l": [("capsule", 0.03, "child:hand_l")],
    "hand_r": [("sphere", 0.045, "0 -0.075 0")],
    "hand_l": [("sphere", 0.045, "0 -0.075 0")],
}
FOOT_BODIES = ("calcaneus", "toes", "calcaneus_l", "toes_l")  # carry the fitted spheres
# each foot sphere gets a concentric "stop" sphere (class segment, STOP_DEPTH smaller): beyond the
# fitted range (hard landings, a collapsing body) it stops the foot sinking further
STOP_DEPTH = 0.012
SEGMENT_SOLREF = "0.002 1"  # time constant 2 ms (2 timesteps, the stable minimum), critical damping


def fmt(x):
    return f"{x:.6g}"


# --- MuJoCo 2.2.2 muscle model (engine_util_misc.c: mju_muscleGain, mju_muscleBias) -----------
def mj_fl(L, lmin, lmax):
    """FL of MuJoCo 2.2.2 as coded: below lmin its if-chain falls into the "L <= 1" branch, so FL
    = 1 - 0.5 ((1 - L) / (1 - a))^2 there, -1 just below lmin and falling (a pushing muscle;
    later MuJoCo versions return 0). The fit keeps lmin below every reachable length."""
    a, b = 0.5 * (lmin + 1), 0.5 * (1 + lmax)
    out = np.zeros_like(L)
    m1 = (L >= lmin) & (L <= a)
    m2 = ((L > a) | (L < lmin)) & (L <= 1)
    m3 = (L > 1) & (L <= b)
    m4 = (L > b) & (L <= lmax)
    out[m1] = 0.5 * ((L[m1] - lmin) / (a - lmin)) ** 2
    out[m2] = 1 - 0.5 * ((1 - L[m2]) / (1 - a)) ** 2
    out[m3] = 1 - 0.5 * ((L[m3] - 1) / (b - 1)) ** 2
    out[m4] = 0.5 * ((lmax - L[m4]) / (lmax - b)) ** 2
    return out


def mj_fp(L, lmax, fpmax):
    b = 0.5 * (1 + lmax)
    x1 = (L - 1) / (b - 1)
    x2 = (L - b) / (b - 1)
    return np.where(L <= 1, 0.0, np.where(L <= b, fpmax * 0.5 * x1 * x1, fpmax * (0.5 + x2)))


def mj_fv(V, fvmax):
    y = fvmax - 1
    return np.where(V <= -1, 0.0, np.where(V <= 0, (V + 1) ** 2,
                    np.where(V <= y, fvmax - (y - V) ** 2 / y, fvmax)))


def mj_isometric_tension(L, acts, lmin, lmax, fpmax):
    """MuJoCo 2.2.2's isometric tension / force at normalised lengths L and activations acts:
    act FL(L) + FP(L) (mju_muscleGain + mju_muscleBias at zero velocity)."""
    return acts * mj_fl(L, lmin, lmax) + mj_fp(L, lmax, fpmax)


def mj_act_dot(u, a, tau):
    t = np.where(u > a, tau[0] * (0.5 + 1.5 * a), tau[1] / (0.5 + 1.5 * a))
    return (u - a) / t


# --- gaitsim (callbacks/gs_muscle.h, gs_activation.h, gs_contact.h) ---------------------------
def gs_fv(v):
    return D1 * np.arcsinh(D2 * v + D3) + D4


def gs_act_dot(u, a, tau_a, tau_d):
    f = 0.5 + 0.5 * np.tanh(ACT_SMOOTHING * (u - a))
    s = 0.5 + 1.5 * a
    return (u - a) * (f / (tau_a * s) + (1 - f) * s / tau_d)


def hunt_crossley(E, R, d):
    return 4.0 / 3.0 * E * math.sqrt(R) * d ** 1.5


# --- MuJoCo 2.2.2 soft contact, static (engine_core_constraint.c: mj_makeImpedance) -----------
def mj_imp(d, dmin, dmax, width, mid, power):
    x = np.minimum(np.abs(d) / width, 1.0)
    y = np.where(x <= mid, x ** power / mid ** (power - 1),
                 1 - (1 - x) ** power / (1 - mid) ** (power - 1))
    return dmin + y * (dmax - dmin)


def mj_static_force(d, K, A, solimp):
    """Normal force holding a still contact at penetration d: aref / R = K imp^2 d / (A (1-imp))
    (aref = K imp d, R = A (1 - imp) / imp, K = -solref0 / dmax^2)."""
    imp = mj_imp(d, *solimp)
    return K * imp * imp * d / (A * (1 - imp))


# --- inputs -----------------------------------------------------------------------------------
def run_inspect(gaitsim, model, pose_file, time, activation):
    """{muscle: (lMT (m), lM/lopt (-), F (N))} from `gaitsim inspect` (gs_scriptlib)."""
    return {name: (r["lMT"], r["lM_norm"], r["F"])
            for name, r in inspect_muscles(gaitsim, model, pose_file, time, activation).items()}


def write_poses_mot(csv_path, mot_path):
    """jw_poses.csv (radians, model coordinate order) as a .mot with time = pose index."""
    with open(csv_path, encoding="utf-8") as f:
        lines = [ln.strip() for ln in f if ln.strip() and not ln.startswith("#")]
    labels = lines[0].split(",")[1:]
    rows = [[float(v) for v in ln.split(",")] for ln in lines[1:]]
    with open(mot_path, "w", encoding="utf-8") as f:
        f.write(storage_text("jw_poses", ["time"] + labels, rows, False, cell=repr))
    return [r[0] for r in rows]


def invweight0(source):
    """{body: translational invweight0} from mujoco-compile's text dump (2 significant digits)."""
    with tempfile.TemporaryDirectory() as tmp:
        txt = os.path.join(tmp, "model.txt")
        res = subprocess.run(["mujoco-compile", source, txt], capture_output=True, text=True)
        if res.returncode != 0 or not os.path.exists(txt):
            raise PrepError(source, "mujoco-compile failed (install libmujoco-samples)")
        with open(txt, encoding="utf-8") as f:
            lines = f.read().splitlines()
    out, name = {}, None
    for ln in lines:
        f = ln.split()
        if len(f) >= 2 and f[0] == "name":
            name = f[1]
        elif len(f) >= 3 and f[0] == "body_invweight0" and name:
            out[name] = float(f[1])
    return out


# --- fits -------------------------------------------------------------------------------------
def fit_velocity():
    """(c, fvmax): MuJoCo FV(c v) ~ De Groote fV(v) for v in [-1, 1] (lopt vmax units)."""
    v = np.linspace(-1, 1, 201)
    target = gs_fv(v)
    res = least_squares(lambda x: mj_fv(x[0] * v, x[1]) - target, [1.0, 1.6],
                        bounds=([0.3, 1.05], [3.0, 3.0]))
    return res.x[0], res.x[1], math.sqrt(np.mean(res.fun ** 2))


def fit_timeconst(tau_a, tau_d):
    """MuJoCo timeconst ~ gaitsim's activation dynamics over (u, a) in [0.01, 1]^2, residuals
    relative to the largest |da/dt|."""
    g = np.linspace(0.01, 1, 40)
    u, a = np.meshgrid(g, g)
    target = gs_act_dot(u, a, tau_a, tau_d)
    scale = np.max(np.abs(target))
    res = least_squares(lambda x: ((mj_act_dot(u, a, x) - target) / scale).ravel(),
                        [tau_a, tau_d], bounds=([1e-3, 1e-3], [1.0, 1.0]))
    return res.x, math.sqrt(np.mean(res.fun ** 2))


def fit_muscle(lmt, force, fmax, lopt, lnorm, lmt_min):
    """Fit (s, alpha, beta, lmin, lmax, fpmax) of tension = s Fmax (a FL(L) + FP(L)),
    L = alpha + beta lMT / lopt, to gaitsim's forces (A x P) at activations ACTIVATIONS and
    muscle-tendon lengths lmt (P). lnorm (A x P): gaitsim's lM/lopt, for the first guess.
    lmt_min (m): the shortest reachable length; a penalty keeps L(lmt_min) >= lmin + 0.02, clear
    of MuJoCo 2.2.2's negative FL below lmin (mj_fl). Returns the parameters and the RMS
    difference / Fmax."""
    acts = np.array(ACTIVATIONS)[:, None]
    x = lmt[None, :] / lopt
    target = force / fmax
    # first guess: gaitsim's normalised fibre length, linear in lMT at a = 0.5
    A = np.vstack([np.ones_like(x[0]), x[0]]).T
    if np.ptp(x[0]) > 1e-6:
        alpha0, beta0 = np.linalg.lstsq(A, lnorm[1], rcond=None)[0]
    else:
        alpha0, beta0 = float(np.mean(lnorm[1]) - x[0].mean()), 1.0
    if not beta0 > 0.05:
        beta0 = 1.0
        alpha0 = float(np.mean(lnorm[1]) - x[0].mean())
    lo = [0.2, -200, 0.05, 0.0, 1.05, 0.01]
    hi = [3.0, 200, 20.0, 0.95, 3.0, 20.0]

    def resid(p, reg):
        L = p[1] + p[2] * x
        model = p[0] * mj_isometric_tension(L, acts, p[3], p[4], p[5])
        r = (model - target).ravel()
        below = max(0.0, p[3] + 0.02 - (p[1] + p[2] * lmt_min / lopt))
        return np.concatenate([r, reg * (p - x0), [1e3 * below]])

    best = None
    for shift in (0.0, -0.15, 0.15, -0.3, 0.3):
        x0 = np.array([1.0, alpha0 + shift, beta0, 0.45, 1.6, 1.3])
        x0 = np.clip(x0, np.array(lo) + 1e-9, np.array(hi) - 1e-9)
        res = least_squares(lambda p: resid(p, 1e-3), x0, bounds=(lo, hi), x_scale="jac")
        rms = math.sqrt(np.mean(res.fun[:target.size] ** 2))
        if best is None or rms < best[1]:
            best = (res.x, rms)
    return best


def muscle_fit_rms(el, lmt, force, fmax, lopt):
    """RMS difference / Fmax between the MuJoCo muscle el (its force, range, lengthrange, lmin,
    lmax, fpmax as written) and gaitsim's forces (A x P) at lengths lmt (P), as fit_muscle's."""
    get = lambda k: [float(v) for v in el.get(k).split()]
    lr, rng = get("lengthrange"), get("range")
    L = rng[0] + (lmt - lr[0]) * (rng[1] - rng[0]) / (lr[1] - lr[0])
    lmin, lmax, fpmax = float(el.get("lmin")), float(el.get("lmax")), float(el.get("fpmax"))
    acts = np.array(ACTIVATIONS)[:, None]
    model = float(el.get("force")) / fmax * mj_isometric_tension(L[None, :], acts, lmin, lmax,
                                                                  fpmax)
    return math.sqrt(np.mean((model - force / fmax) ** 2))


def check_model(committed, generated, lmt, force, fits):
    """Compare a committed stock model (element tree) with the one this run generated. Every
    element, attribute and value must be equal, except the fitted muscle attributes (CHECK_FITTED)
    and the header comment: the muscle fits are non-convex least squares whose local minimum
    moves with the machine's floating point (OpenBLAS kernels, libm), so each committed muscle
    must instead fit gaitsim's forces at most CHECK_RMS_TOL worse than this run's fit. Returns
    ((largest excess, muscle), reason or None)."""
    a, b = list(committed.iter()), list(generated.iter())
    if len(a) != len(b):
        return (0.0, ""), f"{len(a)} elements, this run writes {len(b)}"
    worst, k = (-math.inf, ""), 0
    for ea, eb in zip(a, b):
        if ea.tag != eb.tag or set(ea.attrib) != set(eb.attrib):
            return worst, f"element {ea.tag} {ea.get('name', '')} differs in tag or attribute names"
        fitted = CHECK_FITTED if ea.tag == "muscle" else ()
        for key, val in eb.attrib.items():
            if key not in fitted and ea.get(key) != val:
                return worst, f"{ea.tag} {ea.get('name', '')}: {key}=\"{ea.get(key)}\", " \
                              f"this run writes \"{val}\""
        if ea.tag == "muscle":
            u = user_row(ea, None, 12)
            excess = muscle_fit_rms(ea, lmt[:, k], force[:, :, k], u[U_FMAX], u[U_LOPT]) - fits[k]
            worst = max(worst, (excess, ea.get("name")))
            k += 1
    if worst[0] > CHECK_RMS_TOL:
        return worst, f"muscle {worst[1]} fits gaitsim {worst[0]:.4f} worse than this run"
    return worst, None


def fit_contact_shape():
    """solimp (dmin, dmax, width, mid 0.5, power) and K1 such that
    mj_static_force(d, K1 E sqrt(R) A, A, solimp) ~ 4/3 E sqrt(R) d^1.5 for d in DEPTHS: the
    relative shape does not depend on E, R or A, so one grid search serves every sphere
    (deterministic; minimax relative error, K1 centring the log error). Returns
    (K1, solimp, largest relative error)."""
    target = hunt_crossley(1.0, 1.0, DEPTHS)
    best = None
    for power in (1.0, 1.5, 2.0, 3.0):
        for dmax in (0.6, 0.7, 0.8, 0.9, 0.95):
            for dmin in np.linspace(0.01, 0.9, 90):
                if dmin >= dmax:
                    continue
                widths = np.geomspace(0.002, 0.3, 80)
                imp = np.array([mj_imp(DEPTHS, dmin, dmax, w, 0.5, power) for w in widths])
                g = imp * imp * DEPTHS / (1 - imp)
                lr = np.log(target / g)
                K = np.exp(0.5 * (lr.max(axis=1) + lr.min(axis=1)))
                err = np.max(np.abs(K[:, None] * g / target - 1), axis=1)
                k = int(np.argmin(err))
                if best is None or err[k] < best[0]:
                    best = (float(err[k]), float(K[k]), (dmin, dmax, widths[k], 0.5, power))
    return best[1], best[2], best[0]


# --- model edit -------------------------------------------------------------------------------
def user_row(el, defaults, n):
    txt = el.get("user") or defaults
    vals = [float(v) for v in txt.split()]
    return vals + [0.0] * (n - len(vals))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", default="mjmodels/jw_fullbody.xml")
    ap.add_argument("--hill-model", default="mjmodels/jw_fullbody_knee6.xml")
    ap.add_argument("--trial", default="mjmodels/trials/jw_ngait_og5")
    ap.add_argument("--poses", default="mjmodels/reference/jw_poses.csv")
    ap.add_argument("--gaitsim", default="build/gaitsim")
    ap.add_argument("--out", default="mjmodels/jw_fullbody_mujoco.xml")
    ap.add_argument("--check", metavar="FILE",
                    help="write nothing; exit 1 unless FILE is what this run would write, up to "
                         "the fit's reproducibility (check_model)")
    args = ap.parse_args()
    if args.check:
        try:
            committed = ET.parse(args.check).getroot()
        except (OSError, ET.ParseError) as e:
            raise PrepError(args.check, f"cannot read: {e}")

    tree = ET.parse(args.source)
    root = tree.getroot()
    muscles = root.findall("./actuator/muscle")
    names = [m.get("name") for m in muscles]

    # gaitsim's isometric forces over the trial's rows and the reference poses
    coords = os.path.join(args.trial, "coordinates.mot")
    _, labels, rows = read_storage(coords)
    pose_sets = [(coords, [r[labels.index("time")] for r in rows])]
    with tempfile.TemporaryDirectory() as tmp:
        mot = os.path.join(tmp, "jw_poses.mot")
        pose_sets.append((mot, write_poses_mot(args.poses, mot)))
        lmt, force, lnorm = [], [[] for _ in ACTIVATIONS], [[] for _ in ACTIVATIONS]
        for path, times in pose_sets:
            for t in times:
                for k, a in enumerate(ACTIVATIONS):
                    got = run_inspect(args.gaitsim, args.hill_model, path, t, a)
                    if k == 0:
                        lmt.append([got[n][0] for n in names])
                    lnorm[k].append([got[n][1] for n in names])
                    force[k].append([got[n][2] for n in names])
    lmt = np.array(lmt)                       # P x M
    force = np.array(force)                   # A x P x M
    lnorm = np.array(lnorm)
    npose = lmt.shape[0]

    vel_c, fvmax, fv_rms = fit_velocity()
    user0 = user_row(muscles[0], None, 12)
    (tau_a, tau_d), act_rms = fit_timeconst(user0[U_TAU_ACT], user0[U_TAU_DEACT])

    worst = (0.0, "")
    fits = []
    for i, el in enumerate(muscles):
        u = user_row(el, None, 12)
        fmax, lopt, penn, vmax = u[U_FMAX], u[U_LOPT], u[U_PENN], u[U_VMAX]
        lr = [float(v) for v in el.get("lengthrange").split()]
        lr = [min(lr[0], lmt[:, i].min()), max(lr[1], lmt[:, i].max())]
        p, rms = fit_muscle(lmt[:, i], force[:, :, i], fmax, lopt, lnorm[:, :, i], lr[0])
        s, alpha, beta, lmin, lmax, fpmax = p
        rng = [alpha + beta * lr[0] / lopt, alpha + beta * lr[1] / lopt]
        L0 = lopt / beta
        vmax_mj = vmax * lopt * math.cos(penn) / (vel_c * L0)
        el.set("force", fmt(s * fmax))
        el.set("range", f"{fmt(rng[0])} {fmt(rng[1])}")
        el.set("lengthrange", f"{fmt(lr[0])} {fmt(lr[1])}")
        el.set("lmin", fmt(lmin))
        el.set("lmax", fmt(lmax))
        el.set("fpmax", fmt(fpmax))
        el.set("vmax", fmt(vmax_mj))
        el.set("fvmax", fmt(fvmax))
        el.set("timeconst", f"{fmt(tau_a)} {fmt(tau_d)}")
        fits.append(rms)
        if rms > worst[0]:
            worst = (rms, el.get("name"))

    # contact: fitted solref/solimp per foot sphere; elliptic cone
    iw = invweight0(args.source)
    defaults = root.find("./default")
    contact_def = defaults.find("./default[@class='contact']/geom")
    contact_user = contact_def.get("user")
    K1, solimp, contact_fit_err = fit_contact_shape()
    stops = []
    parents = {c: p for p in root.iter() for c in p}
    for g in root.iter("geom"):
        if g.get("class") != "contact":
            continue
        body = parents[g].get("name")
        urow = user_row(g, contact_user, 6)
        R = float(g.get("size").split()[0])
        A = iw[body]
        K = K1 * urow[G_E] * math.sqrt(R) * A
        imp = float(mj_imp(np.array([DAMPING_DEPTH]), *solimp)[0])
        hc = hunt_crossley(urow[G_E], R, DAMPING_DEPTH)
        B = 1.5 * urow[G_C] * hc * A * (1 - imp) / imp
        dmax = solimp[1]
        g.set("solref", f"{fmt(-K * dmax * dmax)} {fmt(-B * dmax)}")
        g.set("solimp", " ".join(fmt(v) for v in solimp))
        g.set("friction", f"{fmt(urow[G_MUD])} 0.005 0.0001")
        stops.append((parents[g], g))
    contact_def.set("friction", "0.8 0.005 0.0001")
    contact_def.set("condim", "3")
    opt = root.find("./option")
    opt.set("cone", "elliptic")
    floor = root.find("./worldbody/geom[@name='floor']")
    floor.set("conaffinity", "3")
    floor.set("solmix", "0")
    floor.set("friction", "0.8 0.005 0.0001")

    # collision geoms on every other segment: contype 2 touches only the floor (conaffinity 3)
    seg_def = ET.SubElement(defaults, "default", {"class": "segment"})
    ET.SubElement(seg_def, "geom", {"contype": "2", "conaffinity": "0", "group": "1",
                                    "condim": "3", "solref": SEGMENT_SOLREF,
                                    "rgba": "0.85 0.8 0.7 0.4"})
    for body, g in stops:
        stop = ET.Element("geom", {"name": "stop" + g.get("name")[len("contact"):],
                                   "class": "segment", "type": "sphere", "pos": g.get("pos"),
                                   "size": fmt(float(g.get("size").split()[0]) - STOP_DEPTH)})
        body.insert(list(body).index(g) + 1, stop)
    bodies = {b.get("name"): b for b in root.iter("body")}
    for name, geoms in SEGMENTS.items():
        body = bodies[name]
        insert_at = len([c for c in body if c.tag in ("joint", "inertial")])
        for k, (gtype, size, spec) in enumerate(geoms):
            attrs = {"name": f"{name}_collision{k + 1 if k else ''}", "class": "segment",
                     "type": gtype, "size": fmt(size)}
            if spec.startswith("child:"):
                child = [float(v) for v in bodies[spec[6:]].get("pos").split()]
                attrs["fromto"] = "0 0 0 " + " ".join(fmt(0.9 * c) for c in child)
            elif gtype == "capsule":
                attrs["fromto"] = spec
            else:
                attrs["pos"] = spec
            body.insert(insert_at + k, ET.Element("geom", attrs))
    missing = [b for b in bodies if b not in SEGMENTS and b not in FOOT_BODIES
               and b != "ground"]
    if missing:
        raise PrepError(args.source, f"bodies without a collision geom: {', '.join(missing)}")

    root.set("model", "jw_fullbody_mujoco")
    ET.indent(tree, space="  ")
    body_xml = ET.tostring(root, encoding="unicode")
    fit_rms = np.array(fits)
    header = f"""<?xml version="1.0" encoding="utf-8"?>
<!--
  jw_fullbody_mujoco.xml: GENERATED by scripts/make_stock_model.py, do not edit by hand;
  regenerate (after building gaitsim) with /usr/bin/python3 scripts/make_stock_model.py and
    its options source {args.source}, hill-model {args.hill_model},
    trial {args.trial}, poses {args.poses}
  Sources: {args.source} (its header: converted by scripts/osim2mjcf.py from
    JW_AllBody_scaled.osim, gilserrancoli/ReducePoly_forMSK, MIT licence; Knee Grand Challenge
    subject JW, Fregly et al. 2012) and gaitsim's physics on {args.hill_model}.
  JW's full-body model for STOCK MuJoCo 2.2.2 (no gaitsim callbacks): the source model with
  MuJoCo-native parameters fitted by least squares to gaitsim's physics (mjmodels/README.md,
  "jw_fullbody_mujoco.xml"). Kinematics, masses, tendon paths, keyframe and the user rows
  (gaitsim's own Hill and contact parameters) are the source's.
  Muscles: force, range (with lengthrange), lmin, lmax, fpmax fitted per muscle to gaitsim's
    isometric tendon force (gaitsim inspect on the Hill model) at {npose} poses
    ({os.path.join(args.trial, 'coordinates.mot')} rows and {args.poses}) x activations
    {', '.join(str(a) for a in ACTIVATIONS)}: RMS difference / Fmax median {np.median(fit_rms):.3f},
    largest {worst[0]:.3f} ({worst[1]}). Elastic tendons are represented by their rigid-tendon
    equivalent at gaitsim's isometric equilibrium (no tendon state in stock MuJoCo).
    fvmax {fvmax:.4g} and a velocity scale {vel_c:.4g} fitted to De Groote 2016 fV over
    -1..1 lopt vmax (RMS {fv_rms:.3f}); timeconst {tau_a:.4g} {tau_d:.4g} s fitted to
    gaitsim's activation dynamics (RMS {act_rms:.3f} of the largest rate).
  Contact: foot spheres' solref (direct stiffness, damping) and solimp fitted so that the
    static force (efc_aref / efc_R) matches gaitsim's Hunt-Crossley force for 2-15 mm
    penetration (largest relative error of the fit {contact_fit_err:.3f}; contact inverse
    weights from body_invweight0 of mujoco-compile, 2 significant digits); elliptic cone,
    friction {fmt(user_row(contact_def, contact_user, 6)[G_MUD])}. Collision geoms of class
    segment touch only the floor: one or two per segment, and inside each foot sphere a
    concentric stop sphere {STOP_DEPTH * 1000:.0f} mm smaller that ends the fitted range.
  Knee: the source's placeholder springs hold the five secondary right-knee coordinates
    (a 1-DOF knee in effect); gaitsim's implant-knee surrogate is not represented.
-->
"""
    if args.check:
        worst_excess, why = check_model(committed, root, lmt, force, fits)
        verdict = "differs" if why else "matches"
        print(f"make_stock_model: {args.check} {verdict}: {why or 'structure and attributes equal'}"
              f"; largest fit RMS/Fmax above this run's {worst_excess[0]:.4f} ({worst_excess[1]}, "
              f"tolerance {CHECK_RMS_TOL})")
        if why:
            sys.exit(1)
        return
    write_atomic(args.out, header + body_xml + "\n")
    print(f"make_stock_model: wrote {args.out}: {len(names)} muscles, RMS/Fmax median "
          f"{np.median(fit_rms):.3f}, max {worst[0]:.3f} ({worst[1]}); {npose} poses; "
          f"fvmax {fvmax:.3f} c {vel_c:.3f}; timeconst {tau_a:.4f} {tau_d:.4f}; "
          f"contact fit max rel err {contact_fit_err:.3f}")
    for n, r in sorted(zip(names, fits), key=lambda t: -t[1])[:8]:
        print(f"  {n:14s} RMS/Fmax {r:.3f}")


if __name__ == "__main__":
    try:
        main()
    except PrepError as e:
        print(f"make_stock_model: {e}", file=sys.stderr)
        sys.exit(1)
