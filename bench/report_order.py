#!/usr/bin/python3
"""Convergence order in the time step (docs/bench/order.md): the lander's
state in the first 0.5 s of the default landing at halved time steps, from
the series bench/order_landing.sh keeps in results/bench/order/ (all runs on one
relaxed bed). Prints the error of each step against the finest with the
observed order log2(e(2h) / e(h)) at several times, and the difference made
by a 1e-11 m/s change of the impact speed (perturbed.csv, Δt = 2.5e-5 s);
plots docs/bench/order_landing.png.

    bench/report_order.py
"""
import csv
import glob
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
from plots import pyplot  # noqa: E402
KEEP = os.path.join(ROOT, "results", "bench", "order")
VEL = ["vx", "vy", "vz"]
OMEGA = ["wx", "wy", "wz"]
TIMES = [0.02, 0.03, 0.04, 0.05, 0.1, 0.2, 0.5]


def read(path):
    return {round(float(r["t"]), 3): r for r in csv.DictReader(open(path))}


def err(a, b, keys):
    return math.sqrt(sum((float(a[k]) - float(b[k])) ** 2 for k in keys))


def main():
    runs = {}
    for f in glob.glob(os.path.join(KEEP, "dt_*.csv")):
        runs[float(os.path.basename(f)[3:-4])] = read(f)
    runs = dict(sorted(runs.items()))
    dts = list(runs)
    fine = dts[0]
    pert_path = os.path.join(KEEP, "perturbed.csv")
    pert = read(pert_path) if os.path.exists(pert_path) else None
    print(f"Reference Δt = {fine:g} s; the lander's velocity error (m/s) against it, observed order in brackets"
          + ("; last column: the same run at Δt = 2.5e-5 s against itself with the impact speed 1e-11 m/s higher."
             if pert else "."))
    print()
    print("| t (s) | " + " | ".join(f"Δt = {d:g} s" for d in reversed(dts[1:])) + (" | perturbed speed |" if pert else " |"))
    print("|---|" + "---|" * (len(dts) - 1 + (1 if pert else 0)))
    for t in TIMES:
        if not all(t in runs[d] for d in dts):
            continue
        es = [err(runs[d][t], runs[fine][t], VEL) for d in reversed(dts[1:])]
        cells = []
        for k, e in enumerate(es):
            o = f" ({math.log2(es[k - 1] / e):.2f})" if k > 0 and e > 0 and es[k - 1] > 0 else ""
            cells.append(f"{e:.2g}{o}")
        if pert and 2.5e-5 in runs and t in pert:
            cells.append(f"{err(pert[t], runs[2.5e-5][t], VEL):.2g}")
        print(f"| {t:g} | " + " | ".join(cells) + " |")
    try:
        plt = pyplot()
    except ImportError:
        return
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4))
    ts = sorted(t for t in runs[fine] if 0 < t <= 0.5)
    for d in dts[1:]:
        a.semilogy(ts, [max(err(runs[d][t], runs[fine][t], VEL), 1e-16) for t in ts], "o-", ms=3, label=f"Δt = {d:g} s")
    if pert and 2.5e-5 in runs:
        a.semilogy(ts, [max(err(pert[t], runs[2.5e-5][t], VEL), 1e-16) for t in ts], "k--",
                   label="impact speed +1e-11 m/s")
    a.set_xlabel("time (s)")
    a.set_ylabel("lander velocity difference (m/s)")
    a.set_title(f"against Δt = {fine:g} s (contact at 0.013 s)", fontsize=9)
    a.legend(fontsize=7)
    xs = dts[1:]
    for t in (0.02, 0.03, 0.04):
        b.loglog(xs, [err(runs[d][t], runs[fine][t], VEL) for d in xs], "o-", label=f"t = {t:g} s")
    ref_e = err(runs[xs[0]][0.03], runs[fine][0.03], VEL)
    for p, style in ((1, ":"), (2, "--")):
        b.loglog(xs, [ref_e * (x / xs[0]) ** p for x in xs], "k" + style, lw=0.8, label=f"order {p}")
    b.set_xlabel("Δt (s)")
    b.set_title("velocity error against Δt in the first contacts", fontsize=9)
    b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "docs", "bench", "order_landing.png"), dpi=110)


if __name__ == "__main__":
    main()
