#!/usr/bin/env bash
# CI step (run by dev/run_tests.sh after the build): `catkin_make install` of the
# workspace .ws, then the *installed* package, in an environment that sees only the install
# space, runs the demo launch (launch/sim.launch: plant + AIC) and drives the simulated
# Jackal: rospack finds jackal_aic in the install space, the installed closed_loop_run finds
# its data there (run outside the repository: URDF, plant and controller YAML), /odom,
# /cmd_drive and the belief arrive, and a 0.3 m/s set point moves the robot forward. Exit 0 on success; on failure
# prints why and exits 1. Takes about half a minute after the build.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source "$here/ws_env.sh"
cd "$ws"
echo "check_install: catkin_make install"
if ! catkin_make "${catkin_args[@]}" -j"${JOBS:-2}" install > "$ws/install.log" 2>&1; then
  tail -30 "$ws/install.log"
  echo "check_install: FAILED: catkin_make install (log: $ws/install.log)"
  exit 1
fi
port="${CHECK_INSTALL_PORT:-11397}"
log_dir="$(mktemp -d)"
# A clean environment: only the install space (and the system's ROS for Debian's packages).
rc=0
env -i HOME="$HOME" PATH="/usr/bin:/bin" LANG=C.UTF-8 ROS_HOME="$log_dir" \
    ROS_MASTER_URI="http://localhost:$port" INSTALL="$ws/install" LOG_DIR="$log_dir" PORT="$port" \
    bash -c '
# (no set -u: the catkin setup scripts read unset variables)
[ -f /opt/ros/noetic/setup.bash ] && source /opt/ros/noetic/setup.bash
source "$INSTALL/setup.bash"
found="$(rospack find jackal_aic)"
if [ "$found" != "$INSTALL/share/jackal_aic" ]; then
  echo "check_install: FAILED: rospack finds jackal_aic at $found, not in $INSTALL"; exit 1
fi
cd "$LOG_DIR"
for controller in aic stock; do
  if ! out="$("$INSTALL/lib/jackal_aic/closed_loop_run" --controller $controller --step 0.5 --hold 1 2>&1)"; then
    echo "$out" | tail -5
    echo "check_install: FAILED: the installed closed_loop_run --controller $controller (data from $found)"; exit 1
  fi
  case "$out" in
    *\"segments\"*) ;;
    *) echo "check_install: FAILED: the installed closed_loop_run printed no result: $out"; exit 1 ;;
  esac
done
echo "check_install: the installed closed_loop_run reads its URDF and YAML from $found"
# On simulated time (the plant publishes /clock): the 4 s of driving are plant seconds, judged
# from the stamps of /odom, so a loaded machine slows the run down but does not change the verdict.
roslaunch -p "$PORT" jackal_aic sim.launch use_sim_time:=true > "$LOG_DIR/launch.log" 2>&1 &
launch=$!
/usr/bin/python3 - <<PY
import sys, time
import rospy
from geometry_msgs.msg import Twist, TwistStamped
from jackal_msgs.msg import Drive
from nav_msgs.msg import Odometry
seen = {"odom": [], "drive": 0, "belief": 0}
deadline = time.time() + 60.0
while True:
    try:
        rospy.init_node("check_install", anonymous=True)
        break
    except Exception:
        if time.time() > deadline:
            print("check_install: FAILED: no ROS master on port $PORT"); sys.exit(1)
        time.sleep(1.0)
rospy.Subscriber("/odom", Odometry, lambda m: seen["odom"].append((m.header.stamp.to_sec(), m.twist.twist.linear.x)))
rospy.Subscriber("/cmd_drive", Drive, lambda m: seen.__setitem__("drive", seen["drive"] + 1))
rospy.Subscriber("/jackal_AIC/belief", TwistStamped, lambda m: seen.__setitem__("belief", seen["belief"] + 1))
pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=1)
while not (seen["odom"] and seen["drive"] and seen["belief"]):
    if time.time() > deadline:
        print("check_install: FAILED: from the installed sim.launch: /odom %d, /cmd_drive %d, belief %d messages"
              % (len(seen["odom"]), seen["drive"], seen["belief"])); sys.exit(1)
    pub.publish(Twist()); time.sleep(0.05)
deadline = time.time() + 60.0  # a backstop: plant time must advance
t_end = seen["odom"][-1][0] + 4.0  # plant time
cmd = Twist(); cmd.linear.x = 0.3
while seen["odom"][-1][0] < t_end:
    if time.time() > deadline:
        print("check_install: FAILED: plant time stalled at %.2f s" % seen["odom"][-1][0]); sys.exit(1)
    pub.publish(cmd); time.sleep(0.05)
v = seen["odom"][-1][1]
if not 0.2 < v < 0.4:
    print("check_install: FAILED: the installed AIC drove the plant to %.3f m/s, not ~0.3 m/s" % v); sys.exit(1)
print("check_install: the installed sim.launch drives the simulated Jackal at %.3f m/s (set point 0.3)" % v)
PY
rc=$?
kill -INT $launch 2>/dev/null; wait $launch 2>/dev/null
[ $rc -eq 0 ] || tail -20 "$LOG_DIR/launch.log"
exit $rc
' || rc=$?
rm -rf "$log_dir"
[ $rc -eq 0 ] && echo "check_install: ok" || echo "check_install: FAILED"
exit $rc
