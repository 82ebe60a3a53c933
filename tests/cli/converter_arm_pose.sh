#!/usr/bin/env bash
# scripts/osim2mjcf.py's trial_arm_pose (`--arm-pose trial`): the welded arms' coordinates are the
# mean of the IK csv's arm columns over the rows of the stride window, in radians. On a synthetic
# csv (comment line first, as the source's; 11 rows at 0.1 s, arm_flex_r = 10 t deg, elbow_flex_l
# = 25 deg, the other arm columns 0): over 0.2 ... 0.6 s arm_flex_r is 4 deg (the mean of 2, 3,
# 4, 5, 6) within 1e-9 rad, elbow_flex_l 25 deg, arm_add_r 0. Bad input stops with one line
# naming the file and the reason: a csv without an arm column; a window holding fewer than 2 rows.
# The converter's run itself needs ../shared (JW's .osim) and is not part of the suite.
# usage: converter_arm_pose.sh GAITSIM SOURCE_DIR
set -u
src=$2
source "$(dirname "$0")/../cli_common.bash"

/usr/bin/python3 - "$src/scripts" > out.txt 2>&1 <<'PY'
import math, sys
sys.path.insert(0, sys.argv[1])
import osim2mjcf as c
cols = ["time", "pelvis_tx"] + list(c.ARM_POSE)
with open("ik.csv", "w") as f:
    f.write("# synthetic IK\n" + ",".join(cols) + "\n")
    for i in range(11):
        t = 0.1 * i
        row = {k: 0.0 for k in cols}
        row.update(time=t, arm_flex_r=10.0 * t, elbow_flex_l=25.0)
        f.write(",".join("%.6f" % row[k] for k in cols) + "\n")
pose = c.trial_arm_pose("ik.csv", 0.2 - 1e-9, 0.6 + 1e-9)
ok = abs(pose["arm_flex_r"] - math.radians(4.0)) < 1e-9
ok &= abs(pose["elbow_flex_l"] - math.radians(25.0)) < 1e-9 and pose["arm_add_r"] == 0.0
ok &= set(pose) == set(c.ARM_POSE)
print("pose ok" if ok else "pose wrong: %r" % pose)
with open("noarm.csv", "w") as f:
    f.write("time,pelvis_tx\n0,0\n0.1,0\n")
for args in (("noarm.csv", 0.0, 1.0), ("ik.csv", 0.31, 0.39)):
    try:
        c.trial_arm_pose(*args)
        print("no error for %s" % (args,))
    except SystemExit as e:
        print("error: %s" % e)
PY
check "the stride mean in radians ($(head -1 out.txt))" grep -qx "pose ok" out.txt
noarm="error: osim2mjcf: noarm.csv: no column arm_flex_r (needed by --arm-pose trial, the default;"
check "a csv without arm columns: one line naming the file and the column" \
  grep -qx "$noarm --arm-pose hanging needs none)" out.txt
check "a window of fewer than 2 rows: one line naming the file and the window" \
  grep -qx "error: osim2mjcf: ik.csv: fewer than 2 rows within 0.3100-0.3900 s" out.txt
finish
