#!/usr/bin/env python3
"""Stand-in for regolith_land in the sweep self-test: writes a plausible
summary.json, series.csv and surface.csv from the --set options, without a bed.
FAKE_LAND_FAIL=<substring of --out>: exit 3 (blow-up) for that run;
FAKE_LAND_SLEEP=<s>: sleep before writing; FAKE_LAND_DIE_ONCE: see below."""
import json
import math
import os
import sys
import time

args = sys.argv[1:]
out, sets = None, {}
i = 1
while i < len(args):
    if args[i] == "--out":
        out = args[i + 1]
        i += 2
    elif args[i] == "--set":
        k, v = args[i + 1].split("=", 1)
        sets[k] = v
        i += 2
    elif args[i] in ("--threads", "--cache"):
        i += 2
    else:
        i += 1
started = time.time()
time.sleep(float(os.environ.get("FAKE_LAND_SLEEP", "0")))
# FAKE_LAND_DIE_ONCE=<substring of --out>:<marker file>: the first such run
# is killed (SIGKILL) half-way, after writing part of its output.
die = os.environ.get("FAKE_LAND_DIE_ONCE", "")
if die:
    what, marker = die.split(":", 1)
    if what in out and not os.path.exists(marker):
        open(marker, "w").close()
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "series.csv"), "w") as f:
            f.write("t,x\n0,0\n")
        os.kill(os.getpid(), 9)
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, "stamps.json"), "w") as f:  # when this run was under way
    json.dump({"start": started, "end": time.time()}, f)
ang = float(sets.get("landing.angle_deg", 30))
rep = int(sets.get("landing.repeat", 0))
rim = float(sets.get("landing.rim", 0.3))
mat = sets.get("materials.regolith.preset", "moderate")
att = sets.get("landing.attitude", "BCF")
lift = ang < 50 or rep % 2 == 0  # some runs without lift-off
ratio = (0.3 + 0.004 * ang + 0.02 * rep + (0.05 if mat == "gravel" else 0)) if lift else 0.0
status = "blow_up" if os.environ.get("FAKE_LAND_FAIL") and os.environ["FAKE_LAND_FAIL"] in out else "ok"
with open(os.path.join(out, "series.csv"), "w") as f:
    f.write("t,x,y,z,vx,vy,vz,wx,wy,wz,lowest_corner,grain_contacts,body_contacts,fx,fy,fz,E_lin,E_rot,"
            "max_overlap_ratio,ejected_grains\n")
    for k in range(101):
        t = 0.02 * k
        z = rim + 0.12 - 0.1 * t + (0.12 * t * t if lift else 0.05 * t * t)
        low = z - rim - 0.12
        f.write(f"{t},{0.05 * t},0,{z},0.05,0,{-0.1 + 0.24 * t},0,0.1,0,{low},{3 if low < 0 else 0},0,"
                f"0,0,{10 if low < 0 else 0},{0.1 - 0.02 * t},{0.01 * t},0.01,{k // 10}\n")
with open(os.path.join(out, "surface.csv"), "w") as f:
    f.write("x,y,height\n")
    for ix in range(-20, 21):
        for iy in range(-20, 21):
            x, y = ix * 0.01, iy * 0.01
            if x * x + y * y < 0.2 ** 2:
                f.write(f"{x},{y},{-0.02 * math.exp(-(x * x + y * y) / 0.005)}\n")
summary = {
    "scenario": "fake", "status": status,
    "input": {"attitude": att, "angle_deg": ang, "speed": 0.19, "gravity": float(sets.get("landing.g", 2.5e-4)),
              "repeat": rep},
    "bed": {"grains": 100, "trim_plane": rim, "packing_fraction": 0.6},
    "outcome": {"contact": True, "lifted_off": lift, "t_contact": 0.4, "t_liftoff": 1.2 if lift else 0,
                "speed_ratio": ratio, "travel_distance": 10 * ratio, "max_penetration": 0.01 + 0.0001 * ang,
                "collision_duration": 0.8 if lift else 0},
    "run": {"wall_seconds": 0.01},
}
with open(os.path.join(out, "summary.json"), "w") as f:
    json.dump(summary, f)
sys.exit(0 if status == "ok" else 3)
