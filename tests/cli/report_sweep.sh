#!/usr/bin/env bash
# gaitsim report on a tiny sweep folder: the fixture solution (tests/fixtures/solution_small)
# copied into predict_0.9 and predict_1.6 (the second with a left-knee column) and as the tracking
# solution "track" that their summary.json names as guess, and a hand-written sweep.csv with a
# third speed (2.0 m/s, nan: a failed solve without a folder). Exit 0; kinematics, grf,
# excitations, gait_parameters and knee_contact PNGs with a valid signature and a plausible size
# (the knee figure with the left knee's panel); report.md links them, has the sweep table, the
# paper's stride times, the tracking solution found through the guess (from another folder), the
# speed left out; --track and --out; a malformed sweep.csv (short row, missing column,
# non-numeric value) or a NaN in a prediction's controls.sto exits 1 with one line naming the
# file and writes nothing; a missing --track folder exits 1 naming it.
# usage: report_sweep.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

summary() {  # summary FILE JSON-FIELDS: a summary.json with the fixture's stride time
  printf '{"problem": "%s", "stride_time_s": 1.1054841, "body_weight_n": 614.25, %s}\n' "$2" "$3" >"$1"
}

cp -r "$src/tests/fixtures/solution_small" track
summary track/summary.json tracking '"speed_mps": 1.27, "status": "solved"'
mkdir sw
for v in 0.9 1.6; do
  cp -r "$src/tests/fixtures/solution_small" sw/predict_$v
  summary sw/predict_$v/summary.json prediction "\"guess\": \"track\", \"speed_mps\": $v"
done
# the faster speed's knee file gains a left-knee column (contact_total_l)
awk 'f == 1 {$0 = $0 "\tcontact_total_l"; f = 2} f == 2 && !/contact_total_l/ {$0 = $0 "\t" 700 + NR}
     /^nColumns=/ {$0 = "nColumns=5"} /^endheader/ {f = 1} {print}' \
  "$src/tests/fixtures/solution_small/knee_contact.sto" >sw/predict_1.6/knee_contact.sto
cat >sw/sweep.csv <<'EOF'
speed_mps,stride_time_s,stride_length_m,stride_time_change_pct,stride_length_change_pct,cost_of_transport_j_per_kg_m,peak_vertical_grf_bw,peak_knee_contact_r_bw,peak_knee_contact_l_bw,peak_soleus_excitation,peak_gastrocnemius_excitation,status
1.6,0.9123,1.4597,-17.47,3.98,3.412,1.650,2.900,3.100,0.600,0.500,wall-time limit reached
0.9,1.2345,1.1111,11.67,-20.85,4.567,1.100,2.400,2.300,0.400,0.300,wall-time limit reached
2,nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,missing
EOF
cp sw/sweep.csv good.csv

# from another folder: the guess "track" is found beside the sweep folder
mkdir elsewhere
out=$(cd elsewhere && "$gaitsim" report ../sw)
check "sweep report exits 0" test $? -eq 0
check "report names its folder" grep -q "sw/report" <<<"$out"
figs="kinematics grf excitations gait_parameters knee_contact"
for f in $figs; do
  check "$f.png is a plausible PNG ($(png_info sw/report/$f.png))" plausible_png sw/report/$f.png
done
md=sw/report/report.md
check "report.md written" test -s $md
for f in $figs; do
  check "report.md links $f.png" grep -q "^!\[$f\.png\]($f\.png)$" $md
done
check "exactly the five figures linked" test "$(grep -c '^!\[.*\.png\](.*\.png)$' $md)" -eq 5
check "table header from sweep.csv" grep -q '^| speed_mps | stride_time_s | stride_length_m | ' $md
check "table rows ascending" test "$(grep -o '^| [0-9.]* | [0-9.n]' $md | cut -d' ' -f2 | tr '\n' ' ')" = "0.9 1.6 2 "
check "table keeps the status" grep -q '^| 0.9 | 1.2345 | 1.1111 | .* | wall-time limit reached |$' $md
check "paper's stride times" grep -q '1.30 s at 0.8 m/s and 0.92 s at 2.0 m/s' $md
check "tracking solution found through the guess" grep -q "^Tracking solution \`$work/track\`" $md
check "speed without a folder listed" grep -q '2 m/s: no folder predict_2' $md
check "left knee in the caption" grep -q "left (1-DOF) knee's compressive joint reaction" $md
check "no temporary files left" test -z "$(ls -A sw/report | grep -v '^\(report\.md\|[a-z_]*\.png\)$')"
k=$(png_info sw/report/knee_contact.png) k=${k#ok }
check "knee figure: two panels ($k)" test "${k%x*}" -ge 1200

# --track and --out: the same figures elsewhere, the tracking solution named
cp -r track track2
"$gaitsim" report sw --track track2 --out rep2 >/dev/null
check "--track --out exits 0" test $? -eq 0
check "--track: named" grep -q "^Tracking solution \`$work/track2\` (--track)" rep2/report.md
check "--out: five figures" test "$(ls rep2/*.png | wc -l)" -eq 5

# without a tracking solution: a note, still exit 0
cp -r sw notrack && rm -rf notrack/report
sed -i 's/"guess": "track"/"guess": "gone"/' notrack/predict_*/summary.json
"$gaitsim" report notrack --out rep3 >/dev/null 2>&1
check "guess not found: exit 0" test $? -eq 0
check "guess not found: noted" grep -q "^No tracking solution in the figures: guess \`gone\` not found" rep3/report.md

# malformed sweep.csv: one line naming sweep.csv, exit 1, nothing written
bad_csv() {  # bad_csv NAME REASON-REGEX: sw/sweep.csv as prepared, report, check, restore
  local err st
  rm -rf sw/report
  err=$("$gaitsim" report sw 2>&1 >/dev/null)
  st=$?
  check "$1: exit 1 (got $st)" test "$st" -eq 1
  check "$1: one line naming sweep.csv (got: $err)" test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep "^gaitsim: sw/sweep\.csv: $2" <<<"$err")"
  check "$1: nothing written" test ! -e sw/report
  cp good.csv sw/sweep.csv
}
sed -i '3s/,[^,]*$//' sw/sweep.csv
bad_csv "short row" 'line 3: 11 fields, header has 12'
sed -i '1s/cost_of_transport_j_per_kg_m/cot/' sw/sweep.csv
bad_csv "missing column" 'missing column(s) cost_of_transport_j_per_kg_m'
sed -i '2s/^1.6,0.9123/1.6,fast/' sw/sweep.csv
bad_csv "non-numeric" "line 2: stride_time_s 'fast' is not a number"
printf '' >sw/sweep.csv
bad_csv "empty" 'empty'

# a NaN in a prediction's controls.sto: names that file
cp -r sw nan && rm -rf nan/report
awk 'f && n++ == 3 {$39 = "nan"} {print} /^endheader/ {f = 1}' OFS='\t' \
  sw/predict_0.9/controls.sto >nan/predict_0.9/controls.sto
err=$("$gaitsim" report nan --track track 2>&1 >/dev/null)
check "NaN exits 1" test $? -eq 1
check "NaN: one line naming the controls.sto (got: $err)" test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep '^gaitsim: nan/predict_0.9/controls\.sto: column .*NaN' <<<"$err")"
check "NaN: nothing written" test ! -e nan/report

# a missing --track folder
err=$("$gaitsim" report sw --track nowhere --out rep4 2>&1 >/dev/null)
check "missing --track exits 1" test $? -eq 1
check "missing --track: named (got: $err)" grep -q '^gaitsim: nowhere: ' <<<"$err"
check "missing --track: nothing written" test ! -e rep4

finish
