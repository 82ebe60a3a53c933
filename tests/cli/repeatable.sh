#!/usr/bin/env bash
# The same command gives the same numbers, whatever the thread count: two runs of the same
# tracking solve (default trial, 20 nodes, 8 Ipopt iterations, no polish; the default MUMPS
# ordering), one on 2 worker threads and one on 1, must write bitwise equal variables.sto and
# states.sto, the same progress lines (wall time aside) and the same summary.json once its wall
# and CPU times and thread count are left out. This checks gaitsim's own evaluations (threaded
# Jacobian, objective, constraints: reduced in node order) and the KKT ordering: Debian's MUMPS
# orders with SCOTCH 7, whose threaded graph algorithms varied between runs in the 9th digit
# until go_ipopt.c ran it on one thread (docs/BENCHMARKS.md, "Reproducible runs"; with
# SCOTCH_PTHREAD_NUMBER=2 in the environment this test fails). About 15 s.
# usage: repeatable.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

threads=(2 1)
for r in 0 1; do
  "$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --out "run_$r" --nodes 20 --max-iter 8 --no-polish \
    --refine 0 --threads "${threads[$r]}" >/dev/null 2>"log_$r.txt"
  status=$?
  check "run $r stops at the iteration limit: exit 3 (got $status)" test "$status" -eq 3
done
check "variables.sto bitwise equal" cmp -s run_0/variables.sto run_1/variables.sto
check "states.sto bitwise equal" cmp -s run_0/states.sto run_1/states.sto
check "the same progress lines (wall time aside)" \
  cmp -s <(grep '^iter' log_0.txt | sed 's/wall.*//') <(grep '^iter' log_1.txt | sed 's/wall.*//')
check "8 iterations logged" test "$(grep -c '^iter' log_0.txt)" -eq 9
summary_sans_times() {  # summary.json with every wall/cpu time and the thread count removed
  python3 -c '
import json, sys
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items()
                if not ("wall" in k or "cpu" in k or k == "threads")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
print(json.dumps(strip(json.load(open(sys.argv[1]))), sort_keys=True))' "$1"
}
check "summary.json equal but for times and threads" \
  cmp -s <(summary_sans_times run_0/summary.json) <(summary_sans_times run_1/summary.json)
check "summary.json comparison is not empty" test "$(summary_sans_times run_0/summary.json | wc -c)" -gt 500
finish
