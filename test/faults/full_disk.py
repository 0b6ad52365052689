#!/usr/bin/env python3
"""A run whose outputs outgrow the disk (docs/files.md, outputs;
docs/validation/reliability.md): the file size limit (RLIMIT_FSIZE, as
`ulimit -f`; no privileges needed) stands for a full disk. regolith_sim must
stop with exit 2 and an error naming the file and the reason (not be killed
by SIGXFSZ), and leave no corrupt file: the series keeps its header and
complete rows, a checkpoint keeps its previous version, no temporary file is
left and no summary of an earlier run stays beside the new series.

  test/faults/full_disk.py [--bin build/devel/lib/regolith_twin]
"""
import argparse
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
TINY = os.path.join(ROOT, "test", "ros", "tiny_box.yaml")
BIN = os.path.join(ROOT, "build", "devel", "lib", "regolith_twin")


def read(path):
    with open(path, "rb") as f:
        return f.read()


class FullDisk(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="full_disk_")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def sim(self, out, duration, limit=None, extra=()):
        cmd = [os.path.join(BIN, "regolith_sim"), TINY, "--out", out, "--quiet", "--threads", "1",
               "--set", f"stages.0.duration={duration}", "--checkpoint", os.path.join(out, "final.ckpt"), *extra]

        def fsize():
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))

        return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, preexec_fn=fsize if limit else None)

    def no_temp_files(self, d):
        left = [n for n in os.listdir(d) if ".tmp." in n]
        self.assertEqual(left, [], f"temporary files left in {d}")

    def test_series_outgrows_the_disk(self):
        ref = os.path.join(self.dir, "ref")
        p = self.sim(ref, 0.3)
        self.assertEqual(p.returncode, 0, p.stderr)
        series = read(os.path.join(ref, "series.csv"))
        out = os.path.join(self.dir, "out")
        shutil.copytree(ref, out)  # an earlier finished run in the folder
        limit = len(series) // 2
        p = self.sim(out, 0.3, limit)
        self.assertNotEqual(p.returncode, -signal.SIGXFSZ, "killed by SIGXFSZ instead of reporting the error")
        self.assertEqual(p.returncode, 2, p.stderr)
        path = os.path.join(out, "series.csv")
        self.assertIn(f"{path}: could not write output file (File too large)", p.stderr)
        got = read(path)
        self.assertTrue(0 < len(got) <= limit, len(got))
        self.assertTrue(got.endswith(b"\n") and series.startswith(got),
                        "the series is not the header and complete rows of the run")
        self.assertFalse(os.path.exists(os.path.join(out, "summary.json")), "an earlier run's summary is left")
        self.assertEqual(read(os.path.join(out, "final.ckpt")), read(os.path.join(ref, "final.ckpt")))
        self.no_temp_files(out)

    def test_checkpoint_outgrows_the_disk(self):
        sparse = ["--set", "output.every=0.1"]  # a short series: the checkpoint is the largest file
        out = os.path.join(self.dir, "out")
        p = self.sim(out, 0.1, extra=sparse)  # the previous checkpoint
        self.assertEqual(p.returncode, 0, p.stderr)
        before = read(os.path.join(out, "final.ckpt"))
        ref = os.path.join(self.dir, "ref")
        p = self.sim(ref, 0.3, extra=sparse)
        self.assertEqual(p.returncode, 0, p.stderr)
        sizes = {n: os.path.getsize(os.path.join(ref, n)) for n in os.listdir(ref) if not n.startswith(".")}
        ckpt = sizes.pop("final.ckpt")
        self.assertGreater(ckpt, max(sizes.values()) + 64, sizes)
        p = self.sim(out, 0.3, (ckpt + max(sizes.values())) // 2, extra=sparse)
        self.assertNotEqual(p.returncode, -signal.SIGXFSZ, "killed by SIGXFSZ instead of reporting the error")
        self.assertEqual(p.returncode, 2, p.stderr)
        path = os.path.join(out, "final.ckpt")
        self.assertIn(f"{path}: could not write checkpoint (File too large)", p.stderr)
        self.assertEqual(read(path), before, "the previous checkpoint is not intact")
        self.assertNotEqual(before, read(os.path.join(ref, "final.ckpt")))
        self.assertEqual(read(os.path.join(out, "series.csv")), read(os.path.join(ref, "series.csv")))
        self.no_temp_files(out)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=BIN)
    a, rest = ap.parse_known_args()
    BIN = os.path.abspath(a.bin)
    unittest.main(argv=[sys.argv[0]] + rest)
