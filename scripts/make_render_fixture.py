#!/usr/bin/env python3
"""Make tests/fixtures/solution_small/: a small solution folder for the renderer's tests.

usage: scripts/make_render_fixture.py [--trial mjmodels/trials/jw_ngait_og5]
           [--model mjmodels/jw_fullbody.xml] [--out tests/fixtures/solution_small] [--step 11]

From the bundled trial: every STEP-th row of coordinates.mot (plus the last, so the stride is
complete: 14 rows at STEP 11), the model's coordinates only (degrees, inDegrees=yes); grf.mot and
knee_contact.sto at the same rows. Activations ("<muscle>.activation" in states.sto) and
excitations (controls.sto) are SYNTHETIC, not a solution: a = 0.05 + 0.6 sin^2(pi (phase +
i / nmuscle)) for muscle i, so the colours vary across muscles and time; a test fixture, nothing
to read physiology from. Deterministic: the same inputs give the same bytes. Standard library only.

The golden image of tests/test_render.c renders this fixture on mjmodels/jw_fullbody.xml (its
bone meshes, sky and checker floor included): after changing the fixture, the model's display
geometry (mjmodels/meshes/, scripts/osim2mjcf.py) or the renderer, rewrite it with
  GAITSIM_UPDATE_GOLDEN=1 build/tests/test_render
(bit-identical to `gaitsim render tests/fixtures/solution_small --at 0.35 --size 160x120
--png tests/fixtures/render_golden_160x120.png`) and look at it before committing.
"""
import argparse
import math
import os
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import PrepError, read_storage, storage_text, write_atomic  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trial", default="mjmodels/trials/jw_ngait_og5")
    ap.add_argument("--model", default="mjmodels/jw_fullbody.xml")
    ap.add_argument("--out", default="tests/fixtures/solution_small")
    ap.add_argument("--step", type=int, default=11)
    a = ap.parse_args()
    try:
        root = ET.parse(a.model).getroot()
        joints = [j.get("name") for j in root.iter("joint") if j.get("name")]
        muscles = [m.get("name") for m in root.find("actuator") if m.get("name")]
        _, clab, crows = read_storage(os.path.join(a.trial, "coordinates.mot"))
        _, glab, grows = read_storage(os.path.join(a.trial, "grf.mot"))
        _, klab, krows = read_storage(os.path.join(a.trial, "knee_contact.sto"))
        n = len(crows)
        if len(grows) != n or len(krows) != n:
            raise PrepError(a.trial, "coordinates, grf and knee_contact differ in rows")
        pick = list(range(0, n - 1, a.step)) + [n - 1]
        coords = [c for c in clab[1:] if c in joints]
        cidx = [clab.index(c) for c in coords]
        t0, t1 = crows[0][0], crows[-1][0]
        src = f"scripts/make_render_fixture.py from {a.trial} (rows {pick[0]}..{pick[-1]} step {a.step})"
        notes = [f"source={src}", "activations_and_excitations=synthetic (test fixture, not a solution)"]
        srows, urows = [], []
        for i in pick:
            phase = (crows[i][0] - t0) / (t1 - t0)
            act = [0.05 + 0.6 * math.sin(math.pi * (phase + k / len(muscles))) ** 2
                   for k in range(len(muscles))]
            srows.append([crows[i][0]] + [crows[i][j] for j in cidx] + act)
            urows.append([crows[i][0]] + act)
        os.makedirs(a.out, exist_ok=True)
        write_atomic(os.path.join(a.out, "states.sto"), storage_text(
            "states", ["time"] + coords + [m + ".activation" for m in muscles], srows, True, notes))
        write_atomic(os.path.join(a.out, "controls.sto"), storage_text(
            "controls", ["time"] + muscles, urows, False, notes))
        write_atomic(os.path.join(a.out, "grf.mot"), storage_text(
            "grf", glab, [grows[i] for i in pick], False, [f"source={src}"]))
        write_atomic(os.path.join(a.out, "knee_contact.sto"), storage_text(
            "knee_contact", klab, [krows[i] for i in pick], False, [f"source={src}"]))
        write_atomic(os.path.join(a.out, "summary.json"),
                     '{\n\t"problem":\t"render test fixture",\n'
                     f'\t"source":\t"{src}",\n\t"stride_time_s":\t{t1 - t0:.8g}\n}}\n')
    except (PrepError, OSError, ValueError, ET.ParseError) as e:
        print(f"make_render_fixture.py: {e}", file=sys.stderr)
        return 1
    print(f"make_render_fixture.py: wrote {a.out} ({len(pick)} rows, {len(coords)} coordinates, "
          f"{len(muscles)} muscles)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
