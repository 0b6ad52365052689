#!/usr/bin/python3
"""B4/B5 on the landing (docs/bench/b4_landing.md): paired differences of a setting
from the reference on the same perturbed beds, from the summaries that
bench/b4_landing.sh keeps in results/bench/b4/. Prints a markdown table (mean
difference, 95 % confidence interval from Student's t, the margin, accepted or
not) and draws the error against wall time (docs/bench/b4_landing.png).

    bench/report_b4.py [SETTING ...]        default: preview
"""
import argparse
import glob
import json
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
from plots import pyplot  # noqa: E402
from stats import mean_sd, paired_difference  # noqa: E402

KEEP = os.path.join(ROOT, "results", "bench", "b4")
# output key, label, margin, relative margin?
OUTPUTS = [("speed_ratio", "speed ratio", 0.05, False),
           ("max_penetration", "max penetration (m)", 0.01, False),
           ("travel_distance", "travel distance (m)", 0.15, True)]


def load(setting):
    runs = {}
    for f in glob.glob(os.path.join(KEEP, f"{setting}_r*.json")):
        r = int(f.rsplit("_r", 1)[1].split(".")[0])
        runs[r] = json.load(open(f))
    return runs


def sim_time(s):
    return s["outcome"]["t_end"]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("settings", metavar="SETTING", nargs="*", default=["preview"])
    settings = p.parse_args().settings
    ref = load("ref")
    lines = []
    vals = {k: [ref[r]["outcome"][k] for r in sorted(ref)] for k, *_ in OUTPUTS}
    lines.append(f"Reference (the default scene), {len(ref)} beds (repeats {sorted(ref)}): " + "; ".join(
        f"{lab} {mean(vals[k]):.3g}" + (f" ± {sd(vals[k]):.2g} (SD)" if len(ref) > 1 else "")
        for k, lab, *_ in OUTPUTS) + ".")
    lines.append("")
    plot = {}
    for st in settings:
        runs = load(st)
        pairs = sorted(set(runs) & set(ref))
        if not pairs:
            continue
        lines.append(f"**{st}**, {len(pairs)} paired beds (repeats {pairs}); wall time {fmt_wall(runs, pairs)} "
                     f"against {fmt_wall(ref, pairs)} for the reference (ratio of the means "
                     f"{mean([ref[r]['run']['wall_seconds'] for r in pairs]) / mean([runs[r]['run']['wall_seconds'] for r in pairs]):.1f}x); "
                     f"real-time factor {mean([sim_time(runs[r]) / runs[r]['run']['wall_seconds'] for r in pairs]):.2f}.")
        lines.append("")
        allv = {k: [runs[r]["outcome"][k] for r in sorted(runs)] for k, *_ in OUTPUTS}
        lines.append(f"All {len(runs)} beds of {st}: " + "; ".join(
            f"{lab} {mean(allv[k]):.3g} ± {sd(allv[k]):.2g} (SD)" for k, lab, *_ in OUTPUTS) + ".")
        lines.append("")
        lines.append("| output | reference | setting | mean difference | 95 % CI | margin | within |")
        lines.append("|---|---|---|---|---|---|---|")
        for k, lab, margin, rel in OUTPUTS:
            a = [ref[r]["outcome"][k] for r in pairs]
            b = [runs[r]["outcome"][k] for r in pairs]
            m, half = paired_difference(a, b, rel)
            ok = abs(m) + half <= margin
            unit = ", difference relative" if rel else ""
            lines.append(f"| {lab}{unit} | {' / '.join(f'{x:.3g}' for x in a)} | {' / '.join(f'{y:.3g}' for y in b)} | "
                         f"{m:+.3g} | [{m - half:+.3g}, {m + half:+.3g}] | ±{margin:g} | {'yes' if ok else 'no'} |")
            plot.setdefault(lab + unit, []).append((st, mean([runs[r]['run']['wall_seconds'] for r in pairs]), m, half, margin))
        lines.append("")
    print("\n".join(lines))
    draw(plot, mean([ref[r]["run"]["wall_seconds"] for r in ref]) if ref else None)


def draw(plot, ref_wall):
    if not plot:
        return
    plt = pyplot()
    fig, axs = plt.subplots(1, len(plot), figsize=(4 * len(plot), 3.4))
    for ax, (lab, pts) in zip(axs, plot.items()):
        for st, wall, m, half, margin in pts:
            ax.errorbar([wall], [m], yerr=[[half], [half]] if math.isfinite(half) else None, fmt="o", label=st, capsize=3)
            ax.axhspan(-margin, margin, color="g", alpha=0.1)
        if ref_wall:
            ax.errorbar([ref_wall], [0], fmt="ks", label="reference")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xscale("log")
        ax.set_xlabel("wall time per landing (s)")
        ax.set_title(f"{lab}: difference", fontsize=9)
    axs[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "docs", "bench", "b4_landing.png"), dpi=110)


def mean(x):
    return mean_sd(x)[0]


def sd(x):
    """The sample SD; infinite for fewer than two values (no confidence interval)."""
    return mean_sd(x, missing=float("inf"))[1]


def fmt_wall(runs, pairs):
    w = [runs[r]["run"]["wall_seconds"] for r in pairs]
    return f"{min(w):.0f}-{max(w):.0f} s" if len(w) > 1 else f"{w[0]:.0f} s"


if __name__ == "__main__":
    main()
