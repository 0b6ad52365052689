#!/usr/bin/python3
"""Plots of one plume-erosion run (docs/scenes.md D): OUT/erosion.png from OUT/erosion.csv.
  scripts/plot_plume.py OUT"""
import argparse
import json
import os
import sys


sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from csv_columns import read_rows  # noqa: E402
from plots import pyplot  # noqa: E402

plt = pyplot()


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", metavar="OUT", help="the run's output folder")
    out = p.parse_args().out
    rows = read_rows(os.path.join(out, "erosion.csv"))
    t = [float(r["t"]) for r in rows]
    col = lambda k: [float(r[k]) for r in rows]  # noqa: E731
    s = json.load(open(os.path.join(out, "summary.json")))
    e = s["observers"]["erosion"]
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    ax[0].plot(t, col("above"), lw=1.2)
    if e["erosion_rate"] > 0:
        t_end = e["depleted_at"] if e["depleted_at"] > 0 else t[-1]
        ax[0].plot([0, t_end], [e["fit_intercept"], e["fit_intercept"] + e["erosion_rate"] * t_end], "k--", lw=0.8,
                   label="fit: %.4g grains/s" % e["erosion_rate"])
    if e["depleted_at"] > 0:
        ax[0].axvline(e["depleted_at"], color="r", lw=0.8, label="depleted (%.0f %%)" % (100 * e["depleted_fraction"]))
    ax[0].set_ylabel("N above the erosion plane")
    ax[0].legend(fontsize=8)
    ax[1].plot(t, col("up_per_step"), label="upward")
    ax[1].plot(t, col("down_per_step"), label="downward")
    ax[1].set_ylabel("crossings per step\n(%d-step average)" % e["window_steps"])
    ax[1].legend(fontsize=8)
    ax[2].plot(t, col("pairs_per_grain"), label="contacts per grain above")
    ax[2].plot(t, col("touching_fraction"), label="fraction in contact")
    ax[2].set_ylabel("collisions above the plane")
    ax[2].set_xlabel("t (s)")
    ax[2].legend(fontsize=8)
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "erosion.png"), dpi=110)


if __name__ == "__main__":
    main()
