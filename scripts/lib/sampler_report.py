#!/usr/bin/env python3
"""Tables of the sampler validation runs (scripts/validate_sampler), as markdown.

usage: sampler_report.py DIR

DIR holds one folder per run (summary.json, command.txt, wall_seconds) and
smallest_pair_restitution.json. Prints markdown: the runs, the energy
partition at the end of the 0.2 ms window, the wave attenuation slopes, the
Z-model fits, crater, ejecta and collection, and the smallest pair's
restitution at the shot's resolution.
"""
import argparse
import json
import os


def load(d):
    runs = {}
    for name in sorted(os.listdir(d)):
        p = os.path.join(d, name, "summary.json")
        if os.path.isfile(p):
            with open(p) as f:
                runs[name] = json.load(f)
            c = os.path.join(d, name, "command.txt")
            runs[name]["_command"] = open(c).read().strip() if os.path.exists(c) else ""
    return runs


def g(x, fmt="{:.3g}"):
    return "–" if x is None else fmt.format(x)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir", metavar="DIR")
    d = p.parse_args().dir
    runs = load(d)
    print("| run | speed m/s | dt s | repeat (bed rotation, impact shift) | simulated s | steps | grains | wall s |")
    print("|---|---|---|---|---|---|---|---|")
    for n, s in runs.items():
        i, r = s["input"], s["run"]
        shift = i.get("impact_shift", [0, 0])
        print(f"| {n} | {i['speed']:g} | {r['dt']:.3g} | {i['repeat']} ({i['bed_rotation_deg']:.0f}°, "
              f"{1e3 * shift[0]:.2f}/{1e3 * shift[1]:.2f} mm) | {r['sim_time']:.4g} | {r['steps']} | {r['grains']} | "
              f"{r['wall_seconds']:.0f} |")
    print()
    print("Energy partition at the end of the window after impact, as fractions of the projectile's initial "
          "kinetic energy E0 (elastic: every spring term; dissipated: the rest):")
    print()
    print("| run | window s | E0 J | bed translation | bed rotation | projectile | elastic | dissipated |")
    print("|---|---|---|---|---|---|---|---|")
    for n, s in runs.items():
        e = s["observers"].get("energy_partition")
        if not e or not e.get("initial_energy"):
            continue
        # The observer's parts are fractions of E0 already.
        el = sum(v for k, v in e.items() if k.endswith(("_normal", "_tangential", "_rolling", "_twisting")))
        proj = e["ke_proj_trans"] + e["ke_proj_rot"]
        print(f"| {n} | {e['t']:.3g}{'' if e.get('window_complete') else ' (incomplete)'} | "
              f"{e['initial_energy']:.4g} | {e['ke_bed_trans']:.4f} | {e['ke_bed_rot']:.4f} | {proj:.4f} | "
              f"{el:.4f} | {1 - e['total']:.4f} |")
    print()
    print("Wave attenuation: slope of log(largest grain speed) against log(distance) from the impact point, "
          "fitted from the first bin beyond the projectile out to the wave front (docs/scenes.md B.4); runs "
          "from before the front search (no front method) were fitted through the precursor out to the last "
          "bin above the noise floor:")
    print()
    print("| run | time after impact s | slope | fitted bins (mm) | front mm (how) | precursor bins, median m/s |")
    print("|---|---|---|---|---|---|")
    for n, s in runs.items():
        w = s["observers"].get("wave", {})
        for k in sorted(k for k in w if isinstance(w[k], dict)):
            c = w[k]
            if "front_method" in c:
                used = c.get("bins_used", [])
                fitted = (f"{used[0]:.0f}–{used[-1]:.0f} ({1e3 * c['fit_from']:.1f}–{1e3 * c['fit_to']:.1f})"
                          if used else "–")
                front = "–" if c.get("front") is None else f"{1e3 * c['front']:.1f} ({c['front_method']})"
                pre = c.get("precursor_bins", [])
                pre = f"{len(pre)}, {c['precursor_median']:.2g}" if pre else "none"
            else:
                fitted = f"{c['first_bin']:.0f}–{c['last_bin']:.0f} (through the precursor)"
                front, pre = "–", "–"
            print(f"| {n} | {c['t']:.3g} | {g(c.get('slope'), '{:.2f}')} | {fitted} | {front} | {pre} |")
    print()
    print("Z-model (Maxwell) fits of the grain velocity field, flow centre at the impact point (fixed H0) "
          "and fitted:")
    print()
    print("| run | time after impact s | Z (H0 = 0) | misfit mean/sd deg | Z (fitted H0) | H0 m | misfit mean/sd deg | cells |")
    print("|---|---|---|---|---|---|---|---|")
    for n, s in runs.items():
        zm = s["observers"].get("zmodel", {})
        for k in sorted(k for k in zm if isinstance(zm[k], dict)):
            t = zm[k]
            a, b = t.get("fixed_h0", {}), t.get("fitted_h0", {})
            print(f"| {n} | {t['t']:.3g} | {g(a.get('z'), '{:.2f}')} | {g(a.get('misfit_mean_deg'), '{:.1f}')}/"
                  f"{g(a.get('misfit_sd_deg'), '{:.1f}')} | {g(b.get('z'), '{:.2f}')} | {g(b.get('h0'), '{:.4f}')} | "
                  f"{g(b.get('misfit_mean_deg'), '{:.1f}')}/{g(b.get('misfit_sd_deg'), '{:.1f}')} | {a.get('cells', '–')} |")
    print()
    print("Crater, ejecta and collection at the end of each run:")
    print()
    print("| run | crater depth mm | crater radius mm | ejected grains | ejected volume cm³ | mean/median ejection angle deg | in horn (cyl. 1-5) | collected mg | left through the top |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n, s in runs.items():
        o = s["observers"]
        c, ej, h = o.get("crater", {}), o.get("ejection", {}), o.get("horn", {})
        print(f"| {n} | {1e3 * c.get('depth', 0):.1f} | {1e3 * c.get('radius', 0):.1f} | {ej.get('count', 0)} | "
              f"{1e6 * ej.get('volume', 0):.2f} | {g(ej.get('mean_angle_deg'), '{:.1f}')}/"
              f"{g(ej.get('median_angle_deg'), '{:.1f}')} | {'/'.join(str(x) for x in h.get('segment_grains', []))} | "
              f"{1e6 * h.get('collected_mass', 0):.1f} | {h.get('collected_top_grains', 0)} |")
    p = os.path.join(d, "smallest_pair_restitution.json")
    if os.path.exists(p):
        with open(p) as f:
            r = json.load(f)
        print()
        print(f"Smallest grain pair at the shot's resolution ({r['steps_per_contact']:.2f} steps per contact, "
              f"eps_n = {r['eps_n']}, {r['phases']} entry phases):")
        print()
        print("| pair | mean eps | min | max | mean error | worst error | max overlap / x_max |")
        print("|---|---|---|---|---|---|---|")
        for k, v in r.items():
            if isinstance(v, dict):
                print(f"| {k} | {v['eps_mean']:.4f} | {v['eps_min']:.4f} | {v['eps_max']:.4f} | "
                      f"{100 * v['mean_error']:+.2f} % | {100 * v['worst_abs_error']:.2f} % | {v['max_overlap_over_xmax']:.3f} |")
    print()
    print("Commands:")
    print()
    for n, s in runs.items():
        print(f"- {n}: `{s['_command']}`")


if __name__ == "__main__":
    main()
