#!/usr/bin/python3
"""Bed packing study (docs/validation/beds.md; docs/scenes.md E.1, F).

  bed_campaign.py BIN OUT DOCS study [CASE...]   small beds: lattice against random fills, packing
                                                  against the solid fraction of the generation region
  bed_campaign.py BIN OUT DOCS prepare [BED...]  the shipped beds (config/beds/BED.bed), three seeds of
                                                  the 30 cm MASCOT beds and of the sampler bed, and the
                                                  graded 30 cm beds (ga, gd)
  bed_campaign.py BIN OUT DOCS creep [BED...]    how far a prepared MASCOT bed's surface moves when left
                                                  alone for a landing's duration (default: the graded beds
                                                  and their whole beds)
  bed_campaign.py BIN OUT DOCS report            DOCS/study.md, study.png and DOCS/prepared.md

A small MASCOT-like bed (config/validation/bed_small.yaml: the MASCOT grains, walls and
stiffness in a cylinder of 0.25 m radius, 5,000 grains) is poured under 1 g, either from the
jittered lattice the shipped beds were generated on before, or from random positions in a
cylinder whose height sets the solid fraction f of the generation region (the grains fall
from higher the lower f is). Each run's packing is measured from its final grains and kept
as DOCS/study/CASE/summary.json (committed: the study resumes on any machine; BEDS_RERUN=1 reruns).

The shipped beds are generated the same way, at f = 0.15 (FILL_FRACTION) for every bed:
config/beds/mascot_bed.yaml and config/beds/sampler_bed.yaml with the depth, material, seed,
grain count and region height of each (BEDS). Each bed's figures (grains, packing, bulk
density, rest check, wall time) are kept as DOCS/prepared/BED/summary.json, its snapshot as
config/beds/BED.bed; the stages' snapshots stay in OUT/BED (restart points).
BEDS_THREADS: threads per preparation (default 1).
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import campaign_cli  # noqa: E402
from bed_file import mascot_contact, surface  # noqa: E402
from plots import pyplot  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SMALL = os.path.join(ROOT, "config", "validation", "bed_small.yaml")
# The small bed scaled to the sampler's grains (2.5 mm, sigma 30 %): every length a quarter of the
# small bed's, the sampler bed's first-stage contacts (config/validation/bed_small_sampler.yaml).
SMALL_SAMPLER = os.path.join(ROOT, "config", "validation", "bed_small_sampler.yaml")
SAMPLER_SCALE = 0.25  # sampler mean grain radius over the MASCOT one
SAMPLER_FRACTIONS = [0.06, 0.15]
R_SMALL = 0.25        # container radius of the small bed, m
N_SMALL = 5000        # grains generated
MEAN_VOLUME = None    # mean grain volume, m^3 (from the radius distribution; computed once)
FRACTIONS = [0.06, 0.08, 0.10, 0.12, 0.15, 0.20]
MATERIALS = ["gravel", "moderate"]
SEEDS = [1, 2]
H_TRIM = 0.15         # the trim height at which the small beds' counts are compared, m
FILL_FRACTION = 0.15  # solid fraction of the generation region of every shipped bed
# The pile is generated to stand about this much above the rim (at a packing of 0.55): two grain
# diameters of the MASCOT beds, four of the sampler's, m.
MARGIN = {"mascot": 0.04, "sampler": 0.02}
MASCOT_R = 0.75       # MASCOT container radius, m
SAMPLER_R = 0.15      # sampler container radius, m
# Published grain counts (docs/scenes.md A.3, B.5).
PUBLISHED = {"mascot_gravel_d15": 28375, "mascot_gravel_d30": 58454, "mascot_gravel_d40": 78176,
             "mascot_moderate_d15": 31082, "mascot_moderate_d30": 62551, "mascot_moderate_d40": 83097,
             "sampler_gravel": 101657}
CREEP = os.path.join(ROOT, "config", "validation", "bed_creep.yaml")
CREEP_ZONE = 0.35     # the surface is sampled within this distance of the axis (the graded beds' fine zone), m
CREEP_CELL = 0.04     # ... on square cells of this side (two mean diameters), m
CREEP_LIMIT = 0.1     # a bed creeps when its surface moves by more than this many mean radii in 10 s
CORE_WALL = 0.05      # the core region keeps this far from the side wall, m
CORE_FLOOR = 0.03     # ... from the floor and from the pile's top, m


def grain_volume(mean, sigma):
    """Mean volume of a grain of radius mean (1 + sigma z), z standard normal cut at +-1."""
    n, acc, w = 4000, 0.0, 0.0
    for k in range(n):
        z = -1 + (k + 0.5) * 2 / n
        p = math.exp(-z * z / 2)
        acc += p * (4 / 3) * math.pi * (mean * (1 + sigma * z)) ** 3
        w += p
    return acc / w


def mean_volume():
    """Mean volume of a MASCOT grain (1 cm, sigma 33 %)."""
    global MEAN_VOLUME
    if MEAN_VOLUME is None:
        MEAN_VOLUME = grain_volume(0.01, 0.33)
    return MEAN_VOLUME


def fill(radius, depth, margin, v_mean):
    """(count, region top) of a bed of this depth in a cylinder of this radius: enough grains for a
    pile `margin` above the rim at a packing of 0.55, generated at the solid fraction FILL_FRACTION."""
    area = math.pi * radius ** 2
    count = int(round(area * (depth + margin) * 0.55 / v_mean, -3))
    return count, count * v_mean / (area * FILL_FRACTION)


def beds():
    """name -> (config, overrides, snapshot precision, published count or None, container radius, rim)."""
    out = {}
    for mat in MATERIALS:
        for cm in (15, 30, 40):
            for seed in ((1, 2, 3) if cm == 30 else (1,)):
                name = "mascot_%s_d%d%s" % (mat, cm, "" if seed == 1 else "_s%d" % seed)
                count, top = fill(MASCOT_R, cm / 100, MARGIN["mascot"], mean_volume())
                ov = ["materials.regolith.preset=%s" % mat, "materials.container.preset=%s" % mat,
                      "seed=%d" % (2018 + seed - 1), "grains.0.fill.count=%d" % count,
                      "grains.0.fill.z=[0.0,%.4f]" % top, "stages.1.trim_above=%.2f" % (cm / 100)]
                out[name] = ("mascot_bed.yaml", ov, "32", PUBLISHED["mascot_%s_d%d" % (mat, cm)], MASCOT_R,
                             cm / 100)
    # Graded 30 cm beds (config/beds/mascot_bed_graded.yaml; docs/scenes.md E.1): the same region,
    # fraction and seeds as the shipped 30 cm beds, the grading's heights mapped by the pile's
    # compaction (its height over the region's).
    # ga: as the file (fine within 0.35 m of the axis and 10 cm below the surface); gd: in depth only
    # (the published distribution over the whole top 10 cm).
    for grading, extra in (("ga", []), ("gd", ["grains.0.fill.grading.radial_rate=0"])):
        for mat in MATERIALS:
            for seed in (1, 2, 3):
                name = "mascot_%s_d30_%s%s" % (mat, grading, "" if seed == 1 else "_s%d" % seed)
                _, top = fill(MASCOT_R, 0.30, MARGIN["mascot"], mean_volume())
                ov = ["materials.regolith.preset=%s" % mat, "materials.container.preset=%s" % mat,
                      "seed=%d" % (2018 + seed - 1), "grains.0.fill.z=[0.0,%.4f]" % top,
                      "grains.0.fill.grading.compaction=%.4f" % ((0.30 + MARGIN["mascot"]) / top)] + extra
                out[name] = ("mascot_bed_graded.yaml", ov, "32", None, MASCOT_R, 0.30)
    for seed in (1, 2, 3):
        name = "sampler_gravel%s" % ("" if seed == 1 else "_s%d" % seed)
        count, top = fill(SAMPLER_R, 0.20, MARGIN["sampler"], grain_volume(0.0025, 0.30))
        ov = ["seed=%d" % (2019 + seed - 1), "grains.0.fill.count=%d" % count, "grains.0.fill.z=[0.0,%.4f]" % top]
        out[name] = ("sampler_bed.yaml", ov, "64", PUBLISHED["sampler_gravel"], SAMPLER_R, 0.20)
    return out


def bed_figures(grains_file, radius, rim, density=2430.0):
    """Grains, packing fraction and bulk density of a prepared bed (grains with their centre at or below
    the rim, over the cylinder up to the rim), and the highest grain top above the rim."""
    rows = [list(map(float, ln.split()))[1:5] for ln in open(grains_file) if not ln.startswith("#")]
    vol = sum((4 / 3) * math.pi * r ** 3 for _, _, z, r in rows if z <= rim)
    packing = vol / (math.pi * radius ** 2 * rim)
    return {"grains": len(rows), "packing": packing, "bulk_density": packing * density,
            "highest_top_above_rim": max(z + r for _, _, z, r in rows) - rim}


def prepare(bin_dir, out, docs, names):
    known = beds()
    campaign_cli.check_names(names, known, "bed")
    threads = int(os.environ.get("BEDS_THREADS", "1"))
    for name in names or list(known):
        keep = os.path.join(docs, "prepared", name)
        if campaign_cli.kept(keep, "BEDS_RERUN") is not None:
            continue
        config, overrides, precision, published, radius, rim = known[name]
        snapshot = os.path.join(ROOT, "config", "beds", name + ".bed")
        run_dir = os.path.join(out, name)
        extra = ["--snapshot", snapshot, "--snapshot-precision", precision, "--stage-snapshots"]
        s = campaign_cli.run_and_keep(bin_dir, os.path.join(ROOT, "config", "beds", config), run_dir, keep,
                                      overrides, {"bed": name, "published_grains": published}, threads=threads,
                                      extra=extra)
        if s is None:
            continue
        fig = bed_figures(os.path.join(run_dir, "final_grains.txt"), radius, rim)
        fig["snapshot_bytes"] = os.path.getsize(snapshot)
        # The rest check: RMS and largest grain speed at the end (the series' last row).
        with open(os.path.join(run_dir, "series.csv")) as f:
            rows = [ln.strip().split(",") for ln in f if ln.strip() and not ln.startswith("#")]
        head, last = rows[0], rows[-1]
        fig["rest_rms_speed"] = float(last[head.index("rms_speed")])
        fig["rest_max_speed"] = float(last[head.index("max_speed")])
        fig["published_grains"] = published
        fig["difference"] = fig["grains"] / published - 1 if published else None
        s["bed"] = fig
        with open(os.path.join(keep, "summary.json"), "w") as f:
            json.dump(s, f, indent=1)
        print("%s: %d grains (published %s, %+.1f %%), packing %.4f, %.0f kg/m^3 (%.0f s)" % (
            name, fig["grains"], published, 100 * (fig["difference"] or 0), fig["packing"], fig["bulk_density"],
            s["campaign"]["wall_seconds"]), flush=True)


def cases():
    """name -> (material, overrides, config, length scale of the bed)."""
    out = {}
    for mat in MATERIALS:
        mo = ["materials.regolith.preset=%s" % mat, "materials.container.preset=%s" % mat]
        out["lattice_%s" % mat] = (mat, mo + ["grains.0.fill.arrangement=lattice"], SMALL, 1.0)
        # A control: the lattice spread out (4 cm apart) with a jitter as large as the room allows,
        # so that grains of a column no longer stand on each other.
        out["lattice_wide_%s" % mat] = (mat, mo + ["grains.0.fill.arrangement=lattice", "grains.0.fill.spacing=0.04",
                                                   "grains.0.fill.jitter=0.0067", "grains.0.fill.z=[0.0,2.0]"],
                                           SMALL, 1.0)
        for f in FRACTIONS:
            top = N_SMALL * mean_volume() / (math.pi * R_SMALL ** 2 * f)
            for seed in SEEDS:
                out["random_%s_f%.2f_s%d" % (mat, f, seed)] = (
                    mat, mo + ["grains.0.fill.z=[0.0,%.4f]" % top, "seed=%d" % seed], SMALL, 1.0)
    # The same pour with the sampler's grains on a bed scaled to them: is the packing set by the
    # region's height in grain radii (the sampler bed's region is 2.6 times the MASCOT 30 cm bed's
    # in those units at the same f), whatever the grains' size, stiffness and wall restitution?
    r_s = R_SMALL * SAMPLER_SCALE
    for f in SAMPLER_FRACTIONS:
        top = N_SMALL * grain_volume(0.0025, 0.30) / (math.pi * r_s ** 2 * f)
        for seed in SEEDS:
            out["sampler_grains_f%.2f_s%d" % (f, seed)] = (
                "gravel", ["grains.0.fill.z=[0.0,%.4f]" % top, "seed=%d" % seed], SMALL_SAMPLER, SAMPLER_SCALE)
    return out


def cap_volume(r, h):
    """Volume of a sphere of radius r below a plane h above its centre (h in [-r, r])."""
    h = max(-r, min(r, h))
    a = r + h
    return math.pi * a * a * (3 * r - a) / 3


def packing(grains_file, scale=1.0):
    """Packing figures of a settled small bed from its final_grains.txt (every length of the core region,
    the trim height and the container multiplied by scale for a bed scaled to other grains)."""
    rows = [list(map(float, ln.split()))[1:5] for ln in open(grains_file) if not ln.startswith("#")]
    tops = sorted(z + r for _, _, z, r in rows)
    top = sum(tops[-50:]) / 50  # the pile's top: the mean top of its 50 highest grains
    h_trim, radius = H_TRIM * scale, R_SMALL * scale
    zlo, zhi = CORE_FLOOR * scale, min(h_trim, top) - CORE_FLOOR * scale
    rin = radius - CORE_WALL * scale
    vol = 0.0
    for x, y, z, r in rows:
        if math.hypot(x, y) < rin:
            vol += cap_volume(r, zhi - z) - cap_volume(r, zlo - z)
    core = vol / (math.pi * rin * rin * (zhi - zlo))
    n_centre = sum(1 for _, _, z, _ in rows if z <= h_trim)
    n_top = sum(1 for _, _, z, r in rows if z + r <= h_trim)
    return {"core_packing": core, "top": top, "n_centre": n_centre, "n_top": n_top,
            "packing_centre_trim": sum((4 / 3) * math.pi * r ** 3 for _, _, z, r in rows if z <= h_trim)
            / (math.pi * radius ** 2 * h_trim)}


def study(bin_dir, out, docs, names):
    known = cases()
    campaign_cli.check_names(names, known, "case")
    keep_root = os.path.join(docs, "study")
    for name in names or list(known):
        keep = os.path.join(keep_root, name)
        if campaign_cli.kept(keep, "BEDS_RERUN") is not None:
            continue
        mat, overrides, config, scale = known[name]
        run_dir = os.path.join(out, name)
        s = campaign_cli.run_and_keep(bin_dir, config, run_dir, keep, overrides, {"case": name, "material": mat})
        if s is None:
            continue
        p = packing(os.path.join(run_dir, "final_grains.txt"), scale)
        s["packing"] = p
        with open(os.path.join(keep, "summary.json"), "w") as f:
            json.dump(s, f, indent=1)
        print("%s: core packing %.4f, %d grains below %.2f m by centre, %d by top (%.0f s)" % (
            name, p["core_packing"], p["n_centre"], H_TRIM * scale, p["n_top"], s["campaign"]["wall_seconds"]),
            flush=True)


def load(docs):
    out = {}
    root = os.path.join(docs, "study")
    for name in sorted(os.listdir(root)) if os.path.isdir(root) else []:
        f = os.path.join(root, name, "summary.json")
        if os.path.exists(f):
            out[name] = json.load(open(f))
    return out


def report(docs):
    plt = pyplot()
    runs = load(docs)
    lines = ["# Bed packing study", "",
             "Generated by `scripts/validate_beds study` (`scripts/bed_campaign.py`) from the runs in "
             "`study/`. A small MASCOT-like bed (`config/validation/bed_small.yaml`: 5,000 grains of 1 cm "
             "mean radius, σ 33 %%, in a cylinder of %.2f m radius, the MASCOT walls and k_n) is poured "
             "under 1 g until its RMS speed is below 5 mm/s. **Core packing**: the solid fraction of the "
             "grains' volume (exact sphere caps) between %.2f m above the floor and %.2f m below the "
             "pile's top or the %.2f m trim height, within %.2f m of the axis (%.2f m from the wall). "
             "**Counts**: grains whose centre, or whose top, is at or below %.2f m. "
             "f: the solid fraction of the random generation region (its height is N ⟨V⟩ / (π R² f)); "
             "the lattice is the jittered simple cubic fill the beds were generated on before. "
             "`sampler_grains_*`: the same pour with the sampler bed's grains (2.5 mm mean radius, σ 30 %%) "
             "and first-stage contacts (k_n 1.97e4 N/m, Δt 25 µs, wall restitution 0.3) on a bed scaled "
             "to them (`config/validation/bed_small_sampler.yaml`: every length, the core region's and "
             "the trim height's included, %g times the above), so that at one f the region is as tall "
             "in grain radii as the MASCOT-grain bed's." % (
                 R_SMALL, CORE_FLOOR, CORE_FLOOR, H_TRIM, R_SMALL - CORE_WALL, CORE_WALL, H_TRIM,
                 SAMPLER_SCALE), "",
             "| case | material | fill | f | seed | core packing | grains by centre | by top | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    fig, ax = plt.subplots(1, 1, figsize=(6, 4))
    for mat, color in zip(MATERIALS, ("C0", "C1")):
        xs, ys = [], []
        for name, s in runs.items():
            if s["campaign"]["material"] != mat or not name.startswith("random"):
                continue
            f = float(name.split("_f")[1].split("_")[0])
            xs.append(f)
            ys.append(s["packing"]["core_packing"])
        if xs:
            ax.plot(xs, ys, "o", color=color, label="%s, random fill" % mat)
        if mat == "gravel":
            pts = [(float(n.split("_f")[1].split("_")[0]), s["packing"]["core_packing"])
                   for n, s in runs.items() if n.startswith("sampler_grains")]
            if pts:
                ax.plot([f for f, _ in pts], [c for _, c in pts], "x", color=color, ms=8,
                        label="gravel, sampler grains (bed scaled by %g)" % SAMPLER_SCALE)
        lat = runs.get("lattice_%s" % mat)
        if lat:
            ax.axhline(lat["packing"]["core_packing"], color=color, ls="--", lw=1, label="%s, lattice fill" % mat)
    for name, s in runs.items():
        p = s["packing"]
        if name.startswith("random") or name.startswith("sampler_grains"):
            f, seed = name.split("_f")[1].split("_s")
            fill = "random" if name.startswith("random") else "random, sampler grains, scaled bed"
        else:
            f, seed = "–", "–"
            fill = "lattice 4 cm, jitter ±6.7 mm" if name.startswith("lattice_wide") else "lattice"
        lines.append("| `%s` | %s | %s | %s | %s | %.4f | %d | %d | %.0f |" % (
            name, s["campaign"]["material"], fill, f, seed, p["core_packing"], p["n_centre"], p["n_top"],
            s["campaign"]["wall_seconds"]))
    ax.set_xlabel("solid fraction f of the generation region")
    ax.set_ylabel("core packing fraction after the 1 g pour")
    ax.set_title("Small bed (R = 0.25 m, 5,000 grains)", fontsize=9)
    lines += campaign_cli.failure_lines(os.path.join(docs, "study"))
    path = campaign_cli.write_report(docs, lines, fig, [ax], "study.png", "core packing against f", name="study.md")
    print("report: %s" % path)


def whole_bed(name):
    """The whole (ungraded) bed of a graded bed's preparation: mascot_moderate_d30_ga_s2 -> mascot_moderate_d30_s2."""
    return name.replace("_ga", "").replace("_gd", "")


def creep(bin_dir, out, docs, names):
    """Each MASCOT bed in the creep scene (config/validation/bed_creep.yaml): the landing's relaxation,
    then 10 s alone; the surface's height within CREEP_ZONE of the axis before and after the 10 s. A
    graded bed runs at the k_n and dt of the rule on the whole bed of its preparation."""
    known = beds()
    graded = [n for n in known if "_d30_g" in n]
    names = names or graded + [whole_bed(n) for n in graded if "_d30_ga" in n]
    campaign_cli.check_names(names, known, "bed")
    failed = []
    for name in names:
        if not name.startswith("mascot_"):
            raise SystemExit("creep: %s is not a MASCOT bed" % name)
        keep = os.path.join(docs, "creep", name)
        if campaign_cli.kept(keep, "BEDS_RERUN") is not None:
            continue
        bed = os.path.join(ROOT, "config", "beds", name + ".bed")
        if not os.path.exists(bed):
            print("%s: not prepared yet (scripts/validate_beds prepare %s)" % (name, name), flush=True)
            continue
        mat = name.split("_")[1]
        ov = ["materials.regolith.preset=%s" % mat, "materials.container.preset=%s" % mat,
              "grains.0.file=../beds/%s.bed" % name]
        if whole_bed(name) != name:
            kn, dt = mascot_contact(os.path.join(ROOT, "config", "beds", whole_bed(name) + ".bed"))
            ov += ["contact.kn=%.10g" % kn, "contact.dt=%.10g" % dt]
        run_dir = os.path.join(out, "creep", name)
        s = campaign_cli.run_and_keep(bin_dir, CREEP, run_dir, keep, ov, {"bed": name}, extra=["--stage-snapshots"])
        if s is None:
            failed.append("%s (the run failed)" % name)
            continue
        before, cells = surface(os.path.join(run_dir, "relax.bed"), CREEP_ZONE, CREEP_CELL)
        after, _ = surface(os.path.join(run_dir, "free.bed"), CREEP_ZONE, CREEP_CELL)
        s["creep"] = {"surface_before": before, "surface_after": after, "drift": after - before, "cells": cells,
                      "free_seconds": 10.0, "mean_radius": 0.01, "drift_over_mean_radius": (after - before) / 0.01}
        with open(os.path.join(keep, "summary.json"), "w") as f:
            json.dump(s, f, indent=1)
        print("%s: surface %.5f -> %.5f m over 10 s (%.3f mean radii; %.0f s)" % (
            name, before, after, (after - before) / 0.01, s["campaign"]["wall_seconds"]), flush=True)
    # Every named bed's kept result against the criterion (a bed run before counts as well).
    creeping = failed
    for name in names:
        if campaign_cli.kept(os.path.join(docs, "creep", name), "BEDS_RERUN") == "failed" and \
                "%s (the run failed)" % name not in creeping:
            creeping.append("%s (the run failed)" % name)  # kept from an earlier call
        p = os.path.join(docs, "creep", name, "summary.json")
        c = json.load(open(p)).get("creep") if os.path.exists(p) else None
        if c and abs(c["drift_over_mean_radius"]) > CREEP_LIMIT:
            creeping.append("%s (%+.3f mean radii)" % (name, c["drift_over_mean_radius"]))
    return creeping


def report_prepared(docs):
    """DOCS/prepared.md: every prepared bed against its published count (and the f = 0.12 trial)."""
    lines = ["# Shipped beds against the published counts", "",
             "Generated by `scripts/validate_beds report` from `prepared/*/summary.json` (and the trial at "
             "f = 0.12 in `trial_f0.12/`). Grains: after the cut (every grain whose top stood above the rim "
             "removed) and the relaxation, as shipped. Packing: the volume of the grains whose centre is at or "
             "below the rim over the cylinder up to the rim; bulk density: packing × 2430 kg/m³. Rest: RMS and "
             "largest grain speed at the end. Wall: one thread unless stated, on a machine shared with other "
             "runs.", "",
             "| bed | f | seed | grains | published | difference | packing | bulk density (kg/m³) | rest (m/s) "
             "| snapshot | wall (s) |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for sub, f in (("prepared", FILL_FRACTION), ("trial_f0.12", 0.12)):
        root = os.path.join(docs, sub)
        for name in sorted(os.listdir(root)) if os.path.isdir(root) else []:
            p = os.path.join(root, name, "summary.json")
            if not os.path.exists(p):
                continue
            s = json.load(open(p))
            b = s.get("bed") or {}
            seed = [o.split("=")[1] for o in s["campaign"]["overrides"] if o.startswith("seed=")]
            rest = "%.1e / %.1e" % (b["rest_rms_speed"], b["rest_max_speed"]) if "rest_rms_speed" in b else "–"
            lines.append("| `%s` | %.2f | %s | %s | %s | %s | %.4f | %.0f | %s | %s | %.0f |" % (
                name, f, seed[0] if seed else "–", format(b.get("grains", 0), ","),
                format(b["published_grains"], ",") if b.get("published_grains") else "–",
                "%+.1f %%" % (100 * b["difference"]) if b.get("difference") is not None else "–",
                b.get("packing", float("nan")), b.get("bulk_density", float("nan")), rest,
                "%.0f kB" % (b["snapshot_bytes"] / 1e3) if b.get("snapshot_bytes") else "–",
                s["campaign"]["wall_seconds"]))
    root = os.path.join(docs, "creep")
    rows = []
    for name in sorted(os.listdir(root)) if os.path.isdir(root) else []:
        p = os.path.join(root, name, "summary.json")
        c = json.load(open(p)).get("creep") if os.path.exists(p) else None
        if c:
            rows.append("| `%s` | %.4f | %.4f | %+.2f mm | %+.3f | %s |" % (
                name, c["surface_before"], c["surface_after"], 1e3 * c["drift"], c["drift_over_mean_radius"],
                "yes" if abs(c["drift_over_mean_radius"]) <= CREEP_LIMIT else "no"))
    if rows:
        lines += ["", "## Creep", "",
                  "`scripts/validate_beds creep`: each bed as a landing loads it (the landing's relaxation), then "
                  "10 s alone under the scene's gravity; the surface is the mean over 4 cm cells within 0.35 m of "
                  "the axis of the highest grain top in each (graded beds at the whole bed's k_n and Δt). "
                  "Criterion: the surface moves by at most 0.1 mean radius (1 mm).", "",
                  "| bed | surface before (m) | after 10 s (m) | drift | drift / mean radius | within 0.1 |",
                  "|---|---|---|---|---|---|"] + rows
    with open(os.path.join(docs, "prepared.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("report: %s" % os.path.join(docs, "prepared.md"))


def main():
    bin_dir, out, docs, cmd, names = campaign_cli.command_line(__doc__)
    if cmd == "study":
        study(bin_dir, out, docs, names)
    elif cmd == "prepare":
        prepare(bin_dir, out, docs, names)
    elif cmd == "creep":
        creeping = creep(bin_dir, out, docs, names)
        if creeping:
            print("creep: failed or moved by more than %g mean radii in 10 s: %s" % (CREEP_LIMIT, ", ".join(creeping)),
                  file=sys.stderr)
            sys.exit(1)
    elif cmd == "report":
        report(docs)
        report_prepared(docs)
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main()
