#!/usr/bin/python3
"""The figures table (docs/validation/figures.csv) and the reproduction page's table, from the
committed results (docs/reproduction.md).

  figures.py [--check]     write docs/validation/figures.csv, docs/reproduction.md and the campaign's
                           progress in docs/validation/mascot.md (--check: compare with the committed
                           files instead, exit 1 if they differ)

Columns: id,value,sd,n,unit,command. `value` is the mean over the n runs (repeats, beds, seeds,
aim points), `sd` their sample standard deviation (empty when n = 1), `NA` with n = 0 when not run
yet; `command` the command that produces the runs. Units SI (m, s, kg/m^3), angles in degrees,
collected masses in mg. Every figure is computed here from the results under docs/validation/
(never typed in); the ids are those of ids() below.
"""
import argparse
import csv
import glob
import io
import json
import math
import os
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
DOCS = os.path.join(ROOT, "docs", "validation")
RESULTS = os.path.join(ROOT, "results")  # the campaigns' kept runs
OUT = os.path.join(DOCS, "figures.csv")
REPRO = os.path.join(ROOT, "docs", "reproduction.md")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
from stats import describe  # noqa: E402
from sweep import DEFAULT_SCENE, variant_overrides  # noqa: E402


def read_text(path):
    with open(path) as f:
        return f.read()


def dict_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))

MATERIALS = ("gravel", "moderate")
ATTITUDES = ("Flat", "BCF", "FCF")
ANGLES = (0, 15, 30, 45, 60)


def ids():
    """Every figure id, in the table's order, with its unit."""
    out = []
    for m in MATERIALS:
        for d in (15, 30, 40):
            out += [("bed.mascot.%s.d%d.grains" % (m, d), "1"), ("bed.mascot.%s.d%d.packing" % (m, d), "1")]
    out += [("bed.sampler.grains", "1"), ("bed.sampler.bulk_density", "kg/m3")]
    for t in ("gb", "gbb"):
        for h in (8, 10, 12):
            out.append(("bed.bucket.%s.h%d.grains" % (t, h), "1"))
    out.append(("bed.bucket.gb5mm.h10.grains", "1"))
    units = {"speed_ratio": "1", "travel": "m", "collision": "s", "penetration": "m"}
    for m in MATERIALS:
        for att in ATTITUDES:
            for a in ANGLES:
                for k in ("speed_ratio", "travel", "collision", "penetration"):
                    out.append(("mascot.d30.%s.%s.a%d.%s" % (m, att, a, k), units[k]))
                # beyond the published set: the clear lift-off's speed ratio and travel
                out += [("mascot.d30.%s.%s.a%d.speed_ratio_clear" % (m, att, a), "1"),
                        ("mascot.d30.%s.%s.a%d.travel_clear" % (m, att, a), "m")]
    for d in ("d15", "d40"):
        for m in MATERIALS:
            for k in ("speed_ratio", "travel", "penetration"):
                out.append(("mascot.%s.%s.BCF.a30.%s" % (d, m, k), units[k]))
    for m in MATERIALS:
        for k in ("speed_ratio", "travel"):
            out.append(("mascot.d30g12.%s.BCF.a30.%s" % (m, k), units[k]))
    for m in ("moderate", "gravel"):
        out.append(("mascot.d30.%s.BCF.a30.ejected_volume" % m, "m3"))
    out += [("sampler.v300.z.t45us", "1"), ("sampler.v300.z.t1250us", "1"), ("sampler.v300.z.t12500us", "1"),
            ("sampler.v300.z_misfit_deg.t1250us", "deg"),
            ("sampler.v300.wave_exponent.t12us", "1"), ("sampler.v300.wave_exponent.t62us", "1"),
            ("sampler.v300.depth_over_radius.t0.25s", "1"), ("sampler.v300.depth_over_radius.t1s", "1"),
            ("sampler.v300.ejection_angle_mode", "deg"), ("sampler.v50.ejection_angle_mode", "deg"),
            ("sampler.v300.bed_energy_fraction.t120us", "1"),
            ("sampler.v300.collected_mg.t1s", "mg"), ("sampler.v300.runs_ge_100mg_fraction", "1"),
            ("sampler.v50.horn_grains.cyl3.t1s", "1"), ("sampler.v50.horn_grains.cyl4.t1s", "1")]
    for t in ("gb", "gbb", "gb5mm"):
        for v in ("0.25", "0.5", "0.75", "1.0"):
            out.append(("bucket.%s.h10.v%s.zstop" % (t, v), "m"))
    for t in ("gb", "gbb", "gb5mm"):
        out += [("bucket.%s.h10.alpha" % t, "1"), ("bucket.%s.h10.bounced_fraction" % t, "1")]
    out += [("bucket.gb5mm.h10.f0", "N"), ("bucket.gb5mm.h10.inv_d1", "1/m"), ("bucket.gb.h10.f0", "N"),
            ("bucket.gb.h10.inv_d1", "1/m")]
    out += [("incline.onset.gravel", "deg"), ("incline.onset.moderate", "deg"),
            ("incline.onset_tilted.gravel", "deg"), ("incline.onset_tilted.moderate", "deg"),
            ("incline.moderate.mu_s", "1"), ("incline.moderate.mu_2", "1"), ("incline.moderate.I0", "1"),
            ("repose.gravel", "deg"), ("repose.moderate", "deg")]
    for r in ("base", "collisionless", "nondissipative", "pen2", "pen4", "pen6", "ero1", "ero16", "k8e3", "k8e4",
              "k8e5", "k8e6"):
        out.append(("plume.%s.rate" % r, "1/s"))
    for e in ("0.6", "0.8"):
        for mu in ("0.2", "0.5", "0.8", "1.4"):
            out.append(("plume.e%s_mu%s.rate" % (e, mu), "1/s"))
    out += [("plume.base.peak_collision_fraction", "1"), ("plume.base.peak_collision_time", "s")]
    return out


def stats(xs):
    """(mean, sd or None, n) of a list of numbers (None and NaN left out)."""
    d = describe(xs)
    return (None, None, 0) if d is None else (d["mean"], d["sd"], d["n"])


def load_json(path):
    with open(path) as f:
        return json.load(f)


# --- the sections: each returns {id: (list of values, command)} ---------------------------------

def beds():
    out = {}
    root = os.path.join(RESULTS, "beds", "prepared")

    def kept(name):
        f = os.path.join(root, name, "summary.json")
        return load_json(f)["bed"] if os.path.exists(f) else None

    for m in MATERIALS:
        for d in (15, 30, 40):
            names = ["mascot_%s_d%d" % (m, d)] + (["mascot_%s_d%d_s2" % (m, d), "mascot_%s_d%d_s3" % (m, d)]
                                                  if d == 30 else [])
            got = [b for b in (kept(n) for n in names) if b]
            cmd = "scripts/validate_beds prepare %s" % " ".join(names)
            out["bed.mascot.%s.d%d.grains" % (m, d)] = ([b["grains"] for b in got], cmd)
            out["bed.mascot.%s.d%d.packing" % (m, d)] = ([b["packing"] for b in got], cmd)
    names = ["sampler_gravel", "sampler_gravel_s2", "sampler_gravel_s3"]
    got = [b for b in (kept(n) for n in names) if b]
    cmd = "scripts/validate_beds prepare %s" % " ".join(names)
    out["bed.sampler.grains"] = ([b["grains"] for b in got], cmd)
    out["bed.sampler.bulk_density"] = ([b["bulk_density"] for b in got], cmd)
    return out


def bucket():
    import bucket_campaign as bc
    out = {}
    docs = os.path.join(RESULTS, "bucket")
    loaded = bc.load(docs)
    tags = {"gb": "gb", "gbb": "gbb", "gb5mm": "gb"}
    for t, h, bed in [(t, h, "%s_%d" % (t, h)) for t in ("gb", "gbb") for h in (8, 10, 12)] + [("gb5mm", 10,
                                                                                                 "gb_10_5mm")]:
        d = loaded.get(bed)
        cmd = "scripts/validate_bucket run %s" % bed
        runs = (d["sweep"] + [s for v in d["aims"] for s in d["aims"][v]]) if d else []
        out["bed.bucket.%s.h%d.grains" % (t, h)] = ([runs[0]["bed"]["grains"]] if runs else [], cmd)
        if h != 10:
            continue
        for v in bc.AIM_SPEEDS:
            out["bucket.%s.h10.v%s.zstop" % (t, "%g" % v if v != 1.0 else "1.0")] = (
                bc.at_speed(d, v) if d else [], cmd)
        f = bc.bed_figures(d) if d else None
        out["bucket.%s.h10.alpha" % t] = ([f["alpha"]] if f and f["alpha"] == f["alpha"] else [], cmd)
        out["bucket.%s.h10.bounced_fraction" % t] = ([f["bounced"] / f["runs"]] if f and f["runs"] else [], cmd)
        if t in ("gb", "gb5mm"):
            ok = f and f["f0"] == f["f0"]
            out["bucket.%s.h10.f0" % t] = ([f["f0"]] if ok else [], cmd)
            out["bucket.%s.h10.inv_d1" % t] = ([f["inv_d1"]] if ok else [], cmd)
    del tags
    return out


def incline_done():
    """name -> summary of every incline run kept under results/incline."""
    import incline_campaign as ic
    docs = os.path.join(RESULTS, "incline")
    return {n: load_json(os.path.join(docs, n, "summary.json")) for n in ic.RUNS
            if os.path.exists(os.path.join(docs, n, "summary.json"))}


def rain_runs(material):
    """[(angle, flowing, end v, trend)] of the material's rain runs (for the reproduction page)."""
    import incline_campaign as ic
    return ic.rain_onset(incline_done(), material)[1]


def incline():
    import incline_campaign as ic
    out = {}
    done = incline_done()
    for m in MATERIALS:
        onset, _ = ic.rain_onset(done, m)
        cmd = "scripts/validate_incline run %s" % " ".join(ic.rain_run(m, a) for a in ic.RAIN[m])
        out["incline.onset.%s" % m] = ([onset] if onset is not None else [], cmd)
        n = "onset_%s" % m
        o = done.get(n, {}).get("observers", {}).get("incline")
        out["incline.onset_tilted.%s" % m] = ([o["onset_deg"]] if o and o["onset_deg"] >= 0 else [],
                                              "scripts/validate_incline run %s" % n)
    fit = ic.steady_fit(done, "moderate") if hasattr(ic, "steady_fit") else None
    cmd = "scripts/validate_incline run %s" % " ".join(ic.rain_run("moderate", a) for a in ic.RAIN["moderate"])
    for k, i in (("mu_s", 0), ("mu_2", 1), ("I0", 2)):
        out["incline.moderate.%s" % k] = ([fit[i]] if fit else [], cmd)
    return out


def repose():
    """The angle of repose of the tall poured heaps (at least 15 mean grain diameters tall), the outlet near
    the final apex: one angle per kept run, results/repose/tall_<material>_near_s<seed>/result.json
    (scripts/repose_tall.py, whose plan names the runs; the short heaps of scripts/validate are about 6
    diameters tall)."""
    out = {}
    for m in MATERIALS:
        files = sorted(glob.glob(os.path.join(RESULTS, "repose", "tall_%s_near_s*" % m, "result.json")))
        names = [os.path.basename(os.path.dirname(f)) for f in files]
        out["repose.%s" % m] = ([load_json(f)["angle_deg"] for f in files],
                                " ".join(["scripts/repose_tall.py run"] + names))
    return out


PLUME_ALIASES = {"pen4": "base", "ero1": "base", "k8e3": "base", "e0.8_mu0.2": "base"}


def plume():
    out = {}
    docs = os.path.join(RESULTS, "plume")
    names = ["base", "collisionless", "nondissipative", "pen2", "pen4", "pen6", "ero1", "ero16", "k8e3", "k8e4",
             "k8e5", "k8e6"] + ["e%s_mu%s" % (e, mu) for e in ("0.6", "0.8") for mu in ("0.2", "0.5", "0.8", "1.4")]
    for n in names:
        run = PLUME_ALIASES.get(n, n)
        rates = []
        for f in sorted(glob.glob(os.path.join(docs, "%s_s*" % run, "summary.json"))):
            s = load_json(f)
            rates.append(s["observers"]["erosion"]["erosion_rate"])
        out["plume.%s.rate" % n] = (rates, "scripts/validate_plume run %s" % run)
    peaks, times = [], []
    for f in sorted(glob.glob(os.path.join(docs, "base_s*", "n_of_t.csv"))):
        rows = dict_rows(f)
        if rows and "touching_fraction" in rows[0]:
            best = max(rows, key=lambda r: float(r["touching_fraction"]))
            peaks.append(float(best["touching_fraction"]))
            times.append(float(best["t"]))
    out["plume.base.peak_collision_fraction"] = (peaks, "scripts/validate_plume run base")
    out["plume.base.peak_collision_time"] = (times, "scripts/validate_plume run base")
    return out


# MASCOT landings: the campaign records of runs on the shipped beds at the default settings (grids
# listed here; the grids of earlier beds are kept under results/campaign/lattice_beds/ and not read).
# A record made with any other setting (an override that is neither its grid point nor an impact
# condition: the first look's active zone, another steps per contact) is a variant and left out, so
# that no figure pools runs made with different settings.
MASCOT_GRIDS = {"d30": "scripts/campaign a b", "depths": "scripts/campaign c", "low_g": "scripts/campaign d"}
MASCOT_KEYS = {"speed_ratio": "speed_ratio", "travel": "travel_distance", "collision": "collision_duration",
               "penetration": "max_penetration", "ejected_volume": "ejected_volume"}
# The clear lift-off (the lander off the bed for good) beside the published first loss of contact:
# the two differ where the lander skips between two contacts (docs/validation/mascot.md).
MASCOT_CLEAR_KEYS = {"speed_ratio_clear": "speed_ratio", "travel_clear": "travel_distance"}


def mascot_point(record):
    """The figure id prefix (mascot.<depth>.<material>.<attitude>.a<angle>) of a campaign record, or
    None when it is not a finished run of the default landing at the published speed and gravity."""
    sw, s = record.get("sweep_run", {}), record.get("summary") or {}
    if sw.get("status") != "ok" or s.get("status") != "ok":
        return None
    if os.path.basename(str(sw.get("config") or DEFAULT_SCENE)) != DEFAULT_SCENE:
        return None
    if variant_overrides(sw.get("overrides", [])):
        return None
    inp = s["input"]
    depth = "d%d" % round(100 * sw["depth"])
    if abs(inp["gravity"] - 1.2e-4) < 1e-9:
        depth += "g12"
    elif abs(inp["gravity"] - 2.5e-4) > 1e-9 or inp.get("slope_deg", 0) != 0:
        return None
    if abs(inp["speed"] - 0.19) > 1e-9:
        return None
    return "mascot.%s.%s.%s.a%d" % (depth, sw["material"], sw["attitude"], round(sw["angle"]))


def mascot_records(grid):
    """(record, id prefix) of every default-landing run of a campaign grid, by file name."""
    out = []
    for f in sorted(glob.glob(os.path.join(RESULTS, "campaign", grid, "runs", "*.json"))):
        r = load_json(f)
        base = mascot_point(r)
        if base is not None:
            out.append((r, base))
    return out


def mascot():
    vals = {}
    for grid, cmd in MASCOT_GRIDS.items():
        for r, base in mascot_records(grid):
            oc = r["summary"]["outcome"]
            for k, key in MASCOT_KEYS.items():
                vals.setdefault("%s.%s" % (base, k), ([], cmd))[0].append(oc[key])
            clear = oc.get("clear_liftoff") or {}
            for k, key in MASCOT_CLEAR_KEYS.items():
                if key in clear:
                    vals.setdefault("%s.%s" % (base, k), ([], cmd))[0].append(clear[key])
    return vals


def sampler():
    """Runs on the shipped beds: results/sampler/shots/<run>/summary.json, <run> = v300_b<k>
    (to 0.25 s at the scene's stiffness), v300_1s_b<k> (1 s, stiffness schedule), v50_b<k>, v50_1s_b<k>."""
    out = {}
    root = os.path.join(RESULTS, "sampler", "shots")
    cmd = "scripts/validate_sampler shots"

    def runs(prefix):
        got = []
        for d in sorted(glob.glob(os.path.join(root, prefix + "_b*"))):
            f = os.path.join(d, "summary.json")
            if os.path.exists(f) and load_json(f).get("status") == "ok":
                got.append((d, load_json(f)))
        return got

    r300, r300_1s, r50, r50_1s = runs("v300"), runs("v300_1s"), runs("v50"), runs("v50_1s")
    # The first milliseconds, one shot per bed (a turned repeat is a bed of its own): the shot at the scene's
    # stiffness where the bed has one, else the 1 s shot (the same shot to the digit until its schedule
    # first lowers k_n, after 62 us on the shipped beds).
    def one_per_bed(preferred_last):
        per_bed = {}
        for d, s in preferred_last:
            per_bed[os.path.basename(d).rsplit("_b", 1)[1]] = (d, s)
        return [per_bed[b] for b in sorted(per_bed)]

    early = one_per_bed(r300_1s + r300)

    def zfit(s, k, key):
        z = s["observers"].get("zmodel", {}).get("t%d" % k, {}).get("fixed_h0")
        return z.get(key) if z and z.get("cells", 0) > 0 else None

    out["sampler.v300.z.t45us"] = ([zfit(s, 0, "z") for _, s in early], cmd)
    out["sampler.v300.z.t1250us"] = ([zfit(s, 1, "z") for _, s in early], cmd)
    out["sampler.v300.z.t12500us"] = ([zfit(s, 2, "z") for _, s in early], cmd)
    out["sampler.v300.z_misfit_deg.t1250us"] = ([zfit(s, 1, "misfit_sd_deg") for _, s in early], cmd)
    out["sampler.v300.wave_exponent.t12us"] = ([s["observers"]["wave"]["t0"]["slope"] for _, s in early], cmd)
    out["sampler.v300.wave_exponent.t62us"] = ([s["observers"]["wave"]["t1"]["slope"] for _, s in early], cmd)

    def dr(s):
        c = s["observers"]["crater"]
        return c["depth"] / c["radius"] if c.get("radius") else None

    out["sampler.v300.depth_over_radius.t0.25s"] = ([dr(s) for _, s in r300], cmd)
    out["sampler.v300.depth_over_radius.t1s"] = ([dr(s) for _, s in r300_1s], cmd)

    def mode(s):
        h = s["observers"]["ejection"]["angle_histogram"]
        b = s["observers"]["ejection"]["bin_deg"]
        return (max(range(len(h)), key=lambda k: h[k]) + 0.5) * b if sum(h) else None

    # Ejection angles over the whole shot: the longest shot on each bed.
    out["sampler.v300.ejection_angle_mode"] = ([mode(s) for _, s in one_per_bed(r300 + r300_1s)], cmd)
    out["sampler.v50.ejection_angle_mode"] = ([mode(s) for _, s in one_per_bed(r50 + r50_1s)], cmd)

    def energy(d):
        f = os.path.join(d, "energy_partition.csv")
        if not os.path.exists(f):
            return None
        rows = dict_rows(f)
        best = min(rows, key=lambda r: abs(float(r["t"]) - 1.2e-4))
        return float(best["ke_bed_trans"]) + float(best["ke_bed_rot"]) if abs(float(best["t"]) - 1.2e-4) < 1e-5 \
            else None

    out["sampler.v300.bed_energy_fraction.t120us"] = ([energy(d) for d, _ in early], cmd)
    mg = [1e6 * s["collection"]["collected_mass"] for _, s in r300_1s]
    out["sampler.v300.collected_mg.t1s"] = (mg, cmd)
    out["sampler.v300.runs_ge_100mg_fraction"] = ([sum(1 for x in mg if x >= 100) / len(mg)] if mg else [], cmd)
    out["sampler.v50.horn_grains.cyl3.t1s"] = ([s["observers"]["horn"]["segment_grains"][2] for _, s in r50_1s], cmd)
    out["sampler.v50.horn_grains.cyl4.t1s"] = ([s["observers"]["horn"]["segment_grains"][3] for _, s in r50_1s], cmd)
    return out


def table():
    """The rows (id, value, sd, n, unit, command) of every figure."""
    found = {}
    for section in (beds, mascot, sampler, bucket, incline, repose, plume):
        found.update(section())
    rows = []
    for fid, unit in ids():
        vals, cmd = found.get(fid, ([], ""))
        m, sd, n = stats(vals)
        fmt = lambda x: "%.6g" % x  # noqa: E731
        rows.append((fid, fmt(m) if n else "NA", fmt(sd) if sd is not None else "", str(n), unit, cmd))
    return rows


def render(rows):
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["id", "value", "sd", "n", "unit", "command"])
    w.writerows(rows)
    return buf.getvalue()


# --- the reproduction page ----------------------------------------------------------------------
# Each published statement: (section, what was published, the figure ids it is compared with, a test
# of the project's figures -> True / False / None (not run), how the project's side is shown, and the
# reason when it does not hold). The published numbers are those of the studies' set-ups as
# docs/scenes.md states them; the reasons are the findings of docs/validation.md.


def _v(f, fid):
    """The mean of a figure, or None."""
    m, sd, n = f.get(fid, (None, None, 0))
    return m if n else None


def _within(f, fid, target, rel):
    x = _v(f, fid)
    return None if x is None else abs(x / target - 1) <= rel


def _all(tests):
    tests = list(tests)
    if any(t is None for t in tests):
        return None if not any(t is False for t in tests) else False
    return all(tests)


def _num(x, digits):
    """x to `digits` significant digits, thousands separated, never in exponent form."""
    if x == 0:
        return "0"
    p = digits - 1 - int(math.floor(math.log10(abs(x))))
    x = round(x, p)
    if float(x).is_integer():
        p = 0  # a count (or a round figure) without a trailing ".0"
    return "{:,.{}f}".format(x, max(p, 0))


def _fmt(f, fid, scale=1.0, digits=3, unit=""):
    m, sd, n = f.get(fid, (None, None, 0))
    if not n:
        return "not run"
    s = _num(m * scale, digits)
    if sd is not None:
        s += " ± " + _num(sd * scale, 2)
    return s + unit + (" (n = %d)" % n if n > 1 else "")


def _order(f, ids_in_order):
    """The figures strictly increase along the list (None if one is missing)."""
    xs = [_v(f, i) for i in ids_in_order]
    if any(x is None for x in xs):
        return None
    return all(a < b for a, b in zip(xs, xs[1:]))


BED_COUNTS = [("gravel", 15, 28375), ("gravel", 30, 58454), ("gravel", 40, 78176), ("moderate", 15, 31082),
              ("moderate", 30, 62551), ("moderate", 40, 83097)]
BUCKET_COUNTS = [("gb", 8, 6274), ("gb", 10, 7987), ("gb", 12, 9682), ("gbb", 8, 6274), ("gbb", 10, 7987),
                 ("gbb", 12, 9682)]
BUCKET_ZSTOP = [("0.25", 0.0040), ("0.5", 0.0092), ("0.75", 0.0131), ("1.0", 0.0160)]


def statements(f):
    """The rows of the reproduction table: (section, published, project, verdict, command ids)."""
    rows = []
    for m, d, n in BED_COUNTS:
        fid = "bed.mascot.%s.d%d.grains" % (m, d)
        rows.append(("MASCOT bed", "%s, %d cm: %s grains (±2 %%)" % (m, d, format(n, ",")),
                     _fmt(f, fid, digits=5), _within(f, fid, n, 0.02), [fid]))
    rows.append(("Sampler bed", "101,657 grains (±2 %)", _fmt(f, "bed.sampler.grains", digits=6),
                 _within(f, "bed.sampler.grains", 101657, 0.02), ["bed.sampler.grains"]))
    rows.append(("Sampler bed", "bulk density 1,230 kg/m³ (±2 %)", _fmt(f, "bed.sampler.bulk_density", digits=4),
                 _within(f, "bed.sampler.bulk_density", 1230, 0.02), ["bed.sampler.bulk_density"]))
    for t, h, n in BUCKET_COUNTS:
        fid = "bed.bucket.%s.h%d.grains" % (t, h)
        rows.append(("Bucket bed", "%s, 10 mm beads, %d cm: %s beads (±2 %%)" % (t, h, format(n, ",")),
                     _fmt(f, fid, digits=5), _within(f, fid, n, 0.02), [fid]))
    rows.append(("Bucket bed", "5 mm beads, 10 cm: 67,420 beads (±2 %)", _fmt(f, "bed.bucket.gb5mm.h10.grains",
                                                                             digits=5),
                 _within(f, "bed.bucket.gb5mm.h10.grains", 67420, 0.02), ["bed.bucket.gb5mm.h10.grains"]))
    for v, z in BUCKET_ZSTOP:
        fid = "bucket.gb.h10.v%s.zstop" % v
        ok = _within(f, fid, z, 0.20) if v != "0.25" else None
        rows.append(("Bucket", "glass_beads 10 mm, %s m/s: z_stop %.2f cm%s" % (
            v, 100 * z, " (±20 %)" if v != "0.25" else " (not in the check)"), _fmt(f, fid, 100, unit=" cm"), ok, [fid]))
    b = _v(f, "bucket.gb.h10.bounced_fraction")
    rows.append(("Bucket", "glass_beads 10 mm: the sphere never bounces",
                 "fraction of runs that bounced: " + _fmt(f, "bucket.gb.h10.bounced_fraction", digits=2),
                 None if b is None else b == 0, ["bucket.gb.h10.bounced_fraction"]))
    a = [_v(f, "bucket.%s.h10.alpha" % t) for t in ("gb", "gbb")]
    rows.append(("Bucket", "α between 0.53 and 0.73 on 10 mm beads", "glass_beads %s, glass_beads_b %s" % (
        _fmt(f, "bucket.gb.h10.alpha"), _fmt(f, "bucket.gbb.h10.alpha")),
        _all(None if x is None else 0.53 <= x <= 0.73 for x in a), ["bucket.gb.h10.alpha", "bucket.gbb.h10.alpha"]))
    rows.append(("Bucket", "glass_beads 10 mm: f₀ = 15.10 N, 1/d₁ = 90.4 1/m (±20 %)", "%s, %s" % (
        _fmt(f, "bucket.gb.h10.f0", unit=" N"), _fmt(f, "bucket.gb.h10.inv_d1", unit=" 1/m")),
        _all([_within(f, "bucket.gb.h10.f0", 15.10, 0.2), _within(f, "bucket.gb.h10.inv_d1", 90.4, 0.2)]),
        ["bucket.gb.h10.f0", "bucket.gb.h10.inv_d1"]))
    for m, lo, hi in (("gravel", 39, 40), ("moderate", 30, 31)):
        fid = "incline.onset.%s" % m
        x = _v(f, fid)
        text, ok = _fmt(f, fid, unit="°"), None if x is None else lo - 1 <= x <= hi + 1
        runs = rain_runs(m)
        if x is None and runs:
            # No onset among the angles run: the deposit flows at none of them (or not at every steeper one).
            rest = [a for a, fl, _, _ in runs if not fl]
            flows = [a for a, fl, _, _ in runs if fl]
            text = "at rest at %s" % ", ".join("%g°" % a for a in rest) + (
                "; flowing at %s" % ", ".join("%g°" % a for a in flows) if flows else "")
            if not flows:
                text = "no flow up to %g° (%s)" % (max(rest), text)
                ok = False if max(rest) >= hi + 1 else None  # the onset lies above max(rest)
        rows.append(("Inclined plane", "onset, %s: %d–%d° (grains rained onto the tilted plane; ±1°)" % (m, lo, hi),
                     text, ok, [fid]))
    for m, p in (("gravel", 38.5), ("moderate", 28.0)):
        fid = "repose.%s" % m
        x = _v(f, fid)
        rows.append(("Angle of repose", "%s: %.1f° (±2°)" % (m, p), _fmt(f, fid, unit="°"),
                     None if x is None else abs(x - p) <= 2, [fid]))
    rows.append(("Plume", "the nondissipative bed (ε = 1, μ = 0) erodes faster than the base case",
                 "%s against %s grains/s" % (_fmt(f, "plume.nondissipative.rate"), _fmt(f, "plume.base.rate")),
                 _order(f, ["plume.base.rate", "plume.nondissipative.rate"]),
                 ["plume.nondissipative.rate", "plume.base.rate"]))
    rows.append(("Plume", "without collisions the bed erodes faster than the base case",
                 "%s against %s grains/s" % (_fmt(f, "plume.collisionless.rate"), _fmt(f, "plume.base.rate")),
                 _order(f, ["plume.base.rate", "plume.collisionless.rate"]),
                 ["plume.collisionless.rate", "plume.base.rate"]))
    rows.append(("Plume", "the erosion rate rises with the gas's penetration depth (2, 4, 6 d)",
                 "%s, %s, %s grains/s" % (_fmt(f, "plume.pen2.rate"), _fmt(f, "plume.pen4.rate"),
                                          _fmt(f, "plume.pen6.rate")),
                 _order(f, ["plume.pen2.rate", "plume.pen4.rate", "plume.pen6.rate"]),
                 ["plume.pen2.rate", "plume.pen4.rate", "plume.pen6.rate"]))
    rows.append(("Sampler", "≥ 100 mg collected after 1 s on the surface (the science requirement)",
                 _fmt(f, "sampler.v300.collected_mg.t1s", unit=" mg") + "; fraction of shots ≥ 100 mg: " +
                 _fmt(f, "sampler.v300.runs_ge_100mg_fraction", digits=2),
                 None if _v(f, "sampler.v300.collected_mg.t1s") is None else _v(f, "sampler.v300.collected_mg.t1s")
                 >= 100, ["sampler.v300.collected_mg.t1s"]))
    return rows


def reproduction(rows_csv):
    """docs/reproduction.md from the figures (the rows of the table) and the explanations kept in
    docs/reproduction.in.md (hand-written: the set-ups, the reasons for each miss)."""
    f = {}
    for fid, value, sd, n, unit, cmd in rows_csv:
        f[fid] = (float(value) if value != "NA" else None, float(sd) if sd else None, int(n))
    cmds = {r[0]: r[5] for r in rows_csv}
    mark = {True: "✓", False: "✗", None: "–"}
    out = ["| | published | this project | | command |", "|---|---|---|---|---|"]
    for sec, pub, ours, ok, fids in statements(f):
        c = sorted({cmds[i] for i in fids if cmds.get(i)})
        out.append("| %s | %s | %s | %s | %s |" % (sec, pub, ours, mark[ok], "<br>".join("`%s`" % x for x in c)))
    counts = {k: sum(1 for r in statements(f) if r[3] is k) for k in (True, False, None)}
    summary = "%d statements: %d reproduced (✓), %d not (✗), %d not run yet (–)." % (
        sum(counts.values()), counts[True], counts[False], counts[None])
    src = os.path.join(ROOT, "docs", "reproduction.in.md")
    text = read_text(src) if os.path.exists(src) else "# Reproduction\n\n<!-- table -->\n"
    return text.replace("<!-- summary -->", summary).replace("<!-- table -->", "\n".join(out))


# --- the MASCOT campaign's progress (docs/validation/mascot.md, between its markers) ------------------

MASCOT_PAGE = os.path.join(DOCS, "mascot.md")
PROGRESS_BEGIN, PROGRESS_END = "<!-- campaign-progress -->", "<!-- /campaign-progress -->"
CAMPAIGN1_RUNS = {"a": 30, "b": 60}  # scripts/campaign: part a (repeat 0) and part b (repeats 1, 2)


def campaign_progress():
    """The markdown table of every default-landing run of campaign 1 (results/campaign/d30/runs/), then
    how far the campaign has got."""
    order = {a: k for k, a in enumerate(ATTITUDES)}
    recs = sorted(mascot_records("d30"), key=lambda x: (order.get(x[0]["sweep_run"]["attitude"], 9),
                                                        x[0]["sweep_run"]["material"], x[0]["sweep_run"]["angle"],
                                                        x[0]["sweep_run"]["repeat"]))
    out = ["| run | first loss of contact | speed ratio | collision (s) | travel (m) | clear lift-off: "
           "speed ratio | travel (m) | max penetration (cm) | wall (1 thread) |", "|---|---|---|---|---|---|---|---|---|"]
    done = {"a": 0, "b": 0}
    wall = 0.0
    for r, _base in recs:
        sw, oc = r["sweep_run"], r["summary"]["outcome"]
        clear = oc.get("clear_liftoff") or {}
        done["a" if sw["repeat"] == 0 else "b"] += 1
        wall += sw["wall_seconds"]
        if not oc["lifted_off"]:
            first = "none (trapped)"
        else:
            first = "rising" if oc["angle_out_deg"] <= 90 else "descending (%.0f°)" % oc["angle_out_deg"]
        out.append("| %s, %s, %g°, repeat %d | %s | %.3f | %.2f | %.2f | %s | %s | %.2f | %.1f min |" % (
            sw["material"], sw["attitude"], sw["angle"], sw["repeat"], first, oc["speed_ratio"],
            oc["collision_duration"], oc["travel_distance"],
            "%.3f" % clear["speed_ratio"] if "speed_ratio" in clear else "–",
            "%.2f" % clear["travel_distance"] if "travel_distance" in clear else "–",
            100 * oc["max_penetration"], sw["wall_seconds"] / 60))
    n = sum(done.values())
    total = sum(CAMPAIGN1_RUNS.values())
    lines = ["", "%d of the %d runs of campaign 1 are recorded (part a, repeat 0: %d of %d; part b, repeats 1 "
             "and 2: %d of %d)." % (n, total, done["a"], CAMPAIGN1_RUNS["a"], done["b"], CAMPAIGN1_RUNS["b"])]
    if n:
        lines[-1] += (" They took %.1f core-hours (%.1f min a run on one core beside another run); the %d left "
                      "would take about %.0f more at that mean, %.0f h of a 2-core machine."
                      % (wall / 3600, wall / 60 / n, total - n, (total - n) * wall / n / 3600,
                         (total - n) * wall / n / 3600 / 2))
    return "\n".join(out + lines)


def with_progress(text):
    """The MASCOT page with the block between its markers replaced by campaign_progress()."""
    a, b = text.index(PROGRESS_BEGIN) + len(PROGRESS_BEGIN), text.index(PROGRESS_END)
    return text[:a] + "\n\n" + campaign_progress() + "\n\n" + text[b:]


def main():
    rows = table()
    text = render(rows)
    page = reproduction(rows)
    mascot_page = with_progress(read_text(MASCOT_PAGE))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--check", action="store_true",
                   help="write nothing; fail if the committed table or page differ from what the results give")
    if p.parse_args().check:
        for path, want in ((OUT, text), (REPRO, page), (MASCOT_PAGE, mascot_page)):
            old = read_text(path) if os.path.exists(path) else ""
            if old != want:
                sys.stderr.write("%s is not what the committed results give: run scripts/figures.py\n" %
                                 os.path.relpath(path, ROOT))
                sys.exit(1)
        return
    with open(OUT, "w") as f:
        f.write(text)
    with open(REPRO, "w") as f:
        f.write(page)
    with open(MASCOT_PAGE, "w") as f:
        f.write(mascot_page)
    print("figures: %s (%d ids, %d with results); %s" % (os.path.relpath(OUT, ROOT), len(rows),
                                                         sum(1 for r in rows if r[1] != "NA"),
                                                         os.path.relpath(REPRO, ROOT)))


if __name__ == "__main__":
    main()
