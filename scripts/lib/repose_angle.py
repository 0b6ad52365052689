#!/usr/bin/env python3
"""Angle of repose of a fixed-base cone from a final_grains.txt file.

The cone is what stands on the base disk (radius R, base plane z0): grains
with centre above z0 and within R of the axis. Its surface h(r) is the
highest grain top (z + radius) in each 1-grain-diameter radial bin. Two
estimates are reported:
  fit   : atan of minus the slope of a least-squares line through h(r) over
          0.15 R <= r <= 0.85 R (the flank, away from apex and rim);
  cone  : atan((h_apex - z_rim) / R), the fixed-base cone formula, with
          h_apex the surface height in the central bin and z_rim the top of
          the base grains.
usage: repose_angle.py FINAL_GRAINS [--radius 0.25] [--base-top 0.01] [--png FILE --title T]
"""
import argparse
import math

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("final")
    ap.add_argument("--radius", type=float, default=0.25)
    ap.add_argument("--base-top", type=float, default=0.01)
    ap.add_argument("--bin", type=float, default=0.02)
    ap.add_argument("--png")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    d = np.loadtxt(a.final)
    x, y, z, r = d[:, 1], d[:, 2], d[:, 3], d[:, 4]
    rho = np.hypot(x, y)
    pile = (z > a.base_top) & (rho < a.radius)
    edges = np.arange(0, a.radius + 1e-12, a.bin)
    centres, tops = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = pile & (rho >= lo) & (rho < hi)
        if sel.any():
            centres.append(0.5 * (lo + hi))
            tops.append(np.max(z[sel] + r[sel]))
    centres, tops = np.array(centres), np.array(tops)
    flank = (centres >= 0.15 * a.radius) & (centres <= 0.85 * a.radius)
    slope, icpt = np.polyfit(centres[flank], tops[flank], 1)
    fit = math.degrees(math.atan(-slope))
    cone = math.degrees(math.atan((tops[0] - a.base_top) / a.radius))
    print(f"grains_on_base={int(pile.sum())} angle_fit_deg={fit:.2f} angle_cone_deg={cone:.2f} "
          f"apex_height={tops[0]:.4f}")
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.4))
        side = np.abs(y) < 0.03
        ax.scatter(x[pile & side], z[pile & side], s=4, c="0.5", label="grains within 3 cm of the x-z plane")
        ax.plot(centres, tops, "o-", ms=3, label="surface h(r)")
        rr = np.linspace(0.15 * a.radius, 0.85 * a.radius, 2)
        ax.plot(rr, slope * rr + icpt, "r-", lw=2, label=f"flank fit: {fit:.1f}°")
        ax.set_xlim(-a.radius * 1.05, a.radius * 1.05)
        ax.set_aspect("equal")
        ax.set_xlabel("x, r (m)")
        ax.set_ylabel("z (m)")
        ax.set_title(a.title)
        ax.legend(fontsize=7, loc="upper right")
        fig.tight_layout()
        fig.savefig(a.png, dpi=110)


if __name__ == "__main__":
    main()
