#!/usr/bin/python3
"""The shared tooling of the campaign, report and benchmark scripts (scripts/lib): statistics and fits
against exact numbers, the CSV readers on files with comments, and the campaigns' command line."""
import contextlib
import csv
import importlib.util
import json
import io
import math
import os
import shutil
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "lib"))
import campaign_cli  # noqa: E402
import csv_columns  # noqa: E402
import kept_run  # noqa: E402
import stats  # noqa: E402


class Statistics(unittest.TestCase):
    def test_describe_drops_missing_values_and_uses_the_sample_sd(self):
        d = stats.describe([1.0, 2.0, 6.0, None, float("nan")])
        self.assertEqual(d["n"], 3)
        self.assertAlmostEqual(d["mean"], 3.0, places=15)
        self.assertAlmostEqual(d["sd"], math.sqrt(7.0), places=14)  # ((4 + 1 + 9) / 2) ** 0.5
        self.assertEqual((d["min"], d["max"]), (1.0, 6.0))
        self.assertIsNone(stats.describe([]))
        self.assertIsNone(stats.describe([None, float("nan")]))
        self.assertIsNone(stats.describe([5.0])["sd"])

    def test_mean_sd_marks_what_is_undefined(self):
        m, sd = stats.mean_sd([])
        self.assertTrue(math.isnan(m) and math.isnan(sd))
        self.assertEqual(stats.mean_sd([2.0], missing=None), (2.0, None))
        self.assertEqual(stats.mean_sd([2.0], missing=float("inf"))[1], float("inf"))
        self.assertEqual(stats.mean_sd([1.0, 3.0]), (2.0, math.sqrt(2.0)))

    def test_paired_difference_by_students_t(self):
        # Differences 1, 2, 3: mean 2, SD 1, half-width t(2) / sqrt(3).
        m, half = stats.paired_difference([1.0, 1.0, 1.0], [2.0, 3.0, 4.0])
        self.assertAlmostEqual(m, 2.0)
        self.assertAlmostEqual(half, 4.303 / math.sqrt(3))
        m, half = stats.paired_difference([2.0, 4.0], [3.0, 6.0], relative=True)
        self.assertAlmostEqual(m, 0.5)
        self.assertEqual(half, 0.0)  # two equal relative differences
        self.assertEqual(stats.paired_difference([1.0], [2.0]), (1.0, float("inf")))

    def test_line_and_power_fits_recover_exact_data(self):
        a, b = stats.line_fit([0, 1, 2, 3], [1, 3, 5, 7])
        self.assertAlmostEqual(a, 1.0, places=12)
        self.assertAlmostEqual(b, 2.0, places=12)
        xs = [0.1, 0.2, 0.5, 1.0, 2.0]
        amp, alpha = stats.power_fit(xs, [3.0 * x ** 0.6 for x in xs])
        self.assertAlmostEqual(amp, 3.0, places=10)
        self.assertAlmostEqual(alpha, 0.6, places=10)

    def test_curve_fit_recovers_an_exponential_and_respects_bounds(self):
        xs = [0.1 * k for k in range(20)]
        ys = [2.0 * math.exp(-1.5 * x) for x in xs]
        p, rms = stats.curve_fit(lambda x, p: p[0] * (np.exp(-p[1] * x)), xs, ys, [1.0, 1.0],
                                 [0, 0], [10, 10])
        self.assertAlmostEqual(p[0], 2.0, places=8)
        self.assertAlmostEqual(p[1], 1.5, places=8)
        self.assertLess(rms, 1e-10)
        # a decay fitted to growing data stops at its bound
        p, _ = stats.curve_fit(lambda x, p: p[0] * (np.exp(-p[1] * x)), xs,
                               [math.exp(x) for x in xs], [1.0, 1.0], [0, 0], [10, 10])
        self.assertAlmostEqual(p[1], 0.0, places=12)
        self.assertGreaterEqual(p[1], 0.0)


class CsvFiles(unittest.TestCase):
    def test_comments_headers_and_columns(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "a.csv")
            with open(path, "w") as f:
                f.write("# what the columns are\nt,v,label\n0,1.5,a\n# a comment between rows\n1,2.5,b\n")
            rows = csv_columns.read_rows(path)
            self.assertEqual(rows, [{"t": "0", "v": "1.5", "label": "a"}, {"t": "1", "v": "2.5", "label": "b"}])
            c = csv_columns.read_csv(path)
            self.assertEqual(list(c["t"]), [0.0, 1.0])
            self.assertEqual(list(c["v"]), [1.5, 2.5])
            self.assertEqual(list(c["label"]), ["a", "b"])
            with open(path, "w") as f:
                f.write("t,v\n")
            self.assertEqual(csv_columns.read_rows(path), [])
            self.assertIsNone(csv_columns.read_csv(path))
            self.assertEqual(csv_columns.read_rows(os.path.join(d, "absent.csv")), [])
            self.assertIsNone(csv_columns.read_csv(os.path.join(d, "absent.csv")))


class CampaignCommandLine(unittest.TestCase):
    def test_positionals_and_names(self):
        with tempfile.TemporaryDirectory() as d:
            out, docs = os.path.join(d, "out"), os.path.join(d, "docs")
            got = campaign_cli.command_line("doc", ["bin", out, docs, "run", "a", "b"])
            self.assertEqual(got, ("bin", out, docs, "run", ["a", "b"]))
            self.assertTrue(os.path.isdir(out) and os.path.isdir(docs))
            self.assertEqual(campaign_cli.command_line("doc", ["bin", out, docs, "report"])[4], [])

    def test_too_few_arguments_is_a_usage_error(self):
        err = io.StringIO()
        with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as e:
            campaign_cli.command_line("doc", ["bin", "out"])
        self.assertEqual(e.exception.code, 2)
        self.assertIn("DOCS", err.getvalue())


def load_gate():
    from importlib.machinery import SourceFileLoader
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "gate")
    return SourceFileLoader("gate", path).load_module()


def load_script(folder, file):
    """A Python script of the repository (folder/file) loaded as a module."""
    spec = importlib.util.spec_from_file_location(
        file[:-3], os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", folder, file))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class KeptRuns(unittest.TestCase):
    """A benchmark run's summary is kept once, with its metadata; a run that stops keeps nothing."""

    def fake(self, t, code):
        # Stands for regolith_sim: writes OUT/summary.json, then exits with `code`.
        script = os.path.join(t, "fake.py")
        with open(script, "w") as f:
            f.write("import json, os, sys\nout = sys.argv[sys.argv.index('--out') + 1]\nos.makedirs(out)\n"
                    "json.dump({'run': {'steps': 3}}, open(os.path.join(out, 'summary.json'), 'w'))\n"
                    "sys.exit(%d)\n" % code)
        return [sys.executable, script, "--out", os.path.join(t, "out")]

    def test_kept_once_with_its_metadata(self):
        with tempfile.TemporaryDirectory() as t:
            keep = os.path.join(t, "kept", "a_s1.json")
            s, ran = kept_run.run_kept(self.fake(t, 0), keep, "bench", {"setting": "a"}, t)
            self.assertTrue(ran)
            self.assertEqual(s["run"]["steps"], 3)
            self.assertEqual(s["bench"]["setting"], "a")
            self.assertIn("fake.py --out out", s["bench"]["command"])  # paths inside the tree made relative
            shutil.rmtree(os.path.join(t, "out"))
            s2, ran2 = kept_run.run_kept(self.fake(t, 0), keep, "bench", {"setting": "b"}, t)
            self.assertFalse(ran2)
            self.assertEqual(s2["bench"]["setting"], "a")
            self.assertFalse(os.path.exists(os.path.join(t, "out")), "a kept run ran again")

    def test_a_run_that_stops_keeps_nothing(self):
        with tempfile.TemporaryDirectory() as t:
            keep = os.path.join(t, "kept", "a_s1.json")
            with contextlib.redirect_stdout(io.StringIO()) as said:
                s, ran = kept_run.run_kept(self.fake(t, 3), keep, "bench", {}, t)
            self.assertIsNone(s)
            self.assertTrue(ran)
            self.assertIn("exit 3", said.getvalue())
            self.assertFalse(os.path.exists(keep))


class SamplerFloorPairs(unittest.TestCase):
    """The floor study reads every shot at 0.2 s (the series row nearest it) and pairs bed with bed; the
    reference is the validation's shot on each shipped bed, and a thinned series keeps the 0.2 s row."""

    def setUp(self):
        self.sf = load_script("bench", "sampler_floor.py")

    @staticmethod
    def series(path, seg1, crater, dt=1.37e-4):
        # seg1 and crater rise linearly with time; rows every dt up to 0.25 s.
        with open(path, "w") as f:
            f.write("t,seg1_n,seg2_n,crater_depth,ejected_grains\n")
            for k in range(int(0.25 / dt) + 1):
                t = k * dt
                f.write("%.9g,%.9g,%.9g,%.9g,%.9g\n" % (t, seg1 * t / 0.2, 50, crater * t / 0.2, 1000))

    def test_references_floors_and_pairs(self):
        import sampler_campaign
        with tempfile.TemporaryDirectory() as t:
            sf = self.sf
            sf.SHOTS, sf.KEEP, sf.DOCS = os.path.join(t, "shots"), os.path.join(t, "keep"), t
            for b, (seg1, crater) in {1: (100, 0.10), 2: (120, 0.11), 3: (80, 0.09)}.items():
                d = os.path.join(sf.SHOTS, "v300_b%d" % b)
                os.makedirs(d)
                self.series(os.path.join(t, "full.csv"), seg1, crater)
                sampler_campaign.thin(os.path.join(t, "full.csv"), os.path.join(d, "series_thin.csv"))
                json.dump({"status": "ok", "run": {"wall_seconds": 3000.0, "threads": 2}},
                          open(os.path.join(d, "summary.json"), "w"))
                # The floored shot: 10 % more grains in segment 1, the same crater, ten times faster.
                os.makedirs(sf.KEEP, exist_ok=True)
                at = sf.at_time(os.path.join(t, "full.csv"))
                at["seg1_n"] *= 1.1
                # Bed 3's floored shot ran on one thread: its wall time (here 100 s) must not enter the ratio.
                run = {"wall_seconds": 300.0, "threads": 2} if b < 3 else {"wall_seconds": 100.0, "threads": 1}
                json.dump({"status": "ok", "run": run, "bench": {"at": at}},
                          open(os.path.join(sf.KEEP, "floor0.01_b%d.json" % b), "w"))
                # The validation's 1 s shot with the schedule as shipped (one thread, 1 s), 20 % deeper.
                d = os.path.join(sf.SHOTS, "v300_1s_b%d" % b)
                os.makedirs(d)
                self.series(os.path.join(t, "full.csv"), seg1, crater * 1.2)
                sampler_campaign.thin(os.path.join(t, "full.csv"), os.path.join(d, "series_thin.csv"))
                json.dump({"status": "ok", "run": {"wall_seconds": 2000.0, "threads": 1}},
                          open(os.path.join(d, "summary.json"), "w"))
            ref = sf.load("off")
            self.assertEqual(sorted(ref), [1, 2, 3])
            self.assertAlmostEqual(ref[2]["bench"]["at"]["seg1_n"], 120, delta=120 * 1e-3 / 0.2)
            with contextlib.redirect_stdout(io.StringIO()):
                sf.report()
            rows = {r[0]: r for r in csv.reader(open(os.path.join(t, "sampler_floor.csv")))}
            head = rows["setting"]
            row = rows["floor0.01"]
            self.assertEqual(row[head.index("beds")], "3")
            self.assertAlmostEqual(float(row[head.index("wall_ratio_to_off")]), 10.0)  # bed 3 ran on 1 thread: not timed
            self.assertAlmostEqual(float(row[head.index("segment1_rel_diff")]), 0.1, places=3)
            self.assertEqual(row[head.index("segment1_within")], "1")  # +10 % [exactly, no spread] inside 15 %
            self.assertAlmostEqual(float(row[head.index("crater_depth_rel_diff")]), 0.0, places=9)
            row = rows["schedule"]  # read from the 1 s shots, not timed
            self.assertEqual([row[head.index(k)] for k in ("beds", "wall_seconds", "wall_ratio_to_off")],
                             ["3", "NA", "NA"])
            self.assertAlmostEqual(float(row[head.index("crater_depth_rel_diff")]), 0.2, places=6)
            self.assertEqual(row[head.index("crater_depth_within")], "0")
            # With one bed paired there is a difference but no interval, and no verdict.
            for b in (2, 3):
                os.remove(os.path.join(sf.KEEP, "floor0.01_b%d.json" % b))
            with contextlib.redirect_stdout(io.StringIO()):
                sf.report()
            rows = {r[0]: r for r in csv.reader(open(os.path.join(t, "sampler_floor.csv")))}
            row = rows["floor0.01"]
            self.assertEqual(row[head.index("beds")], "1")
            self.assertAlmostEqual(float(row[head.index("segment1_rel_diff")]), 0.1, places=3)
            self.assertEqual([row[head.index("segment1_" + k)] for k in ("ci_lo", "ci_hi", "within")], ["NA"] * 3)
            self.assertIn("one bed: no interval", open(os.path.join(t, "sampler_floor.md")).read())
            # A series with no row near 0.2 s gives nothing to compare.
            with open(os.path.join(t, "short.csv"), "w") as f:
                f.write("t,seg1_n\n0,0\n0.1,5\n")
            self.assertIsNone(sf.at_time(os.path.join(t, "short.csv")))


class KilledRun(unittest.TestCase):
    """A run killed by a signal from outside is not recorded as stopped: it runs again next time."""

    def test_signal_exit_not_kept(self):
        with tempfile.TemporaryDirectory() as t:
            sim = os.path.join(t, "regolith_sim")
            with open(sim, "w") as f:
                f.write("#!/bin/sh\nkill -TERM $$\n")
            os.chmod(sim, 0o755)
            keep = os.path.join(t, "keep", "run_s1")
            with self.assertRaises(SystemExit) as e, contextlib.redirect_stderr(io.StringIO()):
                campaign_cli.run_and_keep(t, "scene.yaml", os.path.join(t, "out"), keep, ["seed=1"], {})
            self.assertIn("killed by signal 15", str(e.exception))
            self.assertFalse(os.path.exists(keep))
            self.assertIsNone(campaign_cli.kept(keep, "NO_SUCH_RERUN_VARIABLE"))


class SamplerShotNames(unittest.TestCase):
    """Shots on the shipped beds are named v<speed>[_1s]_b<bed>[r<repeat>]; a turned repeat keeps its bed."""

    def test_names(self):
        import sampler_campaign
        m = sampler_campaign.SHOT.match("v300_1s_b2r1")
        self.assertEqual((m.group(1), bool(m.group(2)), m.group(3), m.group(4)), ("300", True, "2", "1"))
        m = sampler_campaign.SHOT.match("v50_b3")
        self.assertEqual((m.group(1), bool(m.group(2)), m.group(3), m.group(4)), ("50", False, "3", None))
        for bad in ("v300_1s_b", "v300_1s_b1r", "v300_2s_b1", "c300_r0"):
            self.assertIsNone(sampler_campaign.SHOT.match(bad), bad)


class Gate(unittest.TestCase):
    def write(self, d, files):
        for name, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(d, name)), exist_ok=True)
            with open(os.path.join(d, name), "w") as f:
                f.write(text)

    def test_wall_times_plots_and_bed_relax_are_not_differences(self):
        gate = load_gate()
        with tempfile.TemporaryDirectory() as t:
            a, b = os.path.join(t, "a"), os.path.join(t, "b")
            self.write(a, {"summary.json": '{"run": {"wall_seconds": 1.5, "steps": 10}, "x": [1, 2]}',
                           "series.csv": "t,v\n0,1\n", "plot.png": "A", "bed_relax/series.csv": "old"})
            self.write(b, {"summary.json": '{"run": {"wall_seconds": 9.0, "steps": 10}, "x": [1, 2]}',
                           "series.csv": "t,v\n0,1\n", "plot.png": "B"})
            self.assertEqual(gate.compare(a, b), [])

    def test_values_bytes_and_missing_files_are_differences(self):
        gate = load_gate()
        with tempfile.TemporaryDirectory() as t:
            a, b = os.path.join(t, "a"), os.path.join(t, "b")
            self.write(a, {"summary.json": '{"run": {"steps": 10}}', "series.csv": "t,v\n0,1\n",
                           "ejecta.csv": "x\n"})
            self.write(b, {"summary.json": '{"run": {"steps": 11}}', "series.csv": "t,v\n0,1.0\n"})
            got = dict(gate.compare(a, b))
            self.assertEqual(got["summary.json"], "values differ")
            self.assertEqual(got["series.csv"], "bytes differ")
            self.assertTrue(got["ejecta.csv"].startswith("only in"))

    @unittest.skipUnless(os.environ.get("REGOLITH_BIN"), "REGOLITH_BIN (the build's binaries) not set")
    def test_two_builds_must_load_their_own_libraries(self):
        gate = load_gate()
        new = os.environ["REGOLITH_BIN"]
        with self.assertRaises(SystemExit) as e:
            gate.check_builds(new, new)
        self.assertIn("load the same libregolith_", str(e.exception.code))
        with tempfile.TemporaryDirectory() as old:
            # A copy of the binary alone still loads the build's libraries: refused.
            shutil.copy(os.path.join(new, "regolith_sim"), old)
            with self.assertRaises(SystemExit):
                gate.check_builds(old, new)
            # With the libraries beside it, it loads its own.
            lib = os.path.dirname(os.path.realpath(gate.libraries(new)["libregolith_core.so"]))
            for f in os.listdir(lib):
                if f.startswith("libregolith_") and f.endswith(".so"):
                    shutil.copy(os.path.join(lib, f), old)
            gate.check_builds(old, new)
            self.assertTrue(all(p.startswith(os.path.realpath(old)) for p in gate.libraries(old).values()))


class TallHeaps(unittest.TestCase):
    """scripts/repose_tall.py measures a cone of known angle at that angle (every quadrant), and keeps a run
    whose hopper did not empty as arched, without an angle."""

    def setUp(self):
        self.rt = load_script("scripts", "repose_tall.py")
        self.tmp = tempfile.mkdtemp()
        self.rt.OUT, self.rt.DOCS = os.path.join(self.tmp, "out"), os.path.join(self.tmp, "results")

    def tearDown(self):
        shutil.rmtree(self.tmp)

    @staticmethod
    def snapshot(path, x, y, z, r):
        with open(path, "wb") as f:
            f.write(b"RGTWBED1" + np.array([len(x)], dtype=np.uint64).tobytes())
            f.write(np.stack([x, y, z, r], axis=1).astype(np.float32).tobytes())

    def cone(self, name, angle_deg, left_in_hopper):
        """A run's output: a cone of grains whose tops lie on a surface at angle_deg (apex 0.05 m past the
        disk's radius R, so the flank spans the fit range), and 1000 grains in the hopper after the fill, of
        which left_in_hopper are still there when the drain stage ended."""
        rng = np.random.default_rng(7)
        R = self.rt.SCENES[self.rt.RUNS[name][0]][1]
        base_top, outlet = self.rt.BASE_TOP, self.rt.BASE_TOP + self.rt.OUTLET[self.rt.RUNS[name][1]]
        n = 60000
        rho, phi = (R + 0.02) * np.sqrt(rng.random(n)), 2 * math.pi * rng.random(n)
        r = np.full(n, 0.01)
        top = base_top + (R + 0.05 - rho) * math.tan(math.radians(angle_deg))
        x, y, z = rho * np.cos(phi), rho * np.sin(phi), top - r
        out = os.path.join(self.rt.OUT, name)
        os.makedirs(out)
        with open(os.path.join(out, "final_grains.txt"), "w") as f:
            f.write("# id x y z radius vx vy vz  (SI units)\n")
            for i in range(n):
                f.write("%d %.6f %.6f %.6f %.3f 0 0 0\n" % (i, x[i], y[i], z[i], r[i]))
        hop = np.full(1000, outlet + 0.2)
        zero = np.zeros(1000)
        self.snapshot(os.path.join(out, "fill.bed"), zero, zero, hop, zero + 0.01)
        z_drain = np.where(np.arange(1000) < left_in_hopper, outlet + 0.2, base_top + 0.05)
        self.snapshot(os.path.join(out, "drain.bed"), zero, zero, z_drain, zero + 0.01)
        stages = {k: {"t_end": t, "ended_by": "criteria"} for k, t in (("fill", 0.7), ("pour", 1.2), ("drain", 9.0),
                                                                       ("settle", 10.0))}
        with open(os.path.join(out, "summary.json"), "w") as f:
            json.dump({"stages": stages, "sim_time": 10.0, "steps": 1, "kn": 1.0, "dt": 1.0, "grains": n,
                       "max_overlap_ratio": 0.0}, f)

    def test_a_cone_is_measured_at_its_angle(self):
        for name, angle in (("tall_moderate_near_s11", 28.0), ("tall_gravel_near_s11", 48.0)):
            self.cone(name, angle, left_in_hopper=8)
            with contextlib.redirect_stdout(io.StringIO()):
                self.rt.keep_run(name, 1.0, 1.0, "regolith_sim ...")
            keep = os.path.join(self.rt.DOCS, name)
            self.assertFalse(os.path.exists(os.path.join(keep, "arched.json")))
            res = json.load(open(os.path.join(keep, "result.json")))
            self.assertEqual(res["grains_poured"], 1000)
            self.assertEqual(res["grains_left_in_hopper_after_drain"], 8)
            for q in res["quadrants_deg"]:
                self.assertAlmostEqual(q, angle, delta=0.1, msg=name)

    def test_a_hopper_that_did_not_empty_is_kept_as_arched(self):
        name = "tall_gravel_near_s12"
        self.cone(name, 38.5, left_in_hopper=900)
        with contextlib.redirect_stdout(io.StringIO()) as text:
            self.rt.keep_run(name, 1.0, 1.0, "regolith_sim ...")
        self.assertIn("arched over the outlet: 900 of 1000", text.getvalue())
        keep = os.path.join(self.rt.DOCS, name)
        self.assertFalse(os.path.exists(os.path.join(keep, "result.json")))
        rec = json.load(open(os.path.join(keep, "arched.json")))
        self.assertEqual((rec["status"], rec["grains_left_in_hopper_after_drain"]), ("arched", 900))
        self.assertNotIn("angle_deg", rec)
        self.assertEqual(list(self.rt.load_arched()), [name])
        self.assertEqual(self.rt.load_done(), {})


if __name__ == "__main__":
    unittest.main()
