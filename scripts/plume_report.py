"""Report of the plume-erosion campaign (scripts/plume_campaign.py report):
results/plume/report.md, a table of every run's figures (mean and
sample standard deviation over its seeds), and the plots beside it."""
import csv
import glob
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import campaign_cli  # noqa: E402
from plots import pyplot, save_figure  # noqa: E402

plt = pyplot()
from stats import mean_sd  # noqa: E402


# Published statements (Berger et al. 2013, abstract) a run can be compared with.
PUBLISHED = {
    "base": "collisions are frequent just above the surface: up to 20 % of the grains in a collision at a time",
    "collisionless": "the erosion dynamics change drastically when collisions are left out",
    "nondissipative": "the erosion rate depends on the collision parameters (restitution, friction)",
    "e": "the erosion rate depends on the collision parameters (restitution, friction)",
}
# The published ordering of the rates (Berger et al. 2013): collisions among the lifted grains slow
# erosion, and the rate rises with the gas's penetration depth. (faster run, slower run, statement)
ORDER = [("collisionless", "base", "without collisions erosion is faster"),
         ("nondissipative", "base", "without dissipation (eps = 1, mu = 0) erosion is faster"),
         ("base", "pen2", "penetration 4 d erodes faster than 2 d"),
         ("pen6", "base", "penetration 6 d erodes faster than 4 d")]


def order_lines(runs):
    """The published ordering against the runs: the rates' means, their difference and its standard
    error from the seeds' spread; 'holds' or 'reversed' when the difference exceeds twice its
    standard error, else 'not resolved'."""
    lines = ["| published | faster run (grains/s) | slower run (grains/s) | difference ± its standard error | "
             "here |", "|---|---|---|---|---|"]
    for fast, slow, what in ORDER:
        a = [s["observers"]["erosion"]["erosion_rate"] for _, s, _ in runs.get(fast, [])]
        b = [s["observers"]["erosion"]["erosion_rate"] for _, s, _ in runs.get(slow, [])]
        if len(a) < 2 or len(b) < 2:
            continue
        (ma, sa), (mb, sb) = mean_sd(a), mean_sd(b)
        se = math.sqrt(sa * sa / len(a) + sb * sb / len(b))
        diff = ma - mb
        verdict = "holds" if diff > 2 * se else "reversed" if diff < -2 * se else "not resolved"
        lines.append("| %s | %s %s | %s %s | %+.0f ± %.0f | %s |" % (what, fast, fmt(ma, sa), slow, fmt(mb, sb),
                                                                    diff, se, verdict))
    return lines


def runs_of(docs):
    out = {}
    for f in sorted(glob.glob(os.path.join(docs, "*_s*", "summary.json"))):
        s = json.load(open(f))
        c = s.get("campaign", {})
        out.setdefault(c.get("run", "?"), []).append((c.get("seed", 0), s, os.path.dirname(f)))
    return out


def fmt(m, sd, digits=3):
    if math.isnan(m):
        return "–"
    if math.isnan(sd):
        return "%.*g" % (digits, m)
    return "%.*g ± %.2g" % (digits, m, sd)


def n_of_t(d):
    t, n, touch = [], [], []
    with open(os.path.join(d, "n_of_t.csv")) as f:
        for r in csv.DictReader(f):
            t.append(float(r["t"]))
            n.append(int(r["above"]))
            touch.append(float(r["touching_fraction"]))
    return t, n, touch


def _rows(path):
    with open(path) as f:
        return list(csv.DictReader(x for x in f if not x.startswith("#")))


def mechanism(d):
    """Figures of one run folder from its crossings.csv, series.csv (or n_of_t.csv) and below_end.csv
    (docs/scenes.md D, "Measurements of the mechanism"); None without crossings.csv."""
    p = os.path.join(d, "crossings.csv")
    if not os.path.exists(p):
        return None
    rs = _rows(p)
    out = {"crossings": len(rs)}
    if rs:
        col = lambda k: [float(r[k]) for r in rs]  # noqa: E731
        def mean(xs):
            return mean_sd(xs)[0]
        for k in ("v_start", "v", "dv_gas", "dv_contact", "dv_gravity", "since", "ascent", "ascent_dv_gas",
                  "ascent_dv_contact", "ascent_dv_gravity"):
            out[k] = mean(col(k))
        ag, ac = col("ascent_dv_gas"), col("ascent_dv_contact")
        out["ascent_gas_share"] = sum(ag) / (sum(ag) + sum(ac)) if sum(ag) + sum(ac) else float("nan")
        out["ascent_gas_above_contact"] = mean([1.0 if g > c else 0.0 for g, c in zip(ag, ac)])
        ml = sorted(col("ascent_max_lift"))
        out["ascent_max_lift_median"] = ml[len(ml) // 2]
        out["ascent_max_lift_max"] = ml[-1]
        out["ascent_lift_above_weight"] = mean([1.0 if x > 1 else 0.0 for x in ml])
    p = os.path.join(d, "below_end.csv")
    if os.path.exists(p):
        b = _rows(p)
        out["below_end"] = len(b)
        if b:
            out["below_z_d"] = sum(float(r["z_d"]) for r in b) / len(b)
            out["below_vx"] = sum(float(r["vx"]) for r in b) / len(b)
            out["below_vx_over_u"] = sum(float(r["vx"]) / float(r["u"]) for r in b if float(r["u"]) > 0) / len(b)
            out["below_lift"] = sum(float(r["gas_z_over_weight"]) for r in b) / len(b)
            out["below_lift_max"] = max(float(r["gas_z_over_weight"]) for r in b)
    p = os.path.join(d, "series.csv")
    if os.path.exists(p):
        s = _rows(p)
        if s and "bed_vx" in s[0]:
            out["series"] = [{k: float(r[k]) for k in ("t", "above", "bed_vx", "floor_layer_vx", "lifted_vx",
                                                      "surface_layer_lift", "surface_layer_lift_max")}
                             for r in s]
    return out


def mechanism_lines(docs, names):
    """Markdown table of the mechanism figures of the kept runs `names` (those with crossings.csv)."""
    runs = runs_of(docs)
    lines = ["| run | seed | crossings | v_z at the surface (m/s) | gas / contacts / gravity above the surface (m/s) | "
             "ascent (ms) | gas / contacts / gravity over the ascent (m/s) | gas share of the ascent's push | "
             "ascents with lift > weight | median / largest lift over weight in an ascent |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name in names:
        for seed, s, d in sorted(runs.get(name, []), key=lambda x: x[0]):
            m = mechanism(d)
            if not m or not m["crossings"]:
                continue
            lines.append("| %s | %d | %d | %.3f | %.4f / %.4f / %.4f | %.1f | %.4f / %.4f / %.4f | %.2f | %.2f | "
                         "%.2f / %.2f |" % (
                             name, seed, m["crossings"], m["v_start"], m["dv_gas"], m["dv_contact"],
                             m["dv_gravity"], 1e3 * m["ascent"], m["ascent_dv_gas"], m["ascent_dv_contact"],
                             m["ascent_dv_gravity"], m["ascent_gas_share"], m["ascent_lift_above_weight"],
                             m["ascent_max_lift_median"], m["ascent_max_lift_max"]))
    return lines


def plot_groups(runs, groups, path, title):
    fig, ax = plt.subplots(figsize=(7, 4.2))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, name in enumerate(groups):
        for j, (seed, s, d) in enumerate(sorted(runs.get(name, []), key=lambda x: x[0])):
            t, n, _ = n_of_t(d)
            ax.plot(t, n, color=colours[k % len(colours)], lw=1, alpha=0.85, label=name if j == 0 else None)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("grains above the erosion plane N")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)


def report(docs, RUNS):
    runs = runs_of(docs)
    lines = ["# Plume erosion: campaign figures", "",
             "Generated by `scripts/validate_plume report` from the runs copied under this folder",
             "(one folder per run and seed: summary.json, N(t) every millisecond). Rates are the",
             "slope of one least-squares line through N(t) up to depletion (N >= 90 % of the grains;",
             "docs/scenes.md D); ± is the sample standard deviation over the seeds.", "",
             "| run | what | seeds | erosion rate (grains/s) | rate per area (1/(s m²)) | depleted at (s) | "
             "up / down crossings | max pairs per grain above | max touching fraction | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    failed = {}
    for tag, text in campaign_cli.failures(docs):
        failed.setdefault(tag.rsplit("_s", 1)[0], []).append((tag, text))
    for name, (ov, seeds, what) in RUNS.items():
        rs = runs.get(name, [])
        if name in failed:
            what += " (%d stopped, below)" % len(failed[name])
        if not rs:
            lines.append("| %s | %s | 0 of %d | not run yet | | | | | | |" % (name, what, len(seeds)))
            continue
        e = [s["observers"]["erosion"] for _, s, _ in rs]
        rate = mean_sd([x["erosion_rate"] for x in e])
        area = mean_sd([x["erosion_rate_per_area"] for x in e])
        dep = mean_sd([x["depleted_at"] if x["depleted_at"] >= 0 else None for x in e])
        ndep = sum(1 for x in e if x["depleted_at"] < 0)
        up = mean_sd([x["upward_crossings"] for x in e])
        down = mean_sd([x["downward_crossings"] for x in e])
        pairs = mean_sd([x["max_pairs_per_grain"] for x in e])
        touch = []
        for _, _, d in rs:
            touch.append(max(n_of_t(d)[2] or [0]))
        wall = mean_sd([s["campaign"]["wall_seconds"] for _, s, _ in rs])
        dep_txt = fmt(*dep) + (" (%d not depleted)" % ndep if ndep else "")
        lines.append("| %s | %s | %d of %d | %s | %s | %s | %.0f / %.0f | %s | %s | %.0f |" % (
            name, what, len(rs), len(seeds), fmt(*rate), fmt(*area), dep_txt, up[0], down[0], fmt(*pairs),
            fmt(*mean_sd(touch)), wall[0]))
    lines += campaign_cli.failure_lines(docs)
    order = order_lines(runs)
    if len(order) > 2:
        lines += ["", "The published ordering of the rates (Berger et al. 2013) against these runs:", ""] + order
    mech = mechanism_lines(docs, [n for n in RUNS if n != "splash"])
    if len(mech) > 2:
        lines += ["", "Where the grains crossing the erosion plane get their upward velocity (crossings.csv of each "
                  "run; docs/scenes.md D, \"Measurements of the mechanism\"): means over the crossings of v_z when "
                  "the grain's centre was last below the surface, the impulses over its mass from the gas, the "
                  "contacts and gravity since then, and over its last ascent (since its v_z was last <= 0); the "
                  "gas's share of the ascent's gas + contact impulse; the ascents in which the lift exceeded the "
                  "weight at some step.", ""] + mech
    lines += ["", "Published statements each run can be compared with (Berger et al. 2013):", ""]
    for k, v in PUBLISHED.items():
        lines.append("- `%s`%s: %s" % (k, " (every ε–μ run)" if k == "e" else "", v))
    plots = [("n_of_t_collisions.png", ["base", "collisionless", "nondissipative"], "collisions"),
             ("n_of_t_planes.png", ["base", "pen2", "pen6", "ero16", "upward"], "planes"),
             ("n_of_t_stiffness.png", ["base", "k8e4", "k8e5", "k8e6"], "stiffness k_n"),
             ("n_of_t_box.png", ["base", "box2", "deep"], "box and bed depth")]
    lines += [""]
    for f, groups, title in plots:
        if any(runs.get(g) for g in groups):
            plot_groups(runs, groups, os.path.join(docs, f), "N(t): " + title)
            lines.append("![%s](%s)" % (title, f))
    # Rate over the (eps, mu) grid.
    pts = []
    for name, rs in runs.items():
        if name == "base" or name.startswith("e0"):
            e_val = 0.8 if name == "base" else float(name[1:].split("_mu")[0])
            mu = 0.2 if name == "base" else float(name.split("_mu")[1])
            pts.append((e_val, mu, mean_sd([s["observers"]["erosion"]["erosion_rate"] for _, s, _ in rs])))
    if pts:
        fig, ax = plt.subplots(figsize=(6, 4))
        for e_val in sorted(set(p[0] for p in pts)):
            ps = sorted([p for p in pts if p[0] == e_val], key=lambda p: p[1])
            ax.errorbar([p[1] for p in ps], [p[2][0] for p in ps],
                        yerr=[0 if math.isnan(p[2][1]) else p[2][1] for p in ps], marker="o", capsize=3,
                        label="ε = %g" % e_val)
        ax.set_xlabel("friction μ")
        ax.set_ylabel("erosion rate (grains/s)")
        ax.grid(alpha=0.3)
        ax.legend()
        save_figure(fig, os.path.join(docs, "rate_eps_mu.png"))
        lines.append("![rate over ε and μ](rate_eps_mu.png)")
    cal = os.path.join(docs, "calibration.json")
    if os.path.exists(cal):
        c = json.load(open(cal))
        lines += ["", "Calibration (seed 1, bisection on %s of %s, target depletion at %.3g s; -1: not depleted "
                  "within the run):" % (c["symbol"], c["profile"], c["target_depleted_at"]), "",
                  "| %s (%s) | depleted at (s) |" % (c["symbol"], c.get("unit", "m/s")), "|---|---|"]
        for st in sorted(c["steps"], key=lambda x: x["scale"]):
            lines.append("| %.4g | %.4g |" % (st["scale"], st["depleted_at"]))
        lines.append("")
        lines.append("Chosen: %s = %.6g %s." % (c["symbol"], c["scale"], c.get("unit", "m/s")))
    with open(os.path.join(docs, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("plume report: %s" % os.path.join(docs, "report.md"))
