#!/usr/bin/env python3
"""Plots of one sampler shot (the output folder of regolith_sim on a sampler scene).

usage: plot_sampler.py RUN_DIR

Reads RUN_DIR/summary.json, series.csv, ejecta.csv, energy_partition.csv and
wave.csv (docs/scenes.md B) and writes into RUN_DIR:
  horn.png     grains per horn segment and the collected mass against time
               (the 100 mg requirement marked)
  crater.png   crater depth and radius against time after impact, ejected volume
  ejecta.png   ejection-angle histogram (6 deg bins), launch speed against
               launch position (normalised by R and sqrt(g R))
  energy.png   energy partition over the first 0.2 ms after impact
  wave.png     largest grain speed against distance from the impact point at
               each capture (log-log; four of them if there are more): the
               bins fitted (filled), the power law over them, the wave front
               (dotted), the precursor beyond it (open) with its median
               (dashed) and the noise floor
  wave_front.png  (runs with more than two wave captures) the wave front and
               the last bin above the noise floor against time after impact,
               with the front's speed fitted by least squares
"""
import argparse
import json
import os
import sys

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from csv_columns import read_csv  # noqa: E402
from plots import pyplot, save_figure  # noqa: E402

plt = pyplot()


def plot_wave(d, caps):
    """wave.png: each capture's profile, fitted range, power law, front and precursor (docs/scenes.md B.4);
    of more than four captures, four evenly spread (the first and the last among them)."""
    if len(caps) > 4:
        caps = [caps[i] for i in np.unique(np.round(np.linspace(0, len(caps) - 1, 4)).astype(int))]
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for q, c in enumerate(caps):
        col = "C%d" % q
        dist = np.array(c["distance"]) * 1e3
        v = np.array(c["max_speed"])
        used = np.array(c.get("bins_used", []), dtype=int)
        pre = np.array(c.get("precursor_bins", []), dtype=int)
        shown = v > 0
        ax.loglog(dist[shown], v[shown], "-", color=col, lw=0.6, alpha=0.5)
        slope = c.get("slope")
        lab = "%.3g µs" % (c["t"] * 1e6)
        if slope is not None and len(used):
            lab += ": slope %.2f over %.1f–%.1f mm" % (slope, c["fit_from"] * 1e3, c["fit_to"] * 1e3)
        ax.loglog(dist[used], v[used], "o", color=col, ms=3.5, label=lab)
        if len(pre):
            ax.loglog(dist[pre], v[pre], "o", mfc="none", color=col, ms=4,
                      label="precursor (%d bins, median %.2g m/s)" % (len(pre), c["precursor_median"]))
            ax.hlines(c["precursor_median"], dist[pre[0]], dist[pre[-1]], colors=col, linestyles="--", lw=1)
        if slope is not None and len(used) >= 2:
            x = np.array([dist[used[0]], dist[used[-1]]])
            ax.loglog(x, np.exp(c["intercept"]) * (x * 1e-3) ** slope, "-", color="k", lw=1.2)
        if c.get("front") is not None:
            how = "break" if c["front_method"] == "break" else "last bin above the floor"
            ax.axvline(c["front"] * 1e3, color=col, ls=":", lw=1.2,
                       label="front %.1f mm (%s)" % (c["front"] * 1e3, how))
    ax.axhline(caps[0]["floor"], color="0.5", ls="-.", lw=0.8, label="noise floor")
    ax.set_xlabel("distance from the impact point (mm)")
    ax.set_ylabel("largest grain speed in the bin (m/s)")
    ax.legend(fontsize=7)
    save_figure(fig, os.path.join(d, "wave.png"))


def plot_front_track(d, caps, bin_width, floor=None):
    """wave_front.png: front and last bin above the floor against time; the front's speed fitted by
    least squares over the captures with a break up to the one where the front is farthest. floor: the
    container floor's depth under the impact point, m (drawn if given)."""
    t = np.array([c["t_actual"] for c in caps]) * 1e6
    front = np.array([np.nan if c.get("front") is None else c["front"] for c in caps]) * 1e3
    end = np.array([(c["signal_end"] + 1) * bin_width * 1e3 if c["signal_end"] >= 0 else np.nan for c in caps])
    brk = np.array([c["front_method"] == "break" for c in caps])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(t[brk], front[brk], "o", ms=4, label="front (break)")
    if (~brk).any():
        ax.plot(t[~brk], front[~brk], "x", ms=5, label="front (last bin above the floor)")
    ax.plot(t, end, "s", mfc="none", ms=4, color="0.4", label="last bin above the floor (precursor reach)")
    ok = brk & np.isfinite(front)
    if ok.any():
        ok &= t <= t[ok][np.argmax(front[ok])]
    if ok.sum() >= 3:
        p = np.polyfit(t[ok], front[ok], 1)
        ax.plot(t[ok], np.polyval(p, t[ok]), "k-", lw=0.8,
                label="least squares to the farthest front: %.0f m/s, %.0f mm at impact" % (p[0] * 1e3, p[1]))
    if floor is not None:
        ax.axhline(floor * 1e3, color="0.3", ls="--", lw=0.8, label="container floor under the impact point")
    ax.set_xlabel("time after impact (µs)")
    ax.set_ylabel("distance from the impact point (mm)")
    ax.legend(fontsize=8)
    save_figure(fig, os.path.join(d, "wave_front.png"))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir", metavar="RUN_DIR", help="the shot's output folder")
    d = p.parse_args().dir
    summ = json.load(open(os.path.join(d, "summary.json")))
    obs = summ.get("observers", {})
    t_imp = obs.get("t_impact", 0.0) if obs.get("impact") else 0.0
    s = read_csv(os.path.join(d, "series.csv"))
    if s is not None:
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        for k in range(1, 6):
            ax[0].plot(s["t"] * 1e3, s["seg%d_n" % k], label="cylinder %d" % k)
        ax[0].set_xlabel("time after firing (ms)")
        ax[0].set_ylabel("grains in segment")
        ax[0].legend()
        ax[1].plot(s["t"] * 1e3, s["collected_mass"] * 1e6, label="collected")
        req = summ.get("collection", {}).get("requirement", 1e-4)
        ax[1].axhline(req * 1e6, color="r", ls="--", label="requirement")
        ax[1].set_xlabel("time after firing (ms)")
        ax[1].set_ylabel("collected mass (mg)")
        ax[1].legend()
        save_figure(fig, os.path.join(d, "horn.png"))
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        ta = (s["t"] - t_imp) * 1e3
        ax[0].plot(ta, s["crater_depth"] * 1e3, label="depth")
        ax[0].plot(ta, s["crater_radius"] * 1e3, label="radius")
        ax[0].set_xlabel("time after impact (ms)")
        ax[0].set_ylabel("crater (mm)")
        ax[0].legend()
        ax[1].plot(ta, s["ejected_volume"] * 1e6)
        ax[1].set_xlabel("time after impact (ms)")
        ax[1].set_ylabel("ejected volume (cm$^3$)")
        save_figure(fig, os.path.join(d, "crater.png"))
    e = read_csv(os.path.join(d, "ejecta.csv"))
    if e is not None:
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        ax[0].hist(e["angle"], bins=np.arange(0, 96, 6), edgecolor="k")
        ax[0].set_xlabel("ejection angle from horizontal (deg)")
        ax[0].set_ylabel("grains")
        ax[1].loglog(e["r_launch_over_R"], e["speed_over_sqrt_gR"], ".", ms=3)
        ax[1].set_xlabel("launch position r / R")
        ax[1].set_ylabel("launch speed / sqrt(g R)")
        save_figure(fig, os.path.join(d, "ejecta.png"))
    en = read_csv(os.path.join(d, "energy_partition.csv"))
    if en is not None:
        fig, ax = plt.subplots(figsize=(7, 4.5))
        tcol = "t" if "t" in en else list(en)[0]
        for k, v in en.items():
            if k == tcol or not np.issubdtype(v.dtype, np.number) or np.max(np.abs(v)) < 1e-3:
                continue
            ax.plot(en[tcol] * 1e3, v, label=k)
        ax.set_xlabel("time after impact (ms)")
        ax.set_ylabel("energy / projectile's initial kinetic energy")
        ax.legend(fontsize=7)
        save_figure(fig, os.path.join(d, "energy.png"))
    wave = obs.get("wave", {})
    caps = sorted((v for v in wave.values() if isinstance(v, dict)), key=lambda c: c["t"])
    if caps and all("front_method" in c for c in caps):
        plot_wave(d, caps)
        if len(caps) > 2:
            bed, imp = summ.get("bed", {}), summ.get("input", {}).get("impact_point")
            floor = imp[2] - (bed["surface_top"] - bed["depth"]) if imp and "depth" in bed else None
            plot_front_track(d, caps, wave["bin"], floor)
    else:
        w = read_csv(os.path.join(d, "wave.csv"))  # a run from before the front search (no fit range drawn)
        if w is not None:
            fig, ax = plt.subplots(figsize=(6, 4.5))
            for t in np.unique(w["t"]):
                k = (w["t"] == t) & (w["max_speed"] > 0)
                ax.loglog(w["distance_mid"][k] * 1e3, w["max_speed"][k], "o-", ms=3, label="%.3g ms" % (t * 1e3))
            ax.set_xlabel("distance from the impact point (mm)")
            ax.set_ylabel("largest grain speed (m/s)")
            ax.legend()
            save_figure(fig, os.path.join(d, "wave.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
