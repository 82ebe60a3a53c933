#!/usr/bin/env bash
# gaitsim sweep on a tiny problem: the fixture solution (given a speed of 1.27 m/s) as the guess,
# speeds 0.9 and 1.6, 5 nodes, 2 Ipopt iterations each; exit 3 (solves stopped short), one folder
# per speed with its target speed and log, a table with one row per speed in ascending order and
# the peak knee contact of both knees, and the walk columns (summed vertical GRF minimum, flight
# and double-support nodes) as each summary.json has them. Each speed starts from the guess and
# its solution is bitwise that of `gaitsim predict` with the same words, in whichever process;
# --start neighbour chains 1.6 -> 1.8 (and 0.9 down from the guess in the forked process); bad
# --start, --jobs, --band-scale and a malformed list exit 2; --band-scale reaches each speed
# (summary.json, and bitwise predict's solution). Each solve's polish from its far-from-feasible
# point takes most of the test's minute or two.
# usage: sweep.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

cp -r "$src/tests/fixtures/solution_small" guess
/usr/bin/python3 - guess/summary.json <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); s["speed_mps"] = 1.27
json.dump(s, open(sys.argv[1], "w"))
PY
"$gaitsim" sweep --guess guess --speeds 0.9,1.6 --out sw --nodes 5 --max-iter 2 >out.txt 2>err.txt
status=$?
check "stopped short: exit 3 (got $status)" test "$status" -eq 3
for v in 0.9 1.6; do
  check "predict_$v summary" grep -q "\"speed_target_mps\":\s*$v" "sw/predict_$v/summary.json"
  check "predict_$v log" grep -q '^iter' "sw/predict_$v/log.txt"
done
check "csv: header and two rows" test "$(wc -l < sw/sweep.csv)" -eq 3
check "csv rows ascending" test "$(cut -d, -f1 sw/sweep.csv | tail -n 2 | tr '\n' ' ')" = "0.9 1.6 "
check "markdown table" grep -q '^| 1.6 |' sw/sweep.md
check "peak knee contact of both knees, finite and > 0" /usr/bin/python3 - sw/sweep.csv <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ok = len(rows) == 2 and all(math.isfinite(float(r[k])) and float(r[k]) > 0
                            for r in rows for k in ("peak_knee_contact_r_bw", "peak_knee_contact_l_bw"))
sys.exit(0 if ok else 1)
PY
check "markdown: left knee column" grep -q '| peak knee contact, left (BW) |' sw/sweep.md
check "markdown: change and excitation columns, ratio line" grep -q "change from the guess: time, length" sw/sweep.md
check "markdown: fast/slow excitation ratio" grep -q "^Fast/slow peak excitation ratio" sw/sweep.md
check "csv: changes against the guess's stride, excitations in (0, 1]" /usr/bin/python3 - sw/sweep.csv guess/summary.json <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
g = json.load(open(sys.argv[2]))
T0 = g["stride_time_s"]; L0 = g["speed_mps"] * T0
ok = all(abs(float(r["stride_time_change_pct"]) - 100 * (float(r["stride_time_s"]) / T0 - 1)) < 0.01 and
         abs(float(r["stride_length_change_pct"]) - 100 * (float(r["stride_length_m"]) / L0 - 1)) < 0.02 and
         0 < float(r["peak_soleus_excitation"]) <= 1 and 0 < float(r["peak_gastrocnemius_excitation"]) <= 1
         for r in rows)
sys.exit(0 if ok and rows else 1)
PY
check "csv: walk columns agree with each speed's summary.json (predict's default floor 0.2 BW)" \
  /usr/bin/python3 - sw <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/sweep.csv")))
ok = bool(rows)
for r in rows:
    s = json.load(open("%s/predict_%s/summary.json" % (sys.argv[1], r["speed_mps"])))
    ok &= (abs(float(r["min_summed_vgrf_bw"]) - s["min_summed_vgrf_bw"]) < 1e-3
           and int(r["flight_nodes"]) == s["flight_nodes"]
           and int(r["double_support_nodes"]) == s["double_support_nodes"]
           and s["min_vgrf_bound_bw"] == 0.2)
sys.exit(0 if ok else 1)
PY
check "markdown: walk column" grep -q "lowest summed vertical GRF (BW); nodes in flight, in double support" sw/sweep.md
# each speed from the guess: the words of gaitsim predict, bitwise its solution, any --jobs
for v in 0.9 1.6; do
  check "predict_$v started from the guess" grep -q '"guess":[[:space:]]*"guess"' "sw/predict_$v/summary.json"
done
"$gaitsim" predict --guess guess --speed 1.6 --out p16 --nodes 5 --max-iter 2 --threads 1 >/dev/null 2>&1
check "predict_1.6: bitwise gaitsim predict's variables.sto" cmp -s sw/predict_1.6/variables.sto p16/variables.sto
# continuation: 1.8 from 1.6 (the staging folder's predict_1.6), 0.9 and 1.6 from the guess
"$gaitsim" sweep --guess guess --speeds 0.9,1.6,1.8 --out swn --nodes 5 --max-iter 2 --start neighbour \
  >swn.txt 2>&1
status=$?
check "--start neighbour: exit 3 (got $status)" test "$status" -eq 3
check "--start neighbour: 1.8 from predict_1.6" grep -q '"guess":[[:space:]]*"[^"]*/predict_1.6"' swn/predict_1.8/summary.json
check "--start neighbour: 1.6 from the guess" grep -q '"guess":[[:space:]]*"guess"' swn/predict_1.6/summary.json
check "--start neighbour: by continuation" grep -q "by continuation: 1 downwards, 2 upwards" swn.txt
# the speeds from the guess are the same whichever process solved them (two chains here, two
# solves at once above)
for v in 0.9 1.6; do
  check "--start neighbour: predict_$v bitwise the default sweep's" cmp -s "sw/predict_$v/variables.sto" "swn/predict_$v/variables.sto"
done
"$gaitsim" sweep --guess guess --speeds 0.8:x:2 --out sw2 >/dev/null 2>&1
check "malformed speeds: exit 2" test $? -eq 2
"$gaitsim" sweep --guess guess --speeds 1 --out sw2 --start middle 2>err2.txt
check "--start middle: exit 2, one line naming it" test $? -eq 2 -a "$(grep -c -- '--start' err2.txt)" -eq 1
"$gaitsim" sweep --guess guess --speeds 1 --out sw2 --jobs 9 2>/dev/null
check "--jobs 9: exit 2" test $? -eq 2
for scale in 11 -1 x; do
  "$gaitsim" sweep --guess guess --speeds 1 --out sw2 --band-scale "$scale" 2>err3.txt
  check "--band-scale $scale: exit 2, one line naming it" \
    test $? -eq 2 -a "$(grep -c -- '--band-scale' err3.txt)" -eq 1
done
check "no sw2 written by the refused commands" test ! -e sw2
# --band-scale reaches every speed (a scale other than the default 1.5): bitwise gaitsim predict
# with the same words; without it, predict's default
"$gaitsim" sweep --guess guess --speeds 1.6 --out swb --nodes 5 --max-iter 2 --band-scale 0.8 \
  >/dev/null 2>&1
"$gaitsim" predict --guess guess --speed 1.6 --out pb16 --nodes 5 --max-iter 2 --threads 1 \
  --band-scale 0.8 >/dev/null 2>&1
check "--band-scale 0.8: summary.json band_scale" \
  grep -q '"band_scale":[[:space:]]*0.8' swb/predict_1.6/summary.json
check "--band-scale 0.8: bitwise gaitsim predict's variables.sto" \
  cmp -s swb/predict_1.6/variables.sto pb16/variables.sto
check "no --band-scale: the default 1.5 (summary.json band_scale)" \
  grep -q '"band_scale":[[:space:]]*1.5' sw/predict_1.6/summary.json
finish
