"""Bed snapshots read from Python (docs/model.md section 14) and the k_n rule on them (section 4)."""
import math

import numpy as np


def read_snapshot(path):
    """(x, y, z, r) arrays of the grains of a float32 (RGTWBED1) or float64 (RGTWBED2) bed snapshot."""
    data = open(path, "rb").read()
    kinds = {b"RGTWBED1": np.float32, b"RGTWBED2": np.float64}
    if data[:8] not in kinds:
        raise SystemExit("%s: not a bed snapshot" % path)
    kind = kinds[data[:8]]
    n = int(np.frombuffer(data[8:16], dtype=np.uint64)[0])
    size = 4 * np.dtype(kind).itemsize * n
    if len(data) < 16 + size:
        raise SystemExit("%s: truncated bed snapshot" % path)
    rec = np.frombuffer(data[16:16 + size], dtype=kind).reshape(n, 4).astype(float)
    return rec[:, 0], rec[:, 1], rec[:, 2], rec[:, 3]


def rule_contact(path, v_max, x_max, steps, density):
    """(k_n, dt) the linear law's rule gives on the bed of this snapshot: k_n = m_p (v_max / (x_max r_min))^2,
    dt = pi sqrt(m_p / (2 k_n)) / steps, m_p the mean grain mass."""
    r = read_snapshot(path)[3]
    m_p = float(np.mean(4.0 / 3.0 * math.pi * r ** 3 * density))
    kn = m_p * (v_max / (x_max * float(r.min()))) ** 2
    return kn, math.pi * math.sqrt(m_p / (2 * kn)) / steps


def mascot_contact(path, x_max=0.01, steps=30):
    """(k_n, dt) of the MASCOT rule (config/mascot_landing.yaml: v_max 0.19 m/s, x_max 0.01 of the smallest
    radius, grains of 2430 kg/m^3) on the bed of this snapshot with `steps` per contact (default 30, as the
    bed preparation and creep files have it; the landing itself has 15), or with another x_max."""
    return rule_contact(path, 0.19, x_max, steps, 2430.0)


def surface(path, radius, cell):
    """Mean over square cells of side `cell` (their centres within `radius` of the axis) of the highest
    grain top in each: the height of a bed's surface where it is sampled."""
    x, y, z, r = read_snapshot(path)
    top = {}
    for xi, yi, t in zip(x, y, z + r):
        if math.hypot(xi, yi) > radius + cell:
            continue
        key = (int(math.floor(xi / cell)), int(math.floor(yi / cell)))
        if math.hypot((key[0] + 0.5) * cell, (key[1] + 0.5) * cell) <= radius and t > top.get(key, -1e300):
            top[key] = t
    return float(np.mean(list(top.values()))), len(top)
