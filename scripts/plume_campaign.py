#!/usr/bin/python3
"""Plume-erosion campaign (docs/scenes.md D, docs/validation/plume.md).

  plume_campaign.py BIN OUT DOCS calibrate        bisection on the gas profile's scale (seed 1)
  plume_campaign.py BIN OUT DOCS run [RUN...]     runs (default: all), each seed in turn
  plume_campaign.py BIN OUT DOCS report           results/plume/report.md + plots
  plume_campaign.py BIN OUT DOCS mechanism DIR... the mechanism figures of run folders (crossings.csv, ...)

A finished run's summary.json, its N(t) every millisecond, and its
crossings.csv, below_end.csv, gas_forces.csv and series.csv (docs/scenes.md
D, "Measurements of the mechanism") are copied to DOCS/RUN/ (committed: a
campaign resumes on any machine; a run whose copy exists is not run again
unless PLUME_RERUN=1); a run that stopped leaves DOCS/RUN/failed.txt (its
exit and last lines), reported and not retried.
"""
import csv
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import campaign_cli  # noqa: E402

CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config", "plume_erosion.yaml")
SEEDS = [1, 2, 3]
MAT = ["materials.regolith", "materials.floor"]
# The gas profile's one calibrated scale (docs/scenes.md D): U(h) = u_log ln(1 + h / d) above the
# anchoring plane, zero at the plane. `calibrate` bisects `steps` times on `key` between `bounds`
# with `fixed` set. PLUME_PROFILE=linear selects the linear profile of the sensitivity check
# (docs/validation/plume.md); PLUME_SET="key=value ..." adds overrides to every run (its
# calibrated scale, with DOCS a folder of its own).
PROFILES = {
    "log": {"what": "U(h) = u_log ln(1 + h/d), U(0) = 0", "key": "gas.u_log", "symbol": "u_log", "unit": "m/s",
            "fixed": ["gas.u0=0", "gas.h_log=0.001", "gas.shear=0"], "bounds": (4.0, 40.0), "steps": 7},
    "linear": {"what": "U(h) = G h, U(0) = 0", "key": "gas.shear", "symbol": "G", "unit": "1/s",
               "fixed": ["gas.u0=0", "gas.u_log=0"], "bounds": (2000.0, 6000.0), "steps": 5},
}
PROFILE = PROFILES[os.environ.get("PLUME_PROFILE", "log")]
EXTRA = os.environ.get("PLUME_SET", "").split()
KEEP = ("crossings.csv", "below_end.csv", "gas_forces.csv", "series.csv")


def both(key, value):
    return ["%s.%s=%s" % (m, key, value) for m in MAT]


# name: (overrides, seeds, what it compares with)
RUNS = {
    "base": ([], SEEDS, "calibrated case: depletion at about 0.15 s"),
    "upward": (["plume.plane_motion=upward"], SEEDS, "planes moved by upward crossings only (decision check)"),
    # Free grains strike the held (rigid) bed at up to the gas speed: overlaps reach 0.26 of a radius at
    # k_n = 8000 N/m, beyond the default guard of 0.25 (docs/model.md §13).
    "collisionless": (["plume.collisionless=true", "guards.max_overlap_ratio=0.5"], SEEDS,
                      "no contacts among the free grains (the held bed still supports them)"),
    "nondissipative": (both("eps_n", 1) + both("mu_s", 0), SEEDS, "eps = 1, mu = 0"),
    "pen2": (["plume.penetration_depth=2"], SEEDS, "penetration depth 2 d"),
    "pen6": (["plume.penetration_depth=6"], SEEDS, "penetration depth 6 d"),
    "ero16": (["plume.erosion_height=16"], SEEDS, "erosion plane 16 d above the bed"),
    "box2": (["periodic.x=[0,0.020]", "periodic.y=[0,0.010]", "grains.0.fill.hi=[0.020,0.010,0.030]",
              "grains.0.fill.count=3200"], SEEDS, "box twice as long and wide (3200 grains)"),
    "deep": (["grains.0.fill.hi=[0.010,0.005,0.060]", "grains.0.fill.count=1600"], SEEDS, "bed twice as deep"),
    "k8e4": (["contact.kn=8e4"], SEEDS, "k_n = 8e4 N/m"),
    "k8e5": (["contact.kn=8e5"], SEEDS, "k_n = 8e5 N/m"),
    "k8e6": (["contact.kn=8e6"], [1], "k_n = 8e6 N/m (one seed)"),
    "splash": (["plume.splash.speed=1.0", "plume.splash.angle_deg=15", "plume.duration=0.05"], SEEDS,
               "one grain at 1 m/s, 15 degrees, into the bed; no gas"),
}
for e in (0.6, 0.8):
    for mu in (0.2, 0.5, 0.8, 1.4):
        if (e, mu) != (0.8, 0.2):
            RUNS["e%g_mu%g" % (e, mu)] = (both("eps_n", e) + both("mu_s", mu), SEEDS, "eps = %g, mu = %g" % (e, mu))


def run_one(bin_dir, out, docs, name, seed, extra=(), tag=None):
    tag = tag or "%s_s%d" % (name, seed)
    keep = os.path.join(docs, tag)
    s = campaign_cli.kept(keep, "PLUME_RERUN")
    if s is not None:
        return None if s == "failed" else s
    overrides = EXTRA + (list(RUNS[name][0]) if name in RUNS else []) + list(extra) + ["seed=%d" % seed]
    d = os.path.join(out, tag)
    s = campaign_cli.run_and_keep(bin_dir, CONFIG, d, keep, overrides, {"run": name, "seed": seed}, copies=KEEP)
    if s is None:
        return None
    with open(os.path.join(d, "erosion.csv")) as f, open(os.path.join(keep, "n_of_t.csv"), "w") as g:
        rows = [r for r in csv.reader(x for x in f if not x.startswith("#"))]
        g.write("t,above,erosion_plane,up_per_step,down_per_step,pairs_per_grain,touching_fraction\n")
        last = -1.0
        for r in rows[1:]:
            t = float(r[0])
            if t - last >= 1e-3 - 1e-9 or r is rows[-1]:
                g.write(",".join([r[0], r[2], r[4], r[5], r[6], r[7], r[8]]) + "\n")
                last = t
    print("%s: %s (%.0f s)" % (tag, line(s), s["campaign"]["wall_seconds"]), flush=True)
    return s


def line(s):
    e = s["observers"]["erosion"]
    return "N %d/%d, depleted at %.4g s, rate %.4g grains/s, up %d down %d" % (
        e["grains_above"], e["grains"], e["depleted_at"], e["erosion_rate"], e["upward_crossings"],
        e["downward_crossings"])


def calibrate(bin_dir, out, docs):
    """Bisection on the profile's scale (PROFILE) for depletion at 0.15 s on seed 1."""
    target, (lo, hi) = 0.15, PROFILE["bounds"]
    steps = []

    def t_dep(u):
        tag = "cal_%s%.4g" % (PROFILE["symbol"], u)
        s = run_one(bin_dir, out, os.path.join(docs, "calibration"), "base", 1,
                    PROFILE["fixed"] + ["%s=%.6g" % (PROFILE["key"], u), "plume.duration=0.25"], tag)
        if s is None:
            raise SystemExit("calibration run %s failed" % tag)
        t = s["observers"]["erosion"]["depleted_at"]
        steps.append({"scale": u, "depleted_at": t})
        return t if t >= 0 else 1e9

    for _ in range(PROFILE["steps"]):
        mid = 0.5 * (lo + hi)
        if t_dep(mid) > target:
            lo = mid
        else:
            hi = mid
    best = min(steps, key=lambda x: abs(x["depleted_at"] - target))
    res = {"target_depleted_at": target, "profile": PROFILE["what"], "key": PROFILE["key"],
           "symbol": PROFILE["symbol"], "unit": PROFILE["unit"], "fixed": PROFILE["fixed"], "steps": steps,
           "scale": best["scale"]}
    with open(os.path.join(docs, "calibration.json"), "w") as f:
        json.dump(res, f, indent=1)
    print("calibrated: %s = %.4g (depleted at %.4g s); set it in %s" %
          (PROFILE["key"], best["scale"], best["depleted_at"], CONFIG))


def main():
    bin_dir, out, docs, cmd, names = campaign_cli.command_line(__doc__)
    if cmd == "calibrate":
        calibrate(bin_dir, out, docs)
    elif cmd == "run":
        names = names or list(RUNS)
        campaign_cli.check_names(names, RUNS)
        for n in names:
            for seed in RUNS[n][1]:
                run_one(bin_dir, out, docs, n, seed)
    elif cmd == "report":
        import plume_report
        plume_report.report(docs, RUNS)
    elif cmd == "mechanism":
        import plume_report
        for d in names:
            m = plume_report.mechanism(d) or {}
            m.pop("series", None)
            print(d, json.dumps(m, indent=1))
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main()
