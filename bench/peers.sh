#!/usr/bin/env bash
# Peer benchmark for scene B1: runs LAMMPS and LIGGGHTS on the same granular
# scene that the regolith_twin engine is measured on, and reports speed and a
# physics cross-check in machine-readable lines.
#
# Scene B1
#   * 45,000 spheres, d = 5 mm, rho = 2500 kg/m^3, initially on a simple
#     cubic lattice (spacing 5.25 mm, 30 x 30 x 50 sites, origin offset by
#     half a spacing) with a uniform +-0.1 mm x/y jitter, seed 12345
#     (bench/make_b1_bed.py -> bench/b1_bed.data)
#   * plane walls x = 0, x = 0.1575, y = 0, y = 0.1575, z = 0 (open top),
#     gravity 9.81 m/s^2 along -z
#   * linear spring-dashpot with tangential history: k_n = 2000 N/m,
#     k_t = 571 N/m, e_n = 0.5 ->
#     C_n = -2 ln e_n sqrt(k_n m* / (pi^2 + ln^2 e_n)) (m* = reduced mass,
#     m_i for a wall contact), C_t = C_n / 2, Coulomb mu = 0.5, no rolling
#     resistance, no cohesion; walls use the same law
#   * dt = 2e-5 s, neighbour skin 0.25 d, rebuild check every step
#   * settle 30,000 steps (untimed, once per engine, cached), then restart
#     from the settled state and time 3 blocks of 2,000 steps
#
# Usage: bench/peers.sh COMMAND [ARGS]
#   bed                    create bench/b1_bed.data if it is missing
#   settle ENGINE|all      settle once per engine (cached; re-run only when the
#                          bed, the deck or the step count changed)
#   time ENGINE [RANKS]    timed run (RANKS default 1) from the settled state;
#                          prints RESULT and CHECK lines
#   check ENGINE           CHECK line of the cached settled state
#   versions               VERSION lines of both peers
#   micro                  build and run the OpenMP microbenchmark
#   triad [MB]             build and run the one-core memory triad (default 18 MB)
#   all                    bed, versions, settle all, time at 1 and 2 ranks, micro
# ENGINE is lammps or liggghts.
#
# Output lines:
#   RESULT engine=E ranks=N block=K steps=S seconds=T particle_steps_per_s=P
#   CHECK  engine=E stage=final ranks=N n=.. step=.. bed_height=.. z_mean=..
#          coordination=.. contacts=.. wall_contacts_per_grain=.. ke=.. ke_rot=..
#          (definitions: bench/postprocess_b1.py)
#   SETTLE engine=E steps=S seconds=T cached=yes|no
#   VERSION engine=E version=V package=DEBVERSION
#   LOAD   engine=E ranks=N loadavg_before=L1 loadavg_after=L2
#          (1-minute load average around a timed run: timings taken while
#          the 2-core machine is busy with other work are not comparable)
#
# How the peers realise the contact law (details in the decks):
#   both take the normal/tangential damping as a rate per unit effective mass
#   (LAMMPS pair gran/hooke/history gamma_n, LIGGGHTS hooke/stiffness gamman
#   with absolute_damping off), effective mass m_i m_j/(m_i+m_j) for pairs and
#   m_i at walls, so gamma_n = C_n / m* and the walls get their own value
#   (pair 2130.5 1/s, wall 1506.5 1/s; gamma_t = gamma_n / 2).
#   Remaining difference: when the Coulomb limit is reached, LAMMPS caps
#   |k_t s + m_eff gamma_t v_t| at mu |F_n|, LIGGGHTS caps |k_t s| and drops
#   the tangential damping term while sliding.
#
# Environment:
#   B1_CACHE         cache directory (default bench/.cache, git-ignored)
#   B1_BED           bed data file (default bench/b1_bed.data)
#   B1_SETTLE_STEPS  settling steps (default 30000; other values get their
#                    own cache entry, handy for quick trials)
#   B1_BLOCK_STEPS   steps per timed block (default 2000)
#   B1_BLOCKS        timed blocks per run (default 3; scripts/bench runs 1 per
#                    engine in each of several interleaved rounds)
#   LMP_BIN          LAMMPS executable (default lmp)
#   LIGGGHTS_BIN     LIGGGHTS executable (default liggghts)
#   PYTHON           Python 3 with numpy (default /usr/bin/python3 if present)
#   MPIRUN           MPI launcher (default mpirun if on PATH; without it only
#                    1 rank is possible)

set -euo pipefail

BENCH_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
B1_CACHE="${B1_CACHE:-$BENCH_DIR/.cache}"
B1_BED="${B1_BED:-$BENCH_DIR/b1_bed.data}"
B1_SETTLE_STEPS="${B1_SETTLE_STEPS:-30000}"
B1_BLOCK_STEPS="${B1_BLOCK_STEPS:-2000}"
B1_BLOCKS="${B1_BLOCKS:-3}"
B1_NATOMS=45000
LMP_BIN="${LMP_BIN:-lmp}"
LIGGGHTS_BIN="${LIGGGHTS_BIN:-liggghts}"
if [[ -z "${PYTHON:-}" ]]; then
  if [[ -x /usr/bin/python3 ]]; then PYTHON=/usr/bin/python3; else PYTHON=python3; fi
fi
MPIRUN="${MPIRUN:-$(command -v mpirun || true)}"

# Open MPI probes transports (OFI, PSM) whose libraries are not installed and
# prints a warning per rank; skip them unless the caller chose otherwise.
export OMPI_MCA_mtl="${OMPI_MCA_mtl:-^ofi,psm,psm2}"
export OMPI_MCA_btl="${OMPI_MCA_btl:-^ofi,openib}"
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"

die() { echo "peers.sh: $*" >&2; exit 1; }

engine_bin() {
  case "$1" in
    lammps) echo "$LMP_BIN" ;;
    liggghts) echo "$LIGGGHTS_BIN" ;;
    *) die "unknown engine '$1' (lammps or liggghts)" ;;
  esac
}

engine_deck() { echo "$BENCH_DIR/${1}_b1.in"; }

# Run ENGINE with NRANKS ranks and the remaining deck arguments; the log goes
# to LOG (screen output to LOG.out).
run_engine() {
  local engine="$1" nranks="$2" log="$3"; shift 3
  local bin; bin="$(engine_bin "$engine")"
  command -v "$bin" >/dev/null 2>&1 || die "$engine executable '$bin' not found"
  local -a launch=()
  if [[ -n "$MPIRUN" ]]; then
    launch=("$MPIRUN" --allow-run-as-root --oversubscribe -np "$nranks")
  elif [[ "$nranks" != 1 ]]; then
    die "mpirun not found: cannot run $nranks ranks"
  fi
  if ! "${launch[@]}" "$bin" -in "$(engine_deck "$engine")" -log "$log" -screen none "$@" \
      >"$log.out" 2>&1; then
    echo "peers.sh: $engine failed; last lines of $log:" >&2
    tail -n 20 "$log" >&2 || true
    grep -v -e 'mca_base_component' "$log.out" | tail -n 20 >&2 || true
    return 1
  fi
}

cmd_bed() {
  if [[ ! -s "$B1_BED" ]]; then
    "$PYTHON" "$BENCH_DIR/make_b1_bed.py" -o "$B1_BED" >&2
  fi
}

settle_dir() { echo "$B1_CACHE/$1"; }
settle_restart() { echo "$(settle_dir "$1")/settled_s${B1_SETTLE_STEPS}.restart"; }

# Fingerprint of everything the settled state depends on.
settle_stamp() {
  { md5sum "$B1_BED" "$(engine_deck "$1")" | cut -d' ' -f1; echo "steps=$B1_SETTLE_STEPS"; } \
    | md5sum | cut -d' ' -f1
}

cmd_settle_one() {
  local engine="$1"
  engine_bin "$engine" >/dev/null
  cmd_bed
  local dir; dir="$(settle_dir "$engine")"
  mkdir -p "$dir"
  local restart stampfile base stamp
  restart="$(settle_restart "$engine")"
  base="$dir/settle_s${B1_SETTLE_STEPS}"
  stampfile="$base.stamp"
  stamp="$(settle_stamp "$engine")"
  if [[ -s "$restart" && -s "$stampfile" && "$(cat "$stampfile")" == "$stamp" ]]; then
    echo "SETTLE engine=$engine steps=$B1_SETTLE_STEPS seconds=$(cat "$base.seconds" 2>/dev/null || echo nan) cached=yes"
    return 0
  fi
  rm -f "$restart" "$stampfile"
  local t0 t1 secs
  t0=$(date +%s.%N)
  run_engine "$engine" 1 "$base.log" \
    -var mode settle -var datafile "$B1_BED" -var restart "$restart" \
    -var dumpfile "$base.dump" -var settle_steps "$B1_SETTLE_STEPS"
  t1=$(date +%s.%N)
  secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
  [[ -s "$restart" ]] || die "$engine settle did not write $restart"
  echo "$secs" >"$base.seconds"
  echo "$stamp" >"$stampfile"
  echo "SETTLE engine=$engine steps=$B1_SETTLE_STEPS seconds=$secs cached=no"
}

cmd_settle() {
  local which="${1:-all}"
  if [[ "$which" == all ]]; then
    cmd_settle_one lammps
    cmd_settle_one liggghts
  else
    cmd_settle_one "$which"
  fi
}

# Print RESULT lines from the "Loop time" lines of a log with nonzero steps.
parse_loop_times() {
  local engine="$1" nranks="$2" log="$3"
  awk -v eng="$engine" -v nr="$nranks" '
    /^Loop time of / {
      secs = $4; steps = $9; atoms = $12; sub(/,$/, "", atoms)
      if (steps + 0 > 0) {
        blk++
        printf "RESULT engine=%s ranks=%d block=%d steps=%d seconds=%.4f particle_steps_per_s=%.4g\n",
               eng, nr, blk, steps, secs, atoms * steps / secs
      }
    }' "$log"
}

cmd_check() {
  local engine="$1" dump="${2:-}" stage="${3:-settled}" extra="${4:-}"
  [[ -n "$dump" ]] || dump="$(settle_dir "$engine")/settle_s${B1_SETTLE_STEPS}.dump"
  [[ -s "$dump" ]] || die "no dump $dump (run: peers.sh settle $engine)"
  echo "CHECK engine=$engine stage=$stage${extra:+ $extra} $("$PYTHON" "$BENCH_DIR/postprocess_b1.py" "$dump")"
}

cmd_time() {
  local engine="$1" nranks="${2:-1}"
  engine_bin "$engine" >/dev/null
  cmd_settle_one "$engine" >&2
  local dir base
  dir="$(settle_dir "$engine")"
  base="$dir/time_r${nranks}_b${B1_BLOCK_STEPS}"
  rm -f "$base.log" "$base.dump"
  local load0 load1
  load0="$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo nan)"
  run_engine "$engine" "$nranks" "$base.log" \
    -var mode time -var restart "$(settle_restart "$engine")" \
    -var dumpfile "$base.dump" -var block_steps "$B1_BLOCK_STEPS" -var blocks "$B1_BLOCKS"
  local results
  results="$(parse_loop_times "$engine" "$nranks" "$base.log")"
  [[ "$(grep -c '^RESULT' <<<"$results")" == "$B1_BLOCKS" ]] \
    || die "expected $B1_BLOCKS timed blocks in $base.log"
  load1="$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo nan)"
  echo "$results"
  echo "LOAD engine=$engine ranks=$nranks loadavg_before=$load0 loadavg_after=$load1"
  cmd_check "$engine" "$base.dump" final "ranks=$nranks"
}

cmd_versions() {
  local v pkg
  if command -v "$LMP_BIN" >/dev/null 2>&1; then
    v="$("$LMP_BIN" -h 2>/dev/null | sed -n 's/^Large-scale Atomic\/Molecular Massively Parallel Simulator - //p' | head -n 1)"
    pkg="$(dpkg-query -W -f='${Version}' lammps 2>/dev/null || echo unknown)"
    v="${v// - /_}"; echo "VERSION engine=lammps version=${v// /_} package=${pkg:-unknown}"
  else
    echo "VERSION engine=lammps version=missing package=missing"
  fi
  if command -v "$LIGGGHTS_BIN" >/dev/null 2>&1; then
    v="$(echo "" | "$LIGGGHTS_BIN" -log none 2>/dev/null \
          | sed -n 's/^LIGGGHTS (Version LIGGGHTS-PUBLIC \([^,]*\),.*/\1/p' | head -n 1)"
    pkg="$(dpkg-query -W -f='${Version}' liggghts 2>/dev/null || echo unknown)"
    echo "VERSION engine=liggghts version=${v:-unknown} package=${pkg:-unknown}"
  else
    echo "VERSION engine=liggghts version=missing package=missing"
  fi
}

cmd_micro() {
  mkdir -p "$B1_CACHE"
  g++ -O2 -fopenmp "$BENCH_DIR/omp_micro.cpp" -o "$B1_CACHE/omp_micro"
  OMP_NUM_THREADS=2 "$B1_CACHE/omp_micro" "${1:-1.0}" 2
}

cmd_triad() {
  mkdir -p "$B1_CACHE"
  g++ -O3 -march=native "$BENCH_DIR/mem_triad.cpp" -o "$B1_CACHE/mem_triad"
  "$B1_CACHE/mem_triad" "${1:-18}"
}

cmd_all() {
  cmd_bed
  cmd_versions
  cmd_settle all
  local engine nr
  for engine in lammps liggghts; do
    for nr in 1 2; do
      cmd_time "$engine" "$nr"
    done
  done
  cmd_micro
}

main() {
  local cmd="${1:-}"
  [[ $# -gt 0 ]] && shift
  case "$cmd" in
    bed) cmd_bed ;;
    settle) cmd_settle "$@" ;;
    time) [[ $# -ge 1 ]] || die "usage: peers.sh time ENGINE [RANKS]"; cmd_time "$@" ;;
    check) [[ $# -ge 1 ]] || die "usage: peers.sh check ENGINE"; cmd_check "$1" ;;
    versions) cmd_versions ;;
    micro) cmd_micro "$@" ;;
    triad) cmd_triad "$@" ;;
    all) cmd_all ;;
    ""|-h|--help|help) sed -n '2,/^$/p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' ;;
    *) die "unknown command '$cmd' (try: peers.sh help)" ;;
  esac
}

main "$@"
