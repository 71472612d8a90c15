#!/usr/bin/env bash
# The rehearsal on Clearpath's own jackal_node (doc/first_run.md, 'A rehearsal on the simulator'):
# builds jackal_base (jackal_node), diff_drive_controller and joint_state_controller from their
# public noetic sources in a catkin workspace outside this repository, on top of the package's
# workspace (.ws, dev/build.sh), then measures on the simulated Jackal, base:=jackal_node against
# the stand-in base:=stock_diff_drive: the 0.5 m/s step (settling time, overshoot; the AIC and the
# stock controller; median of 3) and the e-stop lock's stop times (robot_stop_path.test, as in
# doc/results/stop_paths.md; median of 3), on simulated and on real time.
#
#   bash dev/rehearsal.sh [--build-only] [OUTPUT.md]
#
# OUTPUT.md (default doc/results/rehearsal.md) gets one Markdown section per measurement, each naming
# the rostest command that wrote it. Environment:
#   REHEARSAL_WS      the workspace (default: jackal_rehearsal_ws beside the repository)
#   REHEARSAL_SOURCES a folder of bare git repositories named OWNER+NAME/repo to take the sources
#                     from instead of cloning them (default: none, `git clone`)
#   JOBS              parallel build jobs (default 2)
# What the workspace changes in those sources, and why (nothing of them enters this repository):
#   jackal_base: built without rosserial_server (the serial link to the MCU; here the plant
#     publishes the MCU's /feedback and /status on ROS), roslint and teleop_twist_joy (lint and
#     the joystick node's dependencies, unused by jackal_node);
#   joint_state_controller: ros::Time::MIN -> ros::TIME_MIN where roscpp_core predates
#     Time::MIN (Debian 12's), the same value.
# On Debian 12 it installs libtf-dev, libangles-dev and python3-tf with apt if missing (root);
# control_msgs and nmea_msgs, which Debian does not package, are built from source.
set -euo pipefail
build_only=0
if [ "${1:-}" = "--build-only" ]; then build_only=1; shift; fi
source "$(dirname "${BASH_SOURCE[0]}")/ws_env.sh"
output="$(realpath -m "${1:-$repo/doc/results/rehearsal.md}")"
jws="${REHEARSAL_WS:-$(dirname "$repo")/jackal_rehearsal_ws}"
case "$(realpath -m "$jws")/" in
  "$repo"/*) echo "rehearsal: REHEARSAL_WS must be outside the repository" >&2; exit 2 ;;
esac

# owner/name branch [paths...]: the sources, each into src/OWNER+NAME
sources=(
  "ros-controls/ros_control noetic-devel"
  "ros-controls/realtime_tools noetic-devel"
  "ros-controls/ros_controllers noetic-devel"
  "ros-controls/control_msgs kinetic-devel"
  "ros-drivers/nmea_msgs master"
  "jackal/jackal_robot noetic-devel jackal_base"
  "jackal/jackal noetic-devel jackal_control jackal_description jackal_msgs"
)

if [ ! -f "$ws/devel/setup.bash" ]; then
  echo "rehearsal: building the package first (dev/build.sh)"
  bash "$repo/dev/build.sh"
fi
if command -v apt-get >/dev/null && [ -f /etc/debian_version ] && ! grep -qi ubuntu /etc/os-release; then
  missing=()
  for p in libtf-dev libangles-dev python3-tf; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "rehearsal: apt-get install ${missing[*]}"
    apt-get install -y "${missing[@]}"
  fi
fi

mkdir -p "$jws/src"
for entry in "${sources[@]}"; do
  read -r slug branch paths <<<"$entry"
  dir="$jws/src/${slug/\//+}"
  [ -d "$dir" ] && continue
  mkdir -p "$dir"
  bare="${REHEARSAL_SOURCES:-}/${slug/\//+}/repo"
  if [ -n "${REHEARSAL_SOURCES:-}" ] && [ -d "$bare" ]; then
    # shellcheck disable=SC2086  # paths: a list
    git --git-dir="$bare" archive "$branch" $paths | tar -x -C "$dir"
  else
    git clone --depth 1 -b "$branch" "https://github.com/$slug.git" "$dir"
  fi
  echo "rehearsal: $slug $branch in $dir"
done

# The workspace's patches (idempotent).
base_dir="$jws/src/jackal+jackal_robot/jackal_base"
sed -i -e 's/ roslint rosserial_server / /' -e 's/ teleop_twist_joy$//' \
    -e 's/jackal_msgs_gencpp rosserial_msgs_gencpp)/jackal_msgs_gencpp)/' \
    -e '/^roslint_cpp()$/d' -e '/^roslint_add_test()$/d' -e '/^roslaunch_add_file_check(launch\/base.launch)$/d' \
    "$base_dir/CMakeLists.txt"
warn='  ROS_WARN("jackal_base built without rosserial_server: no serial link to %s", port.c_str());'
sed -i -e '/#include <rosserial_server\/serial_session.h>/d' \
    -e "s|^  new rosserial_server::SerialSession(io_service, port, 115200);|$warn|" \
    "$base_dir/src/jackal_base.cpp"
if ! grep -q "Time::MIN" /usr/include/ros/time.h /opt/ros/noetic/include/ros/time.h 2>/dev/null; then
  sed -i 's/ros::Time::MIN/ros::TIME_MIN/' \
      "$jws/src/ros-controls+ros_controllers/joint_state_controller/src/joint_state_controller.cpp"
fi

set +u  # the ROS setup scripts read unset variables
source_ws
(cd "$jws" && catkin_make_isolated --merge \
    --only-pkg-with-deps jackal_base diff_drive_controller joint_state_controller jackal_control \
    --cmake-args "${catkin_args[@]}" --make-args -j"${JOBS:-2}")
echo "rehearsal: built; source $jws/devel_isolated/setup.bash, then roslaunch jackal_aic sim.launch base:=jackal_node"
[ "$build_only" = 1 ] && exit 0

# shellcheck disable=SC1091
source "$jws/devel_isolated/setup.bash"
mkdir -p "$(dirname "$output")"
status=0
for sim_time in true false; do
  for base in jackal_node stock_diff_drive; do
    rostest jackal_aic stock_base_compare.test base:=$base use_sim_time:=$sim_time output:="$output" || status=1
    rostest jackal_aic robot_stop_path.test base:=$base use_sim_time:=$sim_time engagements:=3 \
        output:="$output" || status=1
  done
done
echo "rehearsal: the figures are in $output"
exit $status
