#!/usr/bin/env bash
# scripts/replay_stop_rule.py on a synthetic progress log whose stops are known by construction:
# iterations 0-30, objective 2.0 + 1e-3 * 0.5^k (the change per iteration over max(1, |J|) is
# 5e-4 * 0.5^k, <= 1e-4 from k = 3 on), violation 5e-5 up to iteration 19 and 1e-7 from 20, one
# restoration iteration (12r), which breaks a run, and a feasibility polish at the end whose lines
# must be ignored. Expected: the 1e-4 rule (15 iterations) runs 13..27 and stops at 27; the 3e-5
# rule (10) runs 20..29 and stops at 29; the 1e-6 rule (15) gets only 20..30 and never stops; the
# lowest J over inf_pr <= 1e-6 is 2.0000; the last iteration is 30; the objective never rises,
# so the fall-back guard never fires. A second log, J 2.0 at violation 5e-5 for iterations 0-9,
# 2.4 (+20 %) at 10, 2.6 (+30 %) at 11r (restoration: ignored) and 12: the guard fires at 12.
# A missing file exits 1 with one line naming it.
# usage: replay_stop_rule.sh GAITSIM SOURCE_DIR
set -u
src=$2
source "$(dirname "$0")/../cli_common.bash"

/usr/bin/python3 - <<'PY' >log.txt
for k in range(31):
    obj = 2.0 + 1e-3 * 0.5 ** k
    pr = 1e-7 if k >= 20 else 5e-5
    line = f"iter {k:4d}{'r' if k == 12 else ' '}  obj  {obj:.8e}  inf_pr {pr:.3e}  inf_du 1.000e-01  lg(mu)  -6.0  alpha_pr 1.00e+00  wall     1.00 s"
    print(line)
print("predict: feasibility polish from violation 1e-7")
for k in range(40):
    print(f"iter {k:4d}   obj  {1e-9:.8e}  inf_pr {1e-9:.3e}  inf_du 1.000e-01  lg(mu)  -9.0  alpha_pr 1.00e+00  wall     1.00 s")
PY
/usr/bin/python3 - <<'PY' >fell.txt
for k, obj in [(k, 2.0) for k in range(10)] + [(10, 2.4), (11, 2.6), (12, 2.6)]:
    print(f"iter {k:4d}{'r' if k == 11 else ' '}  obj  {obj:.8e}  inf_pr {5e-5:.3e}  inf_du 1.000e-01  lg(mu)  -6.0  alpha_pr 1.00e+00  wall     1.00 s")
PY
out=$(/usr/bin/python3 "$src/scripts/replay_stop_rule.py" log.txt fell.txt)
status=$?
check "exit 0 (got $status)" test "$status" -eq 0
row=$(grep '^log.txt' <<<"$out")
# columns: path | last | lowest J | rule 1e-6 | rule 1e-4 | rule 3e-5 | rule 1e-5 | guard
IFS='|' read -r _ last jmin r6 r4 r35 r5 guard <<<"$row"
check "last iteration 30, not the polish's (got $last)" test "$(echo $last)" = 30
check "lowest feasible J 2.0000 (got $jmin)" test "$(echo $jmin)" = 2.0000
check "1e-6 rule never holds 15 iterations (got $r6)" test "$(echo $r6)" = -
check "1e-4 rule stops at 27 (got $r4)" test "$(echo $r4 | cut -d' ' -f1)" = 27
check "3e-5 rule stops at 29 (got $r35)" test "$(echo $r35 | cut -d' ' -f1)" = 29
check "guard never fires on a falling objective (got $guard)" test "$(echo $guard)" = -
IFS='|' read -r _ _ _ _ _ _ _ guard <<<"$(grep '^fell.txt' <<<"$out")"
check "guard fires at 12, not at the +20 % of 10 nor the restoration line (got $guard)" \
  test "$(echo $guard | cut -d' ' -f1)" = 12
err=$(/usr/bin/python3 "$src/scripts/replay_stop_rule.py" nowhere.log 2>&1 >/dev/null)
status=$?
check "missing log exits 1 (got $status)" test "$status" -eq 1
check "one line naming the file" test "$(grep -c 'nowhere.log' <<<"$err")" -eq 1
finish
