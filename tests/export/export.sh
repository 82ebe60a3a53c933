#!/usr/bin/env bash
# gaitsim export (issue 21, item 2): the fixture solution, a short planar forward simulation
# (speeds and activations in its states.sto) and a 3-iteration planar tracking solve (its model
# taken from summary.json) exported as keyframes; test_keyframes loads each
# export with stock MuJoCo and checks every key's time, qpos, qvel and act against states.sto
# (1e-12). The command's report names 14 keys from index 1 (after the model's standing key);
# the file includes the model by a path relative to its folder. A folder without states.sto, a
# model whose coordinates are not in states.sto and a missing --out exit 1, 1 and 2 with one
# line and leave no file.
# usage: export.sh GAITSIM TEST_KEYFRAMES SOURCE_DIR
set -u
gaitsim=$1 checker=$2 src=$3
fixture=$src/tests/fixtures/solution_small
source "$(dirname "$0")/../cli_common.bash"

out=$("$gaitsim" export "$fixture" --out k/gait.xml)
check "export exits 0" test $? -eq 0
check "reports 14 keyframes from index 1 ($out)" grep -q '14 keyframes (gait_000.., key index 1 on)' <<<"$out"
check "include is relative" grep -q '<include file="\.\./' k/gait.xml
check "one key per row" test "$(grep -c '<key name="gait_' k/gait.xml)" -eq 14
"$checker" k/gait.xml "$fixture/states.sto"
check "fixture keys match states.sto" test $? -eq 0
check "no temporary files left" test -z "$(ls -A k | grep -v '^gait.xml$')"

# a planar forward simulation: states.sto with speeds and activations
"$gaitsim" simulate "$src/mjmodels/gait2d.xml" --out sim --duration 0.1 --rate 50 >/dev/null
check "simulate exits 0" test $? -eq 0
out=$("$gaitsim" export sim --model "$src/mjmodels/gait2d.xml" --out sim.xml)
check "planar export exits 0" test $? -eq 0
check "planar export has 9 speeds ($out)" grep -q 'coordinates 9, speeds 9, activations 18' <<<"$out"
"$checker" sim.xml sim/states.sto
check "planar keys match states.sto" test $? -eq 0

# a planar tracking solve (3 iterations, unpolished: a solution folder in under a second) whose
# summary.json names gait2d.xml, exported without --model
"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --model "$src/mjmodels/gait2d.xml" --out track \
  --nodes 8 --max-iter 3 --refine 0 --threads 1 --no-polish >/dev/null 2>&1
rc=$?
check "planar track exits 0 or 3 (got $rc)" test "$rc" -eq 0 -o "$rc" -eq 3
out=$("$gaitsim" export track --out track.xml)
check "track export exits 0" test $? -eq 0
check "track export includes gait2d.xml from summary.json" grep -q 'include file="[^"]*/gait2d.xml"' track.xml
check "track export: 8 keys, 9 coordinates and speeds, 18 activations ($out)" \
  grep -q '8 keyframes.*coordinates 9, speeds 9, activations 18' <<<"$out"
"$checker" track.xml track/states.sto
check "track keys match states.sto" test $? -eq 0

# failures: one line, exit status, no file
err=$("$gaitsim" export nowhere --out bad.xml 2>&1 >/dev/null)
rc=$?
check "missing folder exits 1 (got $rc)" test "$rc" -eq 1
check "missing folder: one line naming states.sto" test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep 'nowhere/states.sto' <<<"$err")"
err=$("$gaitsim" export "$fixture" --model "$src/tests/fixtures/one_muscle.xml" --out bad.xml 2>&1 >/dev/null)
rc=$?
check "foreign model exits 1 (got $rc)" test "$rc" -eq 1
check "foreign model names the coordinate" grep -q 'no column for coordinate drop' <<<"$err"
"$gaitsim" export "$fixture" >/dev/null 2>&1
rc=$?
check "no --out exits 2 (got $rc)" test "$rc" -eq 2
check "no file written" test ! -e bad.xml
finish
