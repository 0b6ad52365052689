#!/usr/bin/python3
"""The fits of the laboratory campaigns against exact data (docs/validation/bucket.md,
"Inclined plane"): the force law across impact speeds, the layer's acceleration and base friction,
and mu(I)."""
import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import bucket_campaign  # noqa: E402
import incline_campaign  # noqa: E402


class BucketLawFit(unittest.TestCase):
    def test_exact_law_is_recovered(self):
        f0, k, m, g = 30.0, 20.0, 1.0, 9.81
        vs = [0.1 * i for i in range(1, 11)]
        ps = [0.5 / k * math.log1p(v * v / (f0 / m - g) * k) for v in vs]
        f, kk, rms = bucket_campaign.law_fit(vs, ps)
        self.assertAlmostEqual(f / f0, 1.0, delta=1e-3)
        self.assertAlmostEqual(kk / k, 1.0, delta=1e-3)
        self.assertLess(rms, 1e-5)

    def test_constant_resistance_gives_no_inertial_term(self):
        f0, g = 45.0, 9.81
        vs = [0.1 * i for i in range(1, 11)]
        ps = [v * v / (2 * (f0 - g)) for v in vs]
        f, kk, rms = bucket_campaign.law_fit(vs, ps)
        self.assertAlmostEqual(f / f0, 1.0, delta=1e-3)
        self.assertLess(kk, 0.5)
        self.assertLess(rms, 1e-5)


class InclineFits(unittest.TestCase):
    def test_mu_i_recovered_from_exact_points(self):
        mu1, mu2, i0 = 0.38, 0.64, 0.28
        pts = [(i, mu1 + (mu2 - mu1) / (i0 / i + 1)) for i in (0.01, 0.03, 0.1, 0.3, 1.0)]
        a, b, c, rms = incline_campaign.fit_mu_i(pts)
        self.assertAlmostEqual(a, mu1, delta=1e-8)
        self.assertAlmostEqual(b, mu2, delta=1e-8)
        self.assertAlmostEqual(c / i0, 1.0, delta=1e-7)
        self.assertLess(rms, 1e-9)
        self.assertTrue(incline_campaign.fit_resolved(a, b, c))

    def test_flat_noisy_points_are_not_resolved(self):
        pts = [(0.045, 0.5946), (0.083, 0.6068), (0.137, 0.6003), (0.175, 0.6116)]
        self.assertFalse(incline_campaign.fit_resolved(*incline_campaign.fit_mu_i(pts)[:3]))

    def test_acceleration_and_base_friction(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "series.csv"), "w") as f:
                f.write("t,theta_deg,mean_vx\n")
                for k in range(401):
                    t = 0.01 * k
                    f.write("%.6f,33,%.9f\n" % (t, 0.2 + 0.4 * t))
            v0, v1, a = incline_campaign.acceleration(d)
        self.assertAlmostEqual(a, 0.4, delta=1e-6)
        self.assertAlmostEqual(v0, 1.4, delta=1e-6)
        self.assertAlmostEqual(v1, 1.8, delta=1e-6)
        # A 2 s window (the 8 s series) starts a second earlier on the same line.
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "series.csv"), "w") as f:
                f.write("t,theta_deg,mean_vx\n")
                for k in range(801):
                    t = 0.01 * k
                    f.write("%.6f,31,%.9f\n" % (t, 0.5 + 0.1 * min(t, 7.0)))
            v0, v1, a = incline_campaign.acceleration(d, incline_campaign.window_of("moderate_8s_31"))
        self.assertAlmostEqual(v0, 1.1, delta=1e-6)  # at 6 s (a 1 s window would start at 7 s: 1.2)
        self.assertAlmostEqual(v1, 1.2, delta=1e-6)
        self.assertGreater(a, 0.01)  # the ramp runs on to 7 s inside the window
        self.assertEqual(incline_campaign.window_of("moderate_31"), 1.0)
        # the run itself averages over the window the report reads, and runs the series' duration
        self.assertIn("incline.average=2", incline_campaign.RUNS["moderate_8s_31"][0])
        self.assertIn("incline.duration=8", incline_campaign.RUNS["moderate_8s_31"][0])
        self.assertIn("incline.average=1", incline_campaign.RUNS["moderate_31"][0])
        self.assertIn("incline.duration=4", incline_campaign.RUNS["moderate_31"][0])
        th = math.radians(33)
        o = {"theta_deg": 33}
        self.assertAlmostEqual(incline_campaign.base_friction(o, 0.0), math.tan(th), delta=1e-12)
        # dV/dt = g (sin - mu cos) inverted
        mu = incline_campaign.base_friction(o, 0.4)
        self.assertAlmostEqual(9.81 * (math.sin(th) - mu * math.cos(th)), 0.4, delta=1e-12)

    def test_top_layer_inertial_number(self):
        # A linear profile v = 3 z (1/s) in 1 cm layers under a surface at h = 0.2 m: the top layer's shear
        # is 3 1/s, at the middle of the two highest layers (centres 0.185 and 0.195 m), 1 cm below the surface.
        rows = [((k + 0.5) * 0.01, 3.0 * (k + 0.5) * 0.01) for k in range(25)]
        i = incline_campaign.top_layer_inertial_number(rows, 0.2, 0.6, 30.0, 0.01)
        want = 3.0 * 0.01 / math.sqrt(0.6 * 9.81 * math.cos(math.radians(30)) * 0.01)
        self.assertAlmostEqual(i, want, delta=1e-12 * want)
        # Layers above the surface are left out; one layer is not enough.
        self.assertIsNone(incline_campaign.top_layer_inertial_number(rows[:1], 0.2, 0.6, 30.0, 0.01))


if __name__ == "__main__":
    unittest.main()
