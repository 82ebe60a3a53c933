#!/usr/bin/env bash
# gaitsim moments: net joint moments by inverse dynamics into a .sto.
# - JW's measured gait (jw_ngait_og5: coordinates.mot, the force plates' grf.mot) with
#   jw_fullbody_knee6: exit 0, one column per coordinate (26, OpenSim's names: COORD_moment,
#   COORD_force), and the right leg's peaks within 5 N m of OpenSim's Inverse Dynamics tool on
#   JW's own model and the same trial (the Knee Grand Challenge's ID_ngait_og5.csv, not bundled:
#   ankle_angle -71.8 N m, knee_flexion -25.5 ... +31.6 N m, hip_adduction -51.6 N m; this
#   command: -71.6, -28.7 ... +33.0, -56.1; the trial's coordinates and plates are resampled and
#   filtered by scripts/prepare_trial.py and the arms are welded, so the curves differ by a few
#   N m).
# - Statics, against Newton: the trial's first pose held still (three equal rows, zero speeds and
#   accelerations) with no ground reaction, the pelvis's three slides carry the body's weight
#   (the norm of pelvis_tx/_ty/_tz_force = total mass x 9.80665 within 1e-6 relative); with the
#   right foot pushing straight up with that weight (anywhere under it), they carry nothing
#   (within 1e-6 N).
# - Bad input before any work, one line naming the file or option: no --out (exit 2), --out in a
#   folder that does not exist (exit 1, nothing written), --out naming the --pose file (exit 1,
#   the file unchanged), a coordinates file as --grf (exit 1). An existing --out is replaced whole.
# usage: moments.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

T=$src/mjmodels/trials/jw_ngait_og5 M=$src/mjmodels/jw_fullbody_knee6.xml
"$gaitsim" moments "$M" --pose "$T/coordinates.mot" --grf "$T/grf.mot" --out id.sto >out.txt 2>err.txt
status=$?
check "measured gait: exit 0 (got $status; $(cat err.txt))" test "$status" -eq 0
check "measured gait: the summary line ($(cat out.txt))" grep -q "moments: wrote id.sto: 134 rows" out.txt
check "measured gait: columns and the right leg's peaks against OpenSim's ID" /usr/bin/python3 - id.sto <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
head = lines.index("endheader")
labels = lines[head + 1].split("\t")
rows = [[float(x) for x in l.split("\t")] for l in lines[head + 2:]]
col = {lab: [r[k] for r in rows] for k, lab in enumerate(labels)}
ok = len(labels) == 27 and "knee_tx_force" in col and "lumbar_rotation_moment" in col
ok &= all(len(r) == 27 for r in rows) and len(rows) == 134
# OpenSim's Inverse Dynamics tool on JW_AllBody_scaled.osim, trial ngait_og5 over the same stride
ref = [(min(col["ankle_angle_moment"]), -71.8), (min(col["knee_flexion_moment"]), -25.5),
       (max(col["knee_flexion_moment"]), 31.6), (min(col["hip_adduction_moment"]), -51.6)]
ok &= all(abs(a - b) <= 5.0 for a, b in ref)
print("peaks (this, OpenSim):", ref, file=sys.stderr)
sys.exit(0 if ok else 1)
PY

# statics: the first pose held still, with and without a ground reaction equal to the weight
/usr/bin/python3 - "$T/coordinates.mot" "$T/grf.mot" <<'PY'
import sys
def parts(path):
    lines = open(path).read().splitlines()
    head = lines.index("endheader")
    return lines[:head + 1], lines[head + 1], lines[head + 2]
def write(path, header, labels, first, values=None):
    cells = first.split("\t")
    if values is not None:
        cells = [cells[0]] + values
    body = ["\t".join([f"{t:g}"] + cells[1:]) for t in (0.0, 0.01, 0.02)]
    header = [l.replace("nRows=134", "nRows=3") for l in header]
    open(path, "w").write("\n".join(header + [labels] + body) + "\n")
header, labels, first = parts(sys.argv[1])
write("still.mot", header, labels, first)
header, labels, first = parts(sys.argv[2])
names = labels.split("\t")[1:]
write("none.mot", header, labels, first, ["0"] * len(names))
weight = 62.636148826293962 * 9.80665
pushed = ["0"] * len(names)
# the right foot's force straight up (OpenSim ground frame: y up) at a point under it (its CoP
# at heel strike), no free moment
cop = first.split("\t")[1:]
for k, n in enumerate(names):
    if n == "ground_force_r_vy":
        pushed[k] = repr(weight)
    if n in ("ground_force_r_px", "ground_force_r_py", "ground_force_r_pz"):
        pushed[k] = cop[k]
write("push.mot", header, labels, first, pushed)
PY
"$gaitsim" info "$M" --json >info.json
mass_ok=$(/usr/bin/python3 -c 'import json,sys; print(abs(json.load(open(sys.argv[1]))["mass_kg"] - 62.636148826293962) < 1e-9)' info.json)
check "statics: the model's mass is the one the test uses" test "$mass_ok" = True
"$gaitsim" moments "$M" --pose still.mot --grf none.mot --out still.sto >/dev/null 2>err.txt
status=$?
"$gaitsim" moments "$M" --pose still.mot --grf push.mot --out push.sto >/dev/null 2>>err.txt
status=$((status + $?))
check "statics: exit 0 (got $status; $(cat err.txt))" test "$status" -eq 0
check "statics: the pelvis carries the weight, or nothing when the foot does" /usr/bin/python3 - <<'PY'
import math, sys
def pelvis(path):
    lines = open(path).read().splitlines()
    head = lines.index("endheader")
    labels = lines[head + 1].split("\t")
    out = []
    for l in lines[head + 2:]:
        r = dict(zip(labels, map(float, l.split("\t"))))
        out.append([r[f"pelvis_t{a}_force"] for a in "xyz"])
    return out
weight = 62.636148826293962 * 9.80665
still = [math.sqrt(sum(f * f for f in r)) for r in pelvis("still.sto")]
push = [max(abs(f) for f in r) for r in pelvis("push.sto")]
print("weight", weight, "still", still, "push", push, file=sys.stderr)
ok = all(abs(s - weight) <= 1e-6 * weight for s in still) and all(p <= 1e-6 for p in push)
sys.exit(0 if ok else 1)
PY

# bad input
"$gaitsim" moments "$M" --pose "$T/coordinates.mot" --grf "$T/grf.mot" >/dev/null 2>err.txt
status=$?
check "no --out: exit 2 (got $status), one line naming it" \
  test "$status" -eq 2 -a "$(wc -l <err.txt)" -eq 1 -a "$(grep -c -- "--out" err.txt)" -eq 1
"$gaitsim" moments "$M" --pose "$T/coordinates.mot" --grf "$T/grf.mot" --out nowhere/id.sto \
  >/dev/null 2>err.txt
status=$?
check "--out in a missing folder: exit 1 (got $status), one line ($(cat err.txt)), nothing made" \
  test "$status" -eq 1 -a "$(wc -l <err.txt)" -eq 1 -a "$(grep -c "nowhere/id.sto: folder nowhere does not exist" err.txt)" -eq 1 -a ! -e nowhere
cp still.mot keep.mot
"$gaitsim" moments "$M" --pose keep.mot --grf none.mot --out keep.mot >/dev/null 2>err.txt
status=$?
check "--out naming the --pose file: exit 1 (got $status), one line, the file unchanged" \
  test "$status" -eq 1 -a "$(wc -l <err.txt)" -eq 1 -a "$(grep -c "keep.mot: --out names an input file" err.txt)" -eq 1
check "--out naming the --pose file: the file unchanged" cmp -s keep.mot still.mot
"$gaitsim" moments "$M" --pose "$T/coordinates.mot" --grf "$T/coordinates.mot" --out x.sto \
  >/dev/null 2>err.txt
status=$?
check "a coordinates file as --grf: exit 1 (got $status), one line naming file and column ($(cat err.txt))" \
  test "$status" -eq 1 -a "$(wc -l <err.txt)" -eq 1 -a "$(grep -c "coordinates.mot: no column ground_force_r_vx" err.txt)" -eq 1 -a ! -e x.sto
"$gaitsim" moments "$M" --pose still.mot --grf none.mot --out id.sto >/dev/null 2>err.txt
status=$?
check "an existing --out is replaced whole: exit 0 (got $status), 3 rows now" \
  test "$status" -eq 0 -a "$(grep -c "^nRows=3$" id.sto)" -eq 1 -a "$(ls | grep -c "id.sto.")" -eq 0
finish
