#!/usr/bin/python3
"""report.py: figures and a table for a gaitsim solution folder (`gaitsim report DIR`).

usage: /usr/bin/python3 scripts/report.py DIR [--out D] [--trial T]

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
- report.md: the RMS errors of summary.json beside the paper's participant-2 values (Table 1),
  the solve facts, and links to the figures.
Body weight: trial.json mass_kg x 9.80665 N. Output goes to DIR/report/ (or --out); every file is
written whole (temporary file + rename), report.md last, and only after every input has been
read and checked, so bad input (missing file or column, NaN) leaves nothing new: one line
"gaitsim: FILE: reason" on stderr, exit 1. Debian python3-matplotlib and python3-numpy only.
"""
import argparse
import io
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import PrepError, read_storage, write_atomic  # noqa: E402

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


def read_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            obj = json.load(f)
    except FileNotFoundError:
        raise PrepError(path, "file not found")
    except json.JSONDecodeError as e:
        raise PrepError(path, f"not JSON ({e.msg}, line {e.lineno})")
    except OSError as e:
        raise PrepError(path, e.strerror or "cannot read")
    if not isinstance(obj, dict):
        raise PrepError(path, "not a JSON object")
    return obj


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
    d["bw"] = mass * G
    d["mass"] = mass
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
    return d


def panel_style(ax, xlabel, ylabel):
    ax.set_xlim(0, 100)
    ax.set_xlabel(xlabel, fontsize=7)
    ax.set_ylabel(ylabel, fontsize=7)
    ax.tick_params(labelsize=6)
    ax.grid(alpha=0.3, linewidth=0.5)


def png_bytes(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    return buf.getvalue()


def fig_kinematics(d, plt):
    n = len(d["kin"])
    ncol = 6
    nrow = (n + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(2.3 * ncol, 1.9 * nrow + 0.6), layout="constrained")
    axes = axes.ravel()
    for ax, (name, title, model, meas) in zip(axes, d["kin"]):
        ax.plot(d["meas_coords"].pct, meas, color="0.2", linestyle="--", linewidth=1.2, label="measured")
        ax.plot(d["states"].pct, model, color="tab:red", linewidth=1.2, label="model")
        ax.set_title(title, fontsize=8)
        panel_style(ax, "% gait cycle", "m" if name in TRANSLATIONS else "deg")
    for ax in axes[n:]:
        ax.set_visible(False)
    axes[0].legend(fontsize=6, loc="best")
    fig.suptitle("Kinematics: model (solid) vs measured (dashed), right heel strike to right heel strike",
                 fontsize=9)
    out = png_bytes(fig)
    plt.close(fig)
    return out


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
    fig.suptitle(f"Ground reaction forces, OpenSim frame (x forward, y up); BW = {d['mass']:g} kg x g"
                 f"{scale}", fontsize=9)
    out = png_bytes(fig)
    plt.close(fig)
    return out


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
    fig.suptitle(f"Knee contact force, BW = {d['mass']:g} kg x g{note}", fontsize=9)
    out = png_bytes(fig)
    plt.close(fig)
    return out


def fig_excitations(d, plt):
    import numpy as np
    n = len(d["emg"])
    ncol = 5
    nrow = (n + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(2.4 * ncol, 2.0 * nrow + 0.6), layout="constrained",
                             squeeze=False)
    axes = axes.ravel()
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
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle("Right-leg excitations (model, controls.sto) vs EMG envelope mean +- sd of a healthy "
                 "subject (Falisse et al. 2019), each / its peak: timing only", fontsize=9)
    out = png_bytes(fig)
    plt.close(fig)
    return out


def fmt_value(v):
    if v is None:
        return "n/a"
    if not finite_number(v):
        return "n/a"
    return f"{v:.4g}" if abs(v) < 1000 else f"{v:.1f}"


def report_md(d, figures):
    s = d["summary"]
    rms = s.get("rms") if isinstance(s.get("rms"), dict) else {}
    lines = ["# gaitsim report", "",
             f"Solution `{os.path.abspath(d['dir'])}`; measured trial `{d['trial']}`; "
             f"body weight {d['mass']:g} kg x {G} m/s² = {d['bw']:.1f} N.", "",
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
    }
    for name in figures:
        lines += [f"![{name}]({name})", "", captions[name], ""]
    if d["knee"] is None:
        lines += ["No knee_contact.sto in the solution folder: no knee contact figure.", ""]
    if d["emg_skipped"]:
        lines += ["EMG channels without a model muscle in controls.sto: "
                  + ", ".join(d["emg_skipped"]) + ".", ""]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="gaitsim report", description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="solution folder")
    ap.add_argument("--out", default=None, help="output folder (default DIR/report)")
    ap.add_argument("--trial", default=None, help="measured trial folder (default: summary.json trial)")
    args = ap.parse_args(argv)
    out = args.out or os.path.join(args.dir, "report")
    try:
        d = load(args)
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        figures = {"kinematics.png": fig_kinematics(d, plt), "grf.png": fig_grf(d, plt)}
        if d["knee"] is not None:
            figures["knee_contact.png"] = fig_knee(d, plt)
        figures["excitations.png"] = fig_excitations(d, plt)
        text = report_md(d, list(figures))
        for name, data in figures.items():
            write_atomic(os.path.join(out, name), data)
        write_atomic(os.path.join(out, "report.md"), text)
    except PrepError as e:
        print(f"gaitsim: {e.file}: {e.reason}", file=sys.stderr)
        return 1
    except OSError as e:
        print(f"gaitsim: {e.filename or out}: {e.strerror}", file=sys.stderr)
        return 1
    print(f"report {out}: report.md, " + ", ".join(figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
