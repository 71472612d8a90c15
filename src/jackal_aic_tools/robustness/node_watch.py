"""What the robustness tools watch of the running nodes (aic_ros_soak.py, aic_ros_fuzz.py,
aic_node_load.py): the verdict on the jackal_AIC node's wheel commands (CommandCheck), its
/diagnostics (diagnostics_callback, drop_counters), and the resource use of a process and of
the host (psutil: CPU time, per-thread CPU time, resident memory; the load average).
"""
import math
import struct

import psutil


def float32(x):
    """``x`` rounded to the nearest IEEE 754 single (what a float32 message field holds)."""
    return struct.unpack("f", struct.pack("f", x))[0]


class CommandCheck(object):
    """The verdict on the node's wheel commands (jackal_msgs/Drive.drivers, [rad/s]): counts the
    commands, the non-finite ones and those with |wheel| > ``limit`` [rad/s] (the limit rounded to
    float32 first, the field's type, so that a command clamped exactly to the limit passes), and
    keeps the largest |wheel| and the first few findings as text."""

    KEEP = 5  # findings kept as text

    def __init__(self, limit):
        self.limit = float32(float(limit))
        self.commands = 0
        self.non_finite = 0
        self.over_limit = 0
        self.max_abs = 0.0
        self.findings = []

    def add(self, drivers, stamp=None):
        """Judge one command ``drivers`` (sequence of 2 wheel speeds [rad/s]) received at
        ``stamp`` (any label for the findings, e.g. seconds since the start)."""
        self.commands += 1
        vals = [float(d) for d in drivers]
        if not all(math.isfinite(d) for d in vals):
            self.non_finite += 1
            self._finding("non-finite command %r at %s" % (vals, stamp))
            return
        m = max(abs(d) for d in vals) if vals else 0.0
        self.max_abs = max(self.max_abs, m)
        if m > self.limit:
            self.over_limit += 1
            self._finding("command %r beyond +-%g at %s" % (vals, self.limit, stamp))

    def _finding(self, text):
        if len(self.findings) < self.KEEP:
            self.findings.append(text)

    def clean(self):
        """True when no command was non-finite or over the limit."""
        return self.non_finite == 0 and self.over_limit == 0


def diagnostics_callback(diag):
    """A /diagnostics (DiagnosticArray) callback that keeps, in the dict ``diag``, each status's
    last {key: value} under its name, with the message's stamp [s] under "_stamp"."""
    def on_diag(m):
        for st in m.status:
            values = {kv.key: kv.value for kv in st.values}
            values["_stamp"] = m.header.stamp.to_sec()
            diag[st.name] = values
    return on_diag


def drop_counters(diag):
    """{counter: int} of the node's input drops from the last "jackal_AIC: sensors" status
    (``diag``: {status name: {key: value}}, as diagnostics_callback() keeps them): every
    "dropped: ..." key, "set points clamped" and "stale events"; values that are not integers are
    left out."""
    sens = diag.get("jackal_AIC: sensors", {})
    out = {}
    for k, v in sens.items():
        if k.startswith("dropped:") or k in ("set points clamped", "stale events"):
            try:
                out[k] = int(v)
            except (TypeError, ValueError):
                pass
    return out


# ---- resource use (psutil) ------------------------------------------------------------------

def cpu_seconds(pid):
    """User + system CPU time [s] of process ``pid``, all its threads. Raises
    psutil.NoSuchProcess when the process is gone."""
    t = psutil.Process(pid).cpu_times()
    return t.user + t.system


def thread_times(pid):
    """{"<thread name>:<tid>": user + system CPU time [s]} for every thread of ``pid`` (names as
    set by pthread_setname_np); threads that end while being read are left out."""
    out = {}
    for t in psutil.Process(pid).threads():
        try:
            name = psutil.Process(t.id).name()
        except psutil.NoSuchProcess:
            continue
        out["%s:%d" % (name, t.id)] = t.user_time + t.system_time
    return out


def rss_and_cpu(pid):
    """(resident memory [KiB], user + system CPU time [s]) of process ``pid``."""
    p = psutil.Process(pid)
    t = p.cpu_times()
    return p.memory_info().rss // 1024, t.user + t.system


def loadavg():
    """The host's load average over 1, 5 and 15 min, as /proc/loadavg gives it."""
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])
