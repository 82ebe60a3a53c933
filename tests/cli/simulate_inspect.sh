#!/usr/bin/env bash
# gaitsim simulate and inspect on the one-muscle bench: outputs written and readable; bad
# input files give one line naming the file and exit 1, and leave earlier outputs intact.
# inspect on jw_fullbody at the trial's right foot-flat instant (0.3 s of coordinates.mot): the
# 12 contact spheres listed, the right calcaneus spheres pressed 0-15 mm into the floor (the
# trial-calibrated feet; the earlier sole sat 25-26 mm deep at the heel), the left foot in swing.
# usage: simulate_inspect.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
bench=$src/tests/fixtures/one_muscle.xml
source "$(dirname "$0")/../cli_common.bash"

"$gaitsim" simulate "$bench" --excitation 1 --duration 0.2 --rate 50 --out run >/dev/null
check "simulate exits 0" test $? -eq 0
for f in states.sto grf.mot muscle_forces.sto; do
  check "simulate wrote $f" grep -q '^endheader' "run/$f"
done
check "states has 11 rows (0..0.2 s at 50 Hz)" grep -q '^nRows=11$' run/states.sto
check "states names the fibre state" grep -q 'muscle.normalized_tendon_force' run/states.sto
cp run/states.sto before.sto

out=$("$gaitsim" inspect "$bench" --pose run/states.sto --time 0.1)
check "inspect lists the muscle" grep -q '^muscle .*elastic' <<<"$out"

out=$("$gaitsim" inspect "$src/mjmodels/jw_fullbody.xml" \
  --pose "$src/mjmodels/trials/jw_ngait_og5/coordinates.mot" --time 0.3)
check "inspect lists 12 contact spheres" test "$(grep -c '^contact_[rl]_[1-6] ' <<<"$out")" -eq 12
check "right calcaneus spheres 0-15 mm deep at foot flat" awk '
  /^contact_r_[1-4] / { n++; if (!($3 < 0 && $3 > -15)) bad = 1 }
  END { exit !(n == 4 && !bad) }' <<<"$out"
check "left foot unloaded in swing" grep -q '^foot l: .*(unloaded)$' <<<"$out"

# bad inputs: one line, exit 1, earlier output untouched
printf 'x\nversion=1\nnRows=1\nnColumns=2\nendheader\ntime\tdrop\n0\tnan\n' > nan.sto
printf 'x\nversion=1\nnRows=1\nnColumns=2\nendheader\ntime\tunknown\n0\t1\n' > nocol.sto
printf 'x\nversion=1\nnRows=2\nnColumns=2\ntime\tdrop\n0\t1\n' > noend.sto
for bad in nan.sto nocol.sto noend.sto missing.sto; do
  err=$("$gaitsim" simulate "$bench" --init "$bad" --duration 0.1 --out run 2>&1 >/dev/null)
  status=$?
  check "$bad exits 1 (got $status)" test "$status" -eq 1
  check "$bad one line naming the file" grep -q "^gaitsim: .*$bad" <<<"$err"
  check "$bad one line" test "$(printf '%s\n' "$err" | wc -l)" -eq 1
done
check "earlier states.sto intact" cmp -s before.sto run/states.sto
"$gaitsim" simulate "$bench" --duration -1 --out run 2>/dev/null
check "negative duration is a usage error" test $? -eq 2

finish
