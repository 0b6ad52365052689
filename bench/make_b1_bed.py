#!/usr/bin/env python3
"""Write the initial particle bed of benchmark scene B1 as a LAMMPS data file.

Scene B1 (the full specification is in the header of bench/peers.sh):
  * 45,000 spheres, diameter 5 mm, density 2500 kg/m^3
  * simple cubic lattice, spacing 5.25 mm, 30 x 30 x 50 sites, site centres at
    (i + 1/2) * spacing, so the lattice fills 0 <= x, y <= 0.1575 m and
    0 <= z <= 0.2625 m
  * every site is shifted in x and y (never z) by a uniform jitter in
    [-0.1 mm, +0.1 mm) drawn from numpy.random.default_rng(12345)

Output format (atom_style sphere, as read by LAMMPS and LIGGGHTS `read_data`,
and by the regolith_twin engine's bed reader):

    <title line>
    <blank>
    45000 atoms
    2 atom types
    <blank>
    0 0.1575 xlo xhi
    0 0.1575 ylo yhi
    0 0.4 zlo zhi
    <blank>
    Atoms # sphere
    <blank>
    id type diameter density x y z      (one line per atom, ids 1..N)

All grains are type 1.  Type 2 is declared but unused by any atom: the
LIGGGHTS deck uses it as the wall material so that grain-wall contacts can be
given their own damping coefficient.

The file is written byte-for-byte deterministically: fixed seed, fixed atom
order (x fastest, then y, then z), fixed number formatting.
"""

import argparse
import os
import sys

import numpy as np

# Scene constants (SI units).
N_X, N_Y, N_Z = 30, 30, 50
SPACING = 5.25e-3          # m
DIAMETER = 5.0e-3          # m
DENSITY = 2500.0           # kg/m^3
JITTER = 1.0e-4            # m, half-width of the uniform x/y jitter
SEED = 12345
BOX_X = N_X * SPACING      # 0.1575 m
BOX_Y = N_Y * SPACING      # 0.1575 m
BOX_Z = 0.40               # m, leaves headroom above the 0.2625 m lattice
N_TYPES = 2


def build_positions():
    """Return an (N, 3) array of initial centres in id order."""
    rng = np.random.default_rng(SEED)
    ix = np.arange(N_X)
    iy = np.arange(N_Y)
    iz = np.arange(N_Z)
    # id order: x fastest, then y, then z
    gz, gy, gx = np.meshgrid(iz, iy, ix, indexing="ij")
    pos = np.empty((N_X * N_Y * N_Z, 3), dtype=np.float64)
    pos[:, 0] = (gx.ravel() + 0.5) * SPACING
    pos[:, 1] = (gy.ravel() + 0.5) * SPACING
    pos[:, 2] = (gz.ravel() + 0.5) * SPACING
    jitter = rng.uniform(-JITTER, JITTER, size=(pos.shape[0], 2))
    pos[:, 0:2] += jitter
    return pos


def format_bed(pos):
    lines = []
    lines.append("regolith_twin benchmark bed B1: %d spheres d=%g m rho=%g kg/m^3, "
                 "cubic lattice a=%g m, xy jitter +-%g m, seed %d"
                 % (pos.shape[0], DIAMETER, DENSITY, SPACING, JITTER, SEED))
    lines.append("")
    lines.append("%d atoms" % pos.shape[0])
    lines.append("%d atom types" % N_TYPES)
    lines.append("")
    lines.append("0 %.10g xlo xhi" % BOX_X)
    lines.append("0 %.10g ylo yhi" % BOX_Y)
    lines.append("0 %.10g zlo zhi" % BOX_Z)
    lines.append("")
    lines.append("Atoms # sphere")
    lines.append("")
    for i in range(pos.shape[0]):
        lines.append("%d 1 %.10g %.10g %.10f %.10f %.10f"
                     % (i + 1, DIAMETER, DENSITY, pos[i, 0], pos[i, 1], pos[i, 2]))
    lines.append("")
    return "\n".join(lines)


def main(argv=None):
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default=os.path.join(here, "b1_bed.data"),
                    help="output data file (default: bench/b1_bed.data)")
    args = ap.parse_args(argv)

    pos = build_positions()
    # sanity: nothing may touch a side wall or the floor initially
    r = 0.5 * DIAMETER
    assert pos[:, 0].min() - r > 0 and pos[:, 0].max() + r < BOX_X
    assert pos[:, 1].min() - r > 0 and pos[:, 1].max() + r < BOX_Y
    assert pos[:, 2].min() - r > 0 and pos[:, 2].max() + r < BOX_Z

    text = format_bed(pos)
    tmp = args.output + ".tmp"
    with open(tmp, "w", newline="\n") as fh:
        fh.write(text)
    os.replace(tmp, args.output)
    print("wrote %s (%d atoms)" % (args.output, pos.shape[0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
