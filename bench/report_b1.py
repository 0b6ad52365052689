#!/usr/bin/env python3
"""Turn the raw lines of scripts/bench (RESULT/CHECK/STATE/VERSION/MICRO) into
docs/benchmarks.md figures: medians, ratios and a bar plot.

usage: report_b1.py RAW_LINES_FILE PLOT_PNG > table.md
"""
import argparse
import re
import statistics
import os
import sys
from collections import defaultdict

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts", "lib"))
from plots import pyplot  # noqa: E402


def parse(path):
    rows = []
    for line in open(path):
        line = line.strip()
        m = re.match(r"^(RESULT|CHECK|STATE|VERSION|MICRO|SETTLE|TRIAD)\s+(.*)$", line)
        if not m:
            continue
        kv = dict(re.findall(r"(\w+)=(\S+)", m.group(2)))
        kv["_kind"] = m.group(1)
        rows.append(kv)
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("raw", metavar="RAW_LINES_FILE")
    p.add_argument("png", metavar="PLOT_PNG")
    a = p.parse_args()
    raw, png = a.raw, a.png
    rows = parse(raw)
    speed = defaultdict(list)  # (engine, threads) -> particle-steps/s of each block
    by_round = {}  # (engine, threads, round) -> particle-steps/s (interleaved rounds)
    for r in rows:
        if r["_kind"] != "RESULT":
            continue
        eng = r["engine"] if r.get("label", "default") in ("default", "hooke") else r["engine"] + "_" + r["label"]
        n = int(r.get("threads", r.get("ranks", 1)))
        speed[(eng, n)].append(float(r["particle_steps_per_s"]))
        if "round" in r:
            by_round[(eng, n, int(r["round"]))] = float(r["particle_steps_per_s"])
    med = {k: statistics.median(v) for k, v in speed.items()}

    def paired(a, b):
        """Ratios a/b of the blocks timed in the same round, a and b being (engine, threads)
        (a list; empty for a run without rounds)."""
        return [v / by_round[b + (k,)] for (e, n, k), v in sorted(by_round.items())
                if (e, n) == a and b + (k,) in by_round]

    def ratio(a, b):
        """Median of the per-round ratios where the run has rounds, else the ratio of the medians."""
        p = paired(a, b)
        if p:
            return statistics.median(p)
        x, y = med.get(a), med.get(b)
        return x / y if x and y else None

    def spread(a, b):
        p = paired(a, b)
        return f" ({min(p):.2f}–{max(p):.2f})" if len(p) > 1 else ""

    engines = sorted({k[0] for k in med}, key=lambda e: (e != "regolith", e))
    out = []
    out.append("| engine | 1 thread/rank | 2 threads/ranks | 2 vs 1 |")
    out.append("|---|---|---|---|")
    for e in engines:
        a, b, q = med.get((e, 1)), med.get((e, 2)), ratio((e, 2), (e, 1))
        fmt = lambda x: f"{x / 1e6:.2f} M" if x else "–"
        out.append(f"| {e} | {fmt(a)} | {fmt(b)} | {q:.2f}× |" if q else f"| {e} | {fmt(a)} | {fmt(b)} | – |")
    out.append("")
    nblocks = max((len(v) for v in speed.values()), default=0)
    out.append(f"Median particle-steps per second over the timed blocks ({nblocks} per engine and thread count).")
    out.append("")
    out.append("| ratio | 1 thread/rank | 2 threads/ranks |")
    out.append("|---|---|---|")
    for peer in ("lammps", "liggghts"):
        cells = []
        for n in (1, 2):
            q = ratio(("regolith", n), (peer, n))
            cells.append(f"{q:.2f}×{spread(('regolith', n), (peer, n))}" if q else "–")
        out.append(f"| regolith_twin / {peer} | {cells[0]} | {cells[1]} |")
    if by_round:
        out.append("")
        out.append("Each ratio (also \"2 vs 1\") is the median over the rounds of the two blocks timed in the "
                   "same round (range over the rounds in brackets).")
    micro = [r for r in rows if r["_kind"] == "MICRO" and "ratio_2_over_1" in r]
    if micro:
        out.append("")
        out.append(f"Compute-bound OpenMP microbenchmark on this machine: 2 threads / 1 thread = "
                   f"{float(micro[-1]['ratio_2_over_1']):.2f}×.")
    # The throughput targets of B1, judged on this run's medians.
    verdict = lambda ok: "**met**" if ok else "**not met**"
    targets = []
    for peer, goal in (("lammps", 2.0), ("liggghts", 3.5)):
        for n in (1, 2):
            q = ratio(("regolith", n), (peer, n))
            if q:
                targets.append(f"| at least {goal:g}× {peer}, {n} thread{'s' if n > 1 else ''} | {q:.2f}× | "
                               f"{verdict(q >= goal)} |")
    q = ratio(("regolith", 2), ("regolith", 1))
    if q:
        need = 1.7
        text = "1.7×"
        if micro:
            m = float(micro[-1]["ratio_2_over_1"])
            need = min(need, 0.9 * m)
            text = f"1.7× or 90 % of the microbenchmark's {m:.2f}× (= {0.9 * m:.2f}×)"
        targets.append(f"| 2-thread speed-up at least {text} | {q:.2f}× | {verdict(q >= need)} |")
    if targets:
        out.append("")
        out.append("| target | this run | |")
        out.append("|---|---|---|")
        out.extend(targets)
    triad = [r for r in rows if r["_kind"] == "TRIAD" and "gbps" in r]
    if triad:
        out.append("")
        out.append(f"One-core memory triad (bench/mem_triad.cpp) with a working set of {triad[-1]['mb']} MB: "
                   f"{float(triad[-1]['gbps']):.1f} GB/s.")
    last = {}  # the last check of each engine and thread count (every round ends in the same state)
    for r in rows:
        if r["_kind"] == "CHECK":
            last[(r["engine"], r.get("label"), r.get("threads", r.get("ranks")))] = r
    checks = list(last.values())
    if checks:
        out.append("")
        out.append("Physics check of the same runs (bench/postprocess_b1.py on each engine's final state):")
        out.append("")
        out.append("| engine | threads/ranks | bed height (m) | coordination | wall contacts/grain | KE (J) |")
        out.append("|---|---|---|---|---|---|")
        for r in checks:
            out.append(f"| {r['engine']}{'_' + r['label'] if r.get('label') not in (None, 'default', 'hooke') else ''} "
                       f"| {r.get('threads', r.get('ranks', '?'))} | {float(r['bed_height']):.5f} | "
                       f"{float(r['coordination']):.3f} | {float(r.get('wall_contacts_per_grain', 'nan')):.3f} | "
                       f"{float(r['ke']):.3g} |")
    print("\n".join(out))

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    width = 0.8 / max(len(engines), 1)
    for k, e in enumerate(engines):
        xs = [n - 1 + (k - (len(engines) - 1) / 2) * width for n in (1, 2)]
        ys = [med.get((e, n), 0) / 1e6 for n in (1, 2)]
        errs = [[(med.get((e, n), 0) - min(speed.get((e, n), [0]))) / 1e6 for n in (1, 2)],
                [(max(speed.get((e, n), [0])) - med.get((e, n), 0)) / 1e6 for n in (1, 2)]]
        ax.bar(xs, ys, width, yerr=errs, capsize=3, label=e)
    ax.set_xticks([0, 1])
    ax.set_xticklabels(["1 thread / rank", "2 threads / ranks"])
    ax.set_ylabel("million particle-steps per second")
    ax.set_title("B1 settled bed, 45,000 grains (median, min–max of blocks)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
