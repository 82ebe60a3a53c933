#!/usr/bin/env bash
# Eq. 3's band around the guess and where it holds a prediction, end to end on the planar model
# (mjmodels/gait2d.xml, 20 nodes; about 25 s on 2 cores): a 100-iteration track as the guess, then
# a prediction at 1.2 m/s with the band a quarter as wide (--band-scale 0.25: 5 deg, 1.25 cm,
# 1.5 rad/s, 0.25 m/s; measured: settles after 103 iterations with 11 coordinates and speeds at
# the band at 1-5 nodes each). Expected: summary.json band_scale 0.25 and band_active_nodes equal,
# coordinate by coordinate, to the count recomputed from states.sto against the guess's states.sto
# (nodes within 0.1 % of the half-width from the band's edge; pelvis_tx itself has no band, its
# speed has), and not empty; without a band (--band-scale 0) none held; a negative scale or one
# above 10 is bad usage (exit 2).
# usage: band.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"
model="$src/mjmodels/gait2d.xml"

"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --out track --model "$model" --nodes 20 \
  --hessian lbfgs --max-iter 100 --threads 2 --refine 0 >/dev/null 2>&1
check "guess written" test -s track/variables.sto
"$gaitsim" predict --guess track --model "$model" --speed 1.2 --nodes 20 --max-iter 600 \
  --threads 2 --band-scale 0.25 --out narrow >/dev/null 2>&1
status=$?
check "narrow band: exit 0 (got $status)" test "$status" -eq 0
check "band_active_nodes recomputed from the states" /usr/bin/python3 - "$src/scripts" \
  track/states.sto narrow/states.sto narrow/summary.json <<'PY'
import json, math, sys
sys.path.insert(0, sys.argv[1])
from gs_scriptlib import read_storage
_, hg, g = read_storage(sys.argv[2])
_, hp, p = read_storage(sys.argv[3])
s = json.load(open(sys.argv[4]))
scale, deg = 0.25, 180 / math.pi
slides = {"pelvis_tx", "pelvis_ty"}
want = {}
for name in hp[1:]:
    if "." in name:
        continue
    speed = name.endswith("_u")
    coord = name[:-2] if speed else name
    if coord == "pelvis_tx" and not speed:
        continue
    slide = coord in slides
    hw = scale * ((1.0 if slide else 6.0 * deg) if speed else (0.05 if slide else 0.35 * deg))
    jp, jg = hp.index(name), hg.index(name)
    at = sum(abs(p[k][jp] - g[k][jg]) >= (1 - 1e-3) * hw for k in range(len(p)))
    if at:
        want[coord + ("_speed" if speed else "")] = at
got = s["band_active_nodes"]
ok = s["band_scale"] == 0.25 and got == want and len(got) > 0 and len(p) == len(g) == 20
if not ok:
    print(json.dumps({"summary": got, "recomputed": want}), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
"$gaitsim" predict --guess track --model "$model" --speed 1.2 --nodes 20 --max-iter 50 \
  --threads 2 --band-scale 0 --out none >/dev/null 2>&1
check "no band: band_scale 0, none held" /usr/bin/python3 -c "
import json, sys
s = json.load(open('none/summary.json'))
sys.exit(0 if s['band_scale'] == 0 and s['band_active_nodes'] == {} else 1)"
"$gaitsim" predict --guess track --speed 1.2 --out x --band-scale -1 >/dev/null 2>&1
check "negative --band-scale: usage, exit 2" test $? -eq 2
"$gaitsim" predict --guess track --speed 1.2 --out x --band-scale 11 >/dev/null 2>&1
check "--band-scale 11: usage, exit 2" test $? -eq 2
finish
