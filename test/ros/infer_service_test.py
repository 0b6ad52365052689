#!/usr/bin/env python3
"""The ~infer service of infer.launch (docs/infer.md) on the committed campaigns: a query is answered
with the ranking in plain fields and the whole answer as JSON; an observation outside every ensemble
is explained by none; a bad query is refused with a message naming what is wrong, and the node
answers the next one."""
import json
import math
import unittest

import rospy
import rostest
from regolith_twin.srv import Infer

SERVICE = "/infer_node/infer"


class InferService(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("infer_service_test", anonymous=True)
        rospy.wait_for_service(SERVICE, timeout=60)
        cls.call = rospy.ServiceProxy(SERVICE, Infer)

    def test_answer(self):
        r = self.call(query="observed: {speed_ratio: [0.3, 0.05], angle_out_deg: [80, 15]}\n"
                            "known: {speed: [0.15, 0.23], angle_deg: [0, 60]}\n")
        self.assertTrue(r.success, r.message)
        self.assertGreater(len(r.hypotheses), 0)
        self.assertEqual(len(r.hypotheses), len(r.posterior))
        self.assertEqual(len(r.hypotheses), len(r.consistent))
        covered = [p for p in r.posterior if not math.isnan(p)]
        self.assertAlmostEqual(sum(covered), 1.0, places=9)
        ans = json.loads(r.answer_json)
        self.assertEqual([e["label"] for e in ans["hypotheses"]], list(r.hypotheses))
        self.assertGreater(ans["runs_used"], 0)
        self.assertEqual(r.explained_by_none, not any(r.consistent))

    def test_outside_every_ensemble(self):
        r = self.call(query="observed: {speed_ratio: [0.97, 0.005]}")
        self.assertTrue(r.success, r.message)
        self.assertTrue(r.explained_by_none)
        self.assertIn("explained by none", r.message)

    def test_bad_query_then_a_good_one(self):
        for q, words in (("observed: {bounce: [0.3, 0.1]}", "unknown output"), ("observed: [", "not YAML"),
                         ("", "observed"), ("observed: {speed_ratio: [0.3, -1]}", "sigma")):
            r = self.call(query=q)
            self.assertFalse(r.success, q)
            self.assertIn(words, r.message, q)
        self.assertTrue(self.call(query="observed: {speed_ratio: [0.3, 0.05]}").success)


if __name__ == "__main__":
    rostest.rosrun("regolith_twin", "infer_service", InferService)
