#!/usr/bin/env bash
# roslaunch regolith_twin sampler.launch on the shipped bed: the node comes
# up, relaxes (or loads the cached) bed, fires, publishes ~collected_mass
# and writes summary.json at the end of a 0.2 ms shot; the launch stops
# cleanly. Run by ctest (scripts/test), or after a build:
#   bash test/ros/sampler_launch_smoke.sh
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ros_env.sh" 11800
log=$(mktemp)
out=$(mktemp -d)
roslaunch -p "$port" regolith_twin sampler.launch threads:=2 duration:=0.0002 out:="$out" >"$log" 2>&1 &
launch=$!
msg=""
for _ in $(seq 200); do
  sleep 3
  kill -0 "$launch" 2>/dev/null || break
  [ -n "$msg" ] || msg=$(timeout 10 rostopic echo -n 1 /twin_node/collected_mass 2>/dev/null)
  [ -n "$msg" ] && [ -s "$out/summary.json" ] && break
done
kill -INT "$launch" 2>/dev/null
wait "$launch"
if [ -n "$msg" ] && [ -s "$out/summary.json" ] && grep -q '"impact": true' "$out/summary.json"; then
  echo "sampler_launch_smoke: sampler.launch runs (~collected_mass published, impact seen, summary written)"
  rm -rf "$out" "$log"
  exit 0
fi
echo "sampler_launch_smoke: failed (~collected_mass: ${msg:+seen}${msg:-not seen}; summary: $(ls "$out"));" \
  "roslaunch log:" >&2
tail -30 "$log" >&2
exit 1
