#!/usr/bin/env bash
# Install everything jackal_aic needs, once; a no-op when it is all there.
#   Debian 12:                  Debian's own ROS 1 packages (dev/debian-packages.txt)
#   Ubuntu 20.04 + ROS Noetic:  rosdep install --from-paths <repo> (needs /opt/ros/noetic)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

if [ -f /opt/ros/noetic/setup.bash ]; then
  # shellcheck disable=SC1091
  source /opt/ros/noetic/setup.bash
  if ! command -v rosdep >/dev/null; then
    $SUDO apt-get update && $SUDO apt-get install -y python3-rosdep
  fi
  [ -d /etc/ros/rosdep/sources.list.d ] || $SUDO rosdep init
  rosdep update
  # Every key of package.xml has an apt rule for Ubuntu 20.04 (test/test_packaging.py checks
  # it against test/data/rosdep_apt_rules.yaml); jackal_msgs comes from ros-noetic-jackal-msgs.
  rosdep install --from-paths "$repo" --ignore-src -y
  exit 0
fi

. /etc/os-release
if [ "${ID:-}" != "debian" ]; then
  echo "setup_deps: unsupported system '${PRETTY_NAME:-unknown}': use Debian 12, or Ubuntu 20.04 with ROS Noetic" >&2
  exit 1
fi
mapfile -t pkgs < <(grep -v '^#' "$here/debian-packages.txt" | tr ' ' '\n' | sed '/^$/d')
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "setup_deps: all ${#pkgs[@]} Debian packages present"
  exit 0
fi
echo "setup_deps: installing ${#missing[@]} Debian packages: ${missing[*]}"
$SUDO apt-get update -q
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
