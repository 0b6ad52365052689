#!/usr/bin/env python3
"""Plots of one MASCOT landing run (the output folder of regolith_land).

usage: plot_landing.py RUN_DIR [--rim Z] [--map-cell M]

Reads RUN_DIR/summary.json, series.csv and surface.csv and writes into RUN_DIR:
  trajectory.png  centre-of-mass height above the trim plane, horizontal
                  distance from the start, lowest corner with the trim plane
  energy.png      centre-of-mass speed, translational/rotational energy
  force.png       force on the lander (components and magnitude)
  surface.png     height map of the bed surface after the landing (crater/trace)
First contact and lift-off (summary.json outcome) are marked when they
happened; a run without contact or lift-off is plotted without the marks.
--rim sets the trim plane height when summary.json is missing (default 0.30 m).
"""
import argparse
import json
import os
import sys
import warnings

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from csv_columns import read_csv  # noqa: E402
from plots import pyplot  # noqa: E402

plt = pyplot()


def save(fig, path):
    """path written whole: a temporary name unique to the process, then renamed
    (docs/files.md, outputs), so a stopped run never leaves part of a plot."""
    tmp = f"{path}.tmp.{os.getpid()}"
    fig.savefig(tmp, dpi=100, format="png")
    os.replace(tmp, path)


def load_summary(run):
    path = os.path.join(run, "summary.json")
    if not os.path.exists(path):
        return {}
    with open(path) as f:
        return json.load(f)


def events(summary):
    """(label, time, colour) of first contact and lift-off, only those that happened."""
    oc = summary.get("outcome", {})
    out = []
    if oc.get("contact"):
        out.append(("first contact", oc.get("t_contact", 0.0), "tab:red"))
    if oc.get("lifted_off"):
        out.append(("lift-off", oc.get("t_liftoff", 0.0), "tab:green"))
    return out


def mark(ax, evs, legend=True):
    for lab, t, c in evs:
        ax.axvline(t, color=c, ls=":", lw=1.2, label=lab if legend else None)


def title(summary, run):
    inp = summary.get("input", {})
    oc = summary.get("outcome", {})
    parts = [os.path.basename(os.path.normpath(run))]
    if inp:
        parts.append(f"{inp.get('attitude', '?')}, {inp.get('angle_deg', 0):g} deg, "
                     f"{inp.get('speed', 0):g} m/s, repeat {int(inp.get('repeat', 0))}")
    if oc:
        if oc.get("lifted_off"):
            parts.append(f"V_out/V_in = {oc.get('speed_ratio', 0):.3f}")
        elif oc.get("contact"):
            parts.append("no lift-off")
        else:
            parts.append("no contact")
    status = summary.get("status")
    if status and status != "ok":
        parts.append(f"status {status}")
    return " | ".join(parts)


def plot_trajectory(run, s, rim, evs, head):
    t = s["t"]
    h = s["z"] - rim
    dist = np.hypot(s["x"] - s["x"][0], s["y"] - s["y"][0])
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    ax = axes[0]
    ax.plot(t, h, label="centre-of-mass height above the trim plane")
    ax.plot(t, dist, label="horizontal distance from the start")
    mark(ax, evs)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("m")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1]
    low = s["lowest_corner"]
    ax.plot(t, 100 * low, color="tab:purple", label="lowest corner")
    ax.axhline(0.0, color="k", lw=1, label="trim plane")
    mark(ax, evs)
    if np.any(low < 0):
        i = int(np.argmin(low))
        ax.plot(t[i], 100 * low[i], "v", color="tab:purple", label=f"deepest: {100 * -low[i]:.2f} cm below")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("height above the trim plane (cm)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(head, fontsize=9)
    fig.tight_layout()
    save(fig, os.path.join(run, "trajectory.png"))
    plt.close(fig)


def plot_energy(run, s, evs, head):
    t = s["t"]
    speed = np.sqrt(s["vx"] ** 2 + s["vy"] ** 2 + s["vz"] ** 2)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    ax = axes[0]
    ax.plot(t, speed, label="centre-of-mass speed")
    mark(ax, evs)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("speed (m/s)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1]
    e_lin, e_rot = s["E_lin"], s["E_rot"]
    ax.plot(t, e_lin, label="translational")
    ax.plot(t, e_rot, label="rotational")
    ax.plot(t, e_lin + e_rot, "k--", lw=1, label="lander kinetic total")
    mark(ax, evs)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("energy (J)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(head, fontsize=9)
    fig.tight_layout()
    save(fig, os.path.join(run, "energy.png"))
    plt.close(fig)


def plot_force(run, s, evs, head):
    t = s["t"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    ax = axes[0]
    for k, c in (("fx", "tab:blue"), ("fy", "tab:orange"), ("fz", "tab:green")):
        ax.plot(t, s[k], color=c, lw=1, label=k)
    ax.plot(t, np.sqrt(s["fx"] ** 2 + s["fy"] ** 2 + s["fz"] ** 2), "k", lw=1, label="|F|")
    mark(ax, evs)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("force on the lander (N)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1]
    if "grain_contacts" in s:
        ax.plot(t, s["grain_contacts"], label="lander-grain contacts")
    mark(ax, evs)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("contacts")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(head, fontsize=9)
    fig.tight_layout()
    save(fig, os.path.join(run, "force.png"))
    plt.close(fig)


def plot_surface(run, surf, s, summary, head, map_cell=0.03):
    x, y, h = surf["x"], surf["y"], surf["height"]
    cell = np.min(np.diff(np.unique(x))) if len(np.unique(x)) > 1 else 0.01
    xs = np.round((x - x.min()) / cell).astype(int)
    ys = np.round((y - y.min()) / cell).astype(int)
    grid = np.full((ys.max() + 1, xs.max() + 1), np.nan)
    grid[ys, xs] = h
    # Cells smaller than a grain show the gaps between grains as deep holes:
    # the map takes the highest top over blocks of about map_cell instead.
    k = max(1, int(round(map_cell / cell)))
    if k > 1:
        ny, nx = -(-grid.shape[0] // k) * k, -(-grid.shape[1] // k) * k
        pad = np.full((ny, nx), np.nan)
        pad[:grid.shape[0], :grid.shape[1]] = grid
        blocks = pad.reshape(ny // k, k, nx // k, k)
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # blocks without any grain stay empty
            grid = np.nanmax(blocks, axis=(1, 3))
        x0, y0 = x.min() - cell / 2, y.min() - cell / 2
        extent = (x0, x0 + nx * cell, y0, y0 + ny * cell)
    else:
        extent = (x.min() - cell / 2, x.max() + cell / 2, y.min() - cell / 2, y.max() + cell / 2)
    fig, ax = plt.subplots(figsize=(7.2, 6))
    # Colour range: the crater and the rim around it, so that ejected grains
    # still in flight (high above, a few percent of the cells) do not wash
    # out the map; they show in the darkest red.
    lo, hi = np.nanpercentile(grid, [1, 90])
    lim = max(abs(lo), abs(hi), 1e-4)
    cmap = plt.get_cmap("RdBu_r").copy()
    cmap.set_bad("0.8")  # cells without a grain centre
    im = ax.imshow(100 * grid, origin="lower", extent=extent, cmap=cmap, vmin=-100 * lim, vmax=100 * lim,
                   interpolation="nearest")
    cb = fig.colorbar(im, ax=ax)
    cb.set_label("surface height above the trim plane (cm)")
    if s is not None:
        ax.plot(s["x"], s["y"], "k-", lw=0.8, label="centre-of-mass path")
        ax.plot(s["x"][0], s["y"][0], "ko", ms=3)
    oc = summary.get("outcome", {})
    if oc.get("contact") and s is not None:
        i = int(np.searchsorted(s["t"], oc.get("t_contact", 0.0)))
        i = min(i, len(s["t"]) - 1)
        ax.plot(s["x"][i], s["y"][i], "x", color="tab:red", ms=8, label="centre of mass at first contact")
    rc = summary.get("bed", {}).get("container_radius")
    if rc is None:
        rc = max(abs(extent[0]), abs(extent[1]))
    ax.add_patch(plt.Circle((0, 0), rc, fill=False, color="0.4", lw=0.8))
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8, loc="upper right")
    ax.set_title(head, fontsize=8)
    fig.tight_layout()
    save(fig, os.path.join(run, "surface.png"))
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description="Plots of one regolith_land run.")
    ap.add_argument("run", help="output folder of regolith_land")
    ap.add_argument("--rim", type=float, default=None, help="trim plane height (default: from summary.json, else 0.30)")
    ap.add_argument("--map-cell", type=float, default=0.03,
                    help="cell of the height map, m: the highest grain top over it (default 0.03, about 1.5 grain diameters)")
    a = ap.parse_args(argv)
    run = a.run
    summary = load_summary(run)
    rim = a.rim if a.rim is not None else summary.get("bed", {}).get("trim_plane", 0.30)
    evs = events(summary)
    head = title(summary, run)
    s = read_csv(os.path.join(run, "series.csv"))
    written = []
    if s is not None:
        plot_trajectory(run, s, rim, evs, head)
        plot_energy(run, s, evs, head)
        plot_force(run, s, evs, head)
        written += ["trajectory.png", "energy.png", "force.png"]
    else:
        print(f"plot_landing: {run}/series.csv missing or empty: no time-series plots", file=sys.stderr)
    surf = read_csv(os.path.join(run, "surface.csv"))
    if surf is not None:
        plot_surface(run, surf, s, summary, head, a.map_cell)
        written.append("surface.png")
    else:
        print(f"plot_landing: {run}/surface.csv missing or empty: no height map", file=sys.stderr)
    if not written:
        return 1
    print("plots:       " + ", ".join(os.path.join(run, w) for w in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
