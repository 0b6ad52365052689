#!/usr/bin/env python3
"""The sampler campaign (scripts/validate_sampler campaign): 1 s shots at 300
and 50 m/s on perturbed beds, side by side; and the shots on the shipped beds
(scripts/validate_sampler shots).

usage: sampler_campaign.py OUT_DIR DOCS_DIR

For every campaign run c<speed>_r<repeat>: OUT_DIR/<run>/series.csv (when the
run was made on this machine) is thinned to DOCS_DIR/<run>/series_thin.csv (at
most 400 rows, kept with the run's summary); then DOCS_DIR/campaign.md (one
row per shot, mean and SD per speed) and DOCS_DIR/campaign_*.png (collected
mass, crater depth and radius, grains in the horn against time; ejection
angle histograms) are written from DOCS_DIR. The same for the shots
shots/v<speed>[_1s]_b<bed>[r<repeat>] (to 0.25 s at the scene's stiffness, or 1 s
with the stiffness schedule, on the shipped bed <bed>, turned as perturbed
repeat <repeat>): DOCS_DIR/shots/report.md and DOCS_DIR/shots/shots_*.png,
one table and one set of plots per duration.
"""
import argparse
import csv
import json
import math
import os
import re
import sys

from plots import pyplot, save_figure
from stats import mean_sd

RUN = re.compile(r"^c(\d+)_r(\d+)$")
SHOT = re.compile(r"^v(\d+)(_1s)?_b(\d+)(?:r(\d+))?$")


MARKS = (0.2,)  # times whose nearest row a thinned series always keeps (bench/sampler_floor.py reads 0.2 s), s


def thin(src, dst, rows_max=400):
    """src's rows thinned to about rows_max, the last row and the rows nearest MARKS kept."""
    with open(src) as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]
    step = max(1, math.ceil(len(body) / rows_max))
    picked = set(range(0, len(body), step))
    if body:
        picked.add(len(body) - 1)
        t = [float(r[0]) for r in body]
        for mark in MARKS:
            if t[0] <= mark <= t[-1]:
                picked.add(min(range(len(t)), key=lambda k: abs(t[k] - mark)))
    keep = [body[k] for k in sorted(picked)]
    with open(dst, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(head)
        w.writerows(keep)


def read_series(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else None


def fmt(m, sd, scale=1.0, digits=1):
    if m is None:
        return "–"
    return f"{m * scale:.{digits}f}" + ("" if sd is None else f" ± {sd * scale:.{digits}f}")


def outcome(s):
    o = s["observers"]
    h, c, ej = o.get("horn", {}), o.get("crater", {}), o.get("ejection", {})
    zm = o.get("zmodel", {})
    zlast = None
    for k in sorted((k for k in zm if isinstance(zm[k], dict)), key=lambda k: zm[k].get("t", 0)):
        zlast = zm[k]
    return {
        "collected_mg": 1e6 * h.get("collected_mass", 0.0),
        "time_met": h.get("time_met"),
        "in_horn": sum(h.get("segment_grains", [])),
        "segments": h.get("segment_grains", []),
        "crater_depth_mm": 1e3 * c.get("depth", 0.0),
        "crater_radius_mm": 1e3 * c.get("radius", 0.0),
        "ejected": ej.get("count", 0),
        "ejected_cm3": 1e6 * ej.get("volume", 0.0),
        "angle_mean": ej.get("mean_angle_deg"),
        "angle_median": ej.get("median_angle_deg"),
        "hist": ej.get("angle_histogram", []),
        "bin_deg": ej.get("bin_deg", 6),
        "z": (zlast or {}).get("fixed_h0", {}).get("z"),
        "z_t": (zlast or {}).get("t"),
        "wall": s["run"].get("wall_seconds"),
        "threads": s["run"].get("threads"),
        "steps": s["run"].get("steps"),
        "sim": s["run"].get("sim_time"),
        # The stiffness schedule's raises (docs/model.md §17): how often, and the elastic energy they added.
        "raised": s["run"].get("schedule", {}).get("raised"),
        "injected_j": s["run"].get("schedule", {}).get("injected_energy"),
        # A shot the run stopped (the schedule's bound on injected energy, a blow-up): listed, not averaged.
        "status": s.get("status", "ok"),
    }


def collect(out, docs, pattern, key):
    """name -> (speed, bed or repeat, summary, outcome) of the runs in docs whose name matches pattern
    (key(match) -> (speed, bed or repeat)); each run's series is thinned from out/<name> when it is there."""
    runs = {}
    for name in sorted(os.listdir(docs)) if os.path.isdir(docs) else []:
        m = pattern.match(name)
        p = os.path.join(docs, name, "summary.json")
        if not m or not os.path.isfile(p):
            continue
        src = os.path.join(out, name, "series.csv")
        if os.path.isfile(src):
            thin(src, os.path.join(docs, name, "series_thin.csv"))
        with open(p) as f:
            s = json.load(f)
        runs[name] = key(m) + (s, outcome(s))
    return runs


def write(runs, docs, md, prefix, bed_word, end_word):
    """md (one row per shot, mean and SD per speed) and prefix_series.png, prefix_ejection_angles.png in docs."""
    lines = [
        "| shot | speed m/s | %s | collected %s mg | 100 mg reached at s | grains in horn (cyl. 1-5) | "
        "crater depth / radius mm | ejected grains (cm³) | ejection angle mean / median deg | Z (H0 = 0) | steps | "
        "wall s (threads) | schedule: raises, energy injected J |" % (bed_word, end_word),
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, (v, rep, s, o) in runs.items():
        lines.append(
            f"| {name} | {v} | {rep} | {o['collected_mg']:.1f} | "
            f"{'not reached' if o['time_met'] is None or o['time_met'] < 0 else format(o['time_met'], '.3f')} | "
            f"{'/'.join(str(x) for x in o['segments'])} | {o['crater_depth_mm']:.0f} / {o['crater_radius_mm']:.0f} | "
            f"{o['ejected']} ({o['ejected_cm3']:.0f}) | "
            f"{'–' if o['angle_mean'] is None else format(o['angle_mean'], '.1f')} / "
            f"{'–' if o['angle_median'] is None else format(o['angle_median'], '.1f')} | "
            f"{'–' if o['z'] is None else format(o['z'], '.2f')} | {o['steps']} | "
            f"{o['wall']:.0f} ({o['threads']}) | "
            f"{'off' if o['raised'] is None else '%d, %.3g' % (o['raised'], o['injected_j'])}"
            f"{'' if o['status'] == 'ok' else '; **stopped (%s) at %.4g s**' % (o['status'], o['sim'] or 0)} |")
    stopped = [n for n, r in runs.items() if r[3]["status"] != "ok"]
    if stopped:
        lines += ["", "Stopped before their end, listed with what they reached and left out of the means: " +
                  ", ".join(stopped) + " (their summary.json `message` says why, e.g. the stiffness schedule's "
                  "raises adding more energy than `schedule.max_injected` allows, docs/model.md §17)."]
    lines += ["", "Per speed, mean ± SD over the shots that ran to their end (SD from n − 1):", "",
              "| speed m/s | shots | collected mg | grains in horn | crater depth mm | crater radius mm | ejected grains | "
              "mean ejection angle deg | Z |",
              "|---|---|---|---|---|---|---|---|---|"]
    for v in sorted({r[0] for r in runs.values()}, reverse=True):
        os_ = [r[3] for r in runs.values() if r[0] == v and r[3]["status"] == "ok"]

        def col(key, digits=1):
            return fmt(*mean_sd([o[key] for o in os_], missing=None), digits=digits)
        lines.append(f"| {v} | {len(os_)} | {col('collected_mg')} | {col('in_horn', 0)} | {col('crater_depth_mm')} | "
                     f"{col('crater_radius_mm')} | {col('ejected', 0)} | {col('angle_mean')} | {col('z', 2)} |")
    with open(os.path.join(docs, md), "w") as f:
        f.write("\n".join(lines) + "\n")

    try:
        plt = pyplot()
    except ImportError:
        print("sampler_campaign: matplotlib missing, no plots", file=sys.stderr)
        return
    colours = {300: "tab:red", 50: "tab:blue"}
    styles = ["-", "--", ":", "-."]
    fig, ax = plt.subplots(2, 2, figsize=(11, 7.5))
    place = {}  # a line style per run: its place among the runs at its speed
    for name, (v, rep, s, o) in runs.items():
        place[name] = sum(1 for r in place if runs[r][0] == v)
    for name, (v, rep, s, o) in runs.items():
        ser = read_series(os.path.join(docs, name, "series_thin.csv"))
        if ser is None:
            continue
        t = ser["t"]
        kw = dict(color=colours.get(v, "k"), ls=styles[place[name] % len(styles)], label=f"{v} m/s, {bed_word} {rep}")
        ax[0][0].plot(t, [1e6 * x for x in ser["collected_mass"]], **kw)
        ax[0][1].plot(t, [sum(ser[f"seg{k}_n"][i] for k in range(1, 6)) for i in range(len(t))], **kw)
        ax[1][0].plot(t, [1e3 * x for x in ser["crater_depth"]], **kw)
        ax[1][1].plot(t, [1e3 * x for x in ser["crater_radius"]], **kw)
    ax[0][0].axhline(100, color="k", lw=0.8, ls="--", label="100 mg")
    for a, lab in zip(ax.flat, ["collected mass (mg)", "grains in the horn", "crater depth (mm)",
                                "crater radius (mm)"]):
        a.set_xlabel("time after firing (s)")
        a.set_ylabel(lab)
    ax[0][0].legend(fontsize=8)
    save_figure(fig, os.path.join(docs, prefix + "_series.png"))
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for name, (v, rep, s, o) in runs.items():
        h, b = o["hist"], o["bin_deg"]
        if not h:
            continue
        tot = float(sum(h)) or 1.0
        ax.step([b * (i + 0.5) for i in range(len(h))], [x / tot for x in h], where="mid",
                color=colours.get(v, "k"), ls=styles[place[name] % len(styles)], label=f"{v} m/s, {bed_word} {rep}")
    ax.set_xlabel("ejection angle from the horizontal (deg)")
    ax.set_ylabel("fraction of ejected grains")
    ax.legend(fontsize=8)
    save_figure(fig, os.path.join(docs, prefix + "_ejection_angles.png"))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", metavar="OUT")
    p.add_argument("docs", metavar="DOCS")
    a = p.parse_args()
    out, docs = a.out, a.docs
    runs = collect(out, docs, RUN, lambda m: (int(m.group(1)), int(m.group(2))))
    sdocs, sout = os.path.join(docs, "shots"), os.path.join(out, "shots")
    every = collect(sout, sdocs, SHOT, lambda m: (int(m.group(1)), m.group(3) + (
        " (turned, repeat %s)" % m.group(4) if m.group(4) else "")))
    shots = {d: {n: r for n, r in every.items() if bool(SHOT.match(n).group(2)) == (d == "1 s")}
             for d in ("0.25 s", "1 s")}
    if not runs and not any(shots.values()):
        sys.exit(f"sampler_campaign: no campaign runs (c<speed>_r<repeat>/summary.json) or shots "
                 f"(shots/v<speed>[_1s]_b<bed>/summary.json) in {docs}")
    if runs:
        write(runs, docs, "campaign.md", "campaign", "bed repeat", "at 1 s")
    parts = []
    for d, got in shots.items():
        if not got:
            continue
        tag = "shots_1s" if d == "1 s" else "shots_025s"
        write(got, sdocs, tag + ".md", tag, "bed", "at %s" % d)
        parts.append((d, tag))
    if parts:
        lines = ["# Sampler shots on the shipped beds", "",
                 "Generated by `scripts/lib/sampler_campaign.py` (`scripts/validate_sampler shots`) from "
                 "`shots/*/summary.json`. Bed k: `config/beds/sampler_gravel.bed`, `_s2`, `_s3` (three "
                 "independent preparations, docs/validation/beds.md)."]
        for d, tag in parts:
            with open(os.path.join(sdocs, tag + ".md")) as f:
                body = f.read()
            os.remove(os.path.join(sdocs, tag + ".md"))
            what = ("to 1 s after firing with the stiffness schedule (docs/model.md §17)" if d == "1 s" else
                    "to 0.25 s after firing at the scene's stiffness")
            lines += ["", "## Shots %s" % what, "", body.rstrip("\n"), "",
                      "![%s: against time](%s_series.png)" % (d, tag),
                      "![%s: ejection angles](%s_ejection_angles.png)" % (d, tag)]
        with open(os.path.join(sdocs, "report.md"), "w") as f:
            f.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
