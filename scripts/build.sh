#!/usr/bin/env bash
# Build jackal_aic in the git-ignored catkin workspace <repo>/.ws (created on first use,
# reused afterwards). Adds the bundled interface-identical jackal_msgs only where the
# real one is not installed. Extra arguments go to catkin_make (e.g. `tests`).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ws_env.sh"
mkdir -p "$ws/src"
[ -e "$ws/src/jackal_aic" ] || ln -s "$repo" "$ws/src/jackal_aic"
if [ ! -e "$ws/src/jackal_msgs" ]; then
  if [ -f /opt/ros/noetic/share/jackal_msgs/package.xml ] || [ -f /usr/share/jackal_msgs/package.xml ]; then
    echo "build: using the installed jackal_msgs"
  else
    echo "build: jackal_msgs not installed; using the bundled compat/jackal_msgs"
    ln -s "$repo/compat/jackal_msgs" "$ws/src/jackal_msgs"
  fi
fi
cd "$ws"
catkin_make "${catkin_args[@]}" -j"${JOBS:-2}" "$@"
