#!/usr/bin/env bash
# gaitsim report on a copy of the fixture solution (tests/fixtures/solution_small) with a
# summary.json carrying RMS errors and solve facts: exit 0; kinematics, grf, knee_contact,
# excitations and joint_moments PNGs with a valid signature and a plausible size; report.md has
# the joint moments' RMS differences (the ankles within 3 N m of the trial's) and the Table 1 rows
# with these numbers beside the paper's and links the figures, and the metabolic table of a
# metabolics.sto written here (largest muscle first, mean W and share of the total); --out writes elsewhere; a folder
# without states.sto, or with a NaN in a used column, exits 1 with one line naming the file and
# writes no report.md; usage errors exit 2.
# usage: report.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

cp -r "$src/tests/fixtures/solution_small" sol
cat >sol/summary.json <<EOF
{
  "problem": "tracking",
  "model": "$src/mjmodels/jw_fullbody.xml",
  "trial": "$src/mjmodels/trials/jw_ngait_og5",
  "status": "solved",
  "iterations": 123,
  "wall_s": 45.6,
  "nodes": 14,
  "stride_time_s": 1.1054841,
  "grf_scale": 0.951,
  "rms": {"pelvis_rot_deg": 0.345, "pelvis_trans_cm": 0.678, "grf_ap_bw": 0.0123,
          "grf_v_bw": 0.0456, "grf_ml_bw": 0.0078, "joint_rot_deg": 2.34, "knee_contact_bw": null}
}
EOF

# metabolics.sto: three muscles at constant 10, 30 and 60 W (their total 100 W) over the stride
/usr/bin/python3 - sol/metabolics.sto <<'PY'
import sys
rows = "".join(f"{0.1 * k:.1f}\t10\t30\t60\t100\n" for k in range(12))
open(sys.argv[1], "w").write("metabolics\nversion=1\nnRows=12\nnColumns=5\ninDegrees=no\n"
                             "endheader\ntime\tsoleus\tvaslat\tercspn_r\ttotal\n" + rows)
PY
out=$("$gaitsim" report sol)
check "report exits 0" test $? -eq 0
check "report names its folder" grep -q "sol/report" <<<"$out"
for f in kinematics grf knee_contact excitations joint_moments; do
  check "$f.png is a plausible PNG ($(png_info sol/report/$f.png))" plausible_png sol/report/$f.png
done
md=sol/report/report.md
check "report.md written" test -s $md
check "metabolic table: the largest first, mean W and share" \
  grep -q '^| ercspn_r | 60.0 | 60.0 |$' $md
check "metabolic table: total" grep -q 'Mean over the stride: 100.0 W in all' $md
check "row pelvis rotations" grep -q '^| Pelvis rotations | deg | 0.345 | 0.21 |$' $md
check "row pelvis translations" grep -q '^| Pelvis translations | cm | 0.678 | 0.20 |$' $md
check "row GRF fore-aft" grep -q '^| GRF fore-aft | BW | 0.0123 | 0.02 |$' $md
check "row GRF vertical" grep -q '^| GRF vertical | BW | 0.0456 | 0.04 |$' $md
check "row GRF mediolateral" grep -q '^| GRF mediolateral | BW | 0.0078 | 0.02 |$' $md
check "row joint rotations" grep -q '^| Joint rotations | deg | 2.34 | 1.98 |$' $md
check "row knee contact (null)" grep -q '^| Knee contact force | BW | n/a | 0.32 |$' $md
check "solve facts" grep -q '^| status | solved |$' $md
check "iterations" grep -q '^| iterations | 123 |$' $md
check "wall time" grep -q '^| wall time (s) | 45.6 |$' $md
check "links the figures" test "$(grep -c '^!\[.*\](\(kinematics\|grf\|knee_contact\|excitations\|joint_moments\)\.png)$' $md)" -eq 5
# the joint moments by `gaitsim moments` of the fixture (the trial's own rows) against the trial's:
# a row per hip, knee and ankle coordinate; the ankles, loaded by the ground reaction, within
# 3 N m (measured: 2.1 and 0.7); the hips and knees differ by up to 64 N m, the swing's
# accelerations differenced over the fixture's 14 rows
check "joint-moment table: eight rows, the ankles within 3 N m" /usr/bin/python3 - $md <<'PY2'
import re, sys
rows = dict(re.findall(r"^\| (\w+) \| ([0-9.]+) \|$", open(sys.argv[1]).read().split(
    "## Joint moments against the measured gait")[1], re.M))
ok = len(rows) == 8 and float(rows["ankle_angle"]) < 3 and float(rows["ankle_angle_l"]) < 3
sys.exit(0 if ok else 1)
PY2
check "caption names the GRF scale" grep -q 'grf_scale = 0.9510' $md
check "no temporary files left" test -z "$(ls -A sol/report | grep -v '^\(report\.md\|[a-z_]*\.png\)$')"

# a left-knee column (contact_total_l) adds the left knee's panel beside the right's
cp -r sol left && rm -rf left/report
awk 'f == 1 {$0 = $0 "\tcontact_total_l"; f = 2} f == 2 && !/contact_total_l/ {$0 = $0 "\t" 700 + NR}
     /^nColumns=/ {$0 = "nColumns=5"} /^endheader/ {f = 1} {print}' \
  sol/knee_contact.sto >left/knee_contact.sto
"$gaitsim" report left >/dev/null
check "left knee: report exits 0" test $? -eq 0
w3=$(png_info sol/report/knee_contact.png) w4=$(png_info left/report/knee_contact.png)
w3=${w3#ok } w4=${w4#ok }
check "left knee: one more panel ($w3 -> $w4)" test "${w4%x*}" = "$(( ${w3%x*} * 4 / 3 ))"
check "left knee: caption" grep -q 'left (1-DOF) knee: compressive joint reaction' left/report/report.md

# --out elsewhere; without knee_contact.sto there is no knee figure
cp -r sol noknee && rm -rf noknee/report noknee/knee_contact.sto
"$gaitsim" report noknee --out elsewhere >/dev/null
check "--out exits 0" test $? -eq 0
check "--out: report.md there" test -s elsewhere/report.md
check "--out: nothing in DIR/report" test ! -e noknee/report
check "no knee file: no knee figure" test ! -e elsewhere/knee_contact.png

# a missing states.sto: exit 1, one line naming the file, no report.md
cp -r sol bad && rm -rf bad/report bad/states.sto
err=$("$gaitsim" report bad 2>&1 >/dev/null)
check "missing states.sto exits 1" test $? -eq 1
check "one line naming states.sto (got: $err)" test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep '^gaitsim: .*states\.sto: ' <<<"$err")"
check "missing states.sto: nothing written" test ! -e bad/report

# a NaN in a used column of controls.sto
cp -r sol nan && rm -rf nan/report
awk 'f && n++ == 3 {$39 = "nan"} {print} /^endheader/ {f = 1}' OFS='\t' sol/controls.sto >nan/controls.sto
err=$("$gaitsim" report nan 2>&1 >/dev/null)
check "NaN exits 1" test $? -eq 1
check "NaN: one line naming controls.sto (got: $err)" test "$(wc -l <<<"$err")" -eq 1 -a -n "$(grep '^gaitsim: .*controls\.sto:.*column .*NaN' <<<"$err")"
check "NaN: nothing written" test ! -e nan/report

# usage
"$gaitsim" report >/dev/null 2>&1
check "no DIR exits 2" test $? -eq 2
"$gaitsim" report sol --bogus >/dev/null 2>&1
check "unknown option exits 2" test $? -eq 2
"$gaitsim" report --help | grep -q '^usage: gaitsim report DIR'
check "--help prints usage" test $? -eq 0

finish
