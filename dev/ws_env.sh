# Sourced by the build, test and demo scripts: the git-ignored catkin workspace
# (<repo>/.ws) and the environment to build and run in it.
# Debian 12 trap: `python3` on PATH may be another interpreter without ROS's modules.
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ws="$repo/.ws"
export PATH="/usr/bin:$PATH"
if [ -f /opt/ros/noetic/setup.bash ]; then
  # shellcheck disable=SC1091
  source /opt/ros/noetic/setup.bash
fi
export ROS_HOME="${ROS_HOME:-$ws/ros_home}"
catkin_args=(-DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3
             -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON)
source_ws() {
  # shellcheck disable=SC1091
  source "$ws/devel/setup.bash"
}
