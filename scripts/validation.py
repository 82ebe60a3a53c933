#!/usr/bin/python3
"""docs/VALIDATION.md from a main job's results: the project's figures against measurement.

usage: scripts/validation.py [RESULTS] [--gaitsim GAITSIM] > docs/VALIDATION.md

RESULTS (default results) is the folder `gaitsim run` writes: RESULTS/track (the tracking solve of
mjmodels/trials/jw_ngait_og5) and the predictions RESULTS/sweep/predict_* (or RESULTS/predict_*).
Every figure is read from the solution files (summary.json, grf.mot, controls.sto) and set
beside its reference: the paper's Table 1 for participant 2 (JW) and its predicted and measured
stride times (Lin, Walter & Pandy 2018, Ann Biomed Eng 46:1216), the in-vivo knee contact force of
the instrumented implant (eTibia; Fregly et al. 2012, J Orthop Res 30:503) as each trial folder
holds it (knee_contact.sto), the measured centres of pressure of the trial (grf.mot), and
Ralston's energy-speed relation for level walking (Ralston 1958, Int Z Angew Physiol 17:277:
gross metabolic rate 29 + 0.0053 v^2 cal/(kg min), v in m/min). The targets are those of the
project's issues (#19 resolution, #20 physiology). With --gaitsim (the built binary), also the
mechanical work of the tracking solution and of each prediction (`GAITSIM work MODEL --pose
DIR/states.sto --joints`, MODEL from summary.json) against published human figures: the foot
contact's negative and positive work per collision against the soft tissues' (Zelik & Kuo 2010,
J Exp Biol 213:4257), the knee's share of each leg's sagittal negative work in stance and the
ankle's of the positive (Montgomery & Grabowski 2018, R Soc Open Sci 5:180550); and the
tracking solution's net joint moments against the measured gait's, both by inverse dynamics
(`GAITSIM moments MODEL --pose P --grf G --out F`: the trial's coordinates.mot and plates, the
solution's states.sto and grf.mot). Exit 1 with one line naming the file when an input is
missing.
"""
import glob
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import (ANKLE_POSITIVE_SHARE, KNEE_NEGATIVE_SHARE,  # noqa: E402
                          SOFT_TISSUE_COLLISION_J, SOFT_TISSUE_REBOUND_J, PrepError,
                          inverse_dynamics_moments, inverse_dynamics_work, mechanical_work, read_json, read_storage,
                          results_and_gaitsim, stance_work)
from report import PAPER_MEASURED_STRIDE_TIME, PAPER_STRIDE_TIME, TABLE1  # noqa: E402

CAL = 4.184             # J per cal
BASAL_W_PER_KG = 1.2    # basal rate added to the model's muscle power for its gross cost (W/kg)
MUSCLE_EFFICIENCY = 0.25  # positive work / metabolic energy of human muscle (Margaria 1968) (-)
# speed (m/s): the paper's (predicted, measured mean) stride time (s), from the report's lists
PAPER_STRIDE = {v: (t, dict(PAPER_MEASURED_STRIDE_TIME)[v]) for v, t in PAPER_STRIDE_TIME}
KNEE_PEAK_LIMIT = {0.8: 2.8, 2.0: 3.5}                 # issue #20 item 5 (BW)
SWEEP_SPEEDS = (0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0)     # issue #20 item 4's sweep (m/s)
# the statuses optim/go_solve.c's solve_converged counts as converged (go_solve_status_str's
# texts): for summary.json files written before it carried its own "converged" flag
CONVERGED_STATUSES = ("optimal solution found", "solved to acceptable level", "objective settled")


def converged(summary):
    """Whether the solve met the project's stopping rule (summary.json's converged flag)."""
    if "converged" in summary:
        return bool(summary["converged"])
    return summary.get("status") in CONVERGED_STATUSES


def ralston_gross_w_per_kg(v):
    """Ralston 1958: gross metabolic rate of level walking at v (m/s), W/kg."""
    vm = 60.0 * v
    return (29.0 + 0.0053 * vm * vm) * CAL / 60.0


def stance_cop_z(path):
    """Force-weighted mean mediolateral centre of pressure (m) of each foot over its stance
    (vertical force > 20 N): where each foot stands, from grf.mot."""
    _, labels, rows = read_storage(path)
    out = {}
    for side in "rl":
        try:
            fy = labels.index(f"ground_force_{side}_vy")
            pz = labels.index(f"ground_force_{side}_pz")
        except ValueError:
            raise PrepError(path, f"no ground_force_{side}_vy / _pz columns")
        w = [(r[fy], r[pz]) for r in rows if r[fy] > 20.0]
        if not w:
            raise PrepError(path, f"foot {side}: never loaded above 20 N")
        out[side] = sum(f * z for f, z in w) / sum(f for f, _ in w)
    return out


def fmt(v, digits=2):
    missing = v is None or (isinstance(v, float) and not math.isfinite(v))
    return "-" if missing else f"{v:.{digits}f}"


def row(cells):
    print("| " + " | ".join(cells) + " |")


def tracking(track):
    s = read_json(os.path.join(track, "summary.json"))
    rms = s.get("rms", {})
    trial = s.get("trial", "")
    print(f"## Tracking: {os.path.basename(os.path.normpath(trial)) if trial else '-'}, "
          f"{s.get('nodes')} nodes ({s.get('status')})\n")
    print("Model RMS errors over the stride against the trial; the paper's Table 1 for the same "
          "participant (JW) beside them. Target (#20 item 6): every Table 1 figure met or beaten "
          "while knee contact stays <= 0.30 BW.\n")
    row(["figure", "model", "paper (Table 1, participant 2)", "met"])
    row(["---"] * 4)
    for key, quantity, unit, paper in TABLE1:
        if paper == "-":
            continue
        v, ref = rms.get(key), float(paper)
        row([f"{quantity} ({unit})", fmt(v, 3), fmt(ref), "yes" if v is not None and v <= ref
             else "no"])
    print()
    print("What holds a missed figure (docs/BENCHMARKS.md, \"The effort's weight against Table 1 "
          "(item 6)\" and \"The knee's frontal moment, piece by piece\"): the goals' weights. "
          "A lower effort weight or a higher joint or GRF weight improves the tracking figures "
          "and raises the knee contact, through co-contraction; no weight measured meets Table 1 "
          "with the knee contact at or below 0.30 BW, and the defaults keep the best knee "
          "contact.\n")
    print("Knee contact against the implant's in-vivo measurement (eTibia, the trial's "
          "knee_contact.sto). Targets (#20 item 3): medial and lateral RMS each <= 0.30 BW, total "
          "<= 0.25 BW.\n")
    row(["compartment", "RMS error (BW)", "target (BW)", "met"])
    row(["---"] * 4)
    for key, label, tgt in (("knee_contact_bw", "total", 0.25), ("knee_medial_bw", "medial", 0.30),
                            ("knee_lateral_bw", "lateral", 0.30)):
        v = rms.get(key)
        row([label, fmt(v, 3), fmt(tgt), "yes" if v is not None and v <= tgt else "no"])
    print()
    if trial and os.path.isfile(os.path.join(trial, "grf.mot")):
        m = stance_cop_z(os.path.join(trial, "grf.mot"))
        p = stance_cop_z(os.path.join(track, "grf.mot"))
        wm, wp = 100 * (m["r"] - m["l"]), 100 * (p["r"] - p["l"])
        print("Stance width: the mediolateral distance between the feet, each foot's "
              "force-weighted mean centre of pressure over its stance (grf.mot). Target (#20 "
              "item 2): within 3 cm of the measured one.\n")
        row(["", "model", "measured", "difference", "met"])
        row(["---"] * 5)
        row(["stance width (cm)", fmt(wp, 1), fmt(wm, 1), f"{wp - wm:+.1f}",
             "yes" if abs(wp - wm) <= 3 else "no"])
        print()


def fit_ralston_form(v, power):
    """(a, b) of power = a + b v^2 by least squares (W/kg, v in m/s)."""
    n, x = len(v), [x * x for x in v]
    sx, sy = sum(x), sum(power)
    sxx, sxy = sum(t * t for t in x), sum(t * y for t, y in zip(x, power))
    b = (n * sxy - sx * sy) / (n * sxx - sx * sx)
    return (sy - b * sx) / n, b


def cost_across_speeds(sums):
    """Issue #20 item 4's checks on the predictions' metabolic cost across speeds."""
    pts = [(s["speed_target_mps"], s["cost_of_transport_j_per_kg_m"]) for s in sums
           if s.get("speed_target_mps") and s.get("cost_of_transport_j_per_kg_m") is not None]
    if len(pts) < 2:
        return
    v = [p[0] for p in pts]
    net = [p[0] * p[1] for p in pts]
    gross_cot = [(n + BASAL_W_PER_KG) / x for n, x in zip(net, v)]
    ral_cot = [ralston_gross_w_per_kg(x) / x for x in v]
    by = {round(x, 1): c for x, c in pts}
    # the checks hold for the speeds shown; say so when the sweep is incomplete or unsettled
    missing = [x for x in SWEEP_SPEEDS if x not in by]
    short = [f"{fmt(s['speed_target_mps'], 1)} ({s.get('status')})" for s in sums
             if s.get("speed_target_mps") and not converged(s)]
    caveat = " (provisional)" if missing or short else ""
    kmin = min(range(len(v)), key=lambda k: gross_cot[k])
    kral = min(range(len(v)), key=lambda k: ral_cot[k])
    print("Cost across speeds (#20 item 4): gross cost of transport = (net power + basal "
          f"{BASAL_W_PER_KG} W/kg) / speed, beside Ralston 1958's.\n")
    row(["check", "model", "target", "met"])
    row(["---"] * 4)
    rises = all(b > a for a, b in zip(net, net[1:]))
    row(["net power by speed (W/kg)", ", ".join(f"{fmt(x, 1)}: {fmt(n)}" for x, n in zip(v, net)),
         "rises at every step", ("yes" if rises else "no") + caveat])
    if 1.2 in by and 2.0 in by:
        row(["net CoT 2.0 against 1.2 m/s (J/(kg m))", f"{fmt(by[2.0])} against {fmt(by[1.2])}",
             "2.0 higher", ("yes" if by[2.0] > by[1.2] else "no") + caveat])
    # U-shaped: falling at every step down to the minimum, rising at every step after it
    breaks = [f"{fmt(v[k + 1], 1)} above {fmt(v[k], 1)}" for k in range(kmin)
              if gross_cot[k + 1] >= gross_cot[k]] + \
             [f"{fmt(v[k + 1], 1)} below {fmt(v[k], 1)}" for k in range(kmin, len(v) - 1)
              if gross_cot[k + 1] <= gross_cot[k]]
    u_shape = 0 < kmin < len(v) - 1 and 1.0 <= v[kmin] <= 1.6 and not breaks
    not_u = f"; not U-shaped: {', '.join(breaks)}" if breaks else ""
    row(["gross CoT by speed (J/(kg m)); Ralston's",
         ", ".join(f"{fmt(x, 1)}: {fmt(g)}" for x, g in zip(v, gross_cot)) +
         "; " + ", ".join(f"{fmt(x, 1)}: {fmt(r)}" for x, r in zip(v, ral_cot)),
         "U-shaped, minimum at 1.0-1.6 m/s",
         ("yes" if u_shape else "no") + caveat + f" (model's minimum at {fmt(v[kmin], 1)} m/s, "
         f"Ralston's at {fmt(v[kral], 1)}{not_u})"])
    eff = [(s["speed_target_mps"], s["muscle_efficiency"]) for s in sums
           if s.get("speed_target_mps") and s.get("muscle_efficiency") is not None]
    if eff:
        row(["muscles' positive work over their metabolic energy (summary.json muscle_efficiency)",
             ", ".join(f"{fmt(x, 1)}: {fmt(e)}" for x, e in eff),
             f"about {MUSCLE_EFFICIENCY} (human muscle, Margaria 1968; a reference, not a target)",
             "-"])
    print()
    if caveat:
        parts = []
        if missing:
            parts.append(f"not solved: {', '.join(fmt(x, 1) for x in missing)} m/s, so the "
                         "checks hold for the speeds shown only")
        if short:
            parts.append("stopped short of convergence (best iterates, not minima: their costs "
                         f"may still fall): {', '.join(short)}")
        print("Provisional: " + "; ".join(parts) + ".\n")
    if len(v) >= 3:
        a, b = fit_ralston_form(v, [n + BASAL_W_PER_KG for n in net])
        a_r, b_r = ralston_gross_w_per_kg(0.0), ralston_gross_w_per_kg(1.0) - \
            ralston_gross_w_per_kg(0.0)
        print(f"The model's gross power in Ralston's form, least squares over {len(v)} speeds: "
              f"{a:.2f} + {b:.2f} v^2 W/kg (v in m/s), Ralston's {a_r:.2f} + {b_r:.2f} v^2: the "
              "first term is the cost per second whatever the speed, the second the cost that "
              "grows with speed. On the fitted curve the gross cost of transport a / v + b v is "
              + (f"lowest at sqrt(a / b) = {math.sqrt(a / b):.2f} m/s" if a > 0 and b > 0 else
                 "not U-shaped") + f", Ralston's at {math.sqrt(a_r / b_r):.2f} m/s.\n")


def predictions(folders):
    sums = []
    for f in folders:
        s = read_json(os.path.join(f, "summary.json"))
        if s.get("problem") == "prediction":
            sums.append(s)
    if not sums:
        return
    sums.sort(key=lambda s: s.get("speed_target_mps", 0))
    print("## Predictions: minimum cost of transport, free stride time\n")
    print("Stride time against the paper's predicted and JW's measured means (target, #20 item 4: "
          "within 5 % of the measured). Net cost: the model's muscles (smooth Umberger 2010); "
          f"gross: plus a basal {BASAL_W_PER_KG} W/kg, against Ralston 1958's gross rate "
          "(target: within 25 %). Peak knee contact of either knee (targets, #20 item 5: <= 2.8 BW "
          "at 0.8 m/s, <= 3.5 BW at 2.0 m/s).\n")
    row(["speed (m/s)", "nodes, status", "stride (s)", "paper predicted / measured (s)",
         "net CoT (J/(kg m))", "net power (W/kg)", "gross power (W/kg)", "Ralston gross (W/kg)",
         "gross within 25 %", "peak knee contact r / l (BW)", "knee within limit"])
    row(["---"] * 11)
    for s in sums:
        v = s.get("speed_target_mps")
        T = s.get("stride_time_s")
        ref = PAPER_STRIDE.get(round(v, 1) if v else None)
        cot = s.get("cost_of_transport_j_per_kg_m")
        net = cot * v if cot is not None and v else None
        gross = net + BASAL_W_PER_KG if net is not None else None
        ral = ralston_gross_w_per_kg(v) if v else None
        kr, kl = s.get("peak_knee_contact_r_bw"), s.get("peak_knee_contact_l_bw")
        lim = KNEE_PEAK_LIMIT.get(round(v, 1) if v else None)
        row([fmt(v, 1), f"{s.get('nodes')}, {s.get('status')}",
             fmt(T, 3) + (f" ({100 * (T / ref[1] - 1):+.1f} % of measured)" if ref and T else ""),
             f"{ref[0]:.2f} / {ref[1]:.2f}" if ref else "-", fmt(cot), fmt(net), fmt(gross),
             fmt(ral),
             "yes" if gross is not None and abs(gross / ral - 1) <= 0.25 else "no",
             f"{fmt(kr)} / {fmt(kl)}",
             "-" if lim is None else ("yes" if max(kr, kl) <= lim else "no")])
    print()
    cost_across_speeds(sums)
    by = {round(s.get("speed_target_mps", 0), 1): s for s in sums}
    if 0.8 in by and 2.0 in by:
        pe0, pe1 = by[0.8].get("peak_excitation", {}), by[2.0].get("peak_excitation", {})
        parts = []
        for m in ("soleus", "gasmed", "gaslat"):
            if pe0.get(m) and pe1.get(m):
                parts.append(f"{m} {pe1[m] / pe0[m]:.2f}")
        print("Fast/slow peak excitation ratio (2.0 against 0.8 m/s, right leg): "
              f"{', '.join(parts) or '-'} (paper: about 2.5 for soleus and gastrocnemius).\n")


def share_cells(joints):
    """The two share cells of a mechanical-work row: the knee's of the stance negative work and
    the ankle's of the positive, right / left ("-" for a leg without the coordinates)."""
    legs = [stance_work(joints, suffix) for suffix in ("", "_l")]
    return [" / ".join("-" if leg is None else f"{leg[k]:.2f}" for leg in legs) for k in (2, 3)]


def mechanical(gaitsim, folders):
    """The mechanical work section: the measured gait's net joint work by inverse dynamics
    (`gaitsim work MODEL --pose TRIAL/coordinates.mot --grf TRIAL/grf.mot`, the track's trial),
    then per solution folder (the track first) `gaitsim work`'s foot contact per collision (half
    the stride's) and each leg's stance shares (stance_work)."""
    print("## Mechanical work against published human data\n")
    print("From `gaitsim work MODEL --pose DIR/states.sto --joints` (docs/BENCHMARKS.md, \"Where "
          "the mechanical energy goes\"): the foot contact spheres' negative and positive work "
          "per collision (half the stride's; the model's stand-in for the heel pad and soft "
          f"tissues: Zelik & Kuo 2010 measured {SOFT_TISSUE_COLLISION_J} J of soft-tissue "
          f"negative work per collision and {SOFT_TISSUE_REBOUND_J} J of rebound at 1.25 m/s), "
          "and per leg the knee's share of the muscles' negative work at hip_flexion, "
          "knee_flexion and ankle_angle in stance and the ankle's of the positive (Montgomery & "
          f"Grabowski 2018: {KNEE_NEGATIVE_SHARE} and {ANKLE_POSITIVE_SHARE}); the first row "
          "is the trial JW walked, by inverse dynamics of its coordinates and plates (`gaitsim "
          "work MODEL --pose TRIAL/coordinates.mot --grf TRIAL/grf.mot`).\n")
    row(["solution", "foot contact per collision: negative / positive (J)",
         "knee's share of stance negative work r / l", "ankle's share of stance positive work "
         "r / l"])
    row(["---"] * 4)
    track = read_json(os.path.join(folders[0], "summary.json"))
    trial = track.get("trial")
    if trial and track.get("model"):
        # JW's own gait: the net joint work of inverse dynamics of the trial he walked
        try:
            joints = inverse_dynamics_work(gaitsim, track["model"],
                                           os.path.join(trial, "coordinates.mot"),
                                           os.path.join(trial, "grf.mot"))
        except PrepError as e:
            raise PrepError(trial, f"gaitsim {e.reason}")
        row(["measured (the trial, inverse dynamics: net joint work)", "-"] + share_cells(joints))
    for folder in folders:
        path = os.path.join(folder, "summary.json")
        s = read_json(path)
        if not s.get("model"):
            raise PrepError(path, "no model")
        try:
            rows, _, joints = mechanical_work(gaitsim, s["model"],
                                              os.path.join(folder, "states.sto"))
        except PrepError as e:
            raise PrepError(folder, f"gaitsim {e.reason}")
        foot = rows["foot contact spheres"]
        name = ("tracking" if s.get("problem") == "tracking"
                else f"prediction {fmt(s.get('speed_target_mps'), 1)} m/s")
        row([name, f"{foot[1] / 2:.1f} / {foot[0] / 2:.1f}"] + share_cells(joints))
    print()


# the coordinates of the joint-moment table, with the OpenSim ID column each carries
MOMENT_COORDINATES = ("hip_flexion", "hip_adduction", "hip_rotation", "knee_flexion",
                      "knee_adduction", "ankle_angle", "subtalar_angle", "hip_flexion_l",
                      "hip_adduction_l", "hip_rotation_l", "knee_flexion_l", "ankle_angle_l",
                      "subtalar_angle_l", "lumbar_extension", "lumbar_bending", "lumbar_rotation")


def interp(x, xs, ys):
    """ys at x by linear interpolation in the increasing xs, clamped at the ends."""
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    lo, hi = 0, len(xs) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if xs[mid] <= x else (lo, mid)
    w = (x - xs[lo]) / (xs[hi] - xs[lo])
    return ys[lo] + w * (ys[hi] - ys[lo])


def joint_moments(gaitsim, track):
    """The joint-moment section: the tracking solution's net joint moments against the measured
    gait's, both by inverse dynamics with one command (`gaitsim moments MODEL --pose P --grf G`,
    app/cmd_moments.c): the trial's coordinates.mot under its plates, the solution's states.sto
    under its own grf.mot; the measured curve interpolated at the solution's node times."""
    s = read_json(os.path.join(track, "summary.json"))
    trial, model = s.get("trial"), s.get("model")
    if not trial or not model:
        raise PrepError(os.path.join(track, "summary.json"), "no trial or model")
    try:
        tm, meas = inverse_dynamics_moments(gaitsim, model, os.path.join(trial, "coordinates.mot"),
                                            os.path.join(trial, "grf.mot"))
        ts, sol = inverse_dynamics_moments(gaitsim, model, os.path.join(track, "states.sto"),
                                           os.path.join(track, "grf.mot"))
    except PrepError as e:
        raise PrepError(track, f"gaitsim {e.reason}")
    print("## Joint moments against the measured gait\n")
    print("The tracking solution's net joint moments (what its muscles and passive structures "
          "supply) against those of the gait JW walked, both by inverse dynamics with one command "
          "(`gaitsim moments MODEL --pose TRIAL/coordinates.mot --grf TRIAL/grf.mot --out F`, and "
          "`--pose track/states.sto --grf track/grf.mot` for the solution), so the model and the "
          "method are the same on both sides. Not a target of the issues: a check on where the "
          "solution's muscles work differently from JW's. A moment is positive in its "
          "coordinate's positive direction (hip flexion, adduction and internal rotation, knee "
          "extension, ankle dorsiflexion).\n")
    row(["coordinate", "RMS difference (N m)", "measured range (N m)", "solution range (N m)",
         "measured mean / solution mean (N m)"])
    row(["---"] * 5)
    for c in MOMENT_COORDINATES:
        col = c + "_moment"
        if col not in meas or col not in sol:
            continue
        m = [interp(t, tm, meas[col]) for t in ts]
        v = sol[col]
        rms = math.sqrt(sum((a - b) ** 2 for a, b in zip(v, m)) / len(v))
        row([c, f"{rms:.1f}", f"{min(m):.1f} ... {max(m):.1f}", f"{min(v):.1f} ... {max(v):.1f}",
             f"{sum(m) / len(m):.1f} / {sum(v) / len(v):.1f}"])
    res = []
    for moments in (meas, sol):
        f = [math.sqrt(sum(moments[f"pelvis_t{a}_force"][i] ** 2 for a in "xyz"))
             for i in range(len(moments["pelvis_tx_force"]))]
        res.append(math.sqrt(sum(x * x for x in f) / len(f)))
    print(f"\nPelvis residual force, RMS: measured gait {res[0]:.1f} N (the plates' and the "
          f"markers' disagreement with the model's masses), solution {res[1]:.1f} N (its "
          "accelerations by central differences of the nodes' speeds; its dynamics hold at the "
          "nodes).\n")


def main(argv):
    parsed = results_and_gaitsim(argv, "validation", __doc__)
    if isinstance(parsed, int):
        return parsed
    results, gaitsim = parsed
    try:
        preds = sorted(glob.glob(os.path.join(results, "sweep", "predict_*")) +
                       glob.glob(os.path.join(results, "predict_*")))
        speeds = sorted(os.path.basename(p)[len("predict_"):] for p in preds)
        print("# Validation: the model's figures against measurement\n")
        option = f" --gaitsim {gaitsim}" if gaitsim else ""
        print(f"Generated by `scripts/validation.py {results}{option} > docs/VALIDATION.md` from "
              "the "
              "solutions of `gaitsim run` (`scripts/setup.sh && build/gaitsim run`, which writes "
              f"{results}/track and the predictions at 0.8 and 2.0 m/s)"
              + ("" if set(speeds) <= {"0.8", "2"} else
                 f", with the other speeds ({', '.join(s for s in speeds if s not in ('0.8', '2'))}"
                 f" m/s) by `build/gaitsim predict --guess {results}/track --speed V --threads 1 --out "
                 f"{results}/sweep/predict_V` (each bitwise the speed of `gaitsim sweep`)")
              + ". Regenerate them to check.\n")
        tracking(os.path.join(results, "track"))
        predictions(preds)
        if gaitsim:
            mechanical(gaitsim, [os.path.join(results, "track")] + sorted(
                preds, key=lambda p: read_json(os.path.join(p, "summary.json"))
                .get("speed_target_mps", 0)))
            joint_moments(gaitsim, os.path.join(results, "track"))
        print("## References\n")
        print("- Lin Y-C, Walter JP, Pandy MG (2018). Predictive simulations of neuromuscular "
              "coordination and joint-contact loading in human gait. Ann Biomed Eng 46:1216: "
              "Table 1 (participant 2 is JW), predicted strides 1.30 / 0.92 s, measured means 1.45 "
              "/ 0.93 s.")
        print("- Fregly BJ et al. (2012). Grand challenge competition to predict in vivo knee "
              "loads. J Orthop Res 30:503-513: JW's instrumented tibial implant (eTibia), the "
              "trial's knee_contact.sto.")
        print("- Ralston HJ (1958). Energy-speed relation and optimal speed during level walking. "
              "Int Z Angew Physiol 17:277-283: gross metabolic rate 29 + 0.0053 v^2 cal/(kg min), "
              f"v in m/min; the model's gross rate adds a basal {BASAL_W_PER_KG} W/kg to its "
              "muscles' (Umberger 2010).")
        print("- Umberger BR (2010). Stance and swing phase costs in human walking. J R Soc "
              "Interface 7:1329-1340: the model's muscle energy rates.")
        if gaitsim:
            print("- Zelik KE, Kuo AD (2010). Human walking isn't all hard work: evidence of soft "
                  "tissue contributions to energy dissipation and return. J Exp Biol "
                  "213:4257-4264: at 1.25 m/s about 7.5 J of soft-tissue negative work per "
                  "collision, 4 J of rebound after it.")
            print("- Montgomery JR, Grabowski AM (2018). The contributions of ankle, knee and hip "
                  "joint work to individual leg work change during uphill and downhill walking "
                  "over a range of speeds. R Soc Open Sci 5:180550: the knee's share of the "
                  "leg's stance negative work 0.39 at 1.00 m/s, 0.45 at 1.50 m/s; the ankle's of "
                  "the positive 0.42.")
        print("- Margaria R (1968). Positive and negative work performances and their efficiencies "
              "in human locomotion. Int Z Angew Physiol 25:339-351: muscle's efficiency in "
              f"positive work about {MUSCLE_EFFICIENCY}.\n")
    except PrepError as e:
        print(f"validation: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
