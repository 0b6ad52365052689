#!/usr/bin/python3
"""Inclined-plane campaign (docs/scenes.md C.2, docs/validation/incline.md).

  incline_campaign.py BIN OUT DOCS run [RUN...]   runs (default: all), one seed each
  incline_campaign.py BIN OUT DOCS report         DOCS/report.md and incline.png

Runs: onset_MAT (1-degree steps from rest, MAT = moderate or gravel), MAT_ANGLE
(flow at a fixed ANGLE: profiles over the last second, Bagnold fit, I) and rain_MAT_ANGLE (the
published protocol, config/incline_rain.yaml: grains rained onto the plane tilted at ANGLE, 8 s,
flowing or not over the last 2 s, or ended early once every grain is at rest; the onset is the
smallest angle that flows). A
finished run's summary.json (with profile.csv and series.csv) goes to DOCS/RUN/ (committed:
a campaign resumes on any machine; INCLINE_RERUN=1 runs them again); a run
that stopped leaves failed.txt there, not retried.
mu(I) = mu1 + (mu2 - mu1) / (I0 / I + 1) is fitted to the flowing runs of a material with
at least 4 angles (least squares: mu1, mu2 linear for each I0 on a log grid), mu being the
base friction mu_b = tan theta - (dV/dt) / (g cos theta) of the momentum balance.
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import campaign_cli  # noqa: E402
import csv_columns  # noqa: E402
import stats  # noqa: E402
from plots import pyplot  # noqa: E402

CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config", "incline_moderate.yaml")
DOCS_DEFAULT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "results", "incline")
RAIN_CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config", "incline_rain.yaml")
# The published protocol at fixed angles 1 degree apart around the published onsets (gravel 39-40,
# moderate 30-31 deg); each run 8 s, judged over its last 2 s (config/incline_rain.yaml).
RAIN = {"moderate": [29, 30, 31, 32, 33, 34], "gravel": [37, 38, 39, 40, 41, 42]}
PUBLISHED_ONSET = {"moderate": (30, 31), "gravel": (39, 40)}


def mat(m):
    return ["materials.grains.preset=%s" % m, "materials.base.preset=%s" % m]


RUNS = {
    "onset_moderate": (mat("moderate") + ["incline.mode=onset", "incline.start_deg=25"], "onset angle, moderate"),
    # From 3-3.5 degrees below the published angle of repose (moderate 28, gravel 38.5 deg).
    "onset_gravel": (mat("gravel") + ["incline.mode=onset", "incline.start_deg=35"], "onset angle, gravel"),
    # The history matters: the settled bed tilted at once to 30 degrees (one hold) against raised 1 degree at a time.
    "tilt30_moderate": (mat("moderate") + ["incline.mode=onset", "incline.start_deg=30", "incline.max_deg=30"],
                        "moderate tilted at once from rest to 30 deg (one 1 s hold)"),
}
# Fixed-angle series: (material, angles, run duration in s, the window in s at its end over which
# profiles and dV/dt are taken; both are passed to every run of the series). Around the flowing
# friction of moderate: at 30 deg the bed tilted at once flows and stops, at 33-34 deg it still
# accelerates after 4 s; the 8 s series holds 30.5-32 deg, where the 4 s runs came closest to steady,
# twice as long (docs/validation/incline.md: none of them is steady after 8 s either).
SERIES = {
    "moderate": ("moderate", [30, 31, 32, 33, 34], 4.0, 1.0),
    "gravel": ("gravel", [40, 42], 4.0, 1.0),
    "moderate_8s": ("moderate", [30.5, 31, 31.5, 32], 8.0, 2.0),
}


def series_run(key, a):
    return "%s_%g" % (key, a)


WINDOW = {}  # fixed-angle run -> its window (s)
for key, (m, angles, duration, window) in SERIES.items():
    for a in angles:
        RUNS[series_run(key, a)] = (
            mat(m) + ["incline.angle_deg=%g" % a, "incline.duration=%g" % duration, "incline.average=%g" % window],
            "flow at a fixed angle, %s at %g deg (%g s, profiles over the last %g s)" % (m, a, duration, window))
        WINDOW[series_run(key, a)] = window


def rain_run(m, a):
    return "rain_%s_%g" % (m, a)


for m, angles in RAIN.items():
    for a in angles:
        RUNS[rain_run(m, a)] = (mat(m) + ["incline.angle_deg=%g" % a],
                                "published protocol: %s rained onto the plane at %g deg" % (m, a))


def run_one(bin_dir, out, docs, name):
    keep = os.path.join(docs, name)
    if campaign_cli.kept(keep, "INCLINE_RERUN") is not None:
        return
    config = RAIN_CONFIG if name.startswith("rain_") else CONFIG
    s = campaign_cli.run_and_keep(bin_dir, config, os.path.join(out, name), keep, RUNS[name][0], {"run": name},
                                  copies=["profile.csv", "series.csv"])
    if s is not None:
        print("%s: %s (%.0f s)" % (name, json.dumps(s["observers"]["incline"])[:300], s["campaign"]["wall_seconds"]),
              flush=True)


I0_GRID = (1e-4, 10.0)  # the range of I0 the mu(I) fit searches
I_PLOT_MIN = 1e-3  # the left edge of the mu(I) panel


def fit_mu_i(points):
    """Least squares of mu(I) = mu1 + (mu2 - mu1) / (I0 / I + 1), I0 bounded to I0_GRID (its log the
    fitted parameter), started from five I0 across that range, the best kept: (mu1, mu2, I0, rms)."""
    lo, hi = math.log10(I0_GRID[0]), math.log10(I0_GRID[1])

    def mu(i, p):
        return p[0] + (p[1] - p[0]) * i / (10 ** p[2] + i)

    i_s, mus = [i for i, _ in points], [m for _, m in points]
    best = None
    for k in range(5):
        start = [min(mus), max(mus), lo + (hi - lo) * (k + 0.5) / 5]
        (mu1, mu2, li0), rms = stats.curve_fit(mu, i_s, mus, start, [-10, -10, lo], [10, 10, hi])
        if best is None or rms < best[3]:
            best = (mu1, mu2, 10 ** li0, rms)
    return best


def fit_resolved(mu1, mu2, i0):
    """A mu(I) fit the points determine: 0 <= mu1 < mu2 and I0 inside its grid (not on an edge)."""
    return 0 <= mu1 < mu2 and 1.01 * I0_GRID[0] < i0 < 0.99 * I0_GRID[1]


def acceleration(keep, window=1.0):
    """(v at the window's start, v at its end, slope) of the mean downslope speed over the last
    `window` s of DOCS/RUN/series.csv (least squares), or None without the file."""
    path = os.path.join(keep, "series.csv")
    if not os.path.exists(path):
        return None
    c = csv_columns.read_csv(path)
    t, v = c["t"], c["mean_vx"]
    w = t >= t[-1] - window - 1e-6
    return float(v[w][0]), float(v[w][-1]), stats.line_fit(t[w], v[w])[1]


def base_friction(o, a, g=9.81):
    """The base's friction coefficient from the momentum balance of the whole periodic layer:
    dV/dt = g (sin theta - mu_b cos theta), so mu_b = tan theta - a / (g cos theta) (= tan theta if steady)."""
    th = math.radians(o["theta_deg"])
    return math.tan(th) - a / (g * math.cos(th))


def rain_onset(done, m):
    """(onset angle or None, [(angle, flowing, end v, trend)]) of a material's rain runs: the smallest
    angle run that flows, every larger angle run flowing too (else None, with the runs)."""
    rows = []
    for a in RAIN[m]:
        n = rain_run(m, a)
        if n in done:
            o = done[n]["observers"]["incline"]
            rows.append((a, o["flowing"], o["end_mean_vx"], o["end_dvdt"]))
    onset = None
    for k, (a, fl, _, _) in enumerate(rows):
        if fl and all(r[1] for r in rows[k:]):
            onset = a
            break
    return onset, rows


STEADY_CHANGE = 0.05  # a rain run's flow counts as steady if its mean speed changes by less than this fraction
                      # over the averaging window (|dV/dt| window < 0.05 V)


def top_layer_inertial_number(profile_rows, h, phi, theta_deg, d, g=9.81):
    """I of the top layer of a flow (the published definition: the shear of the top layer):
    I = gamma_dot d / sqrt(P / rho_p), gamma_dot the velocity difference of the two highest 1 cm layers
    wholly below the surface h over their distance, P / rho_p = Phi g cos theta (h - z) at their middle.
    profile_rows: (z, v_x) of the layers (centres above the base). None if the flow has no two layers."""
    rows = sorted(profile_rows)
    if len(rows) < 2:
        return None
    dz = rows[1][0] - rows[0][0]
    inside = [(z, v) for z, v in rows if z + 0.5 * dz <= h + 1e-12]
    if len(inside) < 2:
        return None
    (z1, v1), (z2, v2) = inside[-2], inside[-1]
    zm = 0.5 * (z1 + z2)
    gamma = (v2 - v1) / (z2 - z1)
    return gamma * d / math.sqrt(phi * g * math.cos(math.radians(theta_deg)) * (h - zm))


def rain_points(done, docs, m):
    """(angle, I of the top layer, mu = tan theta, steady) of a material's flowing rain runs."""
    pts = []
    for a in RAIN[m]:
        n = rain_run(m, a)
        if n not in done:
            continue
        o = done[n]["observers"]["incline"]
        if not o["flowing"]:
            continue
        prof = os.path.join(docs, n, "profile.csv")
        if not os.path.exists(prof):
            continue
        c = csv_columns.read_csv(prof)
        rows = list(zip(c["z"], c["vx"]))
        i = top_layer_inertial_number(rows, o["flow_height"], o["packing_mean"], o["theta_deg"],
                                      done[n]["bed"]["diameter"])
        steady = abs(o["end_dvdt"]) * 2.0 < STEADY_CHANGE * abs(o["end_mean_vx"])
        pts.append((a, i, math.tan(math.radians(a)), steady))
    return pts


def steady_fit(done, m, docs=None):
    """mu(I) = mu_s + (mu_2 - mu_s) / (I0 / I + 1) fitted to a material's steady rain flows (mu = tan theta,
    I of the top layer): (mu_s, mu_2, I0) when at least 4 steady flows give a resolved fit, else None."""
    docs = docs or DOCS_DEFAULT
    pts = [(i, mu) for _, i, mu, st in rain_points(done, docs, m) if st and i and i > 0]
    if len(pts) < 4:
        return None
    mu1, mu2, i0, _ = fit_mu_i(pts)
    return (mu1, mu2, i0) if fit_resolved(mu1, mu2, i0) else None


def window_of(name):
    """The averaging window (s) of a fixed-angle run."""
    return WINDOW[name]


def report(docs):
    plt = pyplot()
    done = {n: json.load(open(os.path.join(docs, n, "summary.json"))) for n in RUNS
            if os.path.exists(os.path.join(docs, n, "summary.json"))}
    lines = ["# Inclined plane: campaign figures", "",
             "Generated by `scripts/validate_incline report` from the runs copied under this folder (one seed each).",
             "Onset: the first angle, in 1-degree steps held 1 s from rest, at whose end the mean downslope speed",
             "exceeds 0.01 sqrt(g d) and stays above it after one more hold at its trend over the hold's last quarter",
             "(moderate from 25°, gravel from 35°). Fixed angle: the settled bed tilted at once,",
             "profiles over the last %s; Bagnold v = A (1 - (1 - z/h)^1.5);" % "; ".join(
                 "%g s of %g s (%s)" % (w, d, k) for k, (_, _, d, w) in SERIES.items()),
             "I = 3 d A / (2 h^1.5 sqrt(Phi g cos theta)). A flow still accelerating is read by the momentum",
             "balance of the whole periodic layer: mu_b = tan theta - (dV/dt) / (g cos theta), dV/dt the least-squares",
             "slope of the mean downslope speed over that window (mu_b = tan theta for a steady flow).", "",
             "| run | what | result | wall (s) |", "|---|---|---|---|"]
    for n, (_, what) in RUNS.items():
        if n not in done:
            lines.append("| %s | %s | not run yet | |" % (n, what))
            continue
        o = done[n]["observers"]["incline"]
        w = done[n]["campaign"]["wall_seconds"]
        if o["mode"] == "rain" and o.get("stopped_at_rest"):
            res = "at rest at %.2f s (every grain slower than 0.01 sqrt(g d) for 0.25 s; the run ends there): " \
                  "not flowing, mean v_x %.3g m/s, trend %+.3g m/s²; %d glued" % (
                      o["rest_time"], o["end_mean_vx"], o["end_dvdt"], o["glued_grains"])
        elif o["mode"] == "rain":
            res = "%s: mean v_x %.3g m/s at the end, trend %+.3g m/s² over the last 2 s; %d glued; A = %.4g m/s, " \
                  "h = %.1f d, Phi = %.3f, I = %.4g" % (
                      "flowing" if o["flowing"] else "not flowing", o["end_mean_vx"], o["end_dvdt"],
                      o["glued_grains"], o["bagnold_a"], o["flow_height"] / done[n]["bed"]["diameter"],
                      o["packing_mean"], o["inertial_number"])
        elif o["mode"] == "onset":
            trend = o.get("hold_end_dvdt", [])
            ends = ["%.0f°: %.2g m/s" % (a, v) + (" (%+.2g m/s²)" % trend[k] if k < len(trend) else "")
                    for k, (a, v) in enumerate(zip(o["hold_angles_deg"], o["hold_end_mean_vx"]))]
            res = ("onset at %.0f deg" % o["onset_deg"] if o["onset_deg"] >= 0 else "no onset up to the last hold") + \
                " (hold-end mean v_x and its trend: %s)" % ", ".join(ends)
        else:
            res = "A = %.4g m/s, h = %.1f d, Phi = %.3f, I = %.4g, tan theta = %.4f, fit rms %.2g m/s" % (
                o["bagnold_a"], o["flow_height"] / done[n]["bed"]["diameter"], o["packing_mean"],
                o["inertial_number"], o["mu"], o["bagnold_fit_rms"])
            acc = acceleration(os.path.join(docs, n), window_of(n))
            if acc is not None:
                res += "; mean v_x %.3g -> %.3g m/s over the last %g s (dV/dt %.3g m/s², mu_b = %.4f)" % (
                    acc[0], acc[1], window_of(n), acc[2], base_friction(o, acc[2]))
        lines.append("| %s | %s | %s | %.0f |" % (n, what, res, w))
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    fits = []
    for m, (_, angles, _, window) in SERIES.items():
        pts, tans = [], []
        for a in angles:
            n = series_run(m, a)
            if n in done:
                o = done[n]["observers"]["incline"]
                acc = acceleration(os.path.join(docs, n), window)
                if o["inertial_number"] > 0 and acc is not None:
                    pts.append((o["inertial_number"], base_friction(o, acc[2])))
                    tans.append((o["inertial_number"], o["mu"]))
                prof = os.path.join(docs, n, "profile.csv")
                if os.path.exists(prof):
                    c = csv_columns.read_csv(prof)
                    h = o["flow_height"]
                    below = c["z"] < h
                    z = c["z"][below] / h
                    ax[0].plot(c["vx"][below], z, "o", ms=3, label="%s %g°" % (m, a))
                    ax[0].plot(c["bagnold"][below], z, "-", lw=0.8, color="gray")
                    ax[1].plot(c["packing"][below], z, "o-", ms=3, label="%s %g°" % (m, a))
        if pts:
            # a flow that came to rest (I below the panel's edge) is drawn at the edge as a "<"
            flowing = [p for p in pts if p[0] >= I_PLOT_MIN]
            c = ax[2].plot([p[0] for p in flowing], [p[1] for p in flowing], "o", label="%s: mu_b" % m)[0].get_color()
            rest = [p for p in pts if p[0] < I_PLOT_MIN]
            ax[2].plot([I_PLOT_MIN] * len(rest), [p[1] for p in rest], "<", color=c)
            ax[2].plot([max(p[0], I_PLOT_MIN) for p in tans], [p[1] for p in tans], "x", color="gray")
        if len(pts) >= 4:
            mu1, mu2, i0, rms = fit_mu_i(pts)
            if not fit_resolved(mu1, mu2, i0):
                fits.append("| %s | %d | not resolved: the least-squares I0 (%.3g) lies on the grid's edge or "
                            "mu1 (%.3g) outside 0 .. mu2 (%.3g); mu_b spans %.4f-%.4f over I = %.3g-%.3g | | | %.2g |" % (
                                m, len(pts), i0, mu1, mu2, min(p[1] for p in pts), max(p[1] for p in pts),
                                min(p[0] for p in pts), max(p[0] for p in pts), rms))
                continue
            fits.append("| %s | %d | %.4f (%.1f°) | %.4f (%.1f°) | %.3g | %.2g |" % (
                m, len(pts), mu1, math.degrees(math.atan(mu1)), mu2, math.degrees(math.atan(mu2)), i0, rms))
            ii = [min(p[0] for p in pts) * 0.5 * 1.05 ** k for k in range(200)]
            ii = [i for i in ii if i <= 2 * max(p[0] for p in pts)]
            ax[2].plot(ii, [mu1 + (mu2 - mu1) * i / (i0 + i) for i in ii], "-", lw=1, label="%s fit" % m)
        elif pts:
            fits.append("| %s | %d | (a fit needs 4 angles) | | | |" % (m, len(pts)))
    lines += ["", "Onset by the published protocol (rain onto the tilted plane; the smallest angle whose deposit flows, "
              "every steeper one flowing too):", "", "| material | angles run | flowing at | onset | published |",
              "|---|---|---|---|---|"]
    for m in RAIN:
        onset, rows = rain_onset(done, m)
        if not rows:
            continue
        lines.append("| %s | %s | %s | %s | %d–%d° |" % (
            m, ", ".join("%g°" % r[0] for r in rows), ", ".join("%g°" % r[0] for r in rows if r[1]) or "none",
            "%g°" % onset if onset is not None else "none in the range run", *PUBLISHED_ONSET[m]))
    lines += ["", "Flows of the published protocol (rain runs that flow): mu = tan theta, I of the top layer "
              "(the velocity difference of the two highest 1 cm layers below the surface over their distance, "
              "P / rho_p = Phi g cos theta (h - z)); steady: the mean speed changes by less than %g %% over the "
              "last 2 s." % (100 * STEADY_CHANGE), "", "| material | angle | I (top layer) | mu = tan theta | steady |",
              "|---|---|---|---|---|"]
    for m in RAIN:
        for a, i, mu, st in rain_points(done, docs, m):
            lines.append("| %s | %g° | %s | %.4f | %s |" % (m, a, "%.3g" % i if i else "–", mu, "yes" if st else "no"))
        fit = steady_fit(done, m, docs)
        if fit:
            lines.append("| %s: mu(I) fit | | mu_s %.4f, mu_2 %.4f, I0 %.3g | | |" % (m, *fit))
    lines += campaign_cli.failure_lines(docs)
    lines += ["", "Fitted mu(I) = mu1 + (mu2 - mu1) / (I0 / I + 1):", "",
              "| material | angles | mu1 | mu2 | I0 | rms |", "|---|---|---|---|---|---|"] + fits
    ax[0].set_xlabel("mean v_x in the layer (m/s); gray: Bagnold fit")
    ax[0].set_ylabel("z / h")
    ax[1].set_xlabel("solid fraction")
    ax[1].set_ylabel("z / h")
    ax[2].set_xscale("log")
    ax[2].set_xlim(left=0.7 * I_PLOT_MIN)
    ax[2].set_xlabel("inertial number I; gray x: tan theta; <: at rest (I < %g)" % I_PLOT_MIN)
    ax[2].set_ylabel("base friction mu_b")
    campaign_cli.write_report(docs, lines, fig, ax, "incline.png" if done else None,
                              "velocity and packing profiles, mu(I)")
    print("incline report: %s" % os.path.join(docs, "report.md"))


def main():
    bin_dir, out, docs, cmd, names = campaign_cli.command_line(__doc__)
    if cmd == "run":
        names = names or list(RUNS)
        campaign_cli.check_names(names, RUNS)
        for n in names:
            run_one(bin_dir, out, docs, n)
    elif cmd == "report":
        report(docs)
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main()
