#!/usr/bin/python3
"""Issue 20's diagnostic figures of a main job's results (docs/BENCHMARKS.md, "Physiology").

usage: scripts/physiology_figures.py [RESULTS] [--gaitsim GAITSIM]

RESULTS (default results) is the folder `gaitsim run` writes. Prints:
  - for RESULTS/track: the mean and RMS difference, model minus measured, of the frontal-plane
    and trunk coordinates (states.sto against the trial's coordinates.mot, at the solution's
    nodes; deg, or m for pelvis_tz), and the two means: the hip-adduction bias behind the wide
    stance;
  - for each RESULTS/sweep/predict_*: the stride-mean metabolic power by muscle group
    (metabolics.sto, trapezoid over the nodes; W/kg, and J/(kg m) at the prediction's speed),
    and the mean lumbar_extension (deg), and what its muscles spend while slack: the stride-mean
    power of every muscle at the node intervals where its tendon force (muscle_forces.sto) is
    below 1 % of its Fmax, above Umberger's 1 W/kg floor (Fmax and mass from the `user` rows of
    the model summary.json names; W, and W/kg of body mass), the five largest by name, and the
    coordinates that leave the model's joint ranges (deg, or m for slides);
  - for the tracking solution and each prediction with a grf.mot: each knee's flexion in
    loading response, the most flexed over the first 20 % of the stride after its foot's
    contact (vertical ground force above 20 N; deg), and the leg muscles' metabolic energy
    split by phase as Umberger 2010 splits it (swing, double and single support; his 1.3 m/s
    gait: 0.29, 0.27, 0.44), metabolics.sto and grf.mot at the solution's nodes;
  - over three predictions or more, each group's power in Ralston's form a + b v^2 (least
    squares; W/kg, v in m/s): a, the cost per second whatever the speed, which makes the cost of
    transport fall with speed, and b; beside Ralston 1958's muscle share (his gross rate less the
    basal 1.2 W/kg that scripts/validation.py adds).
With --gaitsim (the built binary), also, for the tracking solution and each prediction: what the
trunk muscles (ercspn, intobl, extobl) carry about each lumbar coordinate at 20 instants of the
stride (`GAITSIM inspect MODEL --pose DIR/states.sto --time t`, MODEL from summary.json): their
summed power (W) and the mean over the instants of the net moment |sum F r| and of the summed
muscle moments sum |F r| (N m); the ratio of the two is the co-contraction the lumbar moments
cost; and the stride's mechanical work by source (`GAITSIM work MODEL --pose DIR/states.sto`):
the contractile elements' positive and negative work per metre, the foot contact's dissipation
and rebound per collision against Zelik & Kuo 2010's soft-tissue work, the contractile
positive work over the muscles' metabolic energy (metabolics.sto), and per leg the muscles'
work at hip_flexion, knee_flexion and ankle_angle in stance (`--joints`) with the knee's share
of the negative and the ankle's of the positive against Montgomery & Grabowski 2018's.
Muscle groups by name: trunk (ercspn, intobl, extobl), vasti, soleus, gastrocnemii, rectus
femoris, hamstrings, gluteals, iliopsoas, adductors, tibialis anterior, other. Exit 1 with one
line naming the file when an input is missing.
"""
import glob
import math
import os
import re
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import (ANKLE_POSITIVE_SHARE, KNEE_NEGATIVE_SHARE,  # noqa: E402
                          SOFT_TISSUE_COLLISION_J, SOFT_TISSUE_REBOUND_J, PrepError,
                          inspect_muscles, mechanical_work, read_json, read_storage,
                          results_and_gaitsim, stance_work)
from validation import BASAL_W_PER_KG, fit_ralston_form, ralston_gross_w_per_kg  # noqa: E402

COORDINATES = ["pelvis_tz", "pelvis_rx", "hip_adduction", "hip_adduction_l", "knee_adduction",
               "subtalar_angle", "subtalar_angle_l", "lumbar_extension", "lumbar_bending"]
GROUPS = [("trunk", "ercspn|intobl|extobl"), ("vasti", "vas"), ("soleus", "soleus"),
          ("gastrocnemii", "gas"), ("rectus femoris", "rect_fem|recfem"),
          ("hamstrings", "bf|semi"), ("gluteals", "glmax|glmed|glmin|glut"),
          ("iliopsoas", "psoas|iliacus"), ("adductors", "add|grac|pect"),
          ("tibialis anterior", "tibant|tib_ant"), ("other", "")]


def columns(path):
    _, labels, rows = read_storage(path)
    return {lab: [r[i] for r in rows] for i, lab in enumerate(labels)}


def interp(t, ts, ys):
    """Linear interpolation of (ts, ys) at t (ts increasing)."""
    for k in range(1, len(ts)):
        if t <= ts[k]:
            w = (t - ts[k - 1]) / (ts[k] - ts[k - 1])
            return ys[k - 1] + w * (ys[k] - ys[k - 1])
    return ys[-1]


def mean_over_time(t, y):
    """Trapezoid mean of y over t."""
    area = sum(0.5 * (y[k] + y[k - 1]) * (t[k] - t[k - 1]) for k in range(1, len(t)))
    return area / (t[-1] - t[0])


CONTACT_N = 20.0          # a foot is on the ground above this vertical ground force (N)
LOADING_RESPONSE = 0.2    # the stride fraction after contact searched for the knee's flexion (-)


def foot_loaded(grf, column, times):
    """Whether the foot carries more than CONTACT_N at each of times: grf's (columns of grf.mot)
    vertical force column, interpolated."""
    return [interp(t, grf["time"], grf[column]) > CONTACT_N for t in times]


def loading_response_knee(folder):
    """Each knee's largest flexion (deg, right and left) over the LOADING_RESPONSE of the
    stride after its foot's contact (the first node where grf.mot's vertical force exceeds
    CONTACT_N after one where it did not, the stride taken as periodic): the stance flexion
    JW's gait has (16-20 deg tracked) and a straight-legged stance lacks. knee_flexion is
    negative in flexion (gait2392). None without grf.mot, its columns or the knees'."""
    grf_path = os.path.join(folder, "grf.mot")
    if not os.path.exists(grf_path):
        return None
    q, g = columns(os.path.join(folder, "states.sto")), columns(grf_path)
    flexion = []
    for coord, force in (("knee_flexion", "ground_force_r_vy"),
                         ("knee_flexion_l", "ground_force_l_vy")):
        if coord not in q or force not in g:
            return None
        on = foot_loaded(g, force, q["time"])
        n = len(on)
        starts = [k for k in range(n) if on[k] and not on[k - 1]]
        if not starts:
            return None
        window = [(starts[0] + j) % n for j in range(max(1, round(LOADING_RESPONSE * n)))]
        flexion.append(-min(q[coord][k] for k in window))
    return flexion


def print_loading_response_knee(folder):
    knee = loading_response_knee(folder)
    if knee:
        print(f"  loading-response knee flexion (deg; the most flexed over the first "
              f"{100 * LOADING_RESPONSE:.0f} % of the stride after contact): right "
              f"{knee[0]:.1f}, left {knee[1]:.1f}")


SWING_SHARE_UMBERGER = 0.29   # leg swing's share of the muscles' cost at 1.3 m/s (-)
DOUBLE_SHARE_UMBERGER = 0.27  # double-limb support's share (-)
SINGLE_SHARE_UMBERGER = 0.44  # single-limb support's share (-)


def phase_costs(folder):
    """The leg muscles' metabolic energy over the stride split by gait phase as Umberger 2010
    (J R Soc Interface 7:1329) splits it: at each instant each leg's muscles count as swing
    while its foot is off the ground (vertical force at most CONTACT_N), as double support while
    both feet are on it, as single support while only theirs is. Trunk muscles are left out (his
    model had none). Returns the three shares (swing, double, single), or None without grf.mot or
    metabolics.sto."""
    grf_path, met_path = os.path.join(folder, "grf.mot"), os.path.join(folder, "metabolics.sto")
    if not os.path.exists(grf_path) or not os.path.exists(met_path):
        return None
    g, met = columns(grf_path), columns(met_path)
    trunk = re.compile(GROUPS[0][1])
    t = met["time"]
    power = {"": [0.0] * len(t), "_l": [0.0] * len(t)}
    for muscle, values in met.items():
        if muscle in ("time", "total") or trunk.search(muscle):
            continue
        leg = power["_l" if muscle.endswith("_l") else ""]
        for k, v in enumerate(values):
            leg[k] += v
    on = {side: foot_loaded(g, f"ground_force_{c}_vy", t) for side, c in (("", "r"), ("_l", "l"))}
    phase = {"swing": [0.0] * len(t), "double": [0.0] * len(t), "single": [0.0] * len(t)}
    for side, other in (("", "_l"), ("_l", "")):
        for k in range(len(t)):
            name = ("swing" if not on[side][k] else "double" if on[other][k] else "single")
            phase[name][k] += power[side][k]
    energy = {name: mean_over_time(t, y) for name, y in phase.items()}
    total = sum(energy.values())
    return tuple(energy[name] / total for name in ("swing", "double", "single"))


def print_phase_costs(folder):
    shares = phase_costs(folder)
    if shares:
        print(f"  leg muscles' cost by phase (Umberger 2010's split): swing {shares[0]:.2f}, "
              f"double support {shares[1]:.2f}, single support {shares[2]:.2f} (his 1.3 m/s "
              f"gait: {SWING_SHARE_UMBERGER}, {DOUBLE_SHARE_UMBERGER}, "
              f"{SINGLE_SHARE_UMBERGER})")


def tracking(track):
    s = read_json(os.path.join(track, "summary.json"))
    trial = s.get("trial")
    if not trial:
        raise PrepError(os.path.join(track, "summary.json"), "no trial")
    model = columns(os.path.join(track, "states.sto"))
    meas = columns(os.path.join(trial, "coordinates.mot"))
    print(f"{track}: at its {len(model['time'])} nodes, model minus measured (mean, RMS) and the "
          "model's and the measured mean")
    for c in COORDINATES:
        if c not in model or c not in meas:
            continue
        m = [interp(t, meas["time"], meas[c]) for t in model["time"]]
        d = [y - x for y, x in zip(model[c], m)]
        rms = (sum(x * x for x in d) / len(d)) ** 0.5
        print(f"  {c:18s} {sum(d) / len(d):+8.3f} {rms:8.3f}  {sum(model[c]) / len(d):+8.2f} "
              f"{sum(m) / len(m):+8.2f}")
    print_loading_response_knee(track)
    print_phase_costs(track)


def prediction(folder):
    s = read_json(os.path.join(folder, "summary.json"))
    mass = s["body_weight_n"] / 9.81 if s.get("body_weight_n") else None
    speed = s.get("speed_target_mps")
    if not mass or not speed:
        raise PrepError(os.path.join(folder, "summary.json"), "no body_weight_n or speed")
    met = columns(os.path.join(folder, "metabolics.sto"))
    power = {name: 0.0 for name, _ in GROUPS}
    for muscle, values in met.items():
        if muscle in ("time", "total"):
            continue
        group = next(name for name, pat in GROUPS if re.search(pat, muscle))
        power[group] += mean_over_time(met["time"], values) / mass
    total = mean_over_time(met["time"], met["total"]) / mass
    lumbar = columns(os.path.join(folder, "states.sto")).get("lumbar_extension")
    print(f"{folder}: {speed} m/s, muscles {total:.2f} W/kg ({total / speed:.2f} J/(kg m))"
          + (f", lumbar_extension mean {sum(lumbar) / len(lumbar):+.1f} deg" if lumbar else ""))
    for name, _ in GROUPS:
        print(f"  {name:18s} {power[name]:6.3f} W/kg  {power[name] / speed:6.3f} J/(kg m)  "
              f"{100 * power[name] / total:5.1f} %")
    if not s.get("model"):
        raise PrepError(os.path.join(folder, "summary.json"), "no model")
    slack_cost(s["model"], met, columns(os.path.join(folder, "muscle_forces.sto")), mass)
    outside = outside_ranges(s["model"], columns(os.path.join(folder, "states.sto")))
    print("  joint ranges (model): " + ("; ".join(outside) if outside else "all kept"))
    print_loading_response_knee(folder)
    print_phase_costs(folder)
    return speed, power, total


def model_root(model):
    """The MJCF file's root element; PrepError naming the file when it cannot be read."""
    try:
        return ET.parse(model).getroot()
    except OSError as e:
        raise PrepError(model, f"cannot read the model ({e.strerror})")
    except ET.ParseError as e:
        raise PrepError(model, f"not an MJCF file ({e})")


def joint_ranges(model):
    """{joint: (lo, hi)} of the model's limited hinge (deg) and slide (m) joints, from each
    <joint>'s own range (angles in radians when <compiler angle="radian">, else degrees, as MuJoCo
    reads them; limited="false" skipped; ranges set through default classes are not read)."""
    root = model_root(model)
    radian = any(c.get("angle") == "radian" for c in root.iter("compiler"))
    out = {}
    for j in root.iter("joint"):
        if not j.get("name") or not j.get("range") or j.get("limited") == "false":
            continue
        try:
            lo, hi = (float(x) for x in j.get("range").split())
        except ValueError:
            raise PrepError(model, f"joint {j.get('name')}: range is not two numbers")
        if j.get("type", "hinge") == "hinge" and radian:
            lo, hi = math.degrees(lo), math.degrees(hi)
        out[j.get("name")] = (lo, hi)
    return out


def outside_ranges(model, states):
    """The coordinates of states (states.sto columns: deg for hinges, m for slides) that leave
    the model's joint ranges, each as 'name extreme below|above bound'."""
    out = []
    for name, (lo, hi) in joint_ranges(model).items():
        values = states.get(name)
        if not values:
            continue
        if min(values) < lo - 1e-9:
            out.append(f"{name} {min(values):.2f} below {lo:.2f}")
        if max(values) > hi + 1e-9:
            out.append(f"{name} {max(values):.2f} above {hi:.2f}")
    return out


def speed_fit(rows):
    """Each group's power across the predictions rows = [(speed, power by group, total)] in
    Ralston's form a + b v^2, beside Ralston's muscle share."""
    v = [r[0] for r in rows]
    print(f"power by speed in Ralston's form a + b v^2 over {len(rows)} predictions (W/kg): "
          "a, b, and a / v at the slowest and fastest speed (J/(kg m))")
    fits = [(name, fit_ralston_form(v, [r[1][name] for r in rows])) for name, _ in GROUPS]
    fits.append(("muscles", fit_ralston_form(v, [r[2] for r in rows])))
    a_r = ralston_gross_w_per_kg(0.0) - BASAL_W_PER_KG
    b_r = ralston_gross_w_per_kg(1.0) - ralston_gross_w_per_kg(0.0)
    fits.append((f"Ralston less {BASAL_W_PER_KG}", (a_r, b_r)))
    for name, (a, b) in fits:
        print(f"  {name:18s} a {a:+6.3f}  b {b:+6.3f}  a/v {a / min(v):6.3f} .. {a / max(v):6.3f}")


SLACK_FORCE = 0.01      # a muscle is slack below this fraction of its Fmax (tendon force)
FLOOR_W_PER_KG = 1.0    # Umberger's minimum heat rate per kg of muscle (gs_metabolics.h)


def muscle_params(model):
    """{muscle: (Fmax N, mass kg)} from the MJCF `user` rows (gs_model_layout.h: 0 and 7)."""
    root = model_root(model)
    out = {}
    for m in root.iter("muscle"):
        try:
            u = [float(x) for x in m.get("user", "").split()]
        except ValueError:
            raise PrepError(model, f"muscle {m.get('name')}: a user value is not a number")
        if len(u) >= 8 and u[0] > 0:
            out[m.get("name")] = (u[0], u[7])
    return out


def slack_cost(model, met, force, mass):
    """Stride-mean power (W) of the muscles of `model` while slack, above the floor, from a
    prediction's metabolics.sto and muscle_forces.sto columns: total and by muscle."""
    prm = muscle_params(model)
    t = met["time"]
    by = {}
    for name, (fmax, mmass) in prm.items():
        if name not in met or name not in force:
            continue
        e, f = met[name], force[name]
        area = sum((0.5 * (e[k] + e[k - 1]) - FLOOR_W_PER_KG * mmass) * (t[k] - t[k - 1])
                   for k in range(1, len(t))
                   if 0.5 * (f[k] + f[k - 1]) < SLACK_FORCE * fmax)
        by[name] = max(area, 0.0) / (t[-1] - t[0])
    total = sum(by.values())
    top = sorted(by.items(), key=lambda x: -x[1])[:5]
    print(f"  slack muscles (tendon force < {100 * SLACK_FORCE:g} % Fmax), above the "
          f"{FLOOR_W_PER_KG:g} W/kg floor: {total:.1f} W ({total / mass:.3f} W/kg); "
          + ", ".join(f"{n} {w:.1f}" for n, w in top))


TRUNK = dict(GROUPS)["trunk"]
LUMBAR = ("lumbar_extension", "lumbar_bending", "lumbar_rotation")
TRUNK_INSTANTS = 20


def trunk_moments(gaitsim, folder):
    """The trunk muscles' power (W) and, per lumbar coordinate, the mean net and summed moments
    (N m) over TRUNK_INSTANTS instants of the stride, from `gaitsim inspect`'s rows
    (inspect_muscles)."""
    s = read_json(os.path.join(folder, "summary.json"))
    T, model = s.get("stride_time_s"), s.get("model")
    if not T or not model:
        raise PrepError(os.path.join(folder, "summary.json"), "no stride_time_s or model")
    power, net, summed = 0.0, {c: 0.0 for c in LUMBAR}, {c: 0.0 for c in LUMBAR}
    for k in range(TRUNK_INSTANTS):
        try:
            rows = inspect_muscles(gaitsim, model, os.path.join(folder, "states.sto"),
                                   round(T * k / TRUNK_INSTANTS, 6))
        except PrepError as e:
            raise PrepError(folder, f"gaitsim {e.reason}")
        m = {c: 0.0 for c in LUMBAR}
        for name, r in rows.items():
            if not re.search(TRUNK, name):
                continue
            power += r["Edot"] / TRUNK_INSTANTS
            for c, arm in r["arms"].items():
                if c in m:
                    m[c] += r["F"] * arm
                    summed[c] += abs(r["F"] * arm) / TRUNK_INSTANTS
        for c in LUMBAR:
            net[c] += abs(m[c]) / TRUNK_INSTANTS
    print(f"{folder}: trunk muscles {power:.1f} W; about each lumbar coordinate the mean net and "
          "summed muscle moments (N m)")
    for c in LUMBAR:
        print(f"  {c:18s} {net[c]:7.1f} {summed[c]:7.1f}")


def work_budget(gaitsim, folder):
    """The stride's mechanical work by source (`GAITSIM work`, mechanical_work): the contractile
    elements' positive and negative work per metre (J/(kg m)), the foot contact's negative and
    positive work per collision (half the stride's: two heel strikes; J), split into its normal
    forces (whose net is the Hunt-Crossley damping's loss) and friction, and the contractile
    positive work over the muscles' metabolic energy (metabolics.sto, when present); per leg, the
    muscles' stance work at hip, knee and ankle (stance_work) and the knee's and ankle's shares."""
    s = read_json(os.path.join(folder, "summary.json"))
    model = s.get("model")
    mass = s["body_weight_n"] / 9.81 if s.get("body_weight_n") else None
    if not model or not mass:
        raise PrepError(os.path.join(folder, "summary.json"), "no model or body_weight_n")
    try:
        rows, distance, joints = mechanical_work(gaitsim, model,
                                                 os.path.join(folder, "states.sto"))
    except PrepError as e:
        raise PrepError(folder, f"gaitsim {e.reason}")
    ce = rows["their contractile elements (active fibre force)"]
    foot = rows["foot contact spheres"]
    normal = rows["their normal forces (elastic and Hunt-Crossley damping)"]
    friction = rows["their friction"]
    line = (f"{folder}: mechanical work over {distance:.3f} m: contractile elements "
            f"+{ce[0] / mass / distance:.3f} / {ce[1] / mass / distance:.3f} J/(kg m); foot "
            f"contact per collision (half the stride's) {foot[1] / 2:.1f} / +{foot[0] / 2:.1f} "
            f"J, its normal forces {normal[1] / 2:.1f} / +{normal[0] / 2:.1f} J (net "
            f"{normal[2] / 2:.1f}: damping), friction {friction[2] / 2:.1f} J (Zelik & Kuo 2010 "
            f"at 1.25 m/s, soft tissue: -{SOFT_TISSUE_COLLISION_J} / +{SOFT_TISSUE_REBOUND_J} J)")
    met_path = os.path.join(folder, "metabolics.sto")
    if os.path.exists(met_path):
        met = columns(met_path)
        energy = mean_over_time(met["time"], met["total"]) * (met["time"][-1] - met["time"][0])
        line += f"; contractile positive work / muscles' metabolic energy {ce[0] / energy:.3f}"
    print(line)
    for side, suffix in (("right", ""), ("left", "_l")):
        leg = stance_work(joints, suffix)
        if leg is None:
            continue
        neg, pos, knee, ankle = leg
        print(f"  {side} leg in stance, the muscles' work at hip / knee / ankle (J): negative "
              + " / ".join(f"{x:.1f}" for x in neg) + ", positive "
              + " / ".join(f"{x:.1f}" for x in pos)
              + f"; the knee's share of the negative {knee:.2f}, the ankle's of the "
              f"positive {ankle:.2f} (Montgomery & Grabowski 2018: "
              f"{KNEE_NEGATIVE_SHARE} and {ANKLE_POSITIVE_SHARE})")


def main(argv):
    parsed = results_and_gaitsim(argv, "physiology_figures", __doc__)
    if isinstance(parsed, int):
        return parsed
    results, gaitsim = parsed
    try:
        tracking(os.path.join(results, "track"))
        predictions = sorted(glob.glob(os.path.join(results, "sweep", "predict_*")))
        rows = [prediction(folder) for folder in predictions]
        if len(rows) >= 3:
            speed_fit(rows)
        if gaitsim:
            for folder in [os.path.join(results, "track")] + predictions:
                trunk_moments(gaitsim, folder)
            for folder in [os.path.join(results, "track")] + predictions:
                work_budget(gaitsim, folder)
    except PrepError as e:
        print(f"physiology_figures: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
