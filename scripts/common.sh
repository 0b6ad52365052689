# Shared by scripts/run, test, bench, validate: install what is missing, build.
# Source it; it defines ROOT, BUILD, BIN and the functions below.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${REGOLITH_BUILD:-$ROOT/build}
# REGOLITH_BIN=DIR: run the tools in DIR (a copy of the binaries, so that a long campaign is not
# changed by a rebuild under it: scripts/copy_binaries DIR) and build nothing. The tools find the
# project's libraries through their run path in the build folder unless DIR holds its own copies,
# which are then put first on LD_LIBRARY_PATH.
BIN=${REGOLITH_BIN:-$BUILD/devel/lib/regolith_twin}
if [ -n "${REGOLITH_BIN:-}" ]; then
  if compgen -G "$REGOLITH_BIN/libregolith_*.so" >/dev/null; then
    export LD_LIBRARY_PATH=$REGOLITH_BIN${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  else
    echo "regolith_twin: $REGOLITH_BIN holds no libregolith_*.so: its tools load the build's libraries," \
      "which a rebuild changes (scripts/copy_binaries DIR copies both)" >&2
  fi
fi
# ROS and catkin tools run with the system interpreter, not a pyenv one.
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
# Waiting OpenMP threads sleep instead of spinning: spinning threads starve
# each other when the two cores are shared with other work.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

# Debian packages the build and tests need.
BUILD_PACKAGES=(g++ make cmake pkg-config catkin libeigen3-dev libyaml-cpp-dev libbullet-dev liburdfdom-dev googletest python3
  # ROS 1 (docs/ros.md): the node, its messages and its rostests.
  ros-core-dev libtf2-ros-dev libtf2-eigen-dev liburdf-dev python3-rostest librostest-dev python3-rosbag librosbag-dev
  ros-message-generation libgeometry-msgs-dev libsensor-msgs-dev libvisualization-msgs-dev libstd-srvs-dev
  libdiagnostic-msgs-dev libros-rosgraph-msgs-dev libtf2-msgs-dev python3-roslaunch
  python3-std-srvs python3-sensor-msgs python3-rospy python3-rosgraph python3-rosservice python3-roslib)
# Extra packages for reports (plots, fits).
REPORT_PACKAGES=(python3-numpy python3-matplotlib python3-scipy)

_apt_updated=0
need_packages() {
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  echo "regolith_twin: installing ${missing[*]}" >&2
  if [ $_apt_updated -eq 0 ]; then
    $sudo apt-get update -qq
    _apt_updated=1
  fi
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# Slurm for the sweep's cluster test. Its munge dependency (unused: the test
# runs with AuthType=auth/none) makes its key as the munge user on install,
# which fails where that user cannot reach /bin/sh (a root directory that is
# not world-readable, as in some container roots): the key is made here
# first, as munge's own installer would make it.
need_slurm() {
  dpkg-query -W -f='${Status}' slurm-wlm 2>/dev/null | grep -q "install ok installed" && return 0
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  if [ ! -e /etc/munge/munge.key ]; then
    $sudo mkdir -p /etc/munge
    $sudo sh -c 'umask 077; head -c 1024 /dev/urandom > /etc/munge/munge.key'
    $sudo chmod 0400 /etc/munge/munge.key
  fi
  need_packages slurm-wlm
}

# Configure and build everything (library, tools, tests) out of source.
build_all() {
  need_packages "${BUILD_PACKAGES[@]}"
  [ -n "${REGOLITH_BIN:-}" ] && return 0
  local jobs
  mkdir -p "$BUILD"
  jobs=$(nproc 2>/dev/null || echo 2)
  # The node's Python tests import the generated messages from the devel space:
  # catkin keeps the configure-time PYTHONPATH for the tests' environment.
  export PYTHONPATH=$BUILD/devel/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}
  # shellcheck disable=SC2086
  cmake -S "$ROOT" -B "$BUILD" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
    ${CMAKE_EXTRA:-} >"$BUILD/configure.log" 2>&1 ||
    { cat "$BUILD/configure.log" >&2; return 1; }
  echo "regolith_twin: building in $BUILD ..." >&2
  if ! make -C "$BUILD" -j"$jobs" --no-print-directory all tests >"$BUILD/make.log" 2>&1; then
    grep -E -A3 "error|Error" "$BUILD/make.log" | head -60 >&2
    echo "regolith_twin: build failed (full log: $BUILD/make.log)" >&2
    return 1
  fi
}
