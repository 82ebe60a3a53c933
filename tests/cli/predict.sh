#!/usr/bin/env bash
# gaitsim predict end to end on a tiny problem: the fixture solution (tests/fixtures/solution_small)
# as the guess, 5 nodes, 3 Ipopt iterations; the solve stops short (exit 3), the best iterate is
# polished towards the dynamics (violation down 10-fold from the guess's; from this far the
# polish does not reach feasibility), every file is written (metabolics.sto: the muscles and
# their total; knee_contact.sto: both knees) and summary.json carries the prediction figures, the
# peak knee contact of both knees and the muscles' positive work and efficiency; a prediction from
# it without --nodes solves on its 5 nodes; bad usage exits 2, a missing guess exits 1 with one
# line naming the folder.
# usage: predict.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

"$gaitsim" predict --guess "$src/tests/fixtures/solution_small" --speed 0.8 --out pred \
  --nodes 5 --max-iter 3 --threads 1 >/dev/null 2>log.txt
status=$?
check "stopped short: exit 3 (got $status)" test "$status" -eq 3
for f in states.sto controls.sto grf.mot muscle_forces.sto metabolics.sto knee_contact.sto \
    summary.json; do
  check "wrote $f" test -s "pred/$f"
done
# metabolics.sto: the muscles of muscle_forces.sto (W) and their sum, "total", at every node;
# knee_contact.sto has the left knee's joint reaction beside the right knee's columns
check "metabolics.sto: muscle columns and their total" /usr/bin/python3 - "$src/scripts" pred <<'PY'
import math, os, sys
sys.path.insert(0, sys.argv[1])
from gs_scriptlib import read_storage
_, mlab, mrows = read_storage(os.path.join(sys.argv[2], "metabolics.sto"))
_, flab, frows = read_storage(os.path.join(sys.argv[2], "muscle_forces.sto"))
_, klab, _ = read_storage(os.path.join(sys.argv[2], "knee_contact.sto"))
ok = mlab == flab + ["total"] and len(mrows) == len(frows) == 5 and "contact_total_l" in klab
for row in mrows:
    parts = row[1:-1]
    ok = ok and all(math.isfinite(v) for v in parts)
    ok = ok and abs(row[-1] - sum(parts)) <= 1e-9 * max(1.0, abs(row[-1]))
if not ok:
    print("labels", mlab[:3], "...", mlab[-2:], "knee", klab, "rows", len(mrows), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
check "summary figures" /usr/bin/python3 - pred/summary.json <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
ok = (s["problem"] == "prediction" and s["speed_target_mps"] == 0.8
      and 0.4 <= s["stride_time_s"] <= 2.5
      # the speed row (dx / T - V, m/s, one of the rows max_violation covers) holds to the
      # violation left: 3 iterations and the polish from 161 leave 0.07-0.19
      and abs(s["stride_length_m"] / s["stride_time_s"] - 0.8) <= max(1e-4, s["max_violation"])
      and s["max_violation"] * 10 <= s["initial_violation"]
      and math.isfinite(s["cost_of_transport_j_per_kg_m"]) and s["cost_of_transport_j_per_kg_m"] > 0
      # the fibres' positive work per metre over the muscles' metabolic energy per metre: a
      # share in (0, 1), since Umberger's heat is at least 1 W/kg of muscle
      and 0 < s["muscle_efficiency"] < 1
      and abs(s["muscle_efficiency"] * s["cost_of_transport_exact_j_per_kg_m"]
              - s["muscle_positive_work_j_per_kg_m"]) <= 1e-9
      and s["polish"]["used"] and set(s["peak_excitation"]) >= {"soleus", "gasmed"}
      and all(s[f"peak_knee_contact_{k}_n"] > 0
              and abs(s[f"peak_knee_contact_{k}_bw"] * s["body_weight_n"]
                      - s[f"peak_knee_contact_{k}_n"]) < 1e-6 for k in "rl"))
if not ok:
    print(json.dumps(s, indent=1), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
# summary.json ipopt_last_iteration: the primal and dual infeasibility of the solve's last
# progress line (printed to 4 digits), before the polish's own lines
check "ipopt_last_iteration: the last progress line" /usr/bin/python3 - pred/summary.json log.txt <<'PY'
import json, re, sys
s = json.load(open(sys.argv[1]))["ipopt_last_iteration"]
last = None
for line in open(sys.argv[2]):
    if "feasibility polish" in line:
        break
    m = re.match(r"iter +(\d+)(r?) .* inf_pr (\S+)  inf_du (\S+)  lg\(mu\) +(\S+)", line)
    if m:
        last = m
ok = (last is not None and int(last[1]) == 3 and s["restoration"] == (last[2] == "r")
      and abs(s["inf_pr"] / float(last[3]) - 1) <= 1e-3 and abs(s["inf_du"] / float(last[4]) - 1) <= 1e-3
      and abs(s["mu"] / 10 ** float(last[5]) - 1) <= 0.13)
if not ok:
    print(s, last and last.groups(), file=sys.stderr)
sys.exit(0 if ok else 1)
PY

# without --nodes a prediction continues its guess on the guess's mesh (summary.json nodes: 5),
# not on GO_NODES_PREDICT's 20
"$gaitsim" predict --guess pred --speed 0.9 --out pred2 --max-iter 0 --no-polish --threads 1 \
  >/dev/null 2>&1
check "no --nodes: the guess's 5 nodes" /usr/bin/python3 -c \
  'import json, sys; sys.exit(json.load(open("pred2/summary.json"))["nodes"] != 5)'

"$gaitsim" predict --speed 0.8 --out x >/dev/null 2>&1
check "no --guess: usage, exit 2" test $? -eq 2
err=$("$gaitsim" predict --guess nowhere --speed 0.8 --out x 2>&1 >/dev/null)
status=$?
check "missing guess exits 1 (got $status)" test "$status" -eq 1
check "one line naming the folder: $err" test "$(grep -c '^gaitsim: nowhere: ' <<<"$err")" -eq 1 -a \
  "$(wc -l <<<"$err")" -eq 1
finish
