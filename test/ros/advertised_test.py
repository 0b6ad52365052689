#!/usr/bin/env python3
"""Every topic and service of ~topics / ~services ({name, type}) is advertised
with its type within ~timeout seconds of wall time. (Debian's rostest
advertisetest fails at once under /use_sim_time before the first /clock
message: its set-up reads an undefined variable.)"""
import time
import unittest

import rospy
import rosservice
import rostest


class Advertised(unittest.TestCase):
    def wait_for(self, wanted, listed, what):
        deadline = time.time() + rospy.get_param("~timeout", 30.0)
        missing = dict(wanted)
        while missing and time.time() < deadline:
            for name, typ in listed():
                if name in missing:
                    self.assertEqual(typ, missing[name], "%s %s has type %s" % (what, name, typ))
                    del missing[name]
            time.sleep(0.1)
        self.assertFalse(missing, "%s not advertised: %s" % (what, sorted(missing)))

    def test_topics(self):
        wanted = {t["name"]: t["type"] for t in rospy.get_param("~topics")}
        self.wait_for(wanted, rospy.get_published_topics, "topic")

    def test_services(self):
        wanted = {s["name"]: s["type"] for s in rospy.get_param("~services")}

        def listed():
            out = []
            for name in rosservice.get_service_list():
                try:
                    out.append((name, rosservice.get_service_type(name)))
                except rosservice.ROSServiceIOException:
                    pass
            return out

        self.wait_for(wanted, listed, "service")


if __name__ == "__main__":
    rospy.init_node("advertised")
    rostest.rosrun("regolith_twin", "advertised", Advertised)
