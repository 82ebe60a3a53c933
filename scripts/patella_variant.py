#!/usr/bin/python3
"""Write a variant of a JW model in which the right patella follows the femoral component.

usage: scripts/patella_variant.py MODEL OUT

MODEL is mjmodels/jw_fullbody_knee6.xml (or jw_fullbody.xml); OUT the variant, written atomically.
The model's meshdir is relative: put OUT in mjmodels/, or beside a link named meshes to
mjmodels/meshes. Exit 1 with one line naming the file when MODEL cannot be read or is not a JW
model with the patella on tibial_tray; exit 2 on wrong usage. In the committed
model the patella is a jointless child of tibial_tray: exact for knee_flexion, but when the
knee's secondary coordinates move, the patella moves with the tibia, so the quadriceps pull on
the tibia along the quadriceps tendon (mjmodels/README.md, "Patellae"). JW's .osim instead
couples the patella to the femoral component: patfem_flexion = knee_flexion + pi/2 about the same
femoral axis. The variant writes exactly that: the patella body (with its sites and wrap
cylinder) becomes a child of femoral_component with a hinge patfem_flexion (ref pi/2) on
knee_flexion's axis and anchor at the default pose, and an <equality><joint> couples it to
knee_flexion (polycoef 0 1 0 0 0); gaitsim holds the coupling with a stiff spring
(callbacks/gs_coupling.h). At every default-pose the patella sits where it did, so lengths and
flexion moment arms are unchanged; the secondary moment arms and pull directions of recfem,
vasint, vaslat and vasmed become the .osim's. The standing keyframe gains patfem_flexion = pi/2.

The variant is a measurement (docs/BENCHMARKS.md, "The patella on the femur"), not the shipped
model: a forward simulation of it needs a timestep below about 0.05 ms (the patella's inertia
on the coupling's stiffness), and it did not improve the knee contact.
"""
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import osim2mjcf as cv  # noqa: E402
from gs_scriptlib import PrepError, write_atomic  # noqa: E402

PATFEM_REF = math.pi / 2   # patfem_flexion at knee_flexion 0 (JW's .osim coupler offset, rad)


def vec(text):
    return [float(v) for v in text.split()]


def unit_mat(q):
    """Rotation matrix of a quaternion (w x y z), normalised first."""
    n = math.sqrt(sum(a * a for a in q))
    return cv.mat_from_quat([a / n for a in q])


def body_tag(text, name, path):
    m = re.search(r'<body name="%s" pos="([^"]+)" quat="([^"]+)">' % name, text)
    if not m:
        raise PrepError(path, "no body %s with pos and quat" % name)
    return m


def variant(text, path):
    """The variant's MJCF text from the model's."""
    if "patfem_flexion" in text:
        raise PrepError(path, "already has patfem_flexion")
    tt = body_tag(text, "tibial_tray", path)
    fj = re.search(r'<joint name="knee_flexion" type="hinge" axis="([^"]+)" pos="([^"]+)"', text)
    if not fj:
        raise PrepError(path, "no hinge knee_flexion with axis and pos")
    pat = body_tag(text, "patella", path)
    # cut the patella block out of tibial_tray
    start = text.rfind("\n", 0, pat.start()) + 1
    indent = text[start:pat.start()]
    end = text.index("\n" + indent + "</body>", pat.start()) + len("\n" + indent + "</body>")
    block = text[start:end]
    text = text[:start] + text[end + 1:]
    # poses in the femoral_component frame at the default pose (every knee coordinate at its
    # ref: there tibial_tray sits at its pos / quat)
    r_tt, p_tt = unit_mat(vec(tt.group(2))), vec(tt.group(1))
    r_pat = cv.mat_mul(r_tt, unit_mat(vec(pat.group(2))))
    q_pat = cv.quat_from_mat(r_pat)
    p_pat = cv.vec_add(p_tt, cv.mat_vec(r_tt, vec(pat.group(1))))
    axis_fc = cv.mat_vec(r_tt, vec(fj.group(1)))
    anchor_fc = cv.vec_add(p_tt, cv.mat_vec(r_tt, vec(fj.group(2))))
    axis = cv.mat_vec(cv.mat_t(r_pat), axis_fc)
    anchor = cv.mat_vec(cv.mat_t(r_pat), cv.vec_sub(anchor_fc, p_pat))
    rng = re.search(r'<joint name="knee_flexion"[^>]*range="([^"]+)"', text)
    lo, hi = vec(rng.group(1)) if rng else (-2.513, 0.349)
    head = ('<body name="patella" pos="%s" quat="%s">\n%s  <joint name="patfem_flexion" '
            'type="hinge" axis="%s" pos="%s" ref="%.10g" range="%.10g %.10g"/>') % (
        cv.fvec(p_pat, 10), cv.fvec(q_pat, 10), indent, cv.fvec(axis, 10), cv.fvec(anchor, 10),
        PATFEM_REF, lo + PATFEM_REF, hi + PATFEM_REF)
    block = block.replace(pat.group(0), head)
    block = "\n".join(line[2:] if line.startswith("  ") else line for line in block.split("\n"))
    # the patella becomes femoral_component's last child
    fc = body_tag(text, "femoral_component", path)
    fc_indent = text[text.rfind("\n", 0, fc.start()) + 1:fc.start()]
    close = text.index("\n" + fc_indent + "</body>", fc.start())
    text = text[:close] + "\n" + block + text[close:]
    # the coupling, then the keyframe's value at patfem_flexion's qpos address
    eq = ('  <equality>\n    <joint name="patfem_coupler" joint1="patfem_flexion" '
          'joint2="knee_flexion" polycoef="0 1 0 0 0"/>\n  </equality>\n')
    if "<equality>" in text:
        raise PrepError(path, "has an <equality> section already")
    text = text.replace("  <tendon>", eq + "  <tendon>", 1)
    body_start = text.index("<worldbody>")
    address = len(re.findall(r"<joint name=", text[body_start:text.index('name="patfem_flexion"')]))
    key = re.search(r'<key name="standing" qpos="([^"]+)"', text)
    if key:
        q = key.group(1).split()
        q.insert(address, "%.10g" % PATFEM_REF)
        text = text.replace(key.group(0), '<key name="standing" qpos="%s"' % " ".join(q))
    return text.replace(
        "<!--\n", "<!--\n  VARIANT by scripts/patella_variant.py: the right patella follows the "
        "femoral component\n    (hinge patfem_flexion coupled to knee_flexion); not the shipped "
        "model.\n", 1)


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 2
    try:
        with open(argv[1]) as f:
            text = f.read()
        write_atomic(argv[2], variant(text, argv[1]))
    except PrepError as e:
        print("patella_variant.py: %s" % e, file=sys.stderr)
        return 1
    except OSError as e:
        print("patella_variant.py: %s: %s" % (e.filename, e.strerror), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
