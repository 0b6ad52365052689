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
  head -1 "$work/$name/series.csv" > "$keep/$name.csv"
  awk -F, 'NR > 1 && $1 > 0.4999 && $1 < 0.5001' "$work/$name/series.csv" >> "$keep/$name.csv"
  cp "$work/$name/summary.json" "$keep/$name.json"
done
