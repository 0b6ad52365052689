#!/usr/bin/env python3
"""Plot a run's series.csv: energies, contacts and the motion of tracked groups.
usage: plot_series.py RUN_DIR  (writes RUN_DIR/series.png)"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from csv_columns import read_rows  # noqa: E402
from plots import pyplot  # noqa: E402

plt = pyplot()


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run", metavar="RUN_DIR", help="a run's output folder (with series.csv)")
    run = p.parse_args().run
    rows = read_rows(os.path.join(run, "series.csv"))
    if not rows:
        return
    t = [float(r["t"]) for r in rows]
    col = lambda k: [float(r[k]) for r in rows]
    groups = sorted({k[:-2] for k in rows[0] if k.endswith("_z") and k[:-2] + "_vz" in rows[0]})
    fig, axes = plt.subplots(1, 2 + (1 if groups else 0), figsize=(13 if groups else 9, 3.6))
    ax = axes[0]
    for k, lab in (("E_trans", "translational"), ("E_rot", "rotational"), ("E_elastic", "elastic")):
        ax.plot(t, col(k), label=lab)
    ax.set_yscale("symlog", linthresh=1e-6)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("energy (J)")
    ax.legend(fontsize=8)
    ax = axes[1]
    ax.plot(t, col("coordination"), label="coordination number")
    ax.plot(t, [100 * x for x in col("max_overlap_ratio")], label="max overlap (% of radius)")
    ax.set_xlabel("t (s)")
    ax.legend(fontsize=8)
    if groups:
        ax = axes[2]
        for g in groups:
            ax.plot(t, col(g + "_z"), label=f"{g}: z (m)")
            ax.plot(t, col(g + "_vz"), "--", label=f"{g}: v_z (m/s)")
        ax.set_xlabel("t (s)")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{run}/series.png", dpi=100)


if __name__ == "__main__":
    main()
