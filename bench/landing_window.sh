#!/usr/bin/env bash
# The default MASCOT landing up to a fixed time after first contact, once per
# setting, in rounds (the settings in turn, their order reversed every other
# round): wall time and the lander's state at the window's end, for the
# sleeping and active-zone settings side by side (docs/bench/b2_sleeping.md), at the 30 steps
# per contact the scene had when they were measured.
#
#   bench/landing_window.sh OUT_DIR [WINDOW_S] [ROUNDS] [THREADS] [SETTING...]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${BIN:-$ROOT/build/devel/lib/regolith_twin}
out=${1:?output folder}
window=${2:-0.3}
rounds=${3:-1}
threads=${4:-2}
mkdir -p "$out"
declare -A SET=(
  [zone]="--set landing.active_radius=0.45"
  [free]="--set landing.active_radius=0"
  [sleep_default]="--set landing.active_radius=0 --set sleep.enabled=true"
  [sleep_v1]="--set landing.active_radius=0 --set sleep.enabled=true --set sleep.force=1e9 --set sleep.speed=1"
  [sleep_v5]="--set landing.active_radius=0 --set sleep.enabled=true --set sleep.force=1e9 --set sleep.speed=5"
  [zone_sleep_v1]="--set landing.active_radius=0.45 --set sleep.enabled=true --set sleep.force=1e9 --set sleep.speed=1"
  [zone_free_flight]="--set landing.active_radius=0.45 --set free_flight.enabled=true"
)
names=("${@:5}")
((${#names[@]})) || names=(zone free sleep_default sleep_v1 sleep_v5 zone_sleep_v1)
for ((r = 1; r <= rounds; ++r)); do
  order=("${names[@]}")
  if ((r % 2 == 0)); then order=($(printf '%s\n' "${names[@]}" | tac)); fi
  for name in "${order[@]}"; do
    dir=$out/$name.r$r
    # shellcheck disable=SC2086
    "$BIN/regolith_sim" "$ROOT/config/mascot_landing.yaml" --out "$dir" --threads "$threads" --quiet \
      --set landing.max_after_contact="$window" --set contact.steps_per_contact=30 ${SET[$name]} >/dev/null
    /usr/bin/python3 - "$dir" "$name" "$r" <<'PY'
import json, sys, csv
d, name, r = sys.argv[1:]
s = json.load(open(d + "/summary.json"))
rows = list(csv.DictReader(open(d + "/series.csv")))
last = rows[-1]
keys = ["vx", "vy", "vz"]
v = sum(float(last[k]) ** 2 for k in keys) ** 0.5
sl = s["run"].get("sleep", {})
print(f"{name} round {r}: wall {s['run']['wall_seconds']:.2f} s, steps {s['run']['steps']:.0f}, "
      f"rebuilds {s['run'].get('rebuilds', 0):.0f}, body rebuilds {s['run'].get('body_rebuilds', 0):.0f}, "
      f"mean awake {sl.get('mean_awake', float('nan')):.0f}, lander speed at end {v:.5f} m/s, "
      f"penetration {s['outcome']['max_penetration']:.5f} m", flush=True)
PY
  done
done | tee "$out/results.txt"
