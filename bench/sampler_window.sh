#!/usr/bin/env bash
# The default sampler shot (config/sampler_shot.yaml, 300 m/s) up to a fixed
# time after firing, once per setting, in rounds (the settings in turn, their
# order reversed every other round): wall time, steps and the shot's outputs
# at the window's end, for the savings alone and together (docs/bench/b3_schedule.md).
#
#   bench/sampler_window.sh OUT_DIR [WINDOW_S] [ROUNDS] [THREADS] [SETTING...]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${BIN:-$ROOT/build/devel/lib/regolith_twin}
out=${1:?output folder}
window=${2:-0.005}
rounds=${3:-1}
threads=${4:-2}
shift $(($# < 4 ? $# : 4))
declare -A SET=(
  [off]=""
  [schedule]="--set schedule.enabled=true"
  [sleep]="--set sleep.enabled=true --set sleep.force=1e9 --set sleep.speed=5"
  [free_flight]="--set free_flight.enabled=true"
  [all]="--set schedule.enabled=true --set sleep.enabled=true --set sleep.force=1e9 --set sleep.speed=5"
)
names=("$@")
((${#names[@]})) || names=(off schedule sleep all)
mkdir -p "$out"
for ((r = 1; r <= rounds; ++r)); do
  order=("${names[@]}")
  if ((r % 2 == 0)); then order=($(printf '%s\n' "${names[@]}" | tac)); fi
  for name in "${order[@]}"; do
    dir=$out/$name.r$r
    # shellcheck disable=SC2086
    "$BIN/regolith_sim" "$ROOT/config/sampler_shot.yaml" --out "$dir" --threads "$threads" --quiet \
      --set sampler.duration="$window" ${SET[$name]} >/dev/null
    /usr/bin/python3 - "$dir" "$name" "$r" <<'PY'
import json, sys, csv
d, name, r = sys.argv[1:]
s = json.load(open(d + "/summary.json"))
last = list(csv.DictReader(open(d + "/series.csv")))[-1]
run = s["run"]
seg = "/".join(str(int(float(last[f"seg{k}_n"]))) for k in range(1, 6))
sl, sc = run.get("sleep", {}), run.get("schedule", {})
print(f"{name} round {r}: wall {run['wall_seconds']:.2f} s, steps {run['steps']:.0f}, "
      f"rebuilds {run.get('rebuilds', 0):.0f}, free max {run.get('free_flight', {}).get('free_grains_max', 0):.0f}, "
      f"dt max {sc.get('dt_max', run['dt']):.3g} s, mean awake {sl.get('mean_awake', run['grains']):.0f}, "
      f"horn segments {seg}, crater depth {float(last['crater_depth']) * 1e3:.3f} mm, "
      f"ejected {int(float(last['ejected_grains']))}, collected {float(last['collected_mass']) * 1e6:.1f} mg, "
      f"injected {sc.get('injected_energy', 0):.3g} J, released {sc.get('released_energy', 0):.3g} J", flush=True)
PY
  done
done | tee -a "$out/results.txt"
