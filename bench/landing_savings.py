#!/usr/bin/python3
"""Resolution where the lander is (docs/bench/landing.md): paired landings on independent beds.

  bench/landing_savings.py run [SETTING ...] [--beds NAME,...] [--threads N]   (default: every setting)
  bench/landing_savings.py report [--docs DIR]   docs/bench/landing_report.md, landing_savings.png, savings.csv
  bench/landing_savings.py list       the settings and beds, and which runs are kept

Beds: the three independent preparations of the 30 cm moderate bed
(config/beds/mascot_moderate_d30{,_s2,_s3}.bed), each as prepared (repeat 0) and rotated and
aimed as a perturbed bed (docs/scenes.md A.7): eight paired beds, s1r0 ... s3r1.

Settings (SETTINGS below): `whole` is the reference, the model with nothing skipped (the whole bed
free, no sleeping, no free flight, the scene's stiffness and time step); `default` is the shipped
landing (active zone 0.45 m); the others are savings. A graded setting lands on the graded bed of
the same preparation (config/beds/mascot_moderate_d30_ga*.bed or _gd*.bed, docs/scenes.md E.1) with k_n and
Delta-t fixed at the values the k_n rule gives on the whole bed of that preparation (its mean grain
mass and smallest radius, docs/model.md section 4): the reference's contact law, which the rule
would otherwise stiffen with the graded bed's larger mean mass. A softer setting changes x_max
(k_n by (0.01 / x_max)^2) and the steps per contact.

Each finished run's summary.json is kept as results/bench/landing/SETTING_BED.json; a kept run is
not run again (the study resumes on any machine once they are committed). Runs go one at a time on
--threads threads (default 1: two studies side by side fill two cores).
Environment: REGOLITH_BIN (default build/devel/lib/regolith_twin).
"""
import argparse
import csv
import json
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
from plots import pyplot, save_figure  # noqa: E402
from bed_file import mascot_contact  # noqa: E402
from kept_run import run_kept  # noqa: E402
from stats import mean_sd, paired_difference  # noqa: E402

KEEP = os.path.join(ROOT, "results", "bench", "landing")
OUT = os.path.join(ROOT, "out", "bench", "landing")
DOCS = os.path.join(ROOT, "docs", "bench")
SCENE = os.path.join(ROOT, "config", "mascot_landing.yaml")
MATERIAL = "moderate"
# name -> (preparation suffix, repeat)
BEDS = {"s1r0": ("", 0), "s1r1": ("", 1), "s1r2": ("", 2), "s2r0": ("_s2", 0), "s2r1": ("_s2", 1),
        "s2r2": ("_s2", 2), "s3r0": ("_s3", 0), "s3r1": ("_s3", 1)}
WHOLE = ["landing.active_radius=0"]
# The active zone as it was the scene's default when the study began (docs/scenes.md A.8), set
# explicitly so that the settings keep their meaning whatever the scene's default.
ZONE = ["landing.active_radius=0.45"]
# The scene's x_max (of the smallest radius) and steps per contact (config/mascot_landing.yaml).
X_MAX, STEPS = 0.01, 30
# name -> {"grading": bed suffix or "", "sets": [--set ...], "profile": name or None, "x_max", "steps", "what"}
SETTINGS = {}


def setting(name, what, grading="", sets=(), profile=None, x_max=X_MAX, steps=STEPS):
    SETTINGS[name] = {"grading": grading, "sets": list(sets), "profile": profile, "x_max": x_max, "steps": steps,
                      "what": what}


setting("whole", "reference: the whole bed free, every saving off", sets=WHOLE)
setting("default", "today's default: active zone 0.45 m", sets=ZONE)
setting("sleep", "whole bed, quiet cells sleep (profile sleep)", profile="sleep")
setting("ga", "graded bed (ga), whole bed free", grading="_ga", sets=WHOLE)
setting("ga_zone", "graded bed (ga) and the active zone 0.45 m", grading="_ga", sets=ZONE)
setting("ga_sleep", "graded bed (ga), quiet cells sleep", grading="_ga", profile="sleep")
setting("gd", "graded bed in depth only (gd), whole bed free", grading="_gd", sets=WHOLE)
setting("gd_zone", "graded bed in depth only (gd) and the active zone 0.45 m", grading="_gd", sets=ZONE)
for xm, n in ((0.02, 30), (0.03, 20), (0.05, 15)):
    tag = "x%02d_n%d" % (round(xm * 100), n)
    setting(tag, "whole bed, x_max %g, %d steps per contact" % (xm, n), sets=WHOLE, x_max=xm, steps=n)
    setting("zone_" + tag, "today's default (active zone 0.45 m), x_max %g, %d steps per contact" % (xm, n), sets=ZONE,
            x_max=xm, steps=n)
    for g in ("ga", "gd"):
        setting("%s_%s" % (g, tag), "graded bed (%s), x_max %g, %d steps per contact" % (g, xm, n), grading="_" + g,
                sets=WHOLE, x_max=xm, steps=n)

# Which of the two knobs moves the outputs: the scene's stiffness with 15 steps per contact, and
# x_max 0.05 with the scene's 30 steps (on ga, where a landing is cheap).
setting("ga_x01_n15", "graded bed (ga), the scene's x_max 0.01, 15 steps per contact", grading="_ga", sets=WHOLE,
        x_max=0.01, steps=15)
setting("ga_x05_n30", "graded bed (ga), x_max 0.05, the scene's 30 steps per contact", grading="_ga", sets=WHOLE,
        x_max=0.05, steps=30)
# The steps per contact alone on the reference: the scene's stiffness, Delta-t twice as long.
setting("x01_n15", "whole bed, the scene's x_max 0.01, 15 steps per contact", sets=WHOLE, x_max=0.01, steps=15)

# The operator preview (config/profiles/preview.yaml: x_max 0.1, 15 steps per contact, 1 cm skin) as
# shipped (with the zone) and on the graded beds with the whole bed free.
setting("preview", "today's preview profile (active zone, x_max 0.1, 15 steps per contact)", profile="preview",
        sets=ZONE, x_max=0.1, steps=15)
for g in ("ga", "gd"):
    setting("%s_preview" % g, "graded bed (%s), the preview's contacts (x_max 0.1, 15 steps, 1 cm skin)" % g,
            grading="_" + g, sets=WHOLE + ["contact.skin=0.01"], x_max=0.1, steps=15)

# output key, label, margin, relative margin?  (B4, docs/bench/b4_landing.md)
OUTPUTS = [("speed_ratio", "speed ratio", 0.05, False),
           ("max_penetration", "max penetration (m)", 0.01, False),
           ("travel_distance", "travel distance", 0.15, True)]


def bed_file(prep, grading=""):
    return "beds/mascot_%s_d30%s%s.bed" % (MATERIAL, grading, prep)


def pinned_contact(prep, x_max, steps):
    """k_n and Delta-t of the rule on the whole (ungraded) bed of this preparation."""
    return mascot_contact(os.path.join(ROOT, "config", bed_file(prep)), x_max, steps)


def command(bin_dir, name, bed, threads):
    st, (prep, repeat) = SETTINGS[name], BEDS[bed]
    cmd = [os.path.join(bin_dir, "regolith_sim"), SCENE, "--out", os.path.join(OUT, "%s_%s" % (name, bed)),
           "--threads", str(threads), "--quiet"]
    if st["profile"]:
        cmd += ["--profile", st["profile"]]
    sets = ["landing.repeat=%d" % repeat, "grains.0.file=%s" % bed_file(prep, st["grading"])] + st["sets"]
    if st["grading"]:
        kn, dt = pinned_contact(prep, st["x_max"], st["steps"])
        sets += ["contact.kn=%.10g" % kn, "contact.dt=%.10g" % dt]
    else:
        sets += ["contact.x_max=%g" % st["x_max"], "contact.steps_per_contact=%d" % st["steps"]]
    for s in sets:
        cmd += ["--set", s]
    return cmd


def run(names, beds, threads):
    bin_dir = os.environ.get("REGOLITH_BIN", os.path.join(ROOT, "build", "devel", "lib", "regolith_twin"))
    os.makedirs(KEEP, exist_ok=True)
    for name in names:
        for bed in beds:
            keep = os.path.join(KEEP, "%s_%s.json" % (name, bed))
            s, ran = run_kept(command(bin_dir, name, bed, threads), keep, "bench",
                              {"setting": name, "bed": bed, "threads": threads}, ROOT)
            if s is None or not ran:
                continue
            o = s["outcome"]
            print("%s %s: speed ratio %.3f, penetration %.4f m, travel %.2f m, %.0f s" % (
                name, bed, o["speed_ratio"], o["max_penetration"], o["travel_distance"], s["run"]["wall_seconds"]),
                flush=True)


def load(name):
    runs = {}
    for bed in BEDS:
        f = os.path.join(KEEP, "%s_%s.json" % (name, bed))
        if os.path.exists(f):
            runs[bed] = json.load(open(f))
    return runs


def compare(ref, runs, base):
    """The setting's paired figures: wall-time ratio to `base` (today's default) and, per output,
    the mean difference from the reference with its 95 % CI."""
    pairs = [b for b in BEDS if b in ref and b in runs]
    row = {"beds": len(pairs)}
    wpairs = [b for b in BEDS if b in base and b in runs]
    if wpairs:
        ratios = [base[b]["run"]["wall_seconds"] / runs[b]["run"]["wall_seconds"] for b in wpairs]
        row["wall_ratio"] = (mean_sd([base[b]["run"]["wall_seconds"] for b in wpairs])[0] /
                             mean_sd([runs[b]["run"]["wall_seconds"] for b in wpairs])[0])
        row["wall_ratio_min"], row["wall_ratio_max"] = min(ratios), max(ratios)
    row["wall"] = mean_sd([runs[b]["run"]["wall_seconds"] for b in runs])[0]
    for key, _, margin, rel in OUTPUTS:
        if len(pairs) < 1:
            continue
        m, half = paired_difference([ref[b]["outcome"][key] for b in pairs], [runs[b]["outcome"][key] for b in pairs],
                                    rel)
        row[key] = (m, half, margin, abs(m) + half <= margin)
    return row


def report(docs=DOCS):
    ref, base = load("whole"), load("default")
    rows = {name: compare(ref, load(name), base) for name in SETTINGS if name != "whole" and load(name)}
    lines = ["<!-- generated by bench/landing_savings.py report -->", ""]
    if ref:
        vals = {k: [ref[b]["outcome"][k] for b in ref] for k, *_ in OUTPUTS}
        lines += ["Reference (`whole`), %d beds: " % len(ref) + "; ".join(
            "%s %.3g ± %.2g (SD)" % (lab, *mean_sd(vals[k])) for k, lab, *_ in OUTPUTS) +
            "; wall time %.0f s per landing." % mean_sd([ref[b]["run"]["wall_seconds"] for b in ref])[0], ""]
    lines += ["| setting | what | beds | wall time (s) | faster than `default` (range) | " +
              " | ".join("%s: difference, 95 %% CI (margin ±%g%s)" % (lab, mg, " relative" if rel else "")
                         for _, lab, mg, rel in OUTPUTS) + " |",
              "|---|---|---|---|---|" + "---|" * len(OUTPUTS)]
    for name, row in rows.items():
        cells = ["`%s`" % name, SETTINGS[name]["what"], str(row["beds"]), "%.0f" % row["wall"]]
        cells.append("%.2f× (%.2f–%.2f)" % (row["wall_ratio"], row["wall_ratio_min"], row["wall_ratio_max"])
                     if "wall_ratio" in row else "–")
        for key, *_ in OUTPUTS:
            if key in row:
                m, half, margin, ok = row[key]
                cells.append("%+.3g [%+.3g, %+.3g] %s" % (m, m - half, m + half, "✓" if ok else "✗"))
            else:
                cells.append("–")
        lines.append("| " + " | ".join(cells) + " |")
    # Every kept run, bed by bed (the paired differences above come from these).
    beds = [b for b in BEDS if any(os.path.exists(os.path.join(KEEP, "%s_%s.json" % (n, b))) for n in SETTINGS)]
    lines += ["", "Every run: speed ratio / maximum penetration (cm) / travel (m) / wall time (s, one thread, on a "
              "shared 2-core machine whose load varied from run to run: the wall-time ratios are indicative; "
              "`scripts/bench --landing-timing` times settings side by side).", "",
              "| setting | " + " | ".join(beds) + " |", "|---|" + "---|" * len(beds)]
    for name in SETTINGS:
        runs = load(name)
        if runs:
            lines.append("| `%s` | " % name + " | ".join(
                "%.3f / %.1f / %.2f / %.0f" % (runs[b]["outcome"]["speed_ratio"], 100 * runs[b]["outcome"]["max_penetration"],
                                              runs[b]["outcome"]["travel_distance"], runs[b]["run"]["wall_seconds"])
                if b in runs else "–" for b in beds) + " |")
    with open(os.path.join(docs, "landing_report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(docs, "savings.csv"), "w", newline="") as f:
        w = csv.writer(f)
        head = ["setting", "beds", "wall_seconds", "wall_ratio_to_default", "wall_ratio_min", "wall_ratio_max"]
        for key, *_ in OUTPUTS:
            head += [key + "_diff", key + "_ci_lo", key + "_ci_hi", key + "_margin", key + "_within"]
        w.writerow(head)
        for name, row in rows.items():
            r = [name, row["beds"], "%.1f" % row["wall"]] + (
                ["%.3f" % row[k] for k in ("wall_ratio", "wall_ratio_min", "wall_ratio_max")] if "wall_ratio" in row
                else ["NA"] * 3)
            for key, *_ in OUTPUTS:
                if key in row:
                    m, half, margin, ok = row[key]
                    r += ["%.5g" % m, "%.5g" % (m - half), "%.5g" % (m + half), "%g" % margin, int(ok)]
                else:
                    r += ["NA"] * 5
            w.writerow(r)
    draw(rows, mean_sd([ref[b]["run"]["wall_seconds"] for b in ref])[0] if ref else None, docs)


def draw(rows, ref_wall, docs):
    plt = pyplot()
    fig, axs = plt.subplots(1, len(OUTPUTS), figsize=(4.2 * len(OUTPUTS) + 1.6, 3.6))
    # One colour and marker per setting, the same in every panel (more settings than one palette has colours).
    cmap = plt.get_cmap("tab20")
    style = {name: (cmap(i % 20), "osD^v<>PX*"[i % 10]) for i, name in enumerate(rows)}
    for ax, (key, lab, margin, rel) in zip(axs, OUTPUTS):
        for name, row in rows.items():
            if key not in row:
                continue
            m, half, _, _ = row[key]
            color, marker = style[name]
            ax.errorbar([row["wall"]], [m], yerr=[[half], [half]] if math.isfinite(half) else None, fmt=marker,
                        color=color, capsize=3, label=name)
        ax.axhspan(-margin, margin, color="g", alpha=0.1)
        if ref_wall and ref_wall == ref_wall:
            ax.plot([ref_wall], [0], "ks", label="whole (reference)")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xscale("log")
        ax.set_xlabel("wall time per landing (s)")
        ax.set_title("%s: difference%s" % (lab, " (relative)" if rel else ""), fontsize=9)
    axs[-1].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    save_figure(fig, os.path.join(docs, "landing_savings.png"))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("cmd", choices=["run", "report", "list"])
    p.add_argument("settings", nargs="*")
    p.add_argument("--beds", default=",".join(BEDS))
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--docs", default=DOCS, help="where report writes (default docs/bench)")
    a = p.parse_args()
    beds = [b for b in a.beds.split(",") if b]
    for b in beds:
        if b not in BEDS:
            raise SystemExit("landing_savings: unknown bed '%s' (known: %s)" % (b, ", ".join(BEDS)))
    for s in a.settings:
        if s not in SETTINGS:
            raise SystemExit("landing_savings: unknown setting '%s' (known: %s)" % (s, ", ".join(SETTINGS)))
    if a.cmd == "run":
        run(a.settings or list(SETTINGS), beds, a.threads)
    elif a.cmd == "report":
        report(a.docs)
    else:
        for name, st in SETTINGS.items():
            done = [b for b in BEDS if os.path.exists(os.path.join(KEEP, "%s_%s.json" % (name, b)))]
            print("%-14s %-58s %d/%d kept" % (name, st["what"], len(done), len(BEDS)))


if __name__ == "__main__":
    main()
