#!/usr/bin/env bash
# scripts/patella_variant.py: the right patella moved onto the femoral component on a hinge
# coupled to knee_flexion (callbacks/gs_coupling.h). Expected: the variant loads in gaitsim; at
# reference pose 0 (mjmodels/reference/jw_poses.csv) the quadriceps' moment arms about the knee's
# secondary coordinates equal the OpenSim reference (mjmodels/reference/jw_moment_arms.csv)
# within 0.2 mm (rotations) and 0.002 m/m (translations), where the shipped model's vaslat is off
# by 20 mm and 1.2 m/m; their flexion moment arm through the coupling (knee_flexion plus
# patfem_flexion) equals the shipped model's within 0.1 mm; the variant's own output is refused
# (exit 1, one line naming it); a missing argument is usage (exit 2).
# usage: patella_variant.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"
ln -s "$src/mjmodels/meshes" meshes   # the model's meshdir, relative to the model file

/usr/bin/python3 "$src/scripts/patella_variant.py" "$src/mjmodels/jw_fullbody_knee6.xml" variant.xml
check "variant written (exit 0)" test -s variant.xml
check "variant: hinge and coupling" grep -q 'joint1="patfem_flexion" joint2="knee_flexion"' variant.xml
/usr/bin/python3 - "$src/mjmodels/reference/jw_poses.csv" > poses.mot <<'PY'
import sys
rows = [l.strip().split(",") for l in open(sys.argv[1]) if not l.startswith("#")]
print("poses\nversion=1\nnRows=%d\nnColumns=%d\ninDegrees=no\nendheader" % (len(rows) - 1, len(rows[0])))
print("\t".join(["time"] + rows[0][1:]))
for r in rows[1:]:
    print("\t".join([r[0]] + r[1:]))
PY
"$gaitsim" inspect variant.xml --pose poses.mot --time 0 > variant.txt 2>&1
status=$?
check "inspect the variant: exit 0 (got $status)" test "$status" -eq 0
"$gaitsim" inspect "$src/mjmodels/jw_fullbody_knee6.xml" --pose poses.mot --time 0 > shipped.txt 2>&1
check "quadriceps' secondary moment arms equal the reference; flexion unchanged" \
  /usr/bin/python3 - variant.txt shipped.txt "$src/mjmodels/reference/jw_moment_arms.csv" <<'PY'
import sys
def arms(path):
    out = {}
    for line in open(path):
        f = line.split()
        if f and f[0] in ("recfem", "vasint", "vaslat", "vasmed"):
            out[f[0]] = {k: float(v) for k, v in (x.split("=") for x in f if "=" in x)}
    return out
var, ship = arms(sys.argv[1]), arms(sys.argv[2])
ref = {}
for line in open(sys.argv[3]):
    f = line.strip().split(",")
    if f[0] == "0" and f[1] in var:
        ref[(f[1], f[2])] = float(f[3])
bad, off = [], 0.0
for mu in ("recfem", "vasint", "vaslat", "vasmed"):
    for c in ("knee_adduction", "knee_rotation", "knee_tx", "knee_ty", "knee_tz"):
        tol = 2e-4 if c.startswith("knee_a") or c.endswith("rotation") else 2e-3
        r, v = ref[(mu, c)], var[mu].get(c, 0.0)
        if abs(v - r) > tol:
            bad.append("%s %s %.4f against %.4f" % (mu, c, v, r))
        off = max(off, abs(ship[mu].get(c, 0.0) - r) / tol)
    flex = var[mu]["knee_flexion"] + var[mu].get("patfem_flexion", 0.0)
    if abs(flex - ship[mu]["knee_flexion"]) > 1e-4:
        bad.append("%s flexion %.4f against %.4f" % (mu, flex, ship[mu]["knee_flexion"]))
if off < 10:  # the shipped model must be far off, or the check proves nothing
    bad.append("shipped model only %.1f tolerances off" % off)
print("\n".join(bad), file=sys.stderr)
sys.exit(1 if bad else 0)
PY
/usr/bin/python3 "$src/scripts/patella_variant.py" variant.xml again.xml 2> refused.txt
status=$?
check "the variant refused (exit 1, got $status)" test "$status" -eq 1
check "one line naming the file" grep -qx 'patella_variant.py: variant.xml: already has patfem_flexion' refused.txt
/usr/bin/python3 "$src/scripts/patella_variant.py" variant.xml 2>/dev/null
check "missing argument: exit 2" test $? -eq 2
finish
