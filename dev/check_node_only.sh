#!/usr/bin/env bash
# The robot's build: the ROS-free core and the jackal_AIC node alone (CMake option
# JACKAL_AIC_NODE_ONLY=ON: no simulated Jackal, no tools, no tests, no ODE, urdfdom, yaml-cpp
# or Boost.program_options), in its own git-ignored workspace <repo>/.ws_node. Checks that the
# build succeeds and installs the node, and that nothing of the simulator or the tools is built.
# Prints "check_node_only: N passed, N failed" last; exit 0 only if it passed. Run by .ci/run.
#
#   bash dev/check_node_only.sh
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ws_env.sh"
wsn="$repo/.ws_node"
fail() {
  echo "check_node_only: FAILURE: $*"
  echo "check_node_only: 0 passed, 1 failed"
  exit 1
}
mkdir -p "$wsn/src/jackal_aic"
shopt -s nullglob
for entry in "$repo"/*; do
  name="$(basename "$entry")"
  [ -L "$wsn/src/jackal_aic/$name" ] || ln -s "$entry" "$wsn/src/jackal_aic/$name"
done
shopt -u nullglob
find "$wsn/src/jackal_aic" -maxdepth 1 -xtype l -delete
if [ ! -e "$wsn/src/jackal_msgs" ] && [ ! -f /opt/ros/noetic/share/jackal_msgs/package.xml ]; then
  ln -s "$repo/compat/jackal_msgs" "$wsn/src/jackal_msgs"
fi
cd "$wsn"
if ! catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=OFF \
    -DJACKAL_AIC_NODE_ONLY=ON -j"${JOBS:-2}" install > "$wsn/build.log" 2>&1; then
  tail -30 "$wsn/build.log"
  fail "the node-only build (log: $wsn/build.log)"
fi
[ -x "$wsn/install/lib/jackal_aic/jackal_aic_node" ] || fail "jackal_aic_node was not installed"
for other in jackal_plant_node closed_loop_run aic_params; do
  [ -e "$wsn/devel/lib/jackal_aic/$other" ] && fail "the node-only build built $other"
done
echo "check_node_only: the core and jackal_aic_node build and install alone"
echo "check_node_only: 1 passed, 0 failed"
