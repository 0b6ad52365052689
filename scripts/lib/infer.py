#!/usr/bin/python3
"""Which surfaces explain an observed bounce (docs/infer.md).

The committed landing ensembles (results/campaign/<grid>/runs/*.json, one record per finished run)
are grouped into hypotheses about the surface: material, bed depth, scene variant (a boulder, the
cliff, any other setting the grid ran with) and attitude. What is known of the impact (speed,
angle, attitude, gravity) selects the grid points of each hypothesis; what is not known is a range
the likelihood is averaged over (a uniform prior over the range). At each grid point the outcome is
taken as normal, with the ensemble's mean and spread (the spread pooled over every point with
repeats, shrunk towards the point's own where it has them), widened by the observation's
uncertainty and the mean's own error. Between two grid angles the means are interpolated linearly
only where they differ by less than twice the pooled spread of every observed output (the ensemble
says the outcome changes slowly there); elsewhere only the grid points count.

A hypothesis is consistent with the observation when its best point (grid or interpolated) has a
chi-square p-value of at least alpha (default 0.01); none consistent: the observation is explained
by none. The posterior of each hypothesis (uniform prior over the covered hypotheses) ranks them.
The next runs are those that most sharpen the choice between the consistent hypotheses left: the
points that hold most of their likelihood with the fewest runs, and grid angles in the range that a
candidate has not run.

Tested in test/scripts/infer_test.py."""
import glob
import json
import math
import os
import sys

from scipy.stats import chi2 as chi2_dist

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
from stats import mean_sd  # noqa: E402
# DEFAULT_SCENE: a record of another scene file is a variant named after it; from_portable: the records'
# $ROOT paths (used by infer_cli too)
from sweep import DEFAULT_SCENE, POINT_OVERRIDE, from_portable, variant_overrides  # noqa: E402,F401

# Observable outcome -> (key of summary.outcome, label, scale to the plotted unit, plotted unit,
# spread assumed when no ensemble has repeats).
OUTPUTS = {
    "speed_ratio": ("speed_ratio", "speed ratio V_out/V_in", 1.0, "", 0.05),
    "angle_out_deg": ("angle_out_deg", "outgoing angle from the vertical", 1.0, "deg", 10.0),
    "travel_distance": ("travel_distance", "travel distance", 1.0, "m", 2.0),
    "spin_out": ("spin_out", "spin at lift-off", 1.0, "rad/s", 0.1),
    "collision_duration": ("collision_duration", "collision duration", 1.0, "s", 2.0),
    "max_penetration": ("max_penetration", "maximum penetration", 100.0, "cm", 0.01),
}
# What a query may give as known of the impact.
KNOWN_KEYS = ("speed", "angle_deg", "attitude", "gravity", "material", "depth")
GRID_ANGLES = (0.0, 15.0, 30.0, 45.0, 60.0)  # the published campaign's impact angles: proposed where not run
INTERP_STEP = 5.0   # deg between interpolated angles
INTERP_SPREADS = 2  # neighbours whose means differ by less than this many pooled spreads are interpolated
SHRINK = 2          # weight (in runs) of the pooled spread in a point's own


MAX_VALUE = 1e6     # largest |value| and sigma of an observation or a known value, SI units
MIN_SIGMA = 1e-9    # smallest observation uncertainty


class InferError(Exception):
    """A query that cannot be answered as given (bad value, unknown output): a clear message."""


# ---------------------------------------------------------------------------------------------- query

def _number(x, what):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise InferError(f"{what}: expected a number, got {x!r}")
    if not math.isfinite(v):
        raise InferError(f"{what}: expected a finite number, got {x!r}")
    return v


def parse_query(doc):
    """The query as {"observed": {output: (value, sigma)}, "known": {key: range or set}, "alpha", "next_runs"}
    from a mapping as the YAML file holds it (docs/infer.md, "Query")."""
    if not isinstance(doc, dict):
        raise InferError("the query is a mapping with 'observed' (and optionally 'known', 'alpha', 'next_runs')")
    unknown = set(doc) - {"observed", "known", "alpha", "next_runs"}
    if unknown:
        raise InferError(f"unknown key(s) {', '.join(sorted(unknown))} (expected observed, known, alpha, next_runs)")
    obs = doc.get("observed")
    if not isinstance(obs, dict) or not obs:
        raise InferError("'observed' must map at least one output to [value, sigma] "
                         f"(outputs: {', '.join(OUTPUTS)})")
    observed = {}
    for k, v in obs.items():
        if k not in OUTPUTS:
            raise InferError(f"observed.{k}: unknown output (known: {', '.join(OUTPUTS)})")
        if isinstance(v, dict):
            v = [v.get("value"), v.get("sigma")]
        if not isinstance(v, (list, tuple)) or len(v) != 2:
            raise InferError(f"observed.{k}: expected [value, sigma] (sigma: its 1-sigma uncertainty)")
        val, sig = _number(v[0], f"observed.{k} value"), _number(v[1], f"observed.{k} sigma")
        if not sig > 0:
            raise InferError(f"observed.{k}: sigma must be > 0 (the observation's uncertainty), got {sig:g}")
        if not (abs(val) <= MAX_VALUE and MIN_SIGMA <= sig <= MAX_VALUE):
            raise InferError(f"observed.{k}: [{val:g}, {sig:g}] is outside the values an answer can be computed "
                             f"for (|value| <= {MAX_VALUE:g}, {MIN_SIGMA:g} <= sigma <= {MAX_VALUE:g}, SI units)")
        observed[k] = (val, sig)
    known = {}
    if not isinstance(doc.get("known") or {}, dict):
        raise InferError("'known' must map keys (" + ", ".join(KNOWN_KEYS) + ") to values or ranges")
    for k, v in (doc.get("known") or {}).items():
        if k not in KNOWN_KEYS:
            raise InferError(f"known.{k}: unknown key (known: {', '.join(KNOWN_KEYS)})")
        if k in ("attitude", "material"):
            items = v if isinstance(v, (list, tuple)) else str(v).split(",")
            if isinstance(v, dict) or any(isinstance(x, (dict, list, tuple)) for x in items):
                raise InferError(f"known.{k}: expected a name or a list of names")
            known[k] = {str(x).strip() for x in items if str(x).strip()}
            if not known[k]:
                raise InferError(f"known.{k}: empty list")
            continue
        if isinstance(v, (list, tuple)):
            if len(v) != 2:
                raise InferError(f"known.{k}: expected a value or a range [min, max]")
            lo, hi = _number(v[0], f"known.{k} min"), _number(v[1], f"known.{k} max")
        else:
            lo = hi = _number(v, f"known.{k}")
        if lo > hi:
            raise InferError(f"known.{k}: the range [{lo:g}, {hi:g}] is empty")
        if max(abs(lo), abs(hi)) > MAX_VALUE:
            raise InferError(f"known.{k}: [{lo:g}, {hi:g}] is beyond {MAX_VALUE:g} (SI units)")
        known[k] = (lo, hi)
    alpha = _number(doc.get("alpha", 0.01), "alpha")
    if not 0 < alpha < 1:
        raise InferError(f"alpha: expected a probability in (0, 1), got {alpha:g}")
    nxt = doc.get("next_runs", 3)
    if not isinstance(nxt, int) or isinstance(nxt, bool) or not 0 <= nxt <= 100:
        raise InferError(f"next_runs: expected a whole number in [0, 100], got {nxt!r}")
    return {"observed": observed, "known": known, "alpha": alpha, "next_runs": nxt}


def parse_cli_value(text):
    """'0.3+-0.05' or '0.3,0.05' -> [0.3, 0.05] (an observation); '0:60' -> [0, 60]; 'BCF,FCF' -> a list."""
    for sep in ("+-", "±"):
        if sep in text:
            return [x.strip() for x in text.split(sep, 1)]
    if ":" in text:
        return [x.strip() for x in text.split(":", 1)]
    if "," in text:
        return [x.strip() for x in text.split(",")]
    return text.strip()


# ------------------------------------------------------------------------------------------ ensembles

def _finite(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def load_runs(dirs):
    """Every finished landing record under the given campaign folders (each: <grid>/runs/*.json, or a
    runs folder itself), deduplicated (the same run recorded by two grids counts once). Returns
    (runs, skipped) with runs as dicts of hypothesis, point and outcome."""
    files = []
    for d in dirs:
        if not os.path.isdir(d):
            raise InferError(f"{d}: no such campaign folder")
        files += sorted(glob.glob(os.path.join(d, "runs", "*.json"))) or \
            sorted(glob.glob(os.path.join(d, "*", "runs", "*.json"))) or sorted(glob.glob(os.path.join(d, "*.json")))
    runs, seen, skipped = [], set(), []
    for f in files:
        try:
            with open(f) as fh:
                rec = json.load(fh)
            meta, s = rec["sweep_run"], rec["summary"]
            if s.get("status") != "ok" or meta.get("exit_code") != 0:
                skipped.append((f, "not a finished run"))
                continue
            inp, out = s["input"], s["outcome"]
            variant = variant_overrides(meta.get("overrides", []))
            scene = os.path.basename(str(meta.get("config") or DEFAULT_SCENE))
            if scene != DEFAULT_SCENE:  # another scene file: the boulder, the cliff
                variant = (scene[:-5] if scene.endswith(".yaml") else scene,) + variant
            hyp = (str(meta["material"]), int(round(100 * float(meta["depth"]))), "; ".join(variant),
                   str(meta["attitude"]))
            run = {"file": os.path.relpath(f, ROOT) if f.startswith(ROOT) else f, "name": meta.get("name"),
                   "grid": os.path.basename(os.path.dirname(os.path.dirname(f))), "hyp": hyp,
                   "angle": float(meta["angle"]), "speed": float(inp["speed"]), "gravity": float(inp["gravity"]),
                   "repeat": int(meta["repeat"]), "bed": meta.get("bed"), "overrides": meta.get("overrides", []),
                   "config": meta.get("config") or os.path.join("$ROOT", "config", DEFAULT_SCENE),
                   "preparations": int(meta.get("preparations", 1)),
                   "outcome": {k: (float(out[src]) if _finite(out.get(src)) else None)
                               for k, (src, *_r) in OUTPUTS.items()}}
            if not all(_finite(run[k]) for k in ("angle", "speed", "gravity")):
                raise ValueError("angle, speed and gravity must be finite numbers")
        except (OSError, ValueError, KeyError, TypeError) as e:
            skipped.append((f, f"not a landing record ({e.__class__.__name__}: {e})"))
            continue
        key = (hyp, run["angle"], run["speed"], run["gravity"], run["repeat"], run["bed"])
        if key in seen:
            continue
        seen.add(key)
        runs.append(run)
    return runs, skipped


def hyp_label(h):
    mat, cm, variant, att = h
    return f"{mat} {cm} cm" + (f" [{variant}]" if variant else "") + f", {att}"


def pooled_spread(points, outputs):
    """Per output: the within-point SD pooled over every point with two runs or more, and its degrees of
    freedom (0: none has repeats, and the stated default of OUTPUTS is used)."""
    pooled = {}
    for o in outputs:
        ss, dof = 0.0, 0
        for p in points.values():
            xs = [r["outcome"][o] for r in p["runs"] if r["outcome"][o] is not None]
            if len(xs) > 1:
                m, sd = mean_sd(xs, missing=None)
                ss += (len(xs) - 1) * sd * sd
                dof += len(xs) - 1
        pooled[o] = (math.sqrt(ss / dof), dof) if dof else (OUTPUTS[o][4], 0)
    return pooled


def group_points(runs, outputs):
    """(hypothesis, angle, speed, gravity) -> {"runs", "n", "mean", "sd"} for the observed outputs."""
    points = {}
    for r in runs:
        if any(r["outcome"][o] is None for o in outputs):
            continue
        points.setdefault((r["hyp"], r["angle"], r["speed"], r["gravity"]), {"runs": []})["runs"].append(r)
    pooled = pooled_spread(points, outputs)
    for p in points.values():
        p["n"] = len(p["runs"])
        p["mean"], p["sd"] = {}, {}
        for o in outputs:
            m, sd = mean_sd([r["outcome"][o] for r in p["runs"]], missing=None)
            pool = pooled[o][0]
            # The point's own spread, shrunk towards the pooled one (SHRINK runs' worth of it).
            p["mean"][o] = m
            p["sd"][o] = math.sqrt(((p["n"] - 1) * sd * sd + SHRINK * pool * pool) / (p["n"] - 1 + SHRINK)) \
                if sd is not None else pool
    return points, pooled


# ------------------------------------------------------------------------------------------- inference

def _in(known, key, x):
    if key not in known:
        return True
    lo, hi = known[key]
    return lo - 1e-9 * max(1.0, abs(lo)) <= x <= hi + 1e-9 * max(1.0, abs(hi))


def _loglik(point, observed):
    chi2, ll = 0.0, 0.0
    for o, (y, s) in observed.items():
        sd = point["sd"][o]
        v = max(sd * sd * (1 + 1.0 / point["n"]) + s * s, 1e-300)
        z2 = (y - point["mean"][o]) ** 2 / v
        chi2 += z2
        ll += -0.5 * (z2 + math.log(2 * math.pi * v))
    return ll, chi2


def _angle_points(grid, pooled, observed, lo, hi):
    """The grid points of one hypothesis (at one speed and gravity) in [lo, hi] and the interpolated
    angles between neighbours whose means differ by less than INTERP_SPREADS pooled spreads, each with
    its weight (its share of the angle range). Returns (points, gaps not interpolated)."""
    angles = sorted(grid)
    pts, gaps = [], []
    for a, b in zip(angles, angles[1:]):
        if b < lo or a > hi:
            continue
        pa, pb = grid[a], grid[b]
        if all(abs(pa["mean"][o] - pb["mean"][o]) <= INTERP_SPREADS * pooled[o][0] for o in observed):
            k = max(1, int(math.ceil((b - a) / INTERP_STEP - 1e-9)))
            for j in range(1, k):
                x = a + (b - a) * j / k
                if lo <= x <= hi:
                    f = j / k
                    pts.append({"angle": x, "interpolated": True, "n": min(pa["n"], pb["n"]), "runs": [],
                                "mean": {o: (1 - f) * pa["mean"][o] + f * pb["mean"][o] for o in observed},
                                "sd": {o: max(pa["sd"][o], pb["sd"][o]) for o in observed}})
        else:
            gaps.append((a, b))
    pts += [dict(grid[a], angle=a, interpolated=False) for a in angles if lo <= a <= hi]
    pts.sort(key=lambda p: p["angle"])
    # Trapezoid weights over the angles present (a lone point carries the whole range).
    for i, p in enumerate(pts):
        left = lo if i == 0 else 0.5 * (pts[i - 1]["angle"] + p["angle"])
        right = hi if i == len(pts) - 1 else 0.5 * (p["angle"] + pts[i + 1]["angle"])
        p["weight"] = max(right - left, 0.0)
    total = sum(p["weight"] for p in pts)
    for p in pts:
        p["weight"] = p["weight"] / total if total > 0 else 1.0 / len(pts)
    return pts, gaps


def infer(query, runs):
    """The answer to a parsed query (parse_query) from the loaded runs (load_runs), as a JSON-ready dict."""
    observed, known, alpha = query["observed"], query["known"], query["alpha"]
    points, pooled = group_points(runs, observed)
    hyps = sorted({k[0] for k in points})
    notes = []
    for o, (sd, dof) in pooled.items():
        if dof == 0:
            notes.append(f"no grid point of the ensembles has repeats: the spread of {o} is the stated default "
                         f"{sd:g} (docs/infer.md)")
    ang_lo, ang_hi = known.get("angle_deg", (-math.inf, math.inf))
    results = []
    for h in hyps:
        mat, cm, variant, att = h
        if "material" in known and mat not in known["material"]:
            continue
        if "attitude" in known and att not in known["attitude"]:
            continue
        if "depth" in known and not _in(known, "depth", cm / 100.0):
            continue
        entry = {"hypothesis": {"material": mat, "depth": cm / 100.0, "variant": variant, "attitude": att},
                 "label": hyp_label(h), "covered": False, "points": [], "runs": [], "not_interpolated": []}
        # Conditions (speed, gravity) within the known ranges, each averaged with equal weight.
        conds = sorted({(k[2], k[3]) for k in points if k[0] == h and _in(known, "speed", k[2]) and
                        _in(known, "gravity", k[3])})
        lls = []
        for sp, g in conds:
            grid = {k[1]: p for k, p in points.items() if k[0] == h and k[2] == sp and k[3] == g}
            lo = max(ang_lo, min(grid)) if math.isinf(ang_lo) else ang_lo
            hi = min(ang_hi, max(grid)) if math.isinf(ang_hi) else ang_hi
            pts, gaps = _angle_points(grid, pooled, observed, lo, hi)
            if not pts:
                continue
            entry["not_interpolated"] += [[a, b] for a, b in gaps]
            for p in pts:
                ll, c2 = _loglik(p, observed)
                p["loglik"], p["chi2"] = ll, c2
                p["p_value"] = float(chi2_dist.sf(c2, len(observed)))
                entry["points"].append({"angle": p["angle"], "speed": sp, "gravity": g, "n": p["n"],
                                        "interpolated": p["interpolated"], "weight": p["weight"] / len(conds),
                                        "mean": p["mean"], "sd": p["sd"], "loglik": ll, "chi2": c2,
                                        "p_value": p["p_value"]})
                entry["runs"] += [r["file"] for r in p["runs"]]
            top = max(p["loglik"] for p in pts)
            lls.append(top + math.log(sum(p["weight"] * math.exp(p["loglik"] - top) for p in pts)))
        if not lls:
            results.append(entry)
            continue
        top = max(lls)
        entry["covered"] = True
        angles = [p["angle"] for p in entry["points"]]
        entry["angles_run"] = [min(angles), max(angles)]
        if "angle_deg" in known and (min(angles) > ang_lo + 1e-9 or max(angles) < ang_hi - 1e-9):
            notes.append(f"{entry['label']}: runs cover {min(angles):g}-{max(angles):g} deg of the known "
                         f"{ang_lo:g}-{ang_hi:g} deg (the nearest grid angle stands for the rest)")
        entry["log_likelihood"] = top + math.log(sum(math.exp(x - top) for x in lls) / len(lls))
        best = max(entry["points"], key=lambda p: p["p_value"])
        entry["best_point"] = {k: best[k] for k in ("angle", "speed", "gravity", "interpolated", "chi2", "p_value")}
        entry["consistent"] = best["p_value"] >= alpha
        results.append(entry)
    covered = [e for e in results if e["covered"]]
    if covered:
        top = max(e["log_likelihood"] for e in covered)
        z = sum(math.exp(e["log_likelihood"] - top) for e in covered)
        for e in covered:
            e["posterior"] = math.exp(e["log_likelihood"] - top) / z
    results.sort(key=lambda e: (not e.get("consistent", False), -e.get("posterior", -1.0), e["label"]))
    explained = [e["label"] for e in results if e.get("consistent")]
    if not covered:
        notes.append("no ensemble covers what is known of the impact (speed, angle, gravity, attitude, material, "
                     "depth): nothing to compare with")
    answer = {"observed": {k: list(v) for k, v in observed.items()},
              "known": {k: (sorted(v) if isinstance(v, set) else list(v)) for k, v in known.items()},
              "alpha": alpha, "runs_used": len({r["file"] for p in points.values() for r in p["runs"]}),
              "pooled_spread": {o: {"sd": sd, "dof": dof} for o, (sd, dof) in pooled.items()},
              "hypotheses": results, "explained_by": explained, "explained_by_none": not explained,
              "notes": notes}
    answer["next_runs"] = next_runs(answer, points, query["next_runs"], known)
    return answer


def next_runs(answer, points, count, known):
    """The runs that would most sharpen the choice between the consistent hypotheses left (posterior
    >= 5 % each, at least two of them; or one with fewer than three runs at its best point): points
    scored by the likelihood they hold divided by the runs behind them; an angle of the published
    grid (GRID_ANGLES) in the known range that a candidate has not run counts twice, at the largest
    likelihood share among its points)."""
    if count <= 0:
        return []
    cands = [e for e in answer["hypotheses"] if e.get("consistent") and e.get("posterior", 0) >= 0.05]
    if not cands:
        return []
    if len(cands) == 1 and cands[0]["best_point"].get("interpolated") is False and \
            max(p["n"] for p in cands[0]["points"] if not p["interpolated"]) >= 3:
        return []
    all_angles = sorted({k[1] for k in points} | set(GRID_ANGLES))
    lo, hi = known.get("angle_deg", (min(all_angles), max(all_angles)))
    scored = []
    for e in cands:
        pts = e["points"]
        top = max(p["loglik"] for p in pts)
        mass = {}
        for p in pts:
            mass[(p["angle"], p["speed"], p["gravity"])] = p["weight"] * math.exp(p["loglik"] - top)
        z = sum(mass.values()) or 1.0
        grid_pts = {(p["angle"], p["speed"], p["gravity"]): p for p in pts if not p["interpolated"]}
        for (a, sp, g), p in grid_pts.items():
            share = sum(m for (x, s2, g2), m in mass.items()
                        if s2 == sp and g2 == g and abs(x - a) <= 0.5 * INTERP_STEP + 1e-9) / z
            scored.append((e["posterior"] * share / p["n"], e, a, sp, g, p["n"]))
        for sp, g in {(k[1], k[2]) for k in grid_pts}:
            for a in all_angles:
                if lo <= a <= hi and (a, sp, g) not in grid_pts:
                    near = [m for (x, s2, g2), m in mass.items() if s2 == sp and g2 == g]
                    share = (max(near) / z) if near else 0.0
                    scored.append((2 * e["posterior"] * share, e, a, sp, g, 0))
    scored.sort(key=lambda t: -t[0])
    out = []
    for score, e, a, sp, g, n in scored[:count]:
        h = e["hypothesis"]
        out.append({"hypothesis": e["label"], "material": h["material"], "depth": h["depth"],
                    "variant": h["variant"], "attitude": h["attitude"], "angle": a, "speed": sp, "gravity": g,
                    "runs_now": n, "score": score})
    return out


# -------------------------------------------------------------------------------------------- reports

def text_report(answer):
    L = []
    obs = ", ".join(f"{k} = {v:g} ± {s:g}" for k, (v, s) in answer["observed"].items())
    L.append(f"observed: {obs}")
    if answer["known"]:
        L.append("known: " + ", ".join(f"{k} {v}" for k, v in answer["known"].items()))
    L.append(f"ensembles: {answer['runs_used']} runs")
    L.append("")
    w = max([len("hypothesis")] + [len(e["label"]) for e in answer["hypotheses"]])
    L.append(f"{'hypothesis':<{w}} {'posterior':>9} {'best p':>8} {'at angle':>8}  runs  verdict")
    for e in answer["hypotheses"]:
        if not e["covered"]:
            L.append(f"{e['label']:<{w}} {'-':>9} {'-':>8} {'-':>8}  {0:>4}  no runs in the known ranges")
            continue
        b = e["best_point"]
        ang = f"{b['angle']:g}" + ("*" if b["interpolated"] else "")
        L.append(f"{e['label']:<{w}} {e['posterior']:>9.3f} {b['p_value']:>8.3g} {ang:>8}  {len(set(e['runs'])):>4}  "
                 + ("consistent" if e["consistent"] else "inconsistent"))
    L.append("")
    if answer["explained_by_none"]:
        L.append("explained by none of the ensembles (no hypothesis reaches p >= %g)" % answer["alpha"])
    else:
        L.append("consistent: " + "; ".join(answer["explained_by"]))
    for n in answer["notes"]:
        L.append("note: " + n)
    if answer["next_runs"]:
        L.append("next runs (most informative first):")
        for r in answer["next_runs"]:
            L.append(f"  {r['hypothesis']} at {r['angle']:g} deg ({r['runs_now']} run(s) there now)")
    L.append("(* an interpolated angle)")
    return "\n".join(L)


def plot(answer, runs, path, top=12):
    """One panel per observed output: each covered hypothesis's runs in the known ranges (dots) and
    the range its points predict (mean ± 2 SD, bars), against the observation (line, ±1 and 2 sigma)."""
    import sys
    sys.path.insert(0, HERE)
    from plots import pyplot, save_figure
    plt = pyplot()
    hyps = [e for e in answer["hypotheses"] if e["covered"]][:top]
    outs = list(answer["observed"])
    fig, axes = plt.subplots(1, len(outs), figsize=(4.2 * len(outs) + 2.5, 0.45 * len(hyps) + 1.6), squeeze=False)
    files = {r["file"]: r for r in runs}
    for ax, o in zip(axes[0], outs):
        _src, label, scale, unit, _sd = OUTPUTS[o]
        y, s = answer["observed"][o]
        ax.axvspan(scale * (y - 2 * s), scale * (y + 2 * s), color="tab:orange", alpha=0.12)
        ax.axvspan(scale * (y - s), scale * (y + s), color="tab:orange", alpha=0.25)
        ax.axvline(scale * y, color="tab:orange", lw=1.5)
        for i, e in enumerate(hyps):
            yy = len(hyps) - 1 - i
            for p in e["points"]:
                m, sd = p["mean"][o], p["sd"][o]
                ax.plot([scale * (m - 2 * sd), scale * (m + 2 * sd)], [yy, yy], color="0.7" if p["interpolated"]
                        else ("tab:blue" if e.get("consistent") else "tab:red"), lw=1, alpha=0.6)
            xs = [files[f]["outcome"][o] for f in sorted(set(e["runs"])) if f in files]
            ax.plot([scale * x for x in xs], [yy] * len(xs), "o", ms=4,
                    color="tab:blue" if e.get("consistent") else "tab:red")
        ax.set_yticks(range(len(hyps)))
        ax.set_yticklabels([f"{e['label']} ({e['posterior']:.2f})" for e in reversed(hyps)] if ax is axes[0][0]
                           else [""] * len(hyps), fontsize=8)
        ax.set_xlabel(label + (f" ({unit})" if unit else ""))
        ax.grid(axis="x", alpha=0.3)
    fig.suptitle("observation (orange) against each hypothesis's runs (dots) and predicted range (bars, ±2 SD); "
                 "blue: consistent", fontsize=9)
    save_figure(fig, path)
