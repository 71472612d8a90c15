"""Measure what the jackal_AIC node costs on the simulated Jackal, in wall-clock time.

For each belief rate: starts launch/sim.launch (the ODE plant and the node, wall clock)
under its own ROS master, holds a 0.5 m/s set point, waits --warmup seconds, then over
--duration seconds reads the node's CPU time (psutil, from /proc: user + system, all threads,
and per thread) and its belief step counter from
/diagnostics ("loops": "belief steps", "belief time integrated [s]", the command latency),
and prints one table row per rate and belief schedule: CPU share of one core (node; its
belief thread), belief steps per second, belief time integrated per second of wall time,
the sensor-to-command latency p50 / p99, and the plant's CPU for scale.

With --bare, also runs `aic_timing --rates RATE --duration DURATION` for each rate and adds
the CPU share of its bare clock_nanosleep loop (the floor of any thread that wakes at that
rate) and of its belief loop (the node's belief schedule timer without ROS). With --output,
the table is also written to a Markdown file with the command, the host's load average
before and after, and the configuration (doc/results/node_load.md).

Example (doc/results/node_load.md, linked from doc/jackal_aic_node.md, 'Loops'):
  aic_node_load.py --rates 1000,10000 --duration 30 --schedules event,timer --bare \
      --output doc/results/node_load.md
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

from ..common import cli, ros_process
from ..experiment import experiment
from .node_watch import cpu_seconds, loadavg, thread_times


def measure_one(rate, config, duration, warmup, overrides, base="direct"):
    """Child process: one rate under its own master, sim.launch with ``base`` (direct |
    stock_diff_drive: the stock controller node stock_base maps the node's twist to the wheels,
    and its CPU is measured in the same window); prints one JSON line."""
    import rospy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import Twist

    launch = os.path.join(cli.package_path(), "launch", "sim.launch")
    with tempfile.TemporaryDirectory() as tmp:
        cfg = os.path.join(tmp, "config.yaml")
        overrides = dict(overrides)
        overrides["belief_rate"] = float(rate)
        experiment.write_config(config, overrides, cfg)
        with ros_process.Simulator(launch, ["config:=" + cfg, "use_sim_time:=false", "base:=" + base]) as sim:
            rospy.init_node("aic_node_load", disable_signals=True)
            steps = []
            lock = threading.Lock()

            def on_diag(msg):
                for status in msg.status:
                    if status.name.endswith("loops"):
                        values = {kv.key: kv.value for kv in status.values}
                        if "belief steps" in values:
                            with lock:
                                steps.append((msg.header.stamp.to_sec(), int(values["belief steps"]),
                                              float(values["belief time integrated [s]"]),
                                              values.get("belief loop", ""),
                                              float(values["command latency p50 [ms] (sensor stamp -> /cmd_drive)"]),
                                              float(values["command latency p99 [ms]"])))

            rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag)
            pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=1)
            stop = threading.Event()

            def hold():
                t = Twist()
                t.linear.x = 0.5
                while not stop.is_set():
                    pub.publish(t)
                    time.sleep(0.05)

            threading.Thread(target=hold, daemon=True).start()
            deadline = time.time() + 60.0
            pid = plant = stock = None
            want_stock = base == "stock_diff_drive"
            while time.time() < deadline and (pid is None or plant is None or (want_stock and stock is None)):
                pid = pid or ros_process.node_pid("/jackal_AIC", "/aic_node_load")
                plant = plant or ros_process.node_pid("/jackal_plant", "/aic_node_load")
                stock = stock or (ros_process.node_pid("/stock_base", "/aic_node_load") if want_stock else None)
                time.sleep(0.5)
            if pid is None or (want_stock and stock is None):
                raise RuntimeError("no /jackal_AIC or /stock_base node: %s" % sim.deaths())
            time.sleep(warmup)

            def stock_cpu():
                return cpu_seconds(stock) if stock else float("nan")
            t0 = time.time()
            c0, p0, th0 = cpu_seconds(pid), cpu_seconds(plant), thread_times(pid)
            s0 = stock_cpu()
            time.sleep(duration)
            t1 = time.time()
            c1, p1, th1 = cpu_seconds(pid), cpu_seconds(plant), thread_times(pid)
            s1 = stock_cpu()
            stop.set()
            with lock:
                window = [s for s in steps if s[0] >= t0 - 1.0]
            if len(window) < 2:
                raise RuntimeError("too few diagnostics in the window")
            (ta, na, ia, loop, _, _), (tb, nb, ib, _, _, _) = window[0], window[-1]
            p50s = sorted(w[4] for w in window[1:])
            belief_thread = sum(th1[k] - th0.get(k, 0.0) for k in th1 if k.startswith("aic_belief"))
            row = {
                "rate": rate, "duration": t1 - t0, "loop": loop,
                "node_cpu": (c1 - c0) / (t1 - t0), "belief_thread_cpu": belief_thread / (t1 - t0),
                "plant_cpu": (p1 - p0) / (t1 - t0), "stock_cpu": (s1 - s0) / (t1 - t0),
                "belief_steps_rate": (nb - na) / (tb - ta), "belief_time_fraction": (ib - ia) / (tb - ta),
                "latency_p50_ms": p50s[len(p50s) // 2], "latency_p99_ms": max(w[5] for w in window[1:]),
                "threads": {k: round(100 * (th1[k] - th0.get(k, 0.0)) / (t1 - t0), 2)
                            for k in th1 if th1[k] - th0.get(k, 0.0) > 0},
            }
            print("RESULT " + json.dumps(row))
            sys.stdout.flush()


def bare_loop(rate, duration, script_file):
    """(bare loop CPU, belief-loop CPU) [share of one core] from aic_timing at one rate."""
    exe = cli.find_executable("aic_timing", script_file, "aic_node_load.py")
    out = subprocess.run([exe, "--rates", "%g" % rate, "--duration", "%g" % duration],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, check=True).stdout
    cpu = {}
    for line in out.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 10 and cells[0] in ("belief", "bare"):
            cpu[cells[0]] = float(re.sub(r"[^0-9.]", "", cells[9])) / 100.0
    if "bare" not in cpu:
        raise RuntimeError("aic_timing printed no bare row: %s" % out)
    return cpu["bare"], cpu.get("belief", float("nan"))


def measure(a, rates, schedules, argv, script_file):
    """Measure every rate of ``rates`` [Hz] and belief schedule of ``schedules``, each in a child
    process (``script_file`` --one RATE: measure_one), print the table row by row and, with
    a.output, write it as Markdown (a: parsed arguments of aic_node_load.py; argv: its command
    line's arguments, or None for sys.argv[1:]). Returns the exit status (1 when a run failed)."""
    lines = ["| belief rate [Hz] | belief_schedule | beliefs advanced on | node CPU (1 core) | belief thread CPU "
             "| belief steps [Hz] | belief time integrated per second | latency p50 / p99 [ms] | plant CPU "
             "| stock controller node CPU (node / stock) | bare loop CPU (aic_timing) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for line in lines:
        print(line)
    load_before = loadavg()
    failed = 0
    for rate in rates:
        bare = ""
        if a.bare:
            try:
                b, belief = bare_loop(rate, a.duration, script_file)
                bare = "%.2f %% (its belief loop %.2f %%)" % (100 * b, 100 * belief)
            except (OSError, RuntimeError, subprocess.CalledProcessError) as e:
                bare = "failed: %s" % e
        for schedule in schedules:
            # One process per run: rospy joins one master per process.
            proc = subprocess.run([sys.executable, os.path.abspath(script_file), "--one", str(rate),
                                   "--duration", str(a.duration), "--warmup", str(a.warmup), "--config", a.config,
                                   "--base", a.base]
                                  + ["--set=" + o for o in a.set] + ["--set=belief_schedule=" + schedule],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
            found = [l for l in proc.stdout.splitlines() if l.startswith("RESULT ")]
            if proc.returncode != 0 or not found:
                failed += 1
                line = "| %.0f | %s | failed: %s |" % (rate, schedule, (proc.stderr.strip().splitlines() or ["?"])[-1])
                print(line)
                lines.append(line)
                continue
            r = json.loads(found[-1][len("RESULT "):])
            stock = r.get("stock_cpu", float("nan"))
            stock_text = "-" if stock != stock else "%.2f %% (%.2f)" % (100 * stock, r["node_cpu"] / stock if stock > 0
                                                                        else float("inf"))
            line = "| %.0f | %s | %s | %.2f %% | %.2f %% | %.2f | %.2f %% | %.2f / %.2f | %.1f %% | %s | %s |" % (
                rate, schedule, r["loop"], 100 * r["node_cpu"], 100 * r["belief_thread_cpu"], r["belief_steps_rate"],
                100 * r["belief_time_fraction"], r["latency_p50_ms"], r["latency_p99_ms"], 100 * r["plant_cpu"],
                stock_text, bare or "-")
            print(line)
            lines.append(line)
            if a.threads:
                line = "|   | threads [%% of a core]: %s |" % ", ".join("%s %.2f" % kv for kv in sorted(
                    r["threads"].items(), key=lambda kv: -kv[1]))
                print(line)
                lines.append(line)
            sys.stdout.flush()
    if a.output:
        command = "scripts/aic_node_load.py " + " ".join(argv if argv is not None else sys.argv[1:])
        with open(a.output, "w") as f:
            f.write("# Node CPU and sensor-to-command latency\n\n")
            f.write("Generated by `%s`: the node on the simulated Jackal (launch/sim.launch base:=%s, wall clock, "
                    "0.5 m/s set point), CPU from /proc over each window, belief steps and latency from "
                    "/diagnostics (\"loops\"); the bare loop is aic_timing's `clock_nanosleep` loop at the same "
                    "rate. Configuration: %s%s. Host load average (1, 5, 15 min) before: %s, after: %s; "
                    "%d CPU(s).\n\n" % (command, a.base, os.path.basename(a.config),
                                        "".join(", " + o for o in a.set), load_before, loadavg(), os.cpu_count()))
            f.write("\n".join(lines) + "\n")
    return 1 if failed else 0
