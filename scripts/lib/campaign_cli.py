"""Shared by the scene campaigns (plume_campaign.py, bucket_campaign.py, incline_campaign.py):
their command line, and one run of regolith_sim whose summary is kept under docs/ (a run that
stops leaves failed.txt there instead: reported, and not retried unless asked)."""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time


def command_line(doc, argv=None):
    """BIN OUT DOCS CMD [NAME...] -> (bin_dir, out, docs, cmd, names); OUT and DOCS made. `doc` (the
    campaign's docstring) is its help."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("bin_dir", metavar="BIN", help="the folder of regolith_sim")
    p.add_argument("out", metavar="OUT", help="where the runs write (scratch)")
    p.add_argument("docs", metavar="DOCS", help="where the kept results go")
    p.add_argument("cmd", metavar="CMD", help="what to do (see above)")
    p.add_argument("names", metavar="NAME", nargs="*", help="runs (default: all)")
    a = p.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(a.docs, exist_ok=True)
    return a.bin_dir, a.out, a.docs, a.cmd, a.names


def check_names(names, known, what="run"):
    for n in names:
        if n not in known:
            raise SystemExit("unknown %s '%s' (%s)" % (what, n, " ".join(known)))


def kept(keep, rerun_env):
    """The kept summary of a finished run, "failed" for a run that stopped, None to run it."""
    if os.environ.get(rerun_env) == "1":
        return None
    if os.path.exists(os.path.join(keep, "summary.json")):
        return json.load(open(os.path.join(keep, "summary.json")))
    if os.path.exists(os.path.join(keep, "failed.txt")):
        return "failed"
    return None


def run_and_keep(bin_dir, config, out_dir, keep, overrides, campaign, copies=(), threads=1, extra=()):
    """regolith_sim CONFIG --set OVERRIDE... [EXTRA...] into out_dir; its summary.json (with `campaign`
    and the wall time added) and the files in `copies` go to keep. Returns the summary, or None if it
    stopped."""
    cmd = [os.path.join(bin_dir, "regolith_sim"), config, "--threads", str(threads), "--out", out_dir, "--quiet"]
    cmd += list(extra)
    for o in overrides:
        cmd += ["--set", o]
    t0 = time.time()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - t0
    if r.returncode < 0:
        # Killed by a signal from outside (the campaign interrupted): nothing is recorded, so the run is
        # not taken as stopped and runs again next time; the campaign stops here.
        sys.stderr.write(r.stdout[-3000:])
        raise SystemExit("%s: killed by signal %d after %.0f s; not recorded (it runs again next time)"
                         % (os.path.basename(keep), -r.returncode, wall))
    os.makedirs(keep, exist_ok=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout[-3000:])
        with open(os.path.join(keep, "failed.txt"), "w") as f:
            f.write("exit %d after %.0f s; %s\n" % (r.returncode, wall, " ".join(overrides)))
            f.write("\n".join(r.stdout.strip().splitlines()[-3:]) + "\n")
        print("%s: FAILED (exit %d; the campaign goes on)" % (os.path.basename(keep), r.returncode), flush=True)
        return None
    s = json.load(open(os.path.join(out_dir, "summary.json")))
    s["campaign"] = dict(campaign, overrides=list(overrides), wall_seconds=wall)
    with open(os.path.join(keep, "summary.json"), "w") as f:
        json.dump(s, f, indent=1)
    for name in copies:
        if os.path.exists(os.path.join(out_dir, name)):
            shutil.copy(os.path.join(out_dir, name), os.path.join(keep, name))
    return s


def failures(docs):
    """[(run folder, failed.txt text)] of the runs under docs that stopped."""
    out = []
    for d in sorted(os.listdir(docs)) if os.path.isdir(docs) else []:
        f = os.path.join(docs, d, "failed.txt")
        if os.path.exists(f):
            out.append((d, " ".join(open(f).read().split())))
    return out


def failure_lines(docs):
    """Markdown lines listing the runs that stopped (none: no lines)."""
    fs = failures(docs)
    if not fs:
        return []
    return ["", "Runs that stopped (the engine's guards or input checks; their partial output is not used):", ""] + [
        "- `%s`: %s" % (d, t) for d, t in fs]


def write_report(docs, lines, fig, axes, png, caption, legend=True, name="report.md"):
    """Grid (and legends) on the axes; the figure saved as DOCS/PNG with its markdown line when there
    is data (lines is not only the header), and DOCS/report.md written. Returns the report's path."""
    from plots import pyplot
    plt = pyplot()
    for a in axes:
        a.grid(alpha=0.3)
        if legend and a.get_legend_handles_labels()[0]:
            a.legend(fontsize=7)
    fig.tight_layout()
    if png:
        fig.savefig(os.path.join(docs, png), dpi=110)
        lines = lines + ["", "![%s](%s)" % (caption, png)]
    plt.close(fig)
    path = os.path.join(docs, name)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path
