#!/usr/bin/python3
"""Plot the collision verification tables written by regolith_verify.

usage: plot_verification.py CSV_DIR PNG_DIR [REFERENCE_CSV]

Reads restitution_convergence.csv, chung_ooi_test3.csv and chung_ooi_test4.csv
from CSV_DIR and writes restitution_convergence.png, chung_ooi_test3.png and
chung_ooi_test4.png into PNG_DIR. Test 4 is drawn against the measurements of
Kharaz, Gorham & Salman (2001), read from REFERENCE_CSV (default
docs/validation/kharaz2001_oblique_impact.csv; its header names the source).
"""
import argparse
import os
import sys


sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from csv_columns import read_rows as read_csv  # noqa: E402
from plots import pyplot, save_figure  # noqa: E402

plt = pyplot()


DEFAULT_REFERENCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "validation",
                                 "kharaz2001_oblique_impact.csv")


def read_reference(path):
    """Measured test 4 curves: {quantity: ([incidence_deg], [value])}."""
    out = {}
    if not path or not os.path.exists(path):
        return out
    for r in read_csv(path):
        xs, ys = out.setdefault(r["quantity"], ([], []))
        xs.append(float(r["incidence_deg"]))
        ys.append(float(r["value"]))
    return out


def plot_convergence(rows, out):
    pairs = ["grain-grain", "grain-wall"]
    # The eps_n of the assertions (the CSV may hold more).
    eps_values = [e for e in (0.1, 0.5, 0.9, 1.0) if any(float(r["eps_n"]) == e for r in rows)]
    colours = ["tab:red", "tab:blue", "tab:green", "tab:purple"]
    fig, axes = plt.subplots(2, 2, figsize=(12, 9.5), sharex=True)
    floor = 1e-12
    for col, pair in enumerate(pairs):
        for row, (key, title) in enumerate(
            [("mean_abs_error", "mean over entry phases of |eps - eps_n| / eps_n"),
             ("mean_error", "|phase-mean eps - eps_n| / eps_n")]):
            ax = axes[row][col]
            for colour, eps in zip(colours, eps_values):
                sel = [r for r in rows if r["pair"] == pair and float(r["eps_n"]) == eps]
                sel.sort(key=lambda r: float(r["N"]))
                n = [float(r["N"]) for r in sel]
                err = [max(abs(float(r[key])), floor) for r in sel]
                if not n or max(err) <= floor:
                    continue
                ax.loglog(n, err, "-o", color=colour, ms=4, lw=1.3, label=f"eps_n={eps:g}")
            # Reference slopes through a visible point.
            n_ref = [8, 240]
            ax.loglog(n_ref, [0.2 * (8 / x) for x in n_ref], "k-", lw=2.2, alpha=0.45, label="slope -1")
            if row == 1:
                ax.loglog(n_ref, [0.05 * (8 / x) ** 2 for x in n_ref], "k:", lw=2.2, alpha=0.6, label="slope -2")
            ax.axvline(30, color="0.6", lw=0.8, ls=":")
            ax.set_title(f"{pair}: {title}", fontsize=10)
            ax.set_ylim(1e-7, 1.0)
            ax.grid(True, which="both", alpha=0.25)
            if row == 1:
                ax.set_xlabel("N  (dt = pi sqrt(m_p / 2 k_n) / N)")
            if col == 0:
                ax.set_ylabel("relative restitution error")
    handles, labels = axes[1][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=6, fontsize=9, frameon=False)
    fig.suptitle("Linear law: measured normal restitution vs steps per contact (rt::step, "
                 f"{rows[0]['phases']} entry phases per point)", fontsize=11)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    fig.savefig(out, dpi=110)
    plt.close(fig)


def plot_test3(rows, out):
    e_in = [float(r["e_in"]) for r in rows]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.6))
    ax.plot([0, 1.05], [0, 1.05], "k-", lw=1, alpha=0.5, label="e_out = e_in")
    ax.plot(e_in, [float(r["e_out_model"]) for r in rows], "o", ms=7, mfc="none", label="engine, docs/model.md §3 prefactor")
    ax.plot(e_in, [float(r["e_out_calibrated"]) for r in rows], "x", ms=7, label="engine, calibrated prefactor")
    ax.plot(e_in, [float(r["e_ode_model"]) for r in rows], "+", ms=9, label="continuous time, docs/model.md §3 prefactor")
    ax.set_xlabel("input restitution e_in")
    ax.set_ylabel("measured restitution e_out")
    ax.set_xlim(0.1, 1.05)
    ax.set_ylim(0.1, 1.05)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Chung & Ooi test 3: aluminium oxide on a rigid plane, 3.9 m/s", fontsize=10)
    ax2.plot(e_in, [float(r["dev_model_pct"]) for r in rows], "o-", mfc="none", label="docs/model.md §3 prefactor")
    ax2.plot(e_in, [float(r["dev_calibrated_pct"]) for r in rows], "x--", label="calibrated prefactor")
    ax2.axhspan(-2, 2, color="g", alpha=0.08, label="+-2 %")
    ax2.set_xlabel("input restitution e_in")
    ax2.set_ylabel("(e_out - e_in) / e_in  [%]")
    steps = [float(r["steps_per_contact"]) for r in rows]
    ax2.set_title(f"deviation ({min(steps):.0f}-{max(steps):.0f} steps per contact)", fontsize=10)
    lim = max(0.5, max(abs(float(r["dev_model_pct"])) for r in rows) * 1.3)
    ax2.set_ylim(-lim, lim)
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=8)
    save_figure(fig, out)


# Kharaz et al. (2001): 5 mm spheres (R = 2.5 mm) at 3.9 m/s, as test 4.
TEST4_RADIUS = 0.0025
TEST4_SPEED = 3.9


def plot_test4(rows, out, ref=None):
    ref = ref or {}
    ang = [float(r["angle_deg"]) for r in rows]
    slide = [r for r in rows]
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    panels = [
        ("vt_ratio", "vt_ratio_rigid", "vt_ratio_sliding", "vt_ratio_fine", "v_t' / v_t (centre of mass)"),
        ("omega_r_over_v", "omega_r_over_v_rigid", "omega_r_over_v_sliding", "omega_r_over_v_fine",
         "omega' R / v"),
    ]
    for ax, (key, rigid, sliding, fine, ylabel) in zip(axes[:2], panels):
        ax.plot(ang, [float(r[sliding]) for r in slide], "k:", lw=1.2, label="gross sliding line")
        ax.plot(ang, [float(r[rigid]) for r in rows], "k-", lw=1.0, alpha=0.6, label="rigid-body Coulomb theory")
        ax.plot(ang, [float(r[fine]) for r in rows], "-", color="tab:orange", lw=1.5,
                label="engine, 8x finer dt")
        ax.plot(ang, [float(r[key]) for r in rows], "o", color="tab:blue", mfc="none", ms=6,
                label=f"engine ({float(rows[0]['steps_per_contact']):.0f} steps/contact)")
        if key == "vt_ratio" and "vt_ratio" in ref:
            ax.plot(*ref["vt_ratio"], "D", color="k", ms=5, label="measured, Kharaz et al. 2001")
        if key == "omega_r_over_v" and "omega" in ref:
            xs, ys = ref["omega"]
            ax.plot(xs, [w * TEST4_RADIUS / TEST4_SPEED for w in ys], "D", color="k", ms=5,
                    label="measured, Kharaz et al. 2001")
        ax.set_xlabel("incidence angle from the normal [deg]")
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    axes[0].set_ylim(-0.2, 1.05)
    axes[1].set_ylim(0, 0.5)
    axes[0].legend(fontsize=8, loc="lower right")
    axes[1].legend(fontsize=8, loc="upper right")
    ax = axes[2]
    ax.plot([0, 90], [0, 90], "k-", lw=0.6, alpha=0.4, label="rebound = incidence")
    ax.plot(ang, [float(r["rebound_deg_rigid"]) for r in rows], "k-", lw=1.0, alpha=0.6,
            label="centre, rigid-body theory")
    ax.plot(ang, [float(r["rebound_deg"]) for r in rows], "o", color="tab:blue", mfc="none", ms=6,
            label="centre, engine")
    if "rebound_deg" in ref:
        ax.plot(*ref["rebound_deg"], "D", color="k", ms=5, label="centre, measured (Kharaz et al. 2001)")
    ax.plot(ang, [float(r["patch_rebound_deg_rigid"]) for r in rows], "k--", lw=1.0, alpha=0.6,
            label="contact patch, rigid-body theory")
    ax.plot(ang, [float(r["patch_rebound_deg"]) for r in rows], "s", color="tab:red", mfc="none", ms=5,
            label="contact patch, engine")
    ax.set_xlabel("incidence angle from the normal [deg]")
    ax.set_ylabel("rebound angle [deg]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    onset = [float(r["angle_deg"]) for r in rows if r["gross_sliding_rigid"] == "1"]
    for a in axes:
        if onset:
            a.axvspan(min(onset), 90, color="g", alpha=0.05)
        a.set_xlim(0, 90)
    fig.suptitle("Chung & Ooi test 4: aluminium oxide sphere on a rigid plane, 3.9 m/s, mu = 0.092, e = 0.98 "
                 "(shaded: gross sliding in rigid-body theory)\ndiamonds: measurements of Kharaz, Gorham & Salman (2001), the experiment the test reproduces",
                 fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.91))
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("src", metavar="CSV_DIR")
    p.add_argument("dst", metavar="PNG_DIR")
    p.add_argument("reference", metavar="REFERENCE_CSV", nargs="?", default=DEFAULT_REFERENCE)
    a = p.parse_args(argv)
    src, dst = a.src, a.dst
    ref = read_reference(a.reference)
    os.makedirs(dst, exist_ok=True)
    plot_convergence(read_csv(os.path.join(src, "restitution_convergence.csv")),
                     os.path.join(dst, "restitution_convergence.png"))
    plot_test3(read_csv(os.path.join(src, "chung_ooi_test3.csv")), os.path.join(dst, "chung_ooi_test3.png"))
    plot_test4(read_csv(os.path.join(src, "chung_ooi_test4.csv")), os.path.join(dst, "chung_ooi_test4.png"), ref)
    for name in ("restitution_convergence.png", "chung_ooi_test3.png", "chung_ooi_test4.png"):
        print(os.path.join(dst, name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
