#!/usr/bin/env python3
"""Plots and a short report of a recorded twin run (a rosbag), for operators
without rqt.

usage: plot_bag BAG [--out DIR] [--ns /twin_node]

Reads the twin's topics from BAG and writes into DIR (default: BAG without
.bag, plus _report):
  trajectory.png  every free body's centre of mass: height and horizontal path
  speed.png       centre-of-mass speed and spin against sim time
  contacts.png    contact force on each body (|F|) and contact point count
  report.md       the recorded outcome (last ~landing message), run figures
                  (sim time, steps, real-time factor) and the plots
"""
import argparse
import math
import os
import sys

import rosbag  # noqa: E402
from plots import pyplot, save_figure  # noqa: E402

plt = pyplot()


def two_panels(series, path, left, right, equal_right=False):
    """One figure of two panels, each ((x key, label), (y key, label), title), a line per body."""
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    for axis, ((xk, xl), (yk, yl), title) in zip(ax, (left, right)):
        for name, d in series.items():
            axis.plot(d[xk], d[yk], label=name)
        axis.set(xlabel=xl, ylabel=yl, title=title)
        axis.grid(alpha=0.3)
        axis.legend()
    if equal_right:
        ax[1].set_aspect("equal", adjustable="datalim")
    save_figure(fig, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bag")
    ap.add_argument("--out")
    ap.add_argument("--ns", default="/twin_node")
    a = ap.parse_args()
    if not os.path.exists(a.bag):
        sys.exit("plot_bag: %s: no such file" % a.bag)
    out = a.out or (a.bag[:-4] if a.bag.endswith(".bag") else a.bag) + "_report"
    os.makedirs(out, exist_ok=True)
    try:
        bag = rosbag.Bag(a.bag)
    except Exception as e:  # a truncated or foreign file
        sys.exit("plot_bag: %s: cannot read the bag (%s)" % (a.bag, e))

    bodies = {}  # name -> lists
    landing = None
    status = []
    with bag:
        for topic, msg, _ in bag.read_messages(topics=[a.ns + "/body_states", a.ns + "/landing", a.ns + "/status"]):
            if topic.endswith("/body_states"):
                t = msg.header.stamp.to_sec()
                for b in msg.bodies:
                    d = bodies.setdefault(b.name, {k: [] for k in ("t", "x", "y", "z", "v", "w", "f", "n")})
                    c, v, w, f = b.center_of_mass, b.twist.linear, b.twist.angular, b.wrench.force
                    d["t"].append(t)
                    d["x"].append(c.x)
                    d["y"].append(c.y)
                    d["z"].append(c.z)
                    d["v"].append(math.sqrt(v.x ** 2 + v.y ** 2 + v.z ** 2))
                    d["w"].append(math.sqrt(w.x ** 2 + w.y ** 2 + w.z ** 2))
                    d["f"].append(math.sqrt(f.x ** 2 + f.y ** 2 + f.z ** 2))
                    d["n"].append(b.contacts)
            elif topic.endswith("/landing"):
                landing = msg
            else:
                status.append(msg)
    moving = {k: d for k, d in bodies.items() if len(d["t"]) and (max(d["v"]) > 0 or max(d["w"]) > 0)}
    if not moving:
        sys.exit("plot_bag: %s: no moving body on %s/body_states" % (a.bag, a.ns))

    t = ("t", "sim time (s)")
    two_panels(moving, os.path.join(out, "trajectory.png"),
               (t, ("z", "centre of mass z (m)"), "height"), (("x", "x (m)"), ("y", "y (m)"), "horizontal path"),
               equal_right=True)
    two_panels(moving, os.path.join(out, "speed.png"),
               (t, ("v", "speed (m/s)"), "centre-of-mass speed"), (t, ("w", "|omega| (rad/s)"), "spin"))
    two_panels(moving, os.path.join(out, "contacts.png"),
               (t, ("f", "|F| (N)"), "contact force"), (t, ("n", "points"), "contact points"))

    lines = ["# Recorded run: %s" % os.path.basename(a.bag), ""]
    any_d = next(iter(moving.values()))
    lines.append("Sim time %.4g to %.4g s, %d body-state messages." % (any_d["t"][0], any_d["t"][-1], len(any_d["t"])))
    if status:
        s = status[-1]
        lines.append("Last status: step %d, dt %.3g s, %d grains (%d active), real-time factor %.3g." %
                     (s.step, s.dt, s.grains, s.active_grains, s.realtime_factor))
    lines.append("")
    if landing is not None:
        lines += ["## Landing outcome (last ~landing message)", "", "| quantity | value |", "|---|---|"]
        for key, unit in (("phase", ""), ("ended_by", ""), ("lifted_off", ""), ("t_contact", "s"), ("t_liftoff", "s"),
                          ("v_in", "m/s"), ("v_out", "m/s"), ("speed_ratio", ""), ("energy_ratio", ""),
                          ("angle_out_deg", "deg"), ("spin_out", "rad/s"), ("collision_duration", "s"),
                          ("max_penetration", "m"), ("travel_distance", "m"), ("travel_time", "s"),
                          ("ejected_volume", "m^3"), ("ejected_grains", "")):
            v = getattr(landing, key)
            text = ("%.4g" % v) if isinstance(v, float) else str(v)
            lines.append("| %s | %s %s |" % (key, text, unit))
        lines.append("")
    lines += ["## Plots", "", "![trajectory](trajectory.png)", "", "![speed](speed.png)", "",
              "![contacts](contacts.png)", ""]
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write("\n".join(lines))
    print("report: %s/report.md (plots: trajectory.png, speed.png, contacts.png)" % out)


if __name__ == "__main__":
    main()
