#!/usr/bin/env python3
"""The Hayabusa2 sampler horn (docs/scenes.md B) as a URDF with STL meshes.

usage: make_horn.py [--out DIR] [--around N] [--check]

Writes DIR/urdf/sampler_horn.urdf and DIR/urdf/meshes/sampler_horn/*.stl
(DIR defaults to the package root, the parent of this script's folder):

  cylinder_1.stl .. cylinder_5.stl  the five segments of the horn, each a
                                    closed thin shell of revolution: inner and
                                    outer surface plus the flat annular rims
  filter_1.stl .. filter_4.stl      the four plates of the filter near the top
                                    of cylinder 4

The horn frame (root link cylinder_1) has its origin at the centre of the
bottom aperture, z up along the axis. Each segment link has its frame at the
segment's bottom centre; the filter link at the filter's bottom centre.

The per-segment dimensions are not published; the values below are chosen to
match what is (deployed length 1007 mm, bottom aperture 138 mm across, a horn
narrowing upwards, a filter near the top of cylinder 4 that stops grains of
1 cm and more, cylinder 4 narrowing like a bottleneck around it, the top of
cylinder 5 open). Change them here; the URDF header lists them.

Meshes: binary STL, float32 coordinates in metres rounded to 0.1 micrometre
first (so the output does not depend on the last bit of a trigonometric
function), triangles counter-clockwise seen from outside, every vertex computed
once and shared by its triangles. Output is deterministic: --check regenerates
everything into a temporary folder and compares it byte by byte with the files
in DIR (exit status 1 and the differing files named when they differ).

Needs python3 and numpy only.
"""
import argparse
import filecmp
import math
import os
import struct
import sys
import tempfile

import numpy as np

# ----------------------------------------------------------------- parameters

WALL = 0.001              # wall thickness, radial, m
AROUND = 64               # facets around the axis (a multiple of 4: mirror symmetric in x and y)
DENSITY = 2700.0          # kg/m^3 (aluminium); the horn is fixed in a scene, the mass only satisfies the reader

# Filter: FILTER_PLATES parallel plates across the neck of cylinder 4, their
# long side along x, FILTER_THICK thick (y) and FILTER_HEIGHT tall (z),
# leaving FILTER_PLATES + 1 slots of FILTER_SLOT (y): a sphere passes a slot
# when its diameter is below the slot width. The outer slots are circular
# segments of the neck whose height (sagitta) is also FILTER_SLOT, so the neck
# radius follows: 2 R = (n + 1) slot + n thick.
FILTER_PLATES = 4
FILTER_SLOT = 0.0095      # m: 1 cm grains stop, 0.9 cm grains pass
FILTER_THICK = 0.002      # m
FILTER_HEIGHT = 0.010     # m
FILTER_Z = 0.835          # bottom of the plates in the horn frame, m (15 mm below the top of cylinder 4)
NECK_R = 0.5 * ((FILTER_PLATES + 1) * FILTER_SLOT + FILTER_PLATES * FILTER_THICK)  # 0.02775 m

# Segments, bottom to top: inner wall profile as (z in the horn frame, inner
# radius) points, m. Consecutive segments meet at a common rim.
SEGMENTS = [
    ("cylinder_1", [(0.000, 0.0690), (0.220, 0.0630)]),
    ("cylinder_2", [(0.220, 0.0630), (0.440, 0.0540)]),
    ("cylinder_3", [(0.440, 0.0540), (0.640, 0.0430)]),
    # bottleneck: a gentle cone, a steep shoulder, a straight neck holding the filter
    ("cylinder_4", [(0.640, 0.0430), (0.770, 0.0400), (0.800, NECK_R), (0.860, NECK_R)]),
    ("cylinder_5", [(0.860, NECK_R), (1.007, 0.0240)]),
]

MESH_DIR = "urdf/meshes/sampler_horn"
URDF_FILE = "urdf/sampler_horn.urdf"
PACKAGE_URI = "package://regolith_twin/" + MESH_DIR

# --------------------------------------------------------------------- meshes


def quantise(v):
    """Coordinates rounded to 0.1 micrometre, as float32 (what the STL holds)."""
    return (np.round(np.asarray(v, dtype=np.float64) * 1e7) / 1e7).astype(np.float32)


def quads(tris, a, b, c, d):
    """Quad a b c d (counter-clockwise seen from outside) as two triangles."""
    tris.append((a, b, c))
    tris.append((a, c, d))


def shell_mesh(profile, z0, wall, n):
    """Closed thin shell of revolution about z: inner surface through the
    profile points (z, r), outer surface at r + wall, flat annular rims at the
    first and last z. Coordinates relative to z0."""
    m = len(profile)
    th = 2 * math.pi * np.arange(n) / n
    c, s = np.cos(th), np.sin(th)
    verts = []
    for off in (0.0, wall):  # inner rings, then outer rings
        for z, r in profile:
            verts.extend(zip((r + off) * c, (r + off) * s, np.full(n, z - z0)))
    inner = lambda k, j: k * n + j % n  # noqa: E731
    outer = lambda k, j: (m + k) * n + j % n  # noqa: E731
    tris = []
    for j in range(n):
        for k in range(m - 1):
            # outer surface: +theta then +z is counter-clockwise seen from outside
            quads(tris, outer(k, j), outer(k, j + 1), outer(k + 1, j + 1), outer(k + 1, j))
            # inner surface faces the axis
            quads(tris, inner(k, j), inner(k + 1, j), inner(k + 1, j + 1), inner(k, j + 1))
        # bottom rim faces -z, top rim +z
        quads(tris, inner(0, j), inner(0, j + 1), outer(0, j + 1), outer(0, j))
        t = m - 1
        quads(tris, inner(t, j), outer(t, j), outer(t, j + 1), inner(t, j + 1))
    return quantise(verts), np.array(tris, dtype=np.int64)


def plate_mesh(y0, y1, z0, z1, rim):
    """A filter plate between y0 and y1 (y0 < y1), z0 and z1 (filter frame),
    across the bore: its ends lie on the circle of radius `rim` (mid-wall), so
    they are buried in the wall. A hexahedron with planar faces."""
    xe = lambda y: math.sqrt(rim * rim - y * y)  # noqa: E731
    verts = []
    for z in (z0, z1):
        for y in (y0, y1):
            for sx in (-1, 1):
                verts.append((sx * xe(y), y, z))
    v = lambda sx, y, z: 4 * z + 2 * y + (sx > 0)  # noqa: E731  (indices: z, y, x bits)
    tris = []
    quads(tris, v(-1, 0, 0), v(-1, 1, 0), v(1, 1, 0), v(1, 0, 0))   # bottom, -z
    quads(tris, v(-1, 0, 1), v(1, 0, 1), v(1, 1, 1), v(-1, 1, 1))   # top, +z
    quads(tris, v(-1, 0, 0), v(1, 0, 0), v(1, 0, 1), v(-1, 0, 1))   # y0 face, -y
    quads(tris, v(-1, 1, 0), v(-1, 1, 1), v(1, 1, 1), v(1, 1, 0))   # y1 face, +y
    quads(tris, v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1))     # +x end
    quads(tris, v(-1, 0, 0), v(-1, 0, 1), v(-1, 1, 1), v(-1, 1, 0))  # -x end
    return quantise(verts), np.array(tris, dtype=np.int64)


def check_mesh(name, verts, tris):
    """Closed and consistently wound outwards: every directed edge once, its
    reverse once; positive signed volume."""
    edges = {}
    for t in tris:
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    for (a, b), k in edges.items():
        if k != 1 or edges.get((b, a)) != 1:
            raise SystemExit(f"{name}: edge {a}-{b} not shared by exactly two opposite triangles")
    p = verts.astype(np.float64)[tris]
    vol = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6
    if not vol > 0:
        raise SystemExit(f"{name}: signed volume {vol} is not positive")


def mass_properties(verts, tris, density):
    """Mass, centre of mass and inertia tensor about it of a closed mesh."""
    p = verts.astype(np.float64)[tris]  # (T, 3 vertices, 3)
    det = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2]))
    vol = det.sum() / 6
    com = (det[:, None] * p.sum(axis=1)).sum(axis=0) / 24 / vol
    s = p.sum(axis=1)
    # second moments of each tetrahedron (origin, a, b, c): det/120 (sum p p^T + s s^T)
    cov = (np.einsum("t,tki,tkj->ij", det, p, p) + np.einsum("t,ti,tj->ij", det, s, s)) / 120
    cov *= density
    mass = density * vol
    inertia = np.trace(cov) * np.eye(3) - cov
    inertia -= mass * (com @ com * np.eye(3) - np.outer(com, com))
    return mass, com, inertia


def stl_bytes(title, verts, tris):
    header = title.encode("ascii")[:80].ljust(80, b" ")
    out = [header, struct.pack("<I", len(tris))]
    for t in tris:
        a, b, c = (verts[i].astype(np.float64) for i in t)
        n = np.cross(b - a, c - a)
        n = n / np.linalg.norm(n)
        out.append(struct.pack("<3f", *n))
        for q in (verts[t[0]], verts[t[1]], verts[t[2]]):
            out.append(q.astype("<f4").tobytes())
        out.append(b"\0\0")
    return b"".join(out)


# ----------------------------------------------------------------------- URDF


def g(x):
    """Numbers in the URDF: 9 significant digits, -0 written as 0."""
    s = f"{x:.9g}"
    return "0" if s in ("0", "-0") else s


def build(n):
    """The meshes and the URDF text: {relative path: bytes}."""
    files = {}
    links = []  # (name, parent, joint origin z, [(collision name, mesh file)], mass, com, inertia)
    z_prev = 0.0
    for k, (name, prof) in enumerate(SEGMENTS):
        z0 = prof[0][0]
        verts, tris = shell_mesh(prof, z0, WALL, n)
        check_mesh(name, verts, tris)
        files[f"{MESH_DIR}/{name}.stl"] = stl_bytes(f"sampler_horn {name} (scripts/make_horn.py)", verts, tris)
        m, c, inertia = mass_properties(verts, tris, DENSITY)
        parent = SEGMENTS[k - 1][0] if k else None
        links.append((name, parent, z0 - z_prev, [(name, f"{name}.stl")], m, c, inertia))
        z_prev = z0
    # filter plates, symmetric about y = 0, in the filter frame (bottom centre)
    pitch = FILTER_SLOT + FILTER_THICK
    rim = NECK_R + 0.5 * WALL
    plates, mass, first = [], 0.0, np.zeros(3)
    tot_cov = np.zeros((3, 3))
    parts = []
    for i in range(FILTER_PLATES):
        yc = (i - 0.5 * (FILTER_PLATES - 1)) * pitch
        pname = f"filter_{i + 1}"
        verts, tris = plate_mesh(yc - 0.5 * FILTER_THICK, yc + 0.5 * FILTER_THICK, 0.0, FILTER_HEIGHT, rim)
        check_mesh(pname, verts, tris)
        files[f"{MESH_DIR}/{pname}.stl"] = stl_bytes(f"sampler_horn {pname} (scripts/make_horn.py)", verts, tris)
        parts.append(mass_properties(verts, tris, DENSITY))
        plates.append((pname, f"{pname}.stl"))
    mass = sum(p[0] for p in parts)
    com = sum(p[0] * p[1] for p in parts) / mass
    inertia = np.zeros((3, 3))
    for m, c, i_c in parts:
        d = c - com
        inertia += i_c + m * (d @ d * np.eye(3) - np.outer(d, d))
    z4 = SEGMENTS[3][1][0][0]
    links.append(("filter", "cylinder_4", FILTER_Z - z4, plates, mass, com, inertia))
    files[URDF_FILE] = urdf_text(links, n).encode("utf-8")
    return files


def urdf_text(links, n):
    seg_rows = []
    for name, prof in SEGMENTS:
        pts = ", ".join(f"({z * 1000:.1f}, {2 * r * 1000:.2f})" for z, r in prof)
        seg_rows.append(f"    {name}: {pts}")
    total = sum(l[4] for l in links)
    lines = [
        '<?xml version="1.0"?>',
        "<!--",
        "  Hayabusa2 sampler horn (docs/scenes.md B) as one fixed rigid body.",
        "  Generated by scripts/make_horn.py: do not edit; change the parameters there and",
        "  run it again (its check option tells whether these files are current).",
        "",
        "  Frame of the root link cylinder_1: origin at the centre of the bottom",
        "  aperture, z up along the axis. Place the body (fixed: true) with its bottom",
        "  edge 5 mm above the bed surface. Each segment link has its frame at the",
        "  segment's bottom centre; the filter link at the bottom centre of its plates.",
        "",
        "  Per-segment dimensions are NOT published; these are an approximation fitted",
        "  to the published ones (deployed length 1007 mm, bottom aperture 138 mm).",
        "  Segments as inner wall profile points (z in the horn frame mm, inner diameter mm):",
        *seg_rows,
        f"  Walls: closed thin shells, {WALL * 1000:g} mm radial thickness (outer radius = inner + {WALL * 1000:g} mm),",
        f"  {n} facets around, flat annular rims; the top of cylinder_5 is open.",
        f"  Filter: {FILTER_PLATES} parallel plates along x, {FILTER_THICK * 1000:g} mm thick (y), "
        f"{FILTER_HEIGHT * 1000:g} mm tall, bottom at z = {FILTER_Z * 1000:g} mm,",
        f"  across the straight neck of cylinder_4 (inner diameter {2 * NECK_R * 1000:g} mm), ends buried in the wall:",
        f"  {FILTER_PLATES + 1} slots {FILTER_SLOT * 1000:g} mm wide (the outer two circular segments {FILTER_SLOT * 1000:g} mm high),",
        "  so spheres of 1 cm stop and spheres of 0.9 cm pass.",
        f"  Mass: {DENSITY:g} kg/m^3 (aluminium) times the mesh volumes, {total:.4f} kg in all; a fixed",
        "  body ignores it. Products of inertia are zero by the mirror symmetry in x and y.",
        "-->",
        '<robot name="sampler_horn">',
    ]
    for name, parent, jz, cols, m, c, inertia in links:
        if parent:
            lines += [
                f'  <joint name="{parent}_to_{name}" type="fixed">',
                f'    <parent link="{parent}"/>',
                f'    <child link="{name}"/>',
                f'    <origin xyz="0 0 {g(jz)}" rpy="0 0 0"/>',
                "  </joint>",
            ]
        lines += [
            f'  <link name="{name}">',
            "    <inertial>",
            f'      <origin xyz="0 0 {g(c[2])}" rpy="0 0 0"/>',
            f'      <mass value="{g(m)}"/>',
            f'      <inertia ixx="{g(inertia[0, 0])}" ixy="0" ixz="0" iyy="{g(inertia[1, 1])}" iyz="0" izz="{g(inertia[2, 2])}"/>',
            "    </inertial>",
        ]
        for cname, file in cols:
            for tag in ("visual", "collision"):
                lines += [
                    f'    <{tag} name="{cname}">',
                    '      <origin xyz="0 0 0" rpy="0 0 0"/>',
                    f'      <geometry><mesh filename="{PACKAGE_URI}/{file}"/></geometry>',
                    f"    </{tag}>",
                ]
        lines.append("  </link>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def write(files, out):
    for rel, data in sorted(files.items()):
        path = os.path.join(out, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data)


def check(files, out):
    """Compare freshly generated files (written to a temporary folder) with those in `out`."""
    bad = []
    with tempfile.TemporaryDirectory(prefix="make_horn_") as tmp:
        write(files, tmp)
        for rel in sorted(files):
            mine, theirs = os.path.join(tmp, rel), os.path.join(out, rel)
            if not os.path.isfile(theirs) or not filecmp.cmp(mine, theirs, shallow=False):
                bad.append(rel)
        mesh_dir = os.path.join(out, MESH_DIR)
        if os.path.isdir(mesh_dir):
            for f in sorted(os.listdir(mesh_dir)):
                if f"{MESH_DIR}/{f}" not in files:
                    bad.append(f"{MESH_DIR}/{f} (not generated)")
    return bad


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                    help="package root to write into (default: this script's package)")
    ap.add_argument("--around", type=int, default=AROUND, help="facets around the axis, a multiple of 4")
    ap.add_argument("--check", action="store_true",
                    help="regenerate into a temporary folder and compare byte by byte with the files in --out")
    args = ap.parse_args()
    if args.around < 8 or args.around % 4:
        ap.error("--around must be a multiple of 4, at least 8")
    files = build(args.around)
    if args.check:
        bad = check(files, args.out)
        if bad:
            print("make_horn.py --check: differ from a fresh generation:\n  " + "\n  ".join(bad), file=sys.stderr)
            return 1
        print(f"make_horn.py --check: {len(files)} files identical to a fresh generation")
        return 0
    write(files, args.out)
    size = sum(len(d) for d in files.values())
    print(f"wrote {len(files)} files ({size} bytes) under {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
