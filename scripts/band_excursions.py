#!/usr/bin/env python3
"""Where a prediction lies against eq. 3's band around a guess (Lin, Walter & Pandy 2018, eq. 3:
q and qdot within a band around the tracking solution; pelvis_tx itself has no band, its speed
has). The half-widths are those gaitsim predict wrote in SOLUTION_DIR/summary.json
(band_half_widths_at_scale_1), times the band scale.

usage: band_excursions.py GUESS_DIR SOLUTION_DIR [--band-scale F] [--model FILE] [--json]

Compares SOLUTION_DIR/states.sto with GUESS_DIR/states.sto node by node (the same node count)
and gives, per coordinate and per speed ("NAME_speed"):
  at_edge   nodes within 0.1 % of the half-width from the band's edge (summary.json's
            band_active_nodes counts the same nodes when the band is the solve's own);
  beyond    nodes farther from the guess than the half-width (a solution whose band was centred
            elsewhere, e.g. restarted from itself);
  largest   the largest distance from the guess (deg, m, deg/s or m/s, as states.sto).
Only coordinates at the edge or beyond are listed. --band-scale defaults to SOLUTION_DIR's
summary.json band_scale; --model to its summary.json model (slide joints from the MJCF).
Markdown table on stdout, or with --json {"band_scale", "at_edge", "beyond", "largest"}.
Bad input: one line naming the file or option, exit 2.
"""
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import PrepError, read_json, read_storage  # noqa: E402

DEG = 180 / math.pi
# summary.json's band_half_widths_at_scale_1 keys, and the factor to states.sto's units
WIDTH_KEYS = {"rot": ("rotation_rad", DEG), "trans": ("translation_m", 1.0),
              "rot_speed": ("rotation_speed_rad_per_s", DEG),
              "trans_speed": ("translation_speed_m_per_s", 1.0)}
EDGE = 1e-3  # "at the edge": within this fraction of the half-width (cmd_solve.c's rule)


def fail(what, why):
    print(f"band_excursions.py: {what}: {why}", file=sys.stderr)
    sys.exit(2)


def slide_joints(model):
    try:
        root = ET.parse(model).getroot()
    except (OSError, ET.ParseError) as e:
        fail(model, f"cannot read the model ({e})")
    return {j.get("name") for j in root.iter("joint") if j.get("type") == "slide"}


def half_widths(summary, summary_path):
    """Half-widths at scale 1 in states.sto's units (deg, m, deg/s, m/s), from summary.json."""
    widths = summary.get("band_half_widths_at_scale_1")
    if not isinstance(widths, dict):
        fail(summary_path, "no band_half_widths_at_scale_1 (not a gaitsim predict solution)")
    out = {}
    for kind, (key, unit) in WIDTH_KEYS.items():
        v = widths.get(key)
        if not isinstance(v, (int, float)) or not v >= 0:
            fail(summary_path, f"band_half_widths_at_scale_1.{key}: not a number >= 0")
        out[kind] = v * unit
    return out


def excursions(guess, sol, scale, slides, width):
    """(at_edge, beyond, largest) dicts keyed by coordinate or NAME_speed."""
    _, hg, g = guess
    _, hs, s = sol
    at_edge, beyond, largest = {}, {}, {}
    for name in hs[1:]:
        if "." in name or name not in hg:  # muscle states, or not in the guess
            continue
        speed = name.endswith("_u")
        coord = name[:-2] if speed else name
        if coord == "pelvis_tx" and not speed:
            continue
        kind = ("trans" if coord in slides else "rot") + ("_speed" if speed else "")
        hw = scale * width[kind]
        if not hw > 0:
            continue
        js, jg = hs.index(name), hg.index(name)
        dist = [abs(s[k][js] - g[k][jg]) for k in range(len(s))]
        key = coord + ("_speed" if speed else "")
        edge = sum(abs(d - hw) <= EDGE * hw for d in dist)
        past = sum(d > hw * (1 + EDGE) for d in dist)
        if edge or past:
            at_edge[key], beyond[key], largest[key] = edge, past, max(dist)
    return at_edge, beyond, largest


def main(argv):
    args, opts = [], {}
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--json":
            opts["json"] = True
        elif a in ("--band-scale", "--model"):
            if i + 1 >= len(argv):
                fail(a, "needs a value")
            opts[a] = argv[i + 1]
            i += 1
        elif a.startswith("--"):
            fail(a, "unknown option")
        else:
            args.append(a)
        i += 1
    if len(args) != 2:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    guess_dir, sol_dir = args
    try:
        guess = read_storage(os.path.join(guess_dir, "states.sto"))
        sol = read_storage(os.path.join(sol_dir, "states.sto"))
        summary_path = os.path.join(sol_dir, "summary.json")
        summary = read_json(summary_path) if os.path.isfile(summary_path) else {}
    except PrepError as e:
        fail(e.file, e.reason)
    if len(guess[2]) != len(sol[2]):
        fail(sol_dir, f"{len(sol[2])} nodes against the guess's {len(guess[2])}")
    try:
        scale = float(opts.get("--band-scale", summary.get("band_scale", "none")))
    except (TypeError, ValueError):
        fail("--band-scale" if "--band-scale" in opts else summary_path,
             "not a number" if "--band-scale" in opts else "no band_scale: give --band-scale")
    if not (0 <= scale <= 10):
        fail("--band-scale", "outside 0-10")
    model = opts.get("--model", summary.get("model"))
    if not model:
        fail(summary_path, "no model named: give --model")
    width = half_widths(summary, summary_path)
    slides = slide_joints(model)
    at_edge, beyond, largest = excursions(guess, sol, scale, slides, width)
    if opts.get("json"):
        print(json.dumps({"band_scale": scale, "at_edge": at_edge, "beyond": beyond,
                          "largest": largest}, indent=1))
        return
    print(f"eq. 3's band x {scale:g} around {guess_dir}: {sol_dir}, {len(sol[2])} nodes\n")
    print("| coordinate | half-width | nodes at the edge | nodes beyond | largest distance |")
    print("|---|---|---|---|---|")
    for key in at_edge:
        speed = key.endswith("_speed")
        coord = key[:-6] if speed else key
        kind = ("trans" if coord in slides else "rot") + ("_speed" if speed else "")
        unit = {"rot": "deg", "trans": "m", "rot_speed": "deg/s", "trans_speed": "m/s"}[kind]
        print(f"| {key} | {scale * width[kind]:.4g} {unit} | {at_edge[key]} | {beyond[key]} "
              f"| {largest[key]:.4g} {unit} |")


if __name__ == "__main__":
    main(sys.argv[1:])
