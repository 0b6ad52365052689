# Sourced by the launch smoke tests: the package's devel space, the system
# python first, and a private master port (ROS_MASTER_URI) from a base.
#   source test/ros/ros_env.sh BASE_PORT    (sets ROOT and port)
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
export PATH=/usr/bin:/bin:$PATH
set +u
source "${REGOLITH_BUILD:-$ROOT/build}/devel/setup.bash"
set -u
port=$(($1 + $$ % 90))
export ROS_MASTER_URI=http://localhost:$port
