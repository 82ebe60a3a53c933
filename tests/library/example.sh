#!/usr/bin/env bash
# libgaitsim as installed (issue 21, item 3): `cmake --install` into a temporary prefix puts the
# shared library (exporting only the gs_lib_* functions of gaitsim.h), the header, gaitsim.pc
# and the models in place; examples/forward_gait.c is compiled with only
# `pkg-config --cflags --libs gaitsim` (no source-tree include path), -Werror, and runs on the
# installed planar model with the installed libgaitsim.so (ldd). Its last line (t = 0.1 s,
# excitation 0.05 from the standing keyframe) must match `gaitsim simulate` of the same run:
# pelvis height to 1e-9 m, each foot's vertical ground reaction to 1e-6 N, and the feet must
# carry between 0.5 and 2 body weights (so the run is not a body in the air).
# usage: example.sh GAITSIM BUILD_DIR SOURCE_DIR
set -u
gaitsim=$1 build=$2 src=$3
source "$(dirname "$0")/../cli_common.bash"

prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >install.log
check "cmake --install exits 0" test $? -eq 0
lib=$(ls "$prefix"/lib*/libgaitsim.so.0 2>/dev/null | head -n 1)
check "libgaitsim.so.0 installed" test -n "$lib"
check "header installed" test -f "$prefix/include/gaitsim/gaitsim.h"
pcdir=$(dirname "$(ls "$prefix"/lib*/pkgconfig/gaitsim.pc | head -n 1)")
check "gaitsim.pc installed" test -f "$pcdir/gaitsim.pc"
model=$prefix/share/gaitsim/mjmodels/gait2d.xml
check "planar model installed" test -f "$model"
exported=$(nm -D --defined-only "$lib" | awk '$2 == "T" {print $3}' | sort | tr '\n' ' ')
check "only gs_lib_* exported ($exported)" test -z "$(tr ' ' '\n' <<<"$exported" | grep -v '^gs_lib_' | grep .)"
check "7 functions exported" test "$(wc -w <<<"$exported")" -eq 7

flags=$(PKG_CONFIG_PATH=$pcdir pkg-config --cflags --libs gaitsim)
check "pkg-config knows gaitsim ($flags)" grep -q -- "-lgaitsim" <<<"$flags"
cp "$src/examples/forward_gait.c" .
# shellcheck disable=SC2086
cc -std=c11 -Wall -Wextra -Wpedantic -Werror forward_gait.c $flags -lm \
  -Wl,-rpath,"$(dirname "$lib")" -o forward_gait
check "example builds against the installed library" test -x forward_gait
check "example links the installed libgaitsim" grep -q "$(dirname "$lib")/libgaitsim.so.0" <<<"$(ldd forward_gait)"

./forward_gait "$model" 0.1 0.05 >example.txt
check "example exits 0" test $? -eq 0
check "example prints 11 frames" test "$(grep -c '^0\.' example.txt)" -eq 11
"$gaitsim" simulate "$model" --excitation 0.05 --duration 0.1 --rate 100 --out sim >/dev/null
check "gaitsim simulate exits 0" test $? -eq 0
/usr/bin/python3 - example.txt sim/states.sto sim/grf.mot "$model" <<'PY'
import sys
def table(path):
    lines = open(path).read().split("\n")
    i = lines.index("endheader")
    labels = lines[i + 1].split("\t")
    return [dict(zip(labels, map(float, l.split("\t")))) for l in lines[i + 2:] if l.strip()]
last = open(sys.argv[1]).read().split("\n")[-2].split()
t, y, fr, fl = map(float, last)
s, g = table(sys.argv[2])[-1], table(sys.argv[3])[-1]
print(f"example t={t} pelvis_ty={y:.12f} fz_r={fr:.6f} fz_l={fl:.6f}")
print(f"simulate t={s['time']} pelvis_ty={s['pelvis_ty']:.12f} fz_r={g['ground_force_r_vy']:.6f} fz_l={g['ground_force_l_vy']:.6f}")
ok = abs(t - 0.1) < 1e-9 and abs(s["time"] - 0.1) < 1e-9
ok &= abs(y - s["pelvis_ty"]) <= 1e-9
ok &= abs(fr - g["ground_force_r_vy"]) <= 1e-6 and abs(fl - g["ground_force_l_vy"]) <= 1e-6
sys.exit(0 if ok else 1)
PY
check "example matches gaitsim simulate" test $? -eq 0
weight=$("$gaitsim" info "$model" --json | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["mass_kg"] * 9.81)')
check "feet carry 0.5-2 body weights ($weight N)" awk -v w="$weight" 'END { f = $3 + $4; exit !(f > 0.5 * w && f < 2 * w) }' example.txt
finish
