#!/usr/bin/python3
"""The sampler shot's stiffness schedule with a floor, paired against the full-stiffness reference on
the three shipped beds, compared at 0.2 s (docs/bench/b3_schedule.md, "With a floor").

  bench/sampler_floor.py run [SETTING ...] [--beds 1,2,3] [--threads 2]
  bench/sampler_floor.py report     docs/bench/sampler_floor.md, sampler_floor.csv
  bench/sampler_floor.py list       the settings and which runs are kept

Beds: the three independent preparations (config/beds/sampler_gravel.bed, _s2, _s3; bed k). Every shot
runs to 0.25 s after firing on bed k as prepared and is compared at 0.2 s, read from its series (the row
nearest 0.2 s). The reference, `off` (every saving off: the scene's k_n and time step throughout), is the
shot scripts/validate_sampler runs as shots/v300_b<k> (kept in results/sampler/shots/v300_b<k>/ with its
thinned series; the same run serves the sampler's validation); `floorF` runs the stiffness schedule
(docs/model.md section 17) with k_n never below F times the scene's; `schedule`, the schedule as shipped
(floor 1e-4), is not run here but read at 0.2 s from the validation's 1 s shots on the same beds
(shots/v300_1s_b<k>: one thread, 1 s, so their wall times are not compared). Outputs at 0.2 s and their margins
(B4): the grains in horn segments 1 and 2 (15 % each) and the crater depth (5 %); the ejected grains are
reported beside. Wall times compare whole shots (0.25 s each).

Each finished floored run's summary.json, with its outputs at 0.2 s, is kept as
results/bench/sampler_floor/SETTING_bK.json (a kept run is not run again: the study resumes on any
machine once they are committed).
Environment: REGOLITH_BIN (default build/devel/lib/regolith_twin)."""
import argparse
import csv
import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
from kept_run import run_kept  # noqa: E402
from stats import mean_sd, paired_difference  # noqa: E402

KEEP = os.path.join(ROOT, "results", "bench", "sampler_floor")
SHOTS = os.path.join(ROOT, "results", "sampler", "shots")
OUT = os.path.join(ROOT, "out", "bench", "sampler_floor")
DOCS = os.path.join(ROOT, "docs", "bench")
SCENE = os.path.join(ROOT, "config", "sampler_shot.yaml")
DURATION = 0.25       # every shot runs this long after firing, s
AT = 0.2              # ... and is compared at this time, s
AT_TOLERANCE = 1e-3   # the series row read must lie this close to AT, s
BEDS = {1: "beds/sampler_gravel.bed", 2: "beds/sampler_gravel_s2.bed", 3: "beds/sampler_gravel_s3.bed"}
# name -> (what, [--set ...])
SETTINGS = {"off": ("reference: the scene's k_n and time step throughout (scripts/validate_sampler shots)", []),
            # Not run by the study: the validation's 1 s shots on the same beds, read at AT (they ran on one
            # thread and for 1 s, so their wall times are not compared).
            "schedule": ("stiffness schedule as shipped, k_n not below 1e-4 of the scene's (the sampler "
                         "validation's 1 s shots)", None)}
# The validation's shots each setting not run here reads: setting -> run name on bed k
SHOT_OF = {"off": "v300_b%d", "schedule": "v300_1s_b%d"}
for floor in (1e-2, 1e-3):
    SETTINGS["floor%g" % floor] = ("stiffness schedule, k_n not below %g of the scene's" % floor,
                                   ["schedule.enabled=true", "schedule.floor=%g" % floor])
# output label, series column, relative margin
OUTPUTS = [("horn segment 1 (grains)", "seg1_n", 0.15),
           ("horn segment 2 (grains)", "seg2_n", 0.15),
           ("crater depth (m)", "crater_depth", 0.05),
           ("ejected grains", "ejected_grains", None)]


def at_time(series):
    """{column: value} of the series row nearest AT (a CSV file with a header), or None when no row lies
    within AT_TOLERANCE of it."""
    if not os.path.exists(series):
        return None
    with open(series) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return None
    best = min(rows, key=lambda r: abs(float(r["t"]) - AT))
    if abs(float(best["t"]) - AT) > AT_TOLERANCE:
        return None
    return {k: float(v) for k, v in best.items()}


def validation_shot(name, bed):
    """The sampler validation's shot a setting reads on bed k (SHOT_OF: results/sampler/shots/v300_b<k> for
    the reference): its summary with its outputs at AT under bench.at, or None when it has not been run."""
    run_name = SHOT_OF[name] % bed
    d = os.path.join(SHOTS, run_name)
    f = os.path.join(d, "summary.json")
    if not os.path.exists(f):
        return None
    s = json.load(open(f))
    at = at_time(os.path.join(d, "series_thin.csv"))
    if s.get("status") != "ok" or at is None:
        return None
    s["bench"] = {"setting": name, "bed": bed, "at": at, "command": "scripts/validate_sampler shots/" + run_name}
    return s


def run(names, beds, threads):
    bin_dir = os.environ.get("REGOLITH_BIN", os.path.join(ROOT, "build", "devel", "lib", "regolith_twin"))
    os.makedirs(KEEP, exist_ok=True)
    for b in beds:
        for name in names:
            if name in SHOT_OF:
                if validation_shot(name, b) is None:
                    print("%s b%d: not run yet (scripts/validate_sampler shots/%s runs it)" %
                          (name, b, SHOT_OF[name] % b), flush=True)
                continue
            keep = os.path.join(KEEP, "%s_b%d.json" % (name, b))
            out = os.path.join(OUT, "%s_b%d" % (name, b))
            cmd = [os.path.join(bin_dir, "regolith_sim"), SCENE, "--out", out, "--threads", str(threads), "--quiet",
                   "--set", "sampler.duration=%g" % DURATION, "--set", "grains.0.file=%s" % BEDS[b]]
            for o in SETTINGS[name][1]:
                cmd += ["--set", o]
            s, ran = run_kept(cmd, keep, "bench", {"setting": name, "bed": b, "threads": threads}, ROOT)
            if s is None or not ran:
                continue
            at = at_time(os.path.join(out, "series.csv"))
            if at is None:
                print("%s b%d: no series row within %g s of %g s" % (name, b, AT_TOLERANCE, AT), flush=True)
                os.remove(keep)
                continue
            s["bench"]["at"] = at
            with open(keep + ".tmp", "w") as f:
                json.dump(s, f, indent=1)
            os.replace(keep + ".tmp", keep)
            print("%s b%d: %s at %g s, %.0f s" % (name, b, ", ".join("%s %g" % (lab, at[col]) for lab, col, _ in OUTPUTS),
                                                  AT, s["run"]["wall_seconds"]), flush=True)


def load(name):
    """bed -> summary (with bench.at) of every kept run of a setting."""
    if name in SHOT_OF:
        return {b: r for b, r in ((b, validation_shot(name, b)) for b in BEDS) if r is not None}
    runs = {}
    for f in sorted(os.listdir(KEEP)) if os.path.isdir(KEEP) else []:
        if f.startswith(name + "_b") and f.endswith(".json"):
            runs[int(f[len(name) + 2:-5])] = json.load(open(os.path.join(KEEP, f)))
    return runs


def report():
    ref = load("off")
    lines = ["<!-- generated by bench/sampler_floor.py report -->", ""]
    if ref:
        def mean_text(values):
            m, sd = mean_sd(values)
            return "%.4g ± %.2g (SD)" % (m, sd) if len(values) > 1 else "%.4g" % m
        lines += ["Reference (`off`), %d bed%s: " % (len(ref), "s" if len(ref) > 1 else "") + "; ".join(
            "%s %s" % (lab, mean_text([s["bench"]["at"][col] for s in ref.values()]))
            for lab, col, _ in OUTPUTS) +
            "; wall time %.0f s per shot." % mean_sd([s["run"]["wall_seconds"] for s in ref.values()])[0], ""]
    lines += ["| setting | what | beds | wall (s) | faster than `off` | " +
              " | ".join("%s: relative difference, 95 %% CI%s" % (lab, " (margin ±%g)" % m if m else "")
                         for lab, _, m in OUTPUTS) + " |", "|---|---|---|---|---|" + "---|" * len(OUTPUTS)]
    rows = []
    for name, (what, _) in SETTINGS.items():
        runs = load(name)
        if name == "off" or not runs:
            continue
        pairs = sorted(set(ref) & set(runs))
        if name in SHOT_OF:  # shots of another length: their wall times are not this study's
            cells = ["`%s`" % name, what, str(len(pairs)), "–", "–"]
            row = [name, len(pairs), "NA", "NA"]
        else:
            wall = mean_sd([runs[r]["run"]["wall_seconds"] for r in runs])[0]
            # Wall times compare only where both shots ran on as many threads.
            timed = [r for r in pairs if ref[r]["run"].get("threads") == runs[r]["run"].get("threads")]
            speed = (mean_sd([ref[r]["run"]["wall_seconds"] for r in timed])[0] /
                     mean_sd([runs[r]["run"]["wall_seconds"] for r in timed])[0]) if timed else float("nan")
            cells = ["`%s`" % name, what, str(len(pairs)), "%.0f" % wall, "%.1f×" % speed]
            row = [name, len(pairs), "%.1f" % wall, "%.3f" % speed]
        for lab, col, margin in OUTPUTS:
            if not pairs:
                cells.append("–")
                row += ["NA"] * 4
                continue
            m, half = paired_difference([ref[r]["bench"]["at"][col] for r in pairs],
                                        [runs[r]["bench"]["at"][col] for r in pairs], relative=True)
            if len(pairs) < 2:
                # One bed gives a difference but no interval: no verdict against the margin.
                cells.append("%+.3f (one bed: no interval)" % m)
                row += ["%.5g" % m, "NA", "NA", "NA"]
                continue
            ok = margin is not None and abs(m) + half <= margin
            cells.append("%+.3f [%+.3f, %+.3f]%s" % (m, m - half, m + half,
                                                     "" if margin is None else (" ✓" if ok else " ✗")))
            row += ["%.5g" % m, "%.5g" % (m - half), "%.5g" % (m + half), "NA" if margin is None else int(ok)]
        lines.append("| " + " | ".join(cells) + " |")
        rows.append(row)
    # Every kept run, bed by bed (the pairs behind the intervals above).
    lines += ["", "Bed by bed, at %g s (wall: the whole %g s shot; `schedule` ran for 1 s on one thread):" %
              (AT, DURATION), "",
              "| bed | setting | " + " | ".join(lab for lab, _, _ in OUTPUTS) +
              " | k_n at the end (of the scene's) | raises | wall (s), threads |",
              "|---|---|" + "---|" * (len(OUTPUTS) + 3)]
    kept = {name: load(name) for name in SETTINGS}
    for b in sorted(BEDS):
        for name in SETTINGS:
            s = kept[name].get(b)
            if s is None:
                continue
            q = s["run"].get("schedule")
            at = s["bench"]["at"]
            lines.append("| %d | `%s` | %s | %s | %s | %s |" % (
                b, name, " | ".join("%.5g" % at[col] for _, col, _ in OUTPUTS),
                "%.3g" % q["kn_factor_at_end"] if q else "1 (off)", q["raised"] if q else "–",
                "%.0f, %s" % (s["run"]["wall_seconds"], s["run"].get("threads", "?"))))
    with open(os.path.join(DOCS, "sampler_floor.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(DOCS, "sampler_floor.csv"), "w", newline="") as f:
        w = csv.writer(f)
        head = ["setting", "beds", "wall_seconds", "wall_ratio_to_off"]
        for key in ("segment1", "segment2", "crater_depth", "ejected"):
            head += [key + "_rel_diff", key + "_ci_lo", key + "_ci_hi", key + "_within"]
        w.writerow(head)
        w.writerows(rows)
    print("report: %s" % os.path.join(DOCS, "sampler_floor.md"))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("cmd", choices=["run", "report", "list"])
    p.add_argument("settings", nargs="*")
    p.add_argument("--beds", default="1,2,3")
    p.add_argument("--threads", type=int, default=2)
    a = p.parse_args()
    try:
        beds = [int(b) for b in a.beds.split(",") if b]
    except ValueError:
        raise SystemExit("sampler_floor: --beds takes bed numbers, e.g. 1,2,3")
    if any(b not in BEDS for b in beds):
        raise SystemExit("sampler_floor: the beds are %s" % ", ".join(str(b) for b in BEDS))
    for s in a.settings:
        if s not in SETTINGS:
            raise SystemExit("sampler_floor: unknown setting '%s' (known: %s)" % (s, ", ".join(SETTINGS)))
    if a.cmd == "run":
        run(a.settings or list(SETTINGS), beds, a.threads)
    elif a.cmd == "report":
        report()
    else:
        for name, (what, _) in SETTINGS.items():
            print("%-10s %-60s kept: %s" % (name, what, ", ".join("b%d" % b for b in sorted(load(name))) or "none"))


if __name__ == "__main__":
    main()
