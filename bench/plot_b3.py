#!/usr/bin/python3
"""Sampler shot with the stiffness schedule against the shot with every saving
off, one bed: horn-segment counts, crater depth and ejected grains over time
(docs/bench/b3_schedule.md). Prints the values at the given times.

    bench/plot_b3.py REF_DIR SCHEDULE_DIR OUT.png [T ...]
"""
import argparse
import os
import sys


sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts", "lib"))
from csv_columns import read_rows  # noqa: E402
from plots import pyplot  # noqa: E402

plt = pyplot()


def series(d):
    rows = read_rows(os.path.join(d, "series.csv"))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def at(s, key, t):
    i = min(range(len(s["t"])), key=lambda k: abs(s["t"][k] - t))
    return s[key][i]


ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("ref", metavar="REF_DIR")
ap.add_argument("schedule", metavar="SCHEDULE_DIR")
ap.add_argument("out", metavar="OUT.png")
ap.add_argument("times", metavar="T", type=float, nargs="*", default=[0.05, 0.1, 0.2])
args = ap.parse_args()
ref, sch = series(args.ref), series(args.schedule)
out = args.out
times = args.times
t_end = min(ref["t"][-1], sch["t"][-1])
fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
for k, c in zip(range(1, 4), ["C0", "C1", "C2"]):
    ax[0].plot(ref["t"], ref[f"seg{k}_n"], c, label=f"segment {k}, all off")
    ax[0].plot(sch["t"], sch[f"seg{k}_n"], c + "--", label=f"segment {k}, schedule")
ax[0].set_ylabel("grains in the horn segment")
ax[1].plot(ref["t"], [1e3 * v for v in ref["crater_depth"]], "k", label="all off")
ax[1].plot(sch["t"], [1e3 * v for v in sch["crater_depth"]], "r--", label="schedule")
ax[1].set_ylabel("crater depth (mm)")
ax[2].plot(ref["t"], ref["ejected_grains"], "k", label="all off")
ax[2].plot(sch["t"], sch["ejected_grains"], "r--", label="schedule")
ax[2].set_ylabel("ejected grains")
for a in ax:
    a.set_xlim(0, t_end)
    a.set_xlabel("time after firing (s)")
    a.legend(fontsize=7)
fig.suptitle("Sampler shot, 300 m/s: stiffness schedule against everything off (one bed)")
fig.tight_layout()
fig.savefig(out, dpi=110)
for t in times:
    if t > t_end + 1e-9:
        continue
    segs = lambda s: "/".join(str(int(at(s, f"seg{k}_n", t))) for k in range(1, 6))
    print(f"t = {t:g} s: horn segments {segs(ref)} (off) vs {segs(sch)} (schedule); "
          f"crater depth {1e3 * at(ref, 'crater_depth', t):.0f} vs {1e3 * at(sch, 'crater_depth', t):.0f} mm; "
          f"ejected {at(ref, 'ejected_grains', t):.0f} vs {at(sch, 'ejected_grains', t):.0f}")
