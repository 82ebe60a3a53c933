#!/usr/bin/env python3
"""Derive the planar model mjmodels/gait2d.xml from mjmodels/jw_fullbody.xml.

The planar model exercises the whole collocation chain fast: the same bodies, masses, muscle
paths, Hill parameters and contact spheres as the full-body model, restricted to the sagittal
plane. Joints that are not kept become welds at their reference value (MuJoCo: a body without a
joint is rigidly attached to its parent), so their mass stays where it was.

Kept degrees of freedom (9): pelvis_tx, pelvis_ty, pelvis_rz (pelvis tilt), and per leg hip
flexion, knee flexion, ankle angle. Kept muscles (9 per leg, 18): the gait2392 units that
dominate the sagittal plane, one per functional group (gait10-style):
glut_max2, iliacus, rect_fem, vas_int, bifemlh, bifemsh, med_gas, soleus, tib_ant.

Usage: /usr/bin/python3 scripts/make_gait2d.py [--full mjmodels/jw_fullbody.xml]
                                              [--out mjmodels/gait2d.xml]
Standard library only. Deterministic output; written atomically.
"""
import argparse
import os
import sys
import xml.etree.ElementTree as ET

from gs_scriptlib import write_atomic

KEPT_JOINTS_COMMON = ["pelvis_tx", "pelvis_ty", "pelvis_rz"]
KEPT_JOINTS_RIGHT = ["hip_flexion", "knee_flexion", "ankle_angle"]
KEPT_JOINTS_LEFT = ["hip_flexion_l", "knee_flexion_l", "ankle_angle_l"]
KEPT_MUSCLES = ["glut_max2", "iliacus", "rect_fem", "vas_int", "bifemlh", "bifemsh",
                "med_gas", "soleus", "tib_ant"]
# JW's right leg uses the .osim's own (Grand Challenge) names without suffix; the left leg uses
# gait2392 names with "_l" (mjmodels/README.md; inverse of GAIT2392_NAME in osim2mjcf.py)
RIGHT_LEG_NAME = {"glut_max2": "glmax2", "iliacus": "iliacus", "rect_fem": "recfem",
                  "vas_int": "vasint", "bifemlh": "bflh", "bifemsh": "bfsh", "med_gas": "gasmed",
                  "soleus": "soleus", "tib_ant": "tibant"}


def fail(path, reason):
    print(f"make_gait2d: {path}: {reason}", file=sys.stderr)
    sys.exit(1)


def kept_muscle_names():
    """Names in jw_fullbody.xml: right leg JW names, left leg gait2392 names + '_l'."""
    return [RIGHT_LEG_NAME[m] for m in KEPT_MUSCLES] + [m + "_l" for m in KEPT_MUSCLES]


def planarize(root, src_path):
    kept_joints = set(KEPT_JOINTS_COMMON + KEPT_JOINTS_RIGHT + KEPT_JOINTS_LEFT)
    # qpos order is the document order of the body tree's joints (all hinge/slide: one qpos
    # each); <default> also holds <joint> elements, which are neither counted nor removed
    world = root.find("worldbody")
    if world is None:
        fail(src_path, "no <worldbody>")
    joint_order = [j.get("name") for j in world.iter("joint")]
    keyframes = []
    for key in root.iter("key"):
        qpos = [float(v) for v in (key.get("qpos") or "").split()]
        if qpos and len(qpos) != len(joint_order):
            fail(src_path, f"keyframe {key.get('name')} has {len(qpos)} qpos for {len(joint_order)} joints")
        keyframes.append((key.get("name"), qpos))
    found = set()
    # drop every joint that is not kept: its body becomes welded to its parent
    for parent in world.iter():
        for child in list(parent):
            if child.tag == "joint":
                name = child.get("name")
                if name in kept_joints:
                    found.add(name)
                else:
                    parent.remove(child)
    missing = kept_joints - found
    if missing:
        fail(src_path, "missing joints " + ", ".join(sorted(missing)))

    muscles = set(kept_muscle_names())
    for section_tag in ("tendon", "actuator"):
        section = root.find(section_tag)
        if section is None:
            fail(src_path, f"no <{section_tag}> section")
        for child in list(section):
            if child.get("name") not in muscles:
                section.remove(child)
        names = {c.get("name") for c in section}
        if names != muscles:
            fail(src_path, f"<{section_tag}> lacks " + ", ".join(sorted(muscles - names)))

    # keyframes keep the kept joints' values; equality/exclusions naming removed parts go
    for tag in ("keyframe", "equality"):
        for el in root.findall(tag):
            root.remove(el)
    if keyframes:
        kf = ET.SubElement(root, "keyframe")
        for name, qpos in keyframes:
            kept = [f"{v:.9g}" for j, v in zip(joint_order, qpos) if j in kept_joints]
            key = ET.SubElement(kf, "key", {"name": name})
            if kept:
                key.set("qpos", " ".join(kept))
    size = root.find("size")
    if size is not None and size.get("nuserdata"):
        size.set("nuserdata", str(len(muscles)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--full", default=os.path.join(here, "..", "mjmodels", "jw_fullbody.xml"))
    ap.add_argument("--out", default=os.path.join(here, "..", "mjmodels", "gait2d.xml"))
    args = ap.parse_args()
    try:
        tree = ET.parse(args.full, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    except (OSError, ET.ParseError) as e:
        fail(args.full, str(e))
    root = tree.getroot()
    planarize(root, args.full)
    root.set("model", "gait2d")
    header = (
        "\n  gait2d: planar (sagittal) model derived from jw_fullbody.xml by scripts/make_gait2d.py."
        "\n  GENERATED FILE - do not edit by hand; regenerate with"
        "\n    /usr/bin/python3 scripts/make_gait2d.py"
        "\n  9 degrees of freedom: " + ", ".join(KEPT_JOINTS_COMMON + KEPT_JOINTS_RIGHT + KEPT_JOINTS_LEFT) +
        "\n  18 muscles (gait2392 unit: right-leg name in this file): " +
        ", ".join("%s: %s" % (m, RIGHT_LEG_NAME[m]) for m in KEPT_MUSCLES) +
        "; left leg <unit>_l."
        "\n  Bodies, masses, paths, Hill parameters and contact spheres are those of jw_fullbody.xml"
        "\n  (provenance: see that file); removed joints are welded at their reference value.\n")
    ET.indent(tree, space="  ")
    body = ET.tostring(root, encoding="unicode")
    write_atomic(args.out, "<!--" + header + "-->\n" + body + "\n")
    print(f"make_gait2d: wrote {args.out}")


if __name__ == "__main__":
    main()
