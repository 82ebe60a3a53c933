#!/usr/bin/env python3
"""Replay an acceptable-level stopping test on gaitsim progress logs (diagnostic, docs/BENCHMARKS.md).

usage: replay_stop_rule.py LOG [LOG ...]

A progress log is what `gaitsim track` / `gaitsim predict` print to stderr: one line per Ipopt
iteration, "iter K[r]  obj J  inf_pr P  inf_du D  lg(mu) M ...". For each log and each rule
(violation tolerance, relative objective change per iteration, consecutive iterations) this prints
the first iteration at which the rule holds, and how far its objective is above the lowest objective
of the log's iterates with inf_pr <= 1e-6 (%). It replays only the parts of Ipopt 3.11's acceptable
test that the log shows (constraint violation, objective change); the complementarity and overall
error parts are not printed there, so Ipopt may stop later than the replay says. It may also stop
earlier: when its line search fails at a point that passes the test once, Ipopt ends there at the
acceptable level without the consecutive iterations.
Restoration-phase iterations ("r") break a run of consecutive iterations; the feasibility polish
that follows a solve (its lines come after "feasibility polish") is left out.

The last column replays gaitsim's fall-back guard (go_ipopt_opts.fallback_rise 0.25, fallback_viol
1e-4, as `gaitsim track` and `predict` set them): the first iteration outside the restoration phase
whose objective is more than 25 % above the lowest objective of the earlier such iterations with
inf_pr <= 1e-4, or "-".
"""
import re
import sys

PROGRESS = re.compile(r"iter\s+(\d+)(r?)\s+obj\s+(\S+)\s+inf_pr\s+(\S+)")
RULES = [  # (violation, objective change, iterations)
    (1e-6, 1e-4, 15),  # gaitsim's rule before commit 3ed244e
    (1e-4, 1e-4, 15),  # gaitsim's rule since
    (3e-5, 1e-4, 10),
    (1e-5, 1e-4, 5),
]
GUARD_RISE, GUARD_VIOL = 0.25, 1e-4


def read_log(path):
    rows = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if "feasibility polish" in line:
                break
            m = PROGRESS.match(line)
            if m:
                rows.append((int(m[1]), m[2] == "r", float(m[3]), float(m[4])))
    return rows


def first_stop(rows, viol_tol, obj_tol, n_iter):
    count, prev = 0, None
    for it, resto, obj, inf_pr in rows:
        ok = (not resto and inf_pr <= viol_tol and prev is not None
              and abs(obj - prev) / max(1.0, abs(obj)) <= obj_tol)
        count = count + 1 if ok else 0
        prev = obj
        if count >= n_iter:
            return it, obj
    return None


def first_fall_back(rows):
    low = None
    for it, resto, obj, inf_pr in rows:
        if resto:
            continue
        if low is not None and obj > low + GUARD_RISE * abs(low):
            return it, obj, low
        if inf_pr <= GUARD_VIOL and (low is None or obj < low):
            low = obj
    return None


def main(paths):
    if not paths:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    print("log | last iteration | lowest J (inf_pr <= 1e-6) | " +
          " | ".join(f"stop at viol {v:g}, dJ {o:g}, {n} its" for v, o, n in RULES) +
          f" | guard: {GUARD_RISE * 100:g} % above the lowest J at viol <= {GUARD_VIOL:g}")
    for path in paths:
        try:
            rows = read_log(path)
        except OSError as e:
            print(f"replay_stop_rule.py: {path}: {e.strerror}", file=sys.stderr)
            return 1
        if not rows:
            print(f"replay_stop_rule.py: {path}: no progress lines", file=sys.stderr)
            return 1
        feasible = [r[2] for r in rows if r[3] <= 1e-6]
        jmin = min(feasible) if feasible else float("nan")
        cells = []
        for rule in RULES:
            hit = first_stop(rows, *rule)
            cells.append("-" if hit is None else
                         f"{hit[0]} ({(hit[1] / jmin - 1) * 100:+.2f} %)" if feasible else f"{hit[0]}")
        fell = first_fall_back(rows)
        cells.append("-" if fell is None else f"{fell[0]} ({fell[1]:.4g} against {fell[2]:.4g})")
        print(f"{path} | {rows[-1][0]} | {jmin:.4f} | " + " | ".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
