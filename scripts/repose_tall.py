#!/usr/bin/python3
"""Angle of repose on tall poured heaps (docs/validation/repose.md).

  scripts/repose_tall.py run [RUN...]   runs (default: all, in the order of RUNS), one at a time
  scripts/repose_tall.py measure RUN...  measure a run's output (out/repose/RUN) again and keep it
  scripts/repose_tall.py report         results/repose/report.md and heaps.png from the kept results
  scripts/repose_tall.py list           the runs, and which are done

Scenes: config/validation/pour_tall_moderate.yaml and pour_tall_gravel.yaml (a poured fixed-base
cone at least 15 mean grain diameters tall). A run is one seed of one pour: "near" (the outlet 0.45 m
above the base, about 0.1 m above the final apex, as in the files), "high" (the outlet, plug and
hopper's grains raised by 0.40 m) or "wide" (gravel: the near pour through an outlet of radius 0.18 m
instead of 0.12 m, over which gravel arched). Each run is one regolith_sim process on one thread at the lowest
priority (nice 15); the raw output goes to out/repose/RUN/. A finished run leaves
results/repose/RUN/result.json (angle per quadrant, grains on the base, heap height in mean
grain diameters, wall and CPU time, the command) and RUN/profile.png, or RUN/arched.json when the grains
arched over the outlet and the hopper did not empty (no heap to measure); a run kept either way is
skipped (REPOSE_RERUN=1 runs it again), so the study resumes on any machine once those files are
committed. The angle is measured exactly as for the short heaps (scripts/lib/repose_angle.py, cone
geometry: four quadrants, flank fits over 0.15 R <= r <= 0.85 R).

Environment: REGOLITH_BIN (the folder of regolith_sim; default build/devel/lib/regolith_twin),
REPOSE_NICE (default 15).
"""
import json
import math
import os
import resource
import shlex
import subprocess
import sys
import time
import argparse
from argparse import Namespace

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(HERE, "lib"))
import repose_angle  # noqa: E402
from bed_file import read_snapshot  # noqa: E402
from plots import pyplot, save_figure  # noqa: E402

DOCS = os.path.join(ROOT, "results", "repose")
OUT = os.path.join(ROOT, "out", "repose")
BASE_TOP = 0.01  # top of the glued base grains (centres at z = 0, radius 0.01 m)
MEAN_DIAMETER = 0.02
PUBLISHED = {"gravel": 38.5, "moderate": 28.0}
# Per material: the scene, the base radius R (m) and the fill's z range in the file (outlet 0.45 m).
SCENES = {
    "moderate": ("config/validation/pour_tall_moderate.yaml", 0.65, (1.125, 1.795)),
    "gravel": ("config/validation/pour_tall_gravel.yaml", 0.45, (1.125, 1.475)),
}
OUTLET_IN_FILE = 0.45  # outlet above the base's top in the files (z = 0.46 m)
OUTLET = {"near": 0.45, "high": 0.85, "wide": 0.45}
# The "wide" pour: the near pour with the outlet's radius 0.18 m (18 mean diameters instead of 12; the
# plug 0.20 m), the hopper's cone keeping its length and top, for gravel, which arched over 0.12 m.
WIDE_OUTLET, WIDE_PLUG = 0.18, 0.20
# A run whose hopper still holds more than this share of the poured grains when the drain stage ends
# (the flow has stopped) arched over the outlet: it is kept as arched.json, not measured.
ARCHED_SHARE = 0.01
CONE_LENGTH = 0.6582  # the hopper cone, outlet radius 0.12 m to 0.5 m at 30 deg from the axis


def overrides(material, pour, seed):
    """--set overrides of one run: the seed, for a raised pour the hopper (walls 2 and 3), the plug
    (wall 4) and the hopper's grains (grains.1) moved up together, and for a wide pour the outlet's
    and the plug's radii."""
    out = ["seed=%d" % seed]
    if pour == "wide":
        out += ["walls.2.radius=%g" % WIDE_OUTLET, "walls.4.radius=%g" % WIDE_PLUG]
    shift = OUTLET[pour] - OUTLET_IN_FILE
    if abs(shift) > 1e-12:
        z_out = BASE_TOP + OUTLET[pour]
        lo, hi = SCENES[material][2]
        out += ["walls.2.base=[0, 0, %.4f]" % z_out,
                "walls.3.base=[0, 0, %.4f]" % (z_out + CONE_LENGTH),
                "walls.4.center=[0, 0, %.4f]" % z_out,
                "grains.1.fill.z=[%.4f, %.4f]" % (lo + shift, hi + shift)]
    return out


def run_name(material, pour, seed):
    return "tall_%s_%s_s%d" % (material, pour, seed)


# The study, in the order it runs: the main moderate configuration (outlet near the apex) on three
# seeds first, then gravel and the raised pour, then gravel's other seeds. The figures table reads the "near"
# pours (scripts/figures.py, repose.<material>: every kept tall_<material>_near_s<seed>).
PLAN = [("moderate", "near", 11), ("gravel", "near", 11), ("moderate", "high", 11), ("moderate", "near", 12),
        ("moderate", "near", 13), ("gravel", "high", 11), ("gravel", "near", 12), ("gravel", "near", 13),
        ("gravel", "wide", 11), ("gravel", "wide", 12), ("gravel", "wide", 13)]
RUNS = {run_name(*p): p for p in PLAN}


def measure(final, R):
    """The heap on the base (repose_angle.cone_profile) and the figures kept for a run."""
    a = Namespace(half_length=R, base_top=BASE_TOP, bin=0.02)
    p = repose_angle.cone_profile(final, a)
    d = np.loadtxt(final)
    z = d[:, 3]
    edges = np.arange(0, R + 1e-12, a.bin)
    rc = 0.5 * (edges[:-1] + edges[1:])
    height = p["apex"] - BASE_TOP
    # The heap covers the disk when the surface stands above the base in the outermost bin and grains
    # ran off the rim to the catch floor (0.5 m below).
    rim_h = p["h"][-1] - BASE_TOP if np.isfinite(p["h"][-1]) else 0.0
    return p, dict(
        angle_deg=float(np.mean(p["flanks"])),
        quadrants_deg=[float(v) for v in p["flanks"]],
        grains_on_base=p["n"],
        apex_m=p["apex"],
        heap_height_m=height,
        heap_height_diameters=height / MEAN_DIAMETER,
        ran_off=int(np.sum(z < -0.2)),
        rim_surface_height_m=float(rim_h),
        covers_disk=bool(rim_h > 0 and np.sum(z < -0.2) > 0),
        base_radius_m=R,
        mean_profile={"r_m": [round(float(v), 4) for v in rc],
                      "h_m": [None if not np.isfinite(v) else round(float(v), 5) for v in p["h"]]},
        mean_profile_fit_deg=math.degrees(math.atan(abs(p["fits"][0][0]))),
    )


def plot(path, res, p, title, published):
    plt = pyplot()
    R = res["base_radius_m"]
    fig, ax = plt.subplots(figsize=(7.5, 3.4))
    side = p["pile"] & (np.abs(p["y"]) < 0.02)
    ax.scatter(np.abs(p["x"][side]), p["z"][side], s=2, c="0.6", label="grains within 2 cm of the plane y = 0")
    ax.plot(p["xc"], p["h"], "-", color="tab:blue", lw=1.3, label="surface, mean of the four quadrants")
    slope, icpt = p["fits"][0]
    xx = np.array([0.15 * R, 0.85 * R])
    ax.plot(xx, slope * xx + icpt, "--", color="tab:red", lw=1.6,
            label="run: %.1f° (quadrants %s°)" % (res["angle_deg"], ", ".join("%.1f" % v for v in res["quadrants_deg"])))
    ok = np.isfinite(p["h"])
    z_mid = float(np.interp(0.5 * R, p["xc"][ok], p["h"][ok]))
    t = math.tan(math.radians(published))
    ax.plot([0, R], [z_mid + t * 0.5 * R, z_mid - t * 0.5 * R], "k:", lw=1.3,
            label="published %g° (through the surface at r = R/2)" % published)
    ax.axvspan(0.15 * R, 0.85 * R, color="0.93", zorder=0)
    ax.set_xlim(0, R * 1.03)
    ax.set_ylim(0, None)
    ax.set_aspect("equal")
    ax.set_xlabel("r (m)")
    ax.set_ylabel("z (m)")
    ax.set_title("%s: heap %.1f mean diameters tall, %d grains on the base" %
                 (title, res["heap_height_diameters"], res["grains_on_base"]), fontsize=9)
    ax.legend(fontsize=6.5, loc="upper right", framealpha=0.85)
    save_figure(fig, path)


def run_one(name, bin_dir):
    material, pour, seed = RUNS[name]
    keep = os.path.join(DOCS, name)
    for f in ("result.json", "arched.json"):
        if os.path.exists(os.path.join(keep, f)) and os.environ.get("REPOSE_RERUN") != "1":
            print("%s: kept (%s)" % (name, os.path.relpath(os.path.join(keep, f), ROOT)), flush=True)
            return
    config = SCENES[material][0]
    out = os.path.join(OUT, name)
    os.makedirs(out, exist_ok=True)
    sets = overrides(material, pour, seed)
    nice = os.environ.get("REPOSE_NICE", "15")
    cmd = ["nice", "-n", nice, os.path.join(bin_dir, "regolith_sim"), config, "--threads", "1", "--stage-snapshots",
           "--out", os.path.relpath(out, ROOT), "--quiet"]
    for s in sets:
        cmd += ["--set", s]
    shown = " ".join(shlex.quote(c) for c in ["regolith_sim"] + cmd[4:])
    print("%s: %s" % (name, shown), flush=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.time()
    r = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if r.returncode != 0:
        sys.stderr.write(r.stdout[-3000:])
        raise SystemExit("%s: regolith_sim exit %d after %.0f s (nothing kept)" % (name, r.returncode, wall))
    keep_run(name, wall, cpu, shown)


def keep_run(name, wall, cpu, shown):
    """Measures a finished run's output (out/repose/NAME) and keeps its figures: RUN/result.json and
    profile.png, or RUN/arched.json when the grains arched over the outlet and the hopper did not empty
    (no heap to measure: the settle stage would end at once with the hopper's grains hanging in the air)."""
    material, pour, seed = RUNS[name]
    R = SCENES[material][1]
    out, keep = os.path.join(OUT, name), os.path.join(DOCS, name)
    s = json.load(open(os.path.join(out, "summary.json")))
    # Grains above the outlet after the fill (all poured grains) and when the drain stage ended.
    outlet_z = BASE_TOP + OUTLET[pour]
    poured = int(np.sum(read_snapshot(os.path.join(out, "fill.bed"))[2] > outlet_z))
    left = int(np.sum(read_snapshot(os.path.join(out, "drain.bed"))[2] > outlet_z))
    stages = {k: dict(t_end=v["t_end"], ended_by=v["ended_by"]) for k, v in s["stages"].items()}
    os.makedirs(keep, exist_ok=True)
    for f in ("result.json", "arched.json", "profile.png"):
        if os.path.exists(os.path.join(keep, f)):
            os.remove(os.path.join(keep, f))
    if left > ARCHED_SHARE * poured:
        res = dict(run=name, material=material, pour=pour, seed=seed, outlet_above_base_m=OUTLET[pour],
                   status="arched", grains_poured=poured, grains_left_in_hopper_after_drain=left, stages=stages,
                   sim_time_s=s["sim_time"], steps=s["steps"], wall_seconds=round(wall, 1),
                   cpu_seconds=round(cpu, 1), threads=1, command=shown)
        with open(os.path.join(keep, "arched.json"), "w") as f:
            json.dump(res, f, indent=1)
        print("%s: the grains arched over the outlet: %d of %d still in the hopper when the flow stopped at "
              "%.2f s; no heap to measure (kept as %s)" % (name, left, poured, stages["drain"]["t_end"],
                                                          os.path.relpath(os.path.join(keep, "arched.json"), ROOT)),
              flush=True)
        return
    p, res = measure(os.path.join(out, "final_grains.txt"), R)
    res = dict(
        run=name, material=material, pour=pour, seed=seed,
        outlet_above_base_m=OUTLET[pour], published_deg=PUBLISHED[material],
        **res,
        grains_poured=poured,
        grains_left_in_hopper_after_drain=left,
        stages=stages,
        sim_time_s=s["sim_time"], steps=s["steps"], kn=s["kn"], dt=s["dt"], grains=s["grains"],
        max_overlap_ratio=s["max_overlap_ratio"],
        wall_seconds=round(wall, 1), cpu_seconds=round(cpu, 1), threads=1,
        command=shown, method="poured fixed-base cone, scripts/lib/repose_angle.py (cone: four quadrants, "
                              "flank fits over 0.15 R <= r <= 0.85 R)")
    plot(os.path.join(keep, "profile.png"), res, p, "%s, outlet %s (%.2f m), seed %d" %
         (material, pour, OUTLET[pour], seed), PUBLISHED[material])
    with open(os.path.join(keep, "result.json"), "w") as f:
        json.dump(res, f, indent=1)
    print("%s: %.2f deg (quadrants %s), %d grains on the base, heap %.1f d, %s; %.0f s wall, %.0f s CPU" %
          (name, res["angle_deg"], " ".join("%.2f" % v for v in res["quadrants_deg"]), res["grains_on_base"],
           res["heap_height_diameters"], "covers the disk" if res["covers_disk"] else "DOES NOT COVER THE DISK",
           wall, cpu), flush=True)


def remeasure(name):
    """keep_run again on a run's output, with the wall and CPU time and command kept before."""
    keep = os.path.join(DOCS, name)
    old = next((json.load(open(os.path.join(keep, f))) for f in ("result.json", "arched.json")
                if os.path.exists(os.path.join(keep, f))), None)
    if old is None or not os.path.exists(os.path.join(OUT, name, "summary.json")):
        raise SystemExit("%s: needs a kept run and its output in %s" % (name, os.path.relpath(OUT, ROOT)))
    keep_run(name, old["wall_seconds"], old["cpu_seconds"], old["command"])


def load_arched():
    return {n: json.load(open(os.path.join(DOCS, n, "arched.json"))) for n in RUNS
            if os.path.exists(os.path.join(DOCS, n, "arched.json"))}


def load_done():
    done = {}
    for n in RUNS:
        f = os.path.join(DOCS, n, "result.json")
        if os.path.exists(f):
            done[n] = json.load(open(f))
    return done


def report():
    plt = pyplot()
    done = load_done()
    lines = ["# Angle of repose on tall poured heaps", "",
             "Generated by `scripts/repose_tall.py report` from the runs kept under this folder "
             "(`RUN/result.json`, `RUN/profile.png`). A run's angle is the mean of its four quadrants' flank fits "
             "(scripts/lib/repose_angle.py, 0.15 R ≤ r ≤ 0.85 R); height is the apex of the mean surface above "
             "the base's top, in mean grain diameters (2 cm).", "",
             "| run | material | outlet above the base | R | angle | quadrants | heap height | grains on the base "
             "| ran off | hopper empty | simulated | wall / CPU time (1 thread) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for n, r in done.items():
        lines.append("| `%s` | %s | %.2f m | %.2f m | %.2f° | %s° | %.1f d | %d | %d | %s | %.1f s | %.0f / %.0f s |" % (
            n, r["material"], r["outlet_above_base_m"], r["base_radius_m"], r["angle_deg"],
            ", ".join("%.1f" % v for v in r["quadrants_deg"]), r["heap_height_diameters"], r["grains_on_base"],
            r["ran_off"], "yes" if r["grains_left_in_hopper_after_drain"] == 0 else
            "no (%d left)" % r["grains_left_in_hopper_after_drain"], r["sim_time_s"], r["wall_seconds"],
            r["cpu_seconds"]))
    arched = load_arched()
    if arched:
        lines += ["", "Runs in which the grains arched over the outlet (kept as `RUN/arched.json`, no heap to measure):",
                  "", "| run | grains poured | still in the hopper when the flow stopped | drain ended at | wall time |",
                  "|---|---|---|---|---|"]
        for n, r in arched.items():
            lines.append("| `%s` | %d | %d | %.2f s | %.0f s |" % (
                n, r["grains_poured"], r["grains_left_in_hopper_after_drain"], r["stages"]["drain"]["t_end"],
                r["wall_seconds"]))
    lines += ["", "Per material and pour (mean ± sample standard deviation over the seeds; single quadrants' range):", "",
              "| material | pour | seeds | heap height | angle | single quadrants | published |", "|---|---|---|---|---|---|---|"]
    groups = {}
    for r in done.values():
        groups.setdefault((r["material"], r["pour"]), []).append(r)
    for (m, pour), rs in sorted(groups.items()):
        ang = np.array([r["angle_deg"] for r in rs])
        q = [v for r in rs for v in r["quadrants_deg"]]
        sd = " ± %.2f°" % np.std(ang, ddof=1) if len(rs) > 1 else ""
        lines.append("| %s | %s (%.2f m) | %s | %.1f–%.1f d | %.2f°%s | %.1f–%.1f° | %g° |" % (
            m, pour, rs[0]["outlet_above_base_m"], " ".join(str(r["seed"]) for r in rs),
            min(r["heap_height_diameters"] for r in rs), max(r["heap_height_diameters"] for r in rs),
            ang.mean(), sd, min(q), max(q), PUBLISHED[m]))
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    for ax, m in zip(axes, ("moderate", "gravel")):
        for n, r in done.items():
            if r["material"] != m:
                continue
            rc = np.array(r["mean_profile"]["r_m"])
            h = np.array([np.nan if v is None else v for v in r["mean_profile"]["h_m"]])
            ax.plot(rc, h, "-" if r["pour"] == "near" else "--",
                    label="%s s%d: %.1f°" % (r["pour"], r["seed"], r["angle_deg"]))
        ax.set_title("%s (published %g°)" % (m, PUBLISHED[m]), fontsize=9)
        ax.set_xlabel("r (m)")
        ax.set_ylabel("mean surface height (m)")
        ax.set_aspect("equal")
        ax.set_ylim(0, None)
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    save_figure(fig, os.path.join(DOCS, "heaps.png"))
    lines += ["", "![mean surfaces of the tall heaps](heaps.png)"]
    with open(os.path.join(DOCS, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("cmd", choices=("run", "measure", "report", "list"))
    p.add_argument("names", metavar="RUN", nargs="*", help="run: the runs (default: all)")
    a = p.parse_args()
    bin_dir = os.environ.get("REGOLITH_BIN", os.path.join(ROOT, "build", "devel", "lib", "regolith_twin"))
    os.makedirs(DOCS, exist_ok=True)
    if a.cmd == "list":
        done, arched = load_done(), load_arched()
        for n in RUNS:
            print("%-28s %s" % (n, "done" if n in done else "arched" if n in arched else "-"))
        return
    if a.cmd == "measure":
        for n in a.names:
            if n not in RUNS:
                raise SystemExit("unknown run '%s' (%s)" % (n, " ".join(RUNS)))
            remeasure(n)
    if a.cmd == "run":
        names = a.names or list(RUNS)
        for n in names:
            if n not in RUNS:
                raise SystemExit("unknown run '%s' (%s)" % (n, " ".join(RUNS)))
        for n in names:
            run_one(n, bin_dir)
    report()


if __name__ == "__main__":
    main()
