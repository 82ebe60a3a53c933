#!/usr/bin/python3
"""make_bone_meshes.py: binary STL bone and implant meshes for MuJoCo 2.2.2 (mjmodels/meshes/).

MuJoCo 2.2.2 cannot read OpenSim's VTK PolyData (.vtp) bone geometry. This script converts, for
every <Mesh> that JW_AllBody_scaled.osim attaches to a body (plus sacrum.vtp and l_pelvis.vtp,
which complete its right-only hemipelvis), the .vtp file of opensim-org/opensim-models
Geometry/ (commit 20a888b9, as copied to ../shared/data/geometry) into a binary STL of the same
base name, in metres and in the owning OpenSim body's frame, UNSCALED (the converter
scripts/osim2mjcf.py writes the .osim's per-body scale_factors into each <mesh scale>).

VTP: XML `VTKFile type="PolyData"`; Points (3 components, Float32/Float64) and Polys
(connectivity + offsets). DataArrays in format="ascii" (what all the source files use) or
format="binary" (base64, uncompressed, UInt32/UInt64 header); compressed or appended data is
refused with a message. Polygons with more than 3 vertices (quads and n-gons up to 10 sides in
bofoot, foot, fibula, pat, hat_jaw, hat_skull, hat_spine) are fan-triangulated; triangles with a
repeated vertex are dropped.

The implant (JW's right TKA): the .osim's femoral_component.vtp and tibial_tray.vtp are not
public. From the prosthesis surfaces of ../shared/data/jw/prosthesis (ASCII STL, MeshLab; the
same surfaces as femPoints_188 / tibPoints, already in JW's femoral_component / tibial_tray frames,
mjmodels/knee/README.md "Frames") two closed solids are made for display:
  femoral_component.stl: Femoral_Component_simpler.stl (188 triangles, the articular surface)
      thickened by FEMORAL_THICKNESS towards its inside (vertex normals), rim closed;
  tibial_insert.stl: Tibial_Insert_simpler_superior.stl (49 triangles, the insert's superior
      surface) extruded down to a flat base INSERT_DEPTH below its lowest point (an insert, not
      the tray: the tray's geometry is not public).
No decimation: the 81 bone meshes total about 61,000 triangles, 3.1 MB as binary STL (50 bytes
per triangle), under the 5 MB aimed at; --max-bytes fails the run if the output grows past it.

Writes OUT/<name>.stl for each mesh and OUT/README.md (provenance, licence, per-file triangle
counts). Deterministic: the same inputs give the same bytes. Standard library + numpy.

Usage:
  /usr/bin/python3 scripts/make_bone_meshes.py [--geometry ../shared/data/geometry]
      [--osim ../shared/data/jw/model/JW_AllBody_scaled.osim]
      [--prosthesis ../shared/data/jw/prosthesis] [--out mjmodels/meshes] [--max-bytes 5000000]
"""
import argparse
import base64
import os
import re
import struct
import sys
import xml.etree.ElementTree as ET

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_scriptlib import write_atomic  # noqa: E402
from osim2mjcf import EXTRA_MESHES, IMPLANT_MESHES, osim_meshes  # noqa: E402

SCRIPT = "scripts/make_bone_meshes.py"
SOURCE_COMMIT = "20a888b9655e73fb84963d6e03eee3752cf6074b"
# the .osim's implant meshes (not public) and the prosthesis surface each is made from
FEMORAL_SOURCE = "Femoral_Component_simpler.stl"
INSERT_SOURCE = "Tibial_Insert_simpler_superior.stl"
FEMORAL_THICKNESS = 0.006   # m, femoral component shell (display)
INSERT_DEPTH = 0.008        # m, insert base below the lowest point of its articular surface
ATTRIBUTION = ("Bone geometry from opensim-org/opensim-models (Geometry/, commit 20a888b9), "
               "OpenSim models by Delp et al. 1990, Anderson & Pandy 1999, Hamner et al. 2010, "
               "Rajagopal et al. 2016; gait-model geometry under CC BY 3.0.")


class MeshError(Exception):
    def __init__(self, path, reason):
        super().__init__("%s: %s" % (path, reason))


# ------------------------------------------------------------------------------------------------
# reading
# ------------------------------------------------------------------------------------------------

VTK_TYPES = {"Float32": "<f4", "Float64": "<f8", "Int32": "<i4", "Int64": "<i8",
             "UInt32": "<u4", "UInt64": "<u8"}


def data_array(path, elem, header_type):
    """Values of one VTK DataArray (ascii or uncompressed base64 binary) as a 1-D numpy array."""
    typ = elem.get("type")
    if typ not in VTK_TYPES:
        raise MeshError(path, "DataArray type %s not supported" % typ)
    fmt = elem.get("format", "ascii")
    text = elem.text or ""
    if fmt == "ascii":
        return np.array(text.split(), dtype=VTK_TYPES[typ])
    if fmt == "binary":
        raw = base64.b64decode("".join(text.split()))
        hdr = np.dtype(VTK_TYPES[header_type]).itemsize
        nbytes = int(np.frombuffer(raw[:hdr], dtype=VTK_TYPES[header_type])[0])
        if len(raw) < hdr + nbytes:
            raise MeshError(path, "binary DataArray shorter than its header says")
        return np.frombuffer(raw[hdr:hdr + nbytes], dtype=VTK_TYPES[typ]).copy()
    raise MeshError(path, "DataArray format %s not supported (ascii or binary only)" % fmt)


def read_vtp(path):
    """Vertices (n x 3, float64) and triangles (m x 3, int) of a VTK PolyData file."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        raise MeshError(path, str(e))
    if root.tag != "VTKFile" or root.get("type") != "PolyData":
        raise MeshError(path, "not a VTKFile of type PolyData")
    header_type = root.get("header_type", "UInt32")
    pieces = root.findall("PolyData/Piece")
    if len(pieces) != 1:
        raise MeshError(path, "%d Pieces (one expected)" % len(pieces))
    piece = pieces[0]
    for kind in ("Verts", "Lines", "Strips"):
        if int(piece.get("NumberOf" + kind, "0")) != 0:
            raise MeshError(path, "has %s (only Polys are converted)" % kind)
    if piece.find(".//AppendedData") is not None or root.find("AppendedData") is not None:
        raise MeshError(path, "appended data not supported")
    pts = piece.find("Points/DataArray")
    if pts is None or int(pts.get("NumberOfComponents", "0")) != 3:
        raise MeshError(path, "no 3-component Points")
    if root.get("compressor") and pts.get("format") == "binary":
        raise MeshError(path, "compressed binary data not supported")
    v = data_array(path, pts, header_type).astype(np.float64)
    npts = int(piece.get("NumberOfPoints"))
    if v.size != 3 * npts:
        raise MeshError(path, "%d point values for %d points" % (v.size, npts))
    v = v.reshape(-1, 3)
    arrays = {a.get("Name"): a for a in piece.findall("Polys/DataArray")}
    if "connectivity" not in arrays or "offsets" not in arrays:
        raise MeshError(path, "Polys without connectivity/offsets")
    conn = data_array(path, arrays["connectivity"], header_type).astype(np.int64)
    offs = data_array(path, arrays["offsets"], header_type).astype(np.int64)
    if offs.size != int(piece.get("NumberOfPolys")) or (offs.size and offs[-1] != conn.size):
        raise MeshError(path, "offsets do not match connectivity")
    if conn.size and (conn.min() < 0 or conn.max() >= npts):
        raise MeshError(path, "vertex index out of range")
    tris = []
    start = 0
    for end in offs:
        poly = conn[start:end]
        # fan triangulation of quads and n-gons
        for k in range(1, len(poly) - 1):
            tris.append((poly[0], poly[k], poly[k + 1]))
        start = end
    f = np.array(tris, dtype=np.int64).reshape(-1, 3)
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    return v, f[keep]


def read_ascii_stl(path):
    """Vertices (merged, n x 3) and triangles (m x 3) of an ASCII STL file."""
    try:
        with open(path, encoding="ascii") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as e:
        raise MeshError(path, "not a readable ASCII STL (%s)" % e)
    nums = re.findall(r"vertex\s+(\S+)\s+(\S+)\s+(\S+)", text)
    if not nums or len(nums) % 3:
        raise MeshError(path, "%d vertices (a positive multiple of 3 expected)" % len(nums))
    corners = np.array(nums, dtype=np.float64)
    v, inv = np.unique(np.round(corners, 9), axis=0, return_inverse=True)
    return v, inv.reshape(-1, 3)


# ------------------------------------------------------------------------------------------------
# implant solids from open surfaces
# ------------------------------------------------------------------------------------------------

def face_normals(v, f):
    return np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])


def boundary_edges(f):
    """Directed edges (a, b) of the faces whose reverse edge is in no face."""
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    have = {(int(a), int(b)) for a, b in edges}
    return [(int(a), int(b)) for a, b in edges if (int(b), int(a)) not in have]


def close_surface(v, f, inner):
    """A closed solid from an open surface (faces f oriented outward) and a copy of its vertices
    `inner` (same order) on the other side: outer faces, reversed inner faces, and a wall of two
    triangles on every boundary edge, so every edge is used once in each direction."""
    n = len(v)
    walls = []
    for a, b in boundary_edges(f):
        walls.append((b, a, a + n))
        walls.append((b, a + n, b + n))
    faces = np.concatenate([f, f[:, ::-1] + n, np.array(walls, dtype=np.int64).reshape(-1, 3)])
    return np.concatenate([v, inner]), faces


def orient_outward(v, f, outward):
    """Flip the faces whose normal points against outward(face centroids) (m x 3)."""
    c = v[f].mean(axis=1)
    flip = np.einsum("ij,ij->i", face_normals(v, f), outward(c)) < 0
    f = f.copy()
    f[flip] = f[flip][:, ::-1]
    return f


def femoral_solid(v, f):
    """The femoral component's articular surface thickened inwards. Outward = away from the
    component's medial-lateral (z) axis through the surface's mean x, y."""
    cx, cy = v[:, 0].mean(), v[:, 1].mean()
    f = orient_outward(v, f, lambda c: np.stack([c[:, 0] - cx, c[:, 1] - cy,
                                                 np.zeros(len(c))], axis=1))
    vn = np.zeros_like(v)
    fn = face_normals(v, f)
    for k in range(3):
        np.add.at(vn, f[:, k], fn)
    vn /= np.maximum(np.linalg.norm(vn, axis=1, keepdims=True), 1e-12)
    return close_surface(v, f, v - FEMORAL_THICKNESS * vn)


def insert_solid(v, f):
    """The insert's superior surface (normals up, +y) extruded down to a flat base."""
    f = orient_outward(v, f, lambda c: np.tile([0.0, 1.0, 0.0], (len(c), 1)))
    inner = v.copy()
    inner[:, 1] = v[:, 1].min() - INSERT_DEPTH
    return close_surface(v, f, inner)


# ------------------------------------------------------------------------------------------------
# writing
# ------------------------------------------------------------------------------------------------

def stl_bytes(v, f, header):
    """Binary STL: 80-byte header, count, per triangle normal + 3 vertices (float32) + 0."""
    tri = v[f].astype(np.float32)
    n = face_normals(v, f)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    rec = np.zeros(len(f), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                           ("a", "<u2")]))
    rec["n"] = n.astype(np.float32)
    rec["v"] = tri
    head = header.encode("ascii")[:80].ljust(80, b" ")
    if head.lstrip().lower().startswith(b"solid"):
        raise ValueError("a binary STL header must not start with 'solid'")
    return head + struct.pack("<I", len(f)) + rec.tobytes()


def readme_text(rows, total):
    lines = [
        "# meshes/: display geometry of the JW models (GENERATED, do not edit)",
        "",
        "Written by `%s` (the command below); every file here is derived, none is a copy." % SCRIPT,
        "Binary STL, metres, in the frame of the body that carries it, unscaled: the models'",
        "`<mesh scale>` applies JW_AllBody_scaled.osim's per-body scale factors",
        "(`scripts/osim2mjcf.py`, which writes them as visual-only geoms: class `bone` / `implant`,",
        "group 1, contype = conaffinity = 0, in bodies with explicit `<inertial>`, so masses,",
        "inertias and all physics are those of the model without meshes).",
        "",
        "```sh",
        "/usr/bin/python3 scripts/make_bone_meshes.py --geometry ../shared/data/geometry \\",
        "    --osim ../shared/data/jw/model/JW_AllBody_scaled.osim \\",
        "    --prosthesis ../shared/data/jw/prosthesis --out mjmodels/meshes",
        "```",
        "",
        "then the models with the commands of mjmodels/README.md (`osim2mjcf.py` reads meshes/",
        "next to its `--out` and fails naming a missing file; `make_gait2d.py` keeps the assets and",
        "geoms). Check that the meshes change no physics: `ctest -R render` (tests/test_render.c,",
        "`display_meshes_should_change_no_physics`: each model against a copy without its meshes,",
        "body masses, inertias and 200 steps of stock MuJoCo and of gaitsim's physics compared",
        "bit for bit).",
        "",
        "## Provenance and licence",
        "",
        "- **Bones** (all files but the two implant files): converted from the VTK PolyData files",
        "  `Geometry/<name>.vtp` of **opensim-org/opensim-models** at commit",
        "  `%s`: the meshes JW_AllBody_scaled.osim (Knee Grand Challenge subject JW," % SOURCE_COMMIT,
        "  Fregly et al. 2012; redistributed by gilserrancoli/ReducePoly_forMSK, MIT) attaches to",
        "  its bodies, plus `sacrum` and `l_pelvis` (not referenced by the .osim, whose pelvis is",
        "  the right half only). Polygons fan-triangulated, no decimation, no smoothing.",
        "- **Licence**: the repository has no licence file. The 15 meshes its generic gait models",
        "  use (bofoot, femur_l, femur_r, fibula, foot, hat_jaw, hat_skull, hat_spine, l_bofoot,",
        "  l_foot, pat, pelvis, talus, tibia_l, tibia_r) are under **CC BY 3.0** (Delp et al.,",
        "  credits of gait2392_thelen2003muscle.osim); the others come from the Hamner 2010 and",
        "  Rajagopal 2016 full-body models, which give credits but state no licence. Attribution:",
        "  \"%s\"" % ATTRIBUTION,
        "- **Implant** (`femoral_component.stl`, `tibial_insert.stl`): JW's own implant meshes",
        "  (femoral_component.vtp, tibial_tray.vtp) are not public. Made from the prosthesis",
        "  surfaces `%s` (the femoral articular surface, thickened %.0f mm" % (
            FEMORAL_SOURCE, 1000 * FEMORAL_THICKNESS),
        "  inwards, rim closed) and `%s` (the insert's superior surface," % INSERT_SOURCE,
        "  extruded to a flat base %.0f mm below its lowest point; an insert, not the metal tray)," % (
            1000 * INSERT_DEPTH),
        "  Knee Grand Challenge JW (Fregly et al. 2012) as redistributed by",
        "  gilserrancoli/ReducePoly_forMSK (MIT). They are in JW's femoral_component / tibial_tray",
        "  frames already (mjmodels/knee/README.md, \"Frames\"). Display only: the knee's contact",
        "  physics uses mjmodels/knee/, not these files.",
        "",
        "## Files",
        "",
        "| file | source | triangles | bytes |",
        "|---|---|---|---|",
    ]
    for name, source, ntri, nbytes in rows:
        lines.append("| %s.stl | %s | %d | %d |" % (name, source, ntri, nbytes))
    lines += ["", "Total: %d files, %d triangles, %d bytes." % (
        len(rows), sum(r[2] for r in rows), total), ""]
    return "\n".join(lines)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    shared = os.path.join(here, "..", "..", "shared", "data")
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--geometry", default=os.path.join(shared, "geometry"))
    ap.add_argument("--osim", default=os.path.join(shared, "jw", "model",
                                                   "JW_AllBody_scaled.osim"))
    ap.add_argument("--prosthesis", default=os.path.join(shared, "jw", "prosthesis"))
    ap.add_argument("--out", default=os.path.join(here, "..", "mjmodels", "meshes"))
    ap.add_argument("--max-bytes", type=int, default=5000000)
    a = ap.parse_args()
    try:
        try:
            names = [name for _, name, _ in osim_meshes(a.osim)]
        except (OSError, ET.ParseError) as e:
            raise MeshError(a.osim, str(e))
        names += [n for lst in EXTRA_MESHES.values() for n in lst]
        os.makedirs(a.out, exist_ok=True)
        rows, total = [], 0
        for name in names:
            if name in IMPLANT_MESHES:
                continue
            src = os.path.join(a.geometry, name + ".vtp")
            v, f = read_vtp(src)
            data = stl_bytes(v, f, "gaitsim %s from opensim-models Geometry/%s.vtp %s" % (
                SCRIPT, name, SOURCE_COMMIT[:8]))
            write_atomic(os.path.join(a.out, name + ".stl"), data)
            rows.append((name, "Geometry/%s.vtp" % name, len(f), len(data)))
            total += len(data)
        for name, source, make in ((IMPLANT_MESHES["femoral_component"], FEMORAL_SOURCE,
                                    femoral_solid),
                                   (IMPLANT_MESHES["tibial_tray"], INSERT_SOURCE, insert_solid)):
            v, f = make(*read_ascii_stl(os.path.join(a.prosthesis, source)))
            data = stl_bytes(v, f, "gaitsim %s from JW prosthesis %s" % (SCRIPT, source))
            write_atomic(os.path.join(a.out, name + ".stl"), data)
            rows.append((name, "prosthesis/%s (solid)" % source, len(f), len(data)))
            total += len(data)
        if total > a.max_bytes:
            raise MeshError(a.out, "%d bytes of meshes, more than --max-bytes %d" % (
                total, a.max_bytes))
        write_atomic(os.path.join(a.out, "README.md"), readme_text(rows, total))
    except MeshError as e:
        print("make_bone_meshes.py: %s" % e, file=sys.stderr)
        sys.exit(1)
    print("wrote %d meshes, %d triangles, %d bytes to %s" % (
        len(rows), sum(r[2] for r in rows), total, a.out))


if __name__ == "__main__":
    main()
