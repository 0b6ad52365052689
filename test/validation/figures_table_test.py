#!/usr/bin/python3
"""The figures table (docs/validation/figures.csv, docs/reproduction.md), the
reproduction page (docs/reproduction.md) and the MASCOT campaign's table (docs/validation/mascot.md):
they are what the committed results give (regenerated and
compared), every id is present once, in order, and every
row is well formed: a number or NA, NA exactly when no run is behind it (n = 0), a standard
deviation exactly when n > 1, a unit and, for every figure with runs, the command that made them.
The generator's statistics are checked on numbers worked by hand."""
import csv
import math
import os
import sys
import unittest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import figures  # noqa: E402


class FiguresTable(unittest.TestCase):
    def setUp(self):
        with open(os.path.join(ROOT, "docs", "validation", "figures.csv")) as f:
            self.rows = list(csv.DictReader(f))

    def test_committed_table_is_what_the_results_give(self):
        self.assertEqual(figures.read_text(os.path.join(ROOT, "docs", "validation", "figures.csv")),
                         figures.render(figures.table()),
                         "docs/validation/figures.csv is stale: run scripts/figures.py")

    def test_committed_reproduction_page_is_what_the_results_give(self):
        self.assertEqual(figures.read_text(os.path.join(ROOT, "docs", "reproduction.md")),
                         figures.reproduction(figures.table()),
                         "docs/reproduction.md is stale: run scripts/figures.py")

    def test_committed_campaign_progress_is_what_the_results_give(self):
        path = os.path.join(ROOT, "docs", "validation", "mascot.md")
        self.assertEqual(figures.read_text(path), figures.with_progress(figures.read_text(path)),
                         "docs/validation/mascot.md's campaign table is stale: run scripts/figures.py")

    def test_verdicts(self):
        # Within the tolerance or not, on numbers worked by hand; a figure not run gives no verdict.
        f = {"a": (10.15, None, 1), "b": (12.5, 0.1, 3), "c": (None, None, 0)}
        self.assertTrue(figures._within(f, "a", 10.0, 0.02))
        self.assertFalse(figures._within(f, "b", 10.0, 0.2))
        self.assertIsNone(figures._within(f, "c", 10.0, 0.2))
        self.assertTrue(figures._order(f, ["a", "b"]))
        self.assertFalse(figures._order(f, ["b", "a"]))
        self.assertIsNone(figures._order(f, ["a", "c"]))
        self.assertEqual(figures._fmt(f, "b", unit=" m"), "12.5 ± 0.10 m (n = 3)")
        self.assertEqual(figures._num(62551.0, 5), "62,551")

    def test_every_id_once_in_order(self):
        want = [i for i, _ in figures.ids()]
        self.assertEqual(len(want), len(set(want)))
        self.assertEqual([r["id"] for r in self.rows], want)
        # The ids the table must hold (a sample of each family, spelled out).
        for fid in ("bed.mascot.gravel.d30.grains", "bed.sampler.bulk_density", "bed.bucket.gb5mm.h10.grains",
                    "mascot.d30.moderate.FCF.a60.penetration", "mascot.d40.gravel.BCF.a30.travel",
                    "mascot.d30g12.moderate.BCF.a30.speed_ratio", "mascot.d30.gravel.BCF.a30.ejected_volume",
                    "sampler.v300.wave_exponent.t62us", "sampler.v50.horn_grains.cyl4.t1s",
                    "bucket.gbb.h10.v0.75.zstop", "bucket.gb5mm.h10.inv_d1", "incline.onset_tilted.gravel",
                    "incline.moderate.I0", "repose.moderate", "plume.k8e6.rate", "plume.e0.6_mu1.4.rate",
                    "plume.base.peak_collision_time"):
            self.assertIn(fid, want)
        self.assertEqual(len(want), 287)

    def test_mascot_figures_take_the_default_landing_only(self):
        # A record made with another setting (the first look's active zone, a pinned steps per contact)
        # is a variant, not a repeat of the default: no figure pools it with the default's runs.
        def record(overrides, config="$ROOT/config/mascot_landing.yaml", gravity=2.5e-4):
            point = ["materials.regolith.preset=gravel", "landing.rim=0.3", "landing.attitude=BCF",
                     "landing.angle_deg=30", "landing.repeat=0", "grains.0.file=$ROOT/config/beds/x.bed"]
            return {"sweep_run": {"status": "ok", "config": config, "overrides": point + overrides,
                                  "material": "gravel", "depth": 0.3, "attitude": "BCF", "angle": 30.0},
                    "summary": {"status": "ok", "input": {"gravity": gravity, "speed": 0.19, "slope_deg": 0}}}
        self.assertEqual(figures.mascot_point(record([])), "mascot.d30.gravel.BCF.a30")
        self.assertEqual(figures.mascot_point(record(["landing.g=1.2e-4"], gravity=1.2e-4)),
                         "mascot.d30g12.gravel.BCF.a30")
        self.assertIsNone(figures.mascot_point(record(["landing.active_radius=0.45"])))
        self.assertIsNone(figures.mascot_point(record(["contact.steps_per_contact=30"])))
        self.assertIsNone(figures.mascot_point(record([], config="$ROOT/config/mascot_boulder.yaml")))
        failed = record([])
        failed["summary"]["status"] = "blown_up"
        self.assertIsNone(figures.mascot_point(failed))

    def test_rows_are_well_formed(self):
        for r in self.rows:
            n = int(r["n"])
            self.assertGreaterEqual(n, 0, r["id"])
            self.assertTrue(r["unit"], r["id"])
            if n == 0:
                self.assertEqual(r["value"], "NA", r["id"])
                self.assertEqual(r["sd"], "", r["id"])
                continue
            v = float(r["value"])
            self.assertTrue(math.isfinite(v), r["id"])
            self.assertTrue(r["command"].startswith("scripts/"), r["id"])
            if n == 1:
                self.assertEqual(r["sd"], "", r["id"])
            else:
                self.assertGreaterEqual(float(r["sd"]), 0.0, r["id"])

    def test_statistics(self):
        self.assertEqual(figures.stats([]), (None, None, 0))
        self.assertEqual(figures.stats([2.0]), (2.0, None, 1))
        m, sd, n = figures.stats([1.0, 2.0, 6.0, float("nan"), None])
        self.assertEqual(n, 3)
        self.assertAlmostEqual(m, 3.0, places=12)
        self.assertAlmostEqual(sd, math.sqrt(7.0), places=12)  # ((4 + 1 + 9) / 2) ** 0.5
        rows = [("a.b", "1.5", "", "1", "m", "scripts/x")]
        self.assertEqual(figures.render(rows), "id,value,sd,n,unit,command\na.b,1.5,,1,m,scripts/x\n")


if __name__ == "__main__":
    unittest.main()
