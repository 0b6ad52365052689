#!/usr/bin/env bash
# Convergence order in the time step (docs/bench/order.md): the default
# MASCOT landing's first 0.5 s after contact (a deterministic early window)
# at fixed k_n and halved time steps. Each run's series (every 10 ms) and
# summary are kept in results/bench/order/ (skipped when present, so the script
# resumes); bench/report_order.py reports the errors and orders.
#
#   bench/order_landing.sh [THREADS] [DT ...]     default: 2, 6.25e-6 5e-5 2.5e-5 1.25e-5
# The first step is the reference: its run relaxes the bed, and every other
# run starts from that relaxed bed (--relaxed-bed; a bed relaxed at another
# step ends its relaxation at another instant, so it differs). The steps
# divide the 10 ms series interval exactly, so every run samples the same
# instants. k_n stays at the scene's rule value (contact.kn: rule). With
# PERTURB=1 the script also runs Δt = 2.5e-5 s with the impact speed raised
# by 1e-11 m/s (the dynamics' own sensitivity, for comparison).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${BIN:-$ROOT/build/devel/lib/regolith_twin}
threads=${1:-2}; shift || true
dts=("$@"); [ ${#dts[@]} -gt 0 ] || dts=(6.25e-6 5e-5 2.5e-5 1.25e-5)
keep=$ROOT/results/bench/order
work=${ORDER_WORK:-$ROOT/out/order}
mkdir -p "$keep" "$work"
common=(--threads "$threads" --quiet --set guards.allow_under_resolved=true --set landing.max_after_contact=0.5
  --set landing.active_radius=0.45)  # the active zone, as when the study was run
land() {  # name dt [extra args]
  local name=$1 dt=$2
  shift 2
  "$BIN/regolith_sim" "$ROOT/config/mascot_landing.yaml" --out "$work/$name" "${common[@]}" \
    --set contact.dt="$dt" "$@" | grep '^landing' || true
}
ref=${dts[0]}
[ -f "$work/dt_$ref/summary.json" ] || land "dt_$ref" "$ref"
bed=$(/usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['bed']['cache'])" "$work/dt_$ref/summary.json")
for dt in "${dts[@]}"; do
  name=dt_$dt
  [ -f "$keep/$name.json" ] && continue
  [ "$dt" = "$ref" ] || land "$name" "$dt" --relaxed-bed "$bed"
  cp "$work/$name/series.csv" "$keep/$name.csv"
  cp "$work/$name/summary.json" "$keep/$name.json"
done
if [ "${PERTURB:-0}" = 1 ] && [ ! -f "$keep/perturbed.csv" ]; then
  land perturbed 2.5e-5 --relaxed-bed "$bed" --set landing.speed=0.19000000001
  cp "$work/perturbed/series.csv" "$keep/perturbed.csv"
fi
