#!/usr/bin/env python3
"""twin_node refuses missing or invalid parameters at start-up: exit code 2
and a message naming the parameter (or the scenario file and key)."""
import os
import subprocess
import unittest

import roslib.packages
import rospy
import rostest


class BadParams(unittest.TestCase):
    runs = 0

    def run_node(self, *args):
        node = roslib.packages.find_node("regolith_twin", "twin_node")
        self.assertTrue(node, "twin_node not built")
        BadParams.runs += 1  # a fresh namespace each time: private parameters stay on the server
        ns = "__ns:=/bad_params_%d_%d" % (os.getpid(), BadParams.runs)
        r = subprocess.run([node[0], ns] + list(args), capture_output=True, text=True, timeout=60)
        return r.returncode, r.stdout + r.stderr

    def test_missing_scenario(self):
        code, text = self.run_node()
        self.assertEqual(code, 2, text)
        self.assertIn("~scenario_file", text)

    def test_out_of_range(self):
        scenario = rospy.get_param("~scenario_file")
        for arg, name in (("_clock_rate:=-5", "~clock_rate"), ("_realtime_factor:=fast", "~realtime_factor"),
                          ("_visual_clock:=gps", "~visual_clock"), ("_threads:=1000", "~threads")):
            code, text = self.run_node("_scenario_file:=" + scenario, arg)
            self.assertEqual(code, 2, arg + ": " + text)
            self.assertIn(name, text, arg)

    def test_bad_scenario_value(self):
        scenario = rospy.get_param("~scenario_file")
        code, text = self.run_node("_scenario_file:=" + scenario, "_set:=contact.steps_per_contact=-3")
        self.assertEqual(code, 2, text)
        self.assertIn("tiny_box.yaml", text)
        self.assertIn("steps_per_contact", text)


if __name__ == "__main__":
    rospy.init_node("bad_params")
    rostest.rosrun("regolith_twin", "bad_params", BadParams)
