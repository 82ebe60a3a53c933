#!/usr/bin/env bash
# The exact-Hessian refinement stage of gaitsim track (app/cmd_solve.c, --refine N) on a tiny
# problem: the fixture solution (tests/fixtures/solution_small) as the start, 5 nodes, 3 L-BFGS
# iterations (stopped short), then --refine 10 (about 20 s). From that far (violation 125) the
# 10 Newton iterations do not converge, so the L-BFGS best iterate must stay: summary.json refine
# {status "iteration limit reached", iterations 10, used false}, the progress says so, and
# "iterations" counts the L-BFGS solve only (3), and wall_s the whole solve: at least the L-BFGS
# solve's ipopt_wall_s, the refinement's and the polish's wall times together. --refine 0 runs no refinement (no refine object);
# --refine with a negative count is a usage error (exit 2).
# usage: refine.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --init "$src/tests/fixtures/solution_small" \
  --out tr --nodes 5 --max-iter 3 --refine 10 --threads 1 >/dev/null 2>log.txt
status=$?
check "stopped short: exit 3 (got $status)" test "$status" -eq 3
check "progress: refinement ran, L-BFGS point kept" \
  grep -q "refinement: iteration limit reached after 10 iterations.*the L-BFGS best iterate stays" log.txt
check "summary refine" /usr/bin/python3 - tr/summary.json <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
r = s.get("refine", {})
ok = (r.get("status") == "iteration limit reached" and r.get("iterations") == 10
      and r.get("used") is False and math.isfinite(r.get("objective", float("nan")))
      and s["iterations"] == 3 and s["status"] == "iteration limit reached"
      # wall_s counts the whole solve, the refinement not kept and the polish included
      and s["wall_s"] >= s["ipopt_wall_s"] + r.get("wall_s", 0) + s.get("polish", {}).get("wall_s", 0)
      and s["ipopt_wall_s"] > 0)
if not ok:
    print(json.dumps({k: s.get(k) for k in ("status", "iterations", "refine", "wall_s",
                                            "ipopt_wall_s", "polish")}), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --init "$src/tests/fixtures/solution_small" \
  --out tr0 --nodes 5 --max-iter 1 --refine 0 --threads 1 --no-polish >/dev/null 2>&1
check "--refine 0: no refine object" /usr/bin/python3 -c \
  'import json,sys; sys.exit("refine" in json.load(open("tr0/summary.json")))'
"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --out x --refine -1 >/dev/null 2>&1
check "negative --refine: usage, exit 2" test $? -eq 2
finish
