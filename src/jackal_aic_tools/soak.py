"""Soak test: run the simulated Jackal and jackal_AIC (launch/sim.launch) for N minutes with a
random set-point profile and randomly injected faults (sim/README.md, 'Fault injection'), then
print the resource use and the counters:

  RSS of both nodes at the start (after the warm-up) and at the end [KiB], their CPU use [%],
  the achieved /cmd_drive and /joint_states rates [Hz] against the nominal ones, the drops, loop
  overruns and runaway resets the node reports on /diagnostics, and the fault events on
  /jackal_AIC/sensor_health.

Runs its own ROS master on a free port (never a shared one) and stops only the roslaunch it
started. Usage (in the workspace environment, dev/ws_env.sh source_ws):

  scripts/aic_soak.py --minutes 10 [--seed 1] [--fault-every 20] [--config config/default.yaml]
"""
import os
import random
import signal
import subprocess
import time

from . import experiment
from .procfs import parent_of, proc_stats

FAULTS = [  # sim/README.md, 'Fault injection': TARGET KIND [VALUE] START DURATION [PERIOD]; each is short
    "left_encoder bias 2.5 0 4",
    "right_encoder bias -2.5 0 4",
    "gyro freeze 0 4",
    "gyro spikes 3.0 0 3 0.2",
    "imu dropout 0 3",
    "joint_states delay 0.1 0 1",
    "imu delay 0.05 0 2",
    "joint_states dropout 0 0.15",
    "friction_left set 0.3 0 4",
    "payload set 10 0 6",
]


def find_node(name, root):
    """PID of the process with __name:=name that descends from `root` (the roslaunch started here)."""
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open("/proc/%s/cmdline" % d, "rb") as f:
                cmd = f.read().split(b"\0")
            if ("__name:=" + name).encode() not in cmd:
                continue
            pid = int(d)
            while pid > 1:
                pid = parent_of(pid)
                if pid == root:
                    return int(d)
        except (OSError, ValueError, IndexError):
            continue
    return None


def run(args):
    """Start launch/sim.launch (controller YAML args.config, or the default) under its own master
    on a free port, soak it (soak()) and stop that roslaunch. Returns the exit status."""
    port = experiment.free_port()
    os.environ["ROS_MASTER_URI"] = "http://localhost:%d" % port
    cmd = ["roslaunch", "-p", str(port), "jackal_aic", "sim.launch"]
    if args.config:
        cmd.append("config:=" + os.path.abspath(args.config))
    launch = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        return soak(args, launch)
    finally:
        os.killpg(launch.pid, signal.SIGINT)  # only the roslaunch this script started
        try:
            launch.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(launch.pid, signal.SIGKILL)


def belief_steps(diag):
    """(stamp of the diagnostics message [s], belief steps so far) from the node's "loops" status,
    or None before the first one."""
    loops = diag.get("jackal_AIC: loops")
    if not loops or "belief steps" not in loops:
        return None
    return loops["_stamp"], int(loops["belief steps"])


def soak(args, launch):
    """Drive the running simulator (``launch``: the roslaunch process) for args.minutes with a
    random set point (seed args.seed), inject a random fault every args.fault_every s after
    args.warmup s, and print the resource use and the counters. Returns the exit status."""
    import rospy
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from geometry_msgs.msg import Twist
    from jackal_msgs.msg import Drive
    from sensor_msgs.msg import JointState

    rng = random.Random(args.seed)
    deadline = time.time() + 60
    while time.time() < deadline:
        if find_node("jackal_AIC", launch.pid) and find_node("jackal_plant", launch.pid):
            break
        time.sleep(0.5)
    node_pid, plant_pid = find_node("jackal_AIC", launch.pid), find_node("jackal_plant", launch.pid)
    if not node_pid or not plant_pid:
        print("soak: the nodes did not start (roslaunch exit %s)" % launch.poll())
        return 1
    rospy.init_node("aic_soak", disable_signals=True)
    counts = {"cmd": 0, "js": 0}
    diag = {}
    health = {"isolations": 0, "events": set()}

    def on_cmd(_):
        counts["cmd"] += 1

    def on_js(_):
        counts["js"] += 1

    def on_diag(m):
        for st in m.status:
            diag[st.name] = {kv.key: kv.value for kv in st.values}
            diag[st.name]["_stamp"] = m.header.stamp.to_sec()

    def on_health(m):
        v = {kv.key: kv.value for kv in m.values}
        if v.get("last event", "none") != "none":
            health["events"].add(v["last event"])

    rospy.Subscriber("/cmd_drive", Drive, on_cmd, queue_size=1000)
    rospy.Subscriber("/joint_states", JointState, on_js, queue_size=1000)
    rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=100)
    rospy.Subscriber("/jackal_AIC/sensor_health", DiagnosticStatus, on_health, queue_size=1000)
    pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=10)

    def drive(seconds, state):
        end = time.time() + seconds
        while time.time() < end and not rospy.is_shutdown():
            if time.time() >= state["next_change"]:
                state["v"] = rng.uniform(-1.0, 1.0)
                state["w"] = rng.uniform(-1.5, 1.5)
                state["next_change"] = time.time() + rng.uniform(2.0, 5.0)
            m = Twist()
            m.linear.x, m.angular.z = state["v"], state["w"]
            pub.publish(m)
            time.sleep(0.05)

    state = {"v": 0.0, "w": 0.0, "next_change": 0.0}
    drive(args.warmup, state)
    rss0 = {n: proc_stats(p) for n, p in (("jackal_AIC", node_pid), ("jackal_plant", plant_pid))}
    c0, t0 = dict(counts), time.time()
    steps0 = belief_steps(diag)
    injected = []
    end = t0 + 60.0 * args.minutes
    next_fault = t0 + args.fault_every
    while time.time() < end and launch.poll() is None:
        drive(min(1.0, end - time.time()), state)
        if time.time() >= next_fault:
            line = rng.choice(FAULTS)
            rospy.set_param("/jackal_plant/faults", [line])
            injected.append(line)
            next_fault += args.fault_every
    rospy.set_param("/jackal_plant/faults", [])
    t1 = time.time()
    c1 = dict(counts)
    steps1 = belief_steps(diag)
    rss1 = {n: proc_stats(p) for n, p in (("jackal_AIC", node_pid), ("jackal_plant", plant_pid))}
    span = t1 - t0
    print("soak: %.1f min, seed %d, %d faults injected (every %.0f s)" % (span / 60, args.seed, len(injected),
                                                                         args.fault_every))
    for n in ("jackal_AIC", "jackal_plant"):
        (r0, cpu0), (r1, cpu1) = rss0[n], rss1[n]
        print("  %-13s RSS start %7d KiB, end %7d KiB, growth %+6d KiB; CPU %5.1f %%" %
              (n, r0, r1, r1 - r0, 100.0 * (cpu1 - cpu0) / span))
    cmd_rate = (c1["cmd"] - c0["cmd"]) / span
    js_rate = (c1["js"] - c0["js"]) / span
    print("  /cmd_drive   %.2f Hz (nominal 50: %+.2f %%)" % (cmd_rate, 100.0 * (cmd_rate / 50.0 - 1)))
    print("  /joint_states %.2f Hz (nominal 50: %+.2f %%; faults drop or delay some)" %
          (js_rate, 100.0 * (js_rate / 50.0 - 1)))
    if steps0 and steps1 and steps1[0] > steps0[0]:
        rate = (steps1[1] - steps0[1]) / (steps1[0] - steps0[0])
        nominal = rospy.get_param("/jackal_AIC/belief_rate", 1000.0)
        print("  belief steps %.2f Hz (nominal %g: %+.3f %%; from the diagnostics counter)" %
              (rate, nominal, 100.0 * (rate / nominal - 1)))
    ctrl = diag.get("jackal_AIC: controller", {})
    sens = diag.get("jackal_AIC: sensors", {})
    loops = diag.get("jackal_AIC: loops", {})
    drops = sum(int(v) for k, v in sens.items() if k.startswith("dropped:") and v.isdigit())
    print("  runaway resets %s; dropped inputs %d (no-imu samples %s); stale events %s" %
          (ctrl.get("runaway resets", "?"), drops,
           sens.get("dropped: sample: no imu within imu_max_skew (sample used without the imu)", "?"),
           sens.get("stale events", "?")))
    print("  belief overruns %s, action overruns %s" %
          (loops.get("belief overruns (interval > 2 periods)", "?"), loops.get("action overruns (interval > 2 periods)", "?")))
    print("  fault events on ~sensor_health: %d distinct (%s)" %
          (len(health["events"]), ", ".join(sorted(e.rsplit(" at ", 1)[0] for e in health["events"]))[:300]))
    print("  injected: %s" % "; ".join(sorted(set(injected))))
    return 0
