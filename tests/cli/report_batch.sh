#!/usr/bin/env bash
# gaitsim report on a batch folder (gaitsim batch: batch.csv, plan.json) and the report folder
# written whole. A hand-written batch.csv in gs_batch_collect's columns (two tracks with Table 1
# RMS errors, a three-speed sweep "up" of plan.json, a prediction, a failed solve and a skipped
# one with empty cells): exit 0; wall_time, gait_speed and rms PNGs with a valid signature and a
# plausible size; report.md links them, its batch table holds batch.csv's cells row by row (empty
# as -), the count per status, the summed wall time and the sweep's solves. Without tracks no
# rms.png (and a note). Whole folder: a report made to fail midway by a real write fault (a file
# size limit, ulimit -f, that the first figure fits under and the second does not) after batch.csv
# changed exits 1 with one line naming the figure and leaves the earlier report byte for byte,
# with no temporary folder; with no earlier report it leaves no folder (nor the parents it
# made); a malformed batch.csv (found by the script, after the folder was begun) the same; --out
# on a folder that holds no report.md is refused untouched; SIGTERM while the script runs (held
# in reading plan.json, a FIFO) is passed on to it: exit 1, one line, the earlier report kept, no
# temporary folder; a later good run replaces the whole folder (a stray file of the old one is
# gone).
# usage: report_batch.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

mkdir b
cat >b/plan.json <<'JSON'
{"model": "mjmodels/gait2d.xml", "options": {"nodes": 5},
 "solves": [{"name": "t1", "track": "trial"}, {"name": "t2", "track": "trial"},
  {"name": "up", "sweep": [1.2, 1.4, 1.6], "guess": "t1"},
  {"name": "p09", "predict": 0.9, "guess": "t2"},
  {"name": "bad", "track": "trial"}, {"name": "after_bad", "predict": 1.2, "guess": "bad"}]}
JSON
head=solve,command,speed_target_mps,status,exit,wall_s,stride_time_s,speed_mps,cost_of_transport_j_per_kg_m
head=$head,rms_pelvis_rot_deg,rms_pelvis_trans_cm,rms_joint_rot_deg,rms_grf_ap_bw,rms_grf_v_bw
head=$head,rms_grf_ml_bw,rms_knee_contact_bw
cat >b/batch.csv <<EOF
$head
t1,track,,stopped short,3,2.9,1.1055,0.8417,2.5576,11.0855,12.8683,18.8514,0.0733,0.1610,0.2046,
t2,track,,done,0,12.7,1.0512,1.2776,3.8601,0.1501,0.3679,2.4230,0.0155,0.0411,0.0148,0.2710
up_1.2,predict,1.2,stopped short,3,2.8,1.0188,1.2000,4.0529,,,,,,,
up_1.4,predict,1.4,stopped short,3,1.6,0.8628,1.4000,4.2715,,,,,,,
up_1.6,predict,1.6,stopped short,3,1.6,0.6184,1.6000,4.7575,,,,,,,
p09,predict,0.9,stopped short,3,2.7,0.7261,0.9000,7.4408,,,,,,,
bad,track,,failed,1,0.1,,,,,,,,,,
after_bad,predict,1.2,skipped,,,,,,,,,,,,
EOF

out=$("$gaitsim" report b)
check "batch report exits 0" test $? -eq 0
check "report names its folder" grep -q "b/report" <<<"$out"
for f in wall_time gait_speed rms; do
  check "$f.png is a plausible PNG ($(png_info b/report/$f.png))" plausible_png b/report/$f.png
done
md=b/report/report.md
check "report.md written" test -s $md
check "exactly the three figures linked" \
  test "$(grep -c '^!\[\(wall_time\|gait_speed\|rms\)\.png\](\(wall_time\|gait_speed\|rms\)\.png)$' $md)" -eq 3
check "batch table: batch.csv's cells row by row" /usr/bin/python3 - b/batch.csv $md <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
md = [l.strip() for l in open(sys.argv[2]) if l.startswith("| ")]
want = ["| " + " | ".join(rows[0]) + " |"] + \
       ["| " + " | ".join(c if c else "-" for c in r) + " |" for r in rows[1:]]
got = md[:len(want)]
for w, g in zip(want, got):
    if w != g:
        print(f"expected {w}\n  got    {g}", file=sys.stderr)
sys.exit(0 if got == want else 1)
PY
check "a row with its numbers" \
  grep -q '^| t2 | track | - | done | 0 | 12.7 | 1.0512 | 1.2776 | 3.8601 | 0.1501 | 0.3679 | 2.4230 | 0.0155 | 0.0411 | 0.0148 | 0.2710 |$' $md
# 2.9 + 12.7 + 2.8 + 1.6 + 1.6 + 2.7 + 0.1 = 24.4 s
check "count per status and summed wall time" grep -q \
  ': 8 solve(s) in batch.csv: 5 stopped short, 1 done, 1 failed, 1 skipped; wall time 24.4 s in all' $md
check "the sweep's solves from plan.json" grep -q '^Sweeps (plan.json): up: up_1.2, up_1.4, up_1.6\.$' $md
check "no temporary files left" \
  test -z "$(ls -A b/report | grep -v '^\(report\.md\|[a-z_]*\.png\)$')$(ls -A b | grep '^\.')"

# predictions only: no rms.png, a note
mkdir p && grep -v ',track,' b/batch.csv >p/batch.csv
"$gaitsim" report p >/dev/null
check "predictions only: exit 0" test $? -eq 0
check "predictions only: two figures, no rms.png" test "$(ls p/report/*.png | wc -l)" -eq 2 -a ! -e p/report/rms.png
check "predictions only: noted" grep -q '^No track with RMS errors: no rms.png\.$' p/report/report.md

# the whole folder: a write fault midway, after batch.csv changed (t2's wall time 12.7 -> 13.9 s)
md5sum b/report/* >old.md5
sed -i 's/^t2,track,,done,0,12.7,/t2,track,,done,0,13.9,/' b/batch.csv
blocks=$(( $(stat -c %s b/report/wall_time.png) / 1024 + 2 ))  # ulimit -f counts 1024 bytes
check "the fault is midway: wall_time.png fits under $blocks kB, gait_speed.png does not" \
  test "$(stat -c %s b/report/gait_speed.png)" -gt $(( blocks * 1024 ))
err=$(ulimit -f $blocks; "$gaitsim" report b 2>&1 >/dev/null)
check "write fault exits 1" test $? -eq 1
check "write fault: one line naming the figure (got: $err)" \
  test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep '^gaitsim: b/report/gait_speed\.png: File too large$' <<<"$err")"
check "write fault: the earlier report byte for byte" md5sum --quiet -c old.md5
check "write fault: the earlier report only" test "$(ls b/report | wc -l)" -eq 4
check "write fault: no temporary folder" test -z "$(ls -A b | grep '^\.')"
err=$(ulimit -f $blocks; "$gaitsim" report b --out new/sub/rep 2>&1 >/dev/null)
check "write fault, no earlier report: exit 1" test $? -eq 1
check "write fault, no earlier report: no folder left, nor its parents" test ! -e new

# a malformed batch.csv: one line naming it, the earlier report kept
cp b/batch.csv good.csv
sed -i 's/^up_1.4,predict,1.4,stopped short,3,1.6,/up_1.4,predict,1.4,stopped short,3,fast,/' b/batch.csv
err=$("$gaitsim" report b 2>&1 >/dev/null)
check "malformed batch.csv exits 1" test $? -eq 1
check "malformed: one line naming batch.csv (got: $err)" \
  test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep "^gaitsim: b/batch.csv: line 5: wall_s 'fast' is not a number$" <<<"$err")"
check "malformed: the earlier report byte for byte" md5sum --quiet -c old.md5
check "malformed: no temporary folder" test -z "$(ls -A b | grep '^\.')"
cp good.csv b/batch.csv

# --out on a folder that is not a report: refused, untouched
mkdir mine && echo keep >mine/notes.txt
err=$("$gaitsim" report b --out mine 2>&1 >/dev/null)
check "not a report folder: exit 1" test $? -eq 1
check "not a report folder: one line (got: $err)" \
  test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep '^gaitsim: report: mine: exists and holds no report\.md' <<<"$err")"
check "not a report folder: untouched" test "$(ls -A mine)" = notes.txt -a "$(cat mine/notes.txt)" = keep

# SIGTERM midway: the script held reading plan.json (a FIFO) while the temporary folder exists;
# gaitsim passes the signal on, exits 1 with one line, the earlier report kept, no temporary folder
mv b/plan.json plan.json && mkfifo b/plan.json
"$gaitsim" report b >/dev/null 2>sigterm.txt &
pid=$!
for _ in $(seq 100); do
  [ -n "$(ls -A b | grep '^\.report\.tmp\.')" ] && break
  sleep 0.1
done
check "SIGTERM: sent while the temporary folder exists" test -n "$(ls -A b | grep '^\.report\.tmp\.')"
sleep 0.5  # the script is in open(plan.json) by now
kill -TERM $pid
wait $pid
status=$?
check "SIGTERM: exit 1 (got $status)" test "$status" -eq 1
check "SIGTERM: one line ($(cat sigterm.txt))" \
  test "$(wc -l <sigterm.txt)" -eq 1 -a -n "$(grep '^gaitsim: report: stopped by signal 15; b/report is as it was$' sigterm.txt)"
check "SIGTERM: the earlier report byte for byte" md5sum --quiet -c old.md5
check "SIGTERM: no temporary folder" test -z "$(ls -A b | grep '^\.')"
rm b/plan.json && mv plan.json b/plan.json

# a good run replaces the whole folder: the new wall time, a stray file of the old folder gone
touch b/report/stray.png
"$gaitsim" report b >/dev/null
check "rerun exits 0" test $? -eq 0
check "rerun: the new wall time" grep -q '^| t2 | track | - | done | 0 | 13.9 | ' $md
check "rerun: 25.6 s in all" grep -q 'wall time 25.6 s in all' $md
check "rerun: the stray file of the old folder is gone" test ! -e b/report/stray.png
check "rerun: no temporary folder" test -z "$(ls -A b | grep '^\.')"

finish
