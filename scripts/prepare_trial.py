#!/usr/bin/python3
"""Prepare one gait cycle of a Knee Grand Challenge (JW format) trial for gaitsim.

Reads IK_<trial>.csv (120 Hz, deg/m, OpenSim Y up), GRF_<trial>.csv (1200 Hz, three force plates
grforce1..3: force N, centre of pressure m, torque at the COP N m) and KCF_<trial>.csv (eTibia load
cells PM, AM, AL, PL in lbf, plus GON and GRFz) from --source and writes, into --out:

  coordinates.mot   one right stride (right heel strike to right heel strike), model coordinates
  grf.mot           per-foot ground reaction force, COP and free moment (ExternalLoads names)
  knee_contact.sto  measured medial / lateral / total tibial contact force in N
  trial.json        events, stride time and length, speed, checks and provenance

Method (details in mjmodels/trials/README.md):
  - contacts: vertical plate force fy above --threshold (20 N) on the unfiltered source data,
    intervals shorter than 0.1 s are ignored;
  - each contact is assigned to a foot by two independent tests that must agree: (a) the side of
    the mean COP relative to the pelvis path (OpenSim z points to the walker's right), (b) the
    swing leg during the middle half of the contact is the one with the larger knee flexion;
  - stride: first right contact whose onset lies inside the record (t0) to the next right contact
    onset (t1); without a second right plate contact, t1 comes from kinematic periodicity;
  - GRF: per plate the wrench about the ground origin is low-pass filtered (2nd-order Butterworth
    run forward and backward = 4th-order zero-lag, --cutoff 15 Hz), masked to the contact,
    summed per foot; COP and free moment are recomputed from the foot wrench;
  - a foot on the floor but off the plates during the stride (stance by the events, no plate
    data) is filled from one stride later or earlier (periodicity, COP shifted by the pelvis
    stride displacement) unless --gap-fill zero;
  - all outputs share one time base: 0 at t0, uniform grid of round(T*rate) intervals (--rate 120).

Errors: one line 'prepare_trial: FILE: reason' on stderr, exit status 1.
"""

import argparse
import datetime
import json
import math
import os
import sys

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.signal import butter, filtfilt

from gs_scriptlib import PrepError, write_atomic

LBF_TO_N = 4.4482216152605
GRAVITY = 9.80665
SCRIPT = "scripts/prepare_trial.py"
SOURCE_REPO = "gilserrancoli/ReducePoly_forMSK (MIT), ExampleTrackingSimulations/OpenSimModel/subject_GC"
DATA_CITATION = "Fregly et al. 2012 J Orthop Res 30:503 (Knee Grand Challenge)"
LICENCE = "MIT (gilserrancoli/ReducePoly_forMSK); data Fregly et al. 2012 J Orthop Res 30:503"

# the 26 model coordinates, JW names (right side unsuffixed), in output order
MODEL_COORDS = [
    "pelvis_rz", "pelvis_rx", "pelvis_ry", "pelvis_tx", "pelvis_ty", "pelvis_tz",
    "lumbar_extension", "lumbar_bending", "lumbar_rotation",
    "hip_flexion", "hip_adduction", "hip_rotation",
    "knee_flexion", "knee_adduction", "knee_rotation", "knee_tx", "knee_ty", "knee_tz",
    "ankle_angle", "subtalar_angle",
    "hip_flexion_l", "hip_adduction_l", "hip_rotation_l",
    "knee_flexion_l", "ankle_angle_l", "subtalar_angle_l",
]
# kept after the model coordinates (locked mtp, arms) for animation and completeness
EXTRA_COORDS = [
    "mtp_angle", "mtp_angle_l",
    "arm_flex_r", "arm_add_r", "arm_rot_r", "elbow_flex_r", "pro_sup_r", "wrist_flex_r",
    "wrist_dev_r", "arm_flex_l", "arm_add_l", "arm_rot_l", "elbow_flex_l", "pro_sup_l",
    "wrist_flex_l", "wrist_dev_l",
]
TRANSLATIONS = {"pelvis_tx", "pelvis_ty", "pelvis_tz", "knee_tx", "knee_ty", "knee_tz"}
PLATE_FIELDS = ["fx", "fy", "fz", "px", "py", "pz", "tx", "ty", "tz"]
KCF_COLS = ["PM", "AM", "AL", "PL", "GON", "GRFz"]
MIN_CONTACT_S = 0.10    # shorter supra-threshold intervals are ignored
MIN_STRIDE_S = 0.6      # a second right heel strike must be this far after the first
MAX_STRIDE_S = 2.0


# ---------------------------------------------------------------------------------------------
# input

def read_csv(path, required):
    """Read a source CSV: '#' comment lines, one header line, numeric rows.

    Returns (comments, columns dict name -> float array). Raises PrepError on a missing file,
    missing columns, non-numeric or NaN values, or a non-increasing time column.
    """
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
                continue
            if header is None:
                header = [h.strip() for h in line.split(",")]
                continue
            parts = line.split(",")
            if len(parts) != len(header):
                raise PrepError(path, f"line {lineno}: {len(parts)} fields, header has {len(header)}")
            try:
                rows.append([float(p) for p in parts])
            except ValueError:
                raise PrepError(path, f"line {lineno}: non-numeric value") from None
    if header is None or len(rows) < 10:
        raise PrepError(path, "no header or fewer than 10 data rows")
    missing = [c for c in required if c not in header]
    if missing:
        raise PrepError(path, "missing column(s) " + ", ".join(missing))
    data = np.asarray(rows)
    bad = np.argwhere(~np.isfinite(data))
    if bad.size:
        r, c = bad[0]
        raise PrepError(path, f"NaN/inf in column {header[c]} at data row {r + 1} ({len(bad)} in all)")
    cols = {h: data[:, i] for i, h in enumerate(header)}
    t = data[:, 0]
    if np.any(np.diff(t) <= 0):
        raise PrepError(path, "time column not strictly increasing")
    return comments, cols


# ---------------------------------------------------------------------------------------------
# contacts and events

def contact_intervals(t, fy, threshold):
    """Index intervals [i0, i1] (inclusive) with fy > threshold lasting at least MIN_CONTACT_S."""
    on = fy > threshold
    edges = np.flatnonzero(np.diff(on.astype(np.int8)))
    starts = [0] if on[0] else []
    ends = []
    for e in edges:
        if on[e + 1]:
            starts.append(e + 1)
        else:
            ends.append(e)
    if on[-1]:
        ends.append(len(on) - 1)
    out = []
    for i0, i1 in zip(starts, ends):
        if t[i1] - t[i0] >= MIN_CONTACT_S:
            out.append((i0, i1))
    return out


def crossing_time(t, f, i, threshold):
    """Time at which f crosses threshold between samples i-1 and i (linear interpolation)."""
    if i <= 0 or i >= len(t):
        return float(t[min(max(i, 0), len(t) - 1)])
    f0, f1 = f[i - 1], f[i]
    if f1 == f0:
        return float(t[i])
    a = (threshold - f0) / (f1 - f0)
    return float(t[i - 1] + a * (t[i] - t[i - 1]))


def progression_right_axis(ik):
    """Unit horizontal right-pointing axis (x, z) from the pelvis path: right = forward x up."""
    dx = ik["pelvis_tx"][-1] - ik["pelvis_tx"][0]
    dz = ik["pelvis_tz"][-1] - ik["pelvis_tz"][0]
    n = math.hypot(dx, dz)
    if n < 0.3:
        raise PrepError("IK", f"pelvis moves only {n:.2f} m over the record: not a walking trial")
    fwd = (dx / n, dz / n)
    return fwd, (-fwd[1], fwd[0])


def assign_foot(ik, tg, plate, i0, i1, p, right_axis, ik_path):
    """Foot ('r' or 'l') of one plate contact by two tests that must agree; returns (foot, info)."""
    ti = tg[i0:i1 + 1]
    w = p["fy"][i0:i1 + 1]
    cop_x = np.sum(p["px"][i0:i1 + 1] * w) / np.sum(w)
    cop_z = np.sum(p["pz"][i0:i1 + 1] * w) / np.sum(w)
    pel_x = np.interp(ti, ik["time"], ik["pelvis_tx"])
    pel_z = np.interp(ti, ik["time"], ik["pelvis_tz"])
    lateral = float(np.sum(((cop_x - pel_x) * right_axis[0] + (cop_z - pel_z) * right_axis[1]) * w)
                    / np.sum(w))
    foot_cop = "r" if lateral > 0 else "l"
    # swing leg during the middle half of the contact has the larger knee flexion magnitude
    tm = np.linspace(ti[0] + 0.25 * (ti[-1] - ti[0]), ti[0] + 0.75 * (ti[-1] - ti[0]), 25)
    if tm[0] < ik["time"][0] or tm[-1] > ik["time"][-1]:
        raise PrepError(ik_path, f"plate {plate} contact at {ti[0]:.3f}-{ti[-1]:.3f} s outside IK time range")
    kr = float(np.max(np.abs(np.interp(tm, ik["time"], ik["knee_flexion"]))))
    kl = float(np.max(np.abs(np.interp(tm, ik["time"], ik["knee_flexion_l"]))))
    foot_knee = "r" if kr < kl else "l"
    info = {"plate": plate, "lateral_cop_minus_pelvis_m": round(lateral, 4),
            "max_knee_flexion_mid_contact_deg": {"r": round(kr, 1), "l": round(kl, 1)},
            "foot_by_cop_side": foot_cop, "foot_by_swing_knee": foot_knee}
    if foot_cop != foot_knee:
        raise PrepError("GRF", f"plate {plate} contact at {ti[0]:.3f} s: COP side says {foot_cop}, "
                        f"swing knee says {foot_knee}; cannot assign a foot")
    if abs(lateral) < 0.02:
        raise PrepError("GRF", f"plate {plate} contact at {ti[0]:.3f} s: COP only {lateral * 100:.1f} cm "
                        "from the pelvis path; side ambiguous")
    return foot_cop, info


def kinematic_period(ik, t0, ik_path):
    """Time t1 > t0 at which the leg angles best repeat those at t0 (periodicity fallback/check)."""
    names = ["hip_flexion", "knee_flexion", "ankle_angle", "hip_flexion_l", "knee_flexion_l",
             "ankle_angle_l"]
    t = ik["time"]
    cand = t[(t > t0 + MIN_STRIDE_S) & (t < t0 + MAX_STRIDE_S)]
    if cand.size < 5:
        raise PrepError(ik_path, "IK record too short after the first right heel strike to find "
                        "the next one by periodicity")
    ref = np.array([np.interp(t0, t, ik[n]) for n in names])
    dref = np.array([np.interp(t0, t, np.gradient(ik[n], t)) for n in names])
    cost = []
    for tc in cand:
        q = np.array([np.interp(tc, t, ik[n]) for n in names])
        dq = np.array([np.interp(tc, t, np.gradient(ik[n], t)) for n in names])
        cost.append(np.sum((q - ref) ** 2) + 0.01 * np.sum((dq - dref) ** 2))
    cost = np.asarray(cost)
    k = int(np.argmin(cost))
    if 0 < k < len(cost) - 1:  # parabolic refinement
        c0, c1, c2 = cost[k - 1], cost[k], cost[k + 1]
        den = c0 - 2 * c1 + c2
        off = 0.5 * (c0 - c2) / den if den > 0 else 0.0
        return float(cand[k] + off * (cand[k + 1] - cand[k]))
    return float(cand[k])


# ---------------------------------------------------------------------------------------------
# signal helpers

def lowpass(x, fs, fc):
    """2nd-order Butterworth forward and backward (4th-order zero-lag), cutoff fc Hz."""
    b, a = butter(2, fc / (0.5 * fs))
    return filtfilt(b, a, x, padtype="odd", padlen=min(3 * max(len(a), len(b)), len(x) - 1))


def best_lag(t_ref, x_ref, t_sig, x_sig, max_lag, step):
    """Lag L maximising corr(x_sig(t), x_ref(t + L)) over t in t_sig; returns (L, r)."""
    best = (0.0, -2.0)
    for lag in np.arange(-max_lag, max_lag + 0.5 * step, step):
        tt = t_sig + lag
        ok = (tt >= t_ref[0]) & (tt <= t_ref[-1])
        if ok.sum() < 20:
            continue
        a = x_sig[ok]
        b = np.interp(tt[ok], t_ref, x_ref)
        if np.std(a) == 0 or np.std(b) == 0:
            continue
        r = float(np.corrcoef(a, b)[0, 1])
        if r > best[1]:
            best = (float(lag), r)
    return best


# ---------------------------------------------------------------------------------------------
# output

def write_storage(path, name, columns, data, in_degrees, provenance):
    """Write an OpenSim storage file (.mot/.sto) atomically; provenance lines go in the header."""
    nrows, ncols = data.shape
    lines = [name, "version=1", f"nRows={nrows}", f"nColumns={ncols}",
             f"inDegrees={'yes' if in_degrees else 'no'}"]
    for p in provenance:
        lines.append(p.replace("=", ":").replace("\t", " "))
    lines.append("endheader")
    lines.append("\t".join(columns))
    body = "\n".join("\t".join(f"{v:.8g}" for v in row) for row in data)
    write_atomic(path, "\n".join(lines) + "\n" + body + "\n")


# ---------------------------------------------------------------------------------------------
# main work

def prepare(args):
    src, trial = args.source, args.trial
    ik_path = os.path.join(src, f"IK_{trial}.csv")
    grf_path = os.path.join(src, f"GRF_{trial}.csv")
    kcf_path = os.path.join(src, f"KCF_{trial}.csv")
    ik_com, ik = read_csv(ik_path, ["time"] + MODEL_COORDS)
    grf_cols = ["time"] + [f"grforce{p}_{f}" for p in (1, 2, 3) for f in PLATE_FIELDS]
    grf_com, grf = read_csv(grf_path, grf_cols)
    kcf_com, kcf = read_csv(kcf_path, ["Time(sec)"] + KCF_COLS)
    ik["time"] = ik["time"]
    kcf["time"] = kcf["Time(sec)"]
    extras = [c for c in EXTRA_COORDS if c in ik]
    checks = {}

    # --- sampling and coordinate system checks
    def rate(t):
        return (len(t) - 1) / (t[-1] - t[0])
    fs_ik, fs_grf, fs_kcf = rate(ik["time"]), rate(grf["time"]), rate(kcf["time"])
    checks["sampling_hz"] = {"IK": round(fs_ik, 2), "GRF": round(fs_grf, 2), "KCF": round(fs_kcf, 2)}
    if abs(fs_ik - 120) > 2:
        raise PrepError(ik_path, f"sampling rate {fs_ik:.1f} Hz, expected 120 Hz")
    if fs_grf < 500:
        raise PrepError(grf_path, f"sampling rate {fs_grf:.1f} Hz, expected 1200 Hz")
    pty = ik["pelvis_ty"]
    if not (0.6 < np.median(pty) < 1.3):
        raise PrepError(ik_path, f"median pelvis_ty {np.median(pty):.2f} m: not Y up in metres")
    for n in MODEL_COORDS:
        if n not in TRANSLATIONS and np.max(np.abs(ik[n])) > 3 * 180:
            raise PrepError(ik_path, f"{n} exceeds 540: not degrees")
    knee_rng = np.ptp(ik["knee_flexion"])
    if knee_rng < 2 * math.pi:
        raise PrepError(ik_path, f"knee_flexion range {knee_rng:.2f}: looks like radians, expected degrees")
    checks["ik_units"] = (f"pelvis_ty median {np.median(pty):.3f} m (Y up, metres); knee_flexion "
                          f"range {knee_rng:.1f} deg (degrees; flexion is negative in this model)")
    plates = {}
    for p in (1, 2, 3):
        d = {f: grf[f"grforce{p}_{f}"] for f in PLATE_FIELDS}
        if np.max(np.abs(d["py"])) > 1e-6:
            raise PrepError(grf_path, f"grforce{p}_py not zero: plates not in the y=0 ground plane")
        if np.max(np.abs(d["tx"])) > 1e-6 or np.max(np.abs(d["tz"])) > 1e-6:
            raise PrepError(grf_path, f"grforce{p}_tx/tz not zero: torque is not a free moment about the COP")
        plates[p] = d
    peak_fy = max(np.max(plates[p]["fy"]) for p in plates)
    if peak_fy < 100.0:
        raise PrepError(grf_path, f"largest fy {peak_fy:.1f} N: vertical force is not fy (Y up)?")
    checks["grf_frame"] = ("fy is vertical (py = 0, COP on the y = 0 ground plane); torques tx = tz = 0, "
                           "ty is the free moment about the vertical axis at the COP")

    # --- contacts and their feet
    tg = grf["time"]
    fwd, right_axis = progression_right_axis(ik)
    contacts = []
    for p, d in plates.items():
        for i0, i1 in contact_intervals(tg, d["fy"], args.threshold):
            foot, info = assign_foot(ik, tg, p, i0, i1, d, right_axis, ik_path)
            c = dict(plate=p, i0=i0, i1=i1, foot=foot,
                     on=crossing_time(tg, d["fy"], i0, args.threshold) if i0 > 0 else None,
                     off=crossing_time(tg, d["fy"], i1 + 1, args.threshold) if i1 < len(tg) - 1 else None)
            info.update(onset_s=None if c["on"] is None else round(c["on"], 4),
                        offset_s=None if c["off"] is None else round(c["off"], 4), foot=foot)
            c["info"] = info
            contacts.append(c)
    if not contacts:
        raise PrepError(grf_path, f"no plate contact above {args.threshold} N")
    contacts.sort(key=lambda c: tg[c["i0"]])
    # two feet on one plate at once cannot be split; flag overlapping same-foot contacts
    right = [c for c in contacts if c["foot"] == "r"]
    left = [c for c in contacts if c["foot"] == "l"]

    # --- right heel strikes
    hs_r = [c for c in right if c["on"] is not None]
    if not hs_r:
        raise PrepError(grf_path, "no right heel strike found on any force plate")
    t0 = hs_r[0]["on"]
    nxt = [c for c in hs_r if c["on"] > t0 + MIN_STRIDE_S]
    t1_kin = kinematic_period(ik, t0, ik_path)
    if nxt:
        t1 = nxt[0]["on"]
        t1_method = f"force plate {nxt[0]['plate']} (fy > {args.threshold:g} N)"
    else:
        t1 = t1_kin
        t1_method = "kinematic periodicity (no second right heel strike on a plate)"
    T = t1 - t0
    if not (MIN_STRIDE_S < T < MAX_STRIDE_S):
        raise PrepError(grf_path, f"stride time {T:.3f} s implausible")
    checks["t1_by_kinematic_periodicity_s"] = round(t1_kin, 4)
    checks["t1_plate_minus_kinematic_s"] = round(t1 - t1_kin, 4)
    for name, src_t in (("IK", ik["time"]), ("GRF", tg), ("KCF", kcf["time"])):
        if src_t[0] > t0 + 1e-9 or src_t[-1] < t1 - 1e-9:
            raise PrepError({"IK": ik_path, "GRF": grf_path, "KCF": kcf_path}[name],
                            f"record {src_t[0]:.3f}-{src_t[-1]:.3f} s does not cover the stride "
                            f"{t0:.4f}-{t1:.4f} s")

    # --- other events
    def first(cands):
        return min(cands) if cands else None
    r_to = first([c["off"] for c in right if c["off"] is not None and t0 < c["off"] < t1])
    r_to_method = "force plate"
    if r_to is None:
        r_to = first([c["off"] - T for c in right if c["off"] is not None and t1 < c["off"] < t1 + T])
        r_to_method = "force plate, one stride later, minus stride time (periodicity)"
    l_hs = first([c["on"] for c in left if c["on"] is not None and t0 < c["on"] < t1])
    l_hs_method = "force plate"
    if l_hs is None:
        l_hs = first([c["on"] - T for c in left if c["on"] is not None and t1 <= c["on"] < t1 + T])
        l_hs_method = "force plate, one stride later, minus stride time (periodicity)"
    l_to = first([c["off"] for c in left if c["off"] is not None and t0 < c["off"] < t1])
    l_to_method = "force plate"
    l_to_plate = None
    if l_to is None:
        later = [c["off"] for c in left if c["off"] is not None and t1 <= c["off"] < t1 + T]
        if later:
            l_to_plate = min(later)
            l_to = l_to_plate - T
            l_to_method = (f"periodicity: left toe-off measured on a plate at {l_to_plate:.4f} s "
                           "(after the stride) minus stride time")
    if r_to is None or l_hs is None or l_to is None:
        raise PrepError(grf_path, "cannot find right toe-off, left heel strike and left toe-off from "
                        "the plates (directly or one stride later)")

    # --- coordinates on the output grid
    n_int = int(round(T * args.rate))
    tout = np.linspace(t0, t1, n_int + 1)
    margin = 3.0 / fs_ik
    sel = (ik["time"] >= t0 - margin) & (ik["time"] <= t1 + margin)
    tik = ik["time"][sel]
    jumps = []
    for n in MODEL_COORDS:
        d2 = np.abs(np.diff(ik[n][sel], 2))
        lim = 0.01 if n in TRANSLATIONS else 5.0
        if d2.size and d2.max() > lim:
            k = int(np.argmax(d2))
            jumps.append(f"{n} at {tik[k + 1]:.4f} s (second difference {d2.max():.3g})")
    if jumps and not args.allow_discontinuity:
        raise PrepError(ik_path, "discontinuity inside the stride: " + "; ".join(jumps[:3]))
    all_d2 = {n: np.abs(np.diff(ik[n], 2)) for n in MODEL_COORDS}
    worst = max(all_d2, key=lambda n: all_d2[n].max() / (0.01 if n in TRANSLATIONS else 5.0))
    kw = int(np.argmax(all_d2[worst]))
    checks["ik_discontinuities_in_stride"] = jumps
    checks["ik_worst_jump_in_record"] = (f"{worst} at {ik['time'][kw + 1]:.4f} s (second difference "
                                         f"{all_d2[worst][kw]:.3g}); the stride window "
                                         f"{t0 - margin:.4f}-{t1 + margin:.4f} s is used for the spline")
    coord_names = MODEL_COORDS + extras
    q = np.column_stack([CubicSpline(tik, ik[n][sel])(tout) for n in coord_names])
    per = {}
    for n in MODEL_COORDS:
        if n in ("pelvis_tx",):
            continue
        per[n] = round(float(q[-1, coord_names.index(n)] - q[0, coord_names.index(n)]), 4)
    checks["periodicity_q(t1)-q(t0)"] = per

    # --- spatiotemporal
    ix = coord_names.index("pelvis_tx")
    iz = coord_names.index("pelvis_tz")
    disp_x = float(q[-1, ix] - q[0, ix])
    disp_z = float(q[-1, iz] - q[0, iz])
    stride_length = disp_x
    speed = stride_length / T

    # --- GRF per foot
    fs = fs_grf
    foot_w = {f: np.zeros((len(tg), 6)) for f in ("r", "l")}   # Fx Fy Fz Mx My Mz about origin
    foot_on = {f: np.zeros(len(tg), bool) for f in ("r", "l")}
    for p, d in plates.items():
        fx, fy, fz, px, pz, ty = d["fx"], d["fy"], d["fz"], d["px"], d["pz"], d["ty"]
        # wrench about the ground origin (py = 0): M = r x F + (0, ty, 0)
        w = np.column_stack([fx, fy, fz, -pz * fy, pz * fx - px * fz + ty, px * fy])
        wf = np.column_stack([lowpass(w[:, k], fs, args.cutoff) for k in range(6)])
        for c in contacts:
            if c["plate"] != p:
                continue
            s = slice(c["i0"], c["i1"] + 1)
            foot_w[c["foot"]][s] += wf[s]
            foot_on[c["foot"]][s] = True

    # stance windows by the events (relative to t0), used for the gap check / fill
    stance = {"r": [(t0, r_to), (t1, t1 + T)], "l": [(t0, l_to), (l_hs, t1)]}
    gap_info = {}
    for f in ("r", "l"):
        gaps = []
        for a, b in stance[f]:
            if b <= a or a >= t1:
                continue
            b = min(b, t1)
            s = (tg >= a + 0.01) & (tg <= b - 0.01)     # 10 ms tolerance at the event edges
            missing = s & ~foot_on[f]
            if missing.any():
                idx = np.flatnonzero(missing)
                gaps.append((float(tg[idx[0]]), float(tg[idx[-1]])))
        gap_info[f] = gaps
    foot_on_raw = {f: foot_on[f].copy() for f in foot_on}
    shift = np.array([disp_x, disp_z])
    filled = []
    if args.gap_fill == "periodic":
        for f in ("r", "l"):
            for a, b in gap_info[f]:
                # extend the gap to the neighbouring event so the whole off-plate stance is filled
                ev = [e for e in (t0, r_to, l_hs, l_to, t1)]
                a2 = max([e for e in ev if e <= a + 1e-9], default=a)
                b2 = min([e for e in ev if e >= b - 1e-9], default=b)
                # one extra sample each side so the resampled grid sees no false edge at the events
                s = np.flatnonzero((tg >= a2 - 1.5 / fs) & (tg <= b2 + 1.5 / fs) & ~foot_on[f])
                for sign in (+1, -1):
                    ts = tg[s] + sign * T
                    if ts.min() < tg[0] or ts.max() > tg[-1]:
                        continue
                    j = np.clip(np.round((ts - tg[0]) * fs).astype(int), 0, len(tg) - 1)
                    if not foot_on[f][j].any():
                        continue
                    w = foot_w[f][j].copy()
                    # move the force by d = -sign * stride displacement: M' = M + d x F (dy = 0)
                    dx, dz = -sign * shift
                    Fx, Fy, Fz = w[:, 0], w[:, 1], w[:, 2]
                    w[:, 3] += -dz * Fy
                    w[:, 4] += dz * Fx - dx * Fz
                    w[:, 5] += dx * Fy
                    foot_w[f][s] = w * foot_on[f][j][:, None]
                    foot_on[f][s] = foot_on[f][j]
                    filled.append({"foot": f, "from_s": round(float(tg[s[0]]) - t0, 4),
                                   "to_s": round(float(tg[s[-1]]) - t0, 4),
                                   "copied_from_source_s": [round(float(tg[s[0]] + sign * T), 4),
                                                            round(float(tg[s[-1]] + sign * T), 4)],
                                   "cop_shift_m": [round(-sign * shift[0], 4), 0.0,
                                                   round(-sign * shift[1], 4)]})
                    break
                else:
                    raise PrepError(grf_path, f"{f} foot off the plates during stance {a:.3f}-{b:.3f} s "
                                    "and no plate data one stride later or earlier to fill it")

    # COP and free moment from the foot wrench, resampled to the output grid
    grf_names, grf_cols_out = [], []
    for f in ("r", "l"):
        w = np.column_stack([np.interp(tout, tg, foot_w[f][:, k]) for k in range(6)])
        Fx, Fy, Fz, Mx, My, Mz = w.T
        valid = Fy > 0.5 * args.threshold
        px = np.where(valid, Mz / np.where(valid, Fy, 1), np.nan)
        pz = np.where(valid, -Mx / np.where(valid, Fy, 1), np.nan)
        # hold the COP through swing (last valid value; before the first, the first valid value)
        for arr in (px, pz):
            if np.all(np.isnan(arr)):
                arr[:] = 0.0
                continue
            first_valid = arr[np.flatnonzero(~np.isnan(arr))[0]]
            last = first_valid
            for k in range(len(arr)):
                if np.isnan(arr[k]):
                    arr[k] = last
                else:
                    last = arr[k]
        Ty = np.where(valid, My - (pz * Fx - px * Fz), 0.0)
        Fx, Fy, Fz = (np.where(valid, v, 0.0) for v in (Fx, Fy, Fz))
        cols = [Fx, Fy, Fz, px, np.zeros_like(px), pz, np.zeros_like(px), Ty, np.zeros_like(px)]
        names = [f"ground_force_{f}_v{a}" for a in "xyz"] + [f"ground_force_{f}_p{a}" for a in "xyz"] \
            + [f"ground_torque_{f}_{a}" for a in "xyz"]
        grf_names += names
        grf_cols_out += cols
    G = np.column_stack(grf_cols_out)

    # body-weight check: mean vertical GRF over a stride equals body weight
    fy_tot = G[:, grf_names.index("ground_force_r_vy")] + G[:, grf_names.index("ground_force_l_vy")]
    mean_fy = float(np.trapz(fy_tot, tout) / T)
    bw = args.mass * GRAVITY
    checks["mean_vertical_grf_over_stride_BW"] = round(mean_fy / bw, 4)
    # independent of the gap fill: a left stride fully covered by plates, if the record has one
    def in_stance(f, t):
        ph = np.mod(t - t0, T)
        if f == "r":
            return ph <= r_to - t0
        return (ph >= l_hs - t0) | (ph <= l_to - t0)
    for hs in sorted(c["on"] for c in left if c["on"] is not None):
        a, b = hs, hs + T
        if b > tg[-1]:
            break
        s = (tg >= a) & (tg <= b)
        cover = [np.mean(foot_on_raw[f][s][in_stance(f, tg[s])]) for f in ("r", "l")]
        if min(cover) > 0.98:
            tot = sum(plates[p]["fy"] for p in plates)
            m_implied = float(np.trapz(tot[s], tg[s]) / T / GRAVITY)
            checks["mass_implied_by_plates_kg"] = round(m_implied, 2)
            checks["mass_implied_note"] = (f"mean total plate fy over the left stride {a:.4f}-{b:.4f} s "
                                           "(every stance sample on a plate, no fill) / g")
            break

    # --- knee contact force, alignment of the KCF clock with the plates
    tk = kcf["time"]
    lag_best = (0.0, -2.0, None)
    for p, d in plates.items():
        lag, r = best_lag(tg, d["fy"], tk, kcf["GRFz"], 0.5, 1.0 / fs_grf)
        if r > lag_best[1]:
            lag_best = (lag, r, p)
    lag_gon, r_gon = best_lag(ik["time"], -ik["knee_flexion"], tk, kcf["GON"], 0.5, 1.0 / (10 * fs_ik))
    scale = float(np.max(plates[lag_best[2]]["fy"]) / np.max(kcf["GRFz"])) if np.max(kcf["GRFz"]) > 0 else None
    if lag_best[1] < 0.9:
        raise PrepError(kcf_path, f"GRFz correlates with no force plate (best r = {lag_best[1]:.2f}); "
                        "cannot check the time base")
    kcf_offset = round(lag_best[0], 4) if abs(lag_best[0]) > 0.5 / fs_kcf else 0.0
    if args.kcf_offset is not None:
        kcf_offset = args.kcf_offset
    tk_al = tk + kcf_offset
    med = (kcf["PM"] + kcf["AM"]) * LBF_TO_N
    lat = (kcf["AL"] + kcf["PL"]) * LBF_TO_N
    K = np.column_stack([np.interp(tout, tk_al, med), np.interp(tout, tk_al, lat)])
    K = np.column_stack([K, K[:, 0] + K[:, 1]])
    kcf_align = {"grfz_best_plate": lag_best[2], "grfz_lag_s": round(lag_best[0], 5),
                 "grfz_corr": round(lag_best[1], 4),
                 "grfz_scale_N_per_unit": None if scale is None else round(scale, 1),
                 "gon_vs_minus_ik_knee_flexion_lag_s": round(lag_gon, 5), "gon_corr": round(r_gon, 4),
                 "offset_applied_s": kcf_offset,
                 "rule": "KCF time + offset = plate time; the GRFz lag is applied when larger than half "
                         "a KCF sample, else 0 (override --kcf-offset)"}

    # --- write
    os.makedirs(args.out, exist_ok=True)
    now = datetime.date.today().isoformat()
    cmd = (f"/usr/bin/python3 {SCRIPT} --source {src} --trial {trial} --out {args.out} "
           f"--mass {args.mass:g}" + (f" --height {args.height:g}" if args.height else "")
           + (f" --gap-fill {args.gap_fill}" if args.gap_fill != "periodic" else ""))
    base_prov = [
        f"source: {SOURCE_REPO}; data {DATA_CITATION}",
        f"licence: {LICENCE}",
        f"prepared_by: {SCRIPT} on {now}; command: {cmd}",
        f"stride: right heel strike {t0:.4f} s to right heel strike {t1:.4f} s of the source clock; "
        f"time here is source time minus {t0:.4f} s; {n_int + 1} rows, uniform step {T / n_int:.6f} s",
    ]
    prov_q = base_prov + [
        f"file: IK_{trial}.csv ({ik_com[0] if ik_com else 'no source comment'})",
        "columns: the 26 model coordinates (JW names, right side unsuffixed) then mtp and arm coordinates; "
        "angles in degrees, translations in m (OpenSim ground frame, Y up)",
        f"resampling: not-a-knot cubic spline through the 120 Hz IK samples of the stride window "
        f"(source samples {t0 - margin:.4f}-{t1 + margin:.4f} s); no filtering",
    ]
    prov_g = base_prov + [
        f"file: GRF_{trial}.csv ({grf_com[0] if grf_com else 'no source comment'})",
        f"filter: wrench about the ground origin per plate, 2nd-order Butterworth {args.cutoff:g} Hz forward "
        f"and backward (4th-order zero lag) at {fs_grf:.0f} Hz, then masked to contacts (fy > {args.threshold:g} N "
        "unfiltered), summed per foot, linearly resampled to the grid",
        "COP and free moment recomputed from the foot wrench; COP held at its last value (first value "
        "before the first contact) when the foot is unloaded; force and torque are 0 there",
        "plates to feet: " + "; ".join(f"plate {c['plate']} {c['info']['onset_s']}-{c['info']['offset_s']} s "
                                       f"-> {c['foot']}" for c in contacts),
        "gap fill: " + ("none" if not filled else "; ".join(
            f"{g['foot']} foot {g['from_s']}-{g['to_s']} s copied from source {g['copied_from_source_s'][0]}-"
            f"{g['copied_from_source_s'][1]} s, COP shifted {g['cop_shift_m'][0]} m in x and "
            f"{g['cop_shift_m'][2]} m in z (periodicity; foot on the floor off the plates)" for g in filled)),
        "units: force N, COP m, torque N m, ground frame (Y up)",
    ]
    prov_k = base_prov + [
        f"file: KCF_{trial}.csv ({kcf_com[0] if kcf_com else 'no source comment'})",
        "eTibia axial load cells: medial = PM + AM, lateral = AL + PL, total = medial + lateral; "
        f"lbf x {LBF_TO_N} = N; linear interpolation of the 120 Hz samples",
        f"time alignment: GRFz channel best matches plate {lag_best[2]} at lag {lag_best[0]:+.4f} s "
        f"(r {lag_best[1]:.3f}); GON vs IK knee flexion lag {lag_gon:+.4f} s (r {r_gon:.3f}); "
        f"offset applied {kcf_offset:+.4f} s",
    ]
    write_storage(os.path.join(args.out, "coordinates.mot"), "coordinates",
                  ["time"] + coord_names, np.column_stack([tout - t0, q]), True, prov_q)
    write_storage(os.path.join(args.out, "grf.mot"), "grf", ["time"] + grf_names,
                  np.column_stack([tout - t0, G]), False, prov_g)
    write_storage(os.path.join(args.out, "knee_contact.sto"), "knee_contact",
                  ["time", "contact_medial_r", "contact_lateral_r", "contact_total_r"],
                  np.column_stack([tout - t0, K]), False, prov_k)

    def rel(x):
        return round(x - t0, 4)

    meta = {
        "subject": "JW",
        "trial": trial,
        "mass_kg": args.mass,
        "height_m": args.height,
        "height_note": ("given with --height" if args.height else
                        "unknown: not in the source files, the scaled model or the project reference "
                        "paper; set with --height when a citable value is available"),
        "implant_side": "r",
        "speed_mps": round(speed, 4),
        "speed_note": "pelvis_tx displacement over the stride / stride time",
        "stride_time_s": round(T, 4),
        "stride_length_m": round(stride_length, 4),
        "stride_lateral_drift_m": round(disp_z, 4),
        "time_base": ("file time 0 = first right heel strike; source time = file time + "
                      f"{t0:.4f} s; event times below are source times, *_cycle are file times"),
        "right_heel_strike_s": [round(t0, 4), round(t1, 4)],
        "left_heel_strike_s": round(l_hs, 4),
        "right_toe_off_s": round(r_to, 4),
        "left_toe_off_s": round(l_to, 4),
        "events_cycle": {"right_heel_strike": [0.0, rel(t1)], "left_toe_off": rel(l_to),
                         "left_heel_strike": rel(l_hs), "right_toe_off": rel(r_to)},
        "events_pct": {"left_toe_off": round(100 * (l_to - t0) / T, 1),
                       "left_heel_strike": round(100 * (l_hs - t0) / T, 1),
                       "right_toe_off": round(100 * (r_to - t0) / T, 1)},
        "events_method": {
            "threshold_N": args.threshold,
            "right_heel_strike_0": f"force plate {hs_r[0]['plate']} (fy > {args.threshold:g} N)",
            "right_heel_strike_1": t1_method,
            "right_toe_off": r_to_method, "left_heel_strike": l_hs_method, "left_toe_off": l_to_method,
        },
        "plate_contacts": [c["info"] for c in contacts],
        "grf_gap_fill": filled if filled else None,
        "grf_filter": f"2nd-order Butterworth {args.cutoff:g} Hz, forward-backward (4th-order zero-lag)",
        "kcf_alignment": kcf_align,
        "checks": checks,
        "files": {"coordinates.mot": "model coordinates", "grf.mot": "per-foot GRF, COP, free moment",
                  "knee_contact.sto": "measured eTibia contact force, N"},
        "units": {"time": "s", "angles": "deg", "translations": "m", "force": "N", "cop": "m",
                  "torque": "N m", "knee_contact": "N", "frame": "OpenSim ground, Y up, x forward"},
        "source": f"{SOURCE_REPO}: IK/IK_{trial}.mat, GRF/GRF_{trial}.mat, KCF/KCF_{trial}.mat "
                  f"(as CSV in {src})",
        "licence": LICENCE,
        "prepared_by": SCRIPT,
        "command": cmd,
    }
    write_atomic(os.path.join(args.out, "trial.json"), json.dumps(meta, indent=2) + "\n")
    return meta


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", required=True, help="folder with IK_/GRF_/KCF_<trial>.csv")
    ap.add_argument("--trial", required=True, help="trial name, e.g. ngait_og5")
    ap.add_argument("--out", required=True, help="output trial folder")
    ap.add_argument("--mass", type=float, default=62.6, help="body mass kg (JW model: 62.6)")
    ap.add_argument("--height", type=float, default=None, help="height m (unknown for JW by default)")
    ap.add_argument("--threshold", type=float, default=20.0, help="contact threshold on fy, N")
    ap.add_argument("--cutoff", type=float, default=15.0, help="GRF low-pass cutoff, Hz")
    ap.add_argument("--rate", type=float, default=120.0, help="output rate, Hz (rounded to fit the stride)")
    ap.add_argument("--gap-fill", choices=["periodic", "zero"], default="periodic",
                    help="stance off the plates: copy from one stride away, or leave zero")
    ap.add_argument("--kcf-offset", type=float, default=None, help="override the KCF time offset, s")
    ap.add_argument("--allow-discontinuity", action="store_true",
                    help="do not fail on a jump in the IK data inside the stride")
    args = ap.parse_args(argv)
    try:
        meta = prepare(args)
    except PrepError as e:
        print(f"prepare_trial: {e.file}: {e.reason}", file=sys.stderr)
        return 1
    except OSError as e:
        print(f"prepare_trial: {e.filename or args.out}: {e.strerror}", file=sys.stderr)
        return 1
    print(f"prepare_trial: {args.out}: stride {meta['right_heel_strike_s'][0]}-{meta['right_heel_strike_s'][1]} s, "
          f"T {meta['stride_time_s']} s, L {meta['stride_length_m']} m, v {meta['speed_mps']} m/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
