"""A process's resource use from Linux's /proc: CPU time, per-thread CPU time, resident memory,
parent (aic_node_load.py, aic_soak.py)."""
import os

CLK_TCK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(stat_path):
    """utime + stime [s] of a /proc/.../stat file (fields 14 and 15; the name may hold spaces).
    Raises OSError when the file cannot be read (the process is gone)."""
    with open(stat_path) as f:
        text = f.read()
    fields = text[text.rindex(")") + 2:].split()
    return (int(fields[11]) + int(fields[12])) / float(CLK_TCK)


def thread_times(pid):
    """{"<thread name>:<tid>": CPU s} for every thread of ``pid`` (names as set by
    pthread_setname_np); threads that end while being read are left out."""
    out = {}
    task = "/proc/%d/task" % pid
    for tid in os.listdir(task):
        try:
            with open(os.path.join(task, tid, "comm")) as f:
                name = f.read().strip()
            out[name + ":" + tid] = cpu_seconds(os.path.join(task, tid, "stat"))
        except OSError:
            pass
    return out


def proc_stats(pid):
    """(RSS [KiB], CPU time [s]) of a process from /proc."""
    rss = 0
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1])
    return rss, cpu_seconds("/proc/%d/stat" % pid)


def parent_of(pid):
    """The parent's PID of process ``pid``."""
    with open("/proc/%d/stat" % pid) as f:
        return int(f.read().rsplit(")", 1)[1].split()[1])
