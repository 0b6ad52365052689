#!/usr/bin/python3
"""Plots of one bucket impact (docs/scenes.md C.1): OUT/impact.png from OUT/impact.csv.
  scripts/plot_impact.py OUT"""
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
    rows = read_rows(os.path.join(out, "impact.csv"))
    t = [float(r["t"]) * 1e3 for r in rows]
    s = json.load(open(os.path.join(out, "summary.json")))
    r = s["result"]
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    ax[0].plot(t, [float(x["depth"]) * 100 for x in rows])
    ax[0].axhline(r["stopping_depth"] * 100, color="k", ls="--", lw=0.8,
                  label="z_stop = %.3g cm" % (r["stopping_depth"] * 100))
    ax[0].set_ylabel("depth below the surface (cm)")
    ax[0].legend(fontsize=8)
    ax[1].plot(t, [float(x["vz"]) for x in rows])
    ax[1].set_ylabel("v_z (m/s)")
    ax[2].plot(t, [float(x["az"]) for x in rows], lw=0.8)
    ax[2].set_ylabel("a_z (m/s²)")
    ax[2].set_xlabel("t (ms)")
    ax[0].set_title("%.2g m/s: f0 = %.3g N, 1/d1 = %.3g 1/m, %s" % (
        s["input"]["speed"], r["f0"], r["inv_d1"], "bounced" if r["bounced"] else "no bounce"))
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "impact.png"), dpi=110)


if __name__ == "__main__":
    main()
