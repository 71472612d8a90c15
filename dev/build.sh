#!/usr/bin/env bash
# Build jackal_aic in the git-ignored catkin workspace <repo>/.ws (created on first use,
# reused afterwards). Adds the bundled interface-identical jackal_msgs only where the
# real one is not installed. Extra arguments go to catkin_make (e.g. `tests`).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ws_env.sh"
mkdir -p "$ws/src"
# The package in the workspace is a folder of links to the repository's top-level entries,
# all but .ws, .ws_node and .git: a link to the whole repository would put the workspace inside its
# own package, so `find -L` (rosrun, roslaunch) would loop and find every executable twice.
[ -L "$ws/src/jackal_aic" ] && rm "$ws/src/jackal_aic"
mkdir -p "$ws/src/jackal_aic"
shopt -s dotglob nullglob
for entry in "$repo"/*; do
  name="$(basename "$entry")"
  case "$name" in .ws|.ws_node|.git) continue ;; esac
  [ -L "$ws/src/jackal_aic/$name" ] || ln -s "$entry" "$ws/src/jackal_aic/$name"
done
shopt -u dotglob nullglob
find "$ws/src/jackal_aic" -maxdepth 1 -xtype l -delete  # entries removed from the repository
if [ ! -e "$ws/src/jackal_msgs" ]; then
  if [ -f /opt/ros/noetic/share/jackal_msgs/package.xml ] || [ -f /usr/share/jackal_msgs/package.xml ]; then
    echo "build: using the installed jackal_msgs"
  else
    echo "build: jackal_msgs not installed; using the bundled compat/jackal_msgs"
    ln -s "$repo/compat/jackal_msgs" "$ws/src/jackal_msgs"
  fi
fi
# catkin snapshots the workspace environment (build/catkin_generated/setup_cached.sh, used
# by run_tests) at the first configure, and adds devel's Python folder to PYTHONPATH only
# if it exists by then: create it first, or the Python test nodes cannot import jackal_msgs.
mkdir -p "$ws/devel/lib/python3/dist-packages"
cd "$ws"
catkin_make "${catkin_args[@]}" -j"${JOBS:-2}" "$@"
