#!/usr/bin/env bash
# gaitsim batch --local on the planar model (mjmodels/gait2d.xml, 5 nodes; about 30 s on 2
# cores): a plan of two tracks (10 iterations), a three-speed sweep from the first (each speed
# from the one before, 3 iterations each), a track made to fail (a broken model) and a prediction
# from it. With --local 2: the two tracks run at once and never more than two solves; exit 1
# (one failed); the failure's dependant skipped, the rest stopped short at their limits (exit 3);
# each solve's record and log (out/logs/NAME.json, NAME.log; the solution folder holds the
# result only, the failure none); the sweep's speeds continue from each other and hold their speed
# (to the violation left); batch.csv with one row per solve, the records' wall times and the
# tracks' RMS errors. The same plan again keeps the five that ended and redoes only the failure;
# a changed sweep option redoes the sweep and keeps the tracks. batch-status reads the folders.
# SIGTERM to the batch stops a running solve cleanly (the batch sends it one SIGINT): exit 3, the
# record says interrupted, the best iterate is written, and the next run redoes it. Plan errors (unknown dependency, cycle, bad option,
# a name the batch uses itself, unknown trial) exit 1 with one line naming the field and create nothing.
# usage: batch.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"
export OPENBLAS_NUM_THREADS=1
trial=$src/mjmodels/trials/jw_ngait_og5

echo '<mujoco><worldbody><body><joint type="bogus"/></body></worldbody></mujoco>' >bad.xml
plan() {  # plan SWEEP_ITER: the test plan into plan.json
  cat >plan.json <<EOF
{"model": "$src/mjmodels/gait2d.xml",
 "options": {"nodes": 5, "threads": 1, "max-iter": 10, "refine": 0},
 "solves": [
  {"name": "t1", "track": "$trial"},
  {"name": "t2", "track": "$trial", "options": {"weight": ["grf=5"]}},
  {"name": "up", "sweep": [1.2, 1.4, 1.6], "guess": "t1", "start": "neighbour", "options": {"max-iter": $1}},
  {"name": "bad", "track": "$trial", "options": {"model": "bad.xml"}},
  {"name": "after_bad", "predict": 1.2, "guess": "bad"}]}
EOF
}
plan 3
"$gaitsim" batch plan.json --out out --local 2 >run1.txt 2>err1.txt
status=$?
check "one failed: exit 1 (got $status)" test "$status" -eq 1
check "runs: the tracks together, never more than two at once, the dependant skipped" \
  /usr/bin/python3 - run1.txt <<'PY'
import re, sys
going, most, both = set(), 0, False
skipped = False
for line in open(sys.argv[1]):
    m = re.match(r"batch: (\S+): (started|exit|skipped)", line)
    if not m:
        continue
    if m[2] == "started":
        going.add(m[1])
        both |= {"t1", "t2"} <= going
    elif m[2] == "exit":
        going.discard(m[1])
    else:
        skipped |= m[1] == "after_bad"
    most = max(most, len(going))
sys.exit(0 if most == 2 and both and skipped else 1)
PY
check "records and logs of the five that ran" /usr/bin/python3 - out <<'PY'
import json, sys
d = sys.argv[1]
want = {"t1": 3, "t2": 3, "up_1.2": 3, "up_1.4": 3, "up_1.6": 3, "bad": 1}
ok = True
for n, code in want.items():
    r = json.load(open(f"{d}/logs/{n}.json"))
    log = open(f"{d}/logs/{n}.log").read()
    ok &= r["exit"] == code and not r["interrupted"] and 0 < r["wall_s"] < 120
    ok &= ("iter" in log) if code == 3 else ("bad.xml" in log)
    if not ok:
        print(n, r, file=sys.stderr)
sys.exit(0 if ok else 1)
PY
check "the skipped solve has no folder" test ! -e out/after_bad
check "the failed solve left no folder (a solve writes its folder whole or not at all)" \
  test ! -e out/bad
check "a solution folder holds the solve's result only (its log and record in out/logs)" \
  test "$(ls out/t1 | grep -c -e summary.json -e log.txt -e batch.json)" -eq 1 -a -f out/t1/summary.json
check "sweep with \"start\": \"neighbour\": each speed from the one before, holding its speed" /usr/bin/python3 - out <<'PY'
import json, os, sys
d = os.path.realpath(sys.argv[1])
ok = True
for v, g in (("1.2", "t1"), ("1.4", "up_1.2"), ("1.6", "up_1.4")):
    cmd = json.load(open(f"{d}/logs/up_{v}.json"))["command"]
    s = json.load(open(f"{d}/up_{v}/summary.json"))
    ok &= cmd[cmd.index("--guess") + 1] == f"{d}/{g}" and cmd[cmd.index("--speed") + 1] == v
    ok &= abs(s["speed_mps"] - float(v)) <= max(1e-4, s["max_violation"])
sys.exit(0 if ok else 1)
PY
check "batch.csv: a row per solve, statuses, wall times, RMS of the tracks" \
  /usr/bin/python3 - "$PWD/out" <<'PY'
import csv, json, math, sys
d = sys.argv[1]
rows = {r["solve"]: r for r in csv.DictReader(open(f"{d}/batch.csv"))}
want = {"t1": "stopped short", "t2": "stopped short", "up_1.2": "stopped short",
        "up_1.4": "stopped short", "up_1.6": "stopped short", "bad": "failed",
        "after_bad": "skipped"}
ok = {n: r["status"] for n, r in rows.items()} == want
for n in ("t1", "t2", "up_1.2"):
    r, rec = rows[n], json.load(open(f"{d}/logs/{n}.json"))
    s = json.load(open(f"{d}/{n}/summary.json"))
    ok &= abs(float(r["wall_s"]) - rec["wall_s"]) <= 0.05
    ok &= abs(float(r["stride_time_s"]) - s["stride_time_s"]) <= 1e-4
    if n.startswith("t"):
        ok &= abs(float(r["rms_joint_rot_deg"]) - s["rms"]["joint_rot_deg"]) <= 1e-4
    else:
        ok &= r["rms_joint_rot_deg"] == "" and float(r["speed_target_mps"]) == 1.2
ok &= rows["after_bad"]["exit"] == "" and rows["bad"]["exit"] == "1"
if not ok:
    print(rows, file=sys.stderr)
sys.exit(0 if ok else 1)
PY
check "batch.md: a row per solve" test "$(grep -c '^| [a-z]' out/batch.md)" -eq 8

# the same plan again: the five that ended are kept, the failure is tried again
cp out/logs/t1.json t1_record.json
"$gaitsim" batch plan.json --out out --local 2 >run2.txt 2>&1
status=$?
check "again: exit 1 (got $status)" test "$status" -eq 1
check "again: five kept" grep -q '^batch: 7 solves, 5 kept from an earlier run' run2.txt
check "again: only bad started" test "$(grep -c ': started' run2.txt)" -eq 1
check "again: t1's record untouched" cmp -s t1_record.json out/logs/t1.json
# a changed sweep option: the sweep is redone, the tracks kept
plan 2
"$gaitsim" batch plan.json --out out --local 2 >run3.txt 2>&1
check "sweep changed: its three speeds and bad redone, the tracks kept" \
  test "$(grep ': started' run3.txt | cut -d: -f2 | tr -d ' ' | sort | tr '\n' ' ')" = \
  "bad up_1.2 up_1.4 up_1.6 "
check "sweep changed: the new iteration limit" grep -q '"2"' out/logs/up_1.6.json
"$gaitsim" batch-status out >status.txt 2>&1
check "batch-status: statuses" test "$(awk '{print $1 ":" $2}' status.txt | tr '\n' ' ')" = \
  "t1:stopped t2:stopped up_1.2:stopped up_1.4:stopped up_1.6:stopped bad:failed after_bad:skipped "

# SIGTERM while a long track runs: it stops with its best iterate; the next run redoes it
cat >long.json <<EOF
{"model": "$src/mjmodels/gait2d.xml",
 "solves": [{"name": "long", "track": "$trial",
             "options": {"nodes": 10, "threads": 1, "max-iter": 5000, "refine": 0}}]}
EOF
"$gaitsim" batch long.json --out lo --local 1 >run4.txt 2>&1 &
pid=$!
for _ in $(seq 300); do grep -q '^iter' lo/logs/long.log 2>/dev/null && break; sleep 0.1; done
kill -TERM "$pid"
wait "$pid"
status=$?
check "SIGTERM: exit 3 (got $status)" test "$status" -eq 3
check "SIGTERM: the solve interrupted with its best iterate written" /usr/bin/python3 - lo/long <<'PY'
import json, sys
r = json.load(open(sys.argv[1] + "/../logs/long.json"))
s = json.load(open(sys.argv[1] + "/summary.json"))
ok = r["interrupted"] and r["exit"] == 3 and r["wall_s"] < 60 and s["iterations"] < 5000
if not ok:
    print(r, s.get("iterations"), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
n=$(grep -c 'stop signal' lo/logs/long.log)
check "SIGTERM: one stop signal reached the solve (got $n)" test "$n" -eq 1
"$gaitsim" batch long.json --out lo --local 1 >run5.txt 2>&1 &
pid=$!
for _ in $(seq 300); do grep -q 'started' run5.txt && break; sleep 0.1; done
kill -TERM "$pid"
wait "$pid"
check "after SIGTERM: the interrupted solve is not kept" grep -q '^batch: 1 solves, 0 kept' run5.txt

# plan errors: one line naming the field, exit 1, nothing created
bad_plan() {  # bad_plan NAME EXPECTED-LINE SOLVES-JSON
  echo "{\"solves\": [$3]}" >p.json
  local err
  err=$("$gaitsim" batch p.json --out never 2>&1 >/dev/null)
  local rc=$?
  check "$1: exit 1 (got $rc)" test "$rc" -eq 1
  check "$1: the one line (got: $err)" test "$err" = "gaitsim: p.json: $2"
  check "$1: nothing created" test ! -e never
}
t="{\"name\": \"a\", \"track\": \"$trial\"}"
bad_plan "unknown dependency" 'solves[3].depends: unknown solve "x"' \
  "$t, {\"name\": \"b\", \"predict\": 1.2, \"guess\": \"a\"}, {\"name\": \"c\", \"predict\": 1.2, \"guess\": \"a\"}, {\"name\": \"d\", \"predict\": 1, \"guess\": \"a\", \"depends\": [\"x\"]}"
bad_plan "cycle" 'solves[1].depends: a cycle: b -> c -> b (each waits for the next)' \
  "$t, {\"name\": \"b\", \"predict\": 1.2, \"guess\": \"c\"}, {\"name\": \"c\", \"predict\": 1.2, \"guess\": \"a\", \"depends\": [\"b\"]}"
bad_plan "bad option" 'solves[0].options.nodes: an integer >= 3 and <= 1000000 expected' \
  "{\"name\": \"a\", \"track\": \"$trial\", \"options\": {\"nodes\": 2}}"
bad_plan "option of the other command" 'solves[0].options.refine: not an option of gaitsim predict' \
  "{\"name\": \"a\", \"predict\": 1.2, \"guess\": \"$PWD/out/t1\", \"options\": {\"refine\": 2}}"
bad_plan "a name the batch uses itself" "solves[0].name: a name of letters, digits, '_', '-', '.' expected (it names the solve's folder; not logs, slurm, plan.json, batch.csv, batch.md)" \
  "{\"name\": \"logs\", \"track\": \"$trial\"}"
bad_plan "unknown trial" 'solves[0].track: no trial folder (coordinates.mot, grf.mot) "nowhere"' \
  '{"name": "a", "track": "nowhere"}'
bad_plan "bad start" 'solves[1].start: "guess" or "neighbour" expected, with a "sweep"' \
  "$t, {\"name\": \"s\", \"sweep\": [1, 2], \"guess\": \"a\", \"start\": \"chain\"}"
bad_plan "start without a sweep" 'solves[1].start: "guess" or "neighbour" expected, with a "sweep"' \
  "$t, {\"name\": \"p\", \"predict\": 1, \"guess\": \"a\", \"start\": \"guess\"}"
# a sweep's speeds start from its guess by default (as gaitsim sweep): every command --guess DIR/a
echo "{\"solves\": [$t, {\"name\": \"s\", \"sweep\": [1, 1.5, 2], \"guess\": \"a\"}]}" >p.json
"$gaitsim" batch p.json --check >check.txt 2>&1
check "sweep by default: exit 0, each speed from the guess ($(grep -c -- '--guess [^ ]*/a ' check.txt) of 3)" \
  test "$(grep -c -- '--guess [^ ]*/a ' check.txt)" -eq 3
# the plan's option table follows the commands: every option in `gaitsim track --help` and
# `gaitsim predict --help` is known to the plan (a wrong value is refused as a value)
known=0 unknown=""
for cmd in track predict; do
  if [ "$cmd" = track ]; then head="\"track\": \"$trial\""; else head="\"predict\": 1.2, \"guess\": \"$PWD/out/t1\""; fi
  for opt in $("$gaitsim" "$cmd" --help | grep -oE '^ +--[a-z-]+' | sed 's/^ *--//'); do
    echo "{\"solves\": [{\"name\": \"a\", $head, \"options\": {\"$opt\": {}}}]}" >p.json
    err=$("$gaitsim" batch p.json --check 2>&1 >/dev/null)
    case $err in
      *"options.$opt: "*unknown*|*"options.$opt: not an option"*|"") unknown="$unknown $cmd:$opt" ;;
      *"options.$opt: "*) known=$((known + 1)) ;;
      *) unknown="$unknown $cmd:$opt($err)" ;;
    esac
  done
done
check "every option of track and predict known to the plan (unknown:$unknown)" test -z "$unknown"
check "options checked: at least 25 (got $known)" test "$known" -ge 25
"$gaitsim" batch plan.json --out x --local 0 >/dev/null 2>&1
check "--local 0: usage, exit 2" test $? -eq 2
finish
