#!/usr/bin/env python3
"""Record -> replay of a sampler shot: record ~collected_mass and ~particles
while a short shot whose rising grains reach every segment and the top runs, then recompute from the recorded grains alone
the grains and mass in each horn segment (positions against the horn's inner
wall profile, read from the URDF header) and the collected mass (mass that
left the run through the top, as the first cloud's mass minus the last one's,
plus the mass in cylinder 5), and compare them with the last ~collected_mass
message and the node's summary.json."""
import json
import math
import os
import re
import shutil
import unittest

import rosbag
import rospy
import rostest
import sensor_msgs.point_cloud2 as pc2
from recording import record_run

TOPICS = ["/twin_node/collected_mass", "/twin_node/particles", "/twin_node/status"]


def horn_profile(urdf):
    """Inner wall profile [(z, r)] in m and the segments' end planes, from the
    'cylinder_k: (z mm, diameter mm), ...' lines of the URDF header."""
    text = open(urdf).read()
    profile, ends = [], []
    for line in re.findall(r"cylinder_\d: (.*)", text):
        pts = [(float(z) * 1e-3, 0.5 * float(d) * 1e-3) for z, d in re.findall(r"\(([0-9.]+), ([0-9.]+)\)", line)]
        if not pts:
            continue  # prose naming a link
        if not ends:
            ends.append(pts[0][0])
        ends.append(pts[-1][0])
        for p in pts:
            if not profile or abs(profile[-1][0] - p[0]) > 1e-12:
                profile.append(p)
    return profile, ends


def inner_radius(profile, z):
    if z <= profile[0][0]:
        return profile[0][1]
    for (z0, r0), (z1, r1) in zip(profile, profile[1:]):
        if z <= z1:
            return r0 + (z - z0) / (z1 - z0) * (r1 - r0)
    return profile[-1][1]


class SamplerRecordReplay(unittest.TestCase):
    def test_recomputed_collection_equals_summary(self):
        out = rospy.get_param("~out")
        rho = rospy.get_param("~grain_density")
        rp, mp = rospy.get_param("~projectile_radius"), rospy.get_param("~projectile_mass")
        profile, ends = horn_profile(rospy.get_param("~urdf"))
        self.assertEqual(len(ends), 6)
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        bag_path = os.path.join(out, "run.bag")
        summary = os.path.join(out, "summary.json")
        record_run(self, bag_path, TOPICS, TOPICS, summary, "/sampler_record_replay", run_limit=180)
        with open(summary) as f:
            run = json.load(f)
        clouds, last_msg = [], None
        with rosbag.Bag(bag_path) as bag:
            for topic, msg, _ in bag.read_messages(topics=TOPICS[:2]):
                if topic.endswith("particles"):
                    clouds.append(list(pc2.read_points(msg, field_names=("x", "y", "z", "radius"))))
                else:
                    last_msg = msg
        self.assertGreaterEqual(len(clouds), 2, "the recording holds too few particle clouds")
        self.assertIsNotNone(last_msg, "no ~collected_mass message recorded")

        def mass(r):
            return mp if abs(r - rp) < 1e-7 else rho * 4.0 / 3.0 * math.pi * r ** 3

        horn_bottom = run["input"]["horn_bottom"]
        counts, masses = [0] * 5, [0.0] * 5
        for x, y, z, r in clouds[-1]:
            if abs(r - rp) < 1e-7:
                continue  # the projectile is not counted
            a = z - horn_bottom
            if a < ends[0] or a >= ends[5] or math.hypot(x, y) >= inner_radius(profile, a):
                continue
            k = next(k for k in range(5) if a < ends[k + 1])
            counts[k] += 1
            masses[k] += mass(r)
        total_first = sum(mass(p[3]) for p in clouds[0])
        total_last = sum(mass(p[3]) for p in clouds[-1])
        obs = run["observers"]
        self.assertEqual(obs["escaped_mass"], obs["escaped_mass_top"], "grains left other than through the top")
        top_mass = total_first - total_last
        collected = top_mass + masses[4]
        horn = obs["horn"]
        self.assertTrue(all(c > 0 for c in counts), f"the test shot should put grains into every segment: {counts}")
        self.assertGreater(top_mass, 0, "the test shot should lose grains through the top")
        tol = 1e-6 * total_first  # radii travel as float32
        for k in range(5):
            self.assertEqual(counts[k], horn["segment_grains"][k], f"cylinder {k + 1} (summary)")
            self.assertEqual(counts[k], last_msg.segment_counts[k], f"cylinder {k + 1} (~collected_mass)")
            self.assertAlmostEqual(masses[k], horn["segment_mass"][k], delta=tol, msg=f"cylinder {k + 1} mass")
            self.assertAlmostEqual(masses[k], last_msg.segment_masses[k], delta=tol, msg=f"cylinder {k + 1} mass")
        self.assertAlmostEqual(top_mass, horn["collected_top_mass"], delta=tol)
        self.assertAlmostEqual(collected, horn["collected_mass"], delta=tol)
        self.assertAlmostEqual(collected, last_msg.mass, delta=tol)
        self.assertEqual(last_msg.requirement_met, horn["requirement_met"])
        # The node writes the scene's files too: collected.csv lists the grains that left through the top.
        with open(os.path.join(out, "collected.csv")) as f:
            rows = [line for line in f.read().splitlines()[1:] if line.strip()]
        self.assertEqual(len(rows), horn["collected_top_grains"])


if __name__ == "__main__":
    rospy.init_node("sampler_record_replay")
    rostest.rosrun("regolith_twin", "sampler_record_replay", SamplerRecordReplay)
