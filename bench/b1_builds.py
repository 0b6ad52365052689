#!/usr/bin/env python3
"""B1 throughput of two builds of regolith_twin, interleaved on one machine.

Each build settles the B1 bed once in a cache of its own (the settled state
is the same physics; a build does not read the other's files), then every
round times one block of B1_BLOCK_STEPS steps of each build at 1 and at 2
threads, the builds in the opposite order to the round before, so that the
machine's drifts fall on both alike. The figure is the median over the
rounds of the within-round ratio new/old of particle-steps per second, with
the rounds' range beside it as the noise.

  bench/b1_builds.py OLD_BIN NEW_BIN OUT.md [--rounds 5] [--block-steps 2000] [--label-old L] [--label-new L]

OLD_BIN and NEW_BIN are folders holding regolith_bench and the build's
shared libraries (each run gets LD_LIBRARY_PATH set to its own folder).
The raw lines go to OUT.md's folder as b1_builds_raw.txt."""
import argparse
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
B1 = os.path.join(ROOT, "bench", "b1.yaml")


def block(binary, threads, steps, cache):
    env = dict(os.environ, LD_LIBRARY_PATH=binary, OMP_NUM_THREADS=str(threads))
    env.pop("OMP_WAIT_POLICY", None)  # as scripts/bench: OpenMP's own waiting policy
    cmd = [os.path.join(binary, "regolith_bench"), B1, "--threads", str(threads), "--blocks", "1",
           "--block-steps", str(steps), "--label", "hooke", "--cache", cache]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"b1_builds: {' '.join(cmd)}: exit {p.returncode}\n{p.stderr[-2000:]}")
    for line in p.stdout.splitlines():
        if line.startswith("RESULT "):
            return line, float(re.search(r"particle_steps_per_s=(\S+)", line).group(1))
    sys.exit(f"b1_builds: no RESULT line from {binary}/regolith_bench:\n{p.stdout[-2000:]}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("out")
    ap.add_argument("--rounds", type=int, default=6, help="rounds (even: each build first equally often)")
    ap.add_argument("--block-steps", type=int, default=2000)
    ap.add_argument("--label-old", default="old")
    ap.add_argument("--label-new", default="new")
    a = ap.parse_args()
    builds = {"old": os.path.abspath(a.old), "new": os.path.abspath(a.new)}
    for b in builds.values():
        if not os.access(os.path.join(b, "regolith_bench"), os.X_OK):
            sys.exit(f"b1_builds: no regolith_bench in {b}")
    if not os.path.isfile(os.path.join(ROOT, "bench", "b1_bed.data")):  # the seeded bed every engine reads
        subprocess.run([sys.executable, os.path.join(ROOT, "bench", "make_b1_bed.py"), "-o",
                        os.path.join(ROOT, "bench", "b1_bed.data")], check=True)
    caches = {k: os.path.join(ROOT, "bench", ".cache", "builds", k) for k in builds}
    for c in caches.values():
        os.makedirs(c, exist_ok=True)
    raw_path = os.path.join(os.path.dirname(os.path.abspath(a.out)), "b1_builds_raw.txt")
    raw = []
    rates = {(k, t): [] for k in builds for t in (1, 2)}
    for r in range(1, a.rounds + 1):
        order = ["old", "new"] if r % 2 else ["new", "old"]
        for t in (1, 2):
            for k in order:
                line, rate = block(builds[k], t, a.block_steps, caches[k])
                rates[(k, t)].append(rate)
                raw.append(f"round={r} build={k} {line}")
                print(raw[-1], flush=True)
    with open(raw_path, "w") as f:
        f.write(f"old {builds['old']} ({a.label_old})\nnew {builds['new']} ({a.label_new})\n")
        f.write("\n".join(raw) + "\n")
    rows = []
    for t in (1, 2):
        ratios = [n / o for n, o in zip(rates[("new", t)], rates[("old", t)])]
        rows.append((t, statistics.median(rates[("old", t)]), statistics.median(rates[("new", t)]),
                     statistics.median(ratios), statistics.geometric_mean(ratios), min(ratios), max(ratios)))
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    with open(a.out, "w") as f:
        f.write("# B1 throughput: two builds side by side\n\n")
        f.write(f"`bench/b1_builds.py` (`scripts/bench --builds OLD NEW`): {a.rounds} interleaved rounds, each "
                f"timing one block of {a.block_steps} steps of the settled B1 bed ([b1_throughput.md]"
                f"(b1_throughput.md)) with each build at 1 and 2 threads, the builds' order alternating; "
                f"CPU: {cpu}, {os.cpu_count()} logical CPUs. Old: {a.label_old}. New: {a.label_new}. "
                f"Raw lines: [b1_builds_raw.txt](b1_builds_raw.txt).\n\n")
        f.write("| threads | old, particle-steps/s (median) | new | new / old: median of the rounds' ratios "
                "| geometric mean | rounds' range |\n|---:|---:|---:|---:|---:|---|\n")
        for t, o, n, med, gm, lo, hi in rows:
            f.write(f"| {t} | {o:.3g} | {n:.3g} | {med:.3f} | {gm:.3f} | {lo:.3f} – {hi:.3f} |\n")
        f.write("\nWith an even number of rounds each build goes first equally often; the geometric mean of the "
                "ratios then cancels an advantage of the first (or second) place in a round.\n")
    print(open(a.out).read())


if __name__ == "__main__":
    main()
