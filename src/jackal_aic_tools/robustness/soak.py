"""Soak test: run the simulated Jackal and jackal_AIC (launch/sim.launch) for N minutes with a
random set-point profile and randomly injected faults (sim/README.md, 'Fault injection'), then
print the resource use and the counters:

  RSS of both nodes at the start (after the warm-up) and at the end [KiB], their CPU use [%],
  the achieved /cmd_drive and /joint_states rates [Hz] against the nominal ones, the /cmd_drive
  commands that were non-finite or beyond max_wheel_speed, the drops, loop overruns and runaway
  resets the node reports on /diagnostics, and the fault events on /jackal_AIC/sensor_health.
  With --output, the same figures and the command as a Markdown file.

Runs its own ROS master on a free port (never a shared one) and stops only the roslaunch it
started. Usage (in the workspace environment, dev/ws_env.sh source_ws):

  scripts/aic_ros_soak.py --minutes 10 [--seed 1] [--fault-every 20] [--config config/default.yaml]
                          [--output doc/results/ros_soak.md]
"""
import os
import random
import time

from ..common.ros_process import launched, wait_for_nodes
from .node_watch import CommandCheck, diagnostics_callback, drop_counters, rss_and_cpu

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

NOMINAL_RATE = 50.0  # /cmd_drive and /joint_states [Hz] of sim.launch


def run(args, argv=None):
    """Start launch/sim.launch (controller YAML args.config, or the default) under its own master
    on a free port, soak it (soak()) and stop that roslaunch. ``argv``: the command line, for
    --output. Returns the exit status."""
    extra = ["config:=" + os.path.abspath(args.config)] if args.config else []
    with launched("sim.launch", extra) as launch:
        return soak(args, launch, argv)


def belief_steps(diag):
    """(stamp of the diagnostics message [s], belief steps so far) from the node's "loops" status,
    or None before the first one."""
    loops = diag.get("jackal_AIC: loops")
    if not loops or "belief steps" not in loops:
        return None
    return loops["_stamp"], int(loops["belief steps"])


def soak(args, launch, argv=None):
    """Drive the running simulator (``launch``: the roslaunch process) for args.minutes with a
    random set point (seed args.seed), inject a random fault every args.fault_every s after
    args.warmup s, print the figures (summary_lines()) and, with args.output, write them as
    Markdown (markdown(); ``argv`` the command line). Returns the exit status: 1 when the nodes
    did not start or a command was non-finite or beyond max_wheel_speed, else 0."""
    import rospy
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from geometry_msgs.msg import Twist
    from jackal_msgs.msg import Drive
    from sensor_msgs.msg import JointState

    rng = random.Random(args.seed)
    pids = wait_for_nodes(("jackal_AIC", "jackal_plant"), launch)
    if not pids:
        print("soak: the nodes did not start (roslaunch exit %s)" % launch.poll())
        return 1
    rospy.init_node("aic_soak", disable_signals=True)
    check = CommandCheck(rospy.get_param("/jackal_AIC/max_wheel_speed"))
    counts = {"cmd": 0, "js": 0}
    diag = {}
    health = {"events": set()}

    def on_cmd(m):
        counts["cmd"] += 1
        check.add(m.drivers, "%.1f s" % time.time())

    def on_js(_):
        counts["js"] += 1

    def on_health(m):
        v = {kv.key: kv.value for kv in m.values}
        if v.get("last event", "none") != "none":
            health["events"].add(v["last event"])

    rospy.Subscriber("/cmd_drive", Drive, on_cmd, queue_size=1000)
    rospy.Subscriber("/joint_states", JointState, on_js, queue_size=1000)
    rospy.Subscriber("/diagnostics", DiagnosticArray, diagnostics_callback(diag), queue_size=100)
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
    names = ("jackal_AIC", "jackal_plant")
    stats0 = {n: rss_and_cpu(pids[n]) for n in names}
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
    alive = launch.poll() is None
    stats1 = {n: rss_and_cpu(pids[n]) if alive else (0, 0.0) for n in names}
    span = t1 - t0
    fig = {"minutes": span / 60.0, "seed": args.seed, "fault_every": args.fault_every, "alive": alive,
           "faults": len(injected), "injected": sorted(set(injected)), "nodes": {},
           "cmd_rate": (c1["cmd"] - c0["cmd"]) / span, "js_rate": (c1["js"] - c0["js"]) / span,
           "commands": check.commands, "non_finite": check.non_finite, "over_limit": check.over_limit,
           "max_abs_wheel": check.max_abs, "limit": check.limit, "findings": list(check.findings),
           "belief_rate": None, "belief_nominal": rospy.get_param("/jackal_AIC/belief_rate", 1000.0),
           "events": sorted(e.rsplit(" at ", 1)[0] for e in health["events"])}
    for n in names:
        (r0, cpu0), (r1, cpu1) = stats0[n], stats1[n]
        fig["nodes"][n] = {"rss_start": r0, "rss_end": r1, "cpu": 100.0 * (cpu1 - cpu0) / span}
    if steps0 and steps1 and steps1[0] > steps0[0]:
        fig["belief_rate"] = (steps1[1] - steps0[1]) / (steps1[0] - steps0[0])
    ctrl = diag.get("jackal_AIC: controller", {})
    loops = diag.get("jackal_AIC: loops", {})
    drops = drop_counters(diag)
    fig.update({"runaway_resets": ctrl.get("runaway resets", "?"),
                "dropped": sum(v for k, v in drops.items() if k.startswith("dropped:")),
                "no_imu": drops.get("dropped: sample: no imu within imu_max_skew (sample used without the imu)", "?"),
                "stale_events": drops.get("stale events", "?"),
                "belief_overruns": loops.get("belief overruns (interval > 2 periods)", "?"),
                "action_overruns": loops.get("action overruns (interval > 2 periods)", "?")})
    for line in summary_lines(fig):
        print(line)
    if getattr(args, "output", None):
        with open(args.output, "w") as f:
            f.write(markdown(fig, argv))
        print("soak: figures written to %s" % args.output)
    return 0 if alive and check.clean() else 1


def summary_lines(fig):
    """The soak's figures (``fig``: the dict soak() builds) as the lines it prints."""
    out = ["soak: %.1f min, seed %d, %d faults injected (every %.0f s)" %
           (fig["minutes"], fig["seed"], fig["faults"], fig["fault_every"])]
    for n, s in sorted(fig["nodes"].items()):
        out.append("  %-13s RSS start %7d KiB, end %7d KiB, growth %+6d KiB; CPU %5.1f %%" %
                   (n, s["rss_start"], s["rss_end"], s["rss_end"] - s["rss_start"], s["cpu"]))
    out.append("  /cmd_drive   %.2f Hz (nominal %g: %+.2f %%)" %
               (fig["cmd_rate"], NOMINAL_RATE, 100.0 * (fig["cmd_rate"] / NOMINAL_RATE - 1)))
    out.append("  /joint_states %.2f Hz (nominal %g: %+.2f %%; faults drop or delay some)" %
               (fig["js_rate"], NOMINAL_RATE, 100.0 * (fig["js_rate"] / NOMINAL_RATE - 1)))
    out.append("  commands checked (warm-up included) %d: non-finite %d, beyond +-%g rad/s %d; max |wheel| %.3f rad/s" %
               (fig["commands"], fig["non_finite"], fig["limit"], fig["over_limit"], fig["max_abs_wheel"]))
    if fig["belief_rate"] is not None:
        out.append("  belief steps %.2f Hz (nominal %g: %+.3f %%; from the diagnostics counter)" %
                   (fig["belief_rate"], fig["belief_nominal"],
                    100.0 * (fig["belief_rate"] / fig["belief_nominal"] - 1)))
    out.append("  runaway resets %s; dropped inputs %s (no-imu samples %s); stale events %s" %
               (fig["runaway_resets"], fig["dropped"], fig["no_imu"], fig["stale_events"]))
    out.append("  belief overruns %s, action overruns %s" % (fig["belief_overruns"], fig["action_overruns"]))
    out.append("  fault events on ~sensor_health: %d distinct (%s)" %
               (len(fig["events"]), ", ".join(fig["events"])[:300]))
    out.append("  injected: %s" % "; ".join(fig["injected"]))
    if not fig["alive"]:
        out.append("  FINDING: the launch ended before the soak did")
    for f in fig["findings"]:
        out.append("  FINDING: %s" % f)
    return out


def markdown(fig, argv=None):
    """The soak's figures (``fig``: the dict soak() builds) as a Markdown document: a title, the
    command (``argv``, the script's arguments; default shown as aic_ros_soak.py with the run's seed)
    and a table of figure | value."""
    cmd = "scripts/aic_ros_soak.py " + (" ".join(argv) if argv else "--seed %d" % fig["seed"])
    rows = [("wall time", "%.1f min (real time, after the warm-up)" % fig["minutes"]),
            ("faults injected", "%d, one every %g s: %s" % (fig["faults"], fig["fault_every"],
                                                            "; ".join("`%s`" % f for f in fig["injected"]) or "none"))]
    for n, s in sorted(fig["nodes"].items()):
        rows.append(("%s resident memory" % n, "%d KiB at start, %d KiB at the end; growth %+d KiB" %
                     (s["rss_start"], s["rss_end"], s["rss_end"] - s["rss_start"])))
        rows.append(("%s CPU" % n, "%.1f %% of one core" % s["cpu"]))
    rows += [("/cmd_drive rate", "%.2f Hz (nominal %g: %+.2f %%)" %
              (fig["cmd_rate"], NOMINAL_RATE, 100.0 * (fig["cmd_rate"] / NOMINAL_RATE - 1))),
             ("/joint_states rate", "%.2f Hz (nominal %g: %+.2f %%; faults drop or delay some)" %
              (fig["js_rate"], NOMINAL_RATE, 100.0 * (fig["js_rate"] / NOMINAL_RATE - 1))),
             ("/cmd_drive commands checked", "%d (the warm-up included)" % fig["commands"]),
             ("non-finite commands", "%d" % fig["non_finite"]),
             ("commands beyond max_wheel_speed", "%d (limit %g rad/s; max abs wheel %.3f rad/s)" %
              (fig["over_limit"], fig["limit"], fig["max_abs_wheel"]))]
    if fig["belief_rate"] is not None:
        rows.append(("belief steps", "%.2f Hz (nominal %g: %+.3f %%)" %
                     (fig["belief_rate"], fig["belief_nominal"],
                    100.0 * (fig["belief_rate"] / fig["belief_nominal"] - 1))))
    rows += [("runaway resets", "%s" % fig["runaway_resets"]),
             ("dropped inputs", "%s (no-imu samples %s)" % (fig["dropped"], fig["no_imu"])),
             ("stale events", "%s" % fig["stale_events"]),
             ("belief / action overruns", "%s / %s" % (fig["belief_overruns"], fig["action_overruns"])),
             ("fault events on ~sensor_health",
              "%d distinct: %s" % (len(fig["events"]), ", ".join(fig["events"]) or "none")),
             ("node alive at the end", "yes" if fig["alive"] else "no")]
    lines = ["# ROS soak: the simulated Jackal and jackal_AIC on real time", "",
             "Written by `%s` (src/jackal_aic_tools/robustness/soak.py; doc/tools.md, 'ROS soak'): launch/sim.launch "
             "under its own ROS master on the wall clock, a random set point (seed %d) changing every 2-5 s, "
             "a random plant fault every %g s; CPU and resident memory from /proc, counters from /diagnostics." %
             (cmd, fig["seed"], fig["fault_every"]), "", "| figure | value |", "|---|---|"]
    lines += ["| %s | %s |" % (k, v.replace("|", "/")) for k, v in rows]
    if fig["findings"]:
        lines += ["", "Findings:", ""] + ["- %s" % f for f in fig["findings"]]
    return "\n".join(lines) + "\n"
