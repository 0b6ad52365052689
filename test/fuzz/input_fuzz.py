#!/usr/bin/env python3
"""The table-driven input fuzzer (docs/validation/reliability.md, "Input fuzzer").

For every small scene of test/fuzz/inputs/ (one or more per scene kind), the
keys come from the readers themselves (`regolith_sim SCENE --list-keys`: every
key they ask for, present in the file or not), so a key added to a reader is
fuzzed without editing this file. Each key is set, with --set, to each of the
hostile values below, and the scene is run with a step limit and a wall-time
cap. The oracle:

  - exit 2 (refused) with the key named in the message (as a.0.b or a[0].b),
    or the entry it belongs to when that has two parts at least (gravity for
    gravity[0], materials.sand for materials.sand.mu_s);
  - or exit 0 / 3 (ran, or stopped with a diagnostic) with every number in
    summary.json and series.csv finite and below 1e15 in magnitude;
  - never a signal, an exit 1, a Python or C++ traceback, or a run past the cap.

  test/fuzz/input_fuzz.py [--bin DIR] [--jobs N] [--only SUBSTRING] [--report FILE.md] [--keep DIR]
"""
import argparse
import concurrent.futures as cf
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
INPUTS = os.path.join(HERE, "inputs")

# The hostile values: zero both signs, negative, tiny, huge, not-a-number,
# both infinities, a wrong type (a mapping), an empty list, a huge count.
VALUES = ["0", "-0.0", "-1", "1e-300", "1e300", ".nan", ".inf", "-.inf", "{wrong: type}", "[]",
          "9223372036854775807"]
MAX_STEPS = 200000    # the fuzzer's step limit (--max-steps): every accepted run is short
CAP = 120.0           # s of wall time per case; a run past it is a failure
BOUND = 1e15          # a number in the outputs beyond this is nonsense for these small scenes


def list_keys(sim, scene, cache):
    p = subprocess.run([sim, scene, "--list-keys", "--cache", cache], cwd=ROOT, capture_output=True, text=True,
                       timeout=600)
    if p.returncode != 0:
        raise SystemExit(f"input_fuzz: {scene}: --list-keys failed (exit {p.returncode}):\n{p.stderr}")
    keys = []
    for line in p.stdout.splitlines():
        path, kind = line.split()
        keys.append((path, kind))
    return keys


SCENARIO_BLOCKS = {"name", "seed", "gravity", "contact", "guards", "sleep", "schedule", "free_flight", "periodic", "gas",
                   "materials", "walls", "bodies", "grains", "stages", "output"}


def reader_key(path, materials):
    """The key as its reader knows it: list entries as [*], material names as *.
    A scenario key (materials, walls, stages, ...) is read by the same code in
    every scene, so it is fuzzed in the first scene that has it; a kind's own
    block (landing:, impact:, ...) in every scene of that kind."""
    k = re.sub(r"\[\d+\]", "[*]", path)
    parts = k.split(".")
    if parts[0] == "materials" and len(parts) > 1 and parts[1] in materials:
        parts[1] = "*"
    return ".".join(parts)


def set_path(path):
    """walls[0].radius -> walls.0.radius (the --set form)."""
    return re.sub(r"\[(\d+)\]", r".\1", path)


def numbers_of(obj):
    if isinstance(obj, bool):
        return
    if isinstance(obj, (int, float)):
        yield float(obj)
    elif isinstance(obj, dict):
        for v in obj.values():
            yield from numbers_of(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from numbers_of(v)


def bad_number(x):
    return not math.isfinite(x) or abs(x) > BOUND


def check_outputs(out):
    """'' when summary.json and series.csv hold only finite, bounded numbers, else what is wrong."""
    summary = os.path.join(out, "summary.json")
    if not os.path.exists(summary):
        return "no summary.json"
    try:
        with open(summary) as f:
            text = f.read()
        j = json.loads(text, parse_constant=lambda c: float(c))  # NaN/Infinity would be a defect
    except ValueError as e:
        return f"summary.json is not JSON: {e}"
    for x in numbers_of(j):
        if bad_number(x):
            return f"summary.json holds {x}"
    series = os.path.join(out, "series.csv")
    if os.path.exists(series):
        with open(series) as f:
            head = f.readline().strip().split(",")
            for n, line in enumerate(f, 2):
                for name, cell in zip(head, line.strip().split(",")):
                    if cell == "":
                        continue
                    try:
                        x = float(cell)
                    except ValueError:
                        return f"series.csv line {n}: {name} = '{cell}' is not a number"
                    if bad_number(x):
                        return f"series.csv line {n}: {name} = {cell}"
    return ""


def run_case(sim, scene, key, kind, value, cache, work):
    out = tempfile.mkdtemp(prefix="case_", dir=work)
    cmd = [sim, scene, "--set", f"{set_path(key)}={value}", "--out", os.path.join(out, "o"), "--cache", cache,
           "--quiet", "--threads", "1", "--max-steps", str(MAX_STEPS)]
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=CAP)
    except subprocess.TimeoutExpired:
        shutil.rmtree(out, ignore_errors=True)
        return "fail", f"ran past the cap of {CAP:.0f} s", CAP
    wall = time.monotonic() - t0
    err = p.stderr
    verdict, why = "fail", ""
    if p.returncode < 0:
        why = f"killed by signal {-p.returncode}"
    elif "Traceback" in err or "terminate called" in err:
        why = "traceback: " + err.strip().splitlines()[-1][:200]
    elif p.returncode == 2:
        names = [key, set_path(key)]
        # The entry the key belongs to may be named instead (a vector for its
        # component, materials.x for its friction, grains[0].fill for its
        # count), when that entry is itself specific (two parts at least).
        parent = re.sub(r"(\[\d+\]|\.[^.\[]+)$", "", key)
        if parent != key and (re.search(r"[.\[]", parent) or re.search(r"\[\d+\]$", key)):
            names.append(parent)
        named = any(n in err for n in names)
        verdict, why = ("refused", "") if named else ("fail", "refused without naming the key: " + err.strip()[-300:])
    elif p.returncode in (0, 3):
        bad = check_outputs(os.path.join(out, "o"))
        if bad:
            why = bad
        else:
            verdict = "ran" if p.returncode == 0 else "stopped"
    else:
        why = f"exit {p.returncode}: " + err.strip()[-300:]
    shutil.rmtree(out, ignore_errors=True)
    return verdict, why, wall


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "devel", "lib", "regolith_twin"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", default="", help="scenes whose file name contains this")
    ap.add_argument("--report", default="", help="write the counts as a markdown table here")
    ap.add_argument("--keep", default="", help="work folder (kept); default a temporary one")
    ap.add_argument("--shared-once", action="store_true",
                    help="fuzz the scenario keys every kind shares only on the first scene that reads them")
    a = ap.parse_args()
    sim = os.path.join(a.bin, "regolith_sim")
    work = a.keep or tempfile.mkdtemp(prefix="input_fuzz_")
    os.makedirs(work, exist_ok=True)
    cache = os.path.join(work, "cache")
    # The plain scenario first: the scenario keys every kind shares are fuzzed on it, the
    # kinds' own blocks on their scenes.
    scenes = sorted((os.path.join(INPUTS, f) for f in os.listdir(INPUTS) if f.endswith(".yaml") and a.only in f),
                    key=lambda p: (os.path.basename(p) != "plain.yaml", p))
    cases = []
    table = []
    seen = set()
    for scene in scenes:
        keys = list_keys(sim, scene, cache)
        materials = {k.split(".")[1] for k, _ in keys if k.startswith("materials.") and k.count(".") >= 2}
        fresh = []
        for key, kind in keys:
            rk = reader_key(key, materials)
            if a.shared_once and rk.split(".")[0].split("[")[0] in SCENARIO_BLOCKS:
                if rk in seen:
                    continue
                seen.add(rk)
            fresh.append((key, kind))
        table.append([os.path.basename(scene), len(keys), len(fresh)])
        for key, kind in fresh:
            for v in VALUES:
                cases.append((scene, key, kind, v))
    print(f"input_fuzz: {len(cases)} cases: {sum(t[2] for t in table)} keys fuzzed ({sum(t[1] for t in table)} "
          f"listed) of {len(scenes)} scenes x {len(VALUES)} values", flush=True)
    t0 = time.monotonic()
    results = {}
    with cf.ThreadPoolExecutor(a.jobs) as ex:
        futs = {ex.submit(run_case, sim, s, k, kind, v, cache, work): (s, k, kind, v) for s, k, kind, v in cases}
        for n, f in enumerate(cf.as_completed(futs), 1):
            results[futs[f]] = f.result()
            if n % 200 == 0:
                print(f"input_fuzz: {n}/{len(cases)} ({time.monotonic() - t0:.0f} s)", flush=True)
    failures = [(c, r) for c, r in results.items() if r[0] == "fail"]
    for (s, k, kind, v), (_, why, _) in sorted(failures):
        print(f"FAIL {os.path.basename(s)}: --set {set_path(k)}={v} ({kind}): {why}")
    counts = {}
    for (s, _, _, _), (verdict, _, wall) in results.items():
        c = counts.setdefault(os.path.basename(s), {"refused": 0, "ran": 0, "stopped": 0, "fail": 0, "wall": 0.0})
        c[verdict] += 1
        c["wall"] += wall
    slowest = max(results.items(), key=lambda kv: kv[1][2]) if results else None
    print(f"input_fuzz: {len(cases)} cases in {time.monotonic() - t0:.0f} s: {len(failures)} failed"
          + (f"; slowest {slowest[1][2]:.1f} s (--set {set_path(slowest[0][1])}={slowest[0][3]})" if slowest else ""))
    if a.report:
        with open(a.report, "w") as f:
            f.write("| scene | keys read | keys fuzzed | cases | refused (key named) | ran | stopped (exit 3) | failed |\n")
            f.write("|---|---:|---:|---:|---:|---:|---:|---:|\n")
            for name, nkeys, nfresh in table:
                c = counts.get(name, {"refused": 0, "ran": 0, "stopped": 0, "fail": 0})
                f.write(f"| {name} | {nkeys} | {nfresh} | {nfresh * len(VALUES)} | {c['refused']} | {c['ran']} "
                        f"| {c['stopped']} | {c['fail']} |\n")
    if not a.keep:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
