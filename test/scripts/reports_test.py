#!/usr/bin/python3
"""Every campaign report regenerated from the committed results is the committed report: the bucket,
inclined-plane, plume, bed and sampler reports (results/<scene>/), each run on a copy of its
results folder (nothing under docs/ is written), with its plots drawn; and the landing-savings
report (docs/bench/landing_report.md, savings.csv) from results/bench/landing/. And every shipped graded
bed has a creep measurement within its criterion."""
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DOCS = os.path.join(ROOT, "results")
PY = "/usr/bin/python3"


def run(args, **kw):
    return subprocess.run([PY] + args, cwd=ROOT, capture_output=True, text=True, timeout=600, **kw)


class CampaignReports(unittest.TestCase):
    def regenerate(self, script, folder, pages):
        with tempfile.TemporaryDirectory() as tmp:
            docs = os.path.join(tmp, folder)
            shutil.copytree(os.path.join(DOCS, folder), docs)
            for p in pages:
                os.remove(os.path.join(docs, p))
            r = run([os.path.join("scripts", script), "/nonexistent", os.path.join(tmp, "out"), docs, "report"])
            self.assertEqual(r.returncode, 0, r.stderr[-2000:])
            for p in pages:
                with open(os.path.join(docs, p)) as a, open(os.path.join(DOCS, folder, p)) as b:
                    self.assertEqual(a.read(), b.read(), "%s/%s differs from what the committed results give: "
                                     "run scripts/%s ... report" % (folder, p, script))
            self.assertTrue(glob.glob(os.path.join(docs, "*.png")), "no plot drawn")

    def test_bucket(self):
        self.regenerate("bucket_campaign.py", "bucket", ["report.md"])

    def test_incline(self):
        self.regenerate("incline_campaign.py", "incline", ["report.md"])

    def test_plume(self):
        self.regenerate("plume_campaign.py", "plume", ["report.md"])

    def test_beds(self):
        pages = sorted(os.path.basename(p) for p in glob.glob(os.path.join(DOCS, "beds", "*.md")))
        self.assertTrue(pages)
        self.regenerate("bed_campaign.py", "beds", pages)

    def test_shipped_graded_beds_do_not_creep(self):
        # Every graded bed shipped for the landing (config/beds/mascot_*_d30_g*.bed) was left alone for a
        # landing's duration (scripts/validate_beds creep) and its surface moved by at most 0.1 mean radius.
        graded = sorted(os.path.basename(p)[:-4] for p in glob.glob(os.path.join(ROOT, "config", "beds",
                                                                                  "mascot_*_d30_g*.bed")))
        self.assertTrue(graded)
        for name in graded:
            p = os.path.join(DOCS, "beds", "creep", name, "summary.json")
            self.assertTrue(os.path.exists(p), "%s: no creep measurement (scripts/validate_beds creep %s)"
                            % (name, name))
            with open(p) as f:
                c = json.load(f)["creep"]
            self.assertGreaterEqual(c["free_seconds"], 10.0, name)
            self.assertLessEqual(abs(c["drift"]), 0.1 * c["mean_radius"], "%s creeps: %+.2f mm in %g s"
                                 % (name, 1e3 * c["drift"], c["free_seconds"]))

    def test_landing_savings(self):
        with tempfile.TemporaryDirectory() as tmp:
            r = run([os.path.join("bench", "landing_savings.py"), "report", "--docs", tmp])
            self.assertEqual(r.returncode, 0, r.stderr[-2000:])
            for p in ("landing_report.md", "savings.csv"):
                with open(os.path.join(tmp, p)) as a, open(os.path.join(ROOT, "docs", "bench", p)) as b:
                    self.assertEqual(a.read(), b.read(), "docs/bench/%s differs from what results/bench/landing/ "
                                     "gives: run bench/landing_savings.py report" % p)
            self.assertTrue(os.path.exists(os.path.join(tmp, "landing_savings.png")), "no plot drawn")

    def test_sampler_runs_and_campaign(self):
        with tempfile.TemporaryDirectory() as tmp:
            docs = os.path.join(tmp, "sampler")
            shutil.copytree(os.path.join(DOCS, "sampler"), docs)
            r = run([os.path.join("scripts", "lib", "sampler_report.py"), docs])
            self.assertEqual(r.returncode, 0, r.stderr[-2000:])
            self.assertIn("| run | speed m/s |", r.stdout)
            os.remove(os.path.join(docs, "campaign.md"))
            r = run([os.path.join("scripts", "lib", "sampler_campaign.py"), os.path.join(tmp, "out"), docs])
            self.assertEqual(r.returncode, 0, r.stderr[-2000:])
            with open(os.path.join(docs, "campaign.md")) as a, open(os.path.join(DOCS, "sampler", "campaign.md")) as b:
                self.assertEqual(a.read(), b.read())
            shots = os.path.join(DOCS, "sampler", "shots", "report.md")
            if os.path.exists(shots):
                with open(os.path.join(docs, "shots", "report.md")) as a, open(shots) as b:
                    self.assertEqual(a.read(), b.read(), "results/sampler/shots/report.md differs from what its "
                                     "runs give: run scripts/lib/sampler_campaign.py")


class Plots(unittest.TestCase):
    def test_one_run_plots(self):
        for script, run_dir in (("plot_impact.py", os.path.join(DOCS, "bucket", "gb_10_v0.50")),
                                ("plot_sampler.py", os.path.join(DOCS, "sampler", "dt1"))):
            with tempfile.TemporaryDirectory() as tmp:
                d = os.path.join(tmp, "run")
                shutil.copytree(run_dir, d)
                r = run([os.path.join("scripts", script), d])
                self.assertEqual(r.returncode, 0, r.stderr[-2000:])
                self.assertTrue(glob.glob(os.path.join(d, "*.png")))

    def test_usage_errors_are_argparse_errors(self):
        for script in ("plot_impact.py", "plot_plume.py", "plot_sampler.py", "figures.py --bogus",
                       "lib/sampler_report.py", "bucket_campaign.py"):
            parts = script.split()
            r = run([os.path.join("scripts", parts[0])] + parts[1:])
            self.assertEqual(r.returncode, 2, script + ": " + r.stderr[-500:])
            self.assertIn("usage:", r.stderr, script)


if __name__ == "__main__":
    unittest.main()
