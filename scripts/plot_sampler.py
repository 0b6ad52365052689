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
  wave.png     largest grain speed against distance from the impact point
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from csv_columns import read_csv  # noqa: E402


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    d = sys.argv[1]
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
        fig.tight_layout()
        fig.savefig(os.path.join(d, "horn.png"), dpi=110)
        plt.close(fig)
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
        fig.tight_layout()
        fig.savefig(os.path.join(d, "crater.png"), dpi=110)
        plt.close(fig)
    e = read_csv(os.path.join(d, "ejecta.csv"))
    if e is not None:
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        ax[0].hist(e["angle"], bins=np.arange(0, 96, 6), edgecolor="k")
        ax[0].set_xlabel("ejection angle from horizontal (deg)")
        ax[0].set_ylabel("grains")
        ax[1].loglog(e["r_launch_over_R"], e["speed_over_sqrt_gR"], ".", ms=3)
        ax[1].set_xlabel("launch position r / R")
        ax[1].set_ylabel("launch speed / sqrt(g R)")
        fig.tight_layout()
        fig.savefig(os.path.join(d, "ejecta.png"), dpi=110)
        plt.close(fig)
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
        fig.tight_layout()
        fig.savefig(os.path.join(d, "energy.png"), dpi=110)
        plt.close(fig)
    w = read_csv(os.path.join(d, "wave.csv"))
    if w is not None:
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for t in np.unique(w["t"]):
            k = (w["t"] == t) & (w["max_speed"] > 0)
            ax.loglog(w["distance_mid"][k] * 1e3, w["max_speed"][k], "o-", ms=3, label="%.3g ms" % (t * 1e3))
        ax.set_xlabel("distance from the impact point (mm)")
        ax.set_ylabel("largest grain speed (m/s)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(d, "wave.png"), dpi=110)
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
