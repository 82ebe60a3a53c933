#!/usr/bin/env bash
# gaitsim work: the mechanical work of a simulated motion, checked by the energy theorem. The
# one-muscle bench (a 101.97 kg block hanging from an elastic-tendon Hill muscle) simulated at
# full excitation for 0.2 s, every 1 ms step written: the sum of the net works equals the change
# of kinetic plus potential energy within 2 % (the rows' trapezoidal rule against the
# simulation's semi-implicit Euler steps; measured: equal to the printed 0.01 J), the unit's net
# work is over 1 J in size, and its contractile, passive-fibre and tendon parts add up to it
# (0.02 J, the printed rounding); with --joints the block's one coordinate carries the unit's
# net work (0.02 J) and no stance work (no feet). With --grf, JW's measured gait (the trial's
# coordinates.mot and plates) by inverse dynamics: each knee takes 0.35-0.55 of its leg's
# sagittal negative work in stance (measured 0.45 / 0.43; Montgomery & Grabowski 2018: 0.39 at
# 1.00 m/s, 0.45 at 1.50), the trunk's coordinates none in stance. Bad input: a pose file without speeds (the
# trial's coordinates.mot) and a missing file exit 1 with one line naming the file (and the
# missing column), a --grf file without the ExternalLoads columns exits 1 naming it; no --pose,
# and --grf with --joints, exit 2.
# usage: work.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
bench=$src/tests/fixtures/one_muscle.xml
source "$(dirname "$0")/../cli_common.bash"

"$gaitsim" simulate "$bench" --excitation 1 --duration 0.2 --rate 1000 --out run >/dev/null
check "simulate exits 0" test $? -eq 0
"$gaitsim" work "$bench" --pose run/states.sto >out.txt 2>err.txt
status=$?
check "work exits 0 (got $status)" test "$status" -eq 0
check "the energy theorem and the parts ($(tr '\n' ' ' <out.txt))" /usr/bin/python3 - out.txt <<'PY'
import re, sys
txt = open(sys.argv[1]).read()
rows = {}
for line in txt.splitlines():
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) == 5 and cells[0] not in ("source", "---"):
        rows[cells[0]] = [float(c) for c in cells[1:]]
s, de = map(float, re.search(r"sum of the net works: (\S+) J; change of kinetic plus potential "
                             r"energy: (\S+) J", txt).groups())
unit = rows["muscle-tendon units"][2]
parts = sum(rows["their " + k][2] for k in ("contractile elements (active fibre force)",
                                           "passive fibre force and damping", "tendons"))
ok = abs(de) > 1 and abs(s - de) <= 0.02 * abs(de) and abs(unit) > 1
ok &= abs(unit - parts) <= 0.02 and len(rows) == 14
print(f"sum {s} J, change {de} J, unit {unit} J, parts {parts} J", file=sys.stderr)
sys.exit(0 if ok else 1)
PY

"$gaitsim" work "$bench" --pose run/states.sto --joints >joints.txt 2>err.txt
status=$?
check "--joints: exit 0 (got $status)" test "$status" -eq 0
check "--joints: the block's coordinate carries the unit's work ($(tail -1 joints.txt))" \
  /usr/bin/python3 - joints.txt <<'PY'
import sys
rows = {}
for line in open(sys.argv[1]):
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) == 5 and cells[0] not in ("source", "coordinate", "---"):
        rows[cells[0]] = [float(c) for c in cells[1:]]
drop, unit = rows["drop"], rows["muscle-tendon units"]
ok = abs(drop[0] + drop[1] - unit[2]) <= 0.02 and drop[2] == 0 and drop[3] == 0
sys.exit(0 if ok else 1)
PY

# --grf: JW's measured gait by inverse dynamics (the trial's coordinates.mot and plates)
T=$src/mjmodels/trials/jw_ngait_og5
"$gaitsim" work "$src/mjmodels/jw_fullbody_knee6.xml" --pose "$T/coordinates.mot" \
  --grf "$T/grf.mot" >id.txt 2>err.txt
status=$?
check "--grf: exit 0 (got $status)" test "$status" -eq 0
check "--grf: each knee's share of its leg's stance negative work 0.35-0.55" \
  /usr/bin/python3 - id.txt <<'PY'
import sys
rows = {}
for line in open(sys.argv[1]):
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) == 5 and cells[0] not in ("coordinate", "---"):
        rows[cells[0]] = [float(c) for c in cells[1:]]
shares = []
for suffix in ("", "_l"):
    neg = [rows[c + suffix][3] for c in ("hip_flexion", "knee_flexion", "ankle_angle")]
    shares.append(neg[1] / sum(neg))
print(f"knee shares {shares[0]:.3f} / {shares[1]:.3f}", file=sys.stderr)
ok = all(0.35 <= x <= 0.55 for x in shares) and "lumbar_bending" in rows
ok &= rows["lumbar_bending"][2] == 0 and rows["lumbar_bending"][3] == 0  # no foot below it
sys.exit(0 if ok else 1)
PY
"$gaitsim" work "$src/mjmodels/jw_fullbody_knee6.xml" --pose "$T/coordinates.mot" \
  --grf run/states.sto >/dev/null 2>err.txt
status=$?
check "--grf without ExternalLoads columns: exit 1 (got $status), one line naming it" \
  test "$status" -eq 1 -a "$(wc -l <err.txt)" -eq 1 -a "$(grep -c "run/states.sto: no column" err.txt)" -eq 1
"$gaitsim" work "$bench" --pose run/states.sto --grf "$T/grf.mot" --joints >/dev/null 2>err.txt
status=$?
check "--grf with --joints: exit 2 (got $status)" test "$status" -eq 2

for bad in "$src/mjmodels/trials/jw_ngait_og5/coordinates.mot" missing.sto; do
  name=$(basename "$bad")
  "$gaitsim" work "$src/mjmodels/jw_fullbody.xml" --pose "$bad" >/dev/null 2>err.txt
  status=$?
  check "$name: exit 1 (got $status)" test "$status" -eq 1
  check "$name: one line naming the file" test "$(wc -l <err.txt)" -eq 1 -a \
    "$(grep -c "$name" err.txt)" -eq 1
  [[ $name == coordinates.mot ]] && check "$name: names the missing speed" \
    grep -q "no speed column pelvis_tx_u" err.txt
done
"$gaitsim" work "$bench" >/dev/null 2>err.txt
status=$?
check "no --pose: exit 2 (got $status), one line" test "$status" -eq 2 -a "$(wc -l <err.txt)" -eq 1

finish
