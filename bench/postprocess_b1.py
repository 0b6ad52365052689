#!/usr/bin/env python3
"""Physics cross-check for benchmark scene B1, identical for every engine.

Input: a LAMMPS-style text dump ("dump custom" layout), of which only the
LAST snapshot is used:

    ITEM: TIMESTEP
    <step>
    ITEM: NUMBER OF ATOMS
    <N>
    ITEM: BOX BOUNDS ...
    <3 lines>
    ITEM: ATOMS id x y z radius [vx vy vz] [omegax omegay omegaz]
    <N lines, whitespace separated, any order>

Columns are located by name from the "ITEM: ATOMS" header, so extra columns
and any column order are accepted.  LAMMPS and LIGGGHTS write this with
    dump ID all custom 1 FILE id x y z radius vx vy vz omegax omegay omegaz
and the regolith_twin engine writes the same layout.

Definitions (SI units):

  bed_height   height below which 99 % of grain CENTRES lie: the 99th
               percentile of the centre z coordinates (numpy.percentile,
               linear interpolation), measured from the floor z = 0.
  z_mean       mean centre height (for a uniform bed ~ half its height).
  coordination mean number of grain-grain contacts per grain,
               Z = 2 * P / N, where P is the number of unordered grain pairs
               (i, j) with |x_i - x_j| < r_i + r_j (strictly positive
               overlap).  Wall contacts are NOT included in Z.
  wall_contacts_per_grain
               number of grain-wall contacts divided by N; a grain touches a
               plane wall when its centre is closer than its radius to the
               plane (the B1 walls: x = 0, x = Lx, y = 0, y = Ly, z = 0;
               override with --walls).
  ke           translational kinetic energy  sum 1/2 m v^2          [J]
  ke_rot       rotational kinetic energy    sum 1/2 (2/5 m r^2) w^2 [J]
               with m = density * 4/3 pi r^3 (density from --density,
               default 2500 kg/m^3); printed as "nan" when the dump lacks
               the velocity / angular velocity columns.

Output: one line of key=value pairs on stdout, e.g.
    n=45000 step=36000 bed_height=0.19 z_mean=0.097 coordination=4.7 ...

The pair search bins grains into cubic cells of edge 2 * max(radius) and
compares every grain with the grains in its own and the 26 surrounding
cells, vectorised with numpy; no other dependency is needed.
"""

import argparse
import sys

import numpy as np

B1_LX = 0.1575
B1_LY = 0.1575


def read_last_snapshot(path):
    """Return (step, column-name list, float array N x ncol) of the last snapshot."""
    with open(path, "r") as fh:
        lines = fh.readlines()
    starts = [i for i, ln in enumerate(lines) if ln.startswith("ITEM: TIMESTEP")]
    if not starts:
        raise ValueError("%s: no 'ITEM: TIMESTEP' found, not a dump file" % path)
    i = starts[-1]
    step = int(lines[i + 1].split()[0])
    j = i + 2
    natoms = None
    cols = None
    while j < len(lines):
        ln = lines[j]
        if ln.startswith("ITEM: NUMBER OF ATOMS"):
            natoms = int(lines[j + 1].split()[0])
            j += 2
        elif ln.startswith("ITEM: BOX BOUNDS"):
            j += 4
        elif ln.startswith("ITEM: ATOMS"):
            cols = ln.split()[2:]
            j += 1
            break
        else:
            j += 1
    if natoms is None or cols is None:
        raise ValueError("%s: incomplete last snapshot" % path)
    body = lines[j:j + natoms]
    if len(body) != natoms:
        raise ValueError("%s: last snapshot truncated (%d of %d atoms)"
                         % (path, len(body), natoms))
    data = np.array([ln.split()[:len(cols)] for ln in body], dtype=np.float64)
    return step, cols, data


def count_contact_pairs(pos, rad):
    """Number of unordered pairs with centre distance < r_i + r_j."""
    n = pos.shape[0]
    if n < 2:
        return 0
    cell = 2.0 * float(rad.max())
    lo = pos.min(axis=0)
    idx = np.floor((pos - lo) / cell).astype(np.int64) + 1   # one empty layer of padding
    dims = idx.max(axis=0) + 2
    key = (idx[:, 0] * dims[1] + idx[:, 1]) * dims[2] + idx[:, 2]
    order = np.argsort(key, kind="stable")
    counts = np.bincount(key, minlength=int(np.prod(dims)))
    start = np.zeros_like(counts)
    start[1:] = np.cumsum(counts)[:-1]
    max_per_cell = int(counts.max())
    all_i = np.arange(n)
    pairs = 0
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                nkey = key + (dx * dims[1] + dy) * dims[2] + dz
                s = start[nkey]
                c = counts[nkey]
                for k in range(max_per_cell):
                    sel = c > k
                    if not sel.any():
                        break
                    i = all_i[sel]
                    j = order[s[sel] + k]
                    keep = j > i
                    i = i[keep]
                    j = j[keep]
                    d = pos[i] - pos[j]
                    r2 = np.einsum("ij,ij->i", d, d)
                    rs = rad[i] + rad[j]
                    pairs += int(np.count_nonzero(r2 < rs * rs))
    return pairs


def count_wall_contacts(pos, rad, walls):
    """walls: list of (axis, position, side) with side +1 for a lower wall
    (grains above it) and -1 for an upper wall."""
    total = 0
    for axis, w, side in walls:
        gap = side * (pos[:, axis] - w)
        total += int(np.count_nonzero(gap < rad))
    return total


def parse_walls(spec):
    """'xlo=0,xhi=0.1575,ylo=0,yhi=0.1575,zlo=0' -> wall list."""
    walls = []
    if not spec or spec == "none":
        return walls
    for item in spec.split(","):
        name, val = item.split("=")
        name = name.strip().lower()
        axis = "xyz".index(name[0])
        side = +1 if name[1:] == "lo" else -1
        walls.append((axis, float(val), side))
    return walls


def analyse(path, density, walls):
    step, cols, data = read_last_snapshot(path)
    col = {name: k for k, name in enumerate(cols)}
    for need in ("x", "y", "z", "radius"):
        if need not in col:
            raise ValueError("%s: dump lacks column '%s' (has %s)" % (path, need, cols))
    pos = data[:, [col["x"], col["y"], col["z"]]].copy()
    rad = data[:, col["radius"]].copy()
    n = pos.shape[0]
    mass = density * (4.0 / 3.0) * np.pi * rad ** 3

    out = {}
    out["n"] = n
    out["step"] = step
    out["bed_height"] = float(np.percentile(pos[:, 2], 99.0))
    out["z_mean"] = float(pos[:, 2].mean())
    pairs = count_contact_pairs(pos, rad)
    out["contacts"] = pairs
    out["coordination"] = 2.0 * pairs / n
    out["wall_contacts_per_grain"] = count_wall_contacts(pos, rad, walls) / n
    if all(c in col for c in ("vx", "vy", "vz")):
        v = data[:, [col["vx"], col["vy"], col["vz"]]]
        out["ke"] = float(0.5 * np.sum(mass * np.einsum("ij,ij->i", v, v)))
    else:
        out["ke"] = float("nan")
    if all(c in col for c in ("omegax", "omegay", "omegaz")):
        w = data[:, [col["omegax"], col["omegay"], col["omegaz"]]]
        inertia = 0.4 * mass * rad ** 2
        out["ke_rot"] = float(0.5 * np.sum(inertia * np.einsum("ij,ij->i", w, w)))
    else:
        out["ke_rot"] = float("nan")
    return out


def format_result(res):
    parts = []
    for k in ("n", "step", "bed_height", "z_mean", "coordination", "contacts",
              "wall_contacts_per_grain", "ke", "ke_rot"):
        v = res[k]
        if isinstance(v, int):
            parts.append("%s=%d" % (k, v))
        else:
            parts.append("%s=%.6g" % (k, v))
    return " ".join(parts)


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="B1 cross-check: bed height, coordination, kinetic energy from a dump")
    ap.add_argument("dump", help="LAMMPS-style text dump (last snapshot is used)")
    ap.add_argument("--density", type=float, default=2500.0,
                    help="grain density in kg/m^3 (default 2500)")
    ap.add_argument("--walls", default="xlo=0,xhi=%g,ylo=0,yhi=%g,zlo=0" % (B1_LX, B1_LY),
                    help="plane walls as axis{lo,hi}=position list, or 'none' "
                         "(default: the B1 box, open top)")
    args = ap.parse_args(argv)
    res = analyse(args.dump, args.density, parse_walls(args.walls))
    print(format_result(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
