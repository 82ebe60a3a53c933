#!/usr/bin/python3
"""Mesh convergence figures of two resolutions (issue 19, item 4): the tracking solve and the
2.0 m/s prediction solved at a coarse and at a fine mesh, compared figure by figure.

usage: scripts/mesh_convergence.py TRACK_COARSE PREDICT_COARSE TRACK_FINE PREDICT_FINE

Each argument is a solution folder of `gaitsim track` / `gaitsim predict` (summary.json,
grf.mot). Figures, each taken from the coarse and the fine solution, and the target the coarse
one must meet against the fine one:
  - stride time of the prediction (s): within 1 % (the tracking's is the trial's);
  - peak vertical ground reaction per foot (BW, over the nodes: grf.mot ground_force_{r,l}_vy
    divided by summary.json body_weight_n), tracking and prediction: within 0.05 BW;
  - knee contact RMS against the in-vivo measurement (BW, tracking, summary.json
    rms.knee_contact_bw): within 0.02 BW;
  - cost of transport of the prediction (J/(kg m), summary.json cost_of_transport_j_per_kg_m):
    within 2 %.
Prints a Markdown table (figure, coarse, fine, difference, target, met) and the nodes and status
of the four solves; the last line is "mesh_convergence: N of M targets met". Exit 0 when every
target is met, 3 when one is missed, 1 on unreadable input (one line naming the file).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import PrepError, read_json, read_storage  # noqa: E402


def load(folder):
    path = os.path.join(folder, "summary.json")
    s = read_json(path)
    if not s.get("body_weight_n"):
        raise PrepError(path, "no body_weight_n")
    _, labels, rows = read_storage(os.path.join(folder, "grf.mot"))
    peaks = {}
    for side in "rl":
        col = f"ground_force_{side}_vy"
        if col not in labels:
            raise PrepError(os.path.join(folder, "grf.mot"), f"no column {col}")
        k = labels.index(col)
        peaks[side] = max(r[k] for r in rows) / s["body_weight_n"]
    return s, peaks


def figure(s, key, *path):
    v = s
    for p in (key,) + path:
        if not isinstance(v, dict) or p not in v:
            return None
        v = v[p]
    return float(v)


def main(argv):
    if len(argv) != 5:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    try:
        tc, pc, tf, pf = (load(a) for a in argv[1:])
    except PrepError as e:
        print(f"mesh_convergence: {e}", file=sys.stderr)
        return 1
    rows = []  # (figure, coarse, fine, difference text, target text, met)

    def absolute(name, a, b, tol, unit):
        if a is None or b is None:
            rows.append((name, a, b, "missing", f"<= {tol} {unit}", False))
            return
        d = a - b
        rows.append((name, a, b, f"{d:+.4f} {unit}", f"<= {tol} {unit}", abs(d) <= tol))

    def relative(name, a, b, tol_pct):
        if a is None or b is None or b == 0:
            rows.append((name, a, b, "missing", f"<= {tol_pct} %", False))
            return
        d = 100.0 * (a - b) / b
        rows.append((name, a, b, f"{d:+.2f} %", f"<= {tol_pct} %", abs(d) <= tol_pct))

    relative("prediction 2.0 m/s: stride time (s)", figure(pc[0], "stride_time_s"),
             figure(pf[0], "stride_time_s"), 1)
    for label, (c, f) in (("tracking", (tc, tf)), ("prediction 2.0 m/s", (pc, pf))):
        for side, foot in (("r", "right"), ("l", "left")):
            absolute(f"{label}: peak vertical GRF, {foot} (BW)", c[1][side], f[1][side], 0.05, "BW")
    absolute("tracking: knee contact RMS (BW)", figure(tc[0], "rms", "knee_contact_bw"),
             figure(tf[0], "rms", "knee_contact_bw"), 0.02, "BW")
    relative("prediction 2.0 m/s: cost of transport (J/(kg m))",
             figure(pc[0], "cost_of_transport_j_per_kg_m"),
             figure(pf[0], "cost_of_transport_j_per_kg_m"), 2)

    def num(v):
        return "-" if v is None else f"{v:.4f}"

    print("| solve | coarse: nodes, status | fine: nodes, status |")
    print("|---|---|---|")
    for name, c, f in (("tracking", tc, tf), ("prediction 2.0 m/s", pc, pf)):
        print(f"| {name} | {c[0].get('nodes')}, {c[0].get('status')} | "
              f"{f[0].get('nodes')}, {f[0].get('status')} |")
    print()
    print("| figure | coarse | fine | coarse - fine | target | met |")
    print("|---|---|---|---|---|---|")
    for name, a, b, d, t, ok in rows:
        print(f"| {name} | {num(a)} | {num(b)} | {d} | {t} | {'yes' if ok else 'NO'} |")
    met = sum(1 for r in rows if r[5])
    print(f"mesh_convergence: {met} of {len(rows)} targets met")
    return 0 if met == len(rows) else 3


if __name__ == "__main__":
    sys.exit(main(sys.argv))
