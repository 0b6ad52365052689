#!/usr/bin/python3
"""regolith_infer: which surfaces explain an observed bounce (docs/infer.md). Normally started
through scripts/regolith_infer, which installs what is missing (and builds first with --run).

  regolith_infer QUERY.yaml [--out DIR] [--campaigns DIR]... [--run N]
  regolith_infer --observe speed_ratio=0.3+-0.05 --known angle_deg=0:60 --known attitude=BCF,FCF

Writes DIR/answer.json, DIR/answer.md and DIR/answer.png (default out/infer) and prints the
ranking. Exit status: 0 answered (whether or not a hypothesis is consistent), 2 a bad query,
3 a run it started failed."""
import argparse
import json
import os
import subprocess
import sys

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import infer  # noqa: E402

ROOT = infer.ROOT


def query_from_args(a):
    doc = {}
    if a.query:
        try:
            with open(a.query) as f:
                doc = yaml.safe_load(f) or {}
        except (OSError, yaml.YAMLError) as e:
            raise infer.InferError(f"{a.query}: {e}")
    if not isinstance(doc, dict):
        raise infer.InferError(f"{a.query}: expected a mapping with 'observed' and 'known'")
    for kind, items in (("observed", a.observe), ("known", a.known)):
        for item in items:
            if "=" not in item:
                raise infer.InferError(f"--{'observe' if kind == 'observed' else 'known'} '{item}': expected KEY=VALUE")
            k, v = item.split("=", 1)
            doc.setdefault(kind, {})
            doc[kind][k.strip()] = infer.parse_cli_value(v)
    if a.alpha is not None:
        doc["alpha"] = a.alpha
    if a.next is not None:
        doc["next_runs"] = a.next
    return infer.parse_query(doc)


def write_answer(answer, runs, out):
    os.makedirs(out, exist_ok=True)
    tmp = os.path.join(out, ".answer.json.tmp")
    with open(tmp, "w") as f:
        json.dump(answer, f, indent=1)
    os.replace(tmp, os.path.join(out, "answer.json"))
    text = infer.text_report(answer)
    with open(os.path.join(out, "answer.md"), "w") as f:
        f.write("# Which surfaces explain the observation\n\n```\n" + text + "\n```\n\n![observation against the "
                "hypotheses](answer.png)\n")
    if any(e["covered"] for e in answer["hypotheses"]):
        infer.plot(answer, runs, os.path.join(out, "answer.png"))
    return text


def run_next(a, nxt, runs):
    """One next run through the sweep driver, recorded beside the runs of its grid point."""
    same = [r for r in runs if r["hyp"][0] == nxt["material"] and r["hyp"][1] == int(round(100 * nxt["depth"]))
            and r["hyp"][2] == nxt["variant"] and r["hyp"][3] == nxt["attitude"] and r["speed"] == nxt["speed"]
            and r["gravity"] == nxt["gravity"]]
    here = [r for r in same if r["angle"] == nxt["angle"]]
    rep = max(here or same, key=lambda r: sum(1 for x in here if x["file"].rsplit("/", 1)[0] ==
                                              r["file"].rsplit("/", 1)[0]))
    record = os.path.join(ROOT, os.path.dirname(rep["file"]))
    extra = [infer.from_portable(o) for o in rep["overrides"] if not infer.POINT_OVERRIDE.match(o)]
    # The grid's bed preparations (sweep --preparations): repeat r lands where the grid's repeat r did.
    grid_dir = os.path.dirname(rep["file"])
    preps = max(r["preparations"] for r in runs if os.path.dirname(r["file"]) == grid_dir)
    repeats = 2 + max([r["repeat"] for r in here], default=-1)  # repeats 0 .. the next one
    cmd = [sys.executable, os.path.join(HERE, "sweep.py"), "--land", os.path.join(a.bin, "regolith_land"),
           "--config", infer.from_portable(rep["config"]),
           "--sim", os.path.join(a.bin, "regolith_sim"), "--materials", nxt["material"], "--depths",
           f"{nxt['depth']:g}", "--attitudes", nxt["attitude"], "--angles", f"{nxt['angle']:g}", "--repeats",
           str(repeats), "--out", os.path.join(a.out, "runs", rep["grid"]), "--record", record, "--jobs", "1",
           "--spread", "sd", "--no-run-plots", "--preparations", str(preps)]
    if a.threads:
        cmd += ["--threads", str(a.threads)]
    for o in extra:
        cmd += ["--set", o]
    print("regolith_infer: running " + " ".join(cmd[1:]), flush=True)
    return subprocess.call(cmd)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="regolith_infer", description=__doc__.split("\n\n")[0])
    ap.add_argument("query", nargs="?", help="query YAML: observed (output: [value, sigma]) and known (ranges)")
    ap.add_argument("--observe", action="append", default=[], metavar="OUTPUT=VALUE+-SIGMA",
                    help="an observed outcome, e.g. speed_ratio=0.3+-0.05 (SI units: m, s, rad/s, deg)")
    ap.add_argument("--known", action="append", default=[], metavar="KEY=VALUE",
                    help="what is known: speed=0.15:0.23, angle_deg=0:60, attitude=BCF,FCF, gravity=2.5e-4, "
                         "material=moderate, depth=0.3")
    ap.add_argument("--alpha", type=float, default=None, help="p-value below which a hypothesis is inconsistent "
                    "(default 0.01)")
    ap.add_argument("--next", type=int, default=None, help="next runs to propose (default 3)")
    ap.add_argument("--campaigns", action="append", default=[], metavar="DIR",
                    help="campaign folders (<grid>/runs/*.json; default results/campaign)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "infer"), help="answer.json/.md/.png here")
    ap.add_argument("--run", type=int, default=0, metavar="N",
                    help="run up to N of the proposed next runs (one at a time, each recorded with its grid's "
                         "runs), answering again after each")
    ap.add_argument("--bin", default=os.environ.get("REGOLITH_BIN", os.path.join(ROOT, "build", "devel", "lib",
                                                                                    "regolith_twin")))
    ap.add_argument("--threads", type=int, default=0, help="threads per run started by --run")
    ap.add_argument("--json", action="store_true", help="print answer.json instead of the table")
    a = ap.parse_args(argv)
    if not a.query and not a.observe:
        ap.error("give a query file or at least one --observe")
    campaigns = a.campaigns or [os.path.join(ROOT, "results", "campaign")]
    try:
        q = query_from_args(a)
        if a.run > 0 and q["next_runs"] < 1:
            q["next_runs"] = 1
        runs, skipped = infer.load_runs(campaigns)
        for f, why in skipped:
            print(f"regolith_infer: skipped {f}: {why}", file=sys.stderr)
        answer = infer.infer(q, runs)
        done = 0
        while done < a.run and answer["next_runs"]:
            rc = run_next(a, answer["next_runs"][0], runs)
            if rc != 0:
                print(f"regolith_infer: the run failed (exit {rc}); the answer stands on the runs before it",
                      file=sys.stderr)
                write_answer(answer, runs, a.out)
                return 3
            done += 1
            runs, _ = infer.load_runs(campaigns)
            answer = infer.infer(q, runs)
    except infer.InferError as e:
        print(f"regolith_infer: error: {e}", file=sys.stderr)
        return 2
    text = write_answer(answer, runs, a.out)
    print(json.dumps(answer, indent=1) if a.json else text)
    print(f"regolith_infer: answer in {a.out}/answer.json (table: answer.md, plot: answer.png)",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
