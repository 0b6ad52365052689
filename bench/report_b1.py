#!/usr/bin/env python3
"""Turn the raw lines of scripts/bench (RESULT/CHECK/STATE/VERSION/MICRO) into
docs/benchmarks.md figures: medians, ratios and a bar plot.

usage: report_b1.py RAW_LINES_FILE PLOT_PNG > table.md
"""
import re
import statistics
import sys
from collections import defaultdict


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
    raw, png = sys.argv[1], sys.argv[2]
    rows = parse(raw)
    speed = defaultdict(list)  # (engine, threads) -> particle-steps/s of each block
    for r in rows:
        if r["_kind"] != "RESULT":
            continue
        eng = r["engine"] if r.get("label", "default") in ("default", "hooke") else r["engine"] + "_" + r["label"]
        n = int(r.get("threads", r.get("ranks", 1)))
        speed[(eng, n)].append(float(r["particle_steps_per_s"]))
    med = {k: statistics.median(v) for k, v in speed.items()}
    engines = sorted({k[0] for k in med}, key=lambda e: (e != "regolith", e))
    out = []
    out.append("| engine | 1 thread/rank | 2 threads/ranks | 2 vs 1 |")
    out.append("|---|---|---|---|")
    for e in engines:
        a, b = med.get((e, 1)), med.get((e, 2))
        fmt = lambda x: f"{x / 1e6:.2f} M" if x else "–"
        out.append(f"| {e} | {fmt(a)} | {fmt(b)} | {b / a:.2f}× |" if a and b else f"| {e} | {fmt(a)} | {fmt(b)} | – |")
    out.append("")
    out.append("Median particle-steps per second over the timed blocks (each block 2,000 steps).")
    out.append("")
    out.append("| ratio | 1 thread/rank | 2 threads/ranks |")
    out.append("|---|---|---|")
    for peer in ("lammps", "liggghts"):
        cells = []
        for n in (1, 2):
            a, b = med.get(("regolith", n)), med.get((peer, n))
            cells.append(f"{a / b:.2f}×" if a and b else "–")
        out.append(f"| regolith_twin / {peer} | {cells[0]} | {cells[1]} |")
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
            a, b = med.get(("regolith", n)), med.get((peer, n))
            if a and b:
                targets.append(f"| at least {goal:g}× {peer}, {n} thread{'s' if n > 1 else ''} | {a / b:.2f}× | "
                               f"{verdict(a / b >= goal)} |")
    a, b = med.get(("regolith", 1)), med.get(("regolith", 2))
    if a and b:
        need = 1.7
        text = "1.7×"
        if micro:
            m = float(micro[-1]["ratio_2_over_1"])
            need = min(need, 0.9 * m)
            text = f"1.7× or 90 % of the microbenchmark's {m:.2f}× (= {0.9 * m:.2f}×)"
        targets.append(f"| 2-thread speed-up at least {text} | {b / a:.2f}× | {verdict(b / a >= need)} |")
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
    checks = [r for r in rows if r["_kind"] in ("CHECK",)]
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

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
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
