#!/usr/bin/env python3
"""Stability sweep (docs/bench/stability.md): for each scene, raise
the time step and move k_n away from the scene's values until the run fails,
and record where it failed, which guard stopped it and with what message; for
the elastic, frictionless closed box also the energy drift per 10^6 steps.

  bench/stability.py OUT_DIR [SCENE...]     scenes: box, mascot, sampler (default: all)

One JSON per run under OUT_DIR/<scene>/ (a run already recorded is not run
again); then OUT_DIR/stability.md and OUT_DIR/stability.png. The runs' own
outputs go to $STABILITY_WORK (default out/stability). BIN is the folder of
the tools (default build/devel/lib/regolith_twin); STABILITY_THREADS (1).
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
from plots import pyplot  # noqa: E402
BIN = os.environ.get("BIN", os.path.join(ROOT, "build/devel/lib/regolith_twin"))
THREADS = os.environ.get("STABILITY_THREADS", "1")
WORK = os.environ.get("STABILITY_WORK", os.path.join(ROOT, "out/stability"))  # the runs' own outputs

# Steps per contact of the scene's smallest grains when its summary does not give them.
N_RULE = {"mascot": 30}  # sweep_mascot sets steps_per_contact 30

# How a run ended, from the tool's exit code and the blow-up message (docs/model.md §13).
GUARDS = [
    ("NaN or infinite", "non-finite"),
    ("' moved", "body step"),
    ("moved", "grain step"),
    ("bodies '", "body-body overlap"),
    ("touches", "contacts per grain"),
    ("total energy", "energy growth"),
    ("overlap of grain", "overlap"),
]


def label(outcome, msg):
    """The guard of a recorded blow-up message (records keep the tool's own words)."""
    if outcome in ("ok", "refused") or not msg:
        return outcome
    for key, name in GUARDS:
        if key in msg:
            return name
    return outcome


def classify(rc, text):
    if rc == 0:
        return "ok", ""
    msg = ""
    for line in text.splitlines():
        if "blow-up" in line or "error" in line.lower() or "refused" in line.lower():
            msg = line.strip()
    if rc == 2:
        return "refused", msg
    if rc == 3:
        for key, name in GUARDS:
            if key in msg:
                return name, msg
        return "blow-up (other)", msg
    return f"crash (exit {rc})", msg or text.strip().splitlines()[-1:] and text.strip().splitlines()[-1]


def get(d, path, default=None):
    for k in path.split("."):
        if not isinstance(d, dict) or k not in d:
            return default
        d = d[k]
    return d


def run_case(scene, name, args, out_dir, extra):
    rec_path = os.path.join(out_dir, scene, name + ".json")
    if os.path.exists(rec_path):
        return json.load(open(rec_path))
    run_dir = os.path.join(WORK, scene, name)
    os.makedirs(run_dir, exist_ok=True)
    summary = os.path.join(run_dir, "summary.json")
    if os.path.exists(summary):
        os.remove(summary)
    cmd = args + ["--out", run_dir, "--threads", THREADS, "--quiet"]
    t0 = time.time()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - t0
    outcome, msg = classify(p.returncode, p.stdout)
    s = json.load(open(summary)) if os.path.exists(summary) else {}
    rec = {"scene": scene, "case": name, "command": " ".join(os.path.relpath(a, ROOT) if a.startswith(ROOT) else a
                                                            for a in cmd[:-5]),
           "exit": p.returncode, "outcome": outcome, "message": msg, "wall_seconds": round(wall, 1)}
    rec.update(extra)
    rec["kn"] = get(s, "run.kn", get(s, "kn"))
    rec["dt"] = get(s, "run.dt", get(s, "dt"))
    spc = get(s, "steps_per_contact")
    if isinstance(spc, dict) and spc:
        rec["steps_per_contact_min"] = min(v for v in spc.values() if isinstance(v, (int, float)))
    rec["steps"] = get(s, "run.steps", get(s, "steps"))
    rec["max_overlap_ratio"] = get(s, "max_overlap_ratio", get(s, "outcome.max_overlap_ratio"))
    e0, e1 = get(s, "energy_initial.total"), get(s, "energy_final.total")
    if e0 is not None and e1 is not None and rec["steps"]:
        rec["energy_drift"] = (e1 - e0) / abs(e0)
        rec["energy_drift_per_1e6_steps"] = rec["energy_drift"] * 1e6 / rec["steps"]
    for key in ["outcome.max_penetration", "outcome.t_contact", "bed.cache", "observers.impact_speed",
                "observers.ejection.count", "collection.collected_mass"]:
        v = get(s, key)
        if v is not None:
            rec[key.split(".")[-1]] = v
    os.makedirs(os.path.dirname(rec_path), exist_ok=True)
    with open(rec_path, "w") as f:
        json.dump(rec, f, indent=1)
    print(f"[stability] {scene} {name}: {outcome} ({wall:.0f} s) {msg[:160]}", flush=True)
    return rec


def sweep_box(out):
    cfg = os.path.join(ROOT, "config/stability/elastic_box.yaml")
    base = [os.path.join(BIN, "regolith_sim"), cfg, "--set", "stages.0.duration=0.3"]
    ref = run_case("box", "ref", base, out, {"dt_factor": 1, "kn_factor": 1})
    kn0, dt0 = ref["kn"], ref["dt"]
    # The input check first: 3 steps per contact without allow_under_resolved.
    run_case("box", "N3_refused", base + ["--set", "contact.steps_per_contact=3"], out,
             {"dt_factor": 10, "kn_factor": 1, "note": "input check"})
    allow = ["--set", "guards.allow_under_resolved=true"]
    for f in [2, 4, 8, 12, 16, 20, 25, 30, 40]:
        r = run_case("box", f"dt_x{f}", base + allow + ["--set", f"contact.kn={kn0}", "--set", f"contact.dt={dt0 * f}"],
                     out, {"dt_factor": f, "kn_factor": 1})
        if r["outcome"] != "ok":
            break
    # Beyond the energy guard: what stops the run when it is off.
    for f in [12, 16, 25, 40]:
        r = run_case("box", f"dt_x{f}_energy_off",
                     base + allow + ["--set", "guards.max_energy_growth=0", "--set", f"contact.kn={kn0}", "--set",
                                     f"contact.dt={dt0 * f}"], out, {"dt_factor": f, "kn_factor": 1, "energy_off": True})
        if r["outcome"] != "ok":
            break
    for f in [4, 16, 64, 256, 1024]:
        r = run_case("box", f"kn_x{f}", base + allow + ["--set", f"contact.kn={kn0 * f}", "--set", f"contact.dt={dt0}"],
                     out, {"dt_factor": 1, "kn_factor": f})
        if r["outcome"] != "ok":
            break
    for f in [4, 16, 64, 256]:
        r = run_case("box", f"kn_div{f}", base + allow + ["--set", f"contact.kn={kn0 / f}", "--set", f"contact.dt={dt0}"],
                     out, {"dt_factor": 1, "kn_factor": 1 / f})
        if r["outcome"] != "ok":
            break
    # Energy drift per 10^6 steps at the scene's Δt and at twice it.
    for f in [1, 2]:
        steps = 1e6
        run_case("box", f"drift_x{f}", [os.path.join(BIN, "regolith_sim"), cfg, "--set",
                                        f"stages.0.duration={steps * dt0 * f}", "--set", f"contact.kn={kn0}", "--set",
                                        f"contact.dt={dt0 * f}"], out, {"dt_factor": f, "kn_factor": 1, "drift": True})


def sweep_mascot(out):
    cfg = os.path.join(ROOT, "config/mascot_landing.yaml")
    base = [os.path.join(BIN, "regolith_sim"), cfg, "--set", "landing.max_after_contact=0.1",
            "--set", "landing.active_radius=0.45",  # the active zone and the steps per contact, as when
            "--set", "contact.steps_per_contact=30"]  # the sweep's results were kept
    ref = run_case("mascot", "ref", base, out, {"dt_factor": 1, "kn_factor": 1})
    kn0, dt0, bed = ref["kn"], ref["dt"], ref.get("cache")
    fixed = ["--set", "guards.allow_under_resolved=true"] + (["--relaxed-bed", bed] if bed else [])
    for f in [2, 4, 8, 16]:
        r = run_case("mascot", f"dt_x{f}", base + fixed + ["--set", f"contact.kn={kn0}", "--set", f"contact.dt={dt0 * f}"],
                     out, {"dt_factor": f, "kn_factor": 1})
        if r["outcome"] != "ok":
            break
    for f in [16, 64, 256]:
        r = run_case("mascot", f"kn_x{f}", base + fixed + ["--set", f"contact.kn={kn0 * f}", "--set", f"contact.dt={dt0}"],
                     out, {"dt_factor": 1, "kn_factor": f})
        if r["outcome"] != "ok":
            break
    for f in [16, 64]:
        r = run_case("mascot", f"kn_div{f}", base + fixed + ["--set", f"contact.kn={kn0 / f}", "--set", f"contact.dt={dt0}"],
                     out, {"dt_factor": 1, "kn_factor": 1 / f})
        if r["outcome"] != "ok":
            break


def sweep_sampler(out):
    cfg = os.path.join(ROOT, "config/sampler_shot.yaml")
    base = [os.path.join(BIN, "regolith_sim"), cfg, "--set", "sampler.duration=0.002"]
    ref = run_case("sampler", "ref", base, out, {"dt_factor": 1, "kn_factor": 1})
    bed = ref.get("cache")
    fixed = ["--set", "guards.allow_under_resolved=true"] + (["--relaxed-bed", bed] if bed else [])
    kn_ref, dt_ref = 5.47e6, 1.5e-6  # config/sampler_shot.yaml: k_n and Δt at 50 m/s
    for f in [1.25, 1.5, 2, 3, 4, 6]:
        r = run_case("sampler", f"dt_x{f}", base + fixed + ["--set", f"sampler.dt_ref={dt_ref * f}"], out,
                     {"dt_factor": f, "kn_factor": 1})
        if r["outcome"] != "ok":
            break
    for f in [2, 4, 16]:
        r = run_case("sampler", f"kn_x{f}", base + fixed + ["--set", f"sampler.kn_ref={kn_ref * f}"], out,
                     {"dt_factor": 1, "kn_factor": f})
        if r["outcome"] != "ok":
            break
    for f in [2, 4, 16, 64]:
        r = run_case("sampler", f"kn_div{f}", base + fixed + ["--set", f"sampler.kn_ref={kn_ref / f}"], out,
                     {"dt_factor": 1, "kn_factor": 1 / f})
        if r["outcome"] != "ok":
            break


def report(out):
    recs = {}
    for scene in ["box", "mascot", "sampler"]:
        d = os.path.join(out, scene)
        if os.path.isdir(d):
            recs[scene] = [json.load(open(os.path.join(d, f))) for f in sorted(os.listdir(d)) if f.endswith(".json")]
    lines = ["| scene | run | Δt / Δt₀ | k_n / k_n₀ | steps per contact (smallest) | outcome | message | max overlap / r | "
             "figure | wall s |", "|---|---|---|---|---|---|---|---|---|---|"]
    for scene, rs in recs.items():
        rs.sort(key=lambda r: (r["kn_factor"], r["dt_factor"], r["case"]))
        # Steps per contact of the smallest grains: from the run's summary, else
        # from the reference (the landing's rule gives 30) as N ∝ 1 / (Δt sqrt(k_n)).
        ref = next((r for r in rs if r["case"] == "ref"), {})
        n_ref = ref.get("steps_per_contact_min") or N_RULE.get(scene)
        for r in rs:
            if r.get("steps_per_contact_min") is None and n_ref and r["outcome"] != "refused":
                r["steps_per_contact_min"] = n_ref / (r["dt_factor"] * r["kn_factor"] ** 0.5)
        for r in rs:
            r["outcome"] = label(r["outcome"], r["message"])
            fig = ""
            if "energy_drift_per_1e6_steps" in r and r["outcome"] == "ok":
                fig = f"energy drift {r['energy_drift']:+.2e} ({r['energy_drift_per_1e6_steps']:+.2e} per 10⁶ steps)"
            elif "max_penetration" in r and r["outcome"] == "ok":
                fig = f"penetration {100 * r['max_penetration']:.2f} cm"
            elif "count" in r and r["outcome"] == "ok":
                fig = f"ejecta {r['count']}"
            spc = r.get("steps_per_contact_min")
            mo = r.get("max_overlap_ratio")
            msg = r["message"].replace("|", "/")
            msg = msg[:220] + ("…" if len(msg) > 220 else "")
            lines.append(f"| {scene} | {r['case']} | {r['dt_factor']:g} | {r['kn_factor']:g} | "
                         f"{'' if spc is None else f'{spc:.2f}'} | {r['outcome']} | {msg} | "
                         f"{'' if mo is None else f'{mo:.3f}'} | {fig} | {r['wall_seconds']:.0f} |")
    with open(os.path.join(out, "stability.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    try:
        plt = pyplot()
    except ImportError:
        return
    fig, axes = plt.subplots(1, len(recs), figsize=(4.2 * len(recs), 4), squeeze=False)
    style = {"ok": ("o", "tab:green"), "refused": ("s", "tab:gray")}
    for ax, (scene, rs) in zip(axes[0], recs.items()):
        k = 0
        for r in sorted(rs, key=lambda r: (r["dt_factor"], r["kn_factor"])):
            r["outcome"] = label(r["outcome"], r["message"])
            if r.get("drift"):
                continue
            m, c = style.get(r["outcome"], ("x", "tab:red"))
            face = "none" if r.get("energy_off") else c
            if m == "x":
                ax.scatter(r["dt_factor"], r["kn_factor"], marker=m, color=c, s=60)
            else:
                ax.scatter(r["dt_factor"], r["kn_factor"], marker=m, edgecolors=c, facecolors=face, s=60)
            if r["outcome"] != "ok":
                text = r["outcome"] + (" (energy guard off)" if r.get("energy_off") else "")
                ax.annotate(text, (r["dt_factor"], r["kn_factor"]), fontsize=7, xytext=(5, 8 if k % 2 == 0 else -12),
                            textcoords="offset points")
                k += 1
        # Lines of constant steps per contact: N ∝ 1 / (Δt sqrt(k_n)).
        n0 = next((r for r in rs if r["case"] == "ref"), {}).get("steps_per_contact_min") or N_RULE.get(scene)
        if n0:
            import numpy as np
            xs = np.logspace(-0.3, 2, 50)
            for n in [30, 10, 4, 2, 1]:
                ks = (n0 / (n * xs)) ** 2
                ax.plot(xs, ks, lw=0.6, color="0.75", zorder=0)
                x_top = n0 / (n * np.sqrt(2000))
                if 0.5 < x_top < 100:
                    ax.text(x_top, 2000, f"N={n}", fontsize=6, color="0.45", ha="left", va="top")
                else:
                    ax.text(0.52, (n0 / (n * 0.52)) ** 2, f"N={n}", fontsize=6, color="0.45", va="bottom")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(0.5, 100)
        ax.set_ylim(1 / 1000, 3000)
        ax.set_xlabel("Δt / scene Δt")
        ax.set_ylabel("k_n / scene k_n")
        ax.set_title(scene)
    fig.suptitle("Stability edge (N: steps per contact of the smallest grains): green ok, red x stopped by a guard "
                 "(hollow: energy guard off), grey refused at input", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "stability.png"), dpi=110)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", metavar="OUT", nargs="?", default=os.path.join(ROOT, "results/bench/stability"))
    p.add_argument("scenes", metavar="SCENE", nargs="*", help="box, mascot or sampler (default: all three)")
    a = p.parse_args()
    out, scenes = a.out, a.scenes or ["box", "mascot", "sampler"]
    for sc in scenes:
        if sc not in ("box", "mascot", "sampler"):
            p.error("unknown scene '%s' (box, mascot, sampler)" % sc)
    os.makedirs(out, exist_ok=True)
    for sc in scenes:
        {"box": sweep_box, "mascot": sweep_mascot, "sampler": sweep_sampler}[sc](out)
        report(out)
    report(out)


if __name__ == "__main__":
    main()
