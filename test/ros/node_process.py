"""The twin_node process seen from a test: its pid (the node's own XML-RPC
API, getPid) and its resident memory (/proc/<pid>/status, VmRSS)."""
import os
from xmlrpc.client import ServerProxy

import rosgraph


def node_uri(caller, node="/twin_node"):
    return rosgraph.Master(caller).lookupNode(node)


def node_pid(caller, node="/twin_node"):
    code, msg, pid = ServerProxy(node_uri(caller, node)).getPid(caller)
    if code != 1:
        raise RuntimeError("getPid of %s: %s" % (node, msg))
    return int(pid)


def rss_kib(pid):
    """Resident set size of process pid in KiB."""
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS for pid %d" % pid)


def alive(pid):
    try:
        os.kill(pid, 0)
    except OSError:
        return False
    with open("/proc/%d/status" % pid) as f:  # a zombie has exited
        return not any(line.startswith("State:") and "Z" in line.split()[1] for line in f)
