#!/usr/bin/env bash
# scripts/mesh_convergence.py on synthetic solution folders (summary.json + grf.mot, body weight
# 1000 N): the same folders as coarse and fine meet every target (differences 0, exit 0);
# a coarse prediction 1.5 % slower in stride, 3 % dearer, with a right-foot peak 0.08 BW higher
# misses exactly those three targets (exit 3, "4 of 7 targets met", the differences printed to
# the digit); a missing grf.mot exits 1 with one line naming the file; the driver
# scripts/mesh_convergence.sh refuses bad options (exit 2) before any solve.
# usage: mesh_convergence.sh GAITSIM SOURCE_DIR
set -u
src=$2
source "$(dirname "$0")/../cli_common.bash"

# make DIR PROBLEM STRIDE_S COT PEAK_R_BW PEAK_L_BW KNEE_RMS_BW
make() {
  /usr/bin/python3 - "$@" <<'PY'
import json, os, sys
d, problem, T, cot, pr, pl, knee = sys.argv[1], sys.argv[2], *map(float, sys.argv[3:])
os.makedirs(d)
json.dump({"problem": problem, "nodes": 9, "status": "optimal solution found",
           "body_weight_n": 1000.0, "stride_time_s": T, "cost_of_transport_j_per_kg_m": cot,
           "rms": {"knee_contact_bw": knee}}, open(os.path.join(d, "summary.json"), "w"))
with open(os.path.join(d, "grf.mot"), "w") as f:
    f.write("grf\nendheader\ntime\tground_force_r_vy\tground_force_l_vy\n")
    for k in range(5):  # the peaks at node 2 (right) and node 3 (left)
        f.write(f"{0.1 * k}\t{pr * 1000 * (k == 2) + 10}\t{pl * 1000 * (k == 3) + 20}\n")
PY
}
make track tracking 1.1 1.0 1.20 1.25 0.26
make pred prediction 0.90 2.80 1.60 1.70 0.50
make pred_off prediction 0.9135 2.884 1.68 1.70 0.50

out=$(/usr/bin/python3 "$src/scripts/mesh_convergence.py" track pred track pred)
status=$?
check "the same folders: exit 0 (got $status)" test "$status" -eq 0
check "the same folders: 7 of 7 met" grep -q "^mesh_convergence: 7 of 7 targets met$" <<<"$out"

out=$(/usr/bin/python3 "$src/scripts/mesh_convergence.py" track pred_off track pred)
status=$?
check "a coarse prediction off: exit 3 (got $status)" test "$status" -eq 3
check "a coarse prediction off: 4 of 7 met" grep -q "^mesh_convergence: 4 of 7 targets met$" <<<"$out"
check "stride time +1.50 %, missed" grep -q "stride time (s) | 0.9135 | 0.9000 | +1.50 % | <= 1 % | NO |" <<<"$out"
check "cost of transport +3.00 %, missed" grep -q "cost of transport (J/(kg m)) | 2.8840 | 2.8000 | +3.00 % | <= 2 % | NO |" <<<"$out"
check "right peak +0.0800 BW, missed" grep -q "prediction 2.0 m/s: peak vertical GRF, right (BW) | 1.6900 | 1.6100 | +0.0800 BW | <= 0.05 BW | NO |" <<<"$out"
check "left peak met" grep -q "prediction 2.0 m/s: peak vertical GRF, left (BW) | 1.7200 | 1.7200 | +0.0000 BW | <= 0.05 BW | yes |" <<<"$out"

rm pred_off/grf.mot
err=$(/usr/bin/python3 "$src/scripts/mesh_convergence.py" track pred_off track pred 2>&1 >/dev/null)
status=$?
check "missing grf.mot: exit 1 (got $status)" test "$status" -eq 1
check "missing grf.mot: one line naming it" test "$err" = "mesh_convergence: pred_off/grf.mot: file not found"

bash "$src/scripts/mesh_convergence.sh" --nodes 2 >/dev/null 2>err.txt
status=$?
check "driver: --nodes 2 refused, exit 2 (got $status)" test "$status" -eq 2
check "driver: names --nodes" grep -q "^mesh_convergence.sh: --nodes: need an integer >= 3, got .2.$" err.txt
bash "$src/scripts/mesh_convergence.sh" --fine 10 --nodes 20 >/dev/null 2>err.txt
status=$?
check "driver: --fine below --nodes refused, exit 2 (got $status)" test "$status" -eq 2
finish
