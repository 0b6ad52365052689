#!/usr/bin/env python3
"""Angle of repose of a fixed-base ridge (or cone) from final_grains.txt files.

Ridge (default, config/validation/ridge_*.yaml): a strip of glued grains,
|x| <= B, between side walls at |y| <= W/2, carries a ridge whose two flanks
stand at the angle of repose. The pile is every grain with its centre above
the base plane and |x| < B. The surface is sampled on cells of one mean
grain diameter in x and y: the top of a cell is the highest grain top
(z + radius) of the grains centred in it, and h(x) is the mean of the cell
tops across the width. Each flank's angle is atan of the slope of a
least-squares line through h(x) over 0.15 B <= |x| <= 0.85 B (away from the
apex and the strip ends); a run's angle is the mean of its two flanks.

Cone (--geometry cone: config/validation/pour_*.yaml and the earlier
repose_*.yaml scenes): base disk of radius B; the surface is sampled on cells
one bin long in r and about one bin long in azimuth, h(r) is the mean of the
cell tops in each quadrant, and each quadrant's flank is fitted over
0.15 B <= r <= 0.85 B; a run's angle is the mean of its four quadrants.

Several files (one per seed) give one line each and an ensemble line with the
mean over seeds and their sample standard deviation.

usage: repose_angle.py FINAL_GRAINS... [--geometry ridge|cone] [--half-length 0.35]
                       [--width 0.2] [--base-top 0.01] [--png FILE --title T --published DEG]
"""
import argparse
import math

import numpy as np

from plots import pyplot, save_figure


def load(path):
    d = np.loadtxt(path)
    return d[:, 1], d[:, 2], d[:, 3], d[:, 4]


def fit_angle(xc, h, lo, hi):
    sel = (np.abs(xc) >= lo) & (np.abs(xc) <= hi) & np.isfinite(h)
    if sel.sum() < 3:
        return float("nan"), (0.0, 0.0)
    slope, icpt = np.polyfit(xc[sel], h[sel], 1)
    return math.degrees(math.atan(abs(slope))), (slope, icpt)


def ridge_profile(path, a):
    x, y, z, r = load(path)
    pile = (z > a.base_top) & (np.abs(x) < a.half_length)
    xe = np.arange(-a.half_length, a.half_length + 1e-12, a.bin)
    ye = np.linspace(-a.width / 2, a.width / 2, max(1, int(round(a.width / a.bin))) + 1)
    xc = 0.5 * (xe[:-1] + xe[1:])
    h = np.full(len(xc), np.nan)
    ix = np.digitize(x[pile], xe) - 1
    iy = np.digitize(y[pile], ye) - 1
    top = z[pile] + r[pile]
    for i in range(len(xc)):
        tops = []
        for j in range(len(ye) - 1):
            sel = (ix == i) & (iy == j)
            if sel.any():
                tops.append(top[sel].max())
        if tops:
            h[i] = np.mean(tops)
    lo, hi = 0.15 * a.half_length, 0.85 * a.half_length
    left, fl = fit_angle(np.where(xc < 0, xc, np.nan), np.where(xc < 0, h, np.nan), lo, hi)
    right, fr = fit_angle(np.where(xc > 0, xc, np.nan), np.where(xc > 0, h, np.nan), lo, hi)
    return dict(x=x, y=y, z=z, r=r, pile=pile, xc=xc, h=h, flanks=[left, right], fits=[fl, fr],
                n=int(pile.sum()), apex=float(np.nanmax(h)))


def cone_profile(path, a):
    x, y, z, r = load(path)
    rho = np.hypot(x, y)
    phi = np.mod(np.arctan2(y, x), 2 * math.pi)
    pile = (z > a.base_top) & (rho < a.half_length)
    edges = np.arange(0, a.half_length + 1e-12, a.bin)
    xc = 0.5 * (edges[:-1] + edges[1:])
    hq = np.full((4, len(xc)), np.nan)
    top = z + r
    for k, (lo, hi) in enumerate(zip(edges[:-1], edges[1:])):
        sel = pile & (rho >= lo) & (rho < hi)
        if not sel.any():
            continue
        # Cells about one bin long in azimuth, a multiple of 4 so quadrants align.
        n_sec = 4 * max(1, int(math.ceil(2 * math.pi * xc[k] / a.bin / 4)))
        cell = np.minimum((phi[sel] / (2 * math.pi) * n_sec).astype(int), n_sec - 1)
        tops = {}
        for c, t in zip(cell, top[sel]):
            tops[c] = max(tops.get(c, -np.inf), t)
        for q in range(4):
            vals = [t for c, t in tops.items() if c * 4 // n_sec == q]
            if vals:
                hq[q, k] = np.mean(vals)
    fits = [fit_angle(xc, hq[q], 0.15 * a.half_length, 0.85 * a.half_length) for q in range(4)]
    with np.errstate(all="ignore"):
        h = np.nanmean(hq, axis=0)
    # The line drawn in the figure is the fit of the mean profile.
    _, mean_fit = fit_angle(xc, h, 0.15 * a.half_length, 0.85 * a.half_length)
    return dict(x=x, y=y, z=z, r=r, pile=pile, xc=xc, h=h, flanks=[f[0] for f in fits],
                fits=[mean_fit], n=int(pile.sum()), apex=float(np.nanmax(h)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("final", nargs="+")
    ap.add_argument("--geometry", choices=["ridge", "cone"], default="ridge")
    ap.add_argument("--half-length", type=float, default=0.35, help="B: half length of the strip, or disk radius")
    ap.add_argument("--width", type=float, default=0.2)
    ap.add_argument("--base-top", type=float, default=0.01)
    ap.add_argument("--bin", type=float, default=0.02)
    ap.add_argument("--png")
    ap.add_argument("--title", default="")
    ap.add_argument("--published", type=float)
    a = ap.parse_args()
    profile = ridge_profile if a.geometry == "ridge" else cone_profile
    runs = [profile(p, a) for p in a.final]
    angles = []
    for path, run in zip(a.final, runs):
        ang = float(np.mean(run["flanks"]))
        run["angle"] = ang
        angles.append(ang)
        flanks = " ".join(f"{v:.2f}" for v in run["flanks"])
        print(f"file={path} grains_on_base={run['n']} flanks_deg={flanks} angle_deg={ang:.2f} "
              f"apex_height={run['apex']:.4f}")
    angles = np.array(angles)
    allf = np.array([v for run in runs for v in run["flanks"]])
    spread = float(np.std(angles, ddof=1)) if len(angles) > 1 else 0.0
    print(f"ensemble runs={len(angles)} mean_deg={angles.mean():.2f} std_deg={spread:.2f} "
          f"flank_min_deg={allf.min():.2f} flank_max_deg={allf.max():.2f} "
          f"grains_on_base_mean={np.mean([r['n'] for r in runs]):.0f}")
    if a.png:
        plot(a, runs, angles, spread)


def plot(a, runs, angles, spread):
    plt = pyplot()
    B = a.half_length
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    first = runs[0]
    side = first["pile"] & (np.abs(first["y"]) < 0.02)
    xs = first["x"][side] if a.geometry == "ridge" else np.abs(first["x"][side])
    ax.scatter(xs, first["z"][side], s=3, c="0.6",
               label="grains within 2 cm of the mid-plane (first seed)")
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown"]
    for k, (run, ang) in enumerate(zip(runs, angles)):
        c = colours[k % len(colours)]
        ax.plot(run["xc"], run["h"], "-", color=c, lw=1.2, label=f"surface, seed {k + 1}: {ang:.1f}°")
        for (slope, icpt) in run["fits"]:
            if slope == 0:
                continue
            sgn = math.copysign(1.0, -slope) if a.geometry == "ridge" else 1.0
            xx = np.array([0.15 * B, 0.85 * B]) * sgn
            ax.plot(xx, slope * xx + icpt, "--", color=c, lw=1.6)
    if a.published is not None:
        # Drawn through the measured surface at half the base radius (the apex is rounded).
        anchors = []
        for run in runs:
            ok = np.isfinite(run["h"]) & (run["xc"] > 0)
            anchors.append(np.interp(0.5 * B, run["xc"][ok], run["h"][ok]))
        z_mid = float(np.mean(anchors))
        xx = np.array([0.0, B])
        t = math.tan(math.radians(a.published))
        for sgn in ((-1, 1) if a.geometry == "ridge" else (1,)):
            ax.plot(sgn * xx, z_mid - t * (xx - 0.5 * B), "k:", lw=1.3,
                    label=f"published {a.published:g}° (through the surface at r = R/2)" if sgn == 1 else None)
    ax.set_xlim(-B * 1.05 if a.geometry == "ridge" else 0, B * 1.05)
    ax.set_ylim(bottom=0)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)" if a.geometry == "ridge" else "r (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"{a.title}: {angles.mean():.1f}° ± {spread:.1f}° over {len(angles)} seeds", fontsize=10)
    ax.legend(fontsize=6.5, loc="upper right", framealpha=0.8)
    save_figure(fig, a.png)


if __name__ == "__main__":
    main()
