#!/usr/bin/python3
"""Bucket-impact campaign (docs/scenes.md C.1, docs/validation/bucket.md).

  bucket_campaign.py BIN OUT DOCS run [BED...]   every run of each bed (default: the 10 cm beds of both
                                                  10 mm materials), then gb_8 ... gbb_12 and gb_10_5mm on request
  bucket_campaign.py BIN OUT DOCS report         DOCS/report.md and its plots

Beds: glass_beads or glass_beads_b, 10 mm beads cut at 8, 10 or 12 cm (gb_8 ... gbb_12), and
gb_10_5mm (5 mm beads, 10 cm: the costly one). Every bead whose top stands above the bed height H
is cut; z_stop is the sphere's bottom below H (the published definition). Runs of a bed: the ten
speeds 0.1 ... 1.0 m/s on the container's axis (BED_vSPEED), and at 0.25, 0.5, 0.75 and 1.0 m/s
three aim points one bead diameter off the axis (BED_vSPEED_aK, K = 1, 2, 3). A finished run's
summary.json and impact.csv are copied to DOCS/RUN/ (committed: a campaign resumes on any
machine; BUCKET_RERUN=1 runs again); a run that stopped leaves failed.txt there, not retried.
BUCKET_SPEEDS=0.3,0.7 runs only those speeds; BUCKET_AIMS=0 skips the aim points (=only: only
them); BUCKET_THREADS threads per run (default 1). Runs on the beds of the lattice fill (before
the beds were generated at random) are kept in DOCS/lattice_beds/ as evidence; they are not read.
"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import campaign_cli  # noqa: E402
import csv_columns  # noqa: E402
import stats  # noqa: E402
from plots import pyplot  # noqa: E402

CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config", "bucket_impact.yaml")
SPEEDS = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
AIM_SPEEDS = [0.25, 0.5, 0.75, 1.0]
# Aim points one bead diameter (1 cm) off the axis, 120 degrees apart (the 5 mm beads: the same points).
AIMS = {1: (0.01, 0.0), 2: (-0.005, 0.00866), 3: (-0.005, -0.00866)}
# Published (Nguyen et al. 2019 set-up as the published DEM study ran it; docs/scenes.md C.1):
# grain counts of the cut beds, and the glass_beads z_stop curve of 10 mm beads (m).
PUBLISHED_GRAINS = {"gb_8": 6274, "gb_10": 7987, "gb_12": 9682, "gbb_8": 6274, "gbb_10": 7987, "gbb_12": 9682,
                    "gb_10_5mm": 67420}
PUBLISHED_ZSTOP_GB = {0.25: 0.0040, 0.5: 0.0092, 0.75: 0.0131, 1.0: 0.0160}
BEDS = {}
for mat, tag in (("glass_beads", "gb"), ("glass_beads_b", "gbb")):
    for h in (8, 10, 12):
        BEDS["%s_%d" % (tag, h)] = ["materials.beads.preset=%s" % mat, "stages.1.trim_above=%g" % (h / 100)]
# 5 mm beads: 90,000 generated in a region 0.504 m tall (solid fraction 0.15, as the 10 mm beads).
BEDS["gb_10_5mm"] = ["materials.beads.preset=glass_beads", "grains.0.radius=0.0025", "grains.0.fill.count=90000",
                     "grains.0.fill.z=[0.0,0.504]", "stages.1.trim_above=0.10"]
DEFAULT = ["gb_10", "gbb_10"]
# A run ends once the sphere has rested (below 1 mm/s for 0.05 s) or 0.3 s after it is released: on
# these beds it stops sinking within 0.1 s, then jitters on the beads at a few 0.1 mm/s for long
# (gb_10 at 0.1 m/s ran 0.79 s to rest; its depth changed by 0.03 mm after 0.1 s). The report
# checks every run's depth change over its last 0.1 s.
DURATION = 0.3
# The costly bed runs its speeds spread out first, so that a campaign cut short
# across sittings still spans 0.1-1.0 m/s and fits the force law early.
ORDER = {"gb_10_5mm": [0.1, 1.0, 0.5, 0.3, 0.7, 0.8, 0.4, 0.6, 0.2, 0.9]}


def read_json(path):
    with open(path) as f:
        return json.load(f)


def run_name(bed, v, aim=0):
    return "%s_v%.2f%s" % (bed, v, "_a%d" % aim if aim else "")


def run_one(bin_dir, out, docs, bed, v, threads, aim=0):
    tag = run_name(bed, v, aim)
    keep = os.path.join(docs, tag)
    if campaign_cli.kept(keep, "BUCKET_RERUN") is not None:
        return
    overrides = ["impact.speed=%g" % v, "impact.duration=%g" % DURATION] + BEDS[bed]
    if aim:
        overrides.append("impact.aim=[%g,%g]" % AIMS[aim])
    s = campaign_cli.run_and_keep(bin_dir, CONFIG, os.path.join(out, tag), keep, overrides,
                                  {"bed": bed, "speed": v, "aim": aim}, copies=["impact.csv"], threads=threads)
    if s is None:
        return
    res = s["result"]
    print("%s: z_stop %.4g m below H (%.4g below the mean top), %.4g s to 1 cm/s, %s, f0 %.4g N, 1/d1 %.4g 1/m "
          "(%.0f s)" % (tag, res["stopping_depth"], res["stopping_depth_mean_top"], res["duration_1cm_s"],
                        "bounced" if res["bounced"] else "no bounce", res["f0"], res["inv_d1"],
                        s["campaign"]["wall_seconds"]), flush=True)


def law_fit(vs, ps, m=1.0, g=9.81):
    """The force law m a = -m g + f0 + m v^2/d1 fitted across impacts: the stopping depth of a
    sphere entering at V, p(V) = (d1/2) ln(1 + V^2 / ((f0/m - g) d1)) (V^2 / (2 (f0/m - g)) as 1/d1 -> 0)
    by bounded least squares in c = f0/m - g > 0 and 1/d1 >= 0: (f0, 1/d1, rms)."""
    def depth(v, p):
        c, k = p
        x = v * v / c
        return np.where(k > 1e-12, np.log1p(x * max(k, 1e-12)) / (2 * max(k, 1e-12)), 0.5 * x)

    start_c = float(np.median([v * v / (2 * p) for v, p in zip(vs, ps)]))  # the 1/d1 = 0 estimate
    (c, k), rms = stats.curve_fit(depth, vs, ps, [start_c, 1.0], [1e-9, 0.0], [np.inf, 1e4])
    return m * (c + g), k, rms


def load(docs):
    """bed -> {"sweep": [summaries on the axis], "aims": {speed: [summaries at the aim points]}}."""
    out = {}
    for bed in BEDS:
        d = {"sweep": [], "aims": {}}
        for v in SPEEDS:
            f = os.path.join(docs, run_name(bed, v), "summary.json")
            if os.path.exists(f):
                d["sweep"].append(read_json(f))
        for v in AIM_SPEEDS:
            for a in AIMS:
                f = os.path.join(docs, run_name(bed, v, a), "summary.json")
                if os.path.exists(f):
                    d["aims"].setdefault(v, []).append(read_json(f))
        if d["sweep"] or d["aims"]:
            out[bed] = d
    return out


def late_sinking(docs, s):
    """How much deeper the sphere's lowest point went over the run's last 0.1 s (m), from its impact.csv."""
    name = run_name(s["campaign"]["bed"], s["campaign"]["speed"], s["campaign"].get("aim", 0))
    path = os.path.join(docs, name, "impact.csv")
    if not os.path.exists(path):
        return float("nan")
    c = csv_columns.read_csv(path)
    t, depth = c["t"], c["depth"]
    before = float(depth[t <= t[-1] - 0.1].max()) if t[-1] > 0.1 else 0.0
    return float(depth.max()) - before


def at_speed(d, v, key="stopping_depth"):
    """A bed's values of result[key] at speed v: its aim points, and the axis run if the sweep has v."""
    xs = [s["result"][key] for s in d["aims"].get(v, [])]
    xs += [s["result"][key] for s in d["sweep"] if abs(s["input"]["speed"] - v) < 1e-9]
    return xs


def bed_figures(d):
    """A bed's campaign figures: grains, alpha (sweep, z_stop > 0), force law across every run, bounces."""
    runs = d["sweep"] + [s for v in d["aims"] for s in d["aims"][v]]
    f = {"runs": len(runs), "bed": runs[0]["bed"] if runs else None}
    sw = sorted(d["sweep"], key=lambda s: s["input"]["speed"])
    ok = [(s["result"]["total_drop_height"], s["result"]["stopping_depth"]) for s in sw
          if s["result"]["stopping_depth"] > 0]
    f["alpha"] = stats.power_fit(*zip(*ok))[1] if len(ok) >= 3 else float("nan")
    f["alpha_speeds"] = len(ok)
    f["bounced"] = sum(1 for s in runs if s["result"]["bounced"])
    f["bounced_1mm_s"] = sum(1 for s in runs if s["result"].get("bounced_1mm_s"))
    f["f0"] = f["inv_d1"] = f["law_rms"] = float("nan")
    if len(runs) >= 5:
        mass, g = runs[0]["input"]["sphere_mass"], runs[0]["input"]["gravity"]
        f["f0"], f["inv_d1"], f["law_rms"] = law_fit([s["input"]["speed"] for s in runs],
                                                     [s["result"]["stopping_depth"] for s in runs], mass, g)
    return f


def report(docs):
    plt = pyplot()
    beds = load(docs)
    lines = ["# Bucket impact: campaign figures", "",
             "Generated by `scripts/validate_bucket report`. **z_stop** (the published definition): the sphere's "
             "bottom at its lowest below the bed's nominal surface H, the height above which every bead was cut; "
             "the variant measures it below the mean top of the highest beads (one layer). H_drop = V²/2g + z_stop; "
             "α from one least-squares line through log z_stop against log H_drop over the ten speeds on the axis "
             "(z_stop > 0). **Bounce** (published): after the deepest point reached so far the bottom rises by more "
             "than 0.1 mm, or the sphere moves up faster than 1 cm/s; the variant: faster than 1 mm/s. Durations "
             "from the first contact force until |v_z| < 1 cm/s and < 1 mm/s. f₀, 1/d₁ across speeds: the law "
             "m a = −m g + f₀ + m v²/d₁, whose stopping depth for a sphere entering at V is "
             "(d₁/2) ln(1 + V²/((f₀/m − g) d₁)), fitted to every run's z_stop (bounded least squares, 1/d₁ ≥ 0).",
             "", "Aim points: 1 cm off the axis at 0°, 120° and 240°; at 0.5 and 1.0 m/s the axis run of the ten "
             "speeds joins them.", "",
             "| bed | grains (published) | bulk density at H (kg/m³) | packing at H | runs | α | f₀, 1/d₁ across runs "
             "| bounced (published) | bounced (1 mm/s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    aims = ["", "| bed | V (m/s) | z_stop below H (cm), mean ± SD (n) | published (cm) | ratio | below the mean top (cm) "
            "| bounced |", "|---|---|---|---|---|---|---|"]
    detail = ["", "| run | V (m/s) | aim | z_stop below H (cm) | below mean top (cm) | H_drop (cm) | to 1 cm/s (ms) "
              "| to 1 mm/s (ms) | f₀ (N) | 1/d₁ (1/m) | rebound (mm) | bounced | deeper in the last 0.1 s (mm) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    late = []
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    ax[0].plot(list(PUBLISHED_ZSTOP_GB), [100 * z for z in PUBLISHED_ZSTOP_GB.values()], "k*", ms=10,
               label="published, glass_beads 10 mm")
    for bed, d in beds.items():
        f = bed_figures(d)
        b = f["bed"]
        pub = PUBLISHED_GRAINS.get(bed)
        law = "%.4g N, %.4g 1/m (rms %.2g mm)" % (f["f0"], f["inv_d1"], f["law_rms"] * 1e3) \
            if f["f0"] == f["f0"] else "(needs 5 runs)"
        lines.append("| %s | %d (%s, %+.1f %%) | %.0f | %.3f | %d | %.3f (%d speeds) | %s | %d of %d | %d of %d |" % (
            bed, b["grains"], pub, 100 * (b["grains"] / pub - 1), b["bulk_density"], b["packing_fraction"],
            f["runs"], f["alpha"], f["alpha_speeds"], law, f["bounced"], f["runs"], f["bounced_1mm_s"], f["runs"]))
        sw = sorted(d["sweep"], key=lambda s: s["input"]["speed"])
        line = ax[0].plot([s["input"]["speed"] for s in sw], [100 * s["result"]["stopping_depth"] for s in sw],
                          "o-", ms=3, label=bed)[0]
        for v in AIM_SPEEDS:
            zs = at_speed(d, v)
            if not zs:
                continue
            m, sd = stats.mean_sd(zs)
            mt, _ = stats.mean_sd(at_speed(d, v, "stopping_depth_mean_top"))
            nb = sum(1 for x in at_speed(d, v, "bounced") if x)
            ax[0].errorbar([v], [100 * m], yerr=[100 * sd if sd == sd else 0], fmt="s", color=line.get_color(),
                           capsize=3)
            p = PUBLISHED_ZSTOP_GB.get(v) if bed == "gb_10" else None
            aims.append("| %s | %.2f | %.3g ± %s (%d) | %s | %s | %.3g | %d of %d |" % (
                bed, v, 100 * m, "%.2g" % (100 * sd) if sd == sd else "–", len(zs),
                "%.2f" % (100 * p) if p else "–", "%.2f" % (m / p) if p else "–", 100 * mt, nb, len(zs)))
        ax[1].loglog([s["result"]["total_drop_height"] for s in sw if s["result"]["stopping_depth"] > 0],
                     [s["result"]["stopping_depth"] for s in sw if s["result"]["stopping_depth"] > 0], "o",
                     label=bed)
        ax[2].plot([s["input"]["speed"] for s in sw], [s["result"]["duration_1cm_s"] * 1e3 for s in sw], "o-",
                   label=bed)
        for s in sw + sorted([s for v in d["aims"] for s in d["aims"][v]],
                             key=lambda s: (s["input"]["speed"], s["campaign"].get("aim", 0))):
            r = s["result"]
            late.append(late_sinking(docs, s))
            detail.append("| %s | %.2f | %s | %.4g | %.4g | %.4g | %.4g | %.4g | %.4g | %.4g | %.3g | %s | %.3g |" % (
                bed, s["input"]["speed"], s["campaign"].get("aim", 0) or "axis", r["stopping_depth"] * 100,
                r["stopping_depth_mean_top"] * 100, r["total_drop_height"] * 100, r["duration_1cm_s"] * 1e3,
                r["duration_1mm_s"] * 1e3, r["f0"], r["inv_d1"], r["rebound"] * 1e3,
                "yes" if r["bounced"] else "no", 1e3 * late[-1]))
    ax[0].set_xlabel("impact speed V (m/s)")
    ax[0].set_ylabel("z_stop below H (cm); squares: aim points, mean ± SD")
    ax[1].set_xlabel("total drop height H_drop (m)")
    ax[1].set_ylabel("z_stop (m)")
    ax[2].set_xlabel("impact speed V (m/s)")
    ax[2].set_ylabel("collision duration to 1 cm/s (ms)")
    ok = [x for x in late if x == x]
    lines += aims + campaign_cli.failure_lines(docs)
    if ok:
        lines += ["", "Runs end at rest or %g s after release; over its last 0.1 s no run went deeper than %.3g mm "
                  "(the largest of the runs)." % (DURATION, 1e3 * max(ok))]
    lines += detail
    campaign_cli.write_report(docs, lines, fig, ax, "bucket.png" if beds else None,
                              "stopping depth, power law and durations")
    print("bucket report: %s" % os.path.join(docs, "report.md"))


def main():
    bin_dir, out, docs, cmd, beds = campaign_cli.command_line(__doc__)
    threads = int(os.environ.get("BUCKET_THREADS", "1"))
    if cmd == "run":
        beds = beds or DEFAULT
        campaign_cli.check_names(beds, BEDS, "bed")
        only = [float(x) for x in os.environ.get("BUCKET_SPEEDS", "").split(",") if x.strip()]
        bad = [v for v in only if v not in SPEEDS + AIM_SPEEDS]
        if bad:
            raise SystemExit("BUCKET_SPEEDS: %s not among the campaign's speeds %s" % (bad, SPEEDS + AIM_SPEEDS))
        aims = os.environ.get("BUCKET_AIMS", "1")
        for b in beds:
            if aims != "only":
                for v in ORDER.get(b, SPEEDS):
                    if not only or v in only:
                        run_one(bin_dir, out, docs, b, v, threads)
            if aims != "0":
                for v in AIM_SPEEDS:
                    for a in AIMS:
                        if not only or v in only:
                            run_one(bin_dir, out, docs, b, v, threads, a)
    elif cmd == "report":
        report(docs)
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main()
