"""Columns of a CSV file with a header row, for the plot scripts."""
import os

import numpy as np


def read_csv(path):
    """A dict of column arrays (float where every value is a number, else
    strings); None if the file is absent or has no data rows."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [line.strip().split(",") for line in f if line.strip()]
    if not rows or header == [""]:
        return None
    cols = {}
    for i, k in enumerate(header):
        vals = [r[i] for r in rows]
        try:
            cols[k] = np.array([float(v) for v in vals])
        except ValueError:
            cols[k] = np.array(vals)
    return cols
