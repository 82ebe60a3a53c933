#!/usr/bin/env bash
# The refinement stage of gaitsim track (optim/go_solve.c; --refine N, --refine-gn N) on a tiny
# problem: the fixture solution (tests/fixtures/solution_small) as the start, 5 nodes, 3 L-BFGS
# iterations (--hessian lbfgs; the default Gauss-Newton main solve is refined alike; stopped
# short), then 4 Gauss-Newton and 10 exact-Hessian Newton iterations (about
# 20 s). From that far (violation 125) they do not converge, but the Newton best iterate beats
# the L-BFGS one by the glue's ranking (the lower violation, both being far from the polishable
# 1e-3), so it is kept: summary.json refine {status "iteration limit reached", iterations 14
# (both phases), gauss_newton {iterations 4, objective and violation of its last point}, used
# true}, the progress says so, "iterations" counts all solves (17), and wall_s the whole solve:
# at least the solves' ipopt_wall_s and the polish's wall time together. --refine 0 runs no refinement (no refine object); --refine with
# a negative count is a usage error (exit 2). --refine-time 0.2 stops a refinement by its wall
# clock before its 10 Newton iterations (at 5 nodes each takes about 0.05-0.07 s on a quiet core:
# 0.2 s holds about 3, where 0.5 s held up to all 10).
# usage: refine.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --init "$src/tests/fixtures/solution_small" \
  --out tr --nodes 5 --hessian lbfgs --max-iter 3 --refine-gn 4 --refine 10 --threads 1 >/dev/null 2>log.txt
status=$?
check "stopped short: exit 3 (got $status)" test "$status" -eq 3
check "progress: refinement ran, its best iterate kept" \
  grep -q "refinement: iteration limit reached after 14 iterations.*its best iterate beats the main solve.s and is kept" log.txt
check "summary refine" /usr/bin/python3 - tr/summary.json <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
r = s.get("refine", {})
gn = r.get("gauss_newton", {})
ok = (r.get("status") == "iteration limit reached" and r.get("iterations") == 14
      and gn.get("iterations") == 4 and gn.get("wall_s", -1) >= 0
      and math.isfinite(gn.get("objective", float("nan")))
      and math.isfinite(gn.get("violation", float("nan")))
      and r.get("used") is True and math.isfinite(r.get("objective", float("nan")))
      and s["iterations"] == 17 and s["status"] == "iteration limit reached"
      and s["converged"] is False
      # wall_s counts the whole solve, the refinement not kept and the polish included
      and s["wall_s"] >= s["ipopt_wall_s"] + s.get("polish", {}).get("wall_s", 0)
      and s["ipopt_wall_s"] >= r.get("wall_s", 0)
      and s["ipopt_wall_s"] > 0)
if not ok:
    print(json.dumps({k: s.get(k) for k in ("status", "iterations", "refine", "wall_s",
                                            "ipopt_wall_s", "polish")}), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --init "$src/tests/fixtures/solution_small" \
  --out tr0 --nodes 5 --hessian lbfgs --max-iter 1 --refine 0 --threads 1 --no-polish >/dev/null 2>&1
check "--refine 0: no refine object" /usr/bin/python3 -c \
  'import json,sys; sys.exit("refine" in json.load(open("tr0/summary.json")))'
"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --init "$src/tests/fixtures/solution_small" \
  --out trt --nodes 5 --hessian lbfgs --max-iter 1 --refine 10 --refine-time 0.2 --threads 1 --no-polish \
  >/dev/null 2>&1
check "--refine-time 0.2: the refinement stops on its wall clock before 10 iterations" \
  /usr/bin/python3 -c 'import json,sys; r=json.load(open("trt/summary.json"))["refine"]
sys.exit(not (r["status"] == "wall-time limit reached" and r["iterations"] < 10))'
"$gaitsim" track "$src/mjmodels/trials/jw_ngait_og5" --out x --refine -1 >/dev/null 2>&1
check "negative --refine: usage, exit 2" test $? -eq 2
finish
