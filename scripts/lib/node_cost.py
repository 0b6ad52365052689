#!/usr/bin/env python3
"""Publishing cost of the ROS node (docs/benchmarks.md, "ROS node cost").

usage: node_cost.py BIN_DIR OUT.md [--scenario FILE] [--after-contact S] [--repeats N]

Runs the same landing steps three ways on one thread, interleaved, N times:
  cli        regolith_land (headless): steps and wall seconds of its summary
  node       twin_node, started paused, driven by one ~step call of the same
             number of steps, nobody subscribed to the visual topics
  node+pc    the same with a subscriber on ~particles at the default rate
All three take bit-identical steps from the same placed lander. Writes a
markdown table (median steps/s, ratio to the CLI) to OUT.md.
"""
import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin")
    ap.add_argument("out")
    ap.add_argument("--scenario", default=os.path.join(ROOT, "config", "mascot_landing.yaml"))
    ap.add_argument("--after-contact", type=float, default=0.2)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()

    port = 11000 + os.getpid() % 1000
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
    os.environ.update(env)
    core = subprocess.Popen(["roscore", "-p", str(port)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    import rospy  # after ROS_MASTER_URI is set
    from sensor_msgs.msg import PointCloud2
    from regolith_twin.srv import Step
    from std_srvs.srv import Trigger

    sets = ["landing.max_after_contact=%g" % a.after_contact]
    results = {"cli": [], "node": [], "node+pc": []}
    tmp = tempfile.mkdtemp(prefix="regolith_node_cost_")
    try:
        time.sleep(3)
        rospy.init_node("node_cost", anonymous=True)
        received = [0]

        def on_cloud(_):
            received[0] += 1

        for rep in range(a.repeats):
            # 1. Headless.
            out = os.path.join(tmp, "cli%d" % rep)
            cmd = [os.path.join(a.bin, "regolith_land"), a.scenario, "--out", out, "--threads", "1", "--quiet"]
            for s in sets:
                cmd += ["--set", s]
            subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
            with open(os.path.join(out, "summary.json")) as f:
                run = json.load(f)["run"]
            steps = int(run["steps"])
            results["cli"].append(steps / run["wall_seconds"])
            # 2./3. The node, without and with a particles subscriber.
            for label in ("node", "node+pc"):
                ns = "/cost_%s_%d" % (label.replace("+", "_"), rep)
                rospy.set_param(ns + "/twin_node/set", sets)  # a list: the command line takes scalars only
                args = [os.path.join(a.bin, "twin_node"), "__ns:=" + ns, "_scenario_file:=" + a.scenario,
                        "_start_paused:=true", "_threads:=1"]
                node = subprocess.Popen(args, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                try:
                    deadline = time.time() + 300
                    while True:
                        if node.poll() is not None:
                            sys.exit("node_cost: twin_node exited with code %d" % node.returncode)
                        try:
                            rospy.wait_for_service(ns + "/twin_node/step", timeout=1)
                            break
                        except rospy.ROSException:
                            if time.time() > deadline:
                                sys.exit("node_cost: twin_node did not come up")
                    sub = None
                    if label == "node+pc":
                        received[0] = 0
                        sub = rospy.Subscriber(ns + "/twin_node/particles", PointCloud2, on_cloud, queue_size=1)
                        time.sleep(2)
                    t0 = time.time()
                    r = rospy.ServiceProxy(ns + "/twin_node/step", Step)(steps)
                    wall = time.time() - t0
                    if not r.success:
                        sys.exit("node_cost: step failed: " + r.message)
                    results[label].append(steps / wall)
                    if sub is not None:
                        sub.unregister()
                        if received[0] == 0:
                            sys.exit("node_cost: no particles message arrived")
                finally:
                    node.send_signal(signal.SIGINT)
                    node.wait(timeout=60)
            print("repeat %d: %d steps; cli %.1f, node %.1f, node+particles %.1f steps/s" %
                  (rep, steps, results["cli"][-1], results["node"][-1], results["node+pc"][-1]), flush=True)
    finally:
        core.send_signal(signal.SIGINT)
        core.wait(timeout=60)
    cli = statistics.median(results["cli"])
    lines = ["| run | steps/s (median of %d) | vs. headless CLI |" % a.repeats, "|---|---|---|"]
    for label, name in (("cli", "regolith_land (headless)"), ("node", "twin_node, no visual subscriber"),
                        ("node+pc", "twin_node, ~particles subscribed (5 Hz)")):
        m = statistics.median(results[label])
        lines.append("| %s | %.1f | %+.1f %% |" % (name, m, 100 * (m / cli - 1)))
    lines.append("")
    lines.append("Each repeat (steps/s, in the order run): " + "; ".join(
        "cli %.1f, node %.1f, node+particles %.1f" % (c, n, p)
        for c, n, p in zip(results["cli"], results["node"], results["node+pc"])) +
        ". The spread between repeats of one configuration is the machine's noise.")
    lines.append("")
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip() or "unknown"
    lines.append("Measured on %s at commit %s." % (time.strftime("%Y-%m-%d", time.gmtime()), commit))
    lines.append("")
    lines.append("Scene: %s, first %g s after contact (%d steps, one thread); body states published every step." %
                 (os.path.relpath(a.scenario, ROOT), a.after_contact, steps))
    with open(a.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
