"""Helpers shared by the jackal_AIC rostests: recorders that keep (time, message) pairs.

Times are message stamps where the message has a header, otherwise the receipt time
(rospy.get_rostime() in the callback): jackal_msgs/Drive and geometry_msgs/Twist carry
no stamp.
"""
import math
import os
import threading
import xmlrpc.client

import rosgraph
import rosnode
import rospy


class Recorder:
    """Subscribe to a topic and keep (time, msg) for every message."""

    def __init__(self, topic, msg_type, use_stamp=False, queue_size=100000):
        self.items = []
        self.lock = threading.Lock()
        self.use_stamp = use_stamp
        self.sub = rospy.Subscriber(topic, msg_type, self.callback, queue_size=queue_size, tcp_nodelay=True)

    def callback(self, msg):
        t = msg.header.stamp.to_sec() if self.use_stamp else rospy.get_rostime().to_sec()
        with self.lock:
            self.items.append((t, msg))

    def snapshot(self):
        with self.lock:
            return list(self.items)

    def span(self):
        items = self.snapshot()
        return items[-1][0] - items[0][0] if len(items) > 1 else 0.0


def wait_for(predicate, timeout, period=0.05):
    """Poll predicate() until it is true or `timeout` seconds of ROS time pass; return its last value."""
    deadline = rospy.get_rostime() + rospy.Duration(timeout)
    while not rospy.is_shutdown() and rospy.get_rostime() < deadline:
        if predicate():
            return True
        rospy.sleep(period)
    return predicate()


def rate_of(times):
    """Average rate [Hz] of a sorted list of times: (n - 1) / span."""
    if len(times) < 2 or times[-1] <= times[0]:
        return 0.0
    return (len(times) - 1) / (times[-1] - times[0])


def finite(values):
    return all(math.isfinite(v) for v in values)


def live_publishers(topic):
    """Node names the master lists as publishers of `topic`, after the registrations of nodes
    that no longer answer a ping are removed from the master, as `rosnode cleanup` does. A node
    that ends by SIGKILL (roslaunch escalates when a node is slow to exit under load) cannot
    unregister; its stale entry would otherwise read as a publisher that stayed."""
    master = rosgraph.Master(rospy.get_name())
    nodes = sorted(n for t, ns in master.getSystemState()[0] if t == topic for n in ns)
    dead = [n for n in nodes if not rosnode.rosnode_ping(n, max_count=1, verbose=False)]
    if dead:
        rospy.logwarn("%s: removing the stale registration(s) of %s", topic, dead)
        rosnode.cleanup_master_blacklist(master, dead)
    return [n for n in nodes if n not in dead]


def connections(node):
    """The topic connections of `node` from its own XML-RPC getBusInfo: a list of (topic,
    direction, peer) with direction "i" (it subscribes; peer: the publisher's URI in roscpp) or
    "o" (it publishes; peer: the subscriber's node name). A publisher lists a subscriber once
    their connection's headers are exchanged, so from then on its messages reach it (rospy also
    says whether the connection is still up: those that are not are left out; roscpp's sixth
    field is a description). Empty if the node is unknown or does not answer."""
    master = rosgraph.Master(rospy.get_name())
    try:
        uri = master.lookupNode(node)
        code, _, info = xmlrpc.client.ServerProxy(uri).getBusInfo(rospy.get_name())
    except (rosgraph.MasterError, OSError, xmlrpc.client.Error):
        return []
    if code != 1:
        return []
    return [(c[4], c[2], c[1]) for c in info if len(c) > 4 and (len(c) < 6 or c[5] is not False)]


def write_section(path, begin, end, body, title):
    """Write the lines `body` between the marker lines `begin` and `end` of the Markdown file
    `path`, replacing what stood between them and keeping the rest of the file; a file without
    the markers gets the section appended, a missing one is created with the line `title` first.
    Raises OSError when the file cannot be read or written."""
    section = "\n".join([begin] + list(body) + [end])
    old = open(path, encoding="utf-8").read() if os.path.exists(path) else title
    if begin in old and end in old:
        new = old[:old.index(begin)] + section + old[old.index(end) + len(end):]
    else:
        new = old.rstrip("\n") + "\n\n" + section + "\n"
    with open(path, "w", encoding="utf-8") as f:
        f.write(new)
