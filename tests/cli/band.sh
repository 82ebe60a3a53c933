#!/usr/bin/env bash
# Eq. 3's band around the guess and where it holds a prediction, end to end on the planar model
# (mjmodels/gait2d.xml, 20 nodes; about 25 s on 2 cores): a 100-iteration track as the guess, then
# a prediction at 1.2 m/s with the band a quarter as wide (--band-scale 0.25: 5 deg, 1.25 cm,
# 1.5 rad/s, 0.25 m/s; measured: settles after 152 iterations with 10 coordinates and speeds at
# the band at 1-4 nodes each). Expected: summary.json band_scale 0.25 and band_active_nodes equal,
# coordinate by coordinate, to the count scripts/band_excursions.py recomputes from states.sto
# against the guess's states.sto (nodes within 0.1 % of the half-width from the band's edge;
# pelvis_tx itself has no band, its speed has), none beyond the band, and not empty; against a
# band narrower than the solve's (x 0.2) some nodes lie beyond; without a band (--band-scale 0)
# none held; a negative scale or one above 10 is bad usage (exit 2), and so is a scale that is
# not a number to the script; the script takes the half-widths from summary.json
# (band_half_widths_at_scale_1) and names the file when they are missing.
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
/usr/bin/python3 "$src/scripts/band_excursions.py" track narrow --json > excursions.json
check "band_excursions.py: exit 0" test $? -eq 0
check "band_active_nodes recomputed from the states (scripts/band_excursions.py)" \
  /usr/bin/python3 - narrow/summary.json excursions.json <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
e = json.load(open(sys.argv[2]))
got = s["band_active_nodes"]
ok = (s["band_scale"] == 0.25 and e["band_scale"] == 0.25 and got == e["at_edge"] and
      len(got) > 0 and not any(e["beyond"].values()) and "pelvis_tx" not in got)
if not ok:
    print(json.dumps({"summary": got, "recomputed": e}), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
/usr/bin/python3 "$src/scripts/band_excursions.py" track narrow --band-scale 0.2 --json \
  > tighter.json
check "a tighter band than the solve's: nodes beyond it" /usr/bin/python3 -c "
import json, sys
e = json.load(open('tighter.json'))
sys.exit(0 if sum(e['beyond'].values()) > 0 else 1)"
/usr/bin/python3 "$src/scripts/band_excursions.py" track narrow --band-scale x >/dev/null 2>&1
check "band_excursions.py --band-scale x: exit 2" test $? -eq 2
check "summary.json: the half-widths at scale 1 (0.35 rad, 5 cm, 6 rad/s, 1 m/s)" \
  /usr/bin/python3 -c "
import json, sys
w = json.load(open('narrow/summary.json'))['band_half_widths_at_scale_1']
sys.exit(0 if w == {'rotation_rad': 0.35, 'translation_m': 0.05,
                    'rotation_speed_rad_per_s': 6, 'translation_speed_m_per_s': 1} else 1)"
mkdir -p nowidths && cp narrow/states.sto nowidths/ && /usr/bin/python3 -c "
import json
s = json.load(open('narrow/summary.json'))
del s['band_half_widths_at_scale_1']
json.dump(s, open('nowidths/summary.json', 'w'))"
/usr/bin/python3 "$src/scripts/band_excursions.py" track nowidths >/dev/null 2>nowidths.err
status=$?
check "band_excursions.py without the half-widths: exit 2 (got $status)" test "$status" -eq 2
check "band_excursions.py without the half-widths: one line naming summary.json" \
  grep -q "nowidths/summary.json: no band_half_widths_at_scale_1" nowidths.err
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
