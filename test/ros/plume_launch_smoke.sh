#!/usr/bin/env bash
# roslaunch regolith_twin plume_erosion.launch: the node comes up, settles
# (or loads the cached) bed, runs 2 ms of plume, publishes ~status and writes
# summary.json with the erosion figures; the launch stops cleanly. Run by
# ctest (scripts/test), or after a build:
#   bash test/ros/plume_launch_smoke.sh
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ros_env.sh" 11900
log=$(mktemp)
out=$(mktemp -d)
roslaunch -p "$port" regolith_twin plume_erosion.launch duration:=0.002 out:="$out" >"$log" 2>&1 &
launch=$!
msg=""
for _ in $(seq 200); do
  sleep 3
  kill -0 "$launch" 2>/dev/null || break
  [ -n "$msg" ] || msg=$(timeout 10 rostopic echo -n 1 /twin_node/status 2>/dev/null)
  [ -n "$msg" ] && [ -s "$out/summary.json" ] && break
done
kill -INT "$launch" 2>/dev/null
wait "$launch"
if [ -n "$msg" ] && [ -s "$out/summary.json" ] && grep -q '"kind": "plume"' "$out/summary.json" &&
  grep -q '"erosion_rate"' "$out/summary.json"; then
  echo "plume_launch_smoke: plume_erosion.launch runs (~status published, erosion summary written)"
  rm -rf "$out" "$log"
  exit 0
fi
echo "plume_launch_smoke: failed (~status: ${msg:+seen}${msg:-not seen}; summary: $(ls "$out"));" \
  "roslaunch log:" >&2
tail -30 "$log" >&2
exit 1
