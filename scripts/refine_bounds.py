#!/usr/bin/python3
"""Count the states that a defect-keeping mesh refinement puts outside their bounds.

Replays go_refine_trapezoid (optim/go_collocation.c) on a solution's variables.sto: on the
finer mesh of N nodes ((N - 1) a multiple of the solution's nodes - 1), controls and state
derivatives are linear in time and the states follow the trapezoid steps, so every defect is
kept. Where a state rests on a bound, that quadratic dips through it. Prints, per bounded
state (activations a and excitations e in [0.001, 1], normalised tendon forces fT in [0, 5]:
optim/go_gait.h), how many new values lie below the lower bound and the lowest one.

  /usr/bin/python3 scripts/refine_bounds.py SOLUTION_DIR N        e.g. results/track 39
Errors: one line 'refine_bounds: reason', exit status 1 (2 for usage).
"""
import sys

import numpy as np

BOUNDS = {"a": (0.001, 1.0), "e": (0.001, 1.0), "fT": (0.0, 5.0)}
STATES = ("q", "qdot", "a", "fT")
DERIVS = ("dq", "qddot", "adot", "dfT")


def read_variables(path):
    lines = open(path).read().split("\n")
    head = lines.index("endheader")
    cols = lines[head + 1].split("\t")
    rows = [[float(x) for x in l.split("\t")] for l in lines[head + 2:] if l.strip()]
    return cols[1:], np.array(rows)


def main():
    if len(sys.argv) != 3:
        print(__doc__.split("\n\n")[2].strip(), file=sys.stderr)
        return 2
    try:
        names, data = read_variables(sys.argv[1] + "/variables.sto")
        n = int(sys.argv[2])
    except (OSError, ValueError) as e:
        print("refine_bounds: %s" % e, file=sys.stderr)
        return 1
    kind = [c.split(".")[0] for c in names]
    n0, t = len(data), data[-1, 0] - data[0, 0]
    if n0 < 2 or n < n0 or (n - 1) % (n0 - 1):
        print("refine_bounds: N - 1 must be a multiple of %d" % (n0 - 1), file=sys.stderr)
        return 1
    x = [j for s in STATES for j, k in enumerate(kind) if k == s]
    xd = [j for s in DERIVS for j, k in enumerate(kind) if k == s]
    z0 = data[:, 1:]
    r, hf = (n - 1) // (n0 - 1), t / (n - 1)
    z = np.zeros((n, z0.shape[1]))
    for i in range(n0 - 1):
        for q in range(r + 1):
            s, k = q / r, i * r + q
            z[k] = (1 - s) * z0[i] + s * z0[i + 1]  # controls and derivatives linear in time
            if q:  # states: trapezoid steps from the interval's first node
                z[k, x] = z[k - 1, x] + 0.5 * hf * (z[k - 1, xd] + z[k, xd])
    for name, (lo, _) in BOUNDS.items():
        v = z[:, [j for j, k in enumerate(kind) if k == name]]
        print("%s: %d of %d below %g (lowest %.4g)" % (name, (v < lo).sum(), v.size, lo, v.min()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
