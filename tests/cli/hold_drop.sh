#!/usr/bin/env bash
# Issue #4: the full-body model, every joint but the pelvis held, actuators off, dropped from
# 2 cm above its `standing` keyframe, comes to rest on its 8 calcaneus contact spheres within 4 s
# without NaN (the toes spheres, lifted by the converter's GRF fit, clear the floor when standing):
# over the last 0.2 s the total vertical GRF is within 5 % of body weight, both feet carry load
# (each > 20 % BW) and the pelvis speeds are below 0.01 m/s or rad/s. Since the trial-calibrated
# feet (mjmodels/README.md, "Contact spheres and standing pose") the held body sways sideways at
# about 1.7 Hz and settles more slowly than on the earlier 12 level spheres (largest pelvis speed
# 0.012 at 0.85 s, 0.010 over 2.8-3.0 s, 0.008 over 3.8-4.0 s), hence 4 s instead of 1 s.
# usage: hold_drop.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") src=$(cd "$2" && pwd)
model=$src/mjmodels/jw_fullbody.xml
source "$(dirname "$0")/../cli_common.bash"

"$gaitsim" simulate "$model" --hold --drop 0.02 --duration 4 --rate 100 --out run >/dev/null
check "simulate exits 0" test $? -eq 0
mass=$("$gaitsim" info "$model" --json | awk -F: '/"mass_kg"/ { gsub(/[ ,]/, "", $2); print $2 }')
check "info reports the mass ($mass)" awk -v m="$mass" 'BEGIN { exit !(m > 10) }'

# columns by name after `endheader`; rows with time >= 0.8 s
summary() {  # file, then awk program reading the named columns
  awk -F'\t' -v t0=3.7999 "
    hdr { for (i = 1; i <= NF; i++) col[\$i] = i; hdr = 0; next }
    /^endheader/ { hdr = 1; next }
    col[\"time\"] && \$1 + 0 >= t0 { $2 }
    END { $3 }" "$1"
}
grf=$(summary run/grf.mot '
  n++; r = $col["ground_force_r_vy"]; l = $col["ground_force_l_vy"];
  if (r != r + 0 || l != l + 0 || tolower($0) ~ /nan|inf/) bad = 1;
  tot = r + l; if (n == 1 || tot < tmin) tmin = tot; if (n == 1 || tot > tmax) tmax = tot;
  if (n == 1 || r < rmin) rmin = r; if (n == 1 || l < lmin) lmin = l' \
  'printf "%d %d %.6f %.6f %.6f %.6f\n", n, bad, tmin, tmax, rmin, lmin')
read -r n bad tmin tmax rmin lmin <<<"$grf"
bw=$(awk -v m="$mass" 'BEGIN { printf "%.6f", m * 9.80665 }')
echo "hold_drop: last 0.2 s ($n rows): total vertical GRF $tmin..$tmax N (BW $bw N), right >= $rmin N, left >= $lmin N"
check "21 rows over the last 0.2 s" test "$n" -eq 21
check "GRF finite" test "$bad" -eq 0
check "total vertical GRF within 5 % of BW" awk -v a="$tmin" -v b="$tmax" -v w="$bw" \
  'BEGIN { exit !(a > 0.95 * w && b < 1.05 * w) }'
check "each foot carries > 20 % BW" awk -v r="$rmin" -v l="$lmin" -v w="$bw" \
  'BEGIN { exit !(r > 0.2 * w && l > 0.2 * w) }'

vel=$(summary run/states.sto '
  n++; for (c in col) if (c ~ /^pelvis_.*_u$/) { v = $col[c]; if (v != v + 0 || tolower(v) ~ /nan|inf/) bad = 1;
    v = v < 0 ? -v : v; if (v > vmax) vmax = v }
  for (i = 1; i <= NF; i++) if (tolower($i) ~ /nan|inf/) bad = 1' \
  'printf "%d %d %.6f\n", n, bad, vmax')
read -r n bad vmax <<<"$vel"
echo "hold_drop: last 0.2 s: largest pelvis speed $vmax (m/s or rad/s)"
check "states finite" test "$bad" -eq 0
check "states has the pelvis speeds" test "$n" -eq 21
check "pelvis at rest (< 0.01)" awk -v v="$vmax" 'BEGIN { exit !(v < 0.01) }'

finish
