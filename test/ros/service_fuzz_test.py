#!/usr/bin/env python3
"""The node's services against hostile requests, table-driven.

Every service the node advertises under its private namespace is found at
run time (rosservice), and every leaf field of its request is found from the
message class (rospy's slot tables), so a new service or field is covered
without editing this test. Each field gets each hostile value of its type,
once on a request otherwise empty and once on a sensible request; the wire
itself gets malformed requests (a truncated body, an absurd length, a
header of the wrong service).

The oracle, for every case: the call is answered (an error is a message
naming what is wrong), the node lives, and afterwards a paused two-step
advance either succeeds with every published number finite and inside the
state bounds (1e6 m, 1e6 m/s, docs/scenes.md) or stops with a blow-up
diagnostic; a checkpoint load then puts the node back where it was. The
counts are written to ~out/service_fuzz.json."""
import json
import math
import os
import socket
import struct
import time
import unittest

import rosgraph
import rospy
import rosservice
import rostest
from node_process import alive, node_pid
from regolith_twin.msg import BodyStates, Status
from regolith_twin.srv import Checkpoint, Step
from std_srvs.srv import Trigger

NODE = "/twin_node/"
# roscpp's own services, not the node's
ROS_OWN = ("get_loggers", "set_logger_level")
MAX_CALL_S = 15.0
BOUND = 1e6  # m, m/s, rad/s: the state bounds of a loaded or edited state

FLOATS = [0.0, -0.0, -1.0, 1e-300, 1e300, float("nan"), float("inf"), float("-inf")]
INTS = [0, -1, 10 ** 18, 2 ** 63 - 1, -(2 ** 63)]
STRINGS = ["", "x" * 100000, "../../../../etc/passwd", "/dev/full", "/proc/self/mem", "/", ".", "é\n\t",
           "no_such_thing"]
# Fields whose sensible value is not the type's zero, by (service, field path).
SENSIBLE = {
    ("step", "steps"): 1,
    ("save_checkpoint", "path"): "fuzz_case.ckpt",
    ("load_checkpoint", "path"): "fuzz_base.ckpt",
    ("apply_body_wrench", "duration"): 1e-3,
    ("apply_body_wrench", "wrench.force.z"): 1.0,
    ("set_body_state", "pose.orientation.w"): 1.0,
    ("set_body_state", "pose.position.z"): 0.15,
}


def leaves(cls, prefix=""):
    """(path, ROS type) of every leaf field of message class cls."""
    out = []
    for name, typ in zip(cls.__slots__, cls._slot_types):
        path = prefix + name
        sub = getattr(cls(), name)
        if hasattr(sub, "__slots__") and hasattr(sub, "_slot_types"):
            out += leaves(type(sub), path + ".")
        else:
            out.append((path, typ))
    return out


def hostile(typ):
    if typ in ("float32", "float64"):
        return FLOATS
    if typ.startswith("int") or typ.startswith("uint"):
        return INTS if typ == "int64" else [0, -1, 2 ** 31 - 1, -(2 ** 31)]
    if typ == "string":
        return STRINGS
    if typ == "bool":
        return [False, True]
    raise AssertionError("a field of type %s: add its hostile values" % typ)


def set_path(msg, path, value):
    *head, last = path.split(".")
    for h in head:
        msg = getattr(msg, h)
    setattr(msg, last, value)


def number_problems(msg, where=""):
    """Non-finite or out-of-bound numbers anywhere in a message."""
    bad = []
    for name in msg.__slots__:
        v = getattr(msg, name)
        if hasattr(v, "__slots__"):
            bad += number_problems(v, where + name + ".")
        elif isinstance(v, list):
            for k, x in enumerate(v):
                if hasattr(x, "__slots__"):
                    bad += number_problems(x, "%s%s[%d]." % (where, name, k))
        elif isinstance(v, float) and not math.isfinite(v):
            bad.append("%s%s = %r" % (where, name, v))
    return bad


class ServiceFuzz(unittest.TestCase):
    def setUp(self):
        self.out = rospy.get_param("~out")
        self.body = rospy.get_param("~body")
        os.makedirs(self.out, exist_ok=True)
        self.services = {}
        for name in rosservice.get_service_list(namespace=NODE):
            short = name[len(NODE):]
            if short in ROS_OWN:
                continue
            rospy.wait_for_service(name, timeout=60)
            self.services[short] = rosservice.get_service_class_by_name(name)
        self.pid = node_pid("/service_fuzz")
        self.bodies = None
        self.problems = []  # non-finite or out-of-bound numbers in any message received
        rospy.Subscriber(NODE + "body_states", BodyStates, self.on_bodies)
        rospy.Subscriber(NODE + "status", Status, self.on_status)
        self.proxy = {s: rospy.ServiceProxy(NODE + s, c) for s, c in self.services.items()}

    def on_bodies(self, m):
        self.bodies = m
        bad = number_problems(m)
        for b in m.bodies:
            p, v, w = b.pose.position, b.twist.linear, b.twist.angular
            bad += ["%s %s beyond %g" % (b.name, what, BOUND) for what, x in
                    (("position", p), ("velocity", v), ("angular velocity", w))
                    if max(abs(x.x), abs(x.y), abs(x.z)) > BOUND]
        if bad:
            self.problems.append("body_states step %d: %s" % (m.step, "; ".join(bad[:3])))

    def on_status(self, m):
        bad = number_problems(m)
        if bad:
            self.problems.append("status step %d: %s" % (m.step, "; ".join(bad[:3])))

    def call(self, service, req):
        t0 = time.monotonic()
        res = self.proxy[service].call(req)
        return res, time.monotonic() - t0

    def sensible(self, service):
        req = self.services[service]._request_class()
        for path, typ in leaves(type(req)):
            if (service, path) in SENSIBLE:
                set_path(req, path, SENSIBLE[(service, path)])
            elif path == "body" or path.endswith(".body"):
                set_path(req, path, self.body)
        return req

    def after(self, case, log):
        """Pause, two steps, the published numbers, then back to the base state."""
        self.proxy["pause"].call(Trigger._request_class())
        self.bodies = None
        res, _ = self.call("step", Step._request_class(steps=2))
        if res.success:
            deadline = time.monotonic() + 5
            while (self.bodies is None or self.bodies.step < 2) and time.monotonic() < deadline:
                time.sleep(0.01)
            self.assertIsNotNone(self.bodies, "%s: no body_states after two steps" % case)
            self.assertTrue(math.isfinite(res.sim_time), case)
            log["stepped"] += 1
        else:
            self.assertIn("blow-up", res.message, "%s: the step after it failed: %s" % (case, res.message))
            log["stopped"].append("%s: %s" % (case, res.message[:200]))
        back, _ = self.call("load_checkpoint", Checkpoint._request_class(path="fuzz_base.ckpt"))
        self.assertTrue(back.success, "%s: the base state does not load again: %s" % (case, back.message))
        self.assertTrue(alive(self.pid), "%s: the node died" % case)
        self.assertEqual(self.problems, [], "%s: published numbers" % case)

    def wire(self, service, body, header_service=None, length=None):
        """A raw TCPROS request: header, then a length prefix and body bytes.
        The node must drop or answer it, and go on."""
        host, port = rosservice.get_service_uri(NODE + service)[len("rosrpc://"):].rsplit(":", 1)
        fields = {"callerid": "/service_fuzz", "service": NODE + (header_service or service),
                  "md5sum": self.services[service]._md5sum, "persistent": "0"}
        hdr = b"".join(struct.pack("<I", len(f)) + f for f in (("%s=%s" % kv).encode() for kv in fields.items()))
        with socket.create_connection((host, int(port)), timeout=MAX_CALL_S) as s:
            s.sendall(struct.pack("<I", len(hdr)) + hdr)
            try:
                s.recv(4096)
                s.sendall(struct.pack("<I", len(body) if length is None else length) + body)
                s.recv(4096)
            except OSError:
                pass  # the node closed the connection: a dropped request is an answer

    def test_every_field_of_every_service(self):
        log = {"services": sorted(self.services), "fields": 0, "cases": 0, "refused": 0, "accepted": 0,
               "stepped": 0, "stopped": [], "wire": 0, "slowest_s": 0.0}
        self.assertIn("step", self.services)
        self.assertIn("load_checkpoint", self.services)
        self.proxy["pause"].call(Trigger._request_class())
        base, _ = self.call("save_checkpoint", Checkpoint._request_class(path="fuzz_base.ckpt"))
        self.assertTrue(base.success, base.message)
        t0 = time.monotonic()
        for service in sorted(self.services):
            req_class = self.services[service]._request_class
            fields = leaves(req_class)
            if not fields:  # a trigger: one call
                res, dt = self.call(service, req_class())
                log["cases"] += 1
                self.after(service, log)
                continue
            for path, typ in fields:
                log["fields"] += 1
                for start in ("empty", "sensible"):
                    for value in hostile(typ):
                        req = req_class() if start == "empty" else self.sensible(service)
                        set_path(req, path, value)
                        case = "%s %s=%r (%s request)" % (service, path, value if len(repr(value)) < 40 else
                                                           repr(value)[:30] + "...", start)
                        res, dt = self.call(service, req)
                        log["cases"] += 1
                        log["slowest_s"] = max(log["slowest_s"], dt)
                        self.assertLess(dt, MAX_CALL_S, case)
                        if hasattr(res, "success"):
                            if res.success:
                                log["accepted"] += 1
                            else:
                                log["refused"] += 1
                                self.assertTrue(res.message.strip(), "%s: refused without a message" % case)
                        self.after(case, log)
        # The wire: a truncated request, an empty one, one that announces 2 GB
        # and stops, and a header naming another service.
        for service in sorted(self.services):
            for body, length, other in ((b"\x01\x02", None, None), (b"", None, None), (b"", 2 ** 31 - 1, None),
                                        (b"\x00" * 16, None, "no_such_service")):
                self.wire(service, body, other, length)
                log["wire"] += 1
                self.assertTrue(alive(self.pid), "the node died on a malformed %s request" % service)
            self.after("wire " + service, log)
        log["seconds"] = round(time.monotonic() - t0, 1)
        log["slowest_s"] = round(log["slowest_s"], 3)
        with open(os.path.join(self.out, "service_fuzz.json"), "w") as f:
            json.dump(log, f, indent=1)
        print("service fuzz: %d services, %d fields, %d cases (%d refused, %d accepted), %d wire requests, "
              "%d stopped on a blow-up, %.1f s" % (len(self.services), log["fields"], log["cases"], log["refused"],
                                                   log["accepted"], log["wire"], len(log["stopped"]),
                                                   log["seconds"]))


if __name__ == "__main__":
    rospy.init_node("service_fuzz")
    rostest.rosrun("regolith_twin", "service_fuzz", ServiceFuzz)
