#!/usr/bin/env python3
"""Every flag of scripts/sweep against hostile values, table-driven.

The flags come from the sweep's own parser (make_parser), so a new flag is
covered without editing this test. Each flag that takes a value gets each
hostile value below on a one-run grid with the stand-in for regolith_land
(test/sweep/fake_land.py); each switch is given alone. Slurm's commands are
stand-ins that fail (no cluster is reached from here; test_slurm.py runs the
real one).

The oracle, for every case: an exit code of 0, 1 or 2 (never a signal), no
Python traceback, an answer within CASE_S seconds, a message on stderr when
the code is not 0, and nothing written outside the case's folder; a sweep
that exits 0 having run has its aggregate.csv with finite numbers.

  /usr/bin/python3 test/sweep/test_sweep_flags.py
"""
import argparse
import concurrent.futures
import csv
import importlib.util
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
SWEEP = os.path.join(ROOT, "scripts", "lib", "sweep.py")
FAKE = os.path.join(HERE, "fake_land.py")
CASE_S = 120

VALUES = ["", "0", "-0", "-1", "1e-300", "1e300", "nan", "inf", "-inf", "abc", ",", "x" * 5000,
          "../../escape", "/dev/full", "1000000000"]
# The one-run grid every case starts from; a flag under test replaces its entry.
BASE = {"--land": FAKE, "--materials": "moderate", "--depths": "0.30", "--attitudes": "BCF", "--angles": "30",
        "--repeats": "1", "--no-run-plots": None}
SLURM_STUBS = ("sbatch", "squeue", "sacct", "scancel", "sinfo")


def sweep_parser():
    spec = importlib.util.spec_from_file_location("sweep_under_test", SWEEP)
    mod = importlib.util.module_from_spec(spec)
    sys.path.insert(0, os.path.dirname(SWEEP))
    spec.loader.exec_module(mod)
    return mod.make_parser()


def flags():
    """(flag, how many values it takes: 0 for a switch) for every flag but --help."""
    out = []
    for act in sweep_parser()._actions:
        if isinstance(act, argparse._HelpAction):
            continue
        flag = max(act.option_strings, key=len)
        nargs = 0 if act.nargs == 0 else (act.nargs if isinstance(act.nargs, int) else 1)
        out.append((flag, nargs))
    return out


def finite_numbers(path):
    bad = []
    with open(path) as f:
        for row in csv.DictReader(f):
            for k, v in row.items():
                try:
                    x = float(v)
                except (TypeError, ValueError):
                    continue
                if not math.isfinite(x) and v.strip().lower() not in ("nan", ""):
                    bad.append(f"{k}={v}")
    return bad


class SweepFlags(unittest.TestCase):
    def setUp(self):
        self.root = tempfile.mkdtemp(prefix="sweep_flags_")
        self.beds = os.path.join(self.root, "beds")
        os.makedirs(self.beds)
        open(os.path.join(self.beds, "mascot_moderate_d30.bed"), "w").close()
        self.stubs = os.path.join(self.root, "stubs")
        os.makedirs(self.stubs)
        for c in SLURM_STUBS:
            p = os.path.join(self.stubs, c)
            with open(p, "w") as f:
                f.write("#!/bin/sh\necho \"%s: no cluster here (stand-in)\" >&2\nexit 1\n" % c)
            os.chmod(p, 0o755)

    def tearDown(self):
        shutil.rmtree(self.root, ignore_errors=True)

    def run_case(self, k, flag, values):
        case = os.path.join(self.root, "case_%03d" % k)
        cwd = os.path.join(case, "w", "d")  # a relative ../../x stays inside the case
        os.makedirs(cwd)
        args = dict(BASE, **{"--bed-dir": self.beds, "--out": os.path.join(case, "out")})
        args[flag] = values
        cmd = [sys.executable, SWEEP]
        for f, v in args.items():
            cmd += [f] if v is None else [f, *v] if isinstance(v, list) else [f, v]
        env = dict(os.environ, PATH=self.stubs + ":" + os.environ.get("PATH", "/usr/bin:/bin"), MPLBACKEND="Agg")
        label = "%s %s" % (flag, " ".join(repr(v[:30]) for v in values) if values else "")
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd, timeout=CASE_S)
        except subprocess.TimeoutExpired:
            return label, ["no answer within %d s" % CASE_S]
        problems = []
        if p.returncode not in (0, 1, 2):
            problems.append("exit %d" % p.returncode)
        if "Traceback" in p.stderr or "Traceback" in p.stdout:
            problems.append("a traceback: " + p.stderr[-600:])
        if p.returncode != 0 and not p.stderr.strip():
            problems.append("exit %d without a message" % p.returncode)
        out = os.path.join(cwd, values[0]) if flag == "--out" else args["--out"]
        agg = os.path.join(out, "aggregate.csv")
        ran = p.returncode == 0 and flag not in ("--dry-run", "--report-only", "--slurm-task", "--no-wait")
        if ran:
            if not os.path.isfile(agg):
                problems.append("exit 0 without aggregate.csv")
            else:
                problems += ["not finite: " + b for b in finite_numbers(agg)]
        return label, problems

    def test_every_flag(self):
        cases = []
        for flag, nargs in flags():
            if flag in ("--out", "--bed-dir"):
                vals = [[v] for v in VALUES]  # the case's own folders are replaced, still inside the case
            elif nargs == 0:
                vals = [None]
            else:
                vals = [[v] * nargs for v in VALUES]
            cases += [(flag, v) for v in vals]
        self.assertGreater(len(cases), 300)
        before = set(os.listdir(self.root))
        results = []
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as ex:
            futs = [ex.submit(self.run_case, k, f, v) for k, (f, v) in enumerate(cases)]
            results = [f.result() for f in futs]
        bad = ["%s: %s" % (label, "; ".join(p)) for label, p in results if p]
        # Nothing outside the cases' folders (a value such as ../../escape stays where it was given).
        extra = set(os.listdir(self.root)) - before - {"case_%03d" % k for k in range(len(cases))}
        if extra:
            bad.append("written outside the cases' folders: %s" % sorted(extra))
        print("sweep flags: %d flags, %d cases, %d bad" % (len(flags()), len(cases), len(bad)))
        self.assertEqual(bad, [], "\n" + "\n".join(bad[:40]))


if __name__ == "__main__":
    unittest.main()
