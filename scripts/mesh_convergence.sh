#!/usr/bin/env bash
# Mesh convergence, measured (issue 19, item 4): the tracking solve of a trial and the 2.0 m/s
# prediction from it, each at a coarse mesh (default: gaitsim track's default node count) and at
# twice its resolution (2 N - 1 nodes: every interval halved), then the differences of stride
# time, peak vertical GRF per foot, knee contact RMS and cost of transport against the targets
# (scripts/mesh_convergence.py prints the table).
#   scripts/mesh_convergence.sh [--nodes N] [--fine M] [--trial DIR] [--out DIR] [--threads T]
#                               [--reuse]
# --out (default results/mesh_convergence) gets track_N, predict2_N, track_M, predict2_M and
# convergence.md; --reuse keeps a solve folder that already holds a summary.json with its node
# count. Build folder: $GAITSIM_BUILD_DIR (default build). Solves that stop short (exit 3) are
# compared all the same; their status is in the table. Exit status: that of
# mesh_convergence.py (0 all targets met, 3 one missed), 1 when a solve fails, 2 bad usage.
# Time: the four solves of the default resolution, one after another (docs/BENCHMARKS.md,
# "Mesh convergence").
set -euo pipefail
cd "$(dirname "$0")/.."
build=${GAITSIM_BUILD_DIR:-build}
gaitsim="$build/gaitsim"
usage() {
  echo "usage: scripts/mesh_convergence.sh [--nodes N] [--fine M] [--trial DIR] [--out DIR] [--threads T] [--reuse]" >&2
  exit 2
}
nodes="" fine="" trial=mjmodels/trials/jw_ngait_og5 out=results/mesh_convergence threads=2 reuse=0
while (($#)); do
  case $1 in
    --nodes) nodes=${2:?--nodes needs a value}; shift 2 ;;
    --fine) fine=${2:?--fine needs a value}; shift 2 ;;
    --trial) trial=${2:?--trial needs a value}; shift 2 ;;
    --out) out=${2:?--out needs a value}; shift 2 ;;
    --threads) threads=${2:?--threads needs a value}; shift 2 ;;
    --reuse) reuse=1; shift ;;
    -h|--help) usage ;;
    *) echo "mesh_convergence.sh: unknown option $1" >&2; usage ;;
  esac
done
check_count() {  # check_count OPTION VALUE LEAST
  [[ $2 =~ ^[0-9]+$ ]] && (($2 >= $3)) ||
    { echo "mesh_convergence.sh: $1: need an integer >= $3, got '$2'" >&2; exit 2; }
}
[ -z "$nodes" ] || check_count --nodes "$nodes" 3
[ -z "$nodes" ] || [ -z "$fine" ] || check_count --fine "$fine" $((nodes + 1))
[ -x "$gaitsim" ] || { echo "mesh_convergence.sh: $gaitsim: not built (cmake --build $build)" >&2; exit 1; }
if [ -z "$nodes" ]; then  # the default resolution, as gaitsim track --help states it
  nodes=$("$gaitsim" track --help | sed -n 's/.*--nodes N .*(default \([0-9]*\)).*/\1/p')
  check_count "--nodes (gaitsim track's default)" "$nodes" 3
fi
[ -n "$fine" ] || fine=$((2 * nodes - 1))
check_count --fine "$fine" $((nodes + 1))
[ -f "$trial/coordinates.mot" ] || { echo "mesh_convergence.sh: $trial: no coordinates.mot (a trial folder)" >&2; exit 1; }
mkdir -p "$out"
export OPENBLAS_NUM_THREADS=1

# solve DIR N CMD...: run the solve into DIR unless --reuse finds it done at N nodes; exit 3
# (stopped short) is accepted, its status goes into the table
solve() {
  local dir=$1 n=$2; shift 2
  if ((reuse)) && [ -f "$dir/summary.json" ] &&
     /usr/bin/python3 -c 'import json,sys; sys.exit(json.load(open(sys.argv[1])).get("nodes") != int(sys.argv[2]))' "$dir/summary.json" "$n"; then
    echo "mesh_convergence.sh: reusing $dir"
    return 0
  fi
  local t0=$SECONDS rc=0
  "$gaitsim" "$@" --out "$dir" --nodes "$n" --threads "$threads" >"$dir.log" 2>&1 || rc=$?
  if ((rc != 0 && rc != 3)); then
    echo "mesh_convergence.sh: $* failed (exit $rc):" >&2; tail -3 "$dir.log" >&2; exit 1
  fi
  echo "mesh_convergence.sh: $dir: exit $rc, $((SECONDS - t0)) s (log $dir.log)"
}
for n in "$nodes" "$fine"; do
  solve "$out/track_$n" "$n" track "$trial"
  solve "$out/predict2_$n" "$n" predict --guess "$out/track_$n" --speed 2.0
done
rc=0
/usr/bin/python3 scripts/mesh_convergence.py "$out/track_$nodes" "$out/predict2_$nodes" \
  "$out/track_$fine" "$out/predict2_$fine" >"$out/convergence.md" || rc=$?
cat "$out/convergence.md"
exit "$rc"
