#!/usr/bin/python3
"""osim2mjcf.py: convert the Knee Grand Challenge JW OpenSim model to MJCF for MuJoCo 2.2.2.

Reads JW_AllBody_scaled.osim (OpenSim 4.0 document format, gait2392-family muscles) and the
muscle_params folder, writes one MJCF file that follows callbacks/gs_model_layout.h, and a
reference table of muscle-tendon lengths and moment arms computed from the OpenSim geometry
alone (CustomJoint kinematics, path points incl. conditional and moving points; straight
segments, and with OpenSim's wrapping re-implemented: wrapped_path) for the project's C test.

Standard library only; runs the built gaitsim (`inspect`), whose MuJoCo measures the draft
model's path lengths for the tendon calibration. Deterministic: the same inputs give the same
bytes.

Usage:
  /usr/bin/python3 scripts/osim2mjcf.py --osim PATH --muscle-params DIR \
      --out mjmodels/jw_fullbody.xml --reference-out mjmodels/reference/jw_moment_arms.csv \
      [--trial-ik PATH] [--knee-params mjmodels/knee/jw_knee.json] [--gaitsim build/gaitsim]
"""
import argparse
import csv
import json
import math
import os
import xml.etree.ElementTree as ET

from gs_scriptlib import PrepError, inspect_muscles, storage_text, write_atomic

CONVERTER = "scripts/osim2mjcf.py"

# ------------------------------------------------------------------------------------------------
# model decisions (documented in mjmodels/README.md)
# ------------------------------------------------------------------------------------------------

# the 26 generalized coordinates of the MuJoCo model, in qpos order (pelvis first)
MODEL_COORDINATES = [
    "pelvis_tx", "pelvis_ty", "pelvis_tz", "pelvis_rz", "pelvis_rx", "pelvis_ry",
    "hip_flexion", "hip_adduction", "hip_rotation",
    "knee_flexion", "knee_adduction", "knee_rotation", "knee_tx", "knee_ty", "knee_tz",
    "ankle_angle", "subtalar_angle",
    "hip_flexion_l", "hip_adduction_l", "hip_rotation_l", "knee_flexion_l",
    "ankle_angle_l", "subtalar_angle_l",
    "lumbar_extension", "lumbar_bending", "lumbar_rotation",
]

# the coordinates in m (the others in rad; the trial's IK in degrees)
TRANSLATIONS = ("pelvis_tx", "pelvis_ty", "pelvis_tz", "knee_tx", "knee_ty", "knee_tz")

# secondary right-knee coordinates: placeholder springs and damping until a knee-contact model
# replaces them (--knee-params removes both: add_knee_params)
KNEE_SECONDARY = {
    # name: (stiffness N m/rad or N/m, damping N m s/rad or N s/m)
    "knee_adduction": (1.0e4, 50.0),
    "knee_rotation": (1.0e4, 50.0),
    "knee_tx": (1.0e6, 2.0e3),
    "knee_ty": (1.0e6, 2.0e3),
    "knee_tz": (1.0e6, 2.0e3),
}

# locked coordinates of the welded arms with `--arm-pose hanging`: arms down, elbows 15 deg flexed
# (rad); `--arm-pose trial`, the default, welds them at the trial stride's mean instead
# (trial_arm_pose; docs/BENCHMARKS.md, "The welded arms' pose and the pitch residual")
ARM_POSE = {
    "arm_flex_r": 0.0, "arm_add_r": 0.0, "arm_rot_r": 0.0, "elbow_flex_r": math.radians(15.0),
    "wrist_flex_r": 0.0, "wrist_dev_r": 0.0,
    "arm_flex_l": 0.0, "arm_add_l": 0.0, "arm_rot_l": 0.0, "elbow_flex_l": math.radians(15.0),
    "wrist_flex_l": 0.0, "wrist_dev_l": 0.0,
}

# duplicate paths in the .osim that are left out (same muscle with a shorter path or unscaled)
SKIPPED_FORCES = {
    "recfem_withreallength", "vasint_withreallength", "vaslat_withreallength",
    "vasmed_withreallength",
    "ercspn_r_0", "ercspn_l_0", "intobl_r_0", "intobl_l_0", "extobl_r_0", "extobl_l_0",
}

# JW right-leg muscle names -> gait2392 names (to look up the metabolic parameters)
GAIT2392_NAME = {
    "addbrev": "add_brev", "addlong": "add_long", "addmagProx": "add_mag1",
    "addmagMid": "add_mag2", "addmagDist": "add_mag3", "addmagIsch": "add_mag3",
    "bflh": "bifemlh", "bfsh": "bifemsh", "edl": "ext_dig", "ehl": "ext_hal",
    "fdl": "flex_dig", "fhl": "flex_hal", "gaslat": "lat_gas", "gasmed": "med_gas", "gem": "gem",
    "glmax1": "glut_max1", "glmax2": "glut_max2", "glmax3": "glut_max3",
    "glmed1": "glut_med1", "glmed2": "glut_med2", "glmed3": "glut_med3",
    "glmin1": "glut_min1", "glmin2": "glut_min2", "glmin3": "glut_min3",
    "grac": "grac", "iliacus": "iliacus", "pect": "pect", "perbrev": "per_brev",
    "perlong": "per_long", "pertert": "per_tert", "piri": "peri", "psoas": "psoas",
    "quadfem": "quad_fem", "recfem": "rect_fem", "sart": "sar", "semimem": "semimem",
    "semiten": "semiten", "soleus": "soleus", "tfl": "tfl", "tibant": "tib_ant",
    "tibpost": "tib_post", "vasint": "vas_int", "vaslat": "vas_lat", "vasmed": "vas_med",
}

# relative excess of a right muscle's trial-mean length ratio over its left counterpart's above
# which its tendon slack length is recalibrated (calibrate_right_tendon_slack)
OVERSTRETCH_TOL = 0.03
# largest normalised fibre length (tendon at slack) allowed anywhere in the trial
# (cap_fibre_stretch)
LM_MAX_TRIAL = 1.3
# smallest normalised fibre length (tendon at slack) allowed anywhere in the trial, and the
# longest that raising it may cause (the predictive problem's bound, Lin, Walter & Pandy 2018)
# (floor_fibre_shortening)
LM_MIN_TRIAL = 0.4
LM_MAX_HARD = 1.5
MUSCLE_DENSITY = 1059.7   # kg/m^3 (Umberger et al. 2003)
# Specific tension of the six lumped trunk muscles (ercspn, intobl, extobl; Pa), which sets their
# metabolic mass Fmax / sigma * lopt * density. The 3dpredictsim table has no measurement for them
# and carries OpenSim's default 0.25 MPa; with gait2392's trunk strengths (2500 N, 900 N) that
# makes each erector spinae a 100 cm^2, 1.22 kg muscle, where MRI gives the living erector spinae
# about 26 cm^2 a side (Marras et al. 2001, Clin Biomech 16:38) and cadavers 11.6 cm^2 (Delp et
# al. 2001, J Biomech 34:371). Burkhart et al. 2018 (J Orthop Res 36:498) measured the apparent
# maximum stress of the trunk extensors of 49 adults over 65 (JW was 80): 75.5 N/cm^2 on average
# (40-130). That value for all six: erector spinae 0.40 kg a side, obliques 0.12 and 0.14 kg.
TRUNK_SPECIFIC_TENSION = 0.755e6
TRUNK_MUSCLES = ("ercspn_r", "ercspn_l", "intobl_r", "intobl_l", "extobl_r", "extobl_l")
# Specific tension that sets the leg muscles' metabolic mass (Pa): 0.25 MPa, the stress of living
# human knee extensors (Narici et al. 1992, Eur J Appl Physiol 65:438: 250 kN/m^2 from MRI PCSA
# and maximum voluntary force) and the default of OpenSim's Umberger2010 probe. Umberger's heat
# rates are per kilogram and its work is force times velocity, so Fmax / mass sets what work costs
# in heat. The 3dpredictsim table's tensions (0.5-1.5 MPa) made the masses 35-55 % of these and the
# heat too cheap against the work: the fibres' positive work was 0.41 of the muscles' energy at
# 2.0 m/s, where muscle turns chemical energy into positive work at about 0.25 (Margaria 1968, Int
# Z Angew Physiol 25:339). Legs 9.5 kg (right) and 11.7 kg (left), against 7.4 kg a leg in
# Handsfield et al. 2014's mean MRI volumes (J Biomech 47:631; 3.7 and 4.2 kg before). The
# slow-twitch fractions are the table's.
LEG_SPECIFIC_TENSION = 0.25e6

# Passive moments at the ends of the joints' ranges (callbacks/gs_joint_limits.h;
# mjmodels/README.md, "Joint-limit moments"): tau = k1 exp(k2 (q - theta2)) + k3 exp(k4 (q -
# theta1)) (N m, q in rad), Anderson & Pandy 1999's form with the coefficients of Falisse et al.
# 2019 (J R Soc Interface 16:20190402; their 3D model, antoinefalisse/3dpredictsim, MIT). Each row
# names a leg coordinate (the right's name) and is written for both legs alike, COORD and COORD_l
# (the .osim's coordinate conventions are gait2392's, theirs).
# JW's .osim has none: its knees hyperextended by 12-17 deg in the predictions (the coordinate
# range reaches +20 deg), standing on locked knees with idle vasti.
# Only the knees: Falisse's lumbar flexion limit (-30 deg) lies inside JW's flexed trunk (-27 to
# -32 deg in the trial) and the tracking hung the trunk on it (84 N m of support the effort goal
# does not price; docs/BENCHMARKS.md, "Joint-limit moments at the knees"); their hip, ankle and
# subtalar laws give under 0.5 N m over the trials.
JOINT_LIMIT_MOMENTS = (  # coordinate, (k1, k2, k3, k4), (theta1, theta2)
    ("knee_flexion", (-6.09, 33.94, 11.03, -11.33), (-2.4, 0.13)),
)
VMAX = 10.0               # lopt/s
TAU_ACT = 0.010           # s
TAU_DEACT = 0.040         # s
TENDON_KT = 35.0          # De Groote et al. 2016 tendon shape factor (-)

# Hunt-Crossley sphere parameters (geom user row, gs_model_layout.h order)
CONTACT_USER = [1.0e6, 2.0, 0.8, 0.8, 0.5, 0.2]
# Contact spheres in the FOOT FRAME F of each foot (mjmodels/README.md, "Contact spheres"):
# origin at the calcaneus origin's projection on the sole plane, y = the sole's normal (up), x
# forward along the projection of the calcaneus-origin -> mtp-joint-centre line on the sole, z =
# x cross y (to the right). The sole plane is calibrated on the trial (calibrated_soles): the floor
# as the calcaneus sees it while the foot is flat, lowered by the static penetration under body
# weight. Values are for the right foot with z lateral; the left foot mirrors z. Every sphere's
# bottom lies on the sole plane. Spheres 1-4 go on the calcaneus, 5-6 on the toes
# (gs_model_layout.h).
CONTACT_SPHERES = [
    # (index, x forward, z lateral, radius, on toes)
    (1, 0.015, -0.016, 0.032, False),   # heel, medial (under the calcaneal tuberosity)
    (2, 0.165, -0.030, 0.032, False),   # first metatarsal head (medial forefoot)
    (3, 0.140, 0.035, 0.032, False),    # fifth metatarsal head (lateral forefoot)
    (4, 0.015, 0.016, 0.032, False),    # heel, lateral
    (5, 0.215, -0.028, 0.020, True),    # hallux
    (6, 0.195, 0.020, 0.020, True),     # lateral toes
]
# foot-flat frames of the trial: both the calcaneus origin and the toes origin slower than this
# (m/s, central differences of the IK poses)
FOOT_FLAT_SPEED = 0.1
# standard gravity (m/s^2), written into the MJCF's <option gravity>
GRAVITY = 9.80665

# display geometry (mjmodels/meshes/README.md, scripts/make_bone_meshes.py): meshes the .osim does
# not reference, added to a body (a whole pelvis: the .osim draws the right half only), and the
# implant meshes the .osim names but are not public, replaced by files made from the prosthesis
EXTRA_MESHES = {"pelvis": ["sacrum", "l_pelvis"]}
IMPLANT_MESHES = {"femoral_component": "femoral_component", "tibial_tray": "tibial_insert"}
# scene of the generated models (visual only): sky gradient (top, horizon), floor checker of
# FLOOR_SQUARE squares, bone and implant colours (RGBA)
SKY_RGB = ("0.55 0.72 0.90", "0.93 0.95 0.97")
FLOOR_RGB = ("0.80 0.80 0.78", "0.66 0.66 0.64")
FLOOR_SQUARE = 1.0        # m (MuJoCo maps a uniform texture with period 2 / texrepeat)
BONE_RGBA = "0.92 0.89 0.82 1"
IMPLANT_RGBA = "0.72 0.75 0.80 1"

EPS_ZERO = 1e-8           # |default value| below which a coordinate default counts as 0
FD_STEP = 1e-5            # central-difference step for moment arms (rad or m)


# ------------------------------------------------------------------------------------------------
# 3-D rigid transforms: rotation matrices as 3x3 nested lists, transforms as (R, p)
# ------------------------------------------------------------------------------------------------

def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def mat_vec(a, v):
    return [sum(a[i][k] * v[k] for k in range(3)) for i in range(3)]


def mat_t(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def vec_add(a, b):
    return [a[i] + b[i] for i in range(3)]


def vec_sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def vec_scale(a, s):
    return [x * s for x in a]


def vec_norm(a):
    return math.sqrt(sum(x * x for x in a))


def unit(a):
    n = vec_norm(a)
    return [x / n for x in a]


IDENTITY = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
TF_IDENTITY = (IDENTITY, [0.0, 0.0, 0.0])


def axis_angle(axis, angle):
    """Rotation matrix of a right-handed rotation by angle (rad) about the unit axis (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]


def body_fixed_xyz(angles):
    """OpenSim frame orientation: body-fixed X-Y-Z Euler angles (rad), R = Rx Ry Rz."""
    r = axis_angle([1.0, 0.0, 0.0], angles[0])
    r = mat_mul(r, axis_angle([0.0, 1.0, 0.0], angles[1]))
    return mat_mul(r, axis_angle([0.0, 0.0, 1.0], angles[2]))


def tf_mul(a, b):
    """Compose frames: X_AC = X_AB * X_BC."""
    return (mat_mul(a[0], b[0]), vec_add(mat_vec(a[0], b[1]), a[1]))


def tf_inv(a):
    rt = mat_t(a[0])
    return (rt, vec_scale(mat_vec(rt, a[1]), -1.0))


def tf_point(a, p):
    return vec_add(mat_vec(a[0], p), a[1])


def tf_rot(r):
    return (r, [0.0, 0.0, 0.0])


def tf_trans(p):
    return (IDENTITY, list(p))


def mat_from_quat(q):
    """Rotation matrix of a unit quaternion (w x y z)."""
    w, x, y, z = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def quat_from_mat(r):
    """Unit quaternion (w x y z), w >= 0, of a rotation matrix."""
    tr = r[0][0] + r[1][1] + r[2][2]
    if tr > 0.0:
        s = math.sqrt(tr + 1.0) * 2.0
        q = [0.25 * s, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s]
    elif r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = math.sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2.0
        q = [(r[2][1] - r[1][2]) / s, 0.25 * s, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s]
    elif r[1][1] > r[2][2]:
        s = math.sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2.0
        q = [(r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, 0.25 * s, (r[1][2] + r[2][1]) / s]
    else:
        s = math.sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2.0
        q = [(r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, 0.25 * s]
    if q[0] < 0.0:
        q = [-x for x in q]
    n = math.sqrt(sum(x * x for x in q))
    return [x / n for x in q]


# ------------------------------------------------------------------------------------------------
# OpenSim functions (Function.h family): LinearFunction, Constant, MultiplierFunction, SimmSpline
# ------------------------------------------------------------------------------------------------

class LinearFunction:
    """OpenSim LinearFunction: f(x) = a x + b, coefficients 'a b'."""
    def __init__(self, a, b):
        self.a, self.b = a, b

    def __call__(self, x):
        return self.a * x + self.b


class ConstantFunction:
    def __init__(self, value):
        self.value = value

    def __call__(self, x):
        return self.value


class MultiplierFunction:
    """OpenSim MultiplierFunction: f(x) = scale * g(x) (written by model scaling)."""
    def __init__(self, inner, scale):
        self.inner, self.scale = inner, scale

    def __call__(self, x):
        return self.scale * self.inner(x)


class SimmSpline:
    """OpenSim SimmSpline: the Forsythe-Malcolm-Moler cubic spline (end conditions from cubics
    through the first and last four points), linear extrapolation with the end slopes
    (OpenSim SimmSpline::calcCoefficients, SimmSpline::calcValue)."""
    def __init__(self, xs, ys):
        self.x, self.y = list(xs), list(ys)
        n = len(xs)
        b, c, d = [0.0] * n, [0.0] * n, [0.0] * n
        x, y = self.x, self.y
        if n == 2:
            b[0] = b[1] = (y[1] - y[0]) / (x[1] - x[0])
        elif n >= 3:
            nm1 = n - 1
            d[0] = x[1] - x[0]
            c[1] = (y[1] - y[0]) / d[0]
            for i in range(1, nm1):
                d[i] = x[i + 1] - x[i]
                b[i] = 2.0 * (d[i - 1] + d[i])
                c[i + 1] = (y[i + 1] - y[i]) / d[i]
                c[i] = c[i + 1] - c[i]
            b[0] = -d[0]
            b[nm1] = -d[n - 2]
            c[0] = c[nm1] = 0.0
            if n > 3:
                c[0] = c[2] / (x[3] - x[1]) - c[1] / (x[2] - x[0])
                c[nm1] = c[n - 2] / (x[nm1] - x[n - 3]) - c[n - 3] / (x[n - 2] - x[n - 4])
                c[0] = c[0] * d[0] * d[0] / (x[3] - x[0])
                c[nm1] = -c[nm1] * d[n - 2] * d[n - 2] / (x[nm1] - x[n - 4])
            for i in range(1, n):
                t = d[i - 1] / b[i - 1]
                b[i] -= t * d[i - 1]
                c[i] -= t * c[i - 1]
            c[nm1] /= b[nm1]
            for j in range(nm1):
                i = n - 2 - j
                c[i] = (c[i] - d[i] * c[i + 1]) / b[i]
            b[nm1] = (y[nm1] - y[n - 2]) / d[n - 2] + d[n - 2] * (c[n - 2] + 2.0 * c[nm1])
            for i in range(nm1):
                b[i] = (y[i + 1] - y[i]) / d[i] - d[i] * (c[i + 1] + 2.0 * c[i])
                d[i] = (c[i + 1] - c[i]) / d[i]
                c[i] = 3.0 * c[i]
            c[nm1] = 3.0 * c[nm1]
            d[nm1] = d[n - 2]
        self.b, self.c, self.d = b, c, d

    def __call__(self, xv):
        x, y = self.x, self.y
        n = len(x)
        if n == 1:
            return y[0]
        if xv < x[0]:
            return y[0] + (xv - x[0]) * self.b[0]
        if xv > x[-1]:
            return y[-1] + (xv - x[-1]) * self.b[-1]
        k = 0
        while k < n - 2 and xv >= x[k + 1]:
            k += 1
        dx = xv - x[k]
        return y[k] + dx * (self.b[k] + dx * (self.c[k] + dx * self.d[k]))


def floats(text):
    return [float(v) for v in text.split()]


def parse_function(elem):
    """Build a callable from an OpenSim Function element."""
    tag = elem.tag
    if tag == "LinearFunction":
        a, b = floats(elem.findtext("coefficients"))
        return LinearFunction(a, b)
    if tag == "Constant":
        return ConstantFunction(float(elem.findtext("value")))
    if tag == "MultiplierFunction":
        inner = parse_function(elem.find("function")[0])
        return MultiplierFunction(inner, float(elem.findtext("scale")))
    if tag == "SimmSpline":
        return SimmSpline(floats(elem.findtext("x")), floats(elem.findtext("y")))
    raise ValueError("unsupported OpenSim function " + tag)


# ------------------------------------------------------------------------------------------------
# OpenSim model: bodies, joints (with offset frames), coordinates, couplers, muscles
# ------------------------------------------------------------------------------------------------

def osim_meshes(path):
    """(body, mesh base name, [sx, sy, sz]) for every <Mesh> attached to a body of the .osim, in
    document order (the display geometry; JW's meshes sit in their body's own frame, socket_frame
    '..', mjmodels/meshes/README.md)."""
    root = ET.parse(path).getroot()
    out = []
    for body in root.iter("Body"):
        for mesh in body.iter("Mesh"):
            name = os.path.splitext((mesh.findtext("mesh_file") or "").strip())[0]
            scale = floats(mesh.findtext("scale_factors") or "1 1 1")
            out.append((body.get("name"), name, scale))
    return out


def display_meshes(osim_path, mesh_dir):
    """body -> [(mesh asset name, scale, geom class)] of the model's visual-only geoms: the
    .osim's meshes (implant ones replaced, IMPLANT_MESHES) plus EXTRA_MESHES, each as an STL of
    scripts/make_bone_meshes.py in mesh_dir (all must exist)."""
    meshes = {}
    for body, name, scale in osim_meshes(osim_path):
        cls = "implant" if name in IMPLANT_MESHES else "bone"
        meshes.setdefault(body, []).append((IMPLANT_MESHES.get(name, name), scale, cls))
    for body, names in EXTRA_MESHES.items():
        meshes.setdefault(body, []).extend((n, [1.0, 1.0, 1.0], "bone") for n in names)
    missing = [n for lst in meshes.values() for n, _, _ in lst
               if not os.path.isfile(os.path.join(mesh_dir, n + ".stl"))]
    if missing:
        raise SystemExit("osim2mjcf.py: %s: no %s.stl (%d missing; make them with "
                         "scripts/make_bone_meshes.py)" % (mesh_dir, missing[0], len(missing)))
    return meshes


def last_name(path):
    """'/bodyset/femur' -> 'femur', '/jointset/knee_l/knee_flexion_l' -> 'knee_flexion_l'."""
    return path.strip().split("/")[-1]


class OsimModel:
    def __init__(self, path):
        root = ET.parse(path).getroot()
        model = root.find("Model")
        self.bodies = {}
        self.body_order = []
        for b in model.find("BodySet/objects"):
            wraps = []
            for w in b.find("WrapObjectSet/objects"):
                wraps.append({
                    "name": w.get("name"), "type": w.tag,
                    "rotation": body_fixed_xyz(floats(w.findtext("xyz_body_rotation"))),
                    "translation": floats(w.findtext("translation")),
                    "quadrant": (w.findtext("quadrant") or "all").strip(),
                    "radius": float(w.findtext("radius") or 0.0),
                    "length": float(w.findtext("length") or 0.0),
                    "dimensions": floats(w.findtext("dimensions") or "0 0 0"),
                })
            self.bodies[b.get("name")] = {
                "mass": float(b.findtext("mass")),
                "com": floats(b.findtext("mass_center")),
                "inertia": floats(b.findtext("inertia")),
                "wraps": wraps,
            }
            self.body_order.append(b.get("name"))
        self.coords = {}
        self.joints = []
        for j in model.find("JointSet/objects"):
            frames = {}
            for f in j.findall("frames/PhysicalOffsetFrame"):
                frames[f.get("name")] = (
                    last_name(f.findtext("socket_parent")),
                    (body_fixed_xyz(floats(f.findtext("orientation"))),
                     floats(f.findtext("translation"))))
            parent_body, parent_offset = frames[j.findtext("socket_parent_frame").strip()]
            child_body, child_offset = frames[j.findtext("socket_child_frame").strip()]
            axes = []
            for ta in j.findall("SpatialTransform/TransformAxis"):
                fn = [e for e in ta if e.tag not in ("coordinates", "axis")][0]
                axes.append({
                    "kind": "rotation" if ta.get("name").startswith("rotation") else "translation",
                    "axis": unit(floats(ta.findtext("axis"))),
                    "coordinate": (ta.findtext("coordinates") or "").strip() or None,
                    "function": parse_function(fn),
                })
            for c in j.findall("coordinates/Coordinate"):
                self.coords[c.get("name")] = {
                    "default": float(c.findtext("default_value")),
                    "range": floats(c.findtext("range")),
                    "locked": c.findtext("locked").strip() == "true",
                    "joint": j.get("name"),
                }
            self.joints.append({
                "name": j.get("name"), "type": j.tag,
                "parent": parent_body, "parent_offset": parent_offset,
                "child": child_body, "child_offset": child_offset,
                "rotations": [a for a in axes if a["kind"] == "rotation"],
                "translations": [a for a in axes if a["kind"] == "translation"],
            })
        self.arm_pose = dict(ARM_POSE)  # main() replaces it for --arm-pose trial
        self.couplers = {}
        for c in model.find("ConstraintSet/objects"):
            if c.tag == "CoordinateCouplerConstraint" and c.findtext("isEnforced").strip() == "true":
                fn = parse_function(c.find("coupled_coordinates_function")[0])
                self.couplers[c.findtext("dependent_coordinate_name").strip()] = (
                    c.findtext("independent_coordinate_names").strip(), fn,
                    float(c.findtext("scale_factor") or 1.0))
        self.muscles = []
        for f in model.find("ForceSet/objects"):
            if f.find("max_isometric_force") is None or f.get("name") in SKIPPED_FORCES:
                continue
            points = []
            for p in f.find("GeometryPath/PathPointSet/objects"):
                pt = {"name": p.get("name"), "type": p.tag,
                      "body": last_name(p.findtext("socket_parent_frame"))}
                if p.tag == "MovingPathPoint":
                    pt["coords"] = [last_name(p.findtext("socket_%s_coordinate" % a))
                                    for a in "xyz"]
                    pt["functions"] = [parse_function(p.find("%s_location" % a)[0])
                                       for a in "xyz"]
                else:
                    pt["location"] = floats(p.findtext("location"))
                if p.tag == "ConditionalPathPoint":
                    pt["coordinate"] = last_name(p.findtext("socket_coordinate"))
                    pt["range"] = floats(p.findtext("range"))
                points.append(pt)
            wraps = []
            for w in f.findall("GeometryPath/PathWrapSet/objects/PathWrap"):
                wraps.append({"object": w.findtext("wrap_object").strip(),
                              "range": [int(v) for v in floats(w.findtext("range") or "-1 -1")]})
            self.muscles.append({
                "name": f.get("name"), "type": f.tag, "points": points, "wraps": wraps,
                "fmax": float(f.findtext("max_isometric_force")),
                "lopt": float(f.findtext("optimal_fiber_length")),
                "lts": float(f.findtext("tendon_slack_length")),
                "pennation": float(f.findtext("pennation_angle_at_optimal")),
            })
        self._memo = {}
        self.build_tree()

    def build_tree(self):
        """Spanning tree from ground. A joint whose child body is already placed is reversed,
        as OpenSim 4's MultibodyGraphMaker does; the joint still states X_G,pf * X_FM = X_G,cf."""
        placed = {"ground"}
        self.tree = []          # (joint, reversed) in an order where parents come first
        self.tree_parent = {}   # body -> tree parent body
        self.tree_edge = {}     # body -> (joint, reversed) that places it
        remaining = list(self.joints)
        while remaining:
            progress = False
            for j in list(remaining):
                if j["parent"] in placed and j["child"] not in placed:
                    child, parent, rev = j["child"], j["parent"], False
                elif j["child"] in placed and j["parent"] not in placed:
                    child, parent, rev = j["parent"], j["child"], True
                else:
                    continue
                placed.add(child)
                self.tree.append((j, rev))
                self.tree_parent[child] = parent
                self.tree_edge[child] = (j, rev)
                remaining.remove(j)
                progress = True
            if not progress:
                raise ValueError("joints do not form a tree: %s" % [j["name"] for j in remaining])

    # --- coordinate values -------------------------------------------------------------------

    def default_value(self, name):
        v = self.coords[name]["default"]
        return 0.0 if abs(v) < EPS_ZERO else v

    def coordinate_values(self, independent):
        """All coordinate values from the model's independent ones: couplers (enforced
        CoordinateCouplerConstraint: q_dep = f(q_indep)), welded arms, locked defaults."""
        values = {}
        for name in self.coords:
            if name in independent:
                values[name] = independent[name]
            elif name in self.arm_pose:
                values[name] = self.arm_pose[name]
            else:
                values[name] = self.default_value(name)
        for dep, (indep, fn, scale) in self.couplers.items():
            values[dep] = scale * fn(values[indep])
        return values

    # --- CustomJoint kinematics -------------------------------------------------------------

    @staticmethod
    def joint_transform(joint, values):
        """X_FM of a CustomJoint SpatialTransform (OpenSim SpatialTransform /
        Simbody MobilizedBody::FunctionBased): R_FM = R(axis1,f1) R(axis2,f2) R(axis3,f3), each
        rotation about the axis of the frame produced by the previous ones (body-fixed), and
        p_FM = sum f_i axis_i of the three translations, expressed in F."""
        r = IDENTITY
        for ax in joint["rotations"]:
            q = values[ax["coordinate"]] if ax["coordinate"] else 0.0
            r = mat_mul(r, axis_angle(ax["axis"], ax["function"](q)))
        p = [0.0, 0.0, 0.0]
        for ax in joint["translations"]:
            q = values[ax["coordinate"]] if ax["coordinate"] else 0.0
            p = vec_add(p, vec_scale(ax["axis"], ax["function"](q)))
        return (r, p)

    def pose_state(self, independent):
        """(all coordinate values, body transforms) of a pose, memoised by pose."""
        key = tuple(sorted(independent.items()))
        if key not in self._memo:
            if len(self._memo) > 20000:
                self._memo.clear()
            values = self.coordinate_values(independent)
            self._memo[key] = (values, self.body_transforms(values))
        return self._memo[key]

    def body_transforms(self, values):
        """X_G,B of every body (OpenSim ground frame, Y up)."""
        x = {"ground": TF_IDENTITY}
        for j, rev in self.tree:
            xfm = self.joint_transform(j, values)
            if not rev:
                x_gf = tf_mul(x[j["parent"]], j["parent_offset"])
                x[j["child"]] = tf_mul(tf_mul(x_gf, xfm), tf_inv(j["child_offset"]))
            else:
                x_gm = tf_mul(x[j["child"]], j["child_offset"])
                x[j["parent"]] = tf_mul(tf_mul(x_gm, tf_inv(xfm)), tf_inv(j["parent_offset"]))
        return x


# ------------------------------------------------------------------------------------------------
# muscle paths without wrapping (reference geometry)
# ------------------------------------------------------------------------------------------------

def wrap_objects(model):
    """{wrap object name: (body, wrap object)} over every body of the model."""
    return {w["name"]: (b, w) for b in model.body_order for w in model.bodies[b]["wraps"]}


def relocated_body(body):
    """Patella bodies follow the knee through coupler constraints that make them rigid with the
    tibia (patfem_flexion = knee_flexion + 1.57 about the same femoral axis, other patfem
    coordinates locked): they become jointless children of the tibia-side body, returned here
    (None for every other body, whose MJCF frame is the .osim's)."""
    return {"patella": "tibial_tray", "patella_l": "tibia_l"}.get(body)


def fitted_part_names(muscle, k):
    """Geom, side-site and via-site names of the k-th part of a muscle's fitted wrap
    (scripts/fit_wraps.py): <muscle>_wrap, _wrap_side, <muscle>_via for the first part, then
    with the part's number (_wrap3, _via2, ...)."""
    tag = "" if k == 0 else str(k + 1)
    return ("%s_wrap%s" % (muscle, tag), "%s_wrap%s_side" % (muscle, tag),
            "%s_via%s" % (muscle, tag))


def point_is_active(pt, values):
    """ConditionalPathPoint: active while range[0] <= q <= range[1] (OpenSim ConditionalPathPoint)."""
    if pt["type"] != "ConditionalPathPoint":
        return True
    q = values[pt["coordinate"]]
    return pt["range"][0] <= q <= pt["range"][1]


def point_location(pt, values):
    """Location in the point's body frame; MovingPathPoint: (fx(qx), fy(qy), fz(qz))."""
    if pt["type"] == "MovingPathPoint":
        return [fn(values[c]) for fn, c in zip(pt["functions"], pt["coords"])]
    return pt["location"]


def path_length(model, muscle, independent):
    values, x = model.pose_state(independent)
    pts = [tf_point(x[p["body"]], point_location(p, values))
           for p in muscle["points"] if point_is_active(p, values)]
    return sum(vec_norm(vec_sub(pts[i + 1], pts[i])) for i in range(len(pts) - 1))


def wrap_clearance(model, muscle, independent):
    """Smallest clearance of the straight-segment path from the muscle's wrap objects at a pose:
    over every PathWrap and every segment within its point range, the distance of the segment
    from the object's centre in the object's normalised frame (ellipsoid: divided by the semi-axes;
    cylinder: radial only, as if infinitely long; sphere: by the radius). Below 1 the straight
    path penetrates the object, so OpenSim wraps and the no-wrap reference is not its path. A
    segment on the wrong side of a constrained quadrant counts as penetrating (OpenSim wraps it
    onto the quadrant). Returns None for a muscle without wrap objects."""
    if not muscle["wraps"]:
        return None
    values, x = model.pose_state(independent)
    objects = wrap_objects(model)
    pts = [(i, tf_point(x[p["body"]], point_location(p, values)))
           for i, p in enumerate(muscle["points"]) if point_is_active(p, values)]
    best = float("inf")
    for pw in muscle["wraps"]:
        body, w = objects[pw["object"]]
        rot, org = tf_mul(x[body], (w["rotation"], w["translation"]))
        if w["type"] == "WrapEllipsoid":
            scale = w["dimensions"]
        else:
            scale = [w["radius"]] * 3
        quad = quadrant_direction(w)
        lo, hi = pw["range"]
        for s in range(len(pts) - 1):
            (i0, a), (i1, b) = pts[s], pts[s + 1]
            if lo > 0 and not (i0 + 1 >= lo and i1 + 1 <= hi):
                continue
            la = mat_vec(mat_t(rot), vec_sub(a, org))
            lb = mat_vec(mat_t(rot), vec_sub(b, org))
            if w["type"] == "WrapCylinder":
                la[2] = lb[2] = 0.0
            la = [la[k] / scale[k] for k in range(3)]
            lb = [lb[k] / scale[k] for k in range(3)]
            ab = vec_sub(lb, la)
            t = max(0.0, min(1.0, -sum(la[k] * ab[k] for k in range(3))
                             / max(1e-12, sum(v * v for v in ab))))
            near = vec_add(la, vec_scale(ab, t))
            dist = vec_norm(near)
            if quad is not None and sum(near[k] * quad[k] for k in range(3)) < 0.0:
                dist = min(dist, 0.0)
            best = min(best, dist)
    return best


def crossed_coordinates(model, muscle):
    """Model coordinates of the joints between the bodies the path attaches to."""
    def chain(body):
        out = []
        while body != "ground":
            out.append(body)
            body = model.tree_parent[body]
        return out
    chains = [chain(p["body"]) for p in muscle["points"]]
    common = set(chains[0])
    for c in chains[1:]:
        common &= set(c)
    bodies = set()
    for c in chains:
        bodies |= set(c) - common
    names = set()
    for b in bodies:
        j, _ = model.tree_edge[b]
        for ax in j["rotations"] + j["translations"]:
            if ax["coordinate"] in MODEL_COORDINATES:
                names.add(ax["coordinate"])
        # coupled coordinates move with their independent coordinate
        for ax in j["rotations"] + j["translations"]:
            if ax["coordinate"] in model.couplers:
                indep = model.couplers[ax["coordinate"]][0]
                if indep in MODEL_COORDINATES:
                    names.add(indep)
    return [c for c in MODEL_COORDINATES if c in names]


def moment_arms(model, muscle, pose, coordinates):
    """r = -dL/dq by central differences (h = FD_STEP)."""
    out = {}
    for c in coordinates:
        lo, hi = dict(pose), dict(pose)
        lo[c] -= FD_STEP
        hi[c] += FD_STEP
        out[c] = -(path_length(model, muscle, hi) - path_length(model, muscle, lo)) / (2 * FD_STEP)
    return out


# ------------------------------------------------------------------------------------------------
# OpenSim wrapping (reference only; the MJCF uses MuJoCo's own wrapping, wrap_geom_spec)
#
# A port of OpenSim 4's path wrapping (opensim-org/opensim-core, Apache-2.0, Peter Loan / SIMM):
# GeometryPath::applyWrapObjects (order of PathWraps, point range, segment choice, iteration),
# WrapObject::wrapPathSegment (frames), WrapEllipsoid::wrapLine (hybrid/midpoint wrapping plane,
# calcTangentPoint, CalcDistanceOnEllipsoid, findClosestPoint / closestPointToEllipse after
# Eberly, Graphics Gems IV) and WrapCylinder::wrapLine (quadrant/active-side rule, tangent-point
# candidates, far-side and long wraps, display-length rule). Deliberate differences, all so that
# central differences of the length (h = FD_STEP) are smooth (mjmodels/README.md, "Wrapped
# reference"): the tangent-point and closest-point iterations are polished to machine precision
# (OpenSim stops at ssq < 1e-8 resp. |f| < 1e-9); the ellipsoid arc is summed over
# WRAP_ARC_SEGMENTS chords instead of 1-mm chords; the cylinder's spiral is the exact geodesic
# (straight in the developed surface: the limit of OpenSim's _adjust_tangent_point iteration,
# which stops at 0.1 deg); several PathWraps are iterated to a fixed point (|dL| < WRAP_ITER_TOL)
# instead of stopping at 0.5 mm. WrapSphere and WrapTorus are not used by JW's model and not
# implemented (an error names them).
# ------------------------------------------------------------------------------------------------

WRAP_NO, WRAP_INSIDE, WRAP_WRAPPED, WRAP_MANDATORY = 0, 1, 2, 3   # OpenSim WrapObject::WrapAction
WRAP_ARC_SEGMENTS = 400      # chords of the ellipsoid arc (OpenSim: 1 mm each, at most 499)
WRAP_ITER_TOL = 1e-12        # fixed-point tolerance of several PathWraps (m; OpenSim 0.0005)
WRAP_ITER_MAX = 60           # iterations at most (OpenSim 8)
ELL_MU_BLEND_MIN = 0.7073    # WrapEllipsoid.cpp MU_BLEND_MIN (100 % fan)
ELL_MU_BLEND_MAX = 0.9       # MU_BLEND_MAX (100 % Frans)
ELL_FAN_SAMPLES = 300        # NUM_FAN_SAMPLES
ELL_SV_BOUNDARY_BLEND = 0.3  # SV_BOUNDARY_BLEND
ROUNDOFF_ERROR = 2e-13       # SimmMacros.h EQUAL_WITHIN_ERROR


def dot3(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross3(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit_or_zero(a):
    n = vec_norm(a)
    return [x / n for x in a] if n > 0.0 else [0.0, 0.0, 0.0]


def dsign(x):
    return 1 if x >= 0.0 else -1


def solve_linear(a, b):
    """Solve a x = b (Gaussian elimination with partial pivoting, small dense systems)."""
    n = len(b)
    m = [list(a[i]) + [b[i]] for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        if m[c][c] == 0.0:
            raise ZeroDivisionError("singular system")
        for r in range(c + 1, n):
            f = m[r][c] / m[c][c]
            for k in range(c, n + 1):
                m[r][k] -= f * m[c][k]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        x[r] = (m[r][n] - sum(m[r][k] * x[k] for k in range(r + 1, n))) / m[r][r]
    return x


def wrap_quadrant(w):
    """(wrap axis, wrap sign) of OpenSim's quadrant (WrapObject::extendFinalizeFromProperties);
    sign 0 for 'all'."""
    d = quadrant_direction(w)
    if d is None:
        return 0, 0
    k = [i for i in range(3) if d[i] != 0.0][0]
    return k, int(d[k])


def closest_point_to_ellipse(a, b, u, v):
    """WrapEllipsoid::closestPointToEllipse (Eberly): point (x, y) of (x/a)^2 + (y/b)^2 = 1
    closest to (u, v)."""
    a2, b2 = a * a, b * b
    a2u2, b2v2 = a2 * u * u, b2 * v * v
    near_x, near_y = abs(u) <= ROUNDOFF_ERROR, abs(v) <= ROUNDOFF_ERROR
    if near_x and near_y:
        return ((-a if u < 0.0 else a), v) if a < b else (u, (-b if v < 0.0 else b))
    if near_x:
        if a >= b or abs(v) >= b - a2 / b:
            return u, (b if v >= 0 else -b)
        y = b2 * v / (b2 - a2)
        return a * math.sqrt(abs(1 - (y / b) ** 2)), y
    if near_y:
        if b >= a or abs(u) >= a - b2 / a:
            return (a if u >= 0 else -a), v
        x = a2 * u / (a2 - b2)
        return x, b * math.sqrt(abs(1 - (x / a) ** 2))
    t = 0.0 if (u / a) ** 2 + (v / b) ** 2 < 1.0 else max(a, b) * math.sqrt(u * u + v * v)
    extra = 0
    for _ in range(64 + 3):
        p, q = t + a2, t + b2
        f = p * p * q * q - a2u2 * q * q - b2v2 * p * p
        if abs(f) < 1e-9:
            extra += 1          # polish: a few Newton steps past OpenSim's stopping test
            if extra > 3:
                break
        fp = 2.0 * (p * q * (p + q) - a2u2 * q - b2v2 * p)
        if fp == 0.0:
            break
        t -= f / fp
    p, q = t + a2, t + b2
    return a2 * u / p, b2 * v / q


def ellipsoid_closest_point(a, pt, special=-1):
    """WrapEllipsoid::findClosestPoint: point of the ellipsoid with semi-axes a (centred, axis
    aligned) closest to pt; near a coordinate plane (or with special = that axis) the 2-d
    cross-section is used."""
    u = list(pt)
    if special < 0:
        best = float("inf")
        for i in range(3):
            if abs(u[i]) <= ROUNDOFF_ERROR:
                s = sum(a[j] for j in range(3) if j != i)
                if best > s:
                    special, best = i, s
    if special == 0:
        y, z = closest_point_to_ellipse(a[1], a[2], u[1], u[2])
        return [u[0], y, z]
    if special == 1:
        z, x = closest_point_to_ellipse(a[2], a[0], u[2], u[0])
        return [x, u[1], z]
    if special == 2:
        x, y = closest_point_to_ellipse(a[0], a[1], u[0], u[1])
        return [x, y, u[2]]
    a2 = [x * x for x in a]
    c = [a2[i] * u[i] * u[i] for i in range(3)]
    if sum((u[i] / a[i]) ** 2 for i in range(3)) < 1.0:
        t = 0.0
    else:
        t = max(a) * vec_norm(u)
    extra = 0
    for _ in range(64 + 3):
        p, q, r = t + a2[0], t + a2[1], t + a2[2]
        f = (p * p * q * q * r * r - c[0] * q * q * r * r - c[1] * p * p * r * r
             - c[2] * p * p * q * q)
        if abs(f) < 1e-9:
            extra += 1
            if extra > 3:
                break
        fp = 2.0 * (p * q * r * (q * r + p * r + p * q) - c[0] * q * r * (q + r)
                    - c[1] * p * r * (p + r) - c[2] * p * q * (p + q))
        if fp == 0.0:
            break
        t -= f / fp
    return [a2[i] * u[i] / (t + a2[i]) for i in range(3)]


def ellipsoid_tangent_point(pe, r, p, a, vs, vs4):
    """WrapEllipsoid::calcTangentPoint: move r (start: c1) to the point of the ellipse
    (ellipsoid a, centre 0) cut by the plane vs.x + vs4 = 0 whose tangent passes through p.
    OpenSim's damped least squares (4 unknowns r, d1; residuals: in plane, on ellipsoid, d1
    definition, p in the tangent plane), then Newton steps to machine precision."""
    if abs(pe) < 0.0001:
        return list(p)
    r = list(r)
    m = [0.0, 0.0, 0.0]

    def resid(r, d1):
        nr = [2.0 * (r[i] - m[i]) / (a[i] * a[i]) for i in range(3)]
        return [dot3(vs, r) + vs4,
                -1.0 + sum(((r[i] - m[i]) / a[i]) ** 2 for i in range(3)),
                dot3(nr, r) + d1, dot3(nr, p) + d1]

    def jac(r):
        # dedth[i][j] = d ee_j / d theta_i, theta = (r, d1)
        d = [[vs[i], 2.0 * (r[i] - m[i]) / a[i] ** 2, 2.0 * (2.0 * r[i] - m[i]) / a[i] ** 2,
              2.0 * p[i] / a[i] ** 2] for i in range(3)]
        d.append([0.0, 0.0, 1.0, 1.0])
        return d

    nr = [2.0 * (r[i] - m[i]) / (a[i] * a[i]) for i in range(3)]
    d1 = -dot3(nr, r)
    ee = resid(r, d1)
    ssqo = ssq = sum(e * e for e in ee)
    alpha = 0.01
    nit = 0
    while ssq > 1e-8 and nit < 50:
        nit += 1
        dedth = jac(r)
        p1r1 = unit_or_zero(vec_sub(p, r))
        p1m = unit_or_zero(vec_sub(p, m))
        pcos = dot3(p1r1, p1m)
        dd = 1.0 - pcos ** 100 if pcos > 0.1 else 1.0
        v = [-sum(dedth[i][j] * ee[j] for j in range(4)) for i in range(4)]
        d2 = [[sum(dedth[i][k] * dedth[j][k] for k in range(4)) for j in range(4)]
              for i in range(4)]
        diag = [d2[i][i] for i in range(4)]
        vt = [0.0] * 4
        nit2 = 0
        while ssq >= ssqo and nit2 < 1000:
            for i in range(4):
                d2[i][i] = diag[i] * (1.0 + alpha)
            step = solve_linear(d2, v)
            vt = [dd * s / 16.0 for s in step]
            r = [r[i] + vt[i] for i in range(3)]
            d1 += vt[3]
            ee = resid(r, d1)
            ssqo = ssq
            ssq = sum(e * e for e in ee)
            alpha *= 4.0
            nit2 += 1
        alpha /= 8.0
        fakt = 0.5
        nit2 = 0
        while ssq <= ssqo and nit2 < 1000:
            fakt *= 2.0
            r = [r[i] + vt[i] * fakt for i in range(3)]
            d1 += vt[3] * fakt
            ee = resid(r, d1)
            ssqo = ssq
            ssq = sum(e * e for e in ee)
            nit2 += 1
        r = [r[i] - vt[i] * fakt for i in range(3)]
        d1 -= vt[3] * fakt
        ee = resid(r, d1)
        ssq = ssqo = sum(e * e for e in ee)
    # polish (not in OpenSim): Newton on the same 4 equations
    for _ in range(30):
        dedth = jac(r)
        j = [[dedth[i][k] for i in range(4)] for k in range(4)]
        try:
            step = solve_linear(j, [-e for e in ee])
        except ZeroDivisionError:
            break
        r = [r[i] + step[i] for i in range(3)]
        d1 += step[3]
        ee = resid(r, d1)
        if max(abs(s) for s in step) < 1e-15:
            break
    return r


def ellipsoid_arc(r1, r2, a, vs, vs4, far_side):
    """WrapEllipsoid::CalcDistanceOnEllipsoid: the curve where the wrapping plane cuts the
    ellipsoid, from r1 to r2 (the short way, or the long way if far_side), sampled at equal
    angles about the point a0 where the plane meets the axis most normal to it. Returns (points
    r1 .. r2, polyline length) in normalised units; WRAP_ARC_SEGMENTS chords."""
    n = WRAP_ARC_SEGMENTS
    imax = 0
    for i in (1, 2):
        if abs(vs[i]) > abs(vs[imax]):
            imax = i
    u = [0.0, 0.0, 0.0]
    u[imax] = 1.0
    mu = -vs4 / dot3(vs, u)
    a0 = vec_scale(u, mu)
    ar1 = unit_or_zero(vec_sub(r1, a0))
    ar2 = unit_or_zero(vec_sub(r2, a0))
    phi0 = math.acos(max(-1.0, min(1.0, dot3(ar1, ar2))))
    dphi = -(2.0 * math.pi - phi0) / n if far_side else phi0 / n
    vsz = unit_or_zero(cross3(ar1, ar2))
    vsy = cross3(vsz, ar1)
    pts = [list(r1)]
    f2 = [a0[i] / a[i] for i in range(3)]
    cc = dot3(f2, f2) - 1.0
    for i in range(n - 1):
        phi = (i + 1) * dphi
        r = [math.cos(phi) * ar1[k] + math.sin(phi) * vsy[k] for k in range(3)]
        f1 = [r[k] / a[k] for k in range(3)]
        aa, bb = dot3(f1, f1), 2.0 * dot3(f1, f2)
        mu3 = (-bb + math.sqrt(max(0.0, bb * bb - 4.0 * aa * cc))) / (2.0 * aa)
        pts.append([a0[k] + mu3 * r[k] for k in range(3)])
    pts.append(list(r2))
    length = sum(vec_norm(vec_sub(pts[i + 1], pts[i])) for i in range(n))
    return pts, length


def ellipsoid_wrap_line(dims, quadrant, method, pt1, pt2):
    """WrapEllipsoid::wrapLine for the segment pt1-pt2 (wrap-object frame). Returns
    (WrapAction, r1, r2, wrap length) with r1, r2 in the wrap-object frame."""
    factor = 3.0 / sum(dims)
    p1 = vec_scale(pt1, factor)
    p2 = vec_scale(pt2, factor)
    a = vec_scale(dims, factor)
    m = [0.0, 0.0, 0.0]
    p1e = -1.0 + sum((p1[i] / a[i]) ** 2 for i in range(3))
    p2e = -1.0 + sum((p2[i] / a[i]) ** 2 for i in range(3))
    if p1e < -0.0001 or p2e < -0.0001:
        return WRAP_INSIDE, None, None, 0.0
    p1p2 = vec_sub(p1, p2)
    ppm = dot3(unit_or_zero(p1), unit_or_zero(p2)) - 1.0
    if abs(ppm) < 0.0001:
        return WRAP_NO, None, None, 0.0
    f1 = [p1p2[i] / a[i] for i in range(3)]
    f2 = [p2[i] / a[i] for i in range(3)]
    aa, bb, cc = dot3(f1, f1), 2.0 * dot3(f1, f2), dot3(f2, f2) - 1.0
    disc = bb * bb - 4.0 * aa * cc
    if disc < 0.0:
        return WRAP_NO, None, None, 0.0
    l1 = (-bb + math.sqrt(disc)) / (2.0 * aa)
    l2 = (-bb - math.sqrt(disc)) / (2.0 * aa)
    if not (0.0 < l1 < 1.0) or not (0.0 < l2 < 1.0):
        return WRAP_NO, None, None, 0.0
    r1 = vec_add(p2, vec_scale(p1p2, l1))
    r2 = vec_add(p2, vec_scale(p1p2, l2))
    r1r2 = vec_sub(r2, r1)
    # wrapping plane: Frans technique (most parallel axis) and/or fan (WrapEllipsoid.cpp)
    mu = [abs(x) for x in unit_or_zero(p1p2)]
    t, t_sv, t_c1 = [0.0] * 3, [None] * 3, [None] * 3
    for i in range(3):
        t[i] = (m[i] - r1[i]) / r1r2[i] if r1r2[i] != 0.0 else float("inf")
        t_sv[i] = [r1[j] + t[i] * r1r2[j] for j in range(3)] if r1r2[i] != 0.0 else list(r1)
        t_c1[i] = ellipsoid_closest_point(a, t_sv[i], i)
    best = 0
    for i in (1, 2):
        if mu[i] > mu[best]:
            best = i
    fan_weight = -float("inf")
    c1 = sv = None
    if method in ("hybrid", "axial"):
        if method == "hybrid" and mu[best] > ELL_MU_BLEND_MIN:
            s = 1.0
            if t[best] < 0.0 or t[best] > 1.0:
                s = 0.0
            elif t[best] < ELL_SV_BOUNDARY_BLEND:
                s = t[best] / ELL_SV_BOUNDARY_BLEND
            elif t[best] > 1.0 - ELL_SV_BOUNDARY_BLEND:
                s = (1.0 - t[best]) / ELL_SV_BOUNDARY_BLEND
            if s < 1.0:
                mu[best] = ELL_MU_BLEND_MIN + s * (mu[best] - ELL_MU_BLEND_MIN)
        if method == "axial" or mu[best] > ELL_MU_BLEND_MIN:
            c1, sv = list(t_c1[best]), list(t_sv[best])
        if method == "hybrid" and mu[best] < ELL_MU_BLEND_MAX:
            v_sum = [0.0, 0.0, 0.0]
            mid = [r1[i] + 0.5 * r1r2[i] for i in range(3)]
            for i in range(1, ELL_FAN_SAMPLES - 1):
                tt = float(i) / ELL_FAN_SAMPLES
                s0 = [r1[j] + tt * r1r2[j] for j in range(3)]
                c0 = ellipsoid_closest_point(a, s0)
                v_sum = vec_add(v_sum, unit_or_zero(vec_sub(c0, s0)))
            v_sum = unit_or_zero(v_sum)
            tc = vec_add(mid, v_sum)
            if mu[best] <= ELL_MU_BLEND_MIN:
                c1 = ellipsoid_closest_point(a, tc)
                sv = mid
                fan_weight = 1.0
            else:
                tt = (mu[best] - ELL_MU_BLEND_MIN) / (ELL_MU_BLEND_MAX - ELL_MU_BLEND_MIN)
                cf = ellipsoid_closest_point(a, tc)
                blend = [tt * c1[i] + (1.0 - tt) * cf[i] for i in range(3)]
                sv = [tt * sv[i] + (1.0 - tt) * mid[i] for i in range(3)]
                c1 = ellipsoid_closest_point(a, blend)
                fan_weight = 1.0 - tt
    elif method == "midpoint":
        sv = [r1[i] + 0.5 * (r2[i] - r1[i]) for i in range(3)]
        c1 = ellipsoid_closest_point(a, sv)
    else:
        raise ValueError("PathWrap method %s not implemented" % method)
    if method != "axial" or 0.0 < t[best] < 1.0:
        r1, r2 = list(c1), list(c1)
    axis, sign = quadrant
    if sign != 0 and dsign(c1[axis] - m[axis]) != sign:
        orig = list(c1)
        c1[axis] = -c1[axis]
        r1, r2 = list(c1), list(c1)
        if fan_weight == -float("inf"):
            fan_weight = 1.0 - (mu[best] - ELL_MU_BLEND_MIN) / (ELL_MU_BLEND_MAX - ELL_MU_BLEND_MIN)
        fan_weight = min(fan_weight, 1.0)
        if fan_weight > 0.0:
            bis = 0.5 * (orig[axis] + c1[axis])
            c1[axis] = c1[axis] + fan_weight * (bis - c1[axis])
            c1 = ellipsoid_closest_point(a, c1)
    vs = unit_or_zero(cross3(p1p2, vec_sub(p1, c1)))
    vs4 = -dot3(vs, c1)
    r1 = ellipsoid_tangent_point(p1e, r1, p1, a, vs, vs4)
    r2 = ellipsoid_tangent_point(p2e, r2, p2, a, vs, vs4)
    far_side = False
    while True:
        pts, length = ellipsoid_arc(r1, r2, a, vs, vs4, far_side)
        if sign != 0 and len(pts) > 2 and not far_side:
            r1p1 = unit_or_zero(vec_sub(p1, r1))
            r1w1 = unit_or_zero(vec_sub(pts[1], r1))
            r2p2 = unit_or_zero(vec_sub(p2, r2))
            r2w2 = unit_or_zero(vec_sub(pts[-2], r2))
            if dot3(r1p1, r1w1) > 0.0 or dot3(r2p2, r2w2) > 0.0:
                far_side = True
                continue
        break
    return (WRAP_MANDATORY, vec_scale(r1, 1.0 / factor), vec_scale(r2, 1.0 / factor),
            length / factor)


def closest_on_axis(p):
    """Closest point to p on the cylinder axis (local z) and the distance to it."""
    return [0.0, 0.0, p[2]], math.hypot(p[0], p[1])


def intersect_lines(p1, p2, p3, p4):
    """WrapMath::IntersectLines: closest points of lines p1p2 and p3p4 and their parameters
    (fractions of p1p2 and p3p4); None if parallel."""
    v1, v2 = vec_sub(p2, p1), vec_sub(p4, p3)
    mag1, mag2 = vec_norm(v1), vec_norm(v2)
    v1, v2 = vec_scale(v1, 1.0 / mag1), vec_scale(v2, 1.0 / mag2)
    cp = cross3(v1, v2)
    denom = dot3(cp, cp)
    if abs(denom) <= ROUNDOFF_ERROR:
        return None

    def det(r0, r1, r2):
        return (r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) - r0[1] * (r1[0] * r2[2] - r1[2] * r2[0])
                + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0]))
    d31 = vec_sub(p3, p1)
    t = det(d31, v1, cp) / denom
    s = det(d31, v2, cp) / denom
    return vec_add(p1, vec_scale(v1, s)), s / mag1, vec_add(p3, vec_scale(v2, t)), t / mag2


def cylinder_wrap_line(radius, length, quadrant, pt1, pt2):
    """WrapCylinder::wrapLine for the segment pt1-pt2 (wrap-object frame, axis z). OpenSim's
    decisions (inside, miss, mandatory/wrapped, active side, tangent-point candidates, long
    wrap, display length) are ported; the spiral is the exact geodesic: developed into the
    plane, P1 - r1 - spiral - r2 - P2 is one straight line, so with d1, d2 the tangent lengths
    in the cross-section and theta the angle between the chosen tangent points the path is
    sqrt((d1 + R theta + d2)^2 + dz^2) (the limit of OpenSim's _adjust_tangent_point loop).
    Returns (WrapAction, r1, r2, wrap length)."""
    dn = [0.0, 0.0, 1.0]
    r2sq = radius * radius
    axis, sign = quadrant
    constrained = sign != 0
    p11, rho1 = closest_on_axis(pt1)
    p22, rho2 = closest_on_axis(pt2)
    if rho1 * rho1 < r2sq or rho2 * rho2 < r2sq:
        return WRAP_INSIDE, None, None, 0.0
    hit = intersect_lines(pt1, pt2, [0.0, 0.0, -0.5 * length], [0.0, 0.0, 0.5 * length])
    if hit is None:
        return WRAP_NO, None, None, 0.0
    near12, t12, near00, _ = hit
    d_sq = sum((near12[i] - near00[i]) ** 2 for i in range(3))
    code = WRAP_WRAPPED
    if not constrained:
        if d_sq < r2sq and 0.0 < t12 < 1.0:
            code = WRAP_MANDATORY
        else:
            return WRAP_NO, None, None, 0.0

    def candidates(p, pax, rho):
        vv = vec_scale(vec_sub(p, pax), 1.0 / rho)
        dist = radius * radius / rho
        pp = vec_add(pax, vec_scale(vv, dist))
        dist = math.sqrt(r2sq - dist * dist)
        uu = cross3(dn, vv)
        return vec_add(pp, vec_scale(uu, dist)), vec_sub(pp, vec_scale(uu, dist))
    r1a, r1b = candidates(pt1, p11, rho1)
    r2a, r2b = candidates(pt2, p22, rho2)
    far_side = long_wrap = False
    if constrained:
        if dsign(pt1[axis]) == sign or dsign(pt2[axis]) == sign:
            if d_sq < r2sq and 0.0 < t12 < 1.0:
                code = WRAP_MANDATORY
            elif dsign(pt1[axis]) != dsign(pt2[axis]) and dsign(near12[axis]) != sign:
                code = WRAP_WRAPPED
            else:
                return WRAP_NO, None, None, 0.0
        r1am, r1bm = vec_sub(r1a, p11), vec_sub(r1b, p11)
        r2am, r2bm = vec_sub(r2a, p22), vec_sub(r2b, p22)

        def ang(u, v):
            return math.acos(max(-1.0, min(1.0, dot3(u, v) / (vec_norm(u) * vec_norm(v)))))
        alpha, beta = ang(r1am, r2bm), ang(r1bm, r2am)
        on = [dsign(r[axis]) == sign for r in (r1a, r1b, r2a, r2b)]
        if on[0] and on[1]:
            if on[2]:
                r1, r2, far_side = r1b, r2a, not alpha > beta
            else:
                r1, r2, far_side = r1a, r2b, alpha > beta
        elif on[0] and not on[1]:
            r1, r2, far_side = r1a, r2b, alpha > beta
        elif not on[0] and on[1]:
            r1, r2, far_side = r1b, r2a, not alpha > beta
        else:
            if on[2]:
                r1, r2, far_side = r1b, r2a, not alpha > beta
            elif on[3]:
                r1, r2, far_side = r1a, r2b, alpha > beta
            elif alpha > beta:
                r1, r2, far_side = r1a, r2b, True
            else:
                r1, r2, far_side = r1b, r2a, True
        sum_musc = [(r1[i] - pt1[i]) + (r2[i] - pt2[i]) for i in range(3)]
        sum_r = [(r1[i] - p11[i]) + (r2[i] - p22[i]) for i in range(3)]
        long_wrap = dot3(sum_r, sum_musc) < 0.0
    else:
        n1a = unit_or_zero(vec_sub(r1a, p11))
        n1b = unit_or_zero(vec_sub(r1b, p11))
        n2a = unit_or_zero(vec_sub(r2a, p22))
        n2b = unit_or_zero(vec_sub(r2b, p22))
        d1, d2, d3, d4 = dot3(n1a, n2a), dot3(n1a, n2b), dot3(n1b, n2a), dot3(n1b, n2b)
        if d1 > d2 and d1 > d3 and d1 > d4:
            r1, r2 = r1a, r2a
        elif d2 > d3 and d2 > d4:
            r1, r2 = r1a, r2b
        elif d3 > d4:
            r1, r2 = r1b, r2a
        else:
            r1, r2 = r1b, r2b
    # OpenSim's preliminary axial placement (apex plane), used only for the display-length rule
    uu = vec_sub(r1, p11)
    vv = unit_or_zero(vec_add(uu, vec_sub(r2, p22)))
    tt = rho1 / (rho1 + rho2)
    mpt = vec_add(pt1, vec_scale(vec_sub(pt2, pt1), tt))
    axispt = [0.0, 0.0, mpt[2]]
    l1 = unit_or_zero(vec_sub(pt1, axispt))
    l2 = unit_or_zero(vec_sub(pt2, axispt))
    normal = unit_or_zero(cross3(l1, l2))
    vert1 = unit_or_zero(cross3(dn, normal))
    vert2 = unit_or_zero(cross3(normal, dn))
    apex1 = vec_add(axispt, vec_scale(vert1, radius))
    apex2 = vec_add(axispt, vec_scale(vert2, radius))
    dist1 = sum((mpt[i] - apex1[i]) ** 2 for i in range(3))
    dist2 = sum((mpt[i] - apex2[i]) ** 2 for i in range(3))
    if far_side:
        apex = apex2 if dist1 < dist2 else apex1
    else:
        apex = apex1 if dist1 < dist2 else apex2
    normal = cross3(unit_or_zero(vec_sub(pt1, apex)), unit_or_zero(vec_sub(pt2, apex)))
    normal = unit_or_zero(normal)
    dpl = -dot3(pt1, normal)
    pre = []
    for r, pax_far, pax_near in ((r1, p22, p11), (r2, p11, p22)):
        lo, hi = vec_sub(r, vec_scale(dn, 10.0)), vec_add(r, vec_scale(dn, 10.0))
        vec = vec_sub(hi, lo)
        dp = dot3(vec, normal)
        z = r[2]
        if abs(dp) >= 1e-5:
            tp = (-dpl - dot3(normal, lo)) / dp
            if -1e-5 <= tp <= 1.0 + 1e-5:
                rp = vec_add(lo, vec_scale(vec, tp))
                # keep the plane point if it projects between p11 and p22 (OpenSim's test)
                seg = vec_sub(pax_far, pax_near)
                seg_len2 = dot3(seg, seg)
                if seg_len2 > 0.0:
                    s = dot3(vec_sub(rp, pax_near), seg) / seg_len2
                    proj = vec_add(pax_near, vec_scale(seg, s))
                    if (sum((proj[i] - pax_far[i]) ** 2 for i in range(3))
                            < seg_len2):
                        z = rp[2]
        pre.append(z)
    half = 0.5 * length
    if (pre[0] < -half or pre[0] > half) and (pre[1] < -half or pre[1] > half):
        return WRAP_NO, None, None, 0.0
    # exact geodesic with the chosen tangent points and sense
    theta = math.acos(max(-1.0, min(1.0, dot3(unit_or_zero([r1[0], r1[1], 0.0]),
                                                unit_or_zero([r2[0], r2[1], 0.0])))))
    if long_wrap:
        theta = 2.0 * math.pi - theta
    d1 = math.sqrt(max(0.0, rho1 * rho1 - r2sq))
    d2 = math.sqrt(max(0.0, rho2 * rho2 - r2sq))
    s_total = d1 + radius * theta + d2
    dz = pt2[2] - pt1[2]
    z1 = pt1[2] + dz * d1 / s_total
    z2 = pt1[2] + dz * (d1 + radius * theta) / s_total
    wrap_len = math.hypot(radius * theta, z2 - z1)
    return code, [r1[0], r1[1], z1], [r2[0], r2[1], z2], wrap_len


def wrap_line(w, method, pt1, pt2):
    if w["type"] == "WrapEllipsoid":
        return ellipsoid_wrap_line(w["dimensions"], wrap_quadrant(w), method, pt1, pt2)
    if w["type"] == "WrapCylinder":
        return cylinder_wrap_line(w["radius"], w["length"], wrap_quadrant(w), pt1, pt2)
    raise ValueError("wrap object type %s is not implemented in the reference" % w["type"])


def read_wrap_methods(osim_path):
    """{muscle name: [PathWrap method, in PathWrapSet order]} (hybrid, midpoint, axial; OpenSim's
    default hybrid), read from the .osim (not needed by the MJCF conversion)."""
    root = ET.parse(osim_path).getroot()
    out = {}
    for f in root.find("Model").find("ForceSet/objects"):
        out[f.get("name")] = [(w.findtext("method") or "hybrid").strip()
                              for w in f.findall("GeometryPath/PathWrapSet/objects/PathWrap")]
    return out


def wrapped_path(model, muscle, independent, methods):
    """OpenSim's wrapped path of a muscle at a pose (GeometryPath::applyWrapObjects with the
    wrap objects above). Returns (length, [names of the wrap objects the path touches])."""
    values, x = model.pose_state(independent)
    objects = wrap_objects(model)
    allpts = muscle["points"]
    active = [point_is_active(p, values) for p in allpts]
    # path nodes: [kind, wrap index or point index, body, location, wrap length]
    path = [["pt", i, p["body"], point_location(p, values), 0.0]
            for i, p in enumerate(allpts) if active[i]]
    pws = muscle["wraps"]
    if not pws:
        return path_length(model, muscle, independent), []

    def ground(node):
        return tf_point(x[node[2]], node[3])

    def same_wrap(n1, n2):
        return n1[0] != "pt" and n2[0] != "pt" and n1[1] == n2[1]

    def total(path):
        length = 0.0
        for i in range(len(path) - 1):
            if same_wrap(path[i], path[i + 1]):
                length += path[i + 1][4]
            else:
                length += vec_norm(vec_sub(ground(path[i + 1]), ground(path[i])))
        return length

    methods = methods[muscle["name"]]
    order = list(range(len(pws)))
    result = [WRAP_NO] * len(pws)
    max_iter = 1 if len(pws) < 2 else WRAP_ITER_MAX
    last = float("inf")
    for kk in range(max_iter):
        for i in range(len(pws)):
            k = order[i]
            pw = pws[k]
            body, w = objects[pw["object"]]
            frame = tf_mul(x[body], (w["rotation"], w["translation"]))
            inv = tf_inv(frame)
            path = [n for n in path if not (n[0] != "pt" and n[1] == k)]
            result[i] = WRAP_NO
            lo, hi = pw["range"]
            start = 0 if lo < 1 else lo - 1
            end = len(allpts) - 1 if hi < 1 else hi - 1
            jf = start
            while jf <= end and not active[jf]:
                jf += 1
            jr = end
            while jr >= start and not active[jr]:
                jr -= 1
            if jf > end or jr < start:
                continue
            s_idx = [n for n, node in enumerate(path) if node[0] == "pt" and node[1] == jf][0]
            e_idx = [n for n, node in enumerate(path) if node[0] == "pt" and node[1] == jr][0]
            best, min_change = None, float("inf")
            for p1 in range(s_idx, e_idx):
                n1, n2 = path[p1], path[p1 + 1]
                if same_wrap(n1, n2):
                    continue
                g1, g2 = ground(n1), ground(n2)
                code, r1, r2, wlen = wrap_line(w, methods[k], tf_point(inv, g1),
                                               tf_point(inv, g2))
                result[i] = code
                if code == WRAP_MANDATORY:
                    best = (p1, r1, r2, wlen)
                    break
                if code == WRAP_WRAPPED:
                    change = (vec_norm(vec_sub(tf_point(frame, r1), g1)) + wlen
                              + vec_norm(vec_sub(tf_point(frame, r2), g2))
                              - vec_norm(vec_sub(g2, g1)))
                    if change < min_change:
                        best, min_change = (p1, r1, r2, wlen), change
            if best is not None:
                p1, r1, r2, wlen = best
                wb = (w["rotation"], w["translation"])
                path.insert(p1 + 1, ["w1", k, body, tf_point(wb, r1), 0.0])
                path.insert(p1 + 2, ["w2", k, body, tf_point(wb, r2), wlen])
        length = total(path)
        if abs(length - last) < WRAP_ITER_TOL:
            break
        last = length
        if kk == 0 and len(pws) > 1 and result[0] == WRAP_NO and result[1] == WRAP_INSIDE:
            order[0], order[1] = 1, 0
            path = [n for n in path if not (n[0] != "pt" and n[1] == 0)]
    touched = sorted(set(pws[n[1]]["object"] for n in path if n[0] != "pt"))
    return total(path), touched


def wrapped_moment_arms(model, muscle, pose, coordinates, methods):
    """r = -dL/dq of the wrapped path by central differences (h = FD_STEP)."""
    out = {}
    for c in coordinates:
        lo, hi = dict(pose), dict(pose)
        lo[c] -= FD_STEP
        hi[c] += FD_STEP
        out[c] = -(wrapped_path(model, muscle, hi, methods)[0]
                   - wrapped_path(model, muscle, lo, methods)[0]) / (2 * FD_STEP)
    return out


# ------------------------------------------------------------------------------------------------
# trial poses (IK of ngait_og5, degrees and m)
# ------------------------------------------------------------------------------------------------

def read_heel_strikes(path):
    """Heel-strike source times (s) per foot from a prepared trial's trial.json."""
    try:
        with open(path) as f:
            t = json.load(f)
        right = t["right_heel_strike_s"]
        left = t["left_heel_strike_s"]
    except (OSError, ValueError, KeyError) as e:
        raise SystemExit("osim2mjcf: %s: no heel strikes (%s)" % (path, e))
    as_list = lambda v: [float(u) for u in (v if isinstance(v, list) else [v])]
    return {"r": as_list(right), "l": as_list(left)}


def read_ik_rows(path):
    """(column labels, rows of strings) of an IK csv, its '#' comment lines left out."""
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    return rows[0], rows[1:]


def read_trial(path):
    header, rows = read_ik_rows(path)
    frames = []
    for r in rows:
        rec = dict(zip(header, (float(v) for v in r)))
        pose = {}
        for c in MODEL_COORDINATES:
            v = rec[c]
            pose[c] = v if c in TRANSLATIONS else math.radians(v)
        frames.append((rec["time"], pose))
    return frames


def trial_arm_pose(path, start, end):
    """The welded arms' coordinates (ARM_POSE's names, rad) as the mean of the IK csv's columns
    (degrees) over its rows with start <= time <= end (s, source time): one stride of the trial,
    so the arms' mass sits where the subject carried it on average (JW's og5 stride: shoulders
    flexed about 20 deg, abducted 21-27 deg, rotated 74-87 deg, elbows 25 deg) instead of
    hanging."""
    header, rows = read_ik_rows(path)
    missing = [c for c in ARM_POSE if c not in header]
    if missing:
        raise SystemExit("osim2mjcf: %s: no column %s (needed by --arm-pose trial, the default; "
                         "--arm-pose hanging needs none)"
                         % (path, missing[0]))
    t = header.index("time")
    stride = [r for r in rows if start <= float(r[t]) <= end]
    if len(stride) < 2:
        raise SystemExit("osim2mjcf: %s: fewer than 2 rows within %.4f-%.4f s"
                         % (path, start, end))
    column = {c: header.index(c) for c in ARM_POSE}
    return {c: math.radians(sum(float(r[j]) for r in stride) / len(stride))
            for c, j in column.items()}


def reference_poses(frames):
    """Five poses spanning the right knee/hip range: the frames at 0, 20, 40, 60, 80 % of the
    trial duration, the extremes of right knee flexion and of right hip flexion (frame indices
    are written in the pose table)."""
    n = len(frames)
    idx = [int(round(k * (n - 1) / 5.0)) for k in range(5)]
    knee = [f[1]["knee_flexion"] for f in frames]
    hip = [f[1]["hip_flexion"] for f in frames]
    for extra in (knee.index(min(knee)), knee.index(max(knee)), hip.index(min(hip)),
                  hip.index(max(hip))):
        if extra not in idx:
            idx.append(extra)
    return sorted(idx)


# ------------------------------------------------------------------------------------------------
# MJCF body tree: OpenSim joint -> MuJoCo body pos/quat + joints
# ------------------------------------------------------------------------------------------------

def joint_ops(model, joint, reversed_):
    """The frame from the tree parent body to the tree child body as a product of fixed
    transforms and single-axis motions, in order. Forward: X_P,pf * Trans(p(q)) * R1 R2 R3 *
    inv(X_C,cf). Reversed: X_C,cf * inv(X_FM) * inv(X_P,pf) = X_C,cf * R3^T R2^T R1^T *
    Trans(-p(q)) * inv(X_P,pf). Motions: (kind, axis, coordinate, function, sign)."""
    ops = []
    rot = [("hinge", a["axis"], a["coordinate"], a["function"], 1.0) for a in joint["rotations"]]
    tra = [("slide", a["axis"], a["coordinate"], a["function"], 1.0)
           for a in joint["translations"]]
    if not reversed_:
        ops.append(("fixed", joint["parent_offset"]))
        ops += tra + rot
        ops.append(("fixed", tf_inv(joint["child_offset"])))
    else:
        ops.append(("fixed", joint["child_offset"]))
        ops += [(k, ax, c, f, -1.0) for (k, ax, c, f, _) in reversed(rot)]
        ops += [(k, ax, c, f, -1.0) for (k, ax, c, f, _) in tra]
        ops.append(("fixed", tf_inv(joint["parent_offset"])))
    return ops


def motion_transform(kind, axis, amount):
    if kind == "hinge":
        return tf_rot(axis_angle(axis, amount))
    return tf_trans(vec_scale(axis, amount))


def mujoco_body_frame(model, joint, reversed_, values):
    """Split the ops into MuJoCo's form B0 * J'_1(q1 - ref1) * J'_2 ...: every coordinate that is
    not a model coordinate, and each model coordinate's reference value, goes into the fixed
    part; each motion J_i is conjugated by the fixed transforms that follow it,
    J'_i = M_i^-1 J_i M_i (axis R_Mi^T a, anchor -R_Mi^T p_Mi in the body frame)."""
    seq = []   # ("fixed", tf) | ("motion", kind, axis, coordinate, slope)
    for op in joint_ops(model, joint, reversed_):
        if op[0] == "fixed":
            seq.append(op)
            continue
        kind, axis, coord, fn, sign = op
        q = values[coord] if coord else 0.0
        if coord in MODEL_COORDINATES:
            if not isinstance(fn, LinearFunction) or abs(abs(fn.a) - 1.0) > 1e-12:
                raise ValueError("model coordinate %s must map through f(q) = +-q + b" % coord)
            seq.append(("fixed", motion_transform(kind, axis, sign * fn(q))))
            seq.append(("motion", kind, vec_scale(axis, sign * fn.a), coord))
        else:
            amount = sign * fn(q)
            if abs(amount) > 0.0:
                seq.append(("fixed", motion_transform(kind, axis, amount)))
    b0 = TF_IDENTITY
    for s in seq:
        if s[0] == "fixed":
            b0 = tf_mul(b0, s[1])
    joints = []
    for i, s in enumerate(seq):
        if s[0] != "motion":
            continue
        m = TF_IDENTITY
        for t in seq[i + 1:]:
            if t[0] == "fixed":
                m = tf_mul(m, t[1])
        rt = mat_t(m[0])
        joints.append({"kind": s[1], "coordinate": s[3], "axis": mat_vec(rt, s[2]),
                       "anchor": vec_scale(mat_vec(rt, m[1]), -1.0)})
    return b0, joints


# ------------------------------------------------------------------------------------------------
# formatting
# ------------------------------------------------------------------------------------------------

def fmt(v, digits=8):
    """Shortest stable decimal for v (deterministic, no '-0')."""
    s = "%.*g" % (digits, v)
    if float(s) == 0.0:
        return "0"
    return s


def fvec(vs, digits=8):
    return " ".join(fmt(v, digits) for v in vs)


def clean_axis(a):
    return [0.0 if abs(x) < 1e-12 else x for x in a]


# ------------------------------------------------------------------------------------------------
# muscle path -> MuJoCo sites and wrap geoms
# ------------------------------------------------------------------------------------------------

def fit_moving_point(model, muscle, k, frames):
    """Fixed point in the MovingPathPoint's body that best reproduces the muscle's length and
    moment arms over the trial frames: Gauss-Newton on the 3 coordinates of the point, residuals
    = length error and moment-arm error about the point's coordinate (m)."""
    pt = muscle["points"][k]
    coord = pt["coords"][0]
    samples = frames[::6]
    # start from the mean location over the trial
    locs = []
    for _, pose in samples:
        locs.append(point_location(pt, model.coordinate_values(pose)))
    start = [sum(l[i] for l in locs) / len(locs) for i in range(3)]

    fixed = dict(muscle)
    fixed_points = list(muscle["points"])

    def make(loc):
        p = {"name": pt["name"], "type": "PathPoint", "body": pt["body"], "location": loc}
        pts = list(fixed_points)
        pts[k] = p
        f = dict(fixed)
        f["points"] = pts
        return f

    targets = []
    for _, pose in samples:
        targets.append((pose, path_length(model, muscle, pose),
                        moment_arms(model, muscle, pose, [coord])[coord]))

    def residuals(loc):
        f = make(loc)
        res = []
        for pose, l_ref, r_ref in targets:
            res.append(path_length(model, f, pose) - l_ref)
            res.append(moment_arms(model, f, pose, [coord])[coord] - r_ref)
        return res

    # Levenberg-Marquardt on (x, y); z (out of the sagittal plane) stays at its mean: the
    # length and the flexion moment arm hardly depend on it
    def cost(res):
        return sum(v * v for v in res)

    loc = list(start)
    r0 = residuals(loc)
    lam = 1e-6
    for _ in range(30):
        jac = []
        for i in range(2):
            d = list(loc)
            d[i] += 1e-6
            ri = residuals(d)
            jac.append([(ri[n] - r0[n]) / 1e-6 for n in range(len(r0))])
        a = [[sum(jac[i][n] * jac[j][n] for n in range(len(r0))) for j in range(2)]
             for i in range(2)]
        g = [-sum(jac[i][n] * r0[n] for n in range(len(r0))) for i in range(2)]
        while True:
            a00, a11 = a[0][0] * (1 + lam), a[1][1] * (1 + lam)
            det = a00 * a11 - a[0][1] * a[1][0]
            step = [(g[0] * a11 - a[0][1] * g[1]) / det, (a00 * g[1] - a[1][0] * g[0]) / det]
            trial = [loc[0] + step[0], loc[1] + step[1], loc[2]]
            rt = residuals(trial)
            if cost(rt) < cost(r0):
                loc, r0, lam = trial, rt, lam * 0.3
                break
            lam *= 10.0
            if lam > 1e6:
                return loc
        if math.hypot(step[0], step[1]) < 1e-8:
            break
    return loc


def solve3(a, b):
    det = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
           - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
           + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    out = []
    for col in range(3):
        m = [row[:] for row in a]
        for r in range(3):
            m[r][col] = b[r]
        out.append((m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                    - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                    + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) / det)
    return out


def conditional_kept(pt, frames):
    """Keep a ConditionalPathPoint if it is active in at least half of the trial frames."""
    active = sum(1 for _, pose in frames
                 if pt["range"][0] <= pose.get(pt["coordinate"], 0.0) <= pt["range"][1])
    return 2 * active >= len(frames)


def wrap_geom_spec(body, w):
    """MuJoCo wrap geom for an OpenSim wrap object. WrapCylinder -> cylinder (axis local z, as in
    OpenSim); WrapSphere -> sphere; WrapEllipsoid -> cylinder along the longest semi-axis with the
    mean of the two others as radius (sphere with the mean radius if the axes differ < 20 %)."""
    rot = w["rotation"]
    if w["type"] == "WrapCylinder":
        return {"type": "cylinder", "radius": w["radius"], "half": w["length"] / 2.0, "rot": rot}
    if w["type"] == "WrapSphere":
        return {"type": "sphere", "radius": w["radius"], "half": 0.0, "rot": rot}
    dims = w["dimensions"]
    if max(dims) < 1.2 * min(dims):
        return {"type": "sphere", "radius": sum(dims) / 3.0, "half": 0.0, "rot": rot}
    k = dims.index(max(dims))
    others = [dims[i] for i in range(3) if i != k]
    # rotate so that the cylinder's local z is the ellipsoid's axis k
    to_z = {0: [[0, 0, 1], [0, 1, 0], [-1, 0, 0]],   # columns: new x,y,z in ellipsoid frame
            1: [[1, 0, 0], [0, 0, 1], [0, -1, 0]],
            2: IDENTITY}[k]
    return {"type": "cylinder", "radius": sum(others) / 2.0, "half": dims[k],
            "rot": mat_mul(rot, to_z), "axis_index": k}


def quadrant_direction(w):
    """Unit direction (wrap-object frame) of OpenSim's quadrant, None for 'all'."""
    q = w["quadrant"].lower()
    if q in ("all", ""):
        return None
    sign = -1.0 if q.startswith("-") else 1.0
    k = "xyz".index(q[-1])
    d = [0.0, 0.0, 0.0]
    d[k] = sign
    return d


def assign_wraps(model, muscle, kept_points, x0):
    """For each PathWrap choose the path segment (between two kept points) it acts on: within the
    PathWrap's point range, the segment passing closest to the wrap centre at the default pose.
    Returns {segment index: (wrap object body, wrap object)}; one wrap per segment."""
    objects = wrap_objects(model)
    best = {}
    for pw in muscle["wraps"]:
        body, w = objects[pw["object"]]
        centre = tf_point(x0[body], w["translation"])
        lo, hi = pw["range"]
        choices = []
        for s in range(len(kept_points) - 1):
            i0, i1 = kept_points[s][0], kept_points[s + 1][0]
            if lo > 0 and not (i0 + 1 >= lo and i1 + 1 <= hi):
                continue
            a = tf_point(x0[kept_points[s][1]["body"]], kept_points[s][2])
            b = tf_point(x0[kept_points[s + 1][1]["body"]], kept_points[s + 1][2])
            ab = vec_sub(b, a)
            t = max(0.0, min(1.0, sum((centre[i] - a[i]) * ab[i] for i in range(3))
                             / max(1e-12, sum(v * v for v in ab))))
            dist = vec_norm(vec_sub(centre, vec_add(a, vec_scale(ab, t))))
            choices.append((dist, s))
        if not choices:
            continue
        dist, s = min(choices)
        if s not in best or dist < best[s][0]:
            best[s] = (dist, body, w)
    return {s: (v[1], v[2]) for s, v in best.items()}


# ------------------------------------------------------------------------------------------------
# the converter
# ------------------------------------------------------------------------------------------------

def read_metabolic(path):
    """Each muscle's slow-twitch fibre fraction (-) from the 3dpredictsim table. Its
    specific_tension_MPa column is not read: the metabolic mass takes LEG_SPECIFIC_TENSION and
    TRUNK_SPECIFIC_TENSION instead (mjmodels/README.md, "The leg muscles' specific tension")."""
    out = {}
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    for r in rows:
        out[r["muscle"]] = float(r["pct_slow_twitch"])
    return out


def calibrate_right_tendon_slack(model, lengths):
    """Recalibrate overstretched right-leg tendon slack lengths against the left leg
    (mjmodels/README.md, "Right-leg tendon slack lengths"). JW's .osim routes the right (JW-named,
    Schutte) quadriceps over the patella to the tibial tuberosity and places the soleus and
    peronei origins differently from the left (gait2392) leg, but keeps tendon slack lengths no
    longer than the left's, so those right muscle-tendon units sit 14-39 % beyond
    lopt cos(alpha0) + lts at rest (normalised tendon forces of 4-11). Rule: with the length ratio
    rho = mean(L) / (lopt cos(alpha0) + lts) over the trial, a right muscle whose rho exceeds its
    left counterpart's (GAIT2392_NAME) by more than OVERSTRETCH_TOL gets the lts that makes the
    two equal:
        lts_r = mean(L_r) / rho_l - lopt_r cos(alpha_r).
    Only overstretched muscles change, and only by lengthening the tendon; right muscles that are
    relatively shorter (most hip muscles of the Schutte set) keep the .osim's lts (matching them
    would make some lts negative). Path lengths L from `lengths` over every 4th trial frame:
    the straight .osim lines (straight_path_lengths), the same geometry on both sides, as the
    rule compares the .osim's two muscle sets, not the model's paths. Fmax, lopt and pennation
    stay the .osim's.
    Returns [(name, rho_r, rho_l, old lts, new lts)] for the changed muscles."""
    by_name = {mus["name"]: mus for mus in model.muscles}

    def rho(mus):
        samples = lengths[mus["name"]][::2]
        length = sum(samples) / len(samples)
        return length, length / (mus["lopt"] * math.cos(mus["pennation"]) + mus["lts"])

    changes = []
    for mus in model.muscles:
        partner = by_name.get(GAIT2392_NAME.get(mus["name"], "") + "_l")
        if partner is None:
            continue
        length_r, rho_r = rho(mus)
        _, rho_l = rho(partner)
        if rho_r <= rho_l * (1.0 + OVERSTRETCH_TOL):
            continue
        lts = length_r / rho_l - mus["lopt"] * math.cos(mus["pennation"])
        changes.append((mus["name"], rho_r, rho_l, mus["lts"], lts))
        mus["lts_osim"] = mus["lts"]
        mus["lts"] = lts
    return changes


def cap_fibre_stretch(model, lengths):
    """Lengthen any tendon whose muscle would be stretched beyond LM_MAX_TRIAL optimal fibre
    lengths somewhere in the trial (mjmodels/README.md, "Tendon slack lengths"). With the tendon
    at slack length (no tendon strain) and constant-thickness pennation the normalised fibre
    length is lM/lopt = sqrt((L - lts)^2 + (lopt sin alpha0)^2) / lopt; its largest value over
    trial_samples frames must not exceed LM_MAX_TRIAL, else lts is raised so that it equals it:
        lts = L_max - sqrt((LM_MAX_TRIAL lopt)^2 - (lopt sin alpha0)^2).
    Without the cap, JW's scaled geometry leaves soleus, tibialis posterior, piriformis and
    gluteus minimus at 1.4-1.9 lopt in stance, whose passive forces (up to 3 kN) no antagonist can
    balance. Applied to every muscle after calibrate_right_tendon_slack. Path lengths from
    `lengths`: the model's own paths (model_path_lengths), the fibre lengths it will simulate.
    Returns [(name, largest lM/lopt before, old lts, new lts)]
    for the changed muscles."""
    changes = []
    for mus in model.muscles:
        lopt, lts = mus["lopt"], mus["lts"]
        height = lopt * math.sin(mus["pennation"])
        longest = max(lengths[mus["name"]])
        stretch = math.sqrt((longest - lts) ** 2 + height ** 2) / lopt
        if stretch <= LM_MAX_TRIAL:
            continue
        new = longest - math.sqrt((LM_MAX_TRIAL * lopt) ** 2 - height ** 2)
        changes.append((mus["name"], stretch, lts, new))
        mus.setdefault("lts_osim", lts)
        mus["lts"] = new
    return changes


def floor_fibre_shortening(model, lengths):
    """Shorten any tendon whose muscle would need a fibre shorter than LM_MIN_TRIAL optimal fibre
    lengths somewhere in the trial (tendon at slack, as cap_fibre_stretch), so that its shortest
    fibre is LM_MIN_TRIAL, or as close as the longest fibre allows without exceeding LM_MAX_HARD:
        target = min(LM_MIN_TRIAL, LM_MAX_HARD - (L_max - L_min) / lopt),
        lts = L_min - sqrt((target lopt)^2 - (lopt sin alpha0)^2).
    Why: where the muscle-tendon unit is shorter than its slack tendon plus a short fibre, the
    Hill equilibrium (De Groote et al. 2016) has no tendon force to hold and a fibre on the
    vanishing end of its force-length curve: the residual's derivatives vanish, its multipliers
    grow without bound and Ipopt stalls (measured: JW's right semimembranosus, lts 0.378 m, is
    longer than the whole path at the shortest trial pose, lM/lopt -0.56; the tracking solves at
    N = 80 diverged with the largest multiplier on its row). Applied after cap_fibre_stretch.
    Path lengths from `lengths`: the model's own paths (model_path_lengths).
    Returns [(name, shortest lM/lopt before, old lts, new lts)] for the changed muscles."""
    changes = []
    for mus in model.muscles:
        lopt, lts = mus["lopt"], mus["lts"]
        height = lopt * math.sin(mus["pennation"])
        shortest, longest = min(lengths[mus["name"]]), max(lengths[mus["name"]])
        x = shortest - lts
        before = math.copysign(math.sqrt(x * x + height * height), x) / lopt
        if before >= LM_MIN_TRIAL:
            continue
        target = min(LM_MIN_TRIAL, LM_MAX_HARD - (longest - shortest) / lopt)
        if target * lopt <= height or target <= before:
            continue
        new = shortest - math.sqrt((target * lopt) ** 2 - height ** 2)
        changes.append((mus["name"], before, lts, new))
        mus.setdefault("lts_osim", lts)
        mus["lts"] = new
    return changes


# every TRIAL_LENGTH_STEP-th trial frame is a sample of the tendon calibration rules
TRIAL_LENGTH_STEP = 2
# a model path within this of the straight .osim line at every sample is that line (m): twice
# the rounding of `gaitsim inspect`'s lMT column
STRAIGHT_TOL = 2e-6


def trial_samples(frames):
    """The trial frames the tendon calibration rules look at: [(time (s), pose)]."""
    return frames[::TRIAL_LENGTH_STEP]


def straight_path_lengths(model, frames):
    """{muscle: [straight-segment .osim path length (m) at each trial_samples frame]}."""
    poses = [pose for _, pose in trial_samples(frames)]
    return {mus["name"]: [path_length(model, mus, pose) for pose in poses]
            for mus in model.muscles}


def model_path_lengths(gaitsim, model_xml, frames):
    """{muscle: [path length (m) of the MJCF model_xml at each trial_samples frame]}, as MuJoCo
    computes it (wrap geoms included): `gaitsim inspect MODEL --pose P --time t`, column lMT, with
    P a coordinates file of those frames written next to model_xml (and removed). The tendon
    calibration rules need the lengths of the paths the model has: where the converter's wrap
    surrogates wrap, the straight .osim line is shorter (gasmed by 18-23 mm, a third of its
    optimal fibre length; mjmodels/README.md, "Tendon slack lengths")."""
    import tempfile
    samples = trial_samples(frames)
    rows = [[t] + [pose[c] if c in TRANSLATIONS else math.degrees(pose[c])
                   for c in MODEL_COORDINATES] for t, pose in samples]
    folder = os.path.dirname(os.path.abspath(model_xml))
    fd, pose_file = tempfile.mkstemp(prefix=".trial_poses.", suffix=".mot", dir=folder)
    lengths = {}
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
            f.write(storage_text("coordinates", ["time"] + MODEL_COORDINATES, rows, True,
                                 cell=repr))
        for t, _ in samples:
            try:
                muscles = inspect_muscles(gaitsim, model_xml, pose_file, t)
            except PrepError as e:
                raise SystemExit("osim2mjcf.py: %s" % e)
            for name, r in muscles.items():
                lengths.setdefault(name, []).append(r["lMT"])
    finally:
        os.unlink(pose_file)
    return lengths


def metabolic_key(name):
    """JW muscle name -> row of the 3dpredictsim table (right-leg rows serve both legs)."""
    if name in ("ercspn_r", "ercspn_l", "intobl_r", "intobl_l", "extobl_r", "extobl_l"):
        return name
    if name.endswith("_l"):
        return name[:-2] + "_r"
    return GAIT2392_NAME[name] + "_r"


def whole_body_com(model, x):
    """Whole-body centre of mass (OpenSim ground frame) from body transforms x."""
    total, acc = 0.0, [0.0, 0.0, 0.0]
    for name, b in model.bodies.items():
        if b["mass"] > 0.0:
            total += b["mass"]
            acc = vec_add(acc, vec_scale(tf_point(x[name], b["com"]), b["mass"]))
    return vec_scale(acc, 1.0 / total)


def bisect(f, lo, hi, iterations=60):
    """Root of f on [lo, hi] (f(lo), f(hi) of opposite sign), fixed iteration count."""
    flo = f(lo)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        fm = f(mid)
        if (fm < 0.0) == (flo < 0.0):
            lo, flo = mid, fm
        else:
            hi = mid
    return 0.5 * (lo + hi)


def static_sole_penetration(weight):
    """Depth d (m) at which one foot's six spheres, all pressed d into the floor, carry `weight`
    (N) by the elastic term of the Hunt-Crossley law, Fn = 4/3 E sqrt(R) d^(3/2)
    (callbacks/gs_contact.h; E = CONTACT_USER[0], Pa)."""
    e_mod = CONTACT_USER[0]
    per_depth = sum(4.0 / 3.0 * e_mod * math.sqrt(r) for _, _, _, r, _ in CONTACT_SPHERES)
    return (weight / per_depth) ** (2.0 / 3.0)


def calibrated_soles(model, frames):
    """The sole plane of each foot in its calcaneus frame, calibrated on the trial
    (mjmodels/README.md, "Contact spheres and standing pose"): over the foot-flat frames (the
    calcaneus and toes origins both slower than FOOT_FLAT_SPEED) the floor y = 0 seen from the
    calcaneus is the plane n.p = c with n = R^T e_y and c = -y(origin); n and c are their means
    (n normalised). The sole lies the static penetration under body weight below it
    (static_sole_penetration), so the foot-flat poses of the trial load the spheres with about
    one body weight. Returns ({"r"|"l": {"normal": n, "offset": c - depth, "frames": count,
    "spread_deg": largest angle between a frame's n and the mean}}, depth (m))."""
    weight = GRAVITY * sum(b["mass"] for b in model.bodies.values())
    depth = static_sole_penetration(weight)
    xs = [model.body_transforms(model.coordinate_values(p)) for _, p in frames]
    times = [t for t, _ in frames]
    soles = {}
    for side, calc, toes in (("r", "calcaneus", "toes"), ("l", "calcaneus_l", "toes_l")):
        normals, offsets = [], []
        for i in range(1, len(frames) - 1):
            dt = times[i + 1] - times[i - 1]
            v_calc = vec_norm(vec_sub(xs[i + 1][calc][1], xs[i - 1][calc][1])) / dt
            v_toes = vec_norm(vec_sub(xs[i + 1][toes][1], xs[i - 1][toes][1])) / dt
            if v_calc < FOOT_FLAT_SPEED and v_toes < FOOT_FLAT_SPEED:
                normals.append(list(xs[i][calc][0][1]))   # row y of R = R^T e_y
                offsets.append(-xs[i][calc][1][1])
        if len(normals) < 5:
            raise SystemExit("osim2mjcf: the trial has %d foot-flat frames of the %s foot (< 5); "
                             "cannot calibrate its sole" % (len(normals), side))
        n = unit([sum(v[k] for v in normals) / len(normals) for k in range(3)])
        spread = max(math.degrees(math.acos(max(-1.0, min(1.0, sum(a * b for a, b in zip(v, n))
                                                          / vec_norm(v))))) for v in normals)
        soles[side] = {"normal": n, "offset": sum(offsets) / len(offsets) - depth,
                       "frames": len(normals), "spread_deg": spread}
    return soles, depth


def read_storage(path):
    """An OpenSim storage (.mot/.sto) written by scripts/prepare_trial.py: (labels, rows)."""
    try:
        with open(path) as f:
            lines = f.read().splitlines()
        start = [i for i, line in enumerate(lines) if line.strip() == "endheader"][0] + 1
        labels = lines[start].split("\t")
        rows = [[float(v) for v in line.split("\t")] for line in lines[start + 1:] if line]
    except (OSError, IndexError, ValueError) as e:
        raise SystemExit("osim2mjcf: %s: not a storage file (%s)" % (path, e))
    if any(len(r) != len(labels) for r in rows):
        raise SystemExit("osim2mjcf: %s: a row's column count differs from the header" % path)
    return labels, rows


def nelder_mead(f, x0, steps, iterations=600, tol=1e-12):
    """Minimise f from x0 by the Nelder-Mead simplex (initial edges `steps`), fixed budget."""
    pts = [list(x0)] + [[v + (steps[i] if i == j else 0.0) for j, v in enumerate(x0)]
                        for i in range(len(x0))]
    vals = [f(p) for p in pts]
    for _ in range(iterations):
        order = sorted(range(len(pts)), key=lambda i: vals[i])
        pts, vals = [pts[i] for i in order], [vals[i] for i in order]
        if vals[-1] - vals[0] < tol:
            break
        centroid = [sum(p[j] for p in pts[:-1]) / (len(pts) - 1) for j in range(len(x0))]
        move = lambda a: [c + a * (w - c) for c, w in zip(centroid, pts[-1])]
        xr = move(-1.0)
        fr = f(xr)
        if fr < vals[0]:
            xe = move(-2.0)
            fe = f(xe)
            pts[-1], vals[-1] = (xe, fe) if fe < fr else (xr, fr)
        elif fr < vals[-2]:
            pts[-1], vals[-1] = xr, fr
        else:
            xc = move(0.5)
            fc = f(xc)
            if fc < vals[-1]:
                pts[-1], vals[-1] = xc, fc
            else:
                pts = [pts[0]] + [[a + 0.5 * (b - a) for a, b in zip(pts[0], p)]
                                  for p in pts[1:]]
                vals = [vals[0]] + [f(p) for p in pts[1:]]
    best = min(range(len(pts)), key=lambda i: vals[i])
    return pts[best], vals[best]


# sphere groups whose placement fit_contact_spheres adjusts: heel (1, 4), forefoot (2, 3),
# toes (5, 6)
SPHERE_GROUPS = {1: "heel", 4: "heel", 2: "fore", 3: "fore", 5: "toes", 6: "toes"}


def fit_contact_spheres(model, frames, soles, grf_path, stride_start):
    """Fit each foot's sphere placement to the trial's vertical ground reaction (mjmodels/README.md,
    "Contact spheres and standing pose"). Over the IK frames of the prepared stride (grf.mot of
    scripts/prepare_trial.py, file time 0 = source time stride_start), with the measured poses,
    the model's vertical force is the Hunt-Crossley law of callbacks/gs_contact.h, sum over the
    six spheres of 4/3 E sqrt(R) d^1.5 (1 + 3/2 c d'), d the depth below the floor and d' its rate
    (central differences of the poses). Four numbers per foot minimise the mean squared error
    against the measured vertical force of that foot (in body weights), by Nelder-Mead: the heel
    spheres' F x and the offsets along the sole normal of the heel, forefoot and toes spheres
    (m; 0 = bottom on the sole). Sets soles[side]["heel_x"] and soles[side]["lift"] =
    {group: offset} and returns {side: (rms before, rms after, BW)}."""
    labels, rows = read_storage(grf_path)
    weight = GRAVITY * sum(b["mass"] for b in model.bodies.values())
    e_mod, c_diss = CONTACT_USER[0], CONTACT_USER[1]
    t_end = stride_start + rows[-1][0]
    idx = [i for i in range(1, len(frames) - 1) if stride_start <= frames[i][0] <= t_end]
    xs = {i: model.body_transforms(model.coordinate_values(frames[i][1]))
          for j in idx for i in (j - 1, j, j + 1)}
    report = {}
    for side, calc, toes, zsign in (("r", "calcaneus", "toes", 1.0),
                                    ("l", "calcaneus_l", "toes_l", -1.0)):
        col = labels.index("ground_force_%s_vy" % side)
        times = [r[0] + stride_start for r in rows]
        measured = []
        for i in idx:
            t = frames[i][0]
            k = max(1, min(len(times) - 1, next((j for j, u in enumerate(times) if u >= t),
                                                 len(times) - 1)))
            a = (t - times[k - 1]) / (times[k] - times[k - 1])
            measured.append(rows[k - 1][col] + a * (rows[k][col] - rows[k - 1][col]))
        # height of a calcaneus-frame point p in frame i: y(origin) + (row y of R) . p, affine
        lin = {i: (xs[i][calc][1][1], xs[i][calc][0][1]) for i in xs}
        sole = soles[side]
        ex, ez = foot_basis(xs[idx[0]], calc, toes, sole["normal"])

        def force_error(par):
            heel_x, lift = par[0], {"heel": par[1], "fore": par[2], "toes": par[3]}
            centres = []
            for k, fx, fz, r, _ in CONTACT_SPHERES:
                centre = sphere_centre(sole, ex, ez, heel_x if SPHERE_GROUPS[k] == "heel" else fx,
                                       zsign * fz, r)
                centres.append((vec_add(centre, vec_scale(sole["normal"],
                                                          lift[SPHERE_GROUPS[k]])), r))
            acc = 0.0
            for n_i, i in enumerate(idx):
                dt = frames[i + 1][0] - frames[i - 1][0]
                fz_total = 0.0
                for centre, r in centres:
                    h = lin[i][0] + dot(lin[i][1], centre) - r
                    if h >= 0.0:
                        continue
                    rate = -((lin[i + 1][0] + dot(lin[i + 1][1], centre)) -
                             (lin[i - 1][0] + dot(lin[i - 1][1], centre))) / dt
                    fz_total += 4.0 / 3.0 * e_mod * math.sqrt(r) * (-h) ** 1.5 * max(
                        0.0, 1.0 + 1.5 * c_diss * rate)
                acc += ((fz_total - measured[n_i]) / weight) ** 2
            return acc / len(idx)
        start = [sole.get("heel_x", 0.015), 0.0, 0.0, 0.0]
        before = math.sqrt(force_error(start))
        best, val = nelder_mead(force_error, start, [0.01, 0.005, 0.005, 0.005])
        sole["heel_x"] = best[0]
        sole["lift"] = {"heel": best[1], "fore": best[2], "toes": best[3]}
        report[side] = (before, math.sqrt(val))
    return report


def foot_basis(x, calc, toes, normal):
    """Foot frame F's axes in the calcaneus frame: x forward (the calcaneus-origin -> toes-origin
    line projected on the sole), z = x cross y (right), y the sole normal."""
    toes_org = tf_point(tf_inv(x[calc]), x[toes][1])
    ex = unit(vec_sub(toes_org, vec_scale(normal, dot(toes_org, normal))))
    return ex, cross(ex, normal)


def sphere_centre(sole, ex, ez, fx, fz, r):
    """Centre (calcaneus frame) of a sphere of radius r whose bottom lies on the sole at F
    coordinates (fx, fz)."""
    n, c = sole["normal"], sole["offset"]
    return vec_add(vec_scale(n, c + r), vec_add(vec_scale(ex, fx), vec_scale(ez, fz)))


def place_heels(model, frames, soles, heel_strikes):
    """Fore-aft position of the two heel spheres (1 and 4) in each foot frame F, calibrated on the
    trial (mjmodels/README.md, "Contact spheres and standing pose"): at the IK frame nearest each
    heel strike of that foot (trial.json, the force plates' 20 N onset) the heel spheres' bottoms
    touch the floor (their mean height is 0; several heel strikes: the mean over them). The
    height is linear in F x for a fixed pose, so two evaluations solve it. Sets
    soles[side]["heel_x"] (m) and returns {side: (mean bottom height at the default x (m),
    number of heel strikes)}."""
    heels = [(k, fz, r) for k, fx, fz, r, on_toes in CONTACT_SPHERES if k in (1, 4)]
    report = {}
    for side, calc, toes, zsign in (("r", "calcaneus", "toes", 1.0),
                                    ("l", "calcaneus_l", "toes_l", -1.0)):
        poses = []
        for t in heel_strikes[side]:
            i = min(range(len(frames)), key=lambda j: abs(frames[j][0] - t))
            if abs(frames[i][0] - t) > 0.02:
                raise SystemExit("osim2mjcf: no IK frame within 20 ms of the %s heel strike at "
                                 "%.4f s" % (side, t))
            poses.append((frames[i][0], model.body_transforms(model.coordinate_values(
                frames[i][1]))))

        def mean_bottom(fx, poses=poses, calc=calc, toes=toes, zsign=zsign, side=side):
            acc = 0.0
            for _, x in poses:
                ex, ez = foot_basis(x, calc, toes, soles[side]["normal"])
                for _, fz, r in heels:
                    centre = sphere_centre(soles[side], ex, ez, fx, zsign * fz, r)
                    acc += tf_point(x[calc], centre)[1] - r
            return acc / (len(poses) * len(heels))
        default_x = [fx for k, fx, _, _, _ in CONTACT_SPHERES if k == 1][0]
        h0, h1 = mean_bottom(default_x), mean_bottom(default_x - 0.01)
        soles[side]["heel_x"] = soles[side]["heel_x_strike"] = default_x - 0.01 * h0 / (h0 - h1)
        report[side] = (mean_bottom(default_x), len(poses))
    return report


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(u * v for u, v in zip(a, b))


def contact_spheres(model, x, soles):
    """Contact spheres on the calibrated soles (calibrated_soles): CONTACT_SPHERES placed in each
    foot frame F, every bottom on the sole plane. x: body transforms (any pose; the toes spheres
    need the calcaneus -> toes transform). Returns ({body: [(geom name, local position,
    radius)]}, {side: [sphere bottoms, ground frame, at x]})."""
    contacts, bottoms = {}, {}
    for side, calc, toes, zsign in (("r", "calcaneus", "toes", 1.0),
                                    ("l", "calcaneus_l", "toes_l", -1.0)):
        sole = soles[side]
        calc_to_toes = tf_mul(tf_inv(x[toes]), x[calc])
        ex, ez = foot_basis(x, calc, toes, sole["normal"])
        for k, fx, fz, r, on_toes in CONTACT_SPHERES:
            if k in (1, 4) and "heel_x" in sole:
                fx = sole["heel_x"]
            centre = sphere_centre(sole, ex, ez, fx, zsign * fz, r)
            centre = vec_add(centre, vec_scale(sole["normal"],
                                               sole.get("lift", {}).get(SPHERE_GROUPS[k], 0.0)))
            bottom = vec_sub(centre, vec_scale(sole["normal"], r))
            body = toes if on_toes else calc
            local = tf_point(calc_to_toes, centre) if on_toes else centre
            contacts.setdefault(body, []).append(("contact_%s_%d" % (side, k), local, r))
            bottoms.setdefault(side, []).append(tf_point(x[calc], bottom))
    return contacts, bottoms


def solve_newton(residual, u, tol=1e-12, iterations=30, step=1e-7):
    """Root of residual(u) = 0 (as many equations as unknowns) by Newton's method with a
    forward-difference Jacobian and Gaussian elimination with partial pivoting."""
    u = list(u)
    for _ in range(iterations):
        r = residual(u)
        if max(abs(v) for v in r) < tol:
            return u
        n = len(u)
        jac = [[0.0] * n for _ in range(n)]
        for j in range(n):
            up = list(u)
            up[j] += step
            rp = residual(up)
            for i in range(n):
                jac[i][j] = (rp[i] - r[i]) / step
        a = [row + [-r[i]] for i, row in enumerate(jac)]
        for col in range(n):
            piv = max(range(col, n), key=lambda i: abs(a[i][col]))
            a[col], a[piv] = a[piv], a[col]
            for i in range(col + 1, n):
                f = a[i][col] / a[col][col]
                a[i] = [vi - f * vc for vi, vc in zip(a[i], a[col])]
        du = [0.0] * n
        for i in reversed(range(n)):
            du[i] = (a[i][n] - sum(a[i][j] * du[j] for j in range(i + 1, n))) / a[i][i]
        u = [ui + di for ui, di in zip(u, du)]
    r = residual(u)
    if max(abs(v) for v in r) > 1e-9:
        raise SystemExit("osim2mjcf: the standing pose did not converge (residual %.3g)"
                         % max(abs(v) for v in r))
    return u


def standing_pose(model, zero, frames, soles):
    """The `standing` pose (= qpos0) and the contact spheres, computed (mjmodels/README.md,
    "Standing pose"):
    1. pelvic tilt relative to the legs and lumbar_extension: the means over the IK trial;
       other coordinates 0 (right knee's secondary coordinates at their defaults), knees 0;
    2. per leg, hip_flexion and hip_adduction such that the ankle centre (talus origin) lies
       vertically below the hip centre (femur origin) with the pelvis at the trial's mean tilt
       (legs vertical), hip_rotation such that the foot axis (calcaneus origin -> mtp centre)
       points straight ahead (X);
    3. Newton's method on six unknowns: per foot ankle_angle and subtalar_angle level its four
       calcaneus spheres (forefoot pair as high as the heel pair, medial pair as high as the
       lateral pair), pelvis_rx (pelvic list) puts both feet's spheres at one mean height,
       and the whole body leans forward by `lean` about the feet (pelvis_rz = mean tilt - lean,
       the legs lean with it) so that the whole-body COM lies over the middle of the fore-aft
       span of the 8 calcaneus sphere bottoms;
    4. pelvis_ty such that the calcaneus spheres' mean bottom height is 0 (the toes spheres,
       lifted by fit_contact_spheres, clear the floor).
    Returns (pose, {body: [(geom name, local position, radius)]}, report dict)."""
    pose = dict(zero)
    tilt = sum(f[1]["pelvis_rz"] for f in frames) / len(frames)
    pose["pelvis_rz"] = tilt
    pose["lumbar_extension"] = sum(f[1]["lumbar_extension"] for f in frames) / len(frames)

    def xform(p):
        return model.body_transforms(model.coordinate_values(p))

    # legs vertical (ankle centre below the hip centre, sagittal and frontal) and feet pointing
    # straight ahead (foot axis calcaneus -> mtp along X): coordinate-wise bisection, 3 sweeps
    for _ in range(3):
        for sfx, femur, talus, calc, toes in (("", "femur", "talus", "calcaneus", "toes"),
                                              ("_l", "femur_l", "talus_l", "calcaneus_l",
                                               "toes_l")):
            for coord, err in (
                    ("hip_rotation", lambda x: x[toes][1][2] - x[calc][1][2]),
                    ("hip_flexion", lambda x: x[talus][1][0] - x[femur][1][0]),
                    ("hip_adduction", lambda x: x[talus][1][2] - x[femur][1][2])):
                def f(q, c=coord + sfx, e=err):
                    p = dict(pose)
                    p[c] = q
                    return e(xform(p))
                pose[coord + sfx] = bisect(f, -0.6, 0.6)
    unknowns = ["ankle_angle", "subtalar_angle", "ankle_angle_l", "subtalar_angle_l",
                "pelvis_rx", "lean"]

    def posed(u):
        p = dict(pose)
        for name, v in zip(unknowns[:5], u[:5]):
            p[name] = v
        p["pelvis_rz"] = tilt - u[5]
        return p

    def calcaneus_bottoms(x):
        """Bottoms (ground frame) of spheres 1-4 per foot at x: {side: [4 points]}."""
        _, bottoms = contact_spheres(model, x, soles)
        return {side: bottoms[side][:4] for side in bottoms}

    def mean_height(points):
        return sum(p[1] for p in points) / len(points)

    def residual(u):
        x = xform(posed(u))
        feet = calcaneus_bottoms(x)
        level = []
        for side in ("r", "l"):
            b = {k: feet[side][k - 1][1] for k in (1, 2, 3, 4)}
            level += [0.5 * (b[2] + b[3]) - 0.5 * (b[1] + b[4]),   # forefoot - heel
                      0.5 * (b[1] + b[2]) - 0.5 * (b[3] + b[4])]   # medial - lateral
        fwd = [p[0] for side in feet for p in feet[side]]
        return level + [mean_height(feet["r"]) - mean_height(feet["l"]),
                        whole_body_com(model, x)[0] - 0.5 * (min(fwd) + max(fwd))]

    u = solve_newton(residual, [0.0] * 6)
    pose = posed(u)
    x = xform(pose)
    contacts, _ = contact_spheres(model, x, soles)
    pose["pelvis_ty"] = -mean_height(calcaneus_bottoms(x)["r"])
    x = xform(pose)
    _, bottoms = contact_spheres(model, x, soles)
    points = bottoms["r"] + bottoms["l"]
    report = {"com": whole_body_com(model, x), "points": points, "lean": u[5], "tilt": tilt,
              "ankle_r": x["talus"][1], "ankle_l": x["talus_l"][1]}
    return pose, contacts, report


class Converter:
    def __init__(self, model, metabolic, frames, osim_name, heel_strikes, grf_path, meshes,
                 wrap_fit=None):
        self.model = model
        # {muscle: fitted wrap geom} of scripts/fit_wraps.py (mjmodels/README.md, "Fitted wraps")
        self.wrap_fit = wrap_fit or {}
        self.meshes = meshes     # body -> [(mesh, scale, class)] (display_meshes)
        self.metabolic = metabolic
        self.frames = frames
        self.osim_name = osim_name
        # reference (default) pose: OpenSim defaults of the knee's secondary coordinates, 0 else
        zero = {c: model.default_value(c) if c in KNEE_SECONDARY else 0.0
                for c in MODEL_COORDINATES}
        # the OpenSim default pose: wrap segments and patella placement are chosen there
        self.x0 = model.body_transforms(model.coordinate_values(zero))
        # the standing pose is the model's reference configuration: qpos0 = `ref` = standing,
        # so stock tools start standing (mjmodels/README.md, "Standing pose")
        self.soles, self.sole_depth = calibrated_soles(model, frames)
        self.heel_report = place_heels(model, frames, self.soles, heel_strikes)
        self.fit_report = fit_contact_spheres(model, frames, self.soles, grf_path,
                                              heel_strikes["r"][0])
        self.standing, self.contacts, self.standing_report = standing_pose(model, zero, frames,
                                                                           self.soles)
        self.defaults = self.standing
        self.values0 = model.coordinate_values(self.defaults)
        self.children = {}
        for j, rev in model.tree:
            child = j["parent"] if rev else j["child"]
            parent = j["child"] if rev else j["parent"]
            self.children.setdefault(parent, []).append((child, j, rev))
        self.sites = {}          # body -> [(site name, pos)]
        self.wrap_geoms = {}     # body -> [wrap geom spec]
        self.tendons = []        # (muscle, [elements])
        self.notes = {"moving": [], "conditional": [], "dropped_wraps": []}
        self.build_paths()  # paths do not depend on the tendon rules that run after

    # --- bodies ------------------------------------------------------------------------------

    def build_paths(self):
        m = self.model
        for mus in m.muscles:
            kept = []
            for i, p in enumerate(mus["points"]):
                if p["type"] == "ConditionalPathPoint":
                    keep = conditional_kept(p, self.frames)
                    self.notes["conditional"].append((mus["name"], p["name"], p["coordinate"],
                                                      p["range"], keep))
                    if not keep:
                        continue
                if p["type"] == "MovingPathPoint":
                    loc = fit_moving_point(m, mus, i, self.frames)
                    self.notes["moving"].append((mus["name"], p["name"], loc))
                else:
                    loc = p["location"]
                kept.append((i, p, loc))
            elements = []
            seg_wraps = assign_wraps(m, mus, kept, self.x0)
            for wp in mus["wraps"]:
                if wp["object"] not in [w["name"] for (_, w) in seg_wraps.values()]:
                    self.notes["dropped_wraps"].append((mus["name"], wp["object"]))
            fit = self.wrap_fit.get(mus["name"])
            for s, (i, p, loc) in enumerate(kept):
                site = "%s-P%d" % (mus["name"], i + 1)
                self.sites.setdefault(p["body"], []).append((site, loc))
                elements.append(("site", site))
                if s in seg_wraps:
                    if fit and fit["slot"] == len(elements):
                        elements.extend(self.fitted_wrap(mus["name"], fit))
                        continue
                    body, w = seg_wraps[s]
                    geom = self.wrap_geom_name(body, w)
                    side = self.side_site(body, w)
                    elements.append(("geom", geom, side))
            if fit and not any(e[0] == "geom" and e[1] == fitted_part_names(mus["name"], 0)[0]
                               for e in elements):  # the slot must be one of the path's wraps
                raise SystemExit("osim2mjcf.py: --wrap-fit: %s's fitted wrap (slot %d) is not a "
                                 "wrap of its path" % (mus["name"], fit["slot"]))
            self.tendons.append((mus, elements))

    def fitted_wrap(self, muscle, fit):
        """The muscle's own wrap geoms (with side sites) and the via sites between them, as
        scripts/fit_wraps.py placed them (names: fitted_part_names); returns their tendon
        elements in path order."""
        elements = []
        for k, part in enumerate(fit["parts"]):
            name, side_name, via_name = fitted_part_names(muscle, k)
            if part["kind"] == "via":
                self.sites.setdefault(part["body"], []).append((via_name, part["pos"]))
                elements.append(("site", via_name))
                continue
            self.wrap_geoms.setdefault(part["body"], []).append({
                "name": name, "type": part["type"], "radius": part["size"][0],
                "half": part["size"][1] if part["type"] == "cylinder" else 0.0,
                "pos": part["pos"], "quat": part["quat"]})
            side = None
            if part["side"] is not None:
                side = side_name
                self.sites.setdefault(part["body"], []).append((side, part["side"]))
            elements.append(("geom", name, side))
        return elements

    def wrap_geom_name(self, body, w):
        lst = self.wrap_geoms.setdefault(body, [])
        if w["name"] not in [x["name"] for x in lst]:
            spec = wrap_geom_spec(body, w)
            spec["name"] = w["name"]
            spec["pos"] = w["translation"]
            spec["quadrant"] = quadrant_direction(w)
            spec["orig_rot"] = w["rotation"]
            lst.append(spec)
        return w["name"]

    def side_site(self, body, w):
        """Sidesite outside the wrap surface in OpenSim's quadrant direction (none for 'all')."""
        d = quadrant_direction(w)
        if d is None:
            return None
        spec = [x for x in self.wrap_geoms[body] if x["name"] == w["name"]][0]
        reach = 1.5 * max(spec["radius"], max(w["dimensions"]) if w["type"] == "WrapEllipsoid"
                          else spec["radius"])
        pos = tf_point((w["rotation"], w["translation"]), vec_scale(d, reach))
        name = w["name"] + "_side"
        lst = self.sites.setdefault(body, [])
        if name not in [s[0] for s in lst]:
            lst.append((name, pos))
        return name

    # --- writing -----------------------------------------------------------------------------

    def emit_body(self, out, body, j, rev, indent):
        m = self.model
        pad = "  " * indent
        b0, joints = mujoco_body_frame(m, j, rev, self.values0)
        out.append('%s<body name="%s" pos="%s" quat="%s">' % (
            pad, body, fvec(b0[1]), fvec(quat_from_mat(b0[0]))))
        for jt in joints:
            out.append(pad + "  " + self.joint_xml(jt))
        self.emit_body_content(out, body, indent + 1)
        for child, cj, crev in self.children.get(body, []):
            if relocated_body(child):
                continue
            self.emit_body(out, child, cj, crev, indent + 1)
        for moved, host in (("patella", "tibial_tray"), ("patella_l", "tibia_l")):
            if host == body:
                rel = tf_mul(tf_inv(self.x0[body]), self.x0[moved])
                out.append('%s  <body name="%s" pos="%s" quat="%s">' % (
                    pad, moved, fvec(rel[1]), fvec(quat_from_mat(rel[0]))))
                self.emit_body_content(out, moved, indent + 2)
                out.append(pad + "  </body>")
        out.append(pad + "</body>")

    def joint_xml(self, jt):
        c = jt["coordinate"]
        rng = self.model.coords[c]["range"]
        axis = clean_axis(jt["axis"])
        attrs = ['name="%s"' % c, 'type="%s"' % jt["kind"], 'axis="%s"' % fvec(axis)]
        if jt["kind"] == "hinge" and vec_norm(jt["anchor"]) > 1e-12:
            attrs.append('pos="%s"' % fvec(clean_axis(jt["anchor"])))
        ref = self.defaults[c]
        if ref != 0.0:
            attrs.append('ref="%s"' % fmt(ref))
        if not c.startswith("pelvis"):
            attrs.append('range="%s"' % fvec(rng))
        else:
            attrs.append('limited="false"')
        if c in KNEE_SECONDARY:
            k, d = KNEE_SECONDARY[c]
            attrs.append('stiffness="%s" springref="%s" damping="%s"' % (fmt(k), fmt(ref), fmt(d)))
        return "<joint %s/>" % " ".join(attrs)

    def emit_body_content(self, out, body, indent):
        pad = "  " * indent
        b = self.model.bodies[body]
        ixx, iyy, izz, ixy, ixz, iyz = b["inertia"]
        if b["mass"] > 0.0:
            if ixy == 0.0 and ixz == 0.0 and iyz == 0.0:
                inert = 'diaginertia="%s"' % fvec([ixx, iyy, izz])
            else:
                inert = 'fullinertia="%s"' % fvec([ixx, iyy, izz, ixy, ixz, iyz])
            out.append('%s<inertial pos="%s" mass="%s" %s/>' % (pad, fvec(b["com"]),
                                                                fmt(b["mass"], 12), inert))
        elif self.meshes.get(body):
            raise SystemExit("osim2mjcf.py: body %s has meshes but no mass: its display geoms "
                             "would get mass" % body)
        for mesh, _, cls in self.meshes.get(body, []):
            out.append('%s<geom name="%s_%s" class="%s" mesh="%s"/>' % (pad, cls, mesh, cls, mesh))
        for spec in self.wrap_geoms.get(body, []):
            size = fmt(spec["radius"]) if spec["type"] == "sphere" else \
                "%s %s" % (fmt(spec["radius"]), fmt(max(spec["half"], spec["radius"])))
            out.append('%s<geom name="%s" class="wrap" type="%s" size="%s" pos="%s" quat="%s"/>'
                       % (pad, spec["name"], spec["type"], size, fvec(spec["pos"]),
                          fvec(spec["quat"] if "quat" in spec else quat_from_mat(spec["rot"]))))
        for name, pos in self.sites.get(body, []):
            cls = "side" if name.endswith("_side") else "path"
            out.append('%s<site name="%s" class="%s" pos="%s"/>' % (pad, name, cls, fvec(pos)))
        for name, pos, r in self.contacts.get(body, []):
            out.append('%s<geom name="%s" class="contact" size="%s" pos="%s"/>'
                       % (pad, name, fmt(r), fvec(pos, 6)))

    def lengthranges(self):
        out = {}
        for mus in self.model.muscles:
            ls = [path_length(self.model, mus, pose) for _, pose in self.frames[::4]]
            lo, hi = min(ls), max(ls)
            span = max(hi - lo, 0.01)
            out[mus["name"]] = (max(0.01, lo - 0.5 * span), hi + 0.5 * span)
        return out

    def actuator_user(self, mus):
        st = self.metabolic[metabolic_key(mus["name"])]
        sigma = TRUNK_SPECIFIC_TENSION if mus["name"] in TRUNK_MUSCLES else LEG_SPECIFIC_TENSION
        mass = mus["fmax"] / sigma * mus["lopt"] * MUSCLE_DENSITY
        return [mus["fmax"], mus["lopt"], mus["lts"], mus["pennation"], VMAX, st, sigma, mass,
                1.0 if mus["lts"] >= mus["lopt"] else 0.0, TAU_ACT, TAU_DEACT, TENDON_KT]

    def write(self, path):
        m = self.model
        total_mass = sum(b["mass"] for b in m.bodies.values())
        out = []
        out.append('<?xml version="1.0" encoding="utf-8"?>')
        out.append("<!--")
        # no "--" inside an XML comment (not well-formed XML; MuJoCo tolerates it, expat not)
        out.append("  jw_fullbody.xml: GENERATED by %s, do not edit by hand; regenerate with" % CONVERTER)
        out.append("    the command in mjmodels/README.md (options osim, muscle-params, out,")
        out.append("    reference-out: .../JW_AllBody_scaled.osim, .../muscle_params,")
        out.append("    mjmodels/jw_fullbody.xml, mjmodels/reference/jw_moment_arms.csv)")
        out.append("  Source: %s from gilserrancoli/ReducePoly_forMSK (MIT licence)," % self.osim_name)
        out.append("    Knee Grand Challenge subject JW (right TKA, instrumented eTibia),")
        out.append("    Fregly et al. 2012, J Orthop Res 30:503. Metabolic muscle parameters:")
        out.append("    antoinefalisse/3dpredictsim (MIT), Uchida et al. 2016 (slow-twitch")
        out.append("    fractions); the metabolic masses from the specific tension %s MPa (legs;"
                   % fmt(LEG_SPECIFIC_TENSION / 1e6))
        out.append("    Narici et al. 1992) and %s MPa (trunk; Burkhart et al. 2018, J Orthop"
                   % fmt(TRUNK_SPECIFIC_TENSION / 1e6))
        out.append("    Res 36:498).")
        out.append("  %d DOF (hinge/slide only), %d muscles, total mass %s kg." % (
            len(MODEL_COORDINATES), len(m.muscles), fmt(total_mass, 6)))
        if m.arm_pose != ARM_POSE:
            out.append("  Arms welded at the trial stride's mean arm coordinates "
                       "(arm pose 'trial'):")
            for side in ("_r", "_l"):
                out.append("    " + ", ".join("%s %.1f" % (c, math.degrees(v))
                                              for c, v in m.arm_pose.items()
                                              if c.endswith(side) and "wrist" not in c) + " deg")
        out.append("  Frames: body 'ground' rotates OpenSim's Y-up ground (X forward, Y up, Z right)")
        out.append("    into MuJoCo's Z-up world (+90 deg about X): OpenSim Y -> world Z,")
        out.append("    OpenSim Z -> world -Y. Coordinate values mean what they mean in OpenSim.")
        out.append("  Contact spheres calibrated on the trial (IK_ngait_og5 foot-flat frames, the")
        out.append("    heel strikes of mjmodels/trials/jw_ngait_og5/trial.json and the vertical")
        out.append("    GRF of its grf.mot): mjmodels/README.md, Contact spheres and standing pose.")
        out.append("  Display meshes (visual only, no mass, no collision): meshes/, made by")
        out.append("    scripts/make_bone_meshes.py; provenance and licence in meshes/README.md.")
        if self.wrap_fit:
            out.append("  Wrap geoms named <muscle>_wrap (%d muscles): fitted to OpenSim's wrapped"
                       % len(self.wrap_fit))
            out.append("    paths by scripts/fit_wraps.py (mjmodels/reference/jw_wrap_fit.json).")
        out.append("  Layout of actuator and geom user rows: callbacks/gs_model_layout.h;")
        out.append("    choices and errors: mjmodels/README.md.")
        out.append("-->")
        out.append('<mujoco model="jw_fullbody">')
        out.append('  <compiler angle="radian" autolimits="true" balanceinertia="true"'
                   ' meshdir="meshes">')
        out.append('    <lengthrange useexisting="true" mode="muscle"/>')
        out.append("  </compiler>")
        out.append('  <option timestep="0.001" gravity="0 0 -%s" integrator="Euler"/>' % fmt(GRAVITY))
        out.append('  <size nuser_actuator="12" nuser_geom="6"/>')
        out.append("  <default>")
        # stiff joint limits (README "Joint limits"): a held (zero-width range) ankle must carry
        # the body's gravity moment without creeping
        out.append('    <joint armature="0" damping="0" solreflimit="0.004 1"'
                   ' solimplimit="0.95 0.99 0.001"/>')
        out.append('    <geom contype="0" conaffinity="0" group="1"/>')
        out.append('    <site size="0.004" group="4"/>')
        out.append('    <default class="wrap">')
        out.append('      <geom contype="0" conaffinity="0" group="3" rgba="0.3 0.8 0.8 0.3"/>')
        out.append("    </default>")
        out.append('    <default class="path"><site size="0.003" rgba="0.8 0.2 0.2 1"/></default>')
        out.append('    <default class="side"><site size="0.002" rgba="0.2 0.8 0.2 1"/></default>')
        out.append('    <default class="contact">')
        out.append('      <geom type="sphere" contype="1" conaffinity="1" group="2" condim="3"'
                   ' friction="0.8 0.005 0.0001" rgba="0.9 0.6 0.2 1" user="%s"/>'
                   % fvec(CONTACT_USER))
        out.append("    </default>")
        # display meshes: no collision, no mass (every body carrying one has an <inertial>)
        for cls in ("bone", "implant"):
            out.append('    <default class="%s">' % cls)
            out.append('      <geom type="mesh" contype="0" conaffinity="0" group="1"'
                       ' material="%s"/>' % cls)
            out.append("    </default>")
        out.append('    <tendon width="0.002" rgba="0.7 0.1 0.1 1"/>')
        out.append("  </default>")
        out.append("  <visual>")
        out.append('    <headlight ambient="0.3 0.3 0.3" diffuse="0.35 0.35 0.35"'
                   ' specular="0.05 0.05 0.05"/>')
        out.append('    <quality shadowsize="2048"/>')
        out.append("  </visual>")
        out.append("  <asset>")
        out.append('    <texture name="sky" type="skybox" builtin="gradient" rgb1="%s" rgb2="%s"'
                   ' width="128" height="128"/>' % SKY_RGB)
        out.append('    <texture name="floor" type="2d" builtin="checker" rgb1="%s" rgb2="%s"'
                   ' width="64" height="64"/>' % FLOOR_RGB)
        out.append('    <material name="floor" texture="floor" texuniform="true"'
                   ' texrepeat="%s %s"/>' % (fmt(1.0 / FLOOR_SQUARE), fmt(1.0 / FLOOR_SQUARE)))
        out.append('    <material name="bone" rgba="%s" specular="0.2" shininess="0.2"/>'
                   % BONE_RGBA)
        out.append('    <material name="implant" rgba="%s" specular="0.8" shininess="0.7"/>'
                   % IMPLANT_RGBA)
        done = set()
        for body in m.body_order:
            for mesh, scale, _ in self.meshes.get(body, []):
                if mesh in done:
                    raise SystemExit("osim2mjcf.py: mesh %s used twice" % mesh)
                done.add(mesh)
                out.append('    <mesh name="%s" file="%s.stl" scale="%s"/>' % (
                    mesh, mesh, fvec(scale)))
        out.append("  </asset>")
        out.append("  <worldbody>")
        out.append('    <geom name="floor" type="plane" size="10 5 0.1" contype="1" conaffinity="1"'
                   ' group="0" material="floor"/>')
        # sun from above, in front and to the right of the walker (shadows fall behind-left)
        out.append('    <light name="sun" pos="1 -1 4" dir="-0.35 0.45 -1" directional="true"'
                   ' diffuse="0.75 0.75 0.72" specular="0.2 0.2 0.2"/>')
        out.append('    <body name="ground" quat="%s">' % fvec(quat_from_mat(
            axis_angle([1.0, 0.0, 0.0], math.pi / 2.0))))
        for child, j, rev in self.children["ground"]:
            self.emit_body(out, child, j, rev, 3)
        out.append("    </body>")
        out.append("  </worldbody>")
        out.append("  <tendon>")
        for mus, elements in self.tendons:
            out.append('    <spatial name="%s">' % mus["name"])
            for e in elements:
                if e[0] == "site":
                    out.append('      <site site="%s"/>' % e[1])
                elif e[2]:
                    out.append('      <geom geom="%s" sidesite="%s"/>' % (e[1], e[2]))
                else:
                    out.append('      <geom geom="%s"/>' % e[1])
            out.append("    </spatial>")
        out.append("  </tendon>")
        out.append("  <actuator>")
        ranges = self.lengthranges()
        for mus in m.muscles:
            lr = ranges[mus["name"]]
            out.append('    <muscle name="%s" tendon="%s" force="%s" lengthrange="%s" '
                       'range="0.75 1.05" user="%s"/>' % (
                           mus["name"], mus["name"], fmt(mus["fmax"]), fvec(lr, 6),
                           fvec(self.actuator_user(mus))))
        out.append("  </actuator>")
        out.append("  <custom>")
        for coordinate, k, theta in JOINT_LIMIT_MOMENTS:
            for side in ("", "_l"):  # both legs alike
                if coordinate + side not in MODEL_COORDINATES:
                    raise SystemExit("osim2mjcf.py: joint-limit moment for %s: no such "
                                     "coordinate" % (coordinate + side))
                out.append('    <numeric name="gs_limit_%s%s" size="6" data="%s"/>' % (
                    coordinate, side, " ".join(repr(v) for v in k + theta)))
        out.append("  </custom>")
        qpos = []
        for c in MODEL_COORDINATES:
            qpos.append(self.standing[c])
        out.append("  <keyframe>")
        out.append('    <key name="standing" qpos="%s"/>' % fvec(qpos))
        out.append("  </keyframe>")
        out.append("</mujoco>")
        write_atomic(path, "\n".join(out) + "\n")


def write_reference(model, frames, path, poses_path, osim_name, trial_name, methods):
    """The moment-arm reference (mjmodels/README.md, "Moment-arm comparison"): per pose, muscle
    and crossed coordinate the straight-line value (value, as before), and OpenSim's wrapped
    value (value_wrap: wrapped_path, for muscles without wrap objects the same path), both by
    central differences; wrapping = 1 where OpenSim's path touches a wrap object at the pose.
    methods: read_wrap_methods of the .osim."""
    idx = reference_poses(frames)
    lines = []
    lines.append("# GENERATED by %s (do not edit): muscle-tendon lengths and moment arms of %s"
                 % (CONVERTER, osim_name))
    lines.append("# (gilserrancoli/ReducePoly_forMSK, MIT; Knee Grand Challenge subject JW, "
                 "Fregly et al. 2012 J Orthop Res 30:503) computed from the OpenSim geometry only:")
    lines.append("# CustomJoint kinematics incl. reversed joints and coupler constraints, path points "
                 "incl. conditional and moving points evaluated exactly.")
    lines.append("# value: straight segments, NO wrapping. value_wrap: with OpenSim's wrapping "
                 "(port of GeometryPath::applyWrapObjects, WrapEllipsoid, WrapCylinder;")
    lines.append("# see wrapped_path in the converter and mjmodels/README.md). Poses: frames of %s "
                 "listed in jw_poses.csv." % trial_name)
    lines.append("# Length (m) or moment arm r = -dL/dq (m or m/m) by central differences, h = %g."
                 % FD_STEP)
    lines.append("# wraps = 1 if the OpenSim path has wrap objects. clear = 1 if at this pose the straight path "
                 "misses every wrap object of the muscle")
    lines.append("# (normalised clearance >= 1, see wrap_clearance; constrained quadrants respected). "
                 "wrapping = 1 if OpenSim's wrapped path touches")
    lines.append("# a wrap object at this pose (then value_wrap differs from value).")
    lines.append("# MuJoCo actuator_moment = dL/dq = -r.")
    lines.append("pose,muscle,coordinate,value,wraps,clear,value_wrap,wrapping")
    pose_lines = ["# GENERATED by %s: reference poses for jw_moment_arms.csv, frames of %s; "
                  "radians and m, model coordinate order" % (CONVERTER, trial_name),
                  "# pose: trial row (0-based), time (s): " + "; ".join(
                      "%d: %d, %s" % (k, i, fmt(frames[i][0])) for k, i in enumerate(idx)),
                  "pose," + ",".join(MODEL_COORDINATES)]
    for k, i in enumerate(idx):
        t, pose = frames[i]
        pose_lines.append("%d,%s" % (k, ",".join(fmt(pose[c], 10) for c in MODEL_COORDINATES)))
        for mus in model.muscles:
            wraps = 1 if mus["wraps"] else 0
            clearance = wrap_clearance(model, mus, pose)
            clear = 1 if clearance is None or clearance >= 1.0 else 0
            length_wrap, touched = wrapped_path(model, mus, pose, methods)
            wrapping = 1 if touched else 0
            lines.append("%d,%s,length,%s,%d,%d,%s,%d" % (
                k, mus["name"], fmt(path_length(model, mus, pose), 10), wraps, clear,
                fmt(length_wrap, 10), wrapping))
            crossed = crossed_coordinates(model, mus)
            arms_wrap = wrapped_moment_arms(model, mus, pose, crossed, methods)
            for c, r in moment_arms(model, mus, pose, crossed).items():
                lines.append("%d,%s,%s,%s,%d,%d,%s,%d" % (k, mus["name"], c, fmt(r, 8), wraps,
                                                         clear, fmt(arms_wrap[c], 8), wrapping))
    write_atomic(path, "\n".join(lines) + "\n")
    write_atomic(poses_path, "\n".join(pose_lines) + "\n")


def add_knee_params(xml_path, params_path):
    """--knee-params: insert the gs_knee <custom> numerics of mjmodels/knee/jw_knee.json
    (scripts/prepare_knee.py knee_custom_snippet) into the written model and remove the right
    knee's placeholders on knee_rotation, knee_adduction, knee_tx, knee_ty, knee_tz: their springs
    (stiffness/springref) and their joint damping (KNEE_SECONDARY). The implant's contact and the
    ligaments (with the ligaments' own damping) then hold the five coordinates, as in the .osim,
    whose coordinates carry no damping; the placeholders' 50 N m s/rad and 2000 N s/m had no
    tissue behind them and carried, in stance, up to 14 N m of the knee's frontal moment and 230
    N of its anterior shear in a tracking solution (docs/BENCHMARKS.md, "The knee's placeholder
    damping"). Rewrites xml_path atomically."""
    import json
    import re
    from prepare_knee import knee_custom_snippet
    with open(params_path, encoding="utf-8") as f:
        params = json.load(f)
    with open(xml_path, encoding="utf-8") as f:
        text = f.read()
    for name in ("knee_rotation", "knee_adduction", "knee_tx", "knee_ty", "knee_tz"):
        text, n = re.subn(r'(<joint name="%s"[^>]*?) stiffness="[^"]*" springref="[^"]*" '
                          r'damping="[^"]*"' % name, r"\1", text)
        if n != 1:
            raise SystemExit("osim2mjcf.py: %s: joint %s placeholder spring and damping not "
                             "found" % (xml_path, name))
    if "</mujoco>" not in text:
        raise SystemExit("osim2mjcf.py: %s: no </mujoco>" % xml_path)
    text = text.replace("</mujoco>", knee_custom_snippet(params) + "</mujoco>", 1)
    write_atomic(xml_path, text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--osim", required=True)
    ap.add_argument("--muscle-params", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--reference-out", required=True)
    ap.add_argument("--trial-ik", default=None,
                    help="IK csv (default: <osim dir>/../ngait_og5/IK_ngait_og5.csv)")
    ap.add_argument("--knee-params", default=None,
                    help="mjmodels/knee/jw_knee.json: add the gs_knee numerics (opt-in)")
    ap.add_argument("--trial-events", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "mjmodels", "trials", "jw_ngait_og5",
        "trial.json"), help="trial.json of scripts/prepare_trial.py: the heel strikes (source "
                            "times) that place the heel spheres; grf.mot next to it is fitted "
                            "(default: the bundled trial's)")
    ap.add_argument("--gaitsim", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "build", "gaitsim"),
        help="the built gaitsim, whose `inspect` measures the model's own path lengths for the "
             "tendon calibration (default: build/gaitsim)")
    ap.add_argument("--wrap-fit", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "mjmodels", "reference",
        "jw_wrap_fit.json"), help="the fitted wrap geoms of scripts/fit_wraps.py ('none': the "
                                  "converter's own surrogates only)")
    ap.add_argument("--arm-pose", choices=("hanging", "trial"), default="trial",
                    help="where the welded arms sit: 'trial' (the default: the mean of the "
                         "--trial-ik arm columns over the stride between the first two right "
                         "heel strikes of --trial-events) or 'hanging' (arms down, elbows 15 deg)")
    args = ap.parse_args()
    wrap_fit = {}
    if args.wrap_fit != "none":
        try:
            with open(args.wrap_fit) as f:
                wrap_fit = json.load(f)["muscles"]
        except (OSError, ValueError, KeyError) as e:
            ap.error("--wrap-fit %s: %s" % (args.wrap_fit, e))
    if not os.access(args.gaitsim, os.X_OK):
        ap.error("--gaitsim %s: not an executable (build gaitsim first: README.md)" % args.gaitsim)
    heel_strikes = read_heel_strikes(args.trial_events)
    trial = args.trial_ik or os.path.join(os.path.dirname(os.path.abspath(args.osim)), "..",
                                          "ngait_og5", "IK_ngait_og5.csv")
    model = OsimModel(args.osim)
    if args.arm_pose == "trial":
        if len(heel_strikes["r"]) < 2:
            ap.error("--arm-pose trial: %s names fewer than two right heel strikes"
                     % args.trial_events)
        model.arm_pose = trial_arm_pose(trial, heel_strikes["r"][0], heel_strikes["r"][1])
        print("arms welded at the trial stride's mean: " + ", ".join(
            "%s %.1f deg" % (c, math.degrees(v)) for c, v in model.arm_pose.items()))
    frames = read_trial(trial)
    metabolic = read_metabolic(os.path.join(args.muscle_params,
                                            "MTparameters_subject1_with_metabolic_params.csv"))
    # display meshes: meshes/ next to the model (its meshdir)
    meshes = display_meshes(args.osim, os.path.join(os.path.dirname(os.path.abspath(args.out)),
                                                    "meshes"))
    conv = Converter(model, metabolic, frames, os.path.basename(args.osim), heel_strikes,
                     os.path.join(os.path.dirname(os.path.abspath(args.trial_events)), "grf.mot"),
                     meshes, wrap_fit)
    # the tendon rules on the written model's own path lengths: a draft with the .osim's lts
    # (path lengths do not depend on lts) measured by MuJoCo through gaitsim, next to --out
    draft = os.path.join(os.path.dirname(os.path.abspath(args.out)),
                         "." + os.path.basename(args.out) + ".draft.xml")
    conv.write(draft)
    try:
        lengths = model_path_lengths(args.gaitsim, draft, frames)
    finally:
        os.unlink(draft)
    # where the model's path is the straight line at every sample (equal to inspect's 1e-6 m
    # print), the straight length is exact: use it
    straight = straight_path_lengths(model, frames)
    for mus in model.muscles:
        n = mus["name"]
        diff = [a - b for a, b in zip(lengths[n], straight[n])]
        if max(abs(x) for x in diff) <= STRAIGHT_TOL:
            lengths[n] = straight[n]
        else:
            print("path %-11s the model's path minus the straight .osim line: %+.1f to %+.1f mm"
                  % (n, 1e3 * min(diff), 1e3 * max(diff)))
    for name, rho_r, rho_l, old, new in calibrate_right_tendon_slack(model, straight):
        print("lts %-11s rho %.3f (left %.3f): %.4f -> %.4f m (%+.1f %%)" % (
            name, rho_r, rho_l, old, new, 100.0 * (new / old - 1.0)))
    for name, stretch, old, new in cap_fibre_stretch(model, lengths):
        print("lts %-11s lM/lopt max %.3f: %.4f -> %.4f m (%+.1f %%)" % (
            name, stretch, old, new, 100.0 * (new / old - 1.0)))
    for name, short, old, new in floor_fibre_shortening(model, lengths):
        print("lts %-11s lM/lopt min %.3f: %.4f -> %.4f m (%+.1f %%)" % (
            name, short, old, new, 100.0 * (new / old - 1.0)))
    for side in ("r", "l"):
        sole = conv.soles[side]
        print("sole %s: normal %s, offset %.4f m in the calcaneus frame (%d foot-flat frames, "
              "spread %.1f deg, static penetration %.1f mm)" % (
                  side, " ".join("%.4f" % v for v in sole["normal"]), sole["offset"],
                  sole["frames"], sole["spread_deg"], 1000.0 * conv.sole_depth))
        print("heel %s: spheres 1 and 4 at F x = %.4f m (with the default x their bottoms are "
              "%.1f mm above the floor at the %d heel strike(s))" % (
                  side, sole["heel_x_strike"], 1000.0 * conv.heel_report[side][0],
                  conv.heel_report[side][1]))
        print("fit %s: vertical GRF RMS %.3f -> %.3f BW; heel x %.4f m, lift heel %.4f, fore "
              "%.4f, toes %.4f m" % ((side,) + conv.fit_report[side] + (sole["heel_x"],) + tuple(
                  sole["lift"][g] for g in ("heel", "fore", "toes"))))
    print("standing: " + ", ".join("%s %.2f deg" % (c, math.degrees(conv.standing[c])) for c in (
        "pelvis_rz", "pelvis_rx", "ankle_angle", "subtalar_angle", "ankle_angle_l",
        "subtalar_angle_l")) + ", lean %.2f deg, pelvis_ty %.4f m" % (
        math.degrees(conv.standing_report["lean"]), conv.standing["pelvis_ty"]))
    conv.write(args.out)
    if args.knee_params:
        add_knee_params(args.out, args.knee_params)
    write_reference(model, frames, args.reference_out,
                    os.path.join(os.path.dirname(args.reference_out), "jw_poses.csv"),
                    os.path.basename(args.osim), os.path.basename(trial),
                    read_wrap_methods(args.osim))
    print("wrote %s (%d dof, %d muscles, %.4f kg) and %s" % (
        args.out, len(MODEL_COORDINATES), len(model.muscles),
        sum(b["mass"] for b in model.bodies.values()), args.reference_out))


if __name__ == "__main__":
    main()
