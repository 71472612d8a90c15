#!/usr/bin/env bash
# The older-toolchain check: build and test jackal_aic on Debian 11 "bullseye" (GCC 10,
# CMake 3.18, Python 3.9, Boost 1.74, scipy 1.6, Debian's ROS 1 with roscpp 1.15, no CLI11),
# the nearest relative of the robot's Ubuntu 20.04 (GCC 9, CMake 3.16, Boost 1.71) that
# Debian's archive serves.
#
#   1. a bullseye root by debootstrap from Debian's archive (kept and reused: BULLSEYE_ROOT);
#   2. the package's dependencies there: every key of package.xml resolved for bullseye by
#      dev/resolve_deps.py (rosdep's apt rules, test/data/rosdep_apt_rules.yaml, and
#      Debian's ROS packages, test/data/debian_ros_packages.yaml) and installed with apt. A key
#      without a bullseye package, or a package the archive does not have, fails the check;
#   3. the repository's files (tracked and untracked, not ignored) and compat/jackal_msgs in a
#      fresh catkin workspace there, built with catkin_make (Release, tests on);
#   4. every gtest, one short rostest (BULLSEYE_ROSTEST) and the scipy tools (plant_identify.py,
#      aic_tune.py: a few evaluations each, on scipy 1.6).
#
# Prints "check_bullseye: N passed, N failed" last; exit 0 only if everything passed.
# Needs root (debootstrap, chroot, mounts) and Debian's archive; about 15 min on 2 cores
# the first time (the root is reused afterwards). Run by .ci/run after the test suite.
#
#   sudo bash dev/check_bullseye.sh
#   sudo bash dev/check_bullseye.sh --doc     # also writes doc/results/bullseye.txt
#   BULLSEYE_ROOT=/srv/bullseye BULLSEYE_ROSTEST=node_bad_input.test bash dev/check_bullseye.sh
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
root="${BULLSEYE_ROOT:-/var/tmp/jackal_aic/bullseye}"
mirror="${DEBIAN_MIRROR:-http://deb.debian.org/debian}"
rostest_name="${BULLSEYE_ROSTEST:-node_bad_input.test}"
jobs="${JOBS:-2}"
doc=""
case "${1:-}" in
  --doc) doc="$repo/doc/results/bullseye.txt" ;;
  "") ;;
  *) echo "usage: check_bullseye.sh [--doc]" >&2; exit 2 ;;
esac

fail() {
  echo "check_bullseye: FAILURE: $*"
  echo "check_bullseye: 0 passed, 1 failed"
  exit 1
}
[ "$(id -u)" -eq 0 ] || fail "needs root (debootstrap, chroot): run it with sudo"
for tool in debootstrap chroot python3 git; do
  command -v "$tool" >/dev/null || {
    [ "$tool" = debootstrap ] && DEBIAN_FRONTEND=noninteractive apt-get install -y -q debootstrap >/dev/null
    command -v "$tool" >/dev/null || fail "'$tool' not found"
  }
done

# ---- 1. the root ----
if [ ! -f "$root/.jackal_aic_root" ]; then
  echo "check_bullseye: debootstrap bullseye into $root ($mirror)"
  rm -rf "$root"
  mkdir -p "$root"
  debootstrap --variant=minbase bullseye "$root" "$mirror" > "$root.debootstrap.log" 2>&1 ||
    { tail -20 "$root.debootstrap.log"; fail "debootstrap bullseye (log: $root.debootstrap.log)"; }
  touch "$root/.jackal_aic_root"
fi
cp /etc/resolv.conf "$root/etc/resolv.conf"
cp /etc/hosts "$root/etc/hosts"

mounted=()
cleanup() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[$i]}" 2>/dev/null || true; done
}
trap cleanup EXIT
for m in proc sys dev dev/pts; do
  mkdir -p "$root/$m"
  if ! mountpoint -q "$root/$m"; then
    case "$m" in
      proc) mount -t proc proc "$root/proc" ;;
      *) mount --bind "/$m" "$root/$m" ;;
    esac
    mounted+=("$root/$m")
  fi
done
in_root() { chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
  DEBIAN_FRONTEND=noninteractive bash -c "$1"; }

# ---- 2. dependencies ----
pkgs="$(python3 "$here/resolve_deps.py" --os bullseye)" || fail "package.xml has keys without a bullseye package (above)"
# The compiler and build tools rosdep assumes present (build-essential on Ubuntu).
pkgs="$pkgs g++ make cmake git"
echo "check_bullseye: installing $(echo "$pkgs" | wc -w) packages (resolve_deps.py --os bullseye + g++ make cmake git)"
in_root "apt-get update -q >/dev/null && apt-get install -y -q --no-install-recommends $(echo $pkgs)" \
  > "$root.apt.log" 2>&1 || { tail -20 "$root.apt.log"; fail "apt-get install in the bullseye root (log: $root.apt.log)"; }

# ---- 3. the workspace ----
ws="$root/ws"
rm -rf "$ws/src" "$ws/build" "$ws/devel"
mkdir -p "$ws/src/jackal_aic"
(cd "$repo" && git ls-files -z --cached --others --exclude-standard | tar --null -T - -cf -) |
  tar -xf - -C "$ws/src/jackal_aic"
cp -r "$repo/compat/jackal_msgs" "$ws/src/jackal_msgs"
versions="$(in_root 'printf "GCC %s, CMake %s, Python %s, Boost %s, roscpp %s, scipy %s" \
  "$(gcc -dumpfullversion)" "$(cmake --version | sed -n "1s/.* //p")" "$(python3 -c "import platform; print(platform.python_version())")" \
  "$(dpkg-query -W -f="\${Version}" libboost-dev)" "$(dpkg-query -W -f="\${Version}" libroscpp-dev)" \
  "$(python3 -c "import scipy; print(scipy.__version__)")"')"
echo "check_bullseye: toolchain: $versions"

passed=0
failed=0
step() {  # step NAME COMMAND: run in the root, count, keep the log
  local name="$1" log="$root.$1.log"
  if in_root "$2" > "$log" 2>&1; then
    passed=$((passed + 1))
    echo "check_bullseye: $name: ok"
  else
    failed=$((failed + 1))
    echo "check_bullseye: $name: FAILED (log: $log), its end:"
    tail -25 "$log" | sed 's/^/    /'
  fi
}
catkin="cd /ws && catkin_make -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON -j$jobs"
step build "$catkin && $catkin tests"
if [ "$failed" -ne 0 ]; then
  echo "check_bullseye: $passed passed, $failed failed"
  exit 1
fi

# ---- 4. tests ----
step gtests "$catkin run_tests_jackal_aic_gtest -j1 && catkin_test_results /ws/build/test_results"
step rostest "source /ws/devel/setup.bash && rostest jackal_aic $rostest_name --text"
# The tools that need scipy, a few evaluations each (scipy 1.6 API).
tools="source /ws/devel/setup.bash && cd /ws/src/jackal_aic"
step plant_identify "$tools && python3 scripts/plant_identify.py --samples 2 --starts 1 --jobs 1 --max-evals 4"
# The tuner tunes the goal model's gains: its base is that model's effective file.
step aic_tune "$tools && /ws/devel/lib/jackal_aic/aic_params --yaml --config config/default.yaml \
  --config config/goal_model.yaml > /tmp/goal_model.yaml && python3 scripts/aic_tune.py --driving \
  --base /tmp/goal_model.yaml --refine-evals 2 --driving-variants default --jobs 1"
gtest_summary="$(in_root 'catkin_test_results /ws/build/test_results' 2>&1 | grep -E '^Summary:' || true)"
echo "check_bullseye: gtests: ${gtest_summary:-no results}"
rostest_summary="$(sed 's/\x1b\[[0-9;]*m//g' "$root.rostest.log" | grep -E '^ \* (RESULT|TESTS|ERRORS|FAILURES):' | head -4 |
  sed 's/^ \* //' | tr '\n' ' ')"
echo "check_bullseye: rostest $rostest_name: ${rostest_summary:-no summary}"
echo "check_bullseye: $passed passed, $failed failed"
if [ -n "$doc" ]; then
  {
    echo "# sudo bash dev/check_bullseye.sh --doc (Debian 11 root by debootstrap; doc/platforms.md)"
    echo "toolchain: $versions"
    echo "packages: $(echo $pkgs)"
    echo "gtests: ${gtest_summary:-no results}"
    echo "rostest $rostest_name: ${rostest_summary:-no summary}"
    echo "$passed passed, $failed failed (build, gtests, rostest, plant_identify.py, aic_tune.py)"
  } > "$doc"
  echo "check_bullseye: wrote $doc"
fi
[ "$failed" -eq 0 ]
