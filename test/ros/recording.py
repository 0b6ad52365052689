"""Recording a paused twin_node run with rosbag (shared by the record/replay rostests)."""
import os
import signal
import subprocess
import time
from xmlrpc.client import ServerProxy

import rosgraph
import rospy
from std_srvs.srv import Trigger


def connected(topic, caller):
    """The node itself has a live outbound connection on topic (not just a
    subscriber registered with the master)."""
    try:
        uri = rosgraph.Master(caller).lookupNode("/twin_node")
        code, _, info = ServerProxy(uri).getBusInfo(caller)
    except Exception:
        return False
    return code == 1 and any(c[2] == "o" and c[4] == topic and c[5] for c in info)


def record_run(test, bag, topics, wait_topics, summary, caller, run_limit=60):
    """Record `topics` into `bag` while the paused node runs to its end: start
    the recorder, wait until the node serves it on `wait_topics` and the bag
    is open, unpause, wait for `summary` (written at the run end), stop the
    recorder. Failures go to the unittest case `test`."""
    rospy.wait_for_service("/twin_node/unpause", timeout=60)
    # Own process group: the rosbag wrapper and its recorder both get the SIGINT.
    rec = subprocess.Popen(["rosbag", "record", "--quiet", "-O", bag] + topics, start_new_session=True)
    try:
        deadline = time.time() + 30
        while not all(connected(t, caller) for t in wait_topics):
            test.assertLess(time.time(), deadline, "rosbag did not connect")
            time.sleep(0.1)
        # The recorder opens its bag on the first message (the paused
        # node's status): unpause only once it is writing.
        while not os.path.exists(bag + ".active"):
            test.assertLess(time.time(), deadline, "rosbag did not open the bag")
            time.sleep(0.1)
        time.sleep(1.0)
        test.assertTrue(rospy.ServiceProxy("/twin_node/unpause", Trigger)().success)
        deadline = time.time() + run_limit
        while not os.path.exists(summary):
            test.assertLess(time.time(), deadline, "the run did not end")
            time.sleep(0.2)
        time.sleep(1.0)  # the last messages reach the recorder
    finally:
        os.killpg(rec.pid, signal.SIGINT)
        rec.wait(timeout=30)
    deadline = time.time() + 30
    while not os.path.exists(bag) and time.time() < deadline:  # the recorder closes the bag
        time.sleep(0.2)
    test.assertTrue(os.path.exists(bag), "no bag written")
