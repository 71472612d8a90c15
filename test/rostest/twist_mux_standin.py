#!/usr/bin/env python3
"""A stand-in for twist_mux (not packaged for Debian 12) in the robot-path rostests.

It behaves as twist_mux does on a stock Jackal (jackal_control's config/twist_mux.yaml):
each input topic (geometry_msgs/Twist) has a priority and a timeout; a lock topic
(std_msgs/Bool) has a priority too. A message on an input is forwarded to `cmd_vel_out` at
once if, at its arrival, its input has the highest priority among the inputs that are neither
timed out (no message for longer than their timeout, timeout > 0) nor masked by an engaged
lock (priority below the highest engaged lock's). An engaged lock therefore silences every
input below it: nothing is forwarded, nothing else is published (twist_mux sends no zero).
A lock with timeout > 0 also engages when its topic stays silent that long.

Private parameters:
  topics  list of {name, topic, timeout [s], priority [0, 255]}; default: the Jackal's
          joy (joy_teleop/cmd_vel, 0.5 s, 10), interactive_marker
          (twist_marker_server/cmd_vel, 0.5 s, 8), external (cmd_vel, 0.5 s, 1)
  locks   list of {name, topic, timeout [s], priority}; default: e_stop (e_stop, 0, 255)
Publishes cmd_vel_out (remap it, as jackal_control's control.launch does) and ~forwarded
(std_msgs/String, the name of the input of each forwarded message, for the tests).
Times are ROS times (simulated with /use_sim_time).
"""
import threading

import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool, String

DEFAULT_TOPICS = [
    {"name": "joy", "topic": "joy_teleop/cmd_vel", "timeout": 0.5, "priority": 10},
    {"name": "interactive_marker", "topic": "twist_marker_server/cmd_vel", "timeout": 0.5, "priority": 8},
    {"name": "external", "topic": "cmd_vel", "timeout": 0.5, "priority": 1},
]
DEFAULT_LOCKS = [{"name": "e_stop", "topic": "e_stop", "timeout": 0.0, "priority": 255}]


def checked(entries, what):
    """The entries of ~topics or ~locks, each with a name, topic, timeout >= 0 and priority in [0, 255]."""
    out = []
    for e in entries:
        try:
            item = {"name": str(e["name"]), "topic": str(e["topic"]), "timeout": float(e["timeout"]),
                    "priority": int(e["priority"])}
        except (KeyError, TypeError, ValueError) as err:
            raise ValueError("twist_mux_standin: ~%s entry %r: %s" % (what, e, err))
        if item["timeout"] < 0.0 or not 0 <= item["priority"] <= 255:
            raise ValueError("twist_mux_standin: ~%s entry %r: timeout >= 0, priority in [0, 255]" % (what, e))
        out.append(item)
    return out


class TwistMuxStandIn:
    def __init__(self):
        self.topics = checked(rospy.get_param("~topics", DEFAULT_TOPICS), "topics")
        self.locks = checked(rospy.get_param("~locks", DEFAULT_LOCKS), "locks")
        self.mutex = threading.Lock()
        self.last = {t["name"]: None for t in self.topics}    # ROS time of the last message
        self.locked = {l["name"]: False for l in self.locks}  # the lock's last Bool
        self.lock_last = {l["name"]: None for l in self.locks}
        self.pub = rospy.Publisher("cmd_vel_out", Twist, queue_size=1, tcp_nodelay=True)
        self.forwarded = rospy.Publisher("~forwarded", String, queue_size=100)
        self.subs = []
        for t in self.topics:
            self.subs.append(rospy.Subscriber(t["topic"], Twist, self.on_twist, callback_args=t["name"],
                                              queue_size=10, tcp_nodelay=True))
        for l in self.locks:
            self.subs.append(rospy.Subscriber(l["topic"], Bool, self.on_lock, callback_args=l["name"],
                                              queue_size=10, tcp_nodelay=True))

    def expired(self, last, timeout, now):
        return timeout > 0.0 and (last is None or (now - last).to_sec() > timeout)

    def lock_priority(self, now):
        """The highest priority among the engaged locks (0: none)."""
        p = 0
        for l in self.locks:
            engaged = self.locked[l["name"]] or self.expired(self.lock_last[l["name"]], l["timeout"], now)
            if engaged:
                p = max(p, l["priority"])
        return p

    def selected(self, now):
        """The input allowed to drive now: highest priority, not timed out, not masked; None if none."""
        lock = self.lock_priority(now)
        best = None
        for t in self.topics:
            if self.expired(self.last[t["name"]], t["timeout"], now) or t["priority"] < lock:
                continue
            if best is None or t["priority"] > best["priority"]:
                best = t
        return best["name"] if best else None

    def on_twist(self, msg, name):
        now = rospy.get_rostime()
        with self.mutex:
            self.last[name] = now
            forward = self.selected(now) == name
        if forward:
            self.pub.publish(msg)
            self.forwarded.publish(String(data=name))

    def on_lock(self, msg, name):
        with self.mutex:
            self.locked[name] = bool(msg.data)
            self.lock_last[name] = rospy.get_rostime()


def main():
    rospy.init_node("twist_mux")
    try:
        TwistMuxStandIn()
    except ValueError as err:
        rospy.logfatal(str(err))
        raise SystemExit(1)
    rospy.spin()


if __name__ == "__main__":
    main()
