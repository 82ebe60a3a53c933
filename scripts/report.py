#!/usr/bin/python3
"""report.py: figures and a table of a gaitsim solution, sweep or batch folder (gaitsim report).

usage: /usr/bin/python3 scripts/report.py DIR [--out D] [--into S] [--trial T] [--track TRACK_DIR]
                                          [--gaitsim GAITSIM]

Like Lin, Walter & Pandy 2018 (Ann Biomed Eng 46:1216) Fig. 1-3 and Table 1, from a solution
folder (states.sto, controls.sto, grf.mot, summary.json; knee_contact.sto if present) and the
measured trial it tracked (summary.json "trial", or --trial; default mjmodels/trials/jw_ngait_og5:
coordinates.mot, grf.mot, trial.json, knee_contact.sto):
- kinematics.png: pelvis (3 rotations, 3 translations), lumbar, hips, knees, ankles and subtalar
  joints, model vs measured, over % gait cycle (right heel strike to right heel strike);
- grf.png: fore-aft, vertical, mediolateral GRF per foot in body weights, model vs measured (the
  measured GRF times summary.json "grf_scale", the factor tracking applied, when present);
- knee_contact.png (when DIR has knee_contact.sto): right-knee total, medial, lateral contact
  force in BW, model vs measured (whichever of those columns exist); beside them, when the file
  has contact_total_l, the left (1-DOF) knee's compressive joint reaction with the right knee's
  model and measured curves shifted to the left heel strike for comparison (cf. Fig. 8: the
  in-vivo data are for the right, implant knee only);
- excitations.png: right-leg model excitations (controls.sto) against the EMG envelopes of
  mjmodels/reference/healthy_emg.csv (Falisse et al. 2019, a different, healthy subject), each
  normalised to its peak over the cycle: timing only;
- joint_moments.png (with --gaitsim, which `gaitsim report` passes, and a model that `gaitsim
  moments` takes): the net joint moments of inverse dynamics (N m/kg) at both hips (flexion,
  adduction), knees and ankles, the solution (its states.sto under its grf.mot) against the
  measured gait (the trial's coordinates.mot under its plates), both by `GAITSIM moments`;
- report.md: the RMS errors of summary.json beside the paper's participant-2 values (Table 1),
  the solve facts, the joint moments' RMS differences, and links to the figures.
Body weight: summary.json body_weight_n (the model's mass x g, as the solve's RMS errors), else
trial.json mass_kg x 9.80665 N.

A sweep folder (`gaitsim sweep`: sweep.csv and predict_<V>/ solution folders; recognised by its
sweep.csv, or by --track) gets figures comparing the speeds like the paper's Fig. 4-6 and 8, each
speed a colour (viridis, slow to fast) and the tracking solution dashed black (--track, else the
first "guess" of the predictions' summary.json that is not one of the sweep's predict_* folders
and exists, as written or relative to the sweep folder's parent or up to three folders above it):
- kinematics.png: pelvis, lumbar, hip, knee, ankle and subtalar angles over % stride (Fig. 4);
- grf.png: fore-aft and vertical GRF per foot in BW (Fig. 5);
- excitations.png: the main right-leg muscles (SWEEP_MUSCLES: soleus, gastrocnemius, tibialis
  anterior, vasti, rectus femoris, hamstrings, gluteus maximus and medius, iliacus, psoas) (Fig. 6);
- gait_parameters.png: stride time, stride length and cost of transport against speed from
  sweep.csv, with the paper's stride times at 0.8 and 2.0 m/s (1.30, 0.92 s predicted; 1.45, 0.93
  s measured) and the stride lengths they imply marked;
- knee_contact.png (when a solution has knee_contact.sto): right-knee total per speed, and the
  left knee's contact_total_l where present (Fig. 8);
- report.md: the sweep table, the paper's stride times beside this sweep's, figure links.
sweep.csv needs speed_mps, stride_time_s, stride_length_m, cost_of_transport_j_per_kg_m (other
columns are shown in the table); "nan" values (failed solves) are left out of the plots, as are
speeds without a predict_<V>/states.sto (listed in report.md). Body weight per solution:
summary.json body_weight_n, else its trial's mass.

A batch folder (`gaitsim batch`: batch.csv, plan.json, one folder per solve; recognised by its
batch.csv) gets the collected results drawn from batch.csv (the columns gs_batch_collect writes;
solve, command, status, wall_s, stride_time_s, speed_mps, cost_of_transport_j_per_kg_m needed,
rms_<key> of TABLE1 used where present, empty cells for what a solve lacks):
- wall_time.png: wall time per solve, coloured by status;
- gait_speed.png (when a solve has a speed and a stride time or cost of transport): stride time
  and cost of transport against the solved speed, each sweep of plan.json a line (its solves
  NAME_<V>), other predictions and the tracks as markers, the paper's stride times marked;
- rms.png (when a track has RMS errors): the Table 1 RMS errors per track;
- report.md: the batch table (empty cells as -), the count per status, the sweeps, figure links.

Output goes to DIR/report/ (or --out); `gaitsim report` passes --into, a temporary folder beside
--out that it renames to --out in one step when this script succeeds and removes when it fails
(so the folder is whole: the earlier report or the new one). Every file is written whole
(temporary file + rename), report.md last, and only after every input has been read and checked,
so bad input (missing file or column, NaN) leaves nothing new: one line "gaitsim: FILE: reason" on
stderr, exit 1. Debian python3-matplotlib and python3-numpy only.
"""
import argparse
import io
import json
import math
import os
import signal
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import (PrepError, inverse_dynamics_moments, read_json,  # noqa: E402
                          read_storage, write_atomic)

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_TRIAL = os.path.join(SOURCE_DIR, "mjmodels", "trials", "jw_ngait_og5")
EMG_PATH = os.path.join(SOURCE_DIR, "mjmodels", "reference", "healthy_emg.csv")
G = 9.80665  # m/s^2
DPI = 150

# kinematics panels: (coordinate, title); pelvis translations in m, everything else in degrees
KINEMATICS = [
    ("pelvis_rz", "pelvis tilt"), ("pelvis_rx", "pelvis list"), ("pelvis_ry", "pelvis rotation"),
    ("pelvis_tx", "pelvis tx (fore-aft)"), ("pelvis_ty", "pelvis ty (vertical)"),
    ("pelvis_tz", "pelvis tz (mediolateral)"),
    ("lumbar_extension", "lumbar extension"), ("lumbar_bending", "lumbar bending"),
    ("lumbar_rotation", "lumbar rotation"),
    ("hip_flexion", "hip flexion R"), ("hip_adduction", "hip adduction R"),
    ("hip_rotation", "hip rotation R"),
    ("hip_flexion_l", "hip flexion L"), ("hip_adduction_l", "hip adduction L"),
    ("hip_rotation_l", "hip rotation L"),
    ("knee_flexion", "knee flexion R"), ("knee_flexion_l", "knee flexion L"),
    ("ankle_angle", "ankle angle R"), ("ankle_angle_l", "ankle angle L"),
    ("subtalar_angle", "subtalar angle R"), ("subtalar_angle_l", "subtalar angle L"),
]
TRANSLATIONS = {"pelvis_tx", "pelvis_ty", "pelvis_tz"}

# GRF components in the OpenSim ground frame (Y up, x forward)
GRF_COMPONENTS = [("vx", "fore-aft"), ("vy", "vertical"), ("vz", "mediolateral")]

# EMG (gait2392 names) -> JW model right-leg muscles (scripts/osim2mjcf.py GAIT2392_NAME, inverted
# for the muscles the EMG table names)
EMG_TO_MODEL = {
    "soleus": "soleus", "med_gas": "gasmed", "lat_gas": "gaslat", "tib_ant": "tibant",
    "per_long": "perlong", "per_brev": "perbrev", "vas_lat": "vaslat", "vas_med": "vasmed",
    "rect_fem": "recfem", "semimem": "semimem", "semiten": "semiten", "bifemlh": "bflh",
    "glut_med1": "glmed1", "glut_med2": "glmed2", "glut_med3": "glmed3", "add_long": "addlong",
    "tfl": "tfl",
}

# Table 1 rows: (summary.json rms key, quantity, unit, Lin et al. 2018 participant 2)
TABLE1 = [
    ("pelvis_rot_deg", "Pelvis rotations", "deg", "0.21"),
    ("pelvis_trans_cm", "Pelvis translations", "cm", "0.20"),
    ("grf_ap_bw", "GRF fore-aft", "BW", "0.02"),
    ("grf_v_bw", "GRF vertical", "BW", "0.04"),
    ("grf_ml_bw", "GRF mediolateral", "BW", "0.02"),
    ("joint_rot_deg", "Joint rotations", "deg", "1.98"),
    ("knee_contact_bw", "Knee contact force", "BW", "0.32"),
    ("knee_medial_bw", "Knee contact, medial compartment", "BW", "-"),
    ("knee_lateral_bw", "Knee contact, lateral compartment", "BW", "-"),
    # not in the paper's table: where the feet push (both feet, nodes with > 0.1 BW measured)
    ("cop_ap_cm", "Centre of pressure fore-aft", "cm", "-"),
    ("cop_ml_cm", "Centre of pressure mediolateral", "cm", "-"),
]


class Storage:
    """An OpenSim storage file: path, labels, columns (numpy arrays), inDegrees flag."""

    def __init__(self, path):
        import numpy as np
        header, labels, rows = read_storage(path)
        self.path = path
        self.labels = labels
        data = np.array(rows, dtype=float)
        self.cols = {lab: data[:, i] for i, lab in enumerate(labels)}
        self.in_degrees = any(h.strip().lower() == "indegrees=yes" for h in header)
        if labels[0].lower() != "time":
            raise PrepError(path, f"first column is '{labels[0]}', not time")
        t = self.col("time")
        if len(t) < 2 or not np.all(np.diff(t) > 0):
            raise PrepError(path, "time column not increasing (or fewer than 2 rows)")
        span = t[-1] - t[0]
        self.pct = 100.0 * (t - t[0]) / span

    def has(self, name):
        return name in self.cols

    def col(self, name):
        """The column, checked finite; PrepError when missing or with NaN."""
        import numpy as np
        if name not in self.cols:
            raise PrepError(self.path, f"missing column {name}")
        a = self.cols[name]
        bad = int(np.sum(~np.isfinite(a)))
        if bad:
            raise PrepError(self.path, f"column {name}: NaN or infinite value in {bad} row(s)")
        return a

    def coordinate(self, name):
        """A coordinate in degrees (rotations) or metres (translations)."""
        a = self.col(name)
        if name not in TRANSLATIONS and not self.in_degrees:
            a = a * 180.0 / math.pi
        return a


def finite_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def read_emg(path):
    """EMG channels in file order: list of (channel, [gait2392 muscles], pct, mean_norm,
    std_norm)."""
    import numpy as np
    try:
        with open(path, encoding="utf-8") as f:
            lines = [line.strip() for line in f if line.strip() and not line.startswith("#")]
    except FileNotFoundError:
        raise PrepError(path, "file not found")
    if not lines:
        raise PrepError(path, "no header line")
    header = lines[0].split(",")
    need = ["channel", "muscles", "pct_gait_cycle", "mean_norm", "std_norm"]
    missing = [c for c in need if c not in header]
    if missing:
        raise PrepError(path, "missing column(s) " + ", ".join(missing))
    idx = {c: header.index(c) for c in need}
    chans = {}
    order = []
    for lineno, line in enumerate(lines[1:], 2):
        p = line.split(",")
        if len(p) != len(header):
            raise PrepError(path, f"data line {lineno}: {len(p)} fields, header has {len(header)}")
        ch = p[idx["channel"]]
        try:
            vals = [float(p[idx[c]]) for c in ("pct_gait_cycle", "mean_norm", "std_norm")]
        except ValueError:
            raise PrepError(path, f"data line {lineno}: non-numeric value")
        if not all(math.isfinite(v) for v in vals):
            raise PrepError(path, f"data line {lineno}: NaN")
        if ch not in chans:
            chans[ch] = (p[idx["muscles"]].split(";"), [])
            order.append(ch)
        chans[ch][1].append(vals)
    out = []
    for ch in order:
        muscles, rows = chans[ch]
        a = np.array(rows)
        out.append((ch, muscles, a[:, 0], a[:, 1], a[:, 2]))
    return out


def resolve_trial(summary, summary_path, override):
    """The trial folder: --trial, else summary.json "trial" (absolute, or relative to the current
    folder or the source tree), else the bundled trial."""
    if override:
        return override
    t = summary.get("trial")
    if t is None:
        return DEFAULT_TRIAL
    if not isinstance(t, str) or not t:
        raise PrepError(summary_path, "\"trial\" is not a path")
    if os.path.isabs(t) or os.path.isdir(t):
        return t
    return os.path.join(SOURCE_DIR, t)


def knee_columns(st):
    """Right-knee {"total", "medial", "lateral"} -> column name, from whatever columns exist
    (left-knee columns, ending _l, are ignored)."""
    found = {}
    for lab in st.labels[1:]:
        low = lab.lower()
        if low.endswith("_l"):
            continue
        for part in ("total", "medial", "lateral"):
            if part in low and part not in found:
                found[part] = lab
    return found


def knee_series(st):
    """{part: values in N} for total/medial/lateral; total = medial + lateral when only those."""
    cols = knee_columns(st)
    series = {part: st.col(lab) for part, lab in cols.items()}
    if "total" not in series and "medial" in series and "lateral" in series:
        series["total"] = series["medial"] + series["lateral"]
    if not series:
        raise PrepError(st.path, "no medial, lateral or total contact column")
    return series


def heel_strike_pct(st, label, threshold=20.0):
    """% gait cycle of the first rise of st's column label (N) through threshold (N), linearly
    interpolated; None when it never rises through it."""
    f = st.col(label)
    for i in range(1, len(f)):
        if f[i - 1] < threshold <= f[i]:
            w = (threshold - f[i - 1]) / (f[i] - f[i - 1])
            return float(st.pct[i - 1] + w * (st.pct[i] - st.pct[i - 1]))
    return None


def shifted(pct, values, shift):
    """A periodic curve over % gait cycle delayed by shift (%): (pct, values at pct - shift)."""
    import numpy as np
    return pct, np.interp((pct - shift) % 100.0, pct, values, period=100.0)


def load(args):
    """Read and check every input; returns a dict of everything the figures need."""
    sol = args.dir
    if not os.path.isdir(sol):
        raise PrepError(sol, "not a folder")
    d = {"dir": sol}
    summary_path = os.path.join(sol, "summary.json")
    d["summary"] = summary = read_json(summary_path)
    d["states"] = Storage(os.path.join(sol, "states.sto"))
    d["controls"] = Storage(os.path.join(sol, "controls.sto"))
    d["grf"] = Storage(os.path.join(sol, "grf.mot"))
    kpath = os.path.join(sol, "knee_contact.sto")
    d["knee"] = Storage(kpath) if os.path.exists(kpath) else None

    trial = resolve_trial(summary, summary_path, args.trial)
    if not os.path.isdir(trial):
        raise PrepError(trial, "trial folder not found")
    d["trial"] = trial
    tj_path = os.path.join(trial, "trial.json")
    tj = read_json(tj_path)
    mass = tj.get("mass_kg")
    if not finite_number(mass) or mass <= 0:
        raise PrepError(tj_path, "mass_kg missing or not a positive number")
    # the body weight the solve normalised its RMS errors by (the model's mass x g), so that the
    # figures and summary.json agree; the trial's mass x g for a summary without it
    bw = summary.get("body_weight_n")
    d["bw"] = float(bw) if finite_number(bw) and bw > 0 else mass * G
    d["mass"] = d["bw"] / G
    scale = summary.get("grf_scale", 1.0)
    if scale is None:
        scale = 1.0
    if not finite_number(scale) or scale <= 0:
        raise PrepError(summary_path, "grf_scale is not a positive number")
    d["grf_scale"] = float(scale)
    d["meas_coords"] = Storage(os.path.join(trial, "coordinates.mot"))
    d["meas_grf"] = Storage(os.path.join(trial, "grf.mot"))
    mk = os.path.join(trial, "knee_contact.sto")
    d["meas_knee"] = Storage(mk) if d["knee"] is not None and os.path.exists(mk) else None

    # every column used, checked now so that nothing is written on bad input
    d["kin"] = []
    for name, title in KINEMATICS:
        d["kin"].append((name, title, d["states"].coordinate(name), d["meas_coords"].coordinate(name)))
    d["grf_series"] = []
    for side in ("r", "l"):
        for comp, title in GRF_COMPONENTS:
            lab = f"ground_force_{side}_{comp}"
            d["grf_series"].append((side, title, d["grf"].col(lab) / d["bw"],
                                    d["meas_grf"].col(lab) * d["grf_scale"] / d["bw"]))
    if d["knee"] is not None:
        d["knee_model"] = {k: v / d["bw"] for k, v in knee_series(d["knee"]).items()}
        d["knee_meas"] = ({k: v / d["bw"] for k, v in knee_series(d["meas_knee"]).items()}
                          if d["meas_knee"] is not None else {})
        d["knee_left"] = (d["knee"].col("contact_total_l") / d["bw"]
                          if d["knee"].has("contact_total_l") else None)
        d["left_strike_pct"] = heel_strike_pct(d["meas_grf"], "ground_force_l_vy")
    mpath = os.path.join(sol, "metabolics.sto")
    d["metab"] = metabolic_breakdown(Storage(mpath)) if os.path.exists(mpath) else None
    d["emg"] = []
    d["emg_skipped"] = []
    for ch, muscles, pct, mean, std in read_emg(EMG_PATH):
        model = [EMG_TO_MODEL.get(m) for m in muscles]
        present = [m for m in model if m is not None and d["controls"].has(m)]
        if not present:
            d["emg_skipped"].append(ch)
            continue
        d["emg"].append((ch, pct, mean, std, [(m, d["controls"].col(m)) for m in present]))
    if not d["emg"]:
        raise PrepError(d["controls"].path, "no right-leg muscle matching an EMG channel")
    d["moments"], d["moments_note"] = joint_moments(args.gaitsim, summary, sol, trial)
    return d


# the joint-moment panels: (coordinate, title)
MOMENT_PANELS = [("hip_flexion", "hip flexion R"), ("hip_adduction", "hip adduction R"),
                 ("knee_flexion", "knee extension R"), ("ankle_angle", "ankle dorsiflexion R"),
                 ("hip_flexion_l", "hip flexion L"), ("hip_adduction_l", "hip adduction L"),
                 ("knee_flexion_l", "knee extension L"), ("ankle_angle_l", "ankle dorsiflexion L")]


def joint_moments(gaitsim, summary, sol, trial):
    """(moments, note): the net joint moments of the solution and of the measured gait by
    `GAITSIM moments` ({"model": (times, columns), "measured": (...)}), or (None, why not) when
    there is no --gaitsim, no model in summary.json, or the command does not take the model (the
    planar model has no hip_adduction)."""
    if not gaitsim:
        return None, "no gaitsim binary given (--gaitsim)"
    model = summary.get("model")
    if not isinstance(model, str) or not os.path.isfile(model):
        return None, "summary.json names no model file"
    try:
        solved = inverse_dynamics_moments(gaitsim, model, os.path.join(sol, "states.sto"),
                                          os.path.join(sol, "grf.mot"))
        measured = inverse_dynamics_moments(gaitsim, model, os.path.join(trial, "coordinates.mot"),
                                            os.path.join(trial, "grf.mot"))
    except PrepError as e:
        return None, f"`gaitsim moments` on this solution: {e.reason}"
    have = [c for c, _ in MOMENT_PANELS if c + "_moment" in solved[1] and c + "_moment" in measured[1]]
    if not have:
        return None, "the model has none of the hip, knee and ankle coordinates"
    return {"model": solved, "measured": measured, "coordinates": have}, None


def axes_style(ax, xlabel, ylabel):
    """Axis labels, small ticks and a light grid."""
    ax.set_xlabel(xlabel, fontsize=7)
    ax.set_ylabel(ylabel, fontsize=7)
    ax.tick_params(labelsize=6)
    ax.grid(alpha=0.3, linewidth=0.5)


def panel_style(ax, xlabel, ylabel):
    """A panel over % gait cycle (0..100)."""
    ax.set_xlim(0, 100)
    axes_style(ax, xlabel, ylabel)


def png_bytes(fig, plt):
    """The figure as PNG bytes (no Software metadata, so reruns are byte-identical); closes it."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def panel_grid(plt, n, ncol, panel_w, panel_h, extra_h):
    """A figure of n panels in rows of ncol (panel_w x panel_h inches each, extra_h for the
    title): (figure, the n axes in reading order); the unused cells of the last row are hidden."""
    nrow = (n + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(panel_w * ncol, panel_h * nrow + extra_h),
                             layout="constrained", squeeze=False)
    axes = axes.ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig, axes[:n]


def fig_kinematics(d, plt):
    n = len(d["kin"])
    fig, axes = panel_grid(plt, n, 6, 2.3, 1.9, 0.6)
    for ax, (name, title, model, meas) in zip(axes, d["kin"]):
        ax.plot(d["meas_coords"].pct, meas, color="0.2", linestyle="--", linewidth=1.2, label="measured")
        ax.plot(d["states"].pct, model, color="tab:red", linewidth=1.2, label="model")
        ax.set_title(title, fontsize=8)
        panel_style(ax, "% gait cycle", "m" if name in TRANSLATIONS else "deg")
    axes[0].legend(fontsize=6, loc="best")
    fig.suptitle("Kinematics: model (solid) vs measured (dashed), right heel strike to right heel strike",
                 fontsize=9)
    return png_bytes(fig, plt)


def fig_grf(d, plt):
    fig, axes = plt.subplots(2, 3, figsize=(10, 5.5), layout="constrained")
    for ax, (side, title, model, meas) in zip(axes.ravel(), d["grf_series"]):
        ax.plot(d["meas_grf"].pct, meas, color="0.2", linestyle="--", linewidth=1.2, label="measured")
        ax.plot(d["grf"].pct, model, color="tab:blue", linewidth=1.2, label="model")
        ax.set_title(f"{'right' if side == 'r' else 'left'} foot, {title}", fontsize=8)
        panel_style(ax, "% gait cycle", "BW")
    axes[0, 0].legend(fontsize=6, loc="best")
    scale = ("" if d["grf_scale"] == 1.0 else
             f"; measured GRF x {d['grf_scale']:.4f} (grf_scale, as tracked)")
    fig.suptitle(f"Ground reaction forces, OpenSim frame (x forward, y up); BW = {d['mass']:.2f} kg x g"
                 f"{scale}", fontsize=9)
    return png_bytes(fig, plt)


def fig_knee(d, plt):
    parts = [p for p in ("total", "medial", "lateral") if p in d["knee_model"] or p in d["knee_meas"]]
    left = d.get("knee_left") is not None
    npanel = len(parts) + left
    fig, axes = plt.subplots(1, npanel, figsize=(3.4 * npanel, 3.2), layout="constrained",
                             squeeze=False)
    left_at = 1 if "total" in parts else 0  # the left knee's panel: right after the right total
    if left:
        # the left knee beside the right total: left over the right's cycle, the right knee's
        # curves delayed to the left heel strike (measured GRF) so that the stances line up
        ax = axes[0][left_at]
        shift = d["left_strike_pct"]
        if shift is not None:
            for name, st, series, style in (
                    ("measured right (eTibia)", d["meas_knee"], d["knee_meas"], "--"),
                    ("model right", d["knee"], d["knee_model"], ":")):
                if st is not None and "total" in series:
                    x, y = shifted(st.pct, series["total"], shift)
                    ax.plot(x, y, color="0.2" if style == "--" else "tab:purple", linestyle=style,
                            linewidth=1.0, label=f"{name}, +{shift:.0f} %")
        ax.plot(d["knee"].pct, d["knee_left"], color="tab:green", linewidth=1.2,
                label="model left (joint reaction)")
        ax.set_title("left knee (1-DOF), total compressive", fontsize=8)
        panel_style(ax, "% gait cycle", "BW")
        ax.legend(fontsize=6, loc="best")
    panel_axes = [a for k, a in enumerate(axes[0]) if not (left and k == left_at)]
    for ax, part in zip(panel_axes, parts):
        if part in d["knee_meas"]:
            ax.plot(d["meas_knee"].pct, d["knee_meas"][part], color="0.2", linestyle="--",
                    linewidth=1.2, label="measured (eTibia)")
        if part in d["knee_model"]:
            ax.plot(d["knee"].pct, d["knee_model"][part], color="tab:purple", linewidth=1.2,
                    label="model")
        ax.set_title(f"right knee, {part}", fontsize=8)
        panel_style(ax, "% gait cycle", "BW")
        ax.legend(fontsize=6, loc="best")
    note = "" if d["meas_knee"] is not None else " (no measured knee_contact.sto in the trial)"
    fig.suptitle(f"Knee contact force, BW = {d['mass']:.2f} kg x g{note}", fontsize=9)
    return png_bytes(fig, plt)


def moment_rms(d, c):
    """RMS difference (N m) of the solution's c moment from the measured one, the measured curve
    interpolated at the solution's phases of the stride (both run from right heel strike to right
    heel strike, so a prediction at another stride time is compared phase by phase)."""
    import numpy as np
    tm, meas = d["moments"]["measured"]
    ts, model = d["moments"]["model"]
    tm, ts = np.asarray(tm), np.asarray(ts)
    m = np.interp((ts - ts[0]) / (ts[-1] - ts[0]), (tm - tm[0]) / (tm[-1] - tm[0]),
                  meas[c + "_moment"])
    return float(np.sqrt(np.mean((np.asarray(model[c + "_moment"]) - m) ** 2)))


def fig_moments(d, plt):
    import numpy as np
    have = d["moments"]["coordinates"]
    fig, axes = panel_grid(plt, len(have), 4, 2.5, 2.0, 0.6)
    titles = dict(MOMENT_PANELS)
    for ax, c in zip(axes, have):
        for key, style, colour, label in (("measured", "--", "0.2", "measured gait"),
                                          ("model", "-", "tab:green", "model")):
            t, cols = d["moments"][key]
            t = np.asarray(t)
            ax.plot(100.0 * (t - t[0]) / (t[-1] - t[0]), np.asarray(cols[c + "_moment"]) / d["mass"],
                    color=colour, linestyle=style, linewidth=1.2, label=label)
        ax.set_title(f"{titles[c]}, RMS diff {moment_rms(d, c):.1f} N m", fontsize=7)
        panel_style(ax, "% gait cycle", "N m/kg")
    axes[0].legend(fontsize=6, loc="best")
    fig.suptitle("Net joint moments by inverse dynamics (gaitsim moments): model (its states and "
                 "GRF) vs measured gait (the trial's coordinates and plates)", fontsize=9)
    return png_bytes(fig, plt)


def fig_excitations(d, plt):
    import numpy as np
    n = len(d["emg"])
    fig, axes = panel_grid(plt, n, 5, 2.4, 2.0, 0.6)
    pct = d["controls"].pct
    shades = ["tab:red", "tab:orange", "tab:brown"]
    for ax, (ch, epct, mean, std, model) in zip(axes, d["emg"]):
        ax.fill_between(epct, np.maximum(mean - std, 0), mean + std, color="0.8", linewidth=0)
        ax.plot(epct, mean, color="0.3", linewidth=1.0, label="EMG (Falisse 2019)")
        for k, (name, e) in enumerate(model):
            peak = float(np.max(np.abs(e)))
            ax.plot(pct, e / peak if peak > 0 else e, color=shades[k % len(shades)], linewidth=1.2,
                    label=name)
        ax.set_title(ch, fontsize=8)
        ax.set_ylim(0, 1.4)
        panel_style(ax, "% gait cycle", "/ peak")
        ax.legend(fontsize=5, loc="upper right")
    fig.suptitle("Right-leg excitations (model, controls.sto) vs EMG envelope mean +- sd of a healthy "
                 "subject (Falisse et al. 2019), each / its peak: timing only", fontsize=9)
    return png_bytes(fig, plt)


def fmt_value(v):
    if v is None:
        return "n/a"
    if not finite_number(v):
        return "n/a"
    return f"{v:.4g}" if abs(v) < 1000 else f"{v:.1f}"


METAB_TOP = 10  # muscles listed in report.md's metabolic table


def metabolic_breakdown(st):
    """Mean metabolic power over the stride per muscle (W; trapezoid over time / stride time) from
    metabolics.sto (gaitsim's per-muscle Umberger 2010 rates, exact, and their "total"): the
    total and the METAB_TOP largest, each with its share of the total."""
    import numpy as np
    t = st.col("time")
    span = t[-1] - t[0]
    muscles = [lab for lab in st.labels[1:] if lab != "total"]
    if not muscles:
        raise PrepError(st.path, "no muscle column")
    mean = {m: float(np.trapz(st.col(m), t) / span) for m in muscles}
    total = float(np.trapz(st.col("total"), t) / span) if st.has("total") else sum(mean.values())
    top = sorted(muscles, key=lambda m: -mean[m])[:METAB_TOP]
    return {"total": total, "top": [(m, mean[m], 100.0 * mean[m] / total if total > 0 else
                                      float("nan")) for m in top]}


def report_md(d, figures):
    s = d["summary"]
    rms = s.get("rms") if isinstance(s.get("rms"), dict) else {}
    lines = ["# gaitsim report", "",
             f"Solution `{os.path.abspath(d['dir'])}`; measured trial `{d['trial']}`; "
             f"body weight {d['mass']:.3f} kg x {G} m/s² = {d['bw']:.1f} N.", "",
             "## Tracking errors (cf. Lin, Walter & Pandy 2018, Table 1)", "",
             "| quantity | unit | this solution (RMS) | Lin et al. 2018, participant 2 |",
             "|---|---|---|---|"]
    for key, name, unit, paper in TABLE1:
        lines.append(f"| {name} | {unit} | {fmt_value(rms.get(key))} | {paper} |")
    lines += ["", "n/a: not in summary.json (or null). GRF errors in body weights, over both feet.", "",
              "## Solve", "", "| fact | value |", "|---|---|"]
    facts = [("problem", "problem"), ("status", "status"), ("iterations", "iterations"),
             ("wall_s", "wall time (s)"), ("nodes", "nodes"), ("stride_time_s", "stride time (s)"),
             ("speed_mps", "speed (m/s)"), ("objective", "objective"),
             ("max_violation", "max constraint violation"), ("grf_scale", "measured GRF scale"),
             ("model", "model")]
    for key, name in facts:
        v = s.get(key)
        if v is None:
            text = "n/a"
        elif isinstance(v, str):
            text = f"`{v}`" if key == "model" else v
        elif isinstance(v, bool):
            text = "yes" if v else "no"
        else:
            text = fmt_value(v)
        lines.append(f"| {name} | {text} |")
    if d.get("metab") is not None:
        mb = d["metab"]
        lines += ["", "## Metabolic power by muscle (Umberger 2010)", "",
                  f"Mean over the stride: {mb['total']:.1f} W in all, "
                  f"{mb['total'] / d['mass']:.2f} W/kg (metabolics.sto, the exact rates). "
                  f"The {len(mb['top'])} largest:", "",
                  "| muscle | mean power (W) | share of the total (%) |", "|---|---|---|"]
        for m, w, share in mb["top"]:
            lines.append(f"| {m} | {w:.1f} | {share:.1f} |")
    lines += ["", "## Figures", ""]
    captions = {
        "kinematics.png": "Kinematics, model vs measured (pelvis, lumbar, hips, knees, ankles), "
                          "% gait cycle from right heel strike (cf. Fig. 1).",
        "grf.png": "Ground reaction forces per foot in BW, model vs measured (cf. Fig. 2)"
                   + ("." if d["grf_scale"] == 1.0 else
                      f"; the measured GRF is scaled by grf_scale = {d['grf_scale']:.4f}, the factor "
                      "the tracking solve applied so that its stride mean equals the model's weight."),
        "knee_contact.png": "Right-knee contact force (total, medial, lateral) in BW, model vs "
                            "measured eTibia (cf. Fig. 3)"
                            + ("." if d.get("knee_left") is None else
                               "; left (1-DOF) knee: compressive joint reaction along the tibia, "
                               "with the right knee's curves delayed to the left heel strike for "
                               "comparison (cf. Fig. 8; in-vivo data exist for the right knee "
                               "only)."),
        "excitations.png": "Right-leg excitations vs EMG envelopes of a healthy subject (Falisse et "
                           "al. 2019), each normalised to its peak: timing only.",
        "joint_moments.png": "Net joint moments by inverse dynamics, N m per kg of body mass "
                             "(`gaitsim moments`): the solution's states under its own GRF vs the "
                             "measured coordinates under the plates; positive in each coordinate's "
                             "positive direction (hip flexion and adduction, knee extension, ankle "
                             "dorsiflexion).",
    }
    for name in figures:
        lines += [f"![{name}]({name})", "", captions[name], ""]
    if d["knee"] is None:
        lines += ["No knee_contact.sto in the solution folder: no knee contact figure.", ""]
    if d["emg_skipped"]:
        lines += ["EMG channels without a model muscle in controls.sto: "
                  + ", ".join(d["emg_skipped"]) + ".", ""]
    if d.get("moments") is not None:
        lines += ["## Joint moments against the measured gait", "",
                  "| coordinate | RMS difference (N m) |", "|---|---|"]
        lines += [f"| {c} | {moment_rms(d, c):.1f} |" for c in d["moments"]["coordinates"]]
        lines.append("")
    else:
        lines += [f"No joint-moment figure: {d.get('moments_note')}.", ""]
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# sweep reports: `gaitsim report SWEEP_DIR` (a folder with sweep.csv and predict_<V>/ folders,
# written by `gaitsim sweep`), figures comparing the speeds like Lin et al. 2018 Fig. 4-6, 8

SWEEP_REQUIRED = ["speed_mps", "stride_time_s", "stride_length_m", "cost_of_transport_j_per_kg_m"]

# Fig. 4 style panels: (coordinate, title)
SWEEP_KINEMATICS = [
    ("pelvis_rz", "pelvis tilt"), ("pelvis_rx", "pelvis list"), ("pelvis_ry", "pelvis rotation"),
    ("pelvis_ty", "pelvis ty (vertical)"), ("lumbar_extension", "lumbar extension"),
    ("hip_flexion", "hip flexion R"), ("hip_adduction", "hip adduction R"),
    ("hip_rotation", "hip rotation R"), ("knee_flexion", "knee flexion R"),
    ("ankle_angle", "ankle angle R"),
    ("hip_flexion_l", "hip flexion L"), ("hip_adduction_l", "hip adduction L"),
    ("knee_flexion_l", "knee flexion L"), ("ankle_angle_l", "ankle angle L"),
    ("subtalar_angle", "subtalar angle R"),
]

# Fig. 6 style panels: JW's right-leg muscles (controls.sto names) and the paper's groups
SWEEP_MUSCLES = [
    ("soleus", "SOL: soleus"), ("gasmed", "GAS: medial"), ("gaslat", "GAS: lateral"),
    ("tibant", "TA: tibialis anterior"), ("vasmed", "VAS: medialis"), ("vaslat", "VAS: lateralis"),
    ("vasint", "VAS: intermedius"), ("recfem", "RF: rectus femoris"),
    ("bflh", "HAMS: biceps femoris long"), ("bfsh", "HAMS: biceps femoris short"),
    ("semimem", "HAMS: semimembranosus"), ("semiten", "HAMS: semitendinosus"),
    ("glmax1", "GMAX: superior"), ("glmax2", "GMAX: middle"), ("glmax3", "GMAX: inferior"),
    ("glmed1", "GMED: anterior"), ("glmed2", "GMED: middle"), ("glmed3", "GMED: posterior"),
    ("iliacus", "iliacus"), ("psoas", "psoas"),
]

# Lin et al. 2018 (p. 1223): predicted stride times 1.30 s at 0.8 m/s and 0.92 s at 2.0 m/s;
# measured averages 1.45 and 0.93 s
PAPER_STRIDE_TIME = [(0.8, 1.30), (2.0, 0.92)]
PAPER_MEASURED_STRIDE_TIME = [(0.8, 1.45), (2.0, 0.93)]


def is_sweep_dir(args):
    """Sweep mode: DIR has sweep.csv, or --track was given, or DIR has predict_* folders and no
    summary.json."""
    d = args.dir
    if os.path.isfile(os.path.join(d, "sweep.csv")) or args.track:
        return True
    if os.path.isdir(d) and not os.path.exists(os.path.join(d, "summary.json")):
        return any(n.startswith("predict_") for n in os.listdir(d))
    return False


def read_csv_rows(path, required):
    """(header, [(line number, row)]): a CSV file's header and its non-blank rows as dicts of the
    stripped strings. PrepError on a missing or unreadable file, no header, a missing required
    column or a row of the wrong length."""
    import csv
    try:
        with open(path, encoding="utf-8", newline="") as f:
            lines = [(n, r) for n, r in enumerate(csv.reader(f), 1) if any(x.strip() for x in r)]
    except FileNotFoundError:
        raise PrepError(path, "file not found")
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise PrepError(path, getattr(e, "strerror", None) or str(e) or "cannot read")
    if not lines:
        raise PrepError(path, "empty (no header line)")
    header = [h.strip() for h in lines[0][1]]
    missing = [c for c in required if c not in header]
    if missing:
        raise PrepError(path, "missing column(s) " + ", ".join(missing))
    rows = []
    for lineno, fields in lines[1:]:
        if len(fields) != len(header):
            raise PrepError(path, f"line {lineno}: {len(fields)} fields, header has {len(header)}")
        rows.append((lineno, {h: x.strip() for h, x in zip(header, fields)}))
    return header, rows


def read_sweep_csv(path):
    """(header, rows): rows as dicts of the raw strings plus "_speed" and, for SWEEP_REQUIRED,
    floats ("nan" allowed: a failed solve); sorted by speed. PrepError on a missing file, a
    missing required column, a row of the wrong length, a non-numeric required value, a speed
    that is not a positive number or repeated, or no rows."""
    header, lines = read_csv_rows(path, SWEEP_REQUIRED)
    rows = []
    for lineno, r in lines:
        for c in SWEEP_REQUIRED:
            try:
                r["_" + c] = float(r[c])
            except ValueError:
                raise PrepError(path, f"line {lineno}: {c} '{r[c]}' is not a number")
        v = r["_speed_mps"]
        if not (math.isfinite(v) and v > 0):
            raise PrepError(path, f"line {lineno}: speed_mps '{r['speed_mps']}' is not a positive number")
        if any(abs(v - q["_speed_mps"]) < 1e-9 for q in rows):
            raise PrepError(path, f"line {lineno}: speed {v:g} m/s repeated")
        r["_speed"] = v
        r["_line"] = lineno
        rows.append(r)
    if not rows:
        raise PrepError(path, "no data rows")
    rows.sort(key=lambda q: q["_speed"])
    return header, rows


def predict_folder(sweep, v):
    """DIR/predict_<V> as `gaitsim sweep` names it (%.4g), else a predict_* folder whose suffix
    is the same number; None when there is none."""
    p = os.path.join(sweep, f"predict_{v:.4g}")
    if os.path.isdir(p):
        return p
    for name in sorted(os.listdir(sweep)):
        if name.startswith("predict_"):
            try:
                if abs(float(name[len("predict_"):]) - v) < 1e-9:
                    return os.path.join(sweep, name)
            except ValueError:
                pass
    return None


def solution_bw(sol, summary, trial_override):
    """(body weight N, source text) of a solution: summary.json body_weight_n, else its trial's
    trial.json mass_kg x g."""
    bw = summary.get("body_weight_n")
    if finite_number(bw) and bw > 0:
        return float(bw), "summary.json body_weight_n"
    trial = resolve_trial(summary, os.path.join(sol, "summary.json"), trial_override)
    tj_path = os.path.join(trial, "trial.json")
    tj = read_json(tj_path)
    mass = tj.get("mass_kg")
    if not finite_number(mass) or mass <= 0:
        raise PrepError(tj_path, "mass_kg missing or not a positive number")
    return mass * G, f"{tj_path} mass_kg x g"


def load_sweep_solution(sol, trial_override, label):
    """One solution folder of a sweep report: {"dir", "label", "summary", "states", "controls",
    "grf", "knee" (or None), "bw"}, every column the figures use checked."""
    spath = os.path.join(sol, "summary.json")
    s = {"dir": sol, "label": label,
         "summary": read_json(spath) if os.path.exists(spath) else {}}
    s["states"] = Storage(os.path.join(sol, "states.sto"))
    s["controls"] = Storage(os.path.join(sol, "controls.sto"))
    s["grf"] = Storage(os.path.join(sol, "grf.mot"))
    kpath = os.path.join(sol, "knee_contact.sto")
    s["knee"] = Storage(kpath) if os.path.exists(kpath) else None
    s["bw"], s["bw_source"] = solution_bw(sol, s["summary"], trial_override)
    s["kin"] = {name: s["states"].coordinate(name) for name, _ in SWEEP_KINEMATICS}
    s["grf_bw"] = {(side, comp): s["grf"].col(f"ground_force_{side}_{comp}") / s["bw"]
                   for side in ("r", "l") for comp in ("vx", "vy")}
    s["exc"] = {m: s["controls"].col(m) for m, _ in SWEEP_MUSCLES if s["controls"].has(m)}
    if s["knee"] is not None:
        s["knee_r"] = knee_series(s["knee"]).get("total")
        if s["knee_r"] is None:
            raise PrepError(kpath, "no right-knee total (or medial and lateral) contact column")
        s["knee_r"] = s["knee_r"] / s["bw"]
        s["knee_l"] = (s["knee"].col("contact_total_l") / s["bw"]
                       if s["knee"].has("contact_total_l") else None)
    return s


def guess_candidates(g, sweep):
    """Where a summary.json "guess" path may be: as written (absolute, or relative to the current
    folder), else relative to the sweep folder's parent and the three folders above it (the
    folder `gaitsim sweep` ran in)."""
    if os.path.isabs(g):
        return [g]
    out = [g]
    a = os.path.dirname(os.path.abspath(sweep))
    for _ in range(4):
        out.append(os.path.join(a, g))
        a = os.path.dirname(a)
    return out


def find_track(args, sweep, solutions):
    """(tracking solution folder or None, note): --track, else the first "guess" of the
    predictions' summaries that is not one of the sweep's own predict_* folders and exists (with
    states.sto)."""
    if args.track:
        if not os.path.isdir(args.track):
            raise PrepError(args.track, "tracking solution folder not found (--track)")
        return args.track, "--track"
    own = {os.path.realpath(s["dir"]) for s in solutions}
    named = []
    for s in solutions:
        g = s["summary"].get("guess")
        if not isinstance(g, str) or not g or g in named:
            continue
        named.append(g)
        if os.path.basename(os.path.normpath(g)).startswith("predict_"):
            continue
        for c in guess_candidates(g, sweep):
            if os.path.isfile(os.path.join(c, "states.sto")) and os.path.realpath(c) not in own:
                return c, f"the guess `{g}` of the predictions' summary.json"
    if not named:
        return None, "no \"guess\" in the predictions' summary.json and no --track"
    return None, ("guess " + ", ".join(f"`{g}`" for g in named if not
                                       os.path.basename(os.path.normpath(g)).startswith("predict_"))
                  + " not found; pass --track DIR")


def load_sweep(args):
    sweep = args.dir
    if not os.path.isdir(sweep):
        raise PrepError(sweep, "not a folder")
    d = {"dir": sweep, "csv_path": os.path.join(sweep, "sweep.csv")}
    if args.track and not os.path.exists(d["csv_path"]):
        raise PrepError(d["csv_path"], "file not found (--track needs a sweep folder)")
    d["header"], d["rows"] = read_sweep_csv(d["csv_path"])
    d["speeds"] = []
    d["skipped"] = []
    for r in d["rows"]:
        v = r["_speed"]
        sol = predict_folder(sweep, v)
        if sol is None:
            d["skipped"].append((v, f"no folder predict_{v:.4g}"))
            continue
        if not os.path.exists(os.path.join(sol, "states.sto")):
            d["skipped"].append((v, f"no states.sto in {os.path.basename(sol)} (solve failed?)"))
            continue
        s = load_sweep_solution(sol, args.trial, f"{v:.4g} m/s")
        s["speed"] = v
        d["speeds"].append(s)
    if not d["speeds"]:
        raise PrepError(sweep, "no predict_<V> folder with states.sto for any speed of sweep.csv")
    track, d["track_note"] = find_track(args, sweep, d["speeds"])
    d["track"] = None
    if track is not None:
        t = load_sweep_solution(track, args.trial, "tracking")
        v = t["summary"].get("speed_mps")
        t["speed"] = float(v) if finite_number(v) else None
        if t["speed"] is not None:
            t["label"] = f"tracking ({t['speed']:.2f} m/s)"
        d["track"] = t
    d["muscles"] = [(m, title) for m, title in SWEEP_MUSCLES
                    if any(m in s["exc"] for s in d["speeds"])]
    if not d["muscles"]:
        raise PrepError(d["speeds"][0]["controls"].path,
                        "none of the right-leg muscles " + ", ".join(m for m, _ in SWEEP_MUSCLES))
    d["missing_muscles"] = [m for m, _ in SWEEP_MUSCLES if m not in dict(d["muscles"])]
    d["has_knee"] = any(s["knee"] is not None for s in d["speeds"])
    d["has_knee_l"] = any(s["knee"] is not None and s["knee_l"] is not None for s in d["speeds"])
    return d


def speed_styles(d, plt):
    """[(solution, colour, linestyle, width)]: speeds slow to fast in viridis, tracking black
    dashed last (drawn on top)."""
    cmap = plt.get_cmap("viridis")
    n = len(d["speeds"])
    out = [(s, cmap(0.05 + 0.85 * (k / (n - 1) if n > 1 else 0.5)), "-", 1.3)
           for k, s in enumerate(d["speeds"])]
    if d["track"] is not None:
        out.append((d["track"], "black", "--", 1.2))
    return out


def sweep_legend(ax, styles):
    """The speeds' legend, in the first panel (Debian's matplotlib 3.6 has no outside legends)."""
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=c, linestyle=ls, linewidth=w) for _, c, ls, w in styles]
    ax.legend(handles, [s["label"] for s, _, _, _ in styles], fontsize=5, loc="best")


def fig_sweep_kinematics(d, plt):
    n = len(SWEEP_KINEMATICS)
    fig, axes = panel_grid(plt, n, 5, 2.4, 2.0, 0.9)
    styles = speed_styles(d, plt)
    for ax, (name, title) in zip(axes, SWEEP_KINEMATICS):
        for s, c, ls, w in styles:
            ax.plot(s["states"].pct, s["kin"][name], color=c, linestyle=ls, linewidth=w)
        ax.set_title(title, fontsize=8)
        panel_style(ax, "% stride", "m" if name in TRANSLATIONS else "deg")
    sweep_legend(axes[0], styles)
    fig.suptitle("Kinematics per speed (cf. Lin et al. 2018 Fig. 4), right heel strike to right "
                 "heel strike", fontsize=9)
    return png_bytes(fig, plt)


def fig_sweep_grf(d, plt):
    fig, axes = plt.subplots(2, 2, figsize=(8, 5.8), layout="constrained")
    styles = speed_styles(d, plt)
    for i, side in enumerate(("r", "l")):
        for j, (comp, title) in enumerate((("vx", "fore-aft"), ("vy", "vertical"))):
            ax = axes[i, j]
            for s, c, ls, w in styles:
                ax.plot(s["grf"].pct, s["grf_bw"][(side, comp)], color=c, linestyle=ls, linewidth=w)
            ax.set_title(f"{'right' if side == 'r' else 'left'} foot, {title}", fontsize=8)
            panel_style(ax, "% stride", "BW")
    sweep_legend(axes[0, 0], styles)
    fig.suptitle("Ground reaction forces per speed, BW (cf. Lin et al. 2018 Fig. 5)", fontsize=9)
    return png_bytes(fig, plt)


def fig_sweep_excitations(d, plt):
    n = len(d["muscles"])
    fig, axes = panel_grid(plt, n, 5, 2.4, 1.9, 0.9)
    styles = speed_styles(d, plt)
    for ax, (m, title) in zip(axes, d["muscles"]):
        for s, c, ls, w in styles:
            if m in s["exc"]:
                ax.plot(s["controls"].pct, s["exc"][m], color=c, linestyle=ls, linewidth=w)
        ax.set_title(f"{title} ({m})", fontsize=7)
        panel_style(ax, "% stride", "excitation")
        ax.set_ylim(bottom=0)
    sweep_legend(axes[0], styles)
    fig.suptitle("Right-leg muscle excitations per speed (cf. Lin et al. 2018 Fig. 6)", fontsize=9)
    return png_bytes(fig, plt)


def fig_sweep_gait(d, plt):
    import numpy as np
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.6), layout="constrained")
    v = np.array([r["_speed"] for r in d["rows"]])
    t = d["track"]
    tv = t["speed"] if t is not None else None
    for ax, key, title, unit in zip(axes, SWEEP_REQUIRED[1:],
                                    ("stride time", "stride length", "cost of transport"),
                                    ("s", "m", "J/(kg m)")):
        y = np.array([r["_" + key] for r in d["rows"]])
        ok = np.isfinite(y)
        ax.plot(v[ok], y[ok], color="tab:blue", marker="o", markersize=4, linewidth=1.2,
                label="this sweep")
        if key == "stride_time_s":
            ax.plot(*zip(*PAPER_STRIDE_TIME), linestyle="none", marker="*", markersize=10,
                    color="tab:red", label="Lin et al. 2018, predicted")
            ax.plot(*zip(*PAPER_MEASURED_STRIDE_TIME), linestyle="none", marker="s",
                    markersize=5, markerfacecolor="none", color="tab:red",
                    label="Lin et al. 2018, measured mean")
        elif key == "stride_length_m":
            ax.plot([p[0] for p in PAPER_STRIDE_TIME], [p[0] * p[1] for p in PAPER_STRIDE_TIME],
                    linestyle="none", marker="*", markersize=10, color="tab:red",
                    label="Lin et al. 2018, predicted (speed x stride time)")
        if t is not None and tv is not None:
            T = t["summary"].get("stride_time_s")
            ty = {"stride_time_s": T,
                  "stride_length_m": tv * T if finite_number(T) else None,
                  "cost_of_transport_j_per_kg_m": t["summary"].get("cost_of_transport_j_per_kg_m")}[key]
            if finite_number(ty):
                ax.plot([tv], [ty], linestyle="none", marker="x", markersize=7, color="black",
                        label="tracking solution")
        ax.set_title(title, fontsize=8)
        axes_style(ax, "speed (m/s)", unit)
        ax.legend(fontsize=6, loc="best")
    fig.suptitle("Stride time, stride length and cost of transport against speed (sweep.csv)",
                 fontsize=9)
    return png_bytes(fig, plt)


def fig_sweep_knee(d, plt):
    left = d["has_knee_l"]
    fig, axes = plt.subplots(1, 1 + left, figsize=(4.2 * (1 + left), 3.6), layout="constrained",
                             squeeze=False)
    styles = [st for st in speed_styles(d, plt) if st[0]["knee"] is not None]
    for k, (key, title) in enumerate((("knee_r", "right knee (6-DOF implant), total"),
                                      ("knee_l", "left knee (1-DOF), compressive joint "
                                                 "reaction"))[:1 + left]):
        ax = axes[0][k]
        for s, c, ls, w in styles:
            if s.get(key) is not None:
                ax.plot(s["knee"].pct, s[key], color=c, linestyle=ls, linewidth=w)
        ax.set_title(title, fontsize=8)
        panel_style(ax, "% stride", "BW")
    sweep_legend(axes[0][0], styles)
    fig.suptitle("Knee contact force per speed, BW (cf. Lin et al. 2018 Fig. 8)", fontsize=9)
    return png_bytes(fig, plt)


def sweep_report_md(d, figures):
    lines = ["# gaitsim sweep report", "",
             f"Sweep `{os.path.abspath(d['dir'])}`: {len(d['rows'])} speed(s) in sweep.csv, "
             f"{len(d['speeds'])} with a solution folder.", ""]
    if d["track"] is not None:
        lines += [f"Tracking solution `{os.path.abspath(d['track']['dir'])}` ({d['track_note']}).",
                  ""]
    else:
        lines += [f"No tracking solution in the figures: {d['track_note']}.", ""]
    sols = d["speeds"] + ([d["track"]] if d["track"] is not None else [])
    bws = sorted({(round(s["bw"], 1), s["bw_source"]) for s in sols})
    lines += ["Body weight (BW), each solution in its own: "
              + "; ".join(f"{bw:.1f} N ({src})" for bw, src in bws) + ".", ""]
    lines += ["## Sweep table (sweep.csv)", "",
              "| " + " | ".join(d["header"]) + " |", "|" + "---|" * len(d["header"])]
    for r in d["rows"]:
        lines.append("| " + " | ".join(r[h] for h in d["header"]) + " |")
    lines += ["", "Lin, Walter & Pandy 2018: predicted stride time 1.30 s at 0.8 m/s and 0.92 s at "
              "2.0 m/s (measured means 1.45 and 0.93 s); stride length from those, 1.04 and 1.84 m.",
              ""]
    for pv, pt in PAPER_STRIDE_TIME:
        r = next((q for q in d["rows"] if abs(q["_speed"] - pv) < 1e-9), None)
        if r is not None and math.isfinite(r["_stride_time_s"]):
            lines.append(f"- {pv:g} m/s: stride time {r['_stride_time_s']:.3f} s against the "
                         f"paper's {pt:.2f} s ({100 * (r['_stride_time_s'] / pt - 1):+.1f} %).")
    if lines[-1] != "":
        lines.append("")
    captions = {
        "kinematics.png": "Pelvis, lumbar, hip, knee, ankle and subtalar angles over the stride "
                          "(% from right heel strike) per speed, slow (dark) to fast (light), and "
                          "the tracking solution dashed (cf. Fig. 4).",
        "grf.png": "Fore-aft and vertical ground reaction forces per foot, in BW, per speed "
                   "(cf. Fig. 5).",
        "excitations.png": "Right-leg muscle excitations per speed: soleus, gastrocnemius, "
                           "tibialis anterior, vasti, rectus femoris, hamstrings, gluteus maximus "
                           "and medius, iliopsoas (cf. Fig. 6).",
        "gait_parameters.png": "Stride time, stride length and cost of transport against speed from "
                               "sweep.csv, with the paper's values at 0.8 and 2.0 m/s (red) and "
                               "the tracking solution (x).",
        "knee_contact.png": "Right-knee total contact force per speed in BW"
                            + (", and the left (1-DOF) knee's compressive joint reaction"
                               if d["has_knee_l"] else "") + " (cf. Fig. 8).",
    }
    lines += ["## Figures", ""]
    for name in figures:
        lines += [f"![{name}]({name})", "", captions[name], ""]
    notes = [f"{v:.4g} m/s: {why}" for v, why in d["skipped"]]
    if notes:
        lines += ["Speeds of sweep.csv not in the figures: " + "; ".join(notes) + ".", ""]
    if d["missing_muscles"]:
        lines += ["Muscles not in any controls.sto: " + ", ".join(d["missing_muscles"]) + ".", ""]
    if not d["has_knee"]:
        lines += ["No knee_contact.sto in any solution folder: no knee contact figure.", ""]
    return "\n".join(lines)


def sweep_figures(d, plt):
    figures = {"kinematics.png": fig_sweep_kinematics(d, plt), "grf.png": fig_sweep_grf(d, plt),
               "excitations.png": fig_sweep_excitations(d, plt),
               "gait_parameters.png": fig_sweep_gait(d, plt)}
    if d["has_knee"]:
        figures["knee_contact.png"] = fig_sweep_knee(d, plt)
    return figures


# ---------------------------------------------------------------------------------------------
# batch reports: `gaitsim report BATCH_DIR` (a folder with batch.csv, written by `gaitsim batch`):
# the batch table and figures of the collected results

BATCH_REQUIRED = ["solve", "command", "status", "wall_s", "stride_time_s", "speed_mps",
                  "cost_of_transport_j_per_kg_m"]
BATCH_NUMERIC = ["speed_target_mps", "exit", "wall_s", "stride_time_s", "speed_mps",
                 "cost_of_transport_j_per_kg_m"]

# Table 1 RMS columns of batch.csv (rms_<summary.json key>): (key, quantity, unit)
BATCH_RMS = [(key, name, unit) for key, name, unit, _ in TABLE1]

# the statuses of gs_batch_record_status and batch-status; others (running, pending) in blue
STATUS_COLOURS = {"done": "tab:green", "stopped short": "tab:orange", "interrupted": "tab:purple",
                  "failed": "tab:red", "skipped": "0.6", "not run": "0.6"}


def read_batch_csv(path):
    """(header, rows): rows as dicts of the raw strings plus "_<column>" floats (nan for an empty
    cell) for BATCH_NUMERIC and the rms_* columns, in file order. PrepError on a missing file, a
    missing required column, a row of the wrong length, a non-numeric number, a repeated solve or
    no rows."""
    header, lines = read_csv_rows(path, BATCH_REQUIRED)
    numeric = [c for c in header if c in BATCH_NUMERIC or c.startswith("rms_")]
    rows = []
    for lineno, r in lines:
        for c in numeric:
            try:
                r["_" + c] = float(r[c]) if r[c] else float("nan")
            except ValueError:
                raise PrepError(path, f"line {lineno}: {c} '{r[c]}' is not a number")
        if not r["solve"]:
            raise PrepError(path, f"line {lineno}: empty solve name")
        if any(q["solve"] == r["solve"] for q in rows):
            raise PrepError(path, f"line {lineno}: solve {r['solve']} repeated")
        rows.append(r)
    if not rows:
        raise PrepError(path, "no data rows")
    return header, rows


def batch_sweeps(batch, rows):
    """{sweep name: [its rows, slow to fast]} from the batch's plan.json (the solves with
    "sweep"; their speeds are the rows NAME_<V>); {} without a readable plan.json."""
    path = os.path.join(batch, "plan.json")
    if not os.path.isfile(path):
        return {}
    solves = read_json(path).get("solves")
    out = {}
    for s in solves if isinstance(solves, list) else []:
        if isinstance(s, dict) and isinstance(s.get("name"), str) and "sweep" in s:
            mine = [r for r in rows if r["command"] == "predict"
                    and r["solve"].startswith(s["name"] + "_")]
            if mine:
                out[s["name"]] = sorted(mine, key=lambda r: r["_speed_mps"]
                                        if math.isfinite(r["_speed_mps"]) else math.inf)
    return out


def load_batch(args):
    batch = args.dir
    if not os.path.isdir(batch):
        raise PrepError(batch, "not a folder")
    d = {"dir": batch, "csv_path": os.path.join(batch, "batch.csv")}
    d["header"], d["rows"] = read_batch_csv(d["csv_path"])
    d["sweeps"] = batch_sweeps(batch, d["rows"])
    in_sweep = {r["solve"] for rows in d["sweeps"].values() for r in rows}
    d["singles"] = [r for r in d["rows"]
                    if r["command"] == "predict" and r["solve"] not in in_sweep]
    d["tracks"] = [r for r in d["rows"] if r["command"] == "track"]
    d["rms"] = [(k, name, unit) for k, name, unit in BATCH_RMS
                if any(math.isfinite(r.get("_rms_" + k, math.nan)) for r in d["tracks"])]
    d["has_speed"] = any(math.isfinite(r["_speed_mps"]) and
                         (math.isfinite(r["_stride_time_s"]) or
                          math.isfinite(r["_cost_of_transport_j_per_kg_m"])) for r in d["rows"])
    return d


def fig_batch_wall(d, plt):
    import numpy as np
    rows = d["rows"]
    fig, ax = plt.subplots(figsize=(6.5, 1.2 + 0.28 * len(rows)), layout="constrained")
    y = np.arange(len(rows))
    w = [r["_wall_s"] if math.isfinite(r["_wall_s"]) else 0.0 for r in rows]
    colours = [STATUS_COLOURS.get(r["status"], "tab:blue") for r in rows]
    ax.barh(y, w, color=colours)
    ax.set_yticks(y, [r["solve"] for r in rows], fontsize=7)
    ax.invert_yaxis()
    for k, r in enumerate(rows):
        ax.annotate(f" {r['status']}", (w[k], k), va="center", fontsize=6)
    ax.set_xlabel("wall time (s)", fontsize=7)
    ax.tick_params(labelsize=6)
    ax.grid(axis="x", alpha=0.3, linewidth=0.5)
    ax.set_xlim(0, 1.3 * max(w + [1.0]))
    fig.suptitle(f"Wall time per solve (batch.csv; {sum(w):.1f} s in all)", fontsize=9)
    return png_bytes(fig, plt)


def fig_batch_speed(d, plt):
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6), layout="constrained")
    cmap = plt.get_cmap("tab10")
    for ax, key, title, unit in zip(axes, ("stride_time_s", "cost_of_transport_j_per_kg_m"),
                                    ("stride time", "cost of transport"), ("s", "J/(kg m)")):
        def points(rows):
            ok = [r for r in rows if math.isfinite(r["_speed_mps"]) and math.isfinite(r["_" + key])]
            return [r["_speed_mps"] for r in ok], [r["_" + key] for r in ok]
        for k, (name, rows) in enumerate(d["sweeps"].items()):
            ax.plot(*points(rows), color=cmap(k % 10), marker="o", markersize=4, linewidth=1.2,
                    label=f"sweep {name}")
        for rows, marker, label in ((d["singles"], "s", "prediction"), (d["tracks"], "x", "track")):
            x, y = points(rows)
            if x:
                ax.plot(x, y, linestyle="none", marker=marker, markersize=6, color="black",
                        markerfacecolor="none" if marker == "s" else None, label=label)
        if key == "stride_time_s":
            ax.plot(*zip(*PAPER_STRIDE_TIME), linestyle="none", marker="*", markersize=10,
                    color="tab:red", label="Lin et al. 2018, predicted")
        ax.set_title(title, fontsize=8)
        axes_style(ax, "speed (m/s)", unit)
        ax.legend(fontsize=6, loc="best")
    fig.suptitle("Stride time and cost of transport against speed (batch.csv)", fontsize=9)
    return png_bytes(fig, plt)


def fig_batch_rms(d, plt):
    import numpy as np
    n = len(d["rms"])
    fig, axes = panel_grid(plt, n, 4, 2.6, 2.2, 0.6)
    names = [r["solve"] for r in d["tracks"]]
    x = np.arange(len(names))
    for ax, (key, title, unit) in zip(axes, d["rms"]):
        v = [r.get("_rms_" + key, math.nan) for r in d["tracks"]]
        ax.bar(x, [q if math.isfinite(q) else 0.0 for q in v], color="tab:blue")
        ax.set_xticks(x, names, fontsize=6, rotation=45, ha="right")
        ax.set_title(title, fontsize=8)
        ax.set_ylabel(unit, fontsize=7)
        ax.tick_params(labelsize=6)
        ax.grid(axis="y", alpha=0.3, linewidth=0.5)
    fig.suptitle("Tracking errors per track, RMS (cf. Lin et al. 2018 Table 1; batch.csv)",
                 fontsize=9)
    return png_bytes(fig, plt)


def batch_figures(d, plt):
    figures = {"wall_time.png": fig_batch_wall(d, plt)}
    if d["has_speed"]:
        figures["gait_speed.png"] = fig_batch_speed(d, plt)
    if d["rms"]:
        figures["rms.png"] = fig_batch_rms(d, plt)
    return figures


def batch_report_md(d, figures):
    rows = d["rows"]
    counts = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    wall = sum(r["_wall_s"] for r in rows if math.isfinite(r["_wall_s"]))
    lines = ["# gaitsim batch report", "",
             f"Batch `{os.path.abspath(d['dir'])}`: {len(rows)} solve(s) in batch.csv: "
             + ", ".join(f"{n} {s}" for s, n in counts.items())
             + f"; wall time {wall:.1f} s in all (the solves' own, summed).", "",
             "## Batch table (batch.csv)", "",
             "| " + " | ".join(d["header"]) + " |", "|" + "---|" * len(d["header"])]
    for r in rows:
        lines.append("| " + " | ".join(r[h] if r[h] else "-" for h in d["header"]) + " |")
    lines += ["", "-: not in the solve's summary.json (no result, or not a track for the RMS "
              "columns).", ""]
    if d["sweeps"]:
        lines += ["Sweeps (plan.json): " + "; ".join(
            f"{name}: " + ", ".join(r["solve"] for r in rs) for name, rs in d["sweeps"].items())
            + ".", ""]
    captions = {
        "wall_time.png": "Wall time per solve (the batch's record of each), coloured by status.",
        "gait_speed.png": "Stride time and cost of transport against the solved speed: each sweep "
                          "a line, other predictions as squares, tracks as x, the paper's "
                          "predicted stride times at 0.8 and 2.0 m/s as stars.",
        "rms.png": "Table 1 RMS tracking errors per track (the rms_* columns of batch.csv).",
    }
    lines += ["## Figures", ""]
    for name in figures:
        lines += [f"![{name}]({name})", "", captions[name], ""]
    if "gait_speed.png" not in figures:
        lines += ["No solve with a speed and a stride time or cost of transport: no "
                  "gait_speed.png.", ""]
    if "rms.png" not in figures:
        lines += ["No track with RMS errors: no rms.png.", ""]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="gaitsim report", description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="solution folder, sweep folder (sweep.csv, predict_*/) or batch "
                    "folder (batch.csv)")
    ap.add_argument("--out", default=None, help="output folder (default DIR/report)")
    ap.add_argument("--into", default=None,
                    help="write into this folder instead of --out (gaitsim report: its temporary "
                         "folder, renamed to --out when this succeeds); messages name --out")
    ap.add_argument("--trial", default=None, help="measured trial folder (default: summary.json trial)")
    ap.add_argument("--gaitsim", default=None,
                    help="solution folder only: the gaitsim binary, for the joint-moment figure "
                         "(`gaitsim report` passes its own)")
    ap.add_argument("--track", default=None,
                    help="sweep folder only: the tracking solution (default: the predictions' guess)")
    args = ap.parse_args(argv)
    out = args.out or os.path.join(args.dir, "report")
    into = args.into or out
    try:
        batch = not args.track and os.path.isfile(os.path.join(args.dir, "batch.csv"))
        sweep = not batch and is_sweep_dir(args)
        d = load_batch(args) if batch else load_sweep(args) if sweep else load(args)
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        if batch:
            figures = batch_figures(d, plt)
            text = batch_report_md(d, list(figures))
        elif sweep:
            figures = sweep_figures(d, plt)
            text = sweep_report_md(d, list(figures))
        else:
            figures = {"kinematics.png": fig_kinematics(d, plt), "grf.png": fig_grf(d, plt)}
            if d["knee"] is not None:
                figures["knee_contact.png"] = fig_knee(d, plt)
            figures["excitations.png"] = fig_excitations(d, plt)
            if d["moments"] is not None:
                figures["joint_moments.png"] = fig_moments(d, plt)
            text = report_md(d, list(figures))
        for name, data in list(figures.items()) + [("report.md", text)]:
            try:
                write_atomic(os.path.join(into, name), data)
            except OSError as e:  # named as in --out, where the file would have gone
                raise PrepError(os.path.join(out, name), e.strerror or str(e))
    except PrepError as e:
        print(f"gaitsim: {e.file}: {e.reason}", file=sys.stderr)
        return 1
    except OSError as e:
        print(f"gaitsim: {e.filename or out}: {e.strerror}", file=sys.stderr)
        return 1
    print(f"report {out}: report.md, " + ", ".join(figures))
    return 0


if __name__ == "__main__":
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not ignored (nohup, &)
        signal.signal(signal.SIGINT, signal.SIG_DFL)  # Ctrl-C ends it at once, no traceback
    sys.exit(main())
