#!/usr/bin/env python3
"""scripts/sweep --slurm on a one-node Slurm cluster that this test starts
and stops itself (Debian's slurm-wlm as root: no authentication, state and
spool in a temporary folder, non-default ports, SLURM_CONF exported), with
the stand-in for regolith_land (test/sweep/fake_land.py). One run's task is
killed (SIGKILL) half-way: the sweep resubmits it and every run finishes;
a second sweep submits nothing.

  /usr/bin/python3 test/sweep/test_slurm.py     (as root, slurm-wlm installed)
"""
import csv
import os
import shutil
import socket
import subprocess
import sys
import time
import unittest

from test_sweep import make_sweep_folder, remove_sweep_folder  # (this folder is on the path)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
SWEEP = os.path.join(ROOT, "scripts", "lib", "sweep.py")
FAKE = os.path.join(HERE, "fake_land.py")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class OneNodeCluster:
    def __init__(self, folder):
        self.dir = folder
        for d in ("state", "spool"):
            os.makedirs(os.path.join(folder, d))
        host = socket.gethostname().split(".")[0]
        ctld, slurmd = free_port(), free_port()
        self.conf = os.path.join(folder, "slurm.conf")
        with open(self.conf, "w") as f:
            f.write(f"""ClusterName=regolith_test
SlurmctldHost={host}(127.0.0.1)
AuthType=auth/none
CredType=cred/none
SlurmUser=root
SlurmdUser=root
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
StateSaveLocation={folder}/state
SlurmdSpoolDir={folder}/spool
SlurmctldPidFile={folder}/slurmctld.pid
SlurmdPidFile={folder}/slurmd.pid
SlurmctldPort={ctld}
SlurmdPort={slurmd}
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmctldLogFile={folder}/slurmctld.log
SlurmdLogFile={folder}/slurmd.log
NodeName={host} NodeAddr=127.0.0.1 CPUs={os.cpu_count() or 2} State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
""")
        self.env = dict(os.environ, SLURM_CONF=self.conf)

    def start(self):
        subprocess.run(["slurmctld", "-f", self.conf, "-i"], env=self.env, check=True)
        subprocess.run(["slurmd", "-f", self.conf], env=self.env, check=True)
        for _ in range(100):
            s = subprocess.run(["sinfo", "-h", "-o", "%t"], env=self.env, capture_output=True, text=True)
            if s.stdout.strip() == "idle":
                return
            time.sleep(0.2)
        raise RuntimeError("the test cluster did not come up: " + open(os.path.join(self.dir, "slurmctld.log")).read()[-2000:])

    def stop(self):
        for pid_file in ("slurmd.pid", "slurmctld.pid"):
            try:
                with open(os.path.join(self.dir, pid_file)) as f:
                    os.kill(int(f.read().strip()), 15)
            except (OSError, ValueError):
                pass
        time.sleep(0.5)


def cgroup_mounted():
    """slurmd 22.05 starts its cgroup plugin whatever the task and proctrack
    plugins: it needs a cgroup file system on /sys/fs/cgroup (any machine
    booted with systemd has one; in a bare chroot the folder is empty)."""
    try:
        return len(os.listdir("/sys/fs/cgroup")) > 0
    except OSError:
        return False


@unittest.skipUnless(os.geteuid() == 0 and shutil.which("slurmctld") and shutil.which("sbatch"),
                     "needs root and slurm-wlm (scripts/test installs it)")
@unittest.skipUnless(cgroup_mounted(), "slurmd needs a cgroup file system on /sys/fs/cgroup (none is mounted here)")
class SlurmSweepTest(unittest.TestCase):
    def setUp(self):
        make_sweep_folder(self, "slurm_test_")
        self.cluster = OneNodeCluster(os.path.join(self.dir, "cluster"))
        self.cluster.start()

    def tearDown(self):
        self.cluster.stop()
        remove_sweep_folder(self)

    def sweep(self, env):
        cmd = [sys.executable, SWEEP, "--land", FAKE, "--bed-dir", self.beds, "--out", self.out,
               "--materials", "moderate,gravel", "--angles", "0,30,60", "--threads", "1", "--slurm",
               "--slurm-poll", "0.5", "--no-run-plots", "--record", os.path.join(self.dir, "record")]
        return subprocess.run(cmd, capture_output=True, text=True, env=dict(self.cluster.env, **env), timeout=300)

    def test_array_with_a_killed_task(self):
        marker = os.path.join(self.dir, "killed_once")
        p = self.sweep({"FAKE_LAND_DIE_ONCE": f"moderate_d30_BCF_a30_r0:{marker}", "FAKE_LAND_SLEEP": "0.5"})
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertTrue(os.path.exists(marker), "the task was not killed")
        self.assertIn("6 runs submitted as Slurm job array", p.stdout)
        self.assertIn("1 runs resubmitted (failed before)", p.stdout)
        with open(os.path.join(self.out, "aggregate.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), 6)
        self.assertTrue(all(r["status"] == "ok" for r in rows), rows)
        self.assertEqual(len(os.listdir(os.path.join(self.dir, "record"))), 6)
        # Nothing left to do: nothing is submitted again.
        p = self.sweep({})
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("(6 already done, 0 to run)", p.stdout)
        self.assertNotIn("submitted", p.stdout)


if __name__ == "__main__":
    unittest.main()
