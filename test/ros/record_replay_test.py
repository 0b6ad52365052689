#!/usr/bin/env python3
"""Record -> replay: record the twin's topics with rosbag while the short plate
landing runs, recompute the outcome from the recorded body states with
regolith_bag_outcome, and compare it with the node's summary.json."""
import json
import os
import shutil
import subprocess
import unittest

import roslib.packages
import rospy
import rostest
from recording import record_run

TOPICS = ["/twin_node/body_states", "/twin_node/landing", "/twin_node/status", "/tf", "/tf_static"]


class RecordReplay(unittest.TestCase):
    def test_replayed_outcome_equals_summary(self):
        out = rospy.get_param("~out")
        scenario = rospy.get_param("~scenario_file")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        bag = os.path.join(out, "run.bag")
        summary = os.path.join(out, "summary.json")
        record_run(self, bag, TOPICS, TOPICS[:3], summary, "/record_replay")
        tool = roslib.packages.find_node("regolith_twin", "regolith_bag_outcome")
        self.assertTrue(tool, "regolith_bag_outcome not built")
        replay = os.path.join(out, "replay.json")
        r = subprocess.run([tool[0], bag, scenario, "--out", replay], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(summary) as f:
            run = json.load(f)
        with open(replay) as f:
            rep = json.load(f)
        dt = run["run"]["dt"]
        self.assertGreaterEqual(rep["messages"], run["run"]["steps"], "the recording misses steps of the landing")
        a, b = run["outcome"], rep["outcome"]
        self.assertTrue(a["contact"] and a["lifted_off"], "the test landing must touch down and lift off")
        for key in ("contact", "lifted_off", "ended_by"):
            self.assertEqual(a[key], b[key], key)
        for key in ("lifted_off", "cancelled_liftoffs"):
            self.assertEqual(a["clear_liftoff"][key], b["clear_liftoff"][key], "clear_liftoff." + key)
        # Times travel as ROS stamps (1 ns); the rest through the pose and twist messages.
        for key in ("t_contact", "t_liftoff", "collision_duration"):
            self.assertAlmostEqual(a[key], b[key], delta=2e-9, msg=key)
        # The run end is a comparison with a time sum (lift-off + 1 s): on 1 ns
        # stamps it may fall one step apart.
        self.assertAlmostEqual(a["t_end"], b["t_end"], delta=1.01 * dt, msg="t_end")
        for key in ("v_in", "v_out", "speed_ratio", "E_lin_in", "E_lin_out", "E_rot_out", "energy_ratio",
                    "angle_out_deg", "spin_out", "max_penetration", "h_liftoff", "travel_distance",
                    "travel_time", "second_impact_speed", "second_impact_angle_deg"):
            self.assertAlmostEqual(a[key], b[key], delta=1e-9 * max(1.0, abs(a[key])), msg=key)
        for key in ("t_liftoff", "collision_duration"):
            self.assertAlmostEqual(a["clear_liftoff"][key], b["clear_liftoff"][key], delta=2e-9, msg=key)
        for key in ("v_out", "speed_ratio", "travel_distance"):
            self.assertAlmostEqual(a["clear_liftoff"][key], b["clear_liftoff"][key],
                                   delta=1e-9 * max(1.0, abs(a["clear_liftoff"][key])), msg="clear_liftoff." + key)


if __name__ == "__main__":
    rospy.init_node("record_replay")
    rostest.rosrun("regolith_twin", "record_replay", RecordReplay)
