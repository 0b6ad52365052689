#!/usr/bin/env bash
# A scene's launch file end to end: the node comes up, prepares the scene
# (or loads its cached bed), publishes TOPIC, writes summary.json with
# PATTERN in it at the run end, and the launch stops cleanly. Run by ctest
# (scripts/test), or after a build:
#   bash test/ros/launch_summary_smoke.sh BASE_PORT LAUNCH TOPIC PATTERN [ARG:=VALUE ...]
#   e.g. bash test/ros/launch_summary_smoke.sh 12000 plume_erosion.launch /twin_node/status '"erosion_rate"' duration:=0.002
set -uo pipefail
[ $# -ge 4 ] || { echo "usage: $0 BASE_PORT LAUNCH TOPIC PATTERN [ARG:=VALUE ...]" >&2; exit 2; }
base=$1 launch_file=$2 topic=$3 pattern=$4
shift 4
# Under ThreadSanitizer the node runs OpenMP on one thread, as every node test
# does there (docs/validation/reliability.md, "Sanitizers"): libgomp is not
# instrumented, so the end of a parallel region is invisible to it and a
# later write by the main thread is reported as a race.
if [ "${REGOLITH_SANITIZER:-}" = thread ]; then
  args=()
  for a in "$@"; do case $a in threads:=*) ;; *) args+=("$a") ;; esac; done
  set -- "${args[@]}" threads:=1
fi
source "$(dirname "${BASH_SOURCE[0]}")/ros_env.sh" "$base"
log=$(mktemp)
out=$(mktemp -d)
roslaunch -p "$port" regolith_twin "$launch_file" "$@" out:="$out" >"$log" 2>&1 &
launch=$!
msg=""
for _ in $(seq 200); do
  sleep 3
  kill -0 "$launch" 2>/dev/null || break
  [ -n "$msg" ] || msg=$(timeout 10 rostopic echo -n 1 "$topic" 2>/dev/null)
  [ -n "$msg" ] && [ -s "$out/summary.json" ] && break
done
kill -INT "$launch" 2>/dev/null
wait "$launch"
if [ -n "$msg" ] && [ -s "$out/summary.json" ] && grep -q "$pattern" "$out/summary.json"; then
  echo "launch smoke: $launch_file runs ($topic published, summary with $pattern written)"
  rm -rf "$out" "$log"
  exit 0
fi
echo "launch smoke: $launch_file failed ($topic: ${msg:+seen}${msg:-not seen}; summary: $(ls "$out"));" \
  "roslaunch log:" >&2
tail -30 "$log" >&2
exit 1
