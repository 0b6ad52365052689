"""CSV files with a header row (lines starting with '#' are comments), read two ways: as columns
for plots and fits, as rows for tables (tested in test/scripts/tooling_test.py)."""
import csv
import os

import numpy as np


def read_rows(path):
    """The data rows of a CSV file as dicts of strings keyed by the header; [] if the file is absent."""
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def read_csv(path):
    """A dict of column arrays (float where every value is a number, else
    strings); None if the file is absent or has no data rows."""
    rows = read_rows(path)
    if not rows:
        return None
    cols = {}
    for k in rows[0]:
        if k is None or k == "":
            continue
        vals = [r[k] for r in rows]
        try:
            cols[k] = np.array([float(v) for v in vals])
        except (TypeError, ValueError):
            cols[k] = np.array(vals)
    return cols or None
