#!/usr/bin/env bash
# The README's roslaunch command on the shipped bed: the node comes up, the
# lander reaches the bed (landing phase "collision"), and the launch stops
# cleanly. Run after scripts/run or scripts/test (they build the node):
#   bash test/ros/launch_smoke.sh
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ros_env.sh" 11900
log=$(mktemp)
roslaunch -p "$port" regolith_twin mascot_landing.launch threads:=1 out:="$(mktemp -d)" >"$log" 2>&1 &
launch=$!
phase=""
for _ in $(seq 120); do
  sleep 3
  phase=$(timeout 10 rostopic echo -n 1 /twin_node/landing 2>/dev/null | sed -n 's/^phase: "\(.*\)"/\1/p')
  [ "$phase" = collision ] || [ "$phase" = flight ] || [ "$phase" = ended ] && break
done
kill -INT "$launch" 2>/dev/null
wait "$launch"
if [ "$phase" = collision ] || [ "$phase" = flight ] || [ "$phase" = ended ]; then
  echo "launch_smoke: mascot_landing.launch runs (landing phase: $phase)"
  exit 0
fi
echo "launch_smoke: the landing did not reach the bed (phase '$phase'); roslaunch log:" >&2
tail -30 "$log" >&2
exit 1
