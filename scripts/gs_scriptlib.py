"""Helpers shared by gaitsim's data-preparation scripts (standard library only).

- PrepError: a reportable input problem (file and reason); scripts print it as
  "SCRIPT: FILE: reason" and exit 1.
- write_atomic: write text (or bytes) to a temporary file in the target's folder, then rename
  over the target, so a crash never leaves half a file and an earlier file stays until the new one
  is whole.
- read_json: a JSON object file (summary.json, trial.json) as a dict.
- read_storage: an OpenSim storage file (.sto/.mot: header lines, endheader, a tab-separated label
  line, numeric rows) as (header lines, labels, rows).
- storage_text: the text of such a file.
- inspect_muscles: the muscle rows of `gaitsim inspect` (lengths, force, power, moment arms).
"""
import json
import os
import subprocess
import sys
import tempfile


class PrepError(Exception):
    """A reportable input problem: file and reason."""

    def __init__(self, file, reason):
        super().__init__(f"{file}: {reason}")
        self.file = file
        self.reason = reason


def write_atomic(path, text):
    """Write text (str, as UTF-8) or bytes to a temporary file in the same folder (created if
    missing), then rename over path. The file gets the usual 0666 & ~umask mode."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=folder)
    try:
        if isinstance(text, bytes):
            with os.fdopen(fd, "wb") as f:
                f.write(text)
        else:
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
                f.write(text)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read_json(path):
    """The JSON object in path (a dict). Raises PrepError for a missing or unreadable file, text
    that is not JSON, or JSON that is not an object."""
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


def read_storage(path):
    """(header lines, labels, rows) of an OpenSim storage file: the lines before "endheader",
    the column labels (the line after it; tab-separated, or whitespace without tabs) and the rows
    as lists of floats ("nan" parses, so callers check finiteness of what they use). Raises
    PrepError for a missing or unreadable file, no endheader, no rows, a non-numeric value or a
    row whose length differs from the labels'."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
    except FileNotFoundError:
        raise PrepError(path, "file not found")
    except OSError as e:
        raise PrepError(path, e.strerror or "cannot read")
    try:
        end = [line.strip() for line in lines].index("endheader")
    except ValueError:
        raise PrepError(path, "no endheader line")
    if end + 1 >= len(lines) or not lines[end + 1].strip():
        raise PrepError(path, "no column labels after endheader")
    head = lines[end + 1].strip()
    labels = head.split("\t") if "\t" in head else head.split()
    rows = []
    for lineno, line in enumerate(lines[end + 2:], end + 3):
        if not line.strip():
            continue
        try:
            row = [float(x) for x in line.split()]
        except ValueError:
            raise PrepError(path, f"line {lineno}: non-numeric value")
        if len(row) != len(labels):
            raise PrepError(path, f"line {lineno}: {len(row)} values, {len(labels)} labels")
        rows.append(row)
    if not rows:
        raise PrepError(path, "no data rows")
    return lines[:end], labels, rows


def storage_text(name, labels, rows, in_degrees, notes=(), cell=lambda v: f"{v:.8g}"):
    """The text of an OpenSim storage file: header (name, version, sizes, inDegrees, DataType,
    then the lines of notes), endheader, the tab-separated labels (time first), one line per row
    of numbers, each written by cell."""
    out = [name, "version=1", f"nRows={len(rows)}", f"nColumns={len(labels)}",
           f"inDegrees={'yes' if in_degrees else 'no'}", "DataType=double"]
    out += list(notes)
    out += ["endheader", "\t".join(labels)]
    out += ["\t".join(cell(v) for v in r) for r in rows]
    return "\n".join(out) + "\n"


def run_gaitsim(gaitsim, args):
    """The standard output of `GAITSIM ARGS...`; PrepError naming gaitsim when it cannot be run
    or exits non-zero (the reason: args[0] and its stderr)."""
    try:
        res = subprocess.run([gaitsim] + args, capture_output=True, text=True)
    except OSError as e:
        raise PrepError(gaitsim, f"cannot run ({e.strerror})")
    if res.returncode != 0:
        raise PrepError(gaitsim, f"{args[0]} failed: {res.stderr.strip()}")
    return res.stdout


def inspect_muscles(gaitsim, model, pose_file, time, activation=None):
    """{muscle: {"lMT" (m), "lM" (m), "lM_norm" (-), "F" (N), "Edot" (W), "arms": {coordinate:
    moment arm (m or m/m)}}} in the model's order, from `GAITSIM inspect MODEL --pose POSE_FILE
    --time TIME [--activation A]` (app/cmd_inspect.c: a header line starting "muscle", then one
    row per muscle, then the contact spheres). PrepError naming gaitsim when it fails."""
    args = ["inspect", model, "--pose", pose_file, "--time", repr(time)]
    if activation is not None:
        args += ["--activation", repr(activation)]
    rows = run_gaitsim(gaitsim, args).splitlines()
    head = next((k for k, r in enumerate(rows) if r.startswith("muscle ")), None)
    if head is None:
        raise PrepError(gaitsim, "inspect printed no muscle table")
    out = {}
    for line in rows[head + 1:]:
        f = line.split()
        if len(f) < 7 or f[0] == "contact":
            break
        out[f[0]] = {"lMT": float(f[2]), "lM": float(f[3]), "lM_norm": float(f[4]),
                     "F": float(f[5]), "Edot": float(f[6]),
                     "arms": {c: float(r) for c, r in (pair.split("=") for pair in f[7:])}}
    return out


def _table_cells(line):
    """The cells of a data row of one of `gaitsim work`'s markdown tables, else None (a header
    or separator row, or a line outside the tables)."""
    if not line.startswith("|"):
        return None
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if cells[0] in ("source", "coordinate") or cells[0].startswith("---"):
        return None
    return cells


def mechanical_work(gaitsim, model, pose_file):
    """({source: (positive, negative, net) J}, distance the centre of mass travelled (m),
    {coordinate: (positive, negative, positive in stance, negative in stance) J}) from `GAITSIM
    work MODEL --pose POSE_FILE --joints` (app/cmd_work.c: a markdown table of the sources, the
    energy balance and the distance, then the muscles' work per coordinate). PrepError naming
    gaitsim when it fails."""
    out = run_gaitsim(gaitsim, ["work", model, "--pose", pose_file, "--joints"])
    rows, joints, distance = {}, {}, None
    for line in out.splitlines():
        if line.startswith("centre of mass travelled"):
            distance = float(line.split()[4])
        cells = _table_cells(line)
        if cells is None or len(cells) != 5:
            continue
        if distance is None:
            rows[cells[0]] = tuple(float(c) for c in cells[1:4])
        else:
            joints[cells[0]] = tuple(float(c) for c in cells[1:5])
    if not rows or distance is None:
        raise PrepError(gaitsim, "work printed no table")
    return rows, distance, joints


def inverse_dynamics_work(gaitsim, model, pose_file, grf_file):
    """{coordinate: (positive, negative, positive in stance, negative in stance) J}: the net
    joint work of inverse dynamics from `GAITSIM work MODEL --pose POSE_FILE --grf GRF_FILE`
    (app/cmd_work.c), e.g. of a trial's measured gait. PrepError naming gaitsim when it fails."""
    out = run_gaitsim(gaitsim, ["work", model, "--pose", pose_file, "--grf", grf_file])
    joints = {}
    for line in out.splitlines():
        cells = _table_cells(line)
        if cells is not None and len(cells) == 5:
            joints[cells[0]] = tuple(float(c) for c in cells[1:5])
    if not joints:
        raise PrepError(gaitsim, "work printed no joint table")
    return joints


def inverse_dynamics_moments(gaitsim, model, pose_file, grf_file):
    """(times (s), {column: [values]}): the net joint moments of inverse dynamics from `GAITSIM
    moments MODEL --pose POSE_FILE --grf GRF_FILE --out F` (app/cmd_moments.c; columns
    COORD_moment in N m, COORD_force in N), F a temporary file. PrepError naming gaitsim when it
    fails."""
    with tempfile.TemporaryDirectory(prefix="gs_moments_") as tmp:
        out = os.path.join(tmp, "inverse_dynamics.sto")
        run_gaitsim(gaitsim, ["moments", model, "--pose", pose_file, "--grf", grf_file,
                              "--out", out])
        _, labels, rows = read_storage(out)
    return [r[0] for r in rows], {lab: [r[k] for r in rows] for k, lab in enumerate(labels)
                                  if k > 0}


# Published human figures the mechanical work is compared with (docs/VALIDATION.md,
# scripts/physiology_figures.py):
# Zelik & Kuo 2010, J Exp Biol 213:4257, at 1.25 m/s: the soft tissues' negative work per
# collision and their rebound after it (J), from joint work against centre-of-mass work
SOFT_TISSUE_COLLISION_J, SOFT_TISSUE_REBOUND_J = 7.5, 4.0
# Montgomery & Grabowski 2018, R Soc Open Sci 5:180550 (twenty adults, 1.00-1.50 m/s, stance,
# sagittal joint work): the knee's share of the leg's negative work (0.39 at 1.00 m/s, 0.45 at
# 1.50 m/s, over their slopes) and the ankle's of the positive (0.42 at every speed and slope)
KNEE_NEGATIVE_SHARE, ANKLE_POSITIVE_SHARE = "0.39-0.45", "0.42"
SAGITTAL = ("hip_flexion", "knee_flexion", "ankle_angle")


def stance_work(joints, suffix):
    """One leg's muscle work in stance at the SAGITTAL coordinates (suffix "" right, "_l" left;
    mechanical_work's joints): (negative [hip, knee, ankle], positive [...], the knee's share of
    the negative, the ankle's of the positive), or None when a coordinate is missing."""
    work = [joints.get(c + suffix) for c in SAGITTAL]
    if None in work:
        return None
    neg, pos = [w[3] for w in work], [w[2] for w in work]
    return (neg, pos, neg[1] / sum(neg) if sum(neg) else float("nan"),
            pos[2] / sum(pos) if sum(pos) else float("nan"))


def results_and_gaitsim(argv, prog, doc):
    """(RESULTS, GAITSIM or None) from a script's arguments `[RESULTS] [--gaitsim GAITSIM]`
    (RESULTS default "results"), or an exit status (int) after printing the usage (the second
    paragraph of doc) or the error when they are wrong."""
    args = argv[1:]
    gaitsim = None
    if "--gaitsim" in args:
        i = args.index("--gaitsim")
        if i + 1 >= len(args):
            print(f"{prog}: --gaitsim needs the binary's path", file=sys.stderr)
            return 2
        gaitsim = args[i + 1]
        del args[i:i + 2]
    results = args[0] if args else "results"
    if len(args) > 1 or results in ("-h", "--help"):
        print(doc.split("\n\n")[1], file=sys.stderr)
        return 2
    return results, gaitsim

