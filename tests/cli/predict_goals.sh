#!/usr/bin/env bash
# gaitsim predict's goals and fibre bounds on the fixture guess (tests/fixtures/solution_small),
# 5 nodes, 0 Ipopt iterations, no polish (under a second each): summary.json's objective_terms
# sum to the objective and objective_share to 1, the tracking goals are 0; the fibre-length
# bounds 0.25 <= lM/lopt <= 1.5 are on by default (the guess's count outside them printed, a
# fibre block in the violation lines) and --no-fibre-bounds removes their 93 x 5 rows; the accel
# weight parses for track and predict, a negative one is bad usage (exit 2). Without --model,
# predict continues on the model the guess's summary.json names (here the placeholder-knee
# jw_fullbody.xml), else on the bundled default (jw_fullbody_knee6.xml). A 5-node tracking
# summary's coordinate_errors agree with its joint RMS; the knee compartments' RMS are there.
# The walk row (--min-vgrf, default 0.2 BW; 0 removes it); --stride-time holds the stride time.
# usage: predict_goals.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"
guess="$src/tests/fixtures/solution_small"

"$gaitsim" predict --guess "$guess" --speed 0.8 --out on --nodes 5 --max-iter 0 --no-polish \
  --threads 1 >/dev/null 2>on.txt
status=$?
check "default: exit 3 at 0 iterations (got $status)" test "$status" -eq 3
check "goal terms and shares" /usr/bin/python3 - on/summary.json <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t, sh = s["objective_terms"], s["objective_share"]
keys = {"pelvis", "joints", "grf", "effort", "cot", "accel"}
ok = (set(t) == keys and set(sh) == keys and abs(sum(sh.values()) - 1) < 1e-9
      and abs(sum(t.values()) - s["objective"]) <= 1e-9 * s["objective"]
      and t["pelvis"] == t["joints"] == t["grf"] == 0 and t["cot"] > 0 and t["effort"] > 0
      and t["accel"] >= 0)
if not ok:
    print(json.dumps({"objective": s["objective"], "terms": t, "share": sh}), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
check "guess checked against the fibre bounds" \
  grep -q "guess: [0-9]* of 93 muscles outside 0.25 <= lM/lopt <= 1.5" on.txt
check "fibre block in the violation lines" grep -q "initial violation by block:.* fibre " on.txt

"$gaitsim" predict --guess "$guess" --speed 0.8 --out off --nodes 5 --max-iter 0 --no-polish \
  --threads 1 --no-fibre-bounds --weight accel=0 >/dev/null 2>off.txt
status=$?
check "--no-fibre-bounds: exit 3 (got $status)" test "$status" -eq 3
c1=$(sed -n 's/.*variables, \([0-9]*\) constraints.*/\1/p' on.txt)
c2=$(sed -n 's/.*variables, \([0-9]*\) constraints.*/\1/p' off.txt)
check "--no-fibre-bounds: 465 fewer constraints (${c1:-?} vs ${c2:-?})" \
  test "$((${c1:-0} - ${c2:-0}))" -eq 465
check "--no-fibre-bounds: no fibre block" bash -c "! grep -q ' fibre ' off.txt"
check "accel=0: no acceleration goal" /usr/bin/python3 -c "import json, sys
sys.exit(0 if json.load(open('off/summary.json'))['objective_terms']['accel'] == 0 else 1)"

# the guess's model: a copy of the fixture whose summary.json names jw_fullbody.xml
mkdir -p named
cp "$guess"/*.sto "$guess"/*.mot named/
/usr/bin/python3 -c "import json,sys; s=json.load(open(sys.argv[1])); s['model']=sys.argv[2]; \
json.dump(s, open('named/summary.json','w'))" "$guess/summary.json" "$src/mjmodels/jw_fullbody.xml"
"$gaitsim" predict --guess named --speed 0.8 --out from_named --nodes 5 --max-iter 0 --no-polish \
  --threads 1 >/dev/null 2>&1
check "predict continues on the guess's model" /usr/bin/python3 -c "import json,sys; \
sys.exit(0 if json.load(open('from_named/summary.json'))['model'].endswith('/jw_fullbody.xml') else 1)"
check "without a named model: the bundled knee6 model" /usr/bin/python3 -c "import json,sys; \
sys.exit(0 if json.load(open('on/summary.json'))['model'].endswith('/jw_fullbody_knee6.xml') else 1)"

# the walk row (--min-vgrf, on by default): one constraint per node, a walk block in the violation lines,
# and summary.json's summed vertical force minimum equal to the written grf.mot's (Y up, over
# body_weight_n); --stride-time holds T: the written stride and the retimed progression
"$gaitsim" predict --guess "$guess" --speed 0.8 --out walk --nodes 5 --max-iter 0 --no-polish \
  --threads 1 --min-vgrf 0.2 --stride-time 1.3 >/dev/null 2>walk.txt
status=$?
check "--min-vgrf --stride-time: exit 3 at 0 iterations (got $status)" test "$status" -eq 3
"$gaitsim" predict --guess "$guess" --speed 0.8 --out nowalk --nodes 5 --max-iter 0 --no-polish \
  --threads 1 --min-vgrf 0 >/dev/null 2>nowalk.txt
c3=$(sed -n 's/.*variables, \([0-9]*\) constraints.*/\1/p' nowalk.txt)
check "default floor 0.2 BW: 5 more constraints than --min-vgrf 0 (${c1:-?} vs ${c3:-?})" \
  test "$((${c1:-0} - ${c3:-0}))" -eq 5
check "walk block in the violation lines" grep -q "initial violation by block:.* walk " walk.txt
check "no walk block with --min-vgrf 0" bash -c "! grep -q ' walk ' nowalk.txt"
check "summary: the floor, the summed vertical force against grf.mot, T held" \
  /usr/bin/python3 - walk <<'PY'
import json, sys
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))
lines = open(d + "/grf.mot").read().split("endheader\n")[1].split("\n")
head = lines[0].split("\t")
rows = [list(map(float, l.split("\t"))) for l in lines[1:] if l.strip()]
ry, ly = head.index("ground_force_r_vy"), head.index("ground_force_l_vy")
bw = s["body_weight_n"]  # the model's m g (N), as sweep.csv divides by
vmin = min((r[ry] + r[ly]) / bw for r in rows)
flight = sum(r[ry] < 0.02 * bw and r[ly] < 0.02 * bw for r in rows)
ok = (s["min_vgrf_bound_bw"] == 0.2 and abs(s["min_summed_vgrf_bw"] - vmin) < 2e-3
      and s["flight_nodes"] == flight and len(rows) == 5 and s["double_support_nodes"] >= 0
      and s["stride_time_fixed_s"] == 1.3 and abs(s["stride_time_s"] - 1.3) < 1e-12
      and abs(s["stride_length_m"] - 0.8 * 1.3) < 1e-9)
if not ok:
    print(json.dumps({k: s.get(k) for k in ("min_vgrf_bound_bw", "min_summed_vgrf_bw",
          "flight_nodes", "stride_time_s", "stride_length_m", "stride_time_fixed_s")},
          ), "grf.mot", vmin, flight, bw, file=sys.stderr)
sys.exit(0 if ok else 1)
PY
check "free stride time: stride_time_fixed_s null" /usr/bin/python3 -c "import json,sys; \
sys.exit(0 if json.load(open('on/summary.json'))['stride_time_fixed_s'] is None else 1)"
"$gaitsim" predict --guess "$guess" --speed 0.8 --out start --nodes 5 --max-iter 0 --no-polish \
  --threads 1 --stride-time-start 1.4 >/dev/null 2>&1
check "--stride-time-start: the solve starts at 1.4 s, T free" /usr/bin/python3 -c "import json,sys
s = json.load(open('start/summary.json'))
sys.exit(0 if abs(s['stride_time_s'] - 1.4) < 1e-12 and s['stride_time_fixed_s'] is None else 1)"
"$gaitsim" predict --guess "$guess" --speed 0.8 --out x --min-vgrf -1 >/dev/null 2>&1
check "predict --min-vgrf -1: usage, exit 2" test $? -eq 2
"$gaitsim" predict --guess "$guess" --speed 0.8 --out x --stride-time 3 >/dev/null 2>&1
check "predict --stride-time 3 (outside 0.4-2.5 s): usage, exit 2" test $? -eq 2

"$gaitsim" predict --guess "$guess" --speed 0.8 --out x --weight accel=-1 >/dev/null 2>&1
check "predict --weight accel=-1: usage, exit 2" test $? -eq 2
# tracking summary: every measured coordinate's error (RMS >= |mean|), the joint RMS the mean
# square of the paper's joint set (non-pelvis rotations but knee adduction and rotation), and
# the six-DOF knee's medial and lateral contact RMS
"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --out tr --nodes 5 --max-iter 0 --no-polish --refine 0 \
  --threads 1 >/dev/null 2>&1
check "track at 0 iterations: exit 3" test $? -eq 3
check "coordinate errors agree with the joint RMS" /usr/bin/python3 - tr/summary.json <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
ce, rms = s["coordinate_errors"], s["rms"]
joints = [v for k, v in ce.items() if v["unit"] == "deg" and not k.startswith("pelvis_")
          and k not in ("knee_adduction", "knee_rotation")]
joint_rms = math.sqrt(sum(v["rms"] ** 2 for v in joints) / len(joints))
ok = (len(ce) >= 20 and all(v["rms"] >= abs(v["mean"]) - 1e-12 for v in ce.values())
      and abs(joint_rms - rms["joint_rot_deg"]) <= 1e-9 * rms["joint_rot_deg"]
      and rms["knee_medial_bw"] > 0 and rms["knee_lateral_bw"] > 0)
if not ok:
    print(json.dumps({"joint_rms": joint_rms, "rms": rms}), file=sys.stderr)
sys.exit(0 if ok else 1)
PY

"$gaitsim" track nowhere --out x --weight accel=-1 >/dev/null 2>&1
check "track --weight accel=-1: usage, exit 2" test $? -eq 2
"$gaitsim" track nowhere --out x --weight accel=1 >/dev/null 2>&1
check "track --weight accel=1 parses (missing trial: exit 1)" test $? -eq 1
finish
