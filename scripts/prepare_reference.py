#!/usr/bin/python3
"""Derive gaitsim's healthy-walking reference (EMG timing, joint angles, GRF) from Falisse et al. 2019.

Reads --source (default /work/shared/data/healthy_reference): EMG_mean_std.csv, Qs_mean_std.csv,
GRFs_mean_std.csv, spatiotemporal.csv (antoinefalisse/3dpredictsim, MIT; subject1, right leg,
11 overground trials, 100 points per gait cycle from right heel strike, 0..99 %).
Writes into --out (default mjmodels/reference):

  healthy_emg.csv         long format, one row per channel and % cycle: channel, gait2392 muscles
                          (';'-separated base names, right leg), mean, std as stored, and mean/std
                          divided by the channel's peak mean (for timing comparisons)
  healthy_kinematics.csv  mean and SD joint angles (deg) / pelvis translations (m), columns renamed
                          to the JW model's coordinate names
  healthy_grf.csv         mean and SD right-foot GRF in body weights (source: % body weight)

Every file starts with '#' provenance lines. Writes are atomic. Errors: one line
'prepare_reference: FILE: reason' on stderr, exit status 1.
"""

import argparse
import datetime
import os
import sys

import numpy as np

from gs_scriptlib import PrepError, write_atomic

SCRIPT = "scripts/prepare_reference.py"
SOURCE = "antoinefalisse/3dpredictsim ExperimentalData/ExperimentalData.mat (MIT), subject1, Falisse et al. 2019"
LICENCE = "MIT (antoinefalisse/3dpredictsim)"

# EMG channel -> gait2392 muscle base names (right leg; JW model: unsuffixed right, _l left)
EMG_MAP = {
    "Soleus": ["soleus"],
    "Gastrocnemius-medialis": ["med_gas"],
    "Gastrocnemius-lateralis": ["lat_gas"],
    "Tibialis-anterior": ["tib_ant"],
    "Peroneus-longus": ["per_long"],
    "Peroneus-brevis": ["per_brev"],
    "Vastus-lateralis": ["vas_lat"],
    "Vastus-medialis": ["vas_med"],
    "Rectus-femoris": ["rect_fem"],
    "Hamstrings-medialis": ["semimem", "semiten"],
    "Hamstrings-lateralis": ["bifemlh"],
    "Gluteus-medialis": ["glut_med1", "glut_med2", "glut_med3"],
    "Adductor-longus": ["add_long"],
    "Tensor-fasciae-latae": ["tfl"],
}
# Falisse subject1 coordinate -> JW model coordinate name
Q_MAP = {
    "pelvis_tilt": "pelvis_rz", "pelvis_list": "pelvis_rx", "pelvis_rotation": "pelvis_ry",
    "pelvis_tx": "pelvis_tx", "pelvis_ty": "pelvis_ty", "pelvis_tz": "pelvis_tz",
    "hip_flexion": "hip_flexion", "hip_adduction": "hip_adduction", "hip_rotation": "hip_rotation",
    "knee_angle": "knee_flexion", "ankle_angle": "ankle_angle", "subtalar_angle": "subtalar_angle",
    "lumbar_extension": "lumbar_extension", "lumbar_bending": "lumbar_bending",
    "lumbar_rotation": "lumbar_rotation", "arm_flex": "arm_flex_r", "arm_add": "arm_add_r",
    "arm_rot": "arm_rot_r", "elbow_flex": "elbow_flex_r",
}
GRF_MAP = {"Fore-aft": "vx", "Vertical": "vy", "Lateral": "vz"}


def read_csv(path, required, allow_nan=False):
    """'#' comments, a header line, numeric rows -> (comments, header, dict of arrays)."""
    if not os.path.isfile(path):
        raise PrepError(path, "file not found")
    comments, header, rows = [], None, []
    with open(path, encoding="utf-8", errors="replace") as f:
        for lineno, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            if line.startswith("#"):
                comments.append(line.lstrip("# ").strip())
            elif header is None:
                header = [h.strip() for h in line.split(",")]
            else:
                parts = line.split(",")
                if len(parts) != len(header):
                    raise PrepError(path, f"line {lineno}: {len(parts)} fields, header has {len(header)}")
                rows.append(parts)
    if header is None or not rows:
        raise PrepError(path, "no header or no data rows")
    missing = [c for c in required if c not in header]
    if missing:
        raise PrepError(path, "missing column(s) " + ", ".join(missing))
    cols = {}
    for i, h in enumerate(header):
        vals = [r[i] for r in rows]
        try:
            cols[h] = np.array([float(v) for v in vals])
        except ValueError:
            cols[h] = np.array(vals, dtype=object)
    for h in required:
        a = cols[h]
        if a.dtype == object:
            raise PrepError(path, f"column {h}: non-numeric value")
        if not allow_nan and not np.all(np.isfinite(a)):
            raise PrepError(path, f"column {h}: NaN in {int(np.sum(~np.isfinite(a)))} row(s)")
    return comments, header, cols


def fmt(v):
    return "" if not np.isfinite(v) else f"{v:.6g}"


def prepare(args):
    src, out = args.source, args.out
    today = datetime.date.today().isoformat()
    cmd = f"/usr/bin/python3 {SCRIPT} --source {src} --out {out}"
    prov = [f"source: {SOURCE}", f"licence: {LICENCE}",
            f"prepared_by: {SCRIPT} on {today}; command: {cmd}",
            "cycle: right heel strike to right heel strike, 100 points, pct_gait_cycle 0..99"]

    # --- spatiotemporal (for headers)
    st_path = os.path.join(src, "spatiotemporal.csv")
    _, _, st = read_csv(st_path, ["step_width_m", "stride_length_m"])
    if "trial" not in st:
        raise PrepError(st_path, "missing column trial")
    num = np.array([str(t).strip().lower() != "mean" for t in st["trial"]])
    sl = np.asarray(st["stride_length_m"], float)[num]
    sw = np.asarray(st["step_width_m"], float)[num]
    spat = (f"spatiotemporal: {num.sum()} trials, stride length {sl.mean():.3f} +- {sl.std(ddof=1):.3f} m, "
            f"step width {sw.mean():.4f} +- {sw.std(ddof=1):.4f} m")

    # --- EMG
    emg_path = os.path.join(src, "EMG_mean_std.csv")
    req = ["pct_gait_cycle"] + [f"{c}_{s}" for c in EMG_MAP for s in ("mean", "std")]
    emg_com, _, emg = read_csv(emg_path, req, allow_nan=True)
    pct = emg["pct_gait_cycle"]
    if len(pct) != 100 or pct[0] != 0 or np.any(np.diff(pct) != 1):
        raise PrepError(emg_path, "pct_gait_cycle is not 0..99 in steps of 1")
    lines = ["# " + p for p in prov + [
        f"file: EMG_mean_std.csv ({emg_com[0] if emg_com else ''})",
        "mean, std: processed EMG envelopes as stored (source normalisation, dimensionless); "
        "mean_norm, std_norm: divided by the channel's largest mean over the cycle (timing comparisons)",
        "muscles: gait2392 base names, right leg (JW model: right unsuffixed, left _l; gait2392: _r/_l); "
        "';' separates muscles that share a channel",
        "peak_pct per channel: " + ", ".join(
            f"{c} {int(pct[np.nanargmax(emg[c + '_mean'])])}" for c in EMG_MAP),
        spat]]
    lines.append("channel,muscles,pct_gait_cycle,mean,std,mean_norm,std_norm")
    for c, muscles in EMG_MAP.items():
        m, s = emg[c + "_mean"], emg[c + "_std"]
        if np.all(~np.isfinite(m)):
            raise PrepError(emg_path, f"channel {c}: no data")
        peak = np.nanmax(m)
        if not peak > 0:
            raise PrepError(emg_path, f"channel {c}: non-positive peak")
        for k in range(len(pct)):
            lines.append(f"{c},{';'.join(muscles)},{int(pct[k])},{fmt(m[k])},{fmt(s[k])},"
                         f"{fmt(m[k] / peak)},{fmt(s[k] / peak)}")
    os.makedirs(out, exist_ok=True)
    write_atomic(os.path.join(out, "healthy_emg.csv"), "\n".join(lines) + "\n")

    # --- kinematics
    q_path = os.path.join(src, "Qs_mean_std.csv")
    req = ["pct_gait_cycle"] + [f"{c}_{s}" for c in Q_MAP for s in ("mean", "std")]
    q_com, _, q = read_csv(q_path, req)
    if len(q["pct_gait_cycle"]) != 100:
        raise PrepError(q_path, "expected 100 rows")
    names = ["pct_gait_cycle"] + [f"{Q_MAP[c]}_{s}" for s in ("mean", "std") for c in Q_MAP]
    lines = ["# " + p for p in prov + [
        f"file: Qs_mean_std.csv ({q_com[0] if q_com else ''})",
        "columns renamed to JW model coordinate names: " + ", ".join(
            f"{a}->{b}" for a, b in Q_MAP.items() if a != b),
        "units: angles deg, pelvis translations m (pelvis_tx relative to its value at heel strike); "
        "right leg and right arm; knee_flexion negative = flexion (as in the JW model)",
        spat]]
    lines.append(",".join(names))
    for k in range(100):
        row = [str(int(q["pct_gait_cycle"][k]))] + [fmt(q[f"{c}_{s}"][k]) for s in ("mean", "std") for c in Q_MAP]
        lines.append(",".join(row))
    write_atomic(os.path.join(out, "healthy_kinematics.csv"), "\n".join(lines) + "\n")

    # --- GRF
    g_path = os.path.join(src, "GRFs_mean_std.csv")
    req = ["pct_gait_cycle"] + [f"{c}_{s}" for c in GRF_MAP for s in ("mean", "std")]
    g_com, _, g = read_csv(g_path, req)
    peak_v = float(np.max(g["Vertical_mean"]))
    if not 60 < peak_v < 200:
        raise PrepError(g_path, f"vertical peak {peak_v:.3g}: not in % body weight as expected")
    names = ["pct_gait_cycle"] + [f"ground_force_r_{GRF_MAP[c]}_{s}_BW" for s in ("mean", "std") for c in GRF_MAP]
    lines = ["# " + p for p in prov + [
        f"file: GRFs_mean_std.csv ({g_com[0] if g_com else ''})",
        f"normalisation: source in % body weight (vertical peak {peak_v:.1f}); written in body weights "
        "(divided by 100)",
        "axes: Fore-aft -> vx (forward +), Vertical -> vy (up +), Lateral -> vz (source sign kept; "
        "OpenSim z points to the walker's right)",
        spat]]
    lines.append(",".join(names))
    for k in range(100):
        row = [str(int(g["pct_gait_cycle"][k]))] + [fmt(g[f"{c}_{s}"][k] / 100.0) for s in ("mean", "std") for c in GRF_MAP]
        lines.append(",".join(row))
    write_atomic(os.path.join(out, "healthy_grf.csv"), "\n".join(lines) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", default="/work/shared/data/healthy_reference")
    ap.add_argument("--out", default="mjmodels/reference")
    args = ap.parse_args(argv)
    try:
        prepare(args)
    except PrepError as e:
        print(f"prepare_reference: {e.file}: {e.reason}", file=sys.stderr)
        return 1
    except OSError as e:
        print(f"prepare_reference: {e.filename or args.out}: {e.strerror}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
