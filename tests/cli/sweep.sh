#!/usr/bin/env bash
# gaitsim sweep on a tiny problem: the fixture solution (given a speed of 1.27 m/s) as the guess,
# speeds 0.9 (below: the downward chain, in the forked process) and 1.6 (upward chain), 5 nodes,
# 2 Ipopt iterations each; exit 3 (solves stopped short), one folder per speed with its target
# speed and log, a table with one row per speed in ascending order and the peak knee contact of
# both knees, and the walk columns (summed vertical GRF minimum, flight and double-support
# nodes) as each summary.json has them; a malformed list exits 2.
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
"$gaitsim" sweep --guess guess --speeds 0.8:x:2 --out sw2 >/dev/null 2>&1
check "malformed speeds: exit 2" test $? -eq 2
finish
