#!/usr/bin/python3
"""regolith_infer (scripts/lib/infer.py, docs/infer.md) on synthetic ensembles: observations drawn
from one grid point's ensemble rank that point's hypothesis first in at least 9 of 10 draws; an
observation outside every ensemble is explained by none; interpolation only between neighbours the
spread allows; bad queries are refused with a message; --run adds the proposed run to its grid's
records (a stand-in regolith_land)."""
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts", "lib"))
import infer  # noqa: E402

CLI = os.path.join(ROOT, "scripts", "lib", "infer_cli.py")
FAKE = os.path.join(ROOT, "test", "sweep", "fake_land.py")
MATERIALS = ("gravel", "moderate")
ATTITUDES = ("Flat", "BCF", "FCF")
ANGLES = (0, 15, 30, 45, 60)
# Run-to-run spreads of the order the campaigns show (speed ratio, outgoing angle, travel, penetration).
SD = {"speed_ratio": 0.03, "angle_out_deg": 6.0, "travel_distance": 0.8, "max_penetration": 0.006}


def truth(mat, att, ang):
    """Smooth synthetic means over the grid. The speed ratio's offsets between materials and attitudes
    are of the size the first look at the shipped 30 cm beds shows (results/campaign/first_look: at
    30 deg on gravel, Flat 0.30, BCF 0.45, FCF 0.18; moderate BCF 0.25)."""
    g = mat == "gravel"
    a = ATTITUDES.index(att)
    return {"speed_ratio": (0.30 if g else 0.15) + {"Flat": 0.0, "BCF": 0.12, "FCF": -0.12}[att] + 0.003 * ang,
            "angle_out_deg": 40 + 0.6 * ang + (8 if g else 0) - 12 * a,
            "travel_distance": (8.0 if g else 5.0) + 0.05 * ang + 1.5 * a,
            "max_penetration": (0.04 if g else 0.065) - 0.008 * a - 0.0002 * ang}


def record(folder, mat, att, ang, rep, out):
    name = f"{mat}_d30_{att}_a{ang:g}_r{rep}"
    bed = f"$ROOT/config/beds/mascot_{mat}_d30.bed"
    rec = {"sweep_run": {"name": name, "material": mat, "depth": 0.3, "attitude": att, "angle": ang, "repeat": rep,
                         "config": "$ROOT/config/mascot_landing.yaml", "bed": bed, "exit_code": 0, "status": "ok",
                         "overrides": [f"materials.regolith.preset={mat}", f"materials.container.preset={mat}",
                                       f"materials.lander.preset={mat}", "landing.rim=0.3", f"grains.0.file={bed}",
                                       f"landing.attitude={att}", f"landing.angle_deg={ang:g}",
                                       f"landing.repeat={rep}"]},
           "summary": {"status": "ok", "input": {"attitude": att, "angle_deg": ang, "speed": 0.19,
                                                 "gravity": 2.5e-4, "repeat": rep},
                       "outcome": dict(out, spin_out=0.1, collision_duration=8.0)}}
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name + ".json"), "w") as f:
        json.dump(rec, f)


def synthetic_campaign(root, repeats=3, seed=7):
    rng = random.Random(seed)
    folder = os.path.join(root, "d30", "runs")
    for mat in MATERIALS:
        for att in ATTITUDES:
            for ang in ANGLES:
                mu = truth(mat, att, ang)
                for rep in range(repeats):
                    record(folder, mat, att, ang, rep, {k: rng.gauss(mu[k], SD[k]) for k in SD})
    return root


class Infer(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="infer_test_")
        synthetic_campaign(cls.dir)
        cls.runs, skipped = infer.load_runs([cls.dir])
        assert not skipped and len(cls.runs) == 2 * 3 * 5 * 3

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir)

    def ask(self, observed, known=None, **kw):
        return infer.infer(infer.parse_query(dict({"observed": observed, "known": known or {}}, **kw)), self.runs)

    def test_draws_rank_their_hypothesis_first(self):
        # Observations drawn from the ensemble of a grid point (normal, with the mean and SD of its
        # runs), observed to half that spread, the angle known to +-10 deg around it and the attitude
        # unknown: that point's hypothesis ranks first, and is consistent, in at least 9 of 10 draws.
        rng = random.Random(11)
        for mat, att, ang in (("gravel", "BCF", 30), ("moderate", "Flat", 15), ("moderate", "FCF", 45),
                              ("gravel", "Flat", 60)):
            ens = [r["outcome"] for r in self.runs if r["hyp"] == (mat, 30, "", att) and r["angle"] == ang]
            self.assertEqual(len(ens), 3)
            stats = {k: infer.mean_sd([o[k] for o in ens]) for k in SD}
            first = 0
            for _ in range(10):
                obs = {k: [rng.gauss(m, sd), 0.5 * sd] for k, (m, sd) in stats.items()}
                ans = self.ask(obs, {"angle_deg": [ang - 10, ang + 10], "speed": [0.15, 0.23]})
                top = ans["hypotheses"][0]
                first += top["label"] == f"{mat} 30 cm, {att}" and top["consistent"]
            self.assertGreaterEqual(first, 9, (mat, att, ang, first))

    def test_outside_every_ensemble_is_explained_by_none(self):
        ans = self.ask({"speed_ratio": [0.95, 0.02], "travel_distance": [30, 2]})
        self.assertTrue(ans["explained_by_none"])
        self.assertEqual(ans["explained_by"], [])
        self.assertTrue(all(not e["consistent"] for e in ans["hypotheses"]))
        self.assertIn("explained by none", infer.text_report(ans))

    def test_known_ranges_select_the_points(self):
        ans = self.ask({"speed_ratio": [0.3, 0.05]}, {"attitude": "BCF", "material": ["gravel"],
                                                     "angle_deg": [20, 40]})
        self.assertEqual([e["label"] for e in ans["hypotheses"]], ["gravel 30 cm, BCF"])
        self.assertTrue(all(20 <= p["angle"] <= 40 for p in ans["hypotheses"][0]["points"]))
        # A speed no ensemble ran at: nothing covers it, and the answer says so.
        ans = self.ask({"speed_ratio": [0.3, 0.05]}, {"speed": [0.5, 0.6]})
        self.assertTrue(all(not e["covered"] for e in ans["hypotheses"]))
        self.assertTrue(ans["explained_by_none"])
        self.assertTrue(any("no ensemble covers" in n for n in ans["notes"]))

    def test_interpolation_only_where_the_spread_allows(self):
        # Repeats at mean - sd, mean, mean + sd: every point's mean is its given one and the pooled spread
        # is sd (0.02). A speed ratio that changes by 0.015 per 15 deg is interpolated between every
        # pair of grid angles; one that jumps by 0.4 between 30 and 45 deg is not interpolated there.
        def grid(name, mean):
            folder = os.path.join(self.dir, name, "runs")
            for ang in ANGLES:
                for rep, k in enumerate((-1, 0, 1)):
                    record(folder, "moderate", "BCF", ang, rep, {"speed_ratio": mean(ang) + 0.02 * k,
                                                                 "angle_out_deg": 50, "travel_distance": 5,
                                                                 "max_penetration": 0.05})
            return infer.load_runs([os.path.join(self.dir, name)])[0]

        q = infer.parse_query({"observed": {"speed_ratio": [0.4, 0.05]}})
        e = infer.infer(q, grid("smooth", lambda a: 0.2 + 0.001 * a))["hypotheses"][0]
        self.assertEqual(e["not_interpolated"], [])
        self.assertEqual(sorted(p["angle"] for p in e["points"] if p["interpolated"]),
                         [5, 10, 20, 25, 35, 40, 50, 55])
        p20 = next(p for p in e["points"] if p["angle"] == 20)
        self.assertAlmostEqual(p20["mean"]["speed_ratio"], 0.22, places=12)
        e = infer.infer(q, grid("jump", lambda a: 0.2 if a <= 30 else 0.6))["hypotheses"][0]
        self.assertEqual(e["not_interpolated"], [[30.0, 45.0]])
        self.assertFalse(any(p["interpolated"] and 30 < p["angle"] < 45 for p in e["points"]))
        self.assertFalse(e["consistent"])  # 0.4 lies between the two regimes, in neither

    def test_next_runs_come_from_the_candidates(self):
        mu = truth("moderate", "BCF", 30)
        ans = self.ask({"speed_ratio": [mu["speed_ratio"], 0.1]}, {"angle_deg": [30, 30]}, next_runs=4)
        cands = {e["label"] for e in ans["hypotheses"] if e["consistent"] and e["posterior"] >= 0.05}
        self.assertGreaterEqual(len(cands), 2)
        self.assertEqual(len(ans["next_runs"]), 4)
        self.assertTrue(all(r["hypothesis"] in cands and r["angle"] == 30 for r in ans["next_runs"]))

    def test_scene_variants_are_hypotheses_of_their_own(self):
        # Runs of another scene file (a boulder under the aim point) and with a setting beyond the grid
        # point are hypotheses apart from the plain bed's.
        camp = tempfile.mkdtemp(prefix="infer_variants_", dir=self.dir)
        mu = truth("moderate", "BCF", 30)
        record(os.path.join(camp, "plain", "runs"), "moderate", "BCF", 30, 0, mu)
        for grid, config, extra in (("boulder", "$ROOT/config/mascot_boulder.yaml", ["bodies.1.position=[0,0,0.15]"]),
                                    ("low_g", "$ROOT/config/mascot_landing.yaml", ["landing.g=1.2e-4"])):
            folder = os.path.join(camp, grid, "runs")
            record(folder, "moderate", "BCF", 30, 0, mu)
            path = os.path.join(folder, "moderate_d30_BCF_a30_r0.json")
            with open(path) as f:
                rec = json.load(f)
            rec["sweep_run"]["config"] = config
            rec["sweep_run"]["overrides"] += extra
            if grid == "low_g":
                rec["summary"]["input"]["gravity"] = 1.2e-4
            with open(path, "w") as f:
                json.dump(rec, f)
        runs, _ = infer.load_runs([camp])
        labels = sorted(infer.hyp_label(r["hyp"]) for r in runs)
        self.assertEqual(labels, ["moderate 30 cm [mascot_boulder; bodies.1.position=[0,0,0.15]], BCF",
                                  "moderate 30 cm, BCF", "moderate 30 cm, BCF"])
        # The gravity is a condition of the point (landing.g), not a variant: selected by known.gravity.
        ans = infer.infer(infer.parse_query({"observed": {"speed_ratio": [mu["speed_ratio"], 0.05]},
                                             "known": {"gravity": 1.2e-4}}), runs)
        covered = [e for e in ans["hypotheses"] if e["covered"]]
        self.assertEqual([e["label"] for e in covered], ["moderate 30 cm, BCF"])
        self.assertEqual([p["gravity"] for p in covered[0]["points"]], [1.2e-4])

    def test_bad_queries_are_refused(self):
        for doc, words in (({"observed": {"bounce": [0.3, 0.1]}}, "unknown output"),
                           ({"observed": {"speed_ratio": [0.3, 0]}}, "sigma must be > 0"),
                           ({"observed": {"speed_ratio": [0.3, "x"]}}, "expected a number"),
                           ({"observed": {"speed_ratio": [0.3, 0.1]}, "known": {"angle_deg": [60, 0]}}, "empty"),
                           ({"observed": {"speed_ratio": [0.3, 0.1]}, "known": {"colour": 1}}, "unknown key"),
                           ({"observed": {}}, "at least one output"),
                           ({"observed": {"speed_ratio": [0.3, 0.1]}, "alpha": 2}, "alpha"),
                           ({"observed": {"speed_ratio": [0.3, 0.1]}, "next_runs": -1}, "next_runs"),
                           ({"observed": {"speed_ratio": [0.3, 0.1]}, "known": 5}, "'known' must map"),
                           ({"observed": {"speed_ratio": [0.3, 0.1]}, "known": {"attitude": {"a": 1}}},
                            "a name or a list"),
                           ({"observed": {"speed_ratio": [0.3, float("nan")]}}, "finite"),
                           ("observed", "a mapping")):
            with self.assertRaises(infer.InferError) as c:
                infer.parse_query(doc)
            self.assertIn(words, str(c.exception))

    def test_hostile_values_get_an_answer_or_a_message(self):
        # Every key of the query with hostile values: an answer, or InferError with a message; never
        # another exception.
        hostile = [None, "", "x" * 10000, -1, 0, 1e308, -1e308, float("nan"), float("inf"), True, [], [1], [1, 2, 3],
                   {}, {"value": 1}, {"value": 0.3, "sigma": 0.1}, ["a", "b"], [[0.3], [0.1]], "0:60", "BCF,FCF"]
        keys = [("observed", o) for o in infer.OUTPUTS] + [("known", k) for k in infer.KNOWN_KEYS] + \
            [(None, "alpha"), (None, "next_runs")]
        numbers = [0.0, -0.0, 1e-300, -1e-300, 1e-9, 1e6, -1e6, 1e7, 1e308, -1e308, float("nan"), float("inf")]
        cases = [(sec, key, v) for sec, key in keys for v in hostile] + \
            [("observed", "speed_ratio", [x, y]) for x in numbers for y in numbers] + \
            [("known", k, [x, y]) for k in ("speed", "angle_deg", "gravity", "depth") for x in numbers for y in numbers]
        for section, key, v in cases:
            doc = {"observed": {"speed_ratio": [0.3, 0.05]}}
            if section:
                doc.setdefault(section, {})[key] = v
            else:
                doc[key] = v
            try:
                ans = infer.infer(infer.parse_query(doc), self.runs)
            except infer.InferError as e:
                self.assertTrue(str(e), (section, key, v))
                continue
            self.assertIn("hypotheses", ans, (section, key, v))
            for e in ans["hypotheses"]:
                if e["covered"]:
                    self.assertTrue(math.isfinite(e["log_likelihood"]), (section, key, v))
                    self.assertTrue(0 <= e["posterior"] <= 1, (section, key, v))
            json.dumps(ans, allow_nan=False)  # the answer is plain JSON: no NaN or infinity

    def test_records_that_are_not_runs_are_skipped(self):
        # A record that is not a landing's, or whose numbers are not finite, is skipped with the reason;
        # an outcome that is not a number counts as missing for that output only.
        camp = tempfile.mkdtemp(prefix="infer_bad_", dir=self.dir)
        folder = os.path.join(camp, "g", "runs")
        mu = truth("gravel", "BCF", 30)
        for rep in range(3):
            record(folder, "gravel", "BCF", 30, rep, mu)
        with open(os.path.join(folder, "junk.json"), "w") as f:
            f.write("[1, 2")
        path = os.path.join(folder, "gravel_d30_BCF_a30_r1.json")
        with open(path) as f:
            rec = json.load(f)
        rec["summary"]["input"]["speed"] = float("inf")
        with open(path, "w") as f:
            json.dump(rec, f)
        path = os.path.join(folder, "gravel_d30_BCF_a30_r2.json")
        with open(path) as f:
            rec = json.load(f)
        rec["summary"]["outcome"]["travel_distance"] = "far"
        with open(path, "w") as f:
            json.dump(rec, f)
        runs, skipped = infer.load_runs([camp])
        self.assertEqual(sorted(os.path.basename(f) for f, _ in skipped),
                         ["gravel_d30_BCF_a30_r1.json", "junk.json"])
        self.assertEqual(len(runs), 2)
        ans = infer.infer(infer.parse_query({"observed": {"speed_ratio": [mu["speed_ratio"], 0.05],
                                                          "travel_distance": [mu["travel_distance"], 1]}}), runs)
        self.assertEqual(ans["runs_used"], 1)  # the run without a travel distance is left out of this query

    def test_cli_answers_and_runs_the_next_run(self):
        camp = tempfile.mkdtemp(prefix="infer_cli_", dir=self.dir)
        for mat, att in (("gravel", "BCF"), ("moderate", "BCF")):
            for rep in range(2):
                record(os.path.join(camp, "g", "runs"), mat, att, 30, rep, truth(mat, att, 30))
        out = os.path.join(camp, "answer")
        base = [sys.executable, CLI, "--campaigns", camp, "--out", out, "--observe", "speed_ratio=0.45+-0.3",
                "--known", "angle_deg=30"]
        p = subprocess.run(base + ["--next", "1"], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(os.path.join(out, "answer.json")) as f:
            ans = json.load(f)
        self.assertEqual(len(ans["next_runs"]), 1)
        self.assertTrue(os.path.getsize(os.path.join(out, "answer.png")) > 1000)
        # --run 1 with a stand-in regolith_land: the proposed point's next repeat is run and recorded.
        fake_bin = os.path.join(camp, "bin")
        os.makedirs(fake_bin)
        os.symlink(FAKE, os.path.join(fake_bin, "regolith_land"))
        p = subprocess.run(base + ["--run", "1", "--bin", fake_bin], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        nxt = ans["next_runs"][0]
        self.assertTrue(os.path.exists(os.path.join(camp, "g", "runs", f"{nxt['material']}_d30_BCF_a30_r2.json")))
        with open(os.path.join(out, "answer.json")) as f:
            self.assertEqual(json.load(f)["runs_used"], 5)
        p = subprocess.run([sys.executable, CLI, "--campaigns", camp, "--observe", "speed_ratio=0.3+-0"],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 2)
        self.assertIn("sigma must be > 0", p.stderr)


if __name__ == "__main__":
    unittest.main()
