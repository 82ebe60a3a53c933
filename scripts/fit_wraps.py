#!/usr/bin/env python3
"""Fit the MuJoCo wrap surrogates of JW's wrapping muscles to OpenSim's wrapped paths.

MuJoCo 2.2 wraps a spatial tendon over spheres and (infinite) cylinders only, with an optional
side site; JW's .osim wraps over ellipsoids (SIMM's plane-section method) and cylinders, several
per segment. The converter's first surrogate (an ellipsoid -> a cylinder of its mean minor radius,
one wrap per segment) missed OpenSim's paths by up to 27 mm in length and 35 mm in moment arm
(mjmodels/README.md, "Wrapped reference"). This script gives each wrapping muscle its own wrap
geom (and side site) and fits their placement, radius and axis so that MuJoCo's path matches
OpenSim's wrapped path (the converter's port, `wrapped_path`) over the trial:

  minimise  mean e^2 + 10 mean max(0, |e| - 0.5)^2,  e = (L - L_ref) / 5 mm  and
            (r - r_ref) / max(5 mm, 0.15 |r_ref|) over every fitting pose and every coordinate
            the muscle crosses, the right knee's secondary rotations included (not through the
            patella), its translations not

(the tolerance of issue #20 item 1, enforced by tests/test_model_moment_arms.c). Fitting poses:
every --every-th frame of the trial's IK plus the reference poses of jw_poses.csv. Starts: each
of the muscle's OpenSim wrap objects as the surrogate (on its own body), without a side site and
with one at 1.5 radii along each axis perpendicular to the cylinder (each axis of a sphere); each
start is refined by Nelder-Mead over the geom's position (m), log radius, axis tilt (rad) and the
side site's position (m), evaluated by MuJoCo itself (build/path_probe, geometry moved in place).
A refined fit is kept only if its length is continuous (no step above JUMP_TOL along lines
through trial poses). Where one wrap stays above TWO_WRAP_ABOVE, two wraps with a via site, in the
order of the body chain; then a second pass from the fit of a muscle over the same OpenSim
objects. Muscles whose converter surrogate already meets the tolerance with a margin (max |e| <=
--keep), is continuous and clears its wrap by CLEAR_MIN keep it; one that meets it but jumps or
has a path site closer to its wrap is replaced by a fit within --keep where one is found. Writes
mjmodels/reference/jw_wrap_fit.json, which scripts/osim2mjcf.py reads (--wrap-fit);
deterministic (fixed starts, fixed seeds).

usage (mjmodels/README.md, "Fitted wraps", has the whole regeneration):
  fit_wraps.py --osim .../JW_AllBody_scaled.osim --model mjmodels/.fit_base.xml --every 20
         [--probe build/path_probe] [--out mjmodels/reference/jw_wrap_fit.json]
         [--muscles a,b] [--cache /tmp/wrap_ref.json] [--previous FILE]
  fit_wraps.py --osim .../JW_AllBody_scaled.osim --check --every 5    (the written model)
--model is the converter's model without fitted wraps (osim2mjcf.py --wrap-fit none); with
--check, the model to measure (default mjmodels/jw_fullbody.xml).
"""
import argparse
import copy
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import osim2mjcf as cv  # noqa: E402

LENGTH_TOL = 0.005      # m: length tolerance (issue #20 item 1)
ARM_TOL = 0.005         # m: moment-arm tolerance, or ARM_REL of |r_ref| where larger
ARM_REL = 0.15
KNEE_TRANSLATIONS = ("knee_tx", "knee_ty", "knee_tz")  # dL/dq = direction cosines (m/m): not
                        # moment arms; not fitted (MuJoCo's gastrocnemius path cannot follow
                        # OpenSim's two stacked wraps there, mjmodels/README.md)
COORDINATES = ("crossed; the right knee's rotations included but through the patella, its "
               "translations not")  # (the reference cache's key)
SIDE_REACH = 1.5        # side site distance from the axis (radii)
SIDE_MAX = 0.1          # side sites stay within this distance of their geom's centre (m)
SIDE_CLEAR = 0.2        # ... and outside its surface by at least this fraction of the radius
CLEAR_MIN = 0.002       # path sites next to a wrap geom stay this far outside its surface (m)
CLEAR_WEIGHT = 1e6      # penalty weight of a smaller clearance (1/m^2)
STEP_POS = 0.01         # Nelder-Mead initial steps: position (m), log radius, tilt (rad)
STEP_LOGR = 0.3
STEP_TILT = 0.3
MAXFEV = 2500           # evaluations per refinement
SCREEN_MAXFEV = 600     # evaluations per start
REFINED = 2             # best starts refined
NAN_EVERY = 3           # --check's NaN scan: every NAN_EVERY-th trial frame,
NAN_SCALES = (1e-6, 1e-3, 0.05)  # perturbed by these standard deviations (rad),
NAN_SAMPLES = 60        # this many times each
TWO_WRAP_ABOVE = 0.9    # max |e| of the best single wrap above which two wraps are tried
JUMP_SCALE = 0.05       # continuity scan: from every NAN_EVERY-th trial frame a line along a
                        # random direction (this standard deviation per coordinate, rad; 1 % of
                        # it in m for translations), fixed seed,
JUMP_STEPS = 200        # sampled at this many poses (about 1 mrad apart),
JUMP_TOL = 0.0005       # where a step of the length above this (m) is a jump: MuJoCo's wrap
                        # switching sides or off (a side site's forced wrap whose tangent lines
                        # cross), which no smooth path does in 1 mrad
MAX_REFINED = 8         # refinements tried per muscle before giving up on a continuous fit


def quat_mul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


def quat_rotvec(v):
    a = math.sqrt(sum(x * x for x in v))
    if a < 1e-15:
        return [1.0, 0.0, 0.0, 0.0]
    s = math.sin(a / 2) / a
    return [math.cos(a / 2), v[0] * s, v[1] * s, v[2] * s]


class Probe:
    """build/path_probe on one model file: MuJoCo's lengths and moment arms."""

    def __init__(self, exe, model_xml, poses):
        self.p = subprocess.Popen([exe, model_xml], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True, bufsize=1)
        self.joints = self.p.stdout.readline().split()[1:]
        if self.p.stdout.readline().strip() != "ready":
            raise SystemExit("fit_wraps.py: %s did not start on %s" % (exe, model_xml))
        for pose in poses:
            self.p.stdin.write("pose " + " ".join(repr(pose[j]) for j in self.joints) + "\n")
        self.p.stdin.flush()

    def set(self, line):
        self.p.stdin.write(line + "\n")

    def eval(self, tendon):
        self.p.stdin.write("eval %s\n" % tendon)
        self.p.stdin.flush()
        rows = []
        while True:
            line = self.p.stdout.readline()
            if line.startswith("error"):
                raise SystemExit("fit_wraps.py: path_probe: " + line.strip())
            if line.strip() == "end" or not line:
                break
            rows.append([float(v) for v in line.split()])
        return np.array(rows)

    def close(self):
        self.p.stdin.write("quit\n")
        self.p.stdin.close()
        self.p.wait()


def reference(model, muscles, poses, methods):
    """{muscle: {"coords": [...], "L": [pose], "r": [[pose][coord]]}} of OpenSim's wrapped path."""
    out = {}
    for mus in muscles:
        # the rotations of the right knee's secondary coordinates included (with the knee-contact
        # model knee_adduction's moment arm moves load between the compartments), except through
        # the patella: MuJoCo's is rigid with the tibia, the .osim's follows the femur in them
        through_patella = any(cv.relocated_body(p["body"]) for p in mus["points"])
        coords = [c for c in cv.crossed_coordinates(model, mus) if c not in KNEE_TRANSLATIONS
                  and not (through_patella and c in cv.KNEE_SECONDARY)]
        lengths, arms = [], []
        for pose in poses:
            lengths.append(cv.wrapped_path(model, mus, pose, methods)[0])
            r = cv.wrapped_moment_arms(model, mus, pose, coords, methods)
            arms.append([r[c] for c in coords])
        out[mus["name"]] = {"coords": coords, "L": lengths, "r": arms}
        print("reference %-10s %d poses" % (mus["name"], len(poses)), flush=True)
    return out


def errors(ref, joints, rows):
    """Normalised errors e (length first, then moment arms) over the poses."""
    cols = [joints.index(c) for c in ref["coords"]]
    L = rows[:, 0]
    r = rows[:, [1 + c for c in cols]]
    rref = np.array(ref["r"])
    eL = (L - np.array(ref["L"])) / LENGTH_TOL
    er = (r - rref) / np.maximum(ARM_TOL, ARM_REL * np.abs(rref))
    return np.concatenate([eL, er.ravel()])


def objective_of(e, clearance=None):
    """mean e^2 + 10 mean max(0, |e| - 0.5)^2, plus CLEAR_WEIGHT max(0, CLEAR_MIN - C)^2 summed
    over the poses: a site next to a wrap geom on or inside its surface makes MuJoCo's wrap
    ill-posed (it wraps or not on a rounding of the geometry)."""
    j = float(np.mean(e * e) + 10.0 * np.mean(np.maximum(0.0, np.abs(e) - 0.5) ** 2))
    if clearance is not None:
        j += CLEAR_WEIGHT * float(np.sum(np.maximum(0.0, CLEAR_MIN - clearance) ** 2))
    return j


def vec(v):
    return " ".join(repr(float(x)) for x in v)


def write_variant(base_tree, model_dir, muscle, slot, start):
    """Model with muscle's wrap element at tendon position `slot` replaced by the parts of
    `start` (wrap geoms with their side sites, via sites between them); returns the file name
    (written next to the model, so that its meshes resolve)."""
    root = copy.deepcopy(base_tree.getroot())
    bodies = {b.get("name"): b for b in root.iter("body")}
    tendon = [t for t in root.iter("spatial") if t.get("name") == muscle][0]
    elems = []
    for k, part in enumerate(start["parts"]):
        gname, sname, vname = cv.fitted_part_names(muscle, k)
        body = bodies[part["body"]]
        if part["kind"] == "via":
            ET.SubElement(body, "site", {"name": vname, "class": "path", "pos": vec(part["pos"])})
            elems.append(ET.Element("site", {"site": vname}))
            continue
        ET.SubElement(body, "geom", {"name": gname, "class": "wrap", "type": part["type"],
                                     "size": vec(part["size"]), "pos": vec(part["pos"]),
                                     "quat": vec(part["quat"])})
        attrs = {"geom": gname}
        if part["side"] is not None:
            ET.SubElement(body, "site", {"name": sname, "class": "side", "pos": vec(part["side"])})
            attrs["sidesite"] = sname
        elems.append(ET.Element("geom", attrs))
    children = list(tendon)
    for c in children:
        tendon.remove(c)
    for c in children[:slot] + elems + children[slot + 1:]:
        tendon.append(c)
    path = os.path.join(model_dir, ".fit_wraps.%s.xml" % muscle)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
    return path


def part_nparams(part):
    if part["kind"] == "via":
        return 3
    return (6 if part["type"] == "cylinder" else 4) + (3 if part["side"] is not None else 0)


def nparams(start):
    return sum(part_nparams(p) for p in start["parts"])


def steps(start):
    s = []
    for part in start["parts"]:
        if part["kind"] == "via":
            s += [STEP_POS] * 3
            continue
        s += [STEP_POS] * 3 + [STEP_LOGR]
        if part["type"] == "cylinder":
            s += [STEP_TILT, STEP_TILT]
        if part["side"] is not None:
            s += [STEP_POS] * 3
    return s


def written(v):
    """v as the converter writes it (osim2mjcf.fmt: 8 significant digits), so that the fit
    evaluates exactly the model that is written."""
    return [float(cv.fmt(float(u))) for u in v]


def geometry(start, x):
    """The parts of `start` moved by parameter vector x: via sites by dx (m); geoms by dx (m),
    their radius by a factor exp(x) and a cylinder's axis tilted by a rotation vector
    perpendicular to it (rad); side sites by dx (m)."""
    out, k = [], 0
    for part in start["parts"]:
        q = dict(part)
        if part["kind"] == "via":
            q["pos"] = [part["pos"][i] + x[k + i] for i in range(3)]
            k += 3
            out.append(q)
            continue
        q["pos"] = [part["pos"][i] + x[k + i] for i in range(3)]
        q["logr"] = x[k + 3]
        r = part["size"][0] * math.exp(x[k + 3])
        k += 4
        if part["type"] == "cylinder":
            q["quat"] = quat_mul(part["quat"], quat_rotvec([x[k], x[k + 1], 0.0]))
            k += 2
            q["size"] = [r, max(part["size"][1], r)]
        else:
            q["size"] = [r]
        if part["side"] is not None:
            q["side"] = [part["side"][i] + x[k + i] for i in range(3)]
            k += 3
        out.append(q)
    for q in out:
        for key in ("pos", "quat", "size", "side"):
            if q.get(key) is not None:
                q[key] = written(q[key])
    return out


def feasible(parts):
    """Radius within a factor 4.5 of the start; side sites within SIDE_MAX of the geom centre."""
    for q in parts:
        if q["kind"] == "via":
            continue
        if abs(q["logr"]) > 1.5:
            return False
        if q["side"] is not None:
            if math.dist(q["side"], q["pos"]) > SIDE_MAX:
                return False
            # outside the surface, clear of it: with the side site inside, MuJoCo 2.2 wraps by
            # its inside-wrap iteration, which returned NaN lengths at isolated poses (grac's
            # first fit, at a 1.2 m/s prediction's iterate), and at the surface the choice
            # between the two hangs on a rounding
            rel = [q["side"][i] - q["pos"][i] for i in range(3)]
            m = cv.mat_from_quat(q["quat"])
            local = [sum(m[i][k] * rel[i] for i in range(3)) for k in range(3)]
            dist = math.hypot(local[0], local[1]) if q["type"] == "cylinder" else \
                math.sqrt(sum(v * v for v in local))
            if dist < (1.0 + SIDE_CLEAR) * q["size"][0]:
                return False
    return True


def fit_start(probe, muscle, ref, start, x0=None, maxfev=MAXFEV, restarts=3):
    def run(x):
        for k, q in enumerate(geometry(start, x)):
            gname, sname, vname = cv.fitted_part_names(muscle, k)
            if q["kind"] == "via":
                probe.set("site %s %s" % (vname, vec(q["pos"])))
                continue
            size = q["size"] + [0.0] if q["type"] == "sphere" else q["size"]
            probe.set("geom %s %s %s %s" % (gname, vec(q["pos"]), vec(q["quat"]), vec(size)))
            if q["side"] is not None:
                probe.set("site %s %s" % (sname, vec(q["side"])))
        rows = probe.eval(muscle)
        return errors(ref, probe.joints, rows), rows[:, -1]

    def f(x):
        if not feasible(geometry(start, x)):
            return 1e6
        return objective_of(*run(x))

    n = nparams(start)
    x0 = np.zeros(n) if x0 is None else np.array(x0)
    simplex = [x0] + [x0 + np.eye(n)[i] * steps(start)[i] for i in range(n)]
    best = None
    for _ in range(restarts):  # restarts of the simplex at the best point
        res = minimize(f, x0, method="Nelder-Mead",
                       options={"initial_simplex": np.array(simplex), "maxfev": maxfev,
                                "xatol": 1e-6, "fatol": 1e-9, "adaptive": True})
        if best is None or res.fun < best.fun - 1e-9:
            best = res
            x0 = res.x
            simplex = [x0] + [x0 + np.eye(n)[i] * steps(start)[i] * 0.3 for i in range(n)]
        else:
            break
    e, clearance = run(best.x)
    print("    least clearance %.1f mm" % (1000 * float(np.min(clearance))))
    labels = ["L@%d" % k for k in range(len(ref["L"]))] + [
        "%s@%d" % (c, k) for k in range(len(ref["L"])) for c in ref["coords"]]
    worst = np.argsort(-np.abs(e))[:4]
    print("    worst: " + ", ".join("%s %+.2f" % (labels[i], e[i]) for i in worst))
    parts = []
    for q in geometry(start, best.x):
        q = {k: v for k, v in q.items() if k != "logr"}
        parts.append(q)
    return best.fun, float(np.max(np.abs(e))), best.x, {"parts": parts, "from": start["from"]}


def starts_for(model, mus, tendon_geom):
    """Surrogates of each OpenSim wrap object of the muscle, with each side-site choice."""
    objects = cv.wrap_objects(model)
    out = []
    names = [pw["object"] for pw in mus["wraps"]]
    if tendon_geom not in names:
        names.append(tendon_geom)
    for name in names:
        body, w = objects[name]
        if cv.relocated_body(body):
            continue  # their MJCF frames differ from the .osim's; the converter's geom stays
        spec = cv.wrap_geom_spec(body, w)
        shapes = [(spec["type"], spec["radius"], spec["half"], spec["rot"])]
        if w["type"] == "WrapEllipsoid" and spec["type"] == "cylinder":
            shapes.append(("sphere", sum(w["dimensions"]) / 3.0, 0.0, w["rotation"]))
        for kind, radius, half, rot in shapes:
            quat = cv.quat_from_mat(rot)
            axes = [0, 1] if kind == "cylinder" else [0, 1, 2]
            for scale in (1.0, 2.0):
                r = radius * scale
                size = [r] if kind == "sphere" else [r, max(half, r)]
                # no side site (shorter side) or one outside along each axis
                sides = [None]
                for a in axes:
                    for sgn in (1.0, -1.0):
                        d = [sgn * rot[i][a] * SIDE_REACH * r for i in range(3)]
                        sides.append([w["translation"][i] + d[i] for i in range(3)])
                for side in sides:
                    out.append({"parts": [{
                        "kind": "geom", "body": body, "type": kind, "pos": list(w["translation"]),
                        "quat": quat, "size": size, "side": side}],
                        "from": "%s %s x%g" % (name, kind, scale)})
    return out


def chain_position(parents, first, last):
    """{body: position} along the MJCF tree path from body `first` to body `last` (0 at first);
    a body off the path takes the position of its nearest ancestor on it."""
    def up(b):
        out = [b]
        while b in parents:
            b = parents[b]
            out.append(b)
        return out
    a, b = up(first), up(last)
    common = next(x for x in a if x in b)
    path = a[:a.index(common) + 1] + list(reversed(b[:b.index(common)]))
    pos = {x: i for i, x in enumerate(path)}

    def position(body):
        return next(pos[x] for x in up(body) if x in pos)
    return position


def two_wrap_starts(model, mus, first_site, single, position):
    """Two wraps in sequence on one segment, which MuJoCo expresses only with a via site between
    them: the best single fit `single` (from one OpenSim object) and a surrogate of the muscle's
    other wrap object, in path order, with a via site starting at the midpoint of the two
    centres (in the second object's body). Path order: along the body chain from the segment's
    first site to its last (`position`), so that the path never returns to a body it has left
    (a loop femur -> tibia -> femur would pull the tibia with twice the tension); on one body,
    the object nearer the first site first."""
    objects = cv.wrap_objects(model)
    zero = {c: model.default_value(c) if c in cv.KNEE_SECONDARY else 0.0
            for c in cv.MODEL_COORDINATES}
    x0 = model.body_transforms(model.coordinate_values(zero))
    a = single["parts"][0]
    a_name = single["from"].split()[0]
    out = []
    others = [(pw["object"], 0.0) for pw in mus["wraps"] if pw["object"] != a_name]
    if not others:  # one long object: a second copy half-way along its axis either side
        others = [(a_name, 0.5), (a_name, -0.5)]
    for obj, shift in others:
        body, w = objects[obj]
        if cv.relocated_body(body):
            continue
        spec = cv.wrap_geom_spec(body, w)
        centre = [w["translation"][i] + shift * spec["half"] * spec["rot"][i][2]
                  for i in range(3)]
        ca = cv.tf_point(x0[a["body"]], a["pos"])
        cb = cv.tf_point(x0[body], centre)
        site = cv.tf_point(x0[first_site[0]], first_site[1])
        mid = [(ca[i] + cb[i]) / 2.0 for i in range(3)]
        a_first = (position(a["body"]), math.dist(site, ca)) <= (position(body),
                                                                  math.dist(site, cb))
        second = body if a_first else a["body"]
        via = {"kind": "via", "body": second, "pos": cv.tf_point(cv.tf_inv(x0[second]), mid)}
        r = spec["radius"]
        size = [r] if spec["type"] == "sphere" else [r, max(spec["half"], r)]
        # the second geom without a side site or with one outside along each of its axes
        axes = [0, 1] if spec["type"] == "cylinder" else [0, 1, 2]
        sides = [None] + [[centre[i] + sgn * spec["rot"][i][ax] * SIDE_REACH * r
                           for i in range(3)] for ax in axes for sgn in (1.0, -1.0)]
        # the single fit's geom with its side site (if any) and without
        a_variants = [dict(a)] + ([dict(a, side=None)] if a["side"] is not None else [])
        for a_part in a_variants:
            for side in sides:
                b_part = {"kind": "geom", "body": body, "type": spec["type"], "pos": centre,
                          "quat": cv.quat_from_mat(spec["rot"]), "size": size, "side": side}
                parts = [a_part, dict(via), b_part] if a_first else [b_part, dict(via), a_part]
                out.append({"parts": parts, "from": "%s + %s%s" % (
                    single["from"], obj, " %+g half" % shift if shift else "")})
    return out


def nan_scan(probe, frames, muscles):
    """Count the poses where a muscle's MuJoCo length or moment arm is not finite, on `probe`
    (the model's, without fitting poses): every NAN_EVERY-th trial frame, each coordinate
    perturbed NAN_SAMPLES times by a normal deviate of each scale in NAN_SCALES (rad; 1 % of
    that in m for translations), a fixed seed. Returns (poses scanned, [(muscle, non-finite
    poses)])."""
    rng = np.random.default_rng(0)
    bad = {}
    scanned = 0
    for _, base in frames[::NAN_EVERY]:
        probe.set("clear")
        for scale in NAN_SCALES:
            for _ in range(NAN_SAMPLES):
                pose = [base[j] + rng.normal() * scale * (0.01 if j in cv.TRANSLATIONS else 1.0)
                        for j in probe.joints]
                probe.set("pose " + vec(pose))
        scanned += NAN_SAMPLES * len(NAN_SCALES)
        for mus in muscles:
            rows = probe.eval(mus["name"])
            n = int(np.sum(~np.isfinite(rows[:, :-1]).all(axis=1)))
            if n:
                bad[mus["name"]] = bad.get(mus["name"], 0) + n
    return scanned, sorted(bad.items())


def fit_variant(args, base, model_dir, poses, name, slot, r, start, scan=False, **options):
    """fit_start on the model with `start` in place of the muscle's wrap (written, probed,
    removed); returns fit_start's (objective, max |e|, x, fit) and, with scan, the fit's
    largest_jump (the probe ends at the fitted geometry), else None."""
    path = write_variant(base, model_dir, name, slot, start)
    try:
        probe = Probe(args.probe, path, poses)
        result = fit_start(probe, name, r, start, **options)
        jump = largest_jump(probe, name, args.jump_lines) if scan else None
        probe.close()
    finally:
        os.unlink(path)
    return result + (jump,)


def measure_fit(args, base, model_dir, poses, name, slot, r, fit):
    """(max |e|, largest_jump) of the model with `fit` in place of the muscle's wrap."""
    path = write_variant(base, model_dir, name, slot, fit)
    try:
        probe = Probe(args.probe, path, poses)
        emax = float(np.max(np.abs(errors(r, probe.joints, probe.eval(name)))))
        jump = largest_jump(probe, name, args.jump_lines)
        probe.close()
    finally:
        os.unlink(path)
    return emax, jump


def jump_lines(frames):
    """The continuity scan's lines: (base pose, direction) per NAN_EVERY-th trial frame."""
    rng = np.random.default_rng(1)
    out = []
    for _, base in frames[::NAN_EVERY]:
        d = {c: rng.normal() * JUMP_SCALE * (0.01 if c in cv.TRANSLATIONS else 1.0)
             for c in sorted(base)}
        out.append((base, d))
    return out


def largest_jump(probe, muscle, lines):
    """The largest step (m) of the muscle's length between neighbouring poses of the lines."""
    worst = 0.0
    for base, d in lines:
        probe.set("clear")
        for t in np.linspace(0.0, 1.0, JUMP_STEPS):
            probe.set("pose " + vec([base[j] + t * d.get(j, 0.0) for j in probe.joints]))
        L = probe.eval(muscle)[:, 0]
        worst = max(worst, float(np.max(np.abs(np.diff(L)))))
    return worst


def fit_starts(args, base, model_dir, poses, name, slot, r, starts):
    """Screen every start briefly, refine the REFINED best whose fits are continuous (no jump
    in the continuity scan; at most MAX_REFINED refinements); returns (objective, max |e|,
    fit)."""
    screened = []
    for start in starts:
        obj, emax, x, fit, _ = fit_variant(args, base, model_dir, poses, name, slot, r, start,
                                           maxfev=SCREEN_MAXFEV, restarts=1)
        print("  from %-44s objective %.4f max |e| %.2f" % (describe(start), obj, emax),
              flush=True)
        screened.append((obj, emax, len(screened), start, x))
    best, kept = None, 0
    for obj, emax, _, start, x in sorted(screened, key=lambda t: (t[0], t[2]))[:MAX_REFINED]:
        obj, emax, x, fit, jump = fit_variant(args, base, model_dir, poses, name, slot, r,
                                              start, scan=True, x0=x)
        print("  refined %-41s objective %.4f max |e| %.2f, largest step %.2f mm%s" % (
            describe(start), obj, emax, 1000 * jump, " (a jump: rejected)" if jump > JUMP_TOL
            else ""), flush=True)
        if jump > JUMP_TOL:
            continue
        if best is None or (emax, obj) < (best[1], best[0]):
            best = (obj, emax, fit)
        kept += 1
        if kept == REFINED:
            break
    return best


def describe(start):
    sides = ",".join("-" if p["kind"] == "via" else ("side" if p["side"] is not None else "none")
                     for p in start["parts"])
    return "%s [%s]" % (start["from"], sides)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--osim", required=True)
    ap.add_argument("--model", default="mjmodels/jw_fullbody.xml")
    ap.add_argument("--probe", default="build/path_probe")
    ap.add_argument("--out", default="mjmodels/reference/jw_wrap_fit.json")
    ap.add_argument("--trial-ik", default=None)
    ap.add_argument("--every", type=int, default=20)
    ap.add_argument("--muscles", default=None)
    ap.add_argument("--keep", type=float, default=0.8,
                    help="keep the converter's surrogate where max |e| is at most this")
    ap.add_argument("--cache", default=None, help="reference cache (json) to reuse")
    ap.add_argument("--previous", default=None,
                    help="an earlier fit file (json): a muscle this run leaves above the "
                         "tolerance keeps its fit there when that is within it and continuous "
                         "(marked \"kept from\" in the output)")
    ap.add_argument("--check", action="store_true",
                    help="fit nothing: print each wrapping muscle's max |e| of --model over the "
                         "poses, scan perturbed trial poses for non-finite paths and lines "
                         "through trial poses for jumps of the length; exit 1 if any max |e| is "
                         "above 1, a path site sits within 2 mm of a wrap surface, a path is not "
                         "finite or a length jumps")
    args = ap.parse_args()
    if not os.access(args.probe, os.X_OK):
        ap.error("--probe %s: not an executable (cmake --build build --target path_probe)"
                 % args.probe)
    trial = args.trial_ik or os.path.join(os.path.dirname(os.path.abspath(args.osim)), "..",
                                          "ngait_og5", "IK_ngait_og5.csv")
    model = cv.OsimModel(args.osim)
    frames = cv.read_trial(trial)
    args.jump_lines = jump_lines(frames)
    methods = cv.read_wrap_methods(args.osim)
    idx = sorted(set(range(0, len(frames), args.every)) | set(cv.reference_poses(frames)))
    poses = [frames[i][1] for i in idx]
    muscles = [m for m in model.muscles if m["wraps"]]
    if args.muscles:
        want = args.muscles.split(",")
        muscles = [m for m in muscles if m["name"] in want]
    ref = None
    if args.cache and os.path.exists(args.cache):
        with open(args.cache) as f:
            ref = json.load(f)
        if ref.get("poses") != idx or ref.get("coordinates") != COORDINATES or \
                any(m["name"] not in ref["muscles"] for m in muscles):
            ref = None
    if ref is None:
        ref = {"poses": idx, "coordinates": COORDINATES,
               "muscles": reference(model, muscles, poses, methods)}
        if args.cache:
            with open(args.cache, "w") as f:
                json.dump(ref, f)
    base = ET.parse(args.model)
    parent_of = {c: pb for pb in base.getroot().iter("body") for c in pb}
    body_parents = {c.get("name"): pb.get("name") for c, pb in parent_of.items() if c.tag == "body"}
    model_dir = os.path.dirname(os.path.abspath(args.model))
    previous = {}
    if args.previous:
        with open(args.previous) as f:
            previous = json.load(f)["muscles"]
    results, surrogate_error = {}, {}
    base_probe = Probe(args.probe, args.model, poses)
    scan_probe = Probe(args.probe, args.model, [])  # the continuity scan's: no fitting poses
    worst = 0.0
    for mus in muscles:
        name = mus["name"]
        r = ref["muscles"][name]
        rows0 = base_probe.eval(name)
        e0 = errors(r, base_probe.joints, rows0)
        e0_max = float(np.max(np.abs(e0)))
        surrogate_error[name] = e0_max
        # a path site near a wrap surface (inside or out) makes the wrap hang on a rounding;
        # one deep inside is consistent (MuJoCo never wraps that segment)
        near = float(np.min(np.abs(rows0[:, -1])))
        if args.check and near < CLEAR_MIN - 1e-6:
            print("%-10s a path site %.1f mm from a wrap surface (at least %.0f mm wanted)" % (
                name, 1000 * near, 1000 * CLEAR_MIN))
            worst = max(worst, 1e3)
        tendon = [t for t in base.getroot().iter("spatial") if t.get("name") == name][0]
        slots = [k for k, el in enumerate(tendon) if el.get("geom")]
        print("%-10s %s: max |e| %.2f (objective %.3f), %d wrap geom(s)" % (
            name, "model" if args.check else "converter surrogate", e0_max,
            objective_of(e0), len(slots)), flush=True)
        if args.check:
            worst = max(worst, e0_max)
            continue
        if len(slots) != 1:
            continue
        flawed = False
        if e0_max <= args.keep:
            # the surrogate stays if it is also clear of its wrap and continuous; else it is
            # fitted like any other and replaced by a fit within --keep (glmax1's converter
            # surrogate had its path site 0.1 mm from the cylinder, and its length jumped
            # 3.1 mm in the continuity scan)
            jump = largest_jump(scan_probe, name, args.jump_lines)
            if near >= CLEAR_MIN - 1e-6 and jump <= JUMP_TOL:
                continue
            flawed = True
            print("%-10s the surrogate is within --keep but %s: fitted" % (
                name, "jumps %.2f mm" % (1000 * jump) if jump > JUMP_TOL else
                "has a path site %.1f mm from its wrap" % (1000 * near)), flush=True)
        slot = slots[0]
        best = fit_starts(args, base, model_dir, poses, name, slot, r,
                          starts_for(model, mus, tendon[slot].get("geom")))
        if best is not None and best[1] > TWO_WRAP_ABOVE:
            prev = tendon[slot - 1].get("site")
            site = [el for el in base.getroot().iter("site") if el.get("name") == prev][0]
            parent = parent_of[site]
            first_site = (parent.get("name"), [float(v) for v in site.get("pos").split()])
            after = tendon[slot + 1].get("site")
            last = parent_of[[el for el in base.getroot().iter("site")
                              if el.get("name") == after][0]].get("name")
            position = chain_position(body_parents, first_site[0], last)
            two = fit_starts(args, base, model_dir, poses, name, slot, r,
                             two_wrap_starts(model, mus, first_site, best[2], position))
            if two is not None and (two[1], two[0]) < (best[1], best[0]):
                best = two
        if best is not None and (best[1] < e0_max or (flawed and best[1] <= args.keep)):
            keep_fit(results, name, best, slot, e0_max)
            write_out(args, idx, trial, results)
    # second pass: a muscle still above the tolerance starts from the fit of a muscle that wraps
    # over the same OpenSim objects (the other head of a pair), as is and mirrored medio-laterally
    for mus in muscles:
        name = mus["name"]
        if args.check or name not in results or results[name]["max_error"] <= 1.0:
            continue
        objects = sorted(pw["object"] for pw in mus["wraps"])
        shared = [other for other in muscles if other["name"] != name and
                  other["name"] in results and
                  sorted(pw["object"] for pw in other["wraps"]) == objects]
        starts = [s for other in shared for s in shared_starts(other["name"],
                                                               results[other["name"]])]
        if not starts:
            continue
        slot = results[name]["slot"]
        best = fit_starts(args, base, model_dir, poses, name, slot, ref["muscles"][name], starts)
        if best is not None and best[1] < results[name]["max_error"]:
            keep_fit(results, name, best, slot, results[name]["converter_max_error"])
            write_out(args, idx, trial, results)
    # a muscle still above the tolerance keeps an earlier fit that is within it and continuous
    for mus in muscles:
        name = mus["name"]
        old = previous.get(name)
        now = results[name]["max_error"] if name in results else surrogate_error.get(name, 0.0)
        if args.check or old is None or old["max_error"] > 1.0 or now <= 1.0:
            continue
        emax, jump = measure_fit(args, base, model_dir, poses, name, old["slot"],
                                 ref["muscles"][name], old)
        print("%-10s previous fit: max |e| %.2f, largest step %.2f mm" % (
            name, emax, 1000 * jump))
        if emax <= 1.0 and jump <= JUMP_TOL:
            kept = dict(old, max_error=emax, kept_from=os.path.basename(args.previous))
            results[name] = kept
            write_out(args, idx, trial, results)
    base_probe.close()
    if args.check:
        print("%s: largest max |e| %.2f over %d muscles and %d poses (1 = the tolerance)" % (
            args.model, worst, len(muscles), len(idx)))
        scanned, bad = nan_scan(scan_probe, frames, muscles)
        print("%s: NaN scan: %d poses (one trial frame in %d, perturbed by %s rad, 1 %% of that "
              "in m), non-finite lengths or moment arms: %s" % (
                  args.model, scanned, NAN_EVERY, " / ".join("%g" % v for v in NAN_SCALES),
                  ", ".join("%s %d" % b for b in bad) or "none"))
        jumps = [(mus["name"], largest_jump(scan_probe, mus["name"], args.jump_lines))
                 for mus in muscles]
        scan_probe.close()
        jumped = ["%s %.2f mm" % (n, 1000 * j) for n, j in jumps if j > JUMP_TOL]
        print("%s: continuity scan: %d lines of %d poses (from one trial frame in %d, %g rad), "
              "largest length step %.3f mm; jumps above %.1f mm: %s" % (
                  args.model, len(args.jump_lines), JUMP_STEPS, NAN_EVERY, JUMP_SCALE,
                  1000 * max(j for _, j in jumps), 1000 * JUMP_TOL, ", ".join(jumped) or "none"))
        sys.exit(1 if worst > 1.0 or bad or jumped else 0)
    scan_probe.close()
    write_out(args, idx, trial, results)


def keep_fit(results, name, best, slot, converter_error):
    geom = best[2]
    geom["slot"] = slot
    geom["max_error"] = best[1]
    geom["converter_max_error"] = converter_error
    results[name] = geom
    print("  -> %s: max |e| %.2f (converter %.2f)" % (name, best[1], converter_error))


def shared_starts(other, fit):
    """Starts from muscle `other`'s fitted parts: as they are, and mirrored across the body
    frames' sagittal plane (z -> -z; a rotation (w, x, y, z) -> (w, -x, -y, z))."""
    def mirrored(part):
        q = dict(part)
        q["pos"] = [part["pos"][0], part["pos"][1], -part["pos"][2]]
        if part["kind"] == "geom":
            w, x, y, z = part["quat"]
            q["quat"] = [w, -x, -y, z]
            if part["side"] is not None:
                q["side"] = [part["side"][0], part["side"][1], -part["side"][2]]
        return q
    parts = [dict(p) for p in fit["parts"]]
    return [{"parts": parts, "from": "%s's fit" % other},
            {"parts": [mirrored(p) for p in parts], "from": "%s's fit mirrored" % other}]


def write_out(args, idx, trial, results):
    doc = {"generated_by": "scripts/fit_wraps.py (--every %d, --keep %g)" % (args.every, args.keep),
           "source": "OpenSim wrapped paths of %s (scripts/osim2mjcf.py wrapped_path) at %d "
                     "frames of %s" % (os.path.basename(args.osim), len(idx),
                                       os.path.basename(trial)),
           "tolerance": "length %g m; moment arm %g m or %g of |r_ref| about the coordinates: "
                        "%s" % (
               LENGTH_TOL, ARM_TOL, ARM_REL, COORDINATES),
           "frames": "body frames of the .osim (= the MJCF's bodies); quat w x y z",
           "muscles": results}
    with open(args.out, "w") as f:
        json.dump(doc, f, indent=1, sort_keys=True)
        f.write("\n")
    print("wrote %s (%d muscles)" % (args.out, len(results)))


if __name__ == "__main__":
    main()
