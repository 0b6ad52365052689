"""Summary statistics and least-squares fits shared by the campaign, report and benchmark scripts
(tested in test/scripts/tooling_test.py)."""
import math

import numpy as np
from scipy.optimize import least_squares


def describe(xs):
    """{"n", "mean", "sd", "min", "max"} of the numbers in xs (None and NaN left out); sd is the sample
    standard deviation (n - 1), None for a single number. None if xs holds no number."""
    v = [float(x) for x in xs if x is not None and x == x]
    if not v:
        return None
    n = len(v)
    m = math.fsum(v) / n
    sd = math.sqrt(math.fsum((x - m) ** 2 for x in v) / (n - 1)) if n > 1 else None
    return {"n": n, "mean": m, "sd": sd, "min": min(v), "max": max(v)}


def mean_sd(xs, missing=float("nan")):
    """(mean, sample SD) of the numbers in xs; `missing` stands for what is undefined (no number: both;
    one number: the SD)."""
    d = describe(xs)
    if d is None:
        return missing, missing
    return d["mean"], d["sd"] if d["sd"] is not None else missing


# Student's t, two-sided 95 %, by degrees of freedom (1.96 beyond the table).
T95 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262, 10: 2.228,
       11: 2.201, 12: 2.179, 13: 2.160, 14: 2.145, 15: 2.131}


def paired_difference(ref, new, relative=False):
    """(mean, half-width of the 95 % confidence interval) of the paired differences new - ref (relative:
    (new - ref) / ref), Student's t; the half-width is infinite for a single pair."""
    d = [(y - x) / x if relative else y - x for x, y in zip(ref, new)]
    m, s = mean_sd(d, missing=float("inf"))
    half = T95.get(len(d) - 1, 1.96) * s / math.sqrt(len(d)) if len(d) > 1 else float("inf")
    return m, half


def line_fit(x, y):
    """y = a + b x by least squares: (a, b)."""
    b, a = np.polyfit(np.asarray(x, float), np.asarray(y, float), 1)
    return float(a), float(b)


def power_fit(x, y):
    """y = A x^alpha by least squares in logs: (A, alpha)."""
    a, alpha = line_fit(np.log(x), np.log(y))
    return math.exp(a), alpha


def curve_fit(model, x, y, start, lower, upper):
    """The parameters p of y = model(x, p) by bounded nonlinear least squares (scipy's trust-region
    reflective method) from `start`: (p as a list, RMS residual)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    r = least_squares(lambda p: model(x, p) - y, np.asarray(start, float), bounds=(lower, upper),
                      x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    return [float(v) for v in r.x], float(np.sqrt(np.mean(r.fun ** 2)))
