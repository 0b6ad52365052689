#!/usr/bin/env python3
"""MASCOT landing campaign (docs/scenes.md A): a grid of regolith_land runs.

Normally started through scripts/sweep (which builds first). Every grid point
materials x depths x attitudes x angles x repeats is one regolith_land run in
OUT/runs/<material>_d<cm>_<attitude>_a<angle>_r<repeat>/. A run is written in
a temporary folder that is renamed when the run has finished, so a sweep that
was stopped is re-run with the same command and continues: finished runs
(summary.json with status ok) are skipped, unfinished or failed ones redone.
Afterwards (or with --report-only) OUT/aggregate.csv, OUT/*.png and
OUT/report.md are written from every run in OUT/runs. Files are written to a
temporary name and renamed (docs/files.md, outputs), and a sweep holds
OUT/.regolith_twin.lock while it runs, so a second sweep into it is refused.

With --record DIR every finished run is also kept as one small JSON,
DIR/<run>.json (its summary and how it was run, paths relative to the
repository), meant to be committed: a sweep with the same --record on another
machine takes those runs as done (their summaries, without the series and
plots) and runs only the rest.
"""
import argparse
import concurrent.futures
import csv
import fcntl
import io
import json
import math
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, HERE)
from plots import pyplot  # noqa: E402
from stats import describe  # noqa: E402

# Outcome numbers of summary.json that the plots show, with axis labels.
PLOTTED = [
    ("speed_ratio", "speed ratio V_out / V_in", 1.0),
    ("travel_distance", "travel distance (m)", 1.0),
    ("max_penetration", "maximum penetration (cm)", 100.0),
    ("collision_duration", "collision duration (s)", 1.0),
]
KEYS = ["material", "depth", "attitude", "angle", "repeat"]


def fail(msg, code=2):
    print(f"sweep: {msg}", file=sys.stderr)
    sys.exit(code)


def split_list(text, kind, name):
    items = [x.strip() for x in text.split(",") if x.strip()]
    if not items:
        fail(f"--{name}: empty list")
    try:
        return [kind(x) for x in items]
    except ValueError:
        fail(f"--{name} '{text}': expected a comma-separated list of {kind.__name__}")


def depth_cm(d):
    return int(round(d * 100))


def fmt_num(x):
    """Short text of a number for folder names: 30 -> '30', 22.5 -> '22.5'."""
    return f"{x:g}"


def run_name(mat, depth, att, angle, rep):
    return f"{mat}_d{depth_cm(depth)}_{att}_a{fmt_num(angle)}_r{rep}"


def bed_file(bed_dir, mat, depth, prep=1):
    """The bed snapshot of a material and depth; prep > 1: its independent preparation number prep
    (mascot_<material>_d<cm>_s<prep>.bed, another seed: docs/validation/beds.md)."""
    return os.path.join(bed_dir, f"mascot_{mat}_d{depth_cm(depth)}{'' if prep == 1 else f'_s{prep}'}.bed")


def point_bed(a, point):
    """(bed, perturbation) of a grid point: with --preparations K, repeat r lands on preparation
    r mod K + 1, perturbed r div K times over (repeat 0 of each preparation is the bed as prepared)."""
    rep = point[4]
    return bed_file(a.bed_dir, point[0], point[1], rep % a.preparations + 1), rep // a.preparations


def fill_count(depth):
    """Grains to generate for a bed trimmed at `depth` (75000 for the 0.30 m default)."""
    return 1000 * math.ceil(75 * (depth + 0.05) / 0.35)


def bed_command(sim, mat, depth, path):
    args = [sim, os.path.join(ROOT, "config", "beds", "mascot_bed.yaml"),
            "--set", f"materials.regolith.preset={mat}", "--set", f"materials.container.preset={mat}",
            "--set", f"stages.1.trim_above={depth:g}"]
    if depth_cm(depth) != 30:
        args += ["--set", f"grains.0.fill.count={fill_count(depth)}"]
    args += ["--out", os.path.join(ROOT, "out", f"bed_{mat}_d{depth_cm(depth)}"), "--snapshot", path]
    return " ".join(shlex.quote(a) for a in args)


def temp_name(path):
    """A temporary name beside path, unique to this process (written, then renamed over path)."""
    return f"{path}.tmp.{os.getpid()}"


def write_text(path, text):
    """path written whole: a stopped sweep leaves the previous file or none, never part of one."""
    tmp = temp_name(path)
    try:
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def write_json(path, value):
    write_text(path, json.dumps(value, indent=1) + "\n")


def hold_folder(out):
    """One sweep per output folder: an exclusive lock on OUT/.regolith_twin.lock
    for the sweep's lifetime (it ends with the process, even when killed), as
    regolith_land takes its own (docs/files.md, outputs)."""
    os.makedirs(out, exist_ok=True)
    f = open(os.path.join(out, ".regolith_twin.lock"), "a+")
    try:
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        f.seek(0)
        pid = f.read().strip() or "?"
        f.close()
        fail(f"{out}: the output folder is in use by another sweep (pid {pid}); give another --out or wait "
             "until that sweep ends")
    f.truncate(0)
    f.write(f"{os.getpid()}\n")
    f.flush()
    return f


MAX_JSON_BYTES = 16 << 20  # a run's records are a few kB


def read_json(path):
    """The JSON object in PATH; None when it is missing, unreadable, or not an
    object (a file of the right name and the wrong shape is not a run's)."""
    try:
        # a regular file of a record's size: a device or a pipe is not read
        if not os.path.isfile(path) or os.path.getsize(path) > MAX_JSON_BYTES:
            return None
        with open(path) as f:
            v = json.loads(f.read(MAX_JSON_BYTES + 1))
    except (OSError, ValueError, RecursionError):
        return None
    return v if isinstance(v, dict) else None


def obj(x):
    """x when it is a JSON object, else an empty one (a summary's block of the wrong shape)."""
    return x if isinstance(x, dict) else {}


def meta_problem(meta):
    """'' when a run's sweep_run.json names its grid point with values of the right types, else what is wrong."""
    for k, types in (("material", str), ("depth", (int, float)), ("attitude", str), ("angle", (int, float)),
                     ("repeat", int)):
        v = meta.get(k)
        if isinstance(v, bool) or not isinstance(v, types):
            return f"'{k}' is {json.dumps(v)[:40]}"
    return ""


def warn(msg):
    print(f"sweep: warning: {msg}", file=sys.stderr, flush=True)


def is_done(run_dir):
    """A finished run: summary.json with status ok, from a regolith_land that exited 0."""
    s = read_json(os.path.join(run_dir, "summary.json"))
    meta = read_json(os.path.join(run_dir, "sweep_run.json"))
    return bool(s) and s.get("status") == "ok" and bool(meta) and meta.get("exit_code") == 0 \
        and not meta_problem(meta)


def to_portable(x):
    """Paths under the repository written as $ROOT/..., recursively."""
    if isinstance(x, str):
        return x.replace(ROOT + os.sep, "$ROOT/")
    if isinstance(x, list):
        return [to_portable(v) for v in x]
    if isinstance(x, dict):
        return {k: to_portable(v) for k, v in x.items()}
    return x


def from_portable(x):
    if isinstance(x, str):
        return x.replace("$ROOT/", ROOT + os.sep)
    if isinstance(x, list):
        return [from_portable(v) for v in x]
    if isinstance(x, dict):
        return {k: from_portable(v) for k, v in x.items()}
    return x


def write_record(record_dir, run_dir):
    """DIR/<run>.json of a finished run (written to a temporary name, then renamed)."""
    meta = read_json(os.path.join(run_dir, "sweep_run.json"))
    summary = read_json(os.path.join(run_dir, "summary.json"))
    if not meta or not summary:
        return
    os.makedirs(record_dir, exist_ok=True)
    path = os.path.join(record_dir, os.path.basename(run_dir) + ".json")
    write_json(path, to_portable({"sweep_run": meta, "summary": summary}))


def restore_records(a, grid):
    """Runs recorded in a.record and not finished in OUT/runs become finished runs there."""
    restored = 0
    for p in grid:
        name = run_name(*p)
        d = os.path.join(a.out, "runs", name)
        path = os.path.join(a.record, name + ".json")
        if is_done(d) or not os.path.exists(path):
            continue
        rec = read_json(path)
        problem = "not a JSON object" if rec is None else \
            "'sweep_run' and 'summary' must be JSON objects" if not (isinstance(rec.get("sweep_run"), dict) and
                                                                    isinstance(rec.get("summary"), dict)) else \
            meta_problem(rec["sweep_run"])
        if problem:
            warn(f"{path} is not a record of a finished run ({problem}): the run is made again, and its record "
                 "replaces this file when it finishes")
            continue
        rec = from_portable(rec)
        if rec["summary"].get("status") != "ok" or rec["sweep_run"].get("exit_code") != 0:
            continue
        # Written in a temporary folder renamed when whole, as a run's own.
        tmp = os.path.join(a.out, "runs", f".{name}.tmp")
        if os.path.exists(tmp):
            shutil.rmtree(tmp)
        os.makedirs(tmp)
        rec["sweep_run"]["restored_from"] = os.path.join(a.record, name + ".json")
        for f, v in (("sweep_run.json", rec["sweep_run"]), ("summary.json", rec["summary"])):
            write_json(os.path.join(tmp, f), v)
        if os.path.exists(d):
            shutil.rmtree(d)
        os.rename(tmp, d)
        restored += 1
    if restored:
        print(f"sweep: {restored} finished run(s) taken from {a.record}", flush=True)


def fmt_time(sec):
    sec = max(0, int(round(sec)))
    if sec < 120:
        return f"{sec} s"
    if sec < 7200:
        return f"{sec / 60:.1f} min"
    return f"{sec / 3600:.1f} h"


# ---------------------------------------------------------------- running

class Child:
    """The regolith_land processes under way, stopped with the sweep."""
    procs = set()
    lock = threading.Lock()
    stopping = False

    @staticmethod
    def stop_all():
        with Child.lock:
            procs = list(Child.procs)
        for p in procs:
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()


def die_with_parent():
    """In the child: be stopped when the sweep process dies, even by SIGKILL (Linux)."""
    try:
        import ctypes
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except Exception:
        pass


def on_signal(signum, _frame):
    raise KeyboardInterrupt(f"signal {signum}")


DEFAULT_SCENE = "mascot_landing.yaml"  # the landing a sweep runs unless --config names another scene file
# The --set keys run_overrides writes for each grid point itself, and the impact conditions a run's
# summary states (landing.g, landing.speed). Every other override of a record (a --set given to the
# whole sweep, a pinned value) makes a scene variant: another setting, not another grid point.
POINT_OVERRIDE = re.compile(r"^(materials\.(regolith|container|lander)\.preset|landing\.rim|grains\.0\.file|"
                            r"landing\.attitude|landing\.angle_deg|landing\.repeat)=")
CONDITION_OVERRIDE = re.compile(r"^landing\.(g|speed)=")


def variant_overrides(overrides):
    """The overrides of a record that make it a scene variant (sorted): neither the grid point's nor
    an impact condition."""
    return tuple(sorted(o for o in overrides if not POINT_OVERRIDE.match(o) and not CONDITION_OVERRIDE.match(o)))


def run_overrides(a, point, bed):
    """The --set options of one run: the grid point, then the sweep's own --set."""
    mat, depth, att, angle, _rep = point
    rep = point_bed(a, point)[1]
    ov = [f"materials.regolith.preset={mat}"]
    # The container and the lander take the friction of the grains (docs/scenes.md A).
    if not a.regolith_only:
        ov += [f"materials.container.preset={mat}", f"materials.lander.preset={mat}"]
    ov += [f"landing.rim={depth:g}", f"grains.0.file={bed}", f"landing.attitude={att}",
           f"landing.angle_deg={angle:g}", f"landing.repeat={rep}"]
    return ov + list(a.set) + list(a.pinned)


def run_one(a, land, point, bed, out_runs, index, total, eta_text):
    mat, depth, att, angle, rep = point
    name = run_name(*point)
    final = os.path.join(out_runs, name)
    tmp = os.path.join(out_runs, f".{name}.tmp")
    if os.path.exists(tmp):
        shutil.rmtree(tmp)
    os.makedirs(tmp)
    overrides = run_overrides(a, point, bed)
    cmd = [land, a.config, "--out", tmp, "--quiet"]
    for o in overrides:
        cmd += ["--set", o]
    if a.threads:
        cmd += ["--threads", str(a.threads)]
    if a.cache:
        cmd += ["--cache", a.cache]
    meta = {"name": name, "material": mat, "depth": depth, "attitude": att, "angle": angle, "repeat": rep,
            "preparations": a.preparations, "config": a.config, "bed": bed, "overrides": overrides, "command": cmd}
    print(f"[{index}/{total}] start {name}  ({time.strftime('%H:%M:%S')}; ETA {eta_text})", flush=True)
    t0 = time.time()
    with open(os.path.join(tmp, "run.log"), "w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, preexec_fn=die_with_parent)
        with Child.lock:
            Child.procs.add(proc)
        try:
            rc = proc.wait()
        finally:
            if proc.poll() is None:
                proc.terminate()
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()
            with Child.lock:
                Child.procs.discard(proc)
        if Child.stopping:
            raise KeyboardInterrupt("sweep stopped")
    wall = time.time() - t0
    meta["exit_code"] = rc
    meta["wall_seconds"] = round(wall, 3)
    summary = read_json(os.path.join(tmp, "summary.json")) or {}
    status = summary.get("status", "missing") if rc == 0 or summary else f"exit {rc}"
    if rc != 0 and status == "ok":
        status = f"exit {rc}"
    meta["status"] = status
    with open(os.path.join(tmp, "sweep_run.json"), "w") as f:
        json.dump(meta, f, indent=1)
    # Failed runs are kept for inspection under the same name; their summary
    # has no status ok, so the next sweep redoes them.
    if os.path.exists(final):
        shutil.rmtree(final)
    os.rename(tmp, final)
    if status == "ok" and a.record:
        write_record(a.record, final)
    if status == "ok" and not a.no_run_plots:
        plot_run(final)
    return rc, status, wall, summary


def other_settings(a, p, d):
    """'' when the finished run in d (if any) was made with this command's settings, else both settings."""
    meta = read_json(os.path.join(d, "sweep_run.json"))
    if not is_done(d) or meta is None:
        return ""
    want = run_overrides(a, p, point_bed(a, p)[0])
    had = meta.get("overrides")
    # A --pinned value was the scene's default when a run recorded without it was made.
    if isinstance(had, list):
        want_now = [o for o in want if o not in a.pinned or o in had]
    else:
        want_now = want
    if meta.get("config") == a.config and had == want_now:
        return ""
    had = had if isinstance(had, list) else []
    return (f"  {meta.get('config')} --set " + " --set ".join(str(x) for x in had) + f"\nnow:\n  {a.config} --set "
            + " --set ".join(want))


def check_writable_dir(path, what):
    """Fail at once, naming the folder, when path cannot be created or written (not after the first run)."""
    try:
        os.makedirs(path, exist_ok=True)
        probe = temp_name(os.path.join(path, ".probe"))
        with open(probe, "w"):
            pass
        os.remove(probe)
    except OSError as e:
        fail(f"{path}: the {what} cannot be written ({e.strerror}); give another folder or fix its permissions")


def sweep(a, grid, land):
    out_runs = os.path.join(a.out, "runs")
    os.makedirs(out_runs, exist_ok=True)
    a.lock = hold_folder(a.out)
    if a.record:
        restore_records(a, grid)
    total = len(grid)
    todo = [(i, p) for i, p in enumerate(grid, 1) if not is_done(os.path.join(out_runs, run_name(*p)))]
    # Finished runs are only reused when they were made with the same settings.
    for p in grid:
        d = os.path.join(out_runs, run_name(*p))
        other = other_settings(a, p, d)
        if other:
            fail(f"{d} was made with other settings:\n{other}\nuse another --out, or remove that run folder to redo it")
    # The grid of this command, for the report.
    write_json(os.path.join(a.out, "sweep.json"),
               dict(a.grid_lists, config=a.config, bed_dir=a.bed_dir, set=a.set + a.pinned, threads=a.threads,
                    preparations=a.preparations,
                    started=time.strftime("%Y-%m-%d %H:%M:%S")))
    done_before = total - len(todo)
    print(f"sweep: {total} runs in {a.out}/runs ({done_before} already done, {len(todo)} to run)", flush=True)
    if a.slurm:
        return slurm_sweep(a, grid, todo)
    walls, failed = [], []
    jobs = max(1, min(a.jobs, len(todo)))

    def eta_of(left):
        # Runs left, spread over the parallel jobs, at the mean wall time so far.
        return fmt_time(sum(walls) / len(walls) * math.ceil(left / jobs)) if walls else "after the first run"

    def start(k):
        i, p = todo[k]
        return pool.submit(run_one, a, land, p, point_bed(a, p)[0], out_runs, i, total,
                           eta_of(len(todo) - k))

    pool = concurrent.futures.ThreadPoolExecutor(max_workers=jobs)
    running = {}
    try:
        for k in range(min(jobs, len(todo))):  # none when every run is done (a sweep stopped in its report)
            running[start(k)] = k
        next_k = jobs
        while running:
            finished, _ = concurrent.futures.wait(running, return_when=concurrent.futures.FIRST_COMPLETED)
            for fut in finished:
                k = running.pop(fut)
                i, p = todo[k]
                rc, status, wall, summary = fut.result()
                walls.append(wall)
                left = len(todo) - len(walls)
                eta = eta_of(left) if left else "0 s"
                report_run(i, total, p, rc, status, wall, summary, eta, out_runs, failed)
                if next_k < len(todo):
                    running[start(next_k)] = next_k
                    next_k += 1
    except BaseException:
        Child.stopping = True
        Child.stop_all()
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return failed


def run_threads(meta):
    """Threads a finished run used: its command's --threads, else every core of this machine."""
    cmd = meta.get("command") if isinstance(meta.get("command"), list) else []
    for i, x in enumerate(cmd[:-1]):
        if x == "--threads":
            try:
                return max(1, int(cmd[i + 1]))
            except ValueError:
                break
    return os.cpu_count() or 1


def grid_state(a, grid):
    """One line on the grid of this command: runs done and left, core-hours spent on the done ones
    (wall time x threads, as recorded) and the projection for the rest at their mean."""
    done, core_s = 0, 0.0
    for p in grid:
        d = os.path.join(a.out, "runs", run_name(*p))
        if not is_done(d):
            continue
        done += 1
        meta = read_json(os.path.join(d, "sweep_run.json")) or {}
        w = meta.get("wall_seconds")
        if isinstance(w, (int, float)) and not isinstance(w, bool) and w > 0:
            core_s += w * run_threads(meta)
    left = len(grid) - done
    text = f"{done} of {len(grid)} runs done, {left} left; {core_s / 3600:.1f} core-hours spent"
    if left and done and core_s > 0:
        rest = left * core_s / done / 3600
        cores = os.cpu_count() or 1
        text += f"; the rest about {rest:.1f} core-hours ({rest / cores:.1f} h on {cores} cores)"
    return text


# ---------------------------------------------------------------- Slurm

def slurm_wait(job, poll):
    """Until the job (array) has left the queue."""
    while True:
        q = subprocess.run(["squeue", "-h", "-j", job, "-o", "%i %t"], capture_output=True, text=True)
        if q.returncode != 0 and "Invalid job id" not in q.stderr:
            fail(f"squeue failed: {q.stderr.strip()}", 1)
        if not q.stdout.strip():
            return
        time.sleep(poll)


def slurm_sweep(a, grid, todo):
    """The runs to do as Slurm job arrays, one run per task, into the shared
    output folder. A failed task (Slurm does not retry array tasks by itself)
    is resubmitted up to --slurm-retries times; finished runs are never
    submitted again. Returns the names of the runs still failed."""
    sdir = os.path.join(a.out, "slurm")
    os.makedirs(sdir, exist_ok=True)
    index = {run_name(*p): k for k, p in enumerate(grid)}
    pending = [index[run_name(*p)] for _, p in todo]
    for attempt in range(1, a.slurm_retries + 2):
        pending = [k for k in pending if not is_done(os.path.join(a.out, "runs", run_name(*grid[k])))]
        if not pending:
            break
        batch = os.path.join(sdir, f"batch_{time.strftime('%Y%m%d_%H%M%S')}_{attempt}.json")
        write_json(batch, {"argv": a.argv, "points": pending})
        cmd = ["sbatch", "--parsable", f"--array=0-{len(pending) - 1}", "--job-name=regolith_sweep",
               f"--cpus-per-task={max(1, a.threads)}", f"--chdir={os.getcwd()}",
               "--output", os.path.join(sdir, os.path.basename(batch)[:-5] + "_%a.log")]
        cmd += shlex.split(a.slurm_opts)
        cmd += ["--wrap", f"exec {shlex.quote(sys.executable)} {shlex.quote(os.path.abspath(__file__))} "
                          f"--slurm-task {shlex.quote(batch)} $SLURM_ARRAY_TASK_ID"]
        sub = subprocess.run(cmd, capture_output=True, text=True)
        if sub.returncode != 0:
            fail(f"sbatch failed: {sub.stderr.strip() or sub.stdout.strip()}", 1)
        job = sub.stdout.strip().split(";")[0]
        what = "submitted" if attempt == 1 else "resubmitted (failed before)"
        print(f"sweep: {len(pending)} runs {what} as Slurm job array {job}; task logs in {sdir}", flush=True)
        if a.no_wait:
            print("sweep: not waiting (--no-wait); the same command later collects the results and resubmits "
                  "what failed", flush=True)
            return []
        slurm_wait(job, a.slurm_poll)
    failed = [run_name(*grid[k]) for k in pending
              if not is_done(os.path.join(a.out, "runs", run_name(*grid[k])))]
    for n in failed:
        print(f"sweep: {n} failed after {a.slurm_retries + 1} attempts (log: {a.out}/runs/{n}/run.log)", flush=True)
    return failed


def slurm_task(a, grid, land):
    """One array task: the run of grid point points[SLURM_ARRAY_TASK_ID]."""
    batch = read_json(a.slurm_task[0])
    if not batch:
        fail(f"--slurm-task: cannot read {a.slurm_task[0]}")
    k = batch["points"][int(a.slurm_task[1])]
    p = grid[k]
    out_runs = os.path.join(a.out, "runs")
    os.makedirs(out_runs, exist_ok=True)
    rc, status, wall, summary = run_one(a, land, p, point_bed(a, p)[0], out_runs, k + 1, len(grid),
                                        "(Slurm)")
    report_run(k + 1, len(grid), p, rc, status, wall, summary, "(Slurm)", out_runs, [])
    return 0 if status == "ok" else 1


def report_run(i, total, p, rc, status, wall, summary, eta, out_runs, failed):
    """One line per finished run; bad input (exit 2) stops the sweep."""
    name = run_name(*p)
    if status == "ok":
        oc = summary.get("outcome", {})
        what = ("lifted off" if oc.get("lifted_off") else "no lift-off") + \
            f", speed ratio {oc.get('speed_ratio', 0):.3f}"
        print(f"[{i}/{total}] done  {name}: {what}; {fmt_time(wall)} wall; ETA {eta}", flush=True)
        return
    failed.append(name)
    print(f"[{i}/{total}] FAIL  {name}: {status} after {fmt_time(wall)} "
          f"(log: {out_runs}/{name}/run.log); ETA {eta}", flush=True)
    if rc == 2:
        with open(os.path.join(out_runs, name, "run.log")) as f:
            sys.stderr.write(f.read())
        fail("bad input (exit 2): stopping the sweep")


# ---------------------------------------------------------------- report

def collect(out):
    """One row per run folder in OUT/runs that has sweep_run.json."""
    rows, outcome_keys = [], []
    runs = os.path.join(out, "runs")
    if not os.path.isdir(runs):
        return rows, outcome_keys
    for name in sorted(os.listdir(runs)):
        d = os.path.join(runs, name)
        if name.startswith(".") or not os.path.isdir(d):
            continue
        meta = read_json(os.path.join(d, "sweep_run.json"))
        if meta is None:
            continue
        if meta_problem(meta):
            warn(f"{d}/sweep_run.json is not a run's ({meta_problem(meta)}): left out of the report")
            continue
        summary = read_json(os.path.join(d, "summary.json")) or {}
        oc = obj(summary.get("outcome"))
        row = {"run": name}
        for k in KEYS:
            row[k] = meta.get(k)
        row["status"] = summary.get("status", meta.get("status", "missing")) if meta.get("exit_code") == 0 \
            else meta.get("status", "failed")
        for k, v in oc.items():
            if isinstance(v, bool):
                v = int(v)
            if isinstance(v, (int, float)):
                row[k] = v
                if k not in outcome_keys:
                    outcome_keys.append(k)
        row["ended_by"] = oc.get("ended_by")
        bed = obj(summary.get("bed"))
        num = lambda v: v if isinstance(v, (int, float)) and not isinstance(v, bool) else None
        row["grains"] = num(bed.get("grains"))
        row["packing_fraction"] = num(bed.get("packing_fraction"))
        row["land_wall_seconds"] = num(obj(summary.get("run")).get("wall_seconds"))
        row["wall_seconds"] = num(meta.get("wall_seconds"))
        rows.append(row)
    rows.sort(key=lambda r: (r["material"], r["depth"], r["attitude"], r["angle"], r["repeat"]))
    return rows, outcome_keys


def write_aggregate(out, rows, outcome_keys):
    cols = ["run"] + KEYS + ["status", "ended_by"] + outcome_keys + ["grains", "packing_fraction", "land_wall_seconds",
                                                         "wall_seconds"]
    path = os.path.join(out, "aggregate.csv")
    text = io.StringIO(newline="")
    w = csv.writer(text)
    w.writerow(cols)
    for r in rows:
        w.writerow(["" if r.get(c) is None else fmt_num(r[c]) if c in ("depth", "angle") else r.get(c)
                    for c in cols])
    write_text(path, text.getvalue())
    return path


def stats(vals):
    """describe() of the values, with an SD of 0 for a single one (the tables print it)."""
    d = describe(vals)
    if d is not None and d["sd"] is None:
        d["sd"] = 0.0
    return d


def groups(rows):
    """{(material, depth, attitude, angle): [ok rows over repeats]}"""
    g = {}
    for r in rows:
        if r["status"] != "ok":
            continue
        g.setdefault((r["material"], r["depth"], r["attitude"], r["angle"]), []).append(r)
    return g


def published_averages(g):
    """Report lines: the grid points' means averaged as the published tables average them: per angle
    over materials, attitudes and depths, and per material and angle over attitudes (mean ± s.d. of
    the point means; n = points)."""
    def table(title, key_of, head):
        by = {}
        for k, rs in g.items():
            by.setdefault(key_of(k), []).append(k)
        L = ["", f"## {title}", "", "mean ± s.d. over the grid points' means (n = points).", "",
             f"| {head} | n | " + " | ".join(label for _, label, _ in PLOTTED) + " |",
             "|" + "---|" * (head.count("|") + 2 + len(PLOTTED))]
        for key in sorted(by):
            cells = []
            for name, _, scale in PLOTTED:
                means = [stats([r[name] * scale for r in g[k] if r.get(name) is not None]) for k in by[key]]
                s = stats([m["mean"] for m in means if m])
                cells.append("" if not s else f"{s['mean']:.3g}" + (f" ± {s['sd']:.2g}" if s["n"] > 1 else ""))
            label = " | ".join(fmt_num(x) if isinstance(x, float) else str(x) for x in key)
            L.append(f"| {label} | {len(by[key])} | " + " | ".join(cells) + " |")
        return L
    if not g:
        return []
    return (table("Per angle, over materials, attitudes and depths (as the published tables)", lambda k: (k[3],),
                  "angle (deg)") +
            table("Per material and angle, over attitudes", lambda k: (k[0], k[3]), "material | angle (deg)"))


def plot_metrics(out, rows, spread):
    plt = pyplot()

    g = groups(rows)
    if not g:
        return []
    mats = sorted({k[0] for k in g})
    depths = sorted({k[1] for k in g})
    atts = [x for x in ("Flat", "BCF", "FCF") if x in {k[2] for k in g}] + \
        sorted({k[2] for k in g} - {"Flat", "BCF", "FCF"})
    colours = {"Flat": "tab:blue", "BCF": "tab:red", "FCF": "tab:green"}
    styles = ["-", "--", ":", "-."]
    markers = ["o", "s", "^", "D"]
    lines = [(m, t) for m in mats for t in atts]
    angles = sorted({k[3] for k in g})
    step = (max(angles) - min(angles)) / max(1, len(angles) - 1) if len(angles) > 1 else 10.0
    written = []
    for key, label, scale in PLOTTED:
        fig, axes = plt.subplots(1, len(depths), figsize=(5.2 * len(depths) + 1.5, 4.2), squeeze=False)
        for j, d in enumerate(depths):
            ax = axes[0][j]
            for li, (m, t) in enumerate(lines):
                xs, ys, lo, hi = [], [], [], []
                for ang in angles:
                    vals = [r[key] * scale for r in g.get((m, d, t, ang), []) if r.get(key) is not None]
                    s = stats(vals)
                    if s is None:
                        continue
                    # A small sideways shift keeps the error bars of the lines apart.
                    xs.append(ang + (li - (len(lines) - 1) / 2) * 0.04 * step)
                    ys.append(s["mean"])
                    if spread == "minmax":
                        lo.append(s["mean"] - s["min"])
                        hi.append(s["max"] - s["mean"])
                    else:
                        lo.append(s["sd"])
                        hi.append(s["sd"])
                if not xs:
                    continue
                ax.errorbar(xs, ys, yerr=[lo, hi], color=colours.get(t, f"C{li}"),
                            ls=styles[mats.index(m) % len(styles)], marker=markers[mats.index(m) % len(markers)],
                            ms=4, capsize=3, lw=1.2, label=f"{m}, {t}")
            ax.set_xlabel("impact angle from the vertical (deg)")
            ax.set_ylabel(label)
            ax.set_xticks(angles)
            ax.set_title(f"bed depth {d:g} m", fontsize=9)
            ax.grid(alpha=0.3)
            ax.set_ylim(bottom=min(0, ax.get_ylim()[0]))
        axes[0][-1].legend(fontsize=8, loc="center left", bbox_to_anchor=(1.02, 0.5))
        what = "min-max" if spread == "minmax" else "+-1 s.d."
        fig.suptitle(f"{label}: mean over repeats, bars {what}", fontsize=10)
        fig.tight_layout()
        path = os.path.join(out, f"{key}.png")
        fig.savefig(temp_name(path), dpi=100, format="png")
        os.replace(temp_name(path), path)
        plt.close(fig)
        written.append(path)
    return written


def fmt(x, digits=3):
    if x is None:
        return ""
    if isinstance(x, float):
        return f"{x:.{digits}g}"
    return str(x)


def shown(path):
    """A path as the report shows it: relative to the repository when inside it."""
    p = os.path.abspath(path)
    return os.path.relpath(p, ROOT) if p.startswith(ROOT + os.sep) else p


def write_report(out, rows, outcome_keys, plots, spread, grid_meta):
    ok = [r for r in rows if r["status"] == "ok"]
    bad = [r for r in rows if r["status"] != "ok"]
    L = ["# MASCOT landing sweep", ""]
    L.append(f"Folder: `{shown(out)}` ({len(rows)} runs: {len(ok)} ok, {len(bad)} failed or unfinished).")
    if grid_meta:
        L.append("")
        L.append("Grid of the last sweep command:")
        L.append("")
        for k in ("materials", "depths", "attitudes", "angles", "repeats"):
            L.append(f"- {k}: {', '.join(fmt_num(x) if isinstance(x, float) else str(x) for x in grid_meta[k])}")
        L.append(f"- landing file: `{shown(grid_meta['config'])}`, beds from `{shown(grid_meta['bed_dir'])}`")
        if grid_meta.get("set"):
            L.append(f"- overrides: {', '.join('`' + s + '`' for s in grid_meta['set'])}")
        if grid_meta.get("threads"):
            L.append(f"- threads per run: {grid_meta['threads']}")
    L.append("")
    preps = (grid_meta or {}).get("preparations", 1)
    L.append(("Repeat 0 is the bed as prepared; repeats 1, 2, ... are perturbed beds (rotated about the "
              "container axis, aim point shifted within one grain diameter). " if preps == 1 else
              f"Repeats 0 to {preps - 1} land on {preps} independent preparations of each bed (other seeds, "
              f"each as prepared); repeat r >= {preps} on preparation r mod {preps} + 1, perturbed (rotated "
              "about the container axis, aim point shifted within one grain diameter). ") +
             "A run without lift-off counts "
             "with V_out = 0 (speed ratio and travel distance 0); its collision duration is the time until the "
             "run ended (end 'trapped': the lander's kinetic energy stayed below half of what a lift-off needs; "
             "'max_after_contact': the 60 s limit).")
    walls = [r["wall_seconds"] for r in ok if r.get("wall_seconds") is not None]
    if walls:
        s = stats(walls)
        L += ["", "## Wall time", "",
              f"Per run (regolith_land, including loading the bed): mean {fmt_time(s['mean'])}, "
              f"min {fmt_time(s['min'])}, max {fmt_time(s['max'])}; total {fmt_time(sum(walls))} "
              f"over {len(walls)} runs."]
        lw = [r["land_wall_seconds"] for r in ok if r.get("land_wall_seconds") is not None]
        if lw:
            L.append(f"Landing phase alone: mean {fmt_time(sum(lw) / len(lw))}.")
    if plots:
        L += ["", "## Plots", ""]
        what = "min-max" if spread == "minmax" else "+-1 s.d."
        L.append(f"Mean over repeats against the impact angle; bars: {what}.")
        L.append("")
        for p in plots:
            L.append(f"![{os.path.basename(p)}]({os.path.basename(p)})")
    g = groups(rows)
    if g:
        L += ["", "## Ensemble means (over repeats)", "",
              "mean ± s.d. (n = number of repeats finished); penetration in cm.", "",
              "| material | depth (m) | attitude | angle (deg) | n | lifted off | speed ratio | travel (m) "
              "| penetration (cm) | collision (s) |",
              "|---|---|---|---|---|---|---|---|---|---|"]
        for k in sorted(g):
            rs = g[k]
            cells = []
            for key, _, scale in PLOTTED:
                s = stats([r[key] * scale for r in rs if r.get(key) is not None])
                cells.append(f"{s['mean']:.3g} ± {s['sd']:.2g}" if s else "")
            lifted = sum(1 for r in rs if r.get("lifted_off"))
            L.append(f"| {k[0]} | {k[1]:g} | {k[2]} | {fmt_num(k[3])} | {len(rs)} | {lifted}/{len(rs)} | "
                     + " | ".join(cells) + " |")
        L += published_averages(g)
    if rows:
        L += ["", "## Runs", "", "Every number of the summaries is in `aggregate.csv`; per-run plots are in "
              "`runs/<run>/*.png`.", "",
              "| run | status | end | speed ratio | E_rot,out/E_lin,in | angle out (deg) | travel (m) "
              "| penetration (cm) | collision (s) | ejected volume (cm³) | wall |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            def v(k, scale=1.0):
                x = r.get(k)
                return "" if x is None else fmt(x * scale)
            L.append(f"| {r['run']} | {r['status']} | {r.get('ended_by') or ''} | {v('speed_ratio')} | {v('E_rot_out_over_E_lin_in')} | "
                     f"{v('angle_out_deg')} | {v('travel_distance')} | {v('max_penetration', 100)} | "
                     f"{v('collision_duration')} | {v('ejected_volume', 1e6)} | "
                     f"{fmt_time(r['wall_seconds']) if r.get('wall_seconds') is not None else ''} |")
    if bad:
        L += ["", "Failed or unfinished runs (redone by the next sweep with the same command): "
              + ", ".join(r["run"] for r in bad) + "."]
    path = os.path.join(out, "report.md")
    write_text(path, "\n".join(L) + "\n")
    return path


def plot_run(run_dir):
    """The plots of plot_landing.py for one run; a plot problem does not lose the run."""
    import contextlib
    try:
        plt = pyplot()
        import plot_landing
        with contextlib.redirect_stdout(open(os.devnull, "w")):
            plot_landing.main([run_dir])
        plt.close("all")
    except Exception as e:
        print(f"sweep: warning: plots of {run_dir}: {e}", file=sys.stderr)


def run_plots(a, rows):
    """Per-run plots of finished runs that have none yet (e.g. runs made without matplotlib)."""
    if a.no_run_plots:
        return
    for r in rows:
        d = os.path.join(a.out, "runs", r["run"])
        restored = (read_json(os.path.join(d, "sweep_run.json")) or {}).get("restored_from")
        if r["status"] == "ok" and not restored and not os.path.exists(os.path.join(d, "surface.png")):
            plot_run(d)


def report(a):
    rows, outcome_keys = collect(a.out)
    if not rows:
        fail(f"no runs in {a.out}/runs")
    run_plots(a, rows)
    grid_meta = read_json(os.path.join(a.out, "sweep.json"))
    agg = write_aggregate(a.out, rows, outcome_keys)
    plots = plot_metrics(a.out, rows, a.spread)
    rep = write_report(a.out, rows, outcome_keys, plots, a.spread, grid_meta)
    print(f"aggregate:   {agg}\nplots:       {', '.join(plots) if plots else '(no finished runs)'}\nreport:      {rep}")


# ---------------------------------------------------------------- main

MAX_REPEATS = 1000   # beds per grid point
MAX_RUNS = 100000    # runs in one sweep


def make_parser():
    """The sweep's flags (test/sweep/test_sweep_flags.py fuzzes every one of them)."""
    ap = argparse.ArgumentParser(
        prog="scripts/sweep",
        description="MASCOT landing sweep: materials x depths x attitudes x angles x repeats of regolith_land.",
        epilog="example: scripts/sweep --materials moderate,gravel --depths 0.30 --attitudes BCF "
               "--angles 0,30,60 --repeats 3 --out out/sweep1")
    ap.add_argument("--materials", default="moderate", help="comma-separated presets (default moderate)")
    ap.add_argument("--depths", default="0.30", help="bed depths in m (default 0.30)")
    ap.add_argument("--attitudes", default="BCF", help="Flat, BCF, FCF (default BCF)")
    ap.add_argument("--angles", default="30", help="impact angles from the vertical, deg (default 30)")
    ap.add_argument("--repeats", type=int, default=1,
                    help="beds per grid point: repeat 0 = as prepared, 1.. perturbed (default 1)")
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--preparations", type=int, default=1, metavar="K",
                    help="independent bed preparations (default 1): repeat r lands on preparation r mod K + 1 "
                         "(mascot_<material>_d<cm>_s<k>.bed for k > 1), perturbed r div K times over")
    ap.add_argument("--config", default=os.path.join(ROOT, "config", DEFAULT_SCENE),
                    help="landing file (default config/mascot_landing.yaml)")
    ap.add_argument("--bed-dir", default=os.path.join(ROOT, "config", "beds"),
                    help="folder of the bed snapshots mascot_<material>_d<cm>.bed (default config/beds)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="extra override for every run (after the sweep's own)")
    ap.add_argument("--pinned", action="append", default=[], metavar="KEY=VALUE",
                    help="an override for every run (after --set) that holds a scene default the grid began "
                         "with: finished runs recorded without it count as made with it")
    ap.add_argument("--threads", type=int, default=0, help="OpenMP threads per run (default: regolith_land's)")
    ap.add_argument("--jobs", type=int, default=1,
                    help="runs at the same time (default 1); e.g. --jobs 2 --threads 1 on two cores. Runs on a "
                         "bed not yet relaxed in the cache each relax it")
    ap.add_argument("--cache", default="", help="relaxed-bed cache folder passed to regolith_land")
    ap.add_argument("--land", default=os.path.join(ROOT, "build", "devel", "lib", "regolith_twin", "regolith_land"),
                    help="regolith_land binary")
    ap.add_argument("--sim", default=None, help="regolith_sim binary (named in the bed preparation hint)")
    ap.add_argument("--spread", choices=["minmax", "sd"], default="minmax",
                    help="spread over repeats in the plots (default minmax)")
    ap.add_argument("--regolith-only", action="store_true",
                    help="set only materials.regolith.preset (container and lander keep the file's presets)")
    ap.add_argument("--no-run-plots", action="store_true", help="no per-run plots (plot_landing.py)")
    ap.add_argument("--slurm", action="store_true",
                    help="run the grid as Slurm job arrays (one run per task; shared output folder); "
                         "failed tasks are resubmitted, finished runs never")
    ap.add_argument("--slurm-opts", default="", help="extra sbatch options, e.g. \"--partition=long --time=4:00:00\"")
    ap.add_argument("--slurm-retries", type=int, default=2, help="resubmissions of failed tasks (default 2)")
    ap.add_argument("--slurm-poll", type=float, default=10, help="seconds between queue checks (default 10)")
    ap.add_argument("--no-wait", action="store_true", help="with --slurm: submit and return")
    ap.add_argument("--slurm-task", nargs=2, metavar=("BATCH", "INDEX"), help=argparse.SUPPRESS)
    ap.add_argument("--record", default="",
                    help="folder of one small JSON per finished run (to commit); runs recorded there count as done")
    ap.add_argument("--report-only", action="store_true", help="only write aggregate.csv, plots, report.md")
    ap.add_argument("--dry-run", action="store_true", help="list the runs and their state, run nothing")
    return ap


def main(argv=None):
    ap = make_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) == 3 and argv[0] == "--slurm-task":
        # A Slurm array task: the driver's own arguments, from its batch file.
        batch = read_json(argv[1])
        if not batch or "argv" not in batch:
            fail(f"--slurm-task: cannot read {argv[1]}")
        argv = batch["argv"] + argv
    a = ap.parse_args(argv)
    a.argv = [x for x in argv]
    a.out = os.path.abspath(a.out)
    a.config = os.path.abspath(a.config)
    a.bed_dir = os.path.abspath(a.bed_dir)
    a.record = os.path.abspath(a.record) if a.record else ""
    if a.report_only:
        report(a)
        return 0

    mats = split_list(a.materials, str, "materials")
    depths = split_list(a.depths, float, "depths")
    atts = split_list(a.attitudes, str, "attitudes")
    angles = split_list(a.angles, float, "angles")
    for m in mats:
        # a preset's name, also part of file names: no path, no spaces
        if not (m.replace("_", "").isalnum() and m.isascii() and len(m) <= 40):
            fail(f"--materials: '{m[:60]}' is not a material preset's name (letters, digits, _; e.g. moderate)")
    for t in atts:
        if t not in ("Flat", "BCF", "FCF"):
            fail(f"--attitudes: '{t[:60]}' is not one of Flat, BCF, FCF")
    for d in depths:
        if not 0 < d < 2:
            fail(f"--depths: {d} m is out of range (0, 2) m")
    for ang in angles:
        if not 0 <= ang < 90:
            fail(f"--angles: {ang} deg is out of range [0, 90) deg from the vertical")
    if not 1 <= a.repeats <= MAX_REPEATS:
        fail(f"--repeats {a.repeats}: expected 1 to {MAX_REPEATS}")
    if not 1 <= a.preparations <= MAX_REPEATS:
        fail(f"--preparations {a.preparations}: expected 1 to {MAX_REPEATS}")
    if not 0 <= a.threads <= 256:
        fail(f"--threads {a.threads}: expected 1 to 256 (0: regolith_land's default)")
    if not 1 <= a.jobs <= 256:
        fail(f"--jobs {a.jobs}: expected 1 to 256")
    if not 0 <= a.slurm_retries <= 100:
        fail(f"--slurm-retries {a.slurm_retries}: expected 0 to 100")
    if not 0.1 <= a.slurm_poll <= 3600:
        fail(f"--slurm-poll {a.slurm_poll}: expected 0.1 to 3600 s")
    for opt, values in (("--set", a.set), ("--pinned", a.pinned)):
        for s in values:
            if "=" not in s or not s.split("=", 1)[0].strip():
                fail(f"{opt} '{s[:60]}': expected key=value")
    n_runs = len(mats) * len(depths) * len(atts) * len(angles) * a.repeats
    if n_runs > MAX_RUNS:
        fail(f"the grid has {n_runs} runs, more than {MAX_RUNS}: split it into several sweeps")
    if not os.path.isfile(a.config):
        fail(f"landing file {a.config} not found")
    land = os.path.abspath(a.land)
    if not a.dry_run and not (os.path.isfile(land) and os.access(land, os.X_OK)):
        fail(f"regolith_land not found at {land} (build first: scripts/sweep builds it)")
    sim = a.sim or os.path.join(os.path.dirname(land), "regolith_sim")

    a.grid_lists = {"materials": mats, "depths": depths, "attitudes": atts, "angles": angles,
                    "repeats": list(range(a.repeats))}
    grid = [(m, d, t, ang, r) for m in mats for d in depths for t in atts for ang in angles
            for r in range(a.repeats)]
    if a.dry_run:
        for i, p in enumerate(grid, 1):
            d = os.path.join(a.out, "runs", run_name(*p))
            bed = "" if os.path.isfile(point_bed(a, p)[0]) else " (bed missing)"
            state = "to run"
            if is_done(d):
                state = "done, with other settings: the sweep refuses it (use another --out, or remove the " \
                        "folder)" if other_settings(a, p, d) else "done"
            print(f"[{i}/{len(grid)}] {run_name(*p)}: {state}{bed}")
    preps = range(1, min(a.preparations, a.repeats) + 1)
    missing = [(m, d, k) for m in mats for d in depths for k in preps
               if not os.path.isfile(bed_file(a.bed_dir, m, d, k))]
    if missing:
        msg = ["bed snapshot(s) missing; prepare each once (hours on 2 cores) with:"]
        for m, d, k in missing:
            path = bed_file(a.bed_dir, m, d, k)
            msg.append(f"  {path}:")
            msg.append(f"    {bed_command(sim, m, d, path)}" if k == 1 else
                       f"    scripts/validate_beds prepare {os.path.basename(path)[:-4]}  (another seed of the bed)")
        msg.append("(config/beds/mascot_bed.yaml; stages.1 is the trim stage, grains.0.fill.count the grains "
                   "generated: enough that the settled bed reaches the depth)")
        if not a.dry_run:
            fail("\n".join(msg))
        print("\n".join(msg))
    if a.dry_run:
        return 0
    if a.slurm_task:
        return slurm_task(a, grid, land)
    if a.slurm and not shutil.which("sbatch"):
        fail("--slurm: sbatch not found (Slurm's client commands must be on PATH)")

    check_writable_dir(a.out, "output folder")
    if a.record:
        check_writable_dir(a.record, "record folder (--record)")
    signal.signal(signal.SIGTERM, on_signal)
    t0 = time.time()
    try:
        failed = sweep(a, grid, land)
    except KeyboardInterrupt:
        print("sweep: stopped; the same command continues where it stopped", file=sys.stderr)
        print(f"sweep: {grid_state(a, grid)}", file=sys.stderr)
        return 130
    print(f"sweep: finished in {fmt_time(time.time() - t0)}"
          + (f"; {len(failed)} failed: {', '.join(failed)}" if failed else ""), flush=True)
    print(f"sweep: {grid_state(a, grid)}", flush=True)
    report(a)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
