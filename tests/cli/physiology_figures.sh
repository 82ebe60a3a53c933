#!/usr/bin/env bash
# scripts/physiology_figures.py on a synthetic results folder: a tracking solution whose
# hip_adduction is the trial's minus 5 deg at every node (mean -5.000, RMS 5.000; the model's
# mean +1.00 against the measured +6.00 over the nodes), and a prediction at 2.0 m/s of a 1000 N
# (101.94 kg) body whose erector spinae spend 300 W and vasti 100 W throughout (trunk 2.943
# W/kg, 1.472 J/(kg m), 75 % of 3.924 W/kg; vasti 0.981 W/kg, 0.490 J/(kg m)), the vasti slack
# (5 N, below 1 % of their 1000 N) and 0.2 kg (floor 0.2 W: 99.8 W, 0.979 W/kg, spent while
# slack), the erector spinae at 500 N (not slack; the model m.xml's user rows); with --gaitsim
# a stand-in binary whose `inspect` rows give ercspn_r 100 N (arms 0.04 extension, 0.03
# bending; 10 W) and extobl_r 50 N (-0.06, 0.02; 5 W) and vasint 500 N (knee only) at every
# instant: trunk 15.0 W, extension net |4 - 3| = 1.0 and summed 7.0 N m, bending 4.0 and 4.0,
# rotation 0; its `work` table (a 2.000 m stride; contractile elements +203.88 / -101.94 J, the
# feet -30 / +4 J, their normal forces -26 / +10 J, friction -4 J) gives per metre +1.000 /
# -0.500 J/(kg m), per collision -15.0 / +2.0, -13.0 / +5.0 (net -8.0) and -2.0 J, and over the
# prediction's 400 J of metabolic energy a ratio of 0.510 (none for the track, without
# metabolics.sto); its `--joints` rows (hip / knee / ankle in stance: -1.0 / -1.5 / -2.5 and
# +1.5 / +2.0 / +5.0 J) give the right leg's knee share of the negative 0.30 and the ankle's of
# the positive 0.59, and no left-leg line; with two more predictions at 1.0 and 1.5 m/s (erector spinae 300 W, vasti
# 25 v^2 W) the fit a + b v^2 gives the trunk a = 2.943, b = 0 W/kg (a / v 2.943 .. 1.471 J/(kg m)), the
# vasti a = 0, b = 0.245, the muscles a = 2.943, b = 0.245, beside Ralston's 0.822 + 1.331 v^2
# less the basal 1.2 W/kg; a missing states.sto, a missing model or a model whose user row is
# not numbers exits 1 with one line naming the file. The prediction's lumbar_extension (-15 and
# -17 deg) leaves the model's range of -15 ... +28.6 deg (radians in the file), not -20 ... +30
# (degrees, the default when <compiler> gives no angle). Its knees flex 12 (right) and 9 deg (left)
# in loading response (the fixture's comment); the track has no grf.mot, so no knee line.
# usage: physiology_figures.sh GAITSIM SOURCE_DIR
set -u
src=$2
source "$(dirname "$0")/../cli_common.bash"

/usr/bin/python3 - <<'PY'
import json, os
def sto(path, labels, rows):
    with open(path, "w") as f:
        f.write("x\nendheader\n" + "\t".join(labels) + "\n")
        f.writelines("\t".join(str(v) for v in r) + "\n" for r in rows)
os.makedirs("trial"); os.makedirs("results/track"); os.makedirs("results/sweep/predict_2")
sto("trial/coordinates.mot", ["time", "hip_adduction"], [[0.1 * k, 1.0 + k] for k in range(11)])
sto("results/track/states.sto", ["time", "hip_adduction"],
    [[0.2 * k, -4.0 + 2 * k] for k in range(6)])
json.dump({"trial": "trial", "model": "m.xml", "stride_time_s": 1.0, "body_weight_n": 1000.0},
          open("results/track/summary.json", "w"))
sto("results/sweep/predict_2/metabolics.sto", ["time", "ercspn_r", "vasint", "total"],
    [[0.25 * k, 300.0, 100.0, 400.0] for k in range(5)])
# lumbar_extension -15 / -17 (mean -16); the right foot on the ground at nodes 2-6, the left at
# 9, 0, 1, 2 (its contact wraps round the stride's end): loading response = the contact node and
# the next (20 % of 10 nodes), so the right knee's 12 deg and the left's 9 (nodes 9, 0), not the
# 20 and 25 deg one node later
knee_r = [0, 0, -5, -12, -20, -3, 0, 0, 0, 0]
knee_l = [-9, -25, 0, 0, 0, 0, 0, 0, 0, -4]
sto("results/sweep/predict_2/states.sto",
    ["time", "lumbar_extension", "knee_flexion", "knee_flexion_l"],
    [[0.1 * k, -15.0 if k % 2 == 0 else -17.0, knee_r[k], knee_l[k]] for k in range(10)])
sto("results/sweep/predict_2/grf.mot", ["time", "ground_force_r_vy", "ground_force_l_vy"],
    [[0.1 * k, 500.0 if 2 <= k <= 6 else 0.0, 500.0 if k in (9, 0, 1, 2) else 0.0]
     for k in range(10)])
sto("results/sweep/predict_2/muscle_forces.sto", ["time", "ercspn_r", "vasint"],
    [[0.25 * k, 500.0, 5.0] for k in range(5)])
with open("m.xml", "w") as f:
    f.write('<mujoco><compiler angle="radian"/><worldbody><body>'
            '<joint name="lumbar_extension" range="-0.2617993877991494 0.5"/>'
            '<joint name="pelvis_ty" type="slide" range="0 1"/></body></worldbody><actuator>'
            '<muscle name="ercspn_r" user="2500 0.115 0.03 0 10 0.6 250000 1.22 0 0.01 0.04 35"/>'
            '<muscle name="vasint" user="1000 0.099 0.24 0.08 10 0.5 552630 0.2 1 0.01 0.04 35"/>'
            '</actuator></mujoco>')
json.dump({"body_weight_n": 1000.0, "speed_target_mps": 2.0, "model": "m.xml",
           "stride_time_s": 1.0},
          open("results/sweep/predict_2/summary.json", "w"))
PY
out=$(/usr/bin/python3 "$src/scripts/physiology_figures.py" results)
status=$?
check "exit 0 (got $status)" test "$status" -eq 0
check "hip_adduction bias -5" grep -qE "^  hip_adduction +-5\.000 +5\.000 +\+1\.00 +\+6\.00$" <<<"$out"
line="results/sweep/predict_2: 2.0 m/s, muscles 3.92 W/kg (1.96 J/(kg m)), lumbar_extension"
check "muscles 3.92 W/kg, lumbar -16.0" grep -qF "$line mean -16.0 deg" <<<"$out"
check "trunk 75 %" grep -qE "^  trunk +2\.943 W/kg +1\.472 J/\(kg m\) +75\.0 %$" <<<"$out"
check "vasti 25 %" grep -qE "^  vasti +0\.981 W/kg +0\.490 J/\(kg m\) +25\.0 %$" <<<"$out"
check "slack: vasint 99.8 W above its 0.2 W floor" grep -qF \
  "  slack muscles (tendon force < 1 % Fmax), above the 1 W/kg floor: 99.8 W (0.979 W/kg); vasint 99.8, ercspn_r 0.0" <<<"$out"
check "joint ranges: lumbar_extension -17 below -15 deg" grep -qxF \
  "  joint ranges (model): lumbar_extension -17.00 below -15.00" <<<"$out"
check "loading-response knee flexion 12 / 9 deg" grep -qxF \
  "  loading-response knee flexion (deg; the most flexed over the first 20 % of the stride after contact): right 12.0, left 9.0" <<<"$out"
check "no grf.mot for the track: no knee line" test "$(grep -c "loading-response" <<<"$out")" -eq 1
# the vasti (right leg) at 100 W, sampled at 0, 0.25 ... 1 s: the right foot on at 0.25 and
# 0.5 s (grf.mot interpolated; the left on at 0.25 too), so trapezoid weights 2 swing (0, 0.75,
# 1 s), 1 double (0.25 s) and 1 single (0.5 s) of 4; the erector spinae (trunk) left out
check "phase split 0.50 / 0.25 / 0.25" grep -qxF \
  "  leg muscles' cost by phase (Umberger 2010's split): swing 0.50, double support 0.25, single support 0.25 (his 1.3 m/s gait: 0.29, 0.27, 0.44)" <<<"$out"
check "no grf.mot for the track: no phase line" test "$(grep -c "by phase" <<<"$out")" -eq 1
check "one prediction: no fit" test "$(grep -c "Ralston's form" <<<"$out")" -eq 0

/usr/bin/python3 - <<'PY'
import json, os, shutil
for v in (1.0, 1.5):
    d = f"results/sweep/predict_{v:g}"
    shutil.copytree("results/sweep/predict_2", d)
    with open(f"{d}/metabolics.sto", "w") as f:
        f.write("x\nendheader\ntime\tercspn_r\tvasint\ttotal\n")
        f.writelines(f"{0.25 * k}\t300.0\t{25 * v * v}\t{300 + 25 * v * v}\n" for k in range(5))
    s = json.load(open(f"{d}/summary.json"))
    s["speed_target_mps"] = v
    json.dump(s, open(f"{d}/summary.json", "w"))
PY
out=$(/usr/bin/python3 "$src/scripts/physiology_figures.py" results)
check "fit: three predictions" grep -qF "Ralston's form a + b v^2 over 3 predictions" <<<"$out"
check "fit: trunk a 2.943, b 0" \
  grep -qE "^  trunk +a \+2\.943  b [+-]0\.000  a/v  2\.943 \.\.  1\.471$" <<<"$out"
check "fit: vasti a 0, b 0.245" grep -qE "^  vasti +a [+-]0\.000  b \+0\.245  a/v " <<<"$out"
check "fit: muscles a 2.943, b 0.245" grep -qE "^  muscles +a \+2\.943  b \+0\.245 " <<<"$out"
check "fit: Ralston less 1.2" grep -qE "^  Ralston less 1\.2 +a \+0\.822  b \+1\.331 " <<<"$out"
rm -r results/sweep/predict_1 results/sweep/predict_1.5

cat >fake_gaitsim <<'SH'
#!/usr/bin/env bash
if [ "$1" = work ]; then
  echo "mechanical work of m.xml over $4 (5 rows)"
  echo "| source | positive (J) | negative (J) | net (J) | net mean power (W/kg) |"
  echo "|---|---|---|---|---|"
  echo "| muscle-tendon units | 300.00 | -150.00 | 150.00 | 1.0000 |"
  echo "|   their contractile elements (active fibre force) | 203.88 | -101.94 | 101.94 | 1.0000 |"
  echo "| foot contact spheres | 4.00 | -30.00 | -26.00 | -0.2000 |"
  echo "|   their normal forces (elastic and Hunt-Crossley damping) | 10.00 | -26.00 | -16.00 | -0.1000 |"
  echo "|   their friction | 0.00 | -4.00 | -4.00 | -0.0400 |"
  echo "sum of the net works: 0.00 J; change of kinetic plus potential energy: 0.00 J (difference 0.00 J)"
  echo "centre of mass travelled 2.0000 m forward (x)"
  echo
  echo "the muscles' work at each coordinate (J; stance: its foot's vertical force above 20 N)"
  echo "| coordinate | positive | negative | in stance: positive | negative |"
  echo "|---|---|---|---|---|"
  echo "| hip_flexion | 2.00 | -1.00 | 1.50 | -1.00 |"
  echo "| knee_flexion | 3.00 | -2.00 | 2.00 | -1.50 |"
  echo "| ankle_angle | 6.00 | -3.00 | 5.00 | -2.50 |"
  exit 0
fi
[ "$1" = inspect ] || exit 2
echo "m.xml at t = $5 s"
echo "muscle           tendon   lMT (m)   lM (m) lM/lopt     F (N)  Edot (W)  moment arms (m)"
echo "ercspn_r         rigid     0.1465   0.1168   1.014     100.0     10.00  lumbar_extension=0.0400 lumbar_bending=0.0300"
echo "extobl_r         elastic   0.2712   0.1369   1.198      50.0      5.00  lumbar_extension=-0.0600 lumbar_bending=0.0200"
echo "vasint           elastic   0.3044   0.0663   0.667     500.0      2.90  knee_flexion=0.0447"
SH
chmod +x fake_gaitsim
out=$(/usr/bin/python3 "$src/scripts/physiology_figures.py" results --gaitsim ./fake_gaitsim)
status=$?
check "--gaitsim: exit 0 (got $status)" test "$status" -eq 0
check "--gaitsim: trunk 15.0 W" grep -qF "results/sweep/predict_2: trunk muscles 15.0 W;" <<<"$out"
check "--gaitsim: extension 1.0 / 7.0" grep -qE "^  lumbar_extension +1\.0 +7\.0$" <<<"$out"
check "--gaitsim: bending 4.0 / 4.0" grep -qE "^  lumbar_bending +4\.0 +4\.0$" <<<"$out"
check "--gaitsim: rotation 0" grep -qE "^  lumbar_rotation +0\.0 +0\.0$" <<<"$out"
work="mechanical work over 2.000 m: contractile elements +1.000 / -0.500 J/(kg m); foot contact"
work+=" per collision (half the stride's) -15.0 / +2.0 J, its normal forces -13.0 / +5.0 J (net"
work+=" -8.0: damping), friction -2.0 J (Zelik & Kuo 2010 at 1.25 m/s, soft tissue: -7.5 / +4.0 J)"
check "--gaitsim: the track's work, no metabolics.sto" grep -qxF "results/track: $work" <<<"$out"
check "--gaitsim: the prediction's work, 203.88 J of 400 J" grep -qxF \
  "results/sweep/predict_2: $work; contractile positive work / muscles' metabolic energy 0.510" \
  <<<"$out"
joints="  right leg in stance, the muscles' work at hip / knee / ankle (J): negative -1.0 / -1.5 /"
joints+=" -2.5, positive 1.5 / 2.0 / 5.0; the knee's share of the negative 0.30, the ankle's of the"
joints+=" positive 0.59 (Montgomery & Grabowski 2018: 0.39-0.45 and 0.42)"
check "--gaitsim: the right leg's joint work and shares, twice" \
  test "$(grep -cxF "$joints" <<<"$out")" -eq 2
check "--gaitsim: no left leg line (no left coordinates)" test "$(grep -c "left leg in stance" <<<"$out")" -eq 0

cp m.xml m.good
sed -i 's/<compiler angle="radian"\/>//; s/range="-0.2617993877991494 0.5"/range="-20 30"/' m.xml
out=$(/usr/bin/python3 "$src/scripts/physiology_figures.py" results)
check "joint ranges in degrees (no compiler angle): all kept" grep -qxF \
  "  joint ranges (model): all kept" <<<"$out"
cp m.good m.xml
printf '<mujoco><actuator><muscle name="vasint" user="1000 x"/></actuator></mujoco>' >m.xml
err=$(/usr/bin/python3 "$src/scripts/physiology_figures.py" results 2>&1 >/dev/null)
status=$?
check "bad user row: exit 1 (got $status)" test "$status" -eq 1
check "bad user row: one line naming the model" \
  test "$err" = "physiology_figures: m.xml: muscle vasint: a user value is not a number"
rm m.xml
err=$(/usr/bin/python3 "$src/scripts/physiology_figures.py" results 2>&1 >/dev/null)
check "missing model: one line naming it" \
  test "$err" = "physiology_figures: m.xml: cannot read the model (No such file or directory)"
mv m.good m.xml

rm results/track/states.sto
err=$(/usr/bin/python3 "$src/scripts/physiology_figures.py" results 2>&1 >/dev/null)
status=$?
check "missing states.sto: exit 1 (got $status)" test "$status" -eq 1
check "missing states.sto: one line naming it" \
  test "$err" = "physiology_figures: results/track/states.sto: file not found"
finish
