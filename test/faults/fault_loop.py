#!/usr/bin/env python3
"""kill -9 at random moments of runs, sweeps and checkpoint saves, and what
must hold afterwards (docs/files.md, outputs; docs/validation/reliability.md):

- every output file is absent, the previous complete version or the new
  complete one: checkpoints, snapshots, surface maps and records byte for
  byte or field for field those of an uninterrupted run; series.csv the
  header and complete rows of that run's series (a run that stops early
  keeps what it wrote); JSON parses; no NUL bytes; PNGs end with their IEND;
- summary.json only beside the whole series of the run it belongs to;
- a second run (or sweep) into a folder in use is refused naming the pid;
- the same command afterwards resumes (a landing from its relaxed-bed
  checkpoint in the cache, a sweep from its finished runs) and ends with
  outputs identical to the uninterrupted run's, wall-clock fields aside.

Kinds: sim (regolith_sim, a small box, with --checkpoint and --snapshot),
land (regolith_land, a short landing whose bed is relaxed and cached first,
half of the time with the cache emptied before), save (either, killed while
one of its files is under its temporary name), sweep (scripts/lib/sweep.py
with the stand-in regolith_land of test/sweep) and stale (the landing killed
in a folder that holds a finished landing of another speed: none of that
run's files may stay beside a file of the new run's, but for the
checkpoint the user named, which keeps its previous version until
replaced). The first uninterrupted run of
each kind is the reference; the landing's is also re-run from its cached bed
with --relaxed-bed (the checkpoint loads, and the run is bit-identical).

  test/faults/fault_loop.py --bin build/devel/lib/regolith_twin               # short: 8 kills
  test/faults/fault_loop.py --bin build/devel/lib/regolith_twin --kills 120   # the full loop
"""
import argparse
import csv
import io
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
SWEEP = os.path.join(ROOT, "scripts", "lib", "sweep.py")
FAKE = os.path.join(ROOT, "test", "sweep", "fake_land.py")
TINY = os.path.join(ROOT, "test", "ros", "tiny_box.yaml")
PLATE = os.path.join(ROOT, "test", "ros", "plate_landing.yaml")
KINDS = ("sim", "land", "save", "sweep", "stale")
# Files at paths the user names (--checkpoint, --snapshot): the previous
# complete version stays until the new one replaces it (docs/files.md), so a
# failed or killed run never costs the user the state it would resume from.
KEPT_UNTIL_REPLACED = ("final.ckpt", "final.bed")
TEMP = re.compile(r"\.tmp\.(\d+)$")
# Fields that differ between two uninterrupted runs: wall-clock time and rates.
VOLATILE_KEYS = re.compile(r"wall|per_second|steps_per_s|^started$|^start$|^end$|^restored_from$")
# Wall-clock columns of the sweep's aggregate.csv and times in its report.
VOLATILE_COLUMNS = ("land_wall_seconds", "wall_seconds")
TIMES = re.compile(r"\b\d+(\.\d+)? (s|min|h)\b")


class Failure(Exception):
    pass


def read(path):
    with open(path, "rb") as f:
        return f.read()


def files_under(d):
    out = {}
    for base, _, names in os.walk(d):
        for n in names:
            p = os.path.join(base, n)
            out[os.path.relpath(p, d)] = p
    return out


def strip_volatile(x):
    if isinstance(x, dict):
        return {k: strip_volatile(v) for k, v in x.items() if not VOLATILE_KEYS.search(k)}
    if isinstance(x, list):
        return [strip_volatile(v) for v in x]
    return x


def parse_json(path, data):
    try:
        return json.loads(data.decode())
    except (ValueError, UnicodeDecodeError) as e:
        raise Failure(f"{path}: not whole JSON ({e})")


def csv_masked(path, data):
    """Rows of a CSV, each complete (as many fields as the header), wall-clock columns blanked."""
    rows = list(csv.reader(io.StringIO(data.decode())))
    if not rows or not data.endswith(b"\n"):
        raise Failure(f"{path}: not a whole CSV file")
    head = rows[0]
    for r in rows[1:]:
        if len(r) != len(head):
            raise Failure(f"{path}: a row of {len(r)} fields under a header of {len(head)}")
    drop = [k for k, c in enumerate(head) if c in VOLATILE_COLUMNS]
    return [[v for k, v in enumerate(r) if k not in drop] for r in rows]


class Checker:
    """Compares a folder after a kill (or at the end of a resumed run) with the reference run's."""

    def __init__(self, stats):
        self.stats = stats

    def same(self, rel, path, data, ref, whole):
        """One file against the reference's: whole or, for a series, a prefix of complete rows."""
        name = os.path.basename(rel)
        if name.endswith((".csv", ".json", ".md", ".txt", ".log")) and b"\0" in data:
            raise Failure(f"{path}: NUL bytes")
        if name == "series.csv" and not whole:
            if not ref.startswith(data) or (data and not data.endswith(b"\n")):
                raise Failure(f"{path}: not the header and complete rows of the run's series "
                              f"({len(data)} bytes of {len(ref)})")
            return
        if name.endswith(".json"):
            if strip_volatile(parse_json(path, data)) != strip_volatile(parse_json(rel, ref)):
                raise Failure(f"{path}: differs from the uninterrupted run's")
        elif name == "aggregate.csv":
            if csv_masked(path, data) != csv_masked(rel, ref):
                raise Failure(f"{path}: differs from the uninterrupted run's")
        elif name == "report.md":
            if TIMES.sub("T", data.decode()) != TIMES.sub("T", ref.decode()):
                raise Failure(f"{path}: differs from the uninterrupted run's")
        elif name.endswith(".png"):
            if not data.startswith(b"\x89PNG") or not data.endswith(b"IEND\xaeB`\x82"):
                raise Failure(f"{path}: not a whole PNG")
        elif data != ref:
            raise Failure(f"{path}: {len(data)} bytes, not the uninterrupted run's {len(ref)}")

    def stale(self, d, ref_dir, other_dir, killed):
        """After a kill in a folder that held another run's outputs: every file
        is the new run's (as in folder) or the other run's, and the other
        run's files are left only while the new run has written nothing
        (a run removes every output it will write before its first step)."""
        got, ref, other = files_under(d), files_under(ref_dir), files_under(other_dir)
        new, old = [], []
        for rel, path in sorted(got.items()):
            if os.path.basename(rel) in (".regolith_twin.lock", *KEPT_UNTIL_REPLACED) or TEMP.search(rel):
                continue
            data = read(path)
            try:
                if rel not in ref:
                    raise Failure(f"{path}: not written by the uninterrupted run")
                self.same(rel, path, data, read(ref[rel]), False)
                is_new = True
            except Failure:
                is_new = False
            is_old = rel in other and data == read(other[rel])
            if not is_new and not is_old:
                raise Failure(f"{path}: neither this run's nor the earlier run's")
            if is_old and not is_new:
                old.append(rel)
            elif is_new and not is_old:
                new.append(rel)
        if old and new:
            raise Failure(f"{d}: the earlier run's {', '.join(old)} beside this run's {', '.join(new)}")
        self.stats["stale_kills_with_new_files" if new else "stale_kills_before_writing"] += 1

    @staticmethod
    def restored(d, rel):
        """A sweep's run taken from its record: summary.json and sweep_run.json only."""
        parts = rel.split("/")
        if len(parts) < 3 or parts[0] != "runs":
            return False
        try:
            with open(os.path.join(d, "runs", parts[1], "sweep_run.json")) as f:
                return "restored_from" in json.load(f)
        except (OSError, ValueError):
            return False

    def folder(self, d, ref_dir, whole, killed=None):
        """Every file of d against ref_dir. whole: everything present and complete
        (after a finished run); else files may be absent and series partial.
        Temporary files of the killed process are counted and removed."""
        got, ref = files_under(d), files_under(ref_dir)
        for rel, path in sorted(got.items()):
            if os.path.basename(rel) == ".regolith_twin.lock":
                continue
            m = TEMP.search(rel)
            if m:
                if whole or killed is None or int(m.group(1)) not in killed:
                    raise Failure(f"{path}: temporary file left by a process that was not killed")
                self.stats["temp_files_left"] += 1
                os.remove(path)
                continue
            if "/." in "/" + rel and rel.split("/")[0] == "runs":  # a sweep's run under way (.name.tmp)
                if whole:
                    raise Failure(f"{path}: a run folder left under its temporary name")
                continue
            if rel not in ref:
                raise Failure(f"{path}: not written by the uninterrupted run")
            self.same(rel, path, read(path), read(ref[rel]), whole)
            self.stats["files_checked"] += 1
        for rel in ref:
            if os.path.basename(rel) == ".regolith_twin.lock":
                continue
            if whole and rel not in got and not self.restored(d, rel):
                raise Failure(f"{os.path.join(d, rel)}: missing after a finished run")
        # A summary belongs to the series beside it (OutputFolder removes an earlier run's).
        for rel, path in got.items():
            if os.path.basename(rel) == "summary.json":
                series = os.path.join(os.path.dirname(path), "series.csv")
                ref_series = os.path.join(ref_dir, os.path.dirname(rel), "series.csv")
                if self.restored(d, rel):
                    continue
                if os.path.exists(ref_series) and (not os.path.exists(series) or read(series) != read(ref_series)):
                    raise Failure(f"{path}: a summary beside a series that is not its run's")


class Loop:
    def __init__(self, a):
        self.a = a
        self.bin = os.path.abspath(a.bin)
        self.work = tempfile.mkdtemp(prefix="fault_loop_")
        self.rng = random.Random(a.seed)
        self.stats = {"kills": 0, "kills_by_kind": {k: 0 for k in KINDS}, "land_killed_relaxing": 0,
                      "land_killed_landing": 0, "save_targets": {}, "second_run_refused": 0,
                      "temp_files_left": 0, "files_checked": 0, "resumed_identical": 0, "finished_before_kill": 0,
                      "save_missed": 0, "stale_kills_with_new_files": 0, "stale_kills_before_writing": 0}
        self.check = Checker(self.stats)
        self.killed = set()
        self.beds = os.path.join(self.work, "beds")
        os.makedirs(self.beds)
        open(os.path.join(self.beds, "mascot_moderate_d30.bed"), "w").close()

    # ---------------------------------------------------------------- commands

    def sim_cmd(self, out):
        return [os.path.join(self.bin, "regolith_sim"), TINY, "--out", out, "--quiet", "--threads", "1",
                "--set", f"stages.0.duration={self.a.sim_duration}", "--checkpoint", os.path.join(out, "final.ckpt"),
                "--snapshot", os.path.join(out, "final.bed")]

    def land_cmd(self, out, cache):
        return [os.path.join(self.bin, "regolith_land"), PLATE, "--out", out, "--cache", cache, "--quiet",
                "--threads", "1", "--set", f"stages.0.duration={self.a.relax_duration}",
                "--checkpoint", os.path.join(out, "final.ckpt")]

    def sweep_cmd(self, out, rec):
        return [sys.executable, SWEEP, "--land", FAKE, "--bed-dir", self.beds, "--out", out, "--materials",
                "moderate", "--angles", "0,30", "--repeats", "2", "--jobs", "2", "--record", rec, "--no-run-plots"]

    def start(self, cmd):
        env = dict(os.environ, FAKE_LAND_SLEEP="0.1", MPLBACKEND="Agg")
        return subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env,
                                start_new_session=True)

    def finish(self, cmd, what):
        p = self.start(cmd)
        _, err = p.communicate(timeout=600)
        if p.returncode != 0:
            raise Failure(f"{what}: exit {p.returncode}: {err.decode()[-2000:]}")

    # ---------------------------------------------------------------- references

    def references(self):
        """The uninterrupted runs, made in the working folders (outputs name their paths) and copied aside."""
        w = self.work
        t0 = time.time()
        self.finish(self.sim_cmd(f"{w}/sim"), "reference sim run")
        self.t_sim = time.time() - t0
        t0 = time.time()
        self.finish(self.land_cmd(f"{w}/land", f"{w}/cache"), "reference landing")
        self.t_land = time.time() - t0
        t0 = time.time()
        self.finish(self.sweep_cmd(f"{w}/sweep", f"{w}/rec"), "reference sweep")
        self.t_sweep = time.time() - t0
        for d in ("sim", "land", "cache", "sweep", "rec"):
            shutil.copytree(f"{w}/{d}", f"{w}/ref_{d}")
        self.ref_cache = f"{w}/ref_cache"
        # A second uninterrupted run over the first agrees with it but for
        # wall-clock fields.
        self.finish(self.sim_cmd(f"{w}/sim"), "second sim run")
        self.check.folder(f"{w}/sim", f"{w}/ref_sim", whole=True)
        t0 = time.time()
        self.finish(self.land_cmd(f"{w}/land", f"{w}/cache"), "second landing (from the cache)")
        self.t_land_cached = time.time() - t0
        self.check.folder(f"{w}/land", f"{w}/ref_land", whole=True)
        # The cached bed and the final checkpoint load through the tool; the
        # landing from the cached bed is the same, bit for bit.
        (cache,) = files_under(self.ref_cache).values()
        other = f"{w}/from_bed"
        self.finish(self.land_cmd(other, f"{w}/unused_cache") + ["--relaxed-bed", cache], "landing from the cached bed")
        for f in ("series.csv", "surface.csv", "final.ckpt"):
            self.check.same(f, f"{other}/{f}", read(f"{other}/{f}"), read(f"{w}/ref_land/{f}"), True)
        self.finish(self.land_cmd(other, f"{w}/unused_cache") + ["--relaxed-bed", f"{w}/ref_land/final.ckpt"],
                    "landing from the final checkpoint")
        # A finished landing of another speed, made in the landing's folder
        # (its outputs name their paths), kept for the stale kind; then the
        # reference landing over it, whole and identical.
        self.finish(self.land_cmd(f"{w}/land", f"{w}/cache_other") + ["--set", "landing.speed=0.4"],
                    "a landing of another speed")
        shutil.copytree(f"{w}/land", f"{w}/other_land")
        self.finish(self.land_cmd(f"{w}/land", f"{w}/cache"), "the landing over another one")
        self.check.folder(f"{w}/land", f"{w}/ref_land", whole=True)
        print(f"references: sim {self.t_sim:.2f} s, landing {self.t_land:.2f} s (bed relaxed and cached; "
              f"{self.t_land_cached:.2f} s from the cache), sweep {self.t_sweep:.2f} s", flush=True)

    # ---------------------------------------------------------------- one kill

    def refused(self, cmd, holder, folder, what):
        """A second run into the folder while holder holds its lock is refused naming holder's pid."""
        lock = os.path.join(folder, ".regolith_twin.lock")
        try:
            with open(lock) as f:
                if f.read().strip() != str(holder.pid) or holder.poll() is not None:
                    return
        except OSError:
            return
        p = self.start(cmd)
        _, err = p.communicate(timeout=120)
        if holder.poll() is not None:
            return  # the first ended meanwhile: nothing to conclude
        if p.returncode != 2 or f"in use by another {what} (pid {holder.pid})" not in err.decode():
            raise Failure(f"a second {what} into {folder} was not refused: exit {p.returncode}: {err.decode()}")
        self.stats["second_run_refused"] += 1

    def kill(self, p):
        """SIGKILL, then wait until the process group (a sweep's children) is gone."""
        try:
            os.kill(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass  # ended (and not yet reaped)
        p.wait()
        for _ in range(500):
            try:
                os.killpg(p.pid, 0)
            except ProcessLookupError:
                break
            time.sleep(0.01)
        else:
            os.killpg(p.pid, signal.SIGKILL)
        self.killed.add(p.pid)
        if p.returncode != -signal.SIGKILL:
            self.stats["finished_before_kill"] += 1
            if self.a.verbose:
                print(f"  (ended before the kill: exit {p.returncode})", flush=True)
            return False
        return True

    def timed_kill(self, cmd, duration, folder, what):
        p = self.start(cmd)
        t0 = time.time()
        # A kill anywhere in the run, rarely at the very start.
        time.sleep(self.rng.uniform(0.02, 0.8) * duration)
        if self.rng.random() < 0.5:
            self.refused(cmd, p, folder, what)
        if self.a.verbose:
            print(f"  kill at {time.time() - t0:.2f} s of about {duration:.2f} s", flush=True)
        return self.kill(p)

    def one(self, kind):
        w = self.work
        if kind == "sim":
            ok = self.timed_kill(self.sim_cmd(f"{w}/sim"), self.t_sim, f"{w}/sim", "run")
            self.check.folder(f"{w}/sim", f"{w}/ref_sim", whole=False, killed=self.killed)
            self.finish(self.sim_cmd(f"{w}/sim"), "sim run after a kill")
            self.check.folder(f"{w}/sim", f"{w}/ref_sim", whole=True)
        elif kind == "land":
            relax = self.rng.random() < 0.5
            if relax:
                shutil.rmtree(f"{w}/cache")
            ok = self.timed_kill(self.land_cmd(f"{w}/land", f"{w}/cache"),
                                 self.t_land if relax else self.t_land_cached, f"{w}/land", "run")
            self.check.folder(f"{w}/land", f"{w}/ref_land", whole=False, killed=self.killed)
            if os.path.isdir(f"{w}/cache"):
                self.check.folder(f"{w}/cache", self.ref_cache, whole=False, killed=self.killed)
            cached = bool([f for f in files_under(f"{w}/cache").values()]) if os.path.isdir(f"{w}/cache") else False
            if ok:
                self.stats["land_killed_landing" if cached else "land_killed_relaxing"] += 1
            self.finish(self.land_cmd(f"{w}/land", f"{w}/cache"), "landing after a kill")
            self.check.folder(f"{w}/land", f"{w}/ref_land", whole=True)
            self.check.folder(f"{w}/cache", self.ref_cache, whole=True)
        elif kind == "save":
            ok = self.save_kill()
        elif kind == "stale":
            shutil.rmtree(f"{w}/land")
            shutil.copytree(f"{w}/other_land", f"{w}/land")
            ok = self.timed_kill(self.land_cmd(f"{w}/land", f"{w}/cache"), self.t_land_cached, f"{w}/land", "run")
            for rel, path in files_under(f"{w}/land").items():  # the killed process's temporary files
                m = TEMP.search(rel)
                if m and int(m.group(1)) in self.killed:
                    os.remove(path)
            self.check.stale(f"{w}/land", f"{w}/ref_land", f"{w}/other_land", self.killed)
            self.finish(self.land_cmd(f"{w}/land", f"{w}/cache"), "landing after a kill over another landing")
            self.check.folder(f"{w}/land", f"{w}/ref_land", whole=True)
        else:
            # Some runs to redo: their folders removed, and half of their records
            # (a recorded run is restored from its record, not run again).
            runs = sorted(os.listdir(f"{w}/sweep/runs"))
            for r in self.rng.sample(runs, self.rng.randint(1, len(runs))):
                shutil.rmtree(f"{w}/sweep/runs/{r}")
                if self.rng.random() < 0.5 and os.path.exists(f"{w}/rec/{r}.json"):
                    os.remove(f"{w}/rec/{r}.json")
            ok = self.timed_kill(self.sweep_cmd(f"{w}/sweep", f"{w}/rec"), self.t_sweep, f"{w}/sweep", "sweep")
            self.check.folder(f"{w}/sweep", f"{w}/ref_sweep", whole=False, killed=self.killed)
            self.check.folder(f"{w}/rec", f"{w}/ref_rec", whole=False, killed=self.killed)
            self.finish(self.sweep_cmd(f"{w}/sweep", f"{w}/rec"), "sweep after a kill")
            self.check.folder(f"{w}/sweep", f"{w}/ref_sweep", whole=True)
            self.check.folder(f"{w}/rec", f"{w}/ref_rec", whole=True)
        self.stats["resumed_identical"] += 1
        return ok

    def save_kill(self):
        """Killed while a chosen file is under its temporary name (being written or about to be renamed)."""
        w = self.work
        land = self.rng.random() < 0.5
        if land:
            if self.rng.random() < 0.5:
                shutil.rmtree(f"{w}/cache")
            cmd, dirs, ref = (self.land_cmd(f"{w}/land", f"{w}/cache"),
                              [f"{w}/land", f"{w}/land/bed_relax", f"{w}/cache/beds"], "land")
            targets = ["final.ckpt", "summary.json", "surface.csv"] + (
                [] if os.path.isdir(f"{w}/cache") else [".ckpt"])
        else:
            cmd, dirs, ref = self.sim_cmd(f"{w}/sim"), [f"{w}/sim"], "sim"
            targets = ["final.ckpt", "final.bed", "summary.json", "final_grains.txt"]
        target = self.rng.choice(targets)
        delay = self.rng.choice([0, 0, 0.0002, 0.001])
        p = self.start(cmd)
        hit = False
        while p.poll() is None and not hit:
            for d in dirs:
                try:
                    names = os.listdir(d)
                except OSError:
                    continue
                if any(n.endswith(f".tmp.{p.pid}") and n[: -len(f".tmp.{p.pid}")].endswith(target) for n in names):
                    hit = True
                    break
        if hit and delay:
            time.sleep(delay)
        ok = self.kill(p)
        key = f"{ref}:{target}"
        if ok and hit:
            self.stats["save_targets"][key] = self.stats["save_targets"].get(key, 0) + 1
        elif not hit:
            self.stats["save_missed"] += 1
        self.check.folder(f"{w}/{ref}", f"{w}/ref_{ref}", whole=False, killed=self.killed)
        if land and os.path.isdir(f"{w}/cache"):
            self.check.folder(f"{w}/cache", self.ref_cache, whole=False, killed=self.killed)
        self.finish(cmd, f"{ref} run after a kill during a save")
        self.check.folder(f"{w}/{ref}", f"{w}/ref_{ref}", whole=True)
        if land:
            self.check.folder(f"{w}/cache", self.ref_cache, whole=True)
        return ok and hit

    def run(self):
        self.references()
        n = 0
        t0 = time.time()
        kinds = self.a.kinds.split(",")
        order = [kinds[k % len(kinds)] for k in range(self.a.kills)]
        attempts = 0
        while self.stats["kills"] < self.a.kills:
            kind = order[self.stats["kills"]]
            attempts += 1
            if attempts > 4 * self.a.kills + 20:
                raise Failure("too many attempts that ended before the kill")
            if self.one(kind):
                self.stats["kills"] += 1
                self.stats["kills_by_kind"][kind] += 1
                n += 1
                if self.a.verbose:
                    print(f"[{n}/{self.a.kills}] {kind}: killed, checked, resumed", flush=True)
        self.stats["attempts"] = attempts
        self.stats["seconds"] = round(time.time() - t0, 1)
        return self.stats


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "devel", "lib", "regolith_twin"),
                    help="folder of regolith_sim and regolith_land")
    ap.add_argument("--kills", type=int, default=8, help="kills to make (default 8; the full loop: 120)")
    ap.add_argument("--kinds", default=",".join(KINDS), help="kinds of kill, in turn (default all: %(default)s)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--sim-duration", type=float, default=2.5, help="simulated s of the box run")
    ap.add_argument("--relax-duration", type=float, default=2.0, help="simulated s of the landing's bed relaxation")
    ap.add_argument("--report", default="", help="also write the figures as JSON to this file")
    ap.add_argument("--keep", action="store_true", help="keep the working folder")
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    loop = Loop(a)
    try:
        stats = loop.run()
    except Failure as e:
        print(f"fault loop: FAILED: {e}\n(working folder kept: {loop.work})", file=sys.stderr)
        return 1
    if not a.keep:
        shutil.rmtree(loop.work)
    else:
        print(f"kept {loop.work}")
    text = json.dumps(stats, indent=1, sort_keys=True)
    print(text)
    if a.report:
        with open(a.report, "w") as f:
            f.write(text + "\n")
    print(f"fault loop: {stats['kills']} kills, every check passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
