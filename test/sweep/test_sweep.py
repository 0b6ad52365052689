#!/usr/bin/env python3
"""Self-test of scripts/lib/sweep.py and scripts/plot_landing.py with a stand-in
for regolith_land (test/sweep/fake_land.py): no bed and no build needed.

  /usr/bin/python3 test/sweep/test_sweep.py
"""
import csv
import json
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


def make_sweep_folder(test, prefix):
    """A temporary folder for test (its dir), with empty stand-in beds (beds) and an output path (out)."""
    test.dir = tempfile.mkdtemp(prefix=prefix)
    test.beds = os.path.join(test.dir, "beds")
    os.makedirs(test.beds)
    for m in ("moderate", "gravel"):
        open(os.path.join(test.beds, f"mascot_{m}_d30.bed"), "w").close()
    test.out = os.path.join(test.dir, "out")


def remove_sweep_folder(test):
    """The folder of make_sweep_folder removed, unless SWEEP_TEST_KEEP is set."""
    if os.environ.get("SWEEP_TEST_KEEP"):
        print(f"kept {test.dir}")
    else:
        shutil.rmtree(test.dir, ignore_errors=True)


class SweepTest(unittest.TestCase):
    def setUp(self):
        make_sweep_folder(self, "sweep_test_")

    def tearDown(self):
        remove_sweep_folder(self)

    def sweep(self, *extra, env=None):
        cmd = [sys.executable, SWEEP, "--land", FAKE, "--bed-dir", self.beds, "--out", self.out,
               "--materials", "moderate,gravel", "--attitudes", "BCF,Flat", "--angles", "0,30,60",
               "--repeats", "2", *extra]
        e = dict(os.environ, **(env or {}))
        return subprocess.run(cmd, capture_output=True, text=True, env=e)

    def rows(self):
        with open(os.path.join(self.out, "aggregate.csv")) as f:
            return list(csv.DictReader(f))

    def test_grid_failure_resume_report(self):
        # One run blows up: the others finish, the sweep reports it and exits 1.
        p = self.sweep(env={"FAKE_LAND_FAIL": "gravel_d30_Flat_a30_r1"})
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        self.assertIn("FAIL  gravel_d30_Flat_a30_r1", p.stdout)
        rows = self.rows()
        self.assertEqual(len(rows), 24)
        self.assertEqual(sum(r["status"] != "ok" for r in rows), 1)
        for key in ("speed_ratio", "travel_distance", "max_penetration", "collision_duration"):
            self.assertTrue(os.path.exists(os.path.join(self.out, key + ".png")))
        run = os.path.join(self.out, "runs", "moderate_d30_BCF_a30_r0")
        for png in ("trajectory", "energy", "force", "surface"):
            self.assertTrue(os.path.exists(os.path.join(run, png + ".png")), png)
        # A half-finished run (temporary folder) and the failed run are redone, nothing else.
        os.makedirs(os.path.join(self.out, "runs", ".moderate_d30_BCF_a0_r0.tmp"))
        shutil.rmtree(os.path.join(self.out, "runs", "moderate_d30_BCF_a0_r0"))
        p = self.sweep()
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("22 already done, 2 to run", p.stdout)
        self.assertFalse(os.path.exists(os.path.join(self.out, "runs", ".moderate_d30_BCF_a0_r0.tmp")))
        self.assertTrue(all(r["status"] == "ok" for r in self.rows()))
        # Other settings on the same folder are refused.
        p = self.sweep("--set", "landing.speed=0.1")
        self.assertEqual(p.returncode, 2)
        self.assertIn("other settings", p.stderr)
        # --dry-run says so too, instead of listing those runs as done or runnable.
        p = self.sweep("--set", "landing.speed=0.1", "--dry-run")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("moderate_d30_BCF_a0_r0: done, with other settings: the sweep refuses it", p.stdout)
        # A record folder that cannot be written is refused before any run (not a traceback after the first).
        # (Below a regular file: no folder can be made there, even by root.)
        blocker = os.path.join(self.dir, "a_file")
        open(blocker, "w").close()
        p = self.sweep("--record", os.path.join(blocker, "rec"))
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertIn("the record folder (--record) cannot be written", p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        # Report only.
        os.remove(os.path.join(self.out, "report.md"))
        p = subprocess.run([sys.executable, SWEEP, "--out", self.out, "--report-only", "--spread", "sd"],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(os.path.join(self.out, "report.md")) as f:
            text = f.read()
        self.assertIn("| gravel | 0.3 | Flat | 60 | 2 | 1/2 |", text)

    def test_pinned_default(self):
        # A grid begun without a value that was then the scene's default, continued with it pinned:
        # the finished runs count, a new run is made with it, and another value is still refused.
        grid = ("--materials", "moderate", "--attitudes", "BCF", "--angles", "0", "--no-run-plots")
        cmd = [sys.executable, SWEEP, "--land", FAKE, "--bed-dir", self.beds, "--out", self.out, *grid]
        p = subprocess.run(cmd + ["--repeats", "1"], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        p = subprocess.run(cmd + ["--repeats", "1", "--set", "landing.speed=0.19"], capture_output=True, text=True)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertIn("other settings", p.stderr)
        p = subprocess.run(cmd + ["--repeats", "2", "--pinned", "landing.speed=0.19"], capture_output=True,
                           text=True)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("1 already done, 1 to run", p.stdout)
        with open(os.path.join(self.out, "runs", "moderate_d30_BCF_a0_r1", "sweep_run.json")) as f:
            self.assertIn("landing.speed=0.19", json.load(f)["overrides"])
        p = subprocess.run(cmd + ["--repeats", "2", "--pinned", "landing.speed=0.25"], capture_output=True,
                           text=True)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertIn("other settings", p.stderr)
        p = subprocess.run(cmd + ["--repeats", "2", "--pinned", "landing.speed"], capture_output=True, text=True)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertIn("--pinned 'landing.speed': expected key=value", p.stderr)

    def test_parallel_jobs(self):
        # --jobs 3: runs overlap in time, and every run finishes once.
        cmd = [sys.executable, SWEEP, "--land", FAKE, "--bed-dir", self.beds, "--out", self.out,
               "--materials", "moderate,gravel", "--angles", "0,30,60", "--jobs", "3", "--no-run-plots"]
        p = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, FAKE_LAND_SLEEP="1.0"))
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        rows = self.rows()
        self.assertEqual(len(rows), 6)
        self.assertTrue(all(r["status"] == "ok" for r in rows))
        spans = []
        for r in rows:
            with open(os.path.join(self.out, "runs", r["run"], "stamps.json")) as f:
                st = json.load(f)
            spans.append((st["start"], st["end"]))
        most = max(sum(1 for s in spans if s[0] <= t < s[1]) for t, _ in spans)
        self.assertGreaterEqual(most, 2, spans)
        self.assertLessEqual(most, 3, spans)
        self.assertEqual(p.stdout.count(" done  "), 6, p.stdout)

    def test_record_resumes_elsewhere(self):
        # Every finished run leaves one JSON in --record; a new output folder
        # with the same record runs only what is not recorded.
        rec = os.path.join(self.dir, "record")
        p = self.sweep("--record", rec, "--no-run-plots", env={"FAKE_LAND_FAIL": "gravel_d30_Flat_a30_r1"})
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        names = sorted(os.listdir(rec))
        self.assertEqual(len(names), 23)
        self.assertNotIn("gravel_d30_Flat_a30_r1.json", names)
        with open(os.path.join(rec, "moderate_d30_BCF_a30_r0.json")) as f:
            first = json.load(f)
        self.assertEqual(first["summary"]["status"], "ok")
        self.assertEqual(first["sweep_run"]["exit_code"], 0)
        shutil.rmtree(self.out)
        p = self.sweep("--record", rec, "--no-run-plots")
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("23 finished run(s) taken from", p.stdout)
        self.assertIn("23 already done, 1 to run", p.stdout)
        rows = {r["run"]: r for r in self.rows()}
        self.assertEqual(len(rows), 24)
        self.assertTrue(all(r["status"] == "ok" for r in rows.values()))
        self.assertAlmostEqual(float(rows["moderate_d30_BCF_a30_r0"]["speed_ratio"]),
                               first["summary"]["outcome"]["speed_ratio"], places=12)
        self.assertEqual(len(os.listdir(rec)), 24)

    def test_independent_preparations(self):
        # --preparations 3: repeats 0, 1, 2 land on the bed and its seeds 2 and 3, each as prepared;
        # repeat 3 on the bed again, perturbed once. A missing seed stops the sweep naming it.
        cmd = [sys.executable, SWEEP, "--land", FAKE, "--bed-dir", self.beds, "--out", self.out, "--angles", "30",
               "--repeats", "4", "--preparations", "3", "--no-run-plots"]
        p = subprocess.run(cmd, capture_output=True, text=True)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertIn("mascot_moderate_d30_s2.bed", p.stderr)
        self.assertIn("validate_beds prepare mascot_moderate_d30_s3", p.stderr)
        for k in (2, 3):
            open(os.path.join(self.beds, f"mascot_moderate_d30_s{k}.bed"), "w").close()
        p = subprocess.run(cmd, capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        want = {0: ("mascot_moderate_d30.bed", 0), 1: ("mascot_moderate_d30_s2.bed", 0),
                2: ("mascot_moderate_d30_s3.bed", 0), 3: ("mascot_moderate_d30.bed", 1)}
        for r, (bed, perturbation) in want.items():
            with open(os.path.join(self.out, "runs", f"moderate_d30_BCF_a30_r{r}", "sweep_run.json")) as f:
                ov = json.load(f)["overrides"]
            self.assertIn(f"grains.0.file={os.path.join(self.beds, bed)}", ov)
            self.assertIn(f"landing.repeat={perturbation}", ov)
        with open(os.path.join(self.out, "report.md")) as f:
            self.assertIn("3 independent preparations", f.read())
        self.assertRegex(p.stdout, r"sweep: 4 of 4 runs done, 0 left; [0-9.]+ core-hours spent")

    def test_records_of_the_wrong_shape(self):
        # Files of a record's or a run's name that do not hold one (a list, a
        # summary that is a number, a grid point of the wrong types) are named
        # in a warning and made again, never a traceback.
        rec = os.path.join(self.dir, "record")
        os.makedirs(rec)
        bad = {"moderate_d30_BCF_a30_r0": [1, 2], "moderate_d30_BCF_a30_r1": {"sweep_run": [], "summary": 3},
               "gravel_d30_Flat_a0_r0": {"sweep_run": {"material": 7, "exit_code": 0}, "summary": {"status": "ok"}},
               "gravel_d30_Flat_a0_r1": "not json"}
        for name, v in bad.items():
            with open(os.path.join(rec, name + ".json"), "w") as f:
                f.write(v if isinstance(v, str) else json.dumps(v))
        p = self.sweep("--record", rec, "--no-run-plots")
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        for name in bad:
            if name != "gravel_d30_Flat_a0_r1":  # not JSON at all: no record, nothing to say
                self.assertIn(name + ".json is not a record of a finished run", p.stderr)
            with open(os.path.join(rec, name + ".json")) as f:
                self.assertEqual(json.load(f)["summary"]["status"], "ok")  # replaced by the run's own
        self.assertIn("0 already done, 24 to run", p.stdout)
        # A run folder whose sweep_run.json names its point with the wrong types: left out of the report.
        meta = os.path.join(self.out, "runs", "gravel_d30_Flat_a0_r0", "sweep_run.json")
        with open(meta) as f:
            m = json.load(f)
        m["depth"] = "deep"
        with open(meta, "w") as f:
            json.dump(m, f)
        p = subprocess.run([sys.executable, SWEEP, "--out", self.out, "--report-only", "--no-run-plots"],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("sweep_run.json is not a run's ('depth' is \"deep\")", p.stderr)
        self.assertEqual(len(self.rows()), 23)

    def test_missing_bed(self):
        os.remove(os.path.join(self.beds, "mascot_gravel_d30.bed"))
        p = self.sweep()
        self.assertEqual(p.returncode, 2)
        self.assertIn("mascot_gravel_d30.bed", p.stderr)
        self.assertIn("--set materials.regolith.preset=gravel", p.stderr)
        self.assertIn("--set stages.1.trim_above=0.3", p.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.out, "runs")))

    def test_plot_landing_without_contact(self):
        run = os.path.join(self.dir, "run")
        subprocess.run([sys.executable, FAKE, "x.yaml", "--out", run], check=True)
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
        s["outcome"].update(contact=False, lifted_off=False)
        with open(os.path.join(run, "summary.json"), "w") as f:
            json.dump(s, f)
        p = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "plot_landing.py"), run],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        for png in ("trajectory", "energy", "force", "surface"):
            self.assertTrue(os.path.exists(os.path.join(run, png + ".png")), png)


if __name__ == "__main__":
    unittest.main()
