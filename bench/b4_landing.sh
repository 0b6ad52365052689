#!/usr/bin/env bash
# Paired landings on perturbed beds (docs/bench/b4_landing.md): the default
# MASCOT landing with one named setting per run, repeats FIRST..LAST (repeat 0
# is the bed as prepared, 1.. rotated beds with the aim shifted). A run whose
# summary is already in results/bench/b4/ is skipped, so the script resumes; each
# finished run's summary.json is copied there (small, kept in git).
#
#   bench/b4_landing.sh SETTING FIRST LAST [THREADS]     e.g. bench/b4_landing.sh ref 1 7
#   settings: ref (the default scene), or a profile of config/profiles/: preview,
#   coarse2, preview_coarse2, sleep
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${BIN:-$ROOT/build/devel/lib/regolith_twin}
setting=${1:?setting}; first=${2:?first repeat}; last=${3:?last repeat}; threads=${4:-2}
case $setting in
  ref) args=(--set landing.active_radius=0.45 --set contact.steps_per_contact=30) ;;  # the default of the time
  preview|coarse2|preview_coarse2|sleep) args=(--profile "$setting") ;;
  *) echo "b4_landing: unknown setting '$setting'" >&2; exit 2 ;;
esac
keep=$ROOT/results/bench/b4
work=${B4_WORK:-$ROOT/out/b4}
mkdir -p "$keep" "$work"
for ((r = first; r <= last; ++r)); do
  name=${setting}_r$r
  [ -f "$keep/$name.json" ] && continue
  "$BIN/regolith_sim" "$ROOT/config/mascot_landing.yaml" --out "$work/$name" --threads "$threads" --quiet \
    "${args[@]}" --set landing.repeat="$r" | grep '^landing' || true
  cp "$work/$name/summary.json" "$keep/$name.json"
done
