#!/usr/bin/env bash
# Convergence order in the time step (docs/benchmarks.md, B4): the default
# MASCOT landing's first 0.5 s after contact (a deterministic early window)
# at fixed k_n and halved time steps. Each run's series row at t = 0.50 s and
# its summary are kept in docs/bench/order/ (skipped when present, so the
# script resumes); bench/report_order.py fits the order.
#
#   bench/order_landing.sh [THREADS] [DT ...]     default: 2, 5e-5 2.5e-5 1.25e-5 6.25e-6 3.125e-6
# The steps divide the 10 ms series interval exactly, so every run samples the
# same instants. k_n stays at the scene's rule value (contact.kn: rule).
# Every run must start from the same relaxed bed: the bed relaxation ends on a
# criterion checked every 20 ms, so beds relaxed at different steps differ.
# The runs of docs/bench/order/ share the bed relaxed at 6.25e-6 s (its
# cached checkpoint copied to the cache files of the other steps). With
# PERTURB=1 the script also runs Δt = 2.5e-5 s with the impact speed raised
# by 1e-11 m/s (the dynamics' own sensitivity, for comparison).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${BIN:-$ROOT/build/devel/lib/regolith_twin}
threads=${1:-2}; shift || true
dts=("$@"); [ ${#dts[@]} -gt 0 ] || dts=(5e-5 2.5e-5 1.25e-5 6.25e-6 3.125e-6)
keep=$ROOT/docs/bench/order
work=${ORDER_WORK:-$ROOT/out/order}
mkdir -p "$keep" "$work"
for dt in "${dts[@]}"; do
  name=dt_$dt
  [ -f "$keep/$name.json" ] && continue
  "$BIN/regolith_sim" "$ROOT/config/mascot_landing.yaml" --out "$work/$name" --threads "$threads" --quiet \
    --set contact.dt="$dt" --set guards.allow_under_resolved=true --set landing.max_after_contact=0.5 \
    | grep '^landing' || true
  cp "$work/$name/series.csv" "$keep/$name.csv"
  cp "$work/$name/summary.json" "$keep/$name.json"
done
if [ "${PERTURB:-0}" = 1 ] && [ ! -f "$keep/perturbed.csv" ]; then
  "$BIN/regolith_sim" "$ROOT/config/mascot_landing.yaml" --out "$work/perturbed" --threads "$threads" --quiet \
    --set contact.dt=2.5e-5 --set guards.allow_under_resolved=true --set landing.max_after_contact=0.5 \
    --set landing.speed=0.19000000001 | grep '^landing' || true
  cp "$work/perturbed/series.csv" "$keep/perturbed.csv"
fi
