"""One run of a benchmark study whose summary is kept as one JSON file (bench/landing_savings.py,
bench/sampler_floor.py, bench/landing_timing.py): a kept run is not run again, so a study resumes on
any machine once its files are committed."""
import json
import os
import subprocess


def shown(cmd, root):
    """The command as text, paths inside the source tree `root` made relative to it."""
    return " ".join(os.path.relpath(c, root) if c.startswith(root) else c for c in cmd)


def run_kept(cmd, keep, key, meta, root, env=None):
    """Runs cmd (a regolith_sim command line with --out DIR) from `root` unless `keep` exists. Its
    DIR/summary.json, with `meta` and the command added under `key`, is written to `keep` (atomically).
    Returns (summary, True) when it ran, (summary, False) when it was kept, and (None, True) when the
    run stopped (the reason is printed; nothing is kept)."""
    if os.path.exists(keep):
        return json.load(open(keep)), False
    out = cmd[cmd.index("--out") + 1]
    p = subprocess.run(cmd, cwd=root, capture_output=True, text=True, env=env)
    if p.returncode != 0 or not os.path.exists(os.path.join(out, "summary.json")):
        print("%s: exit %d: %s" % (os.path.basename(keep)[:-5], p.returncode, p.stderr.strip()[-400:]), flush=True)
        return None, True
    s = json.load(open(os.path.join(out, "summary.json")))
    s[key] = dict(meta, command=shown(cmd, root))
    os.makedirs(os.path.dirname(keep), exist_ok=True)
    with open(keep + ".tmp", "w") as f:
        json.dump(s, f, indent=1)
    os.replace(keep + ".tmp", keep)
    return s, True
