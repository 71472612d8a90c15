"""Launching and stopping ROS processes: the one place where the tools and the rostest checkers
start roslaunch, rosrun or rosbag (or a tool that launches ROS itself) and stop them again.

Two launchers, one per need:

- ``Simulator``: a launch file started through the roslaunch Python API inside this process,
  under its own ROS master on a free port (this process's ROS_MASTER_URI set to it). It tells
  which nodes died during the run (``deaths()``) and where their logs are; leaving the ``with``
  block shuts the launch and its master down. aic_experiment.py and aic_node_load.py drive the
  simulator this way.
- ``start()``: a command as a child process in a session (and so a process group) of its own,
  its output to a file or discarded; ``roslaunch()`` builds and starts a roslaunch command, and
  ``launched()`` runs one under its own master on a free port for the length of a ``with``
  block. ``stop()`` reaches everything such a process started and nothing else.
  aic_ros_soak.py, aic_ros_fuzz.py, aic_sweep.py (each run of aic_experiment.py) and the rostest
  checkers that start launch files, rosrun or rosbag themselves use it.

The one stop routine, ``stop(proc, timeout)``: SIGINT to the process group (what Ctrl-C in a
terminal sends: roslaunch shuts its nodes and, if it started one, its master down), up to
``timeout`` seconds for the process to end, then SIGKILL to the group; the process is reaped
either way, and a group that has ended already is no error.

``find_node()`` / ``wait_for_nodes()`` find the PIDs of the nodes a started roslaunch runs (psutil);
``node_pid()`` the PID of any running node, from its XML-RPC API.
"""
import contextlib
import logging
import os
import signal
import socket
import subprocess
import time

import psutil

#: Seconds stop() gives a process group to end after SIGINT before it sends SIGKILL.
STOP_TIMEOUT = 20.0


def free_port():
    """A TCP port nobody listens on now (for a run's own master)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        s.bind(("", 0))
        return s.getsockname()[1]
    finally:
        s.close()


# ---- child processes in their own process group --------------------------------------------

def start(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT, **popen_args):
    """Start ``cmd`` (argument list) as a child process in a new session, so that it and every
    process it starts form a process group of their own that stop() ends as a whole (and a
    Ctrl-C at this process's terminal does not reach). ``stdout``/``stderr``: as for
    subprocess.Popen (default: output discarded); further keyword arguments go to Popen.
    Returns the Popen."""
    return subprocess.Popen(cmd, stdout=stdout, stderr=stderr, start_new_session=True, **popen_args)


def roslaunch_command(launch_file, launch_args=(), package="jackal_aic", port=None):
    """The command line ``roslaunch [-p PORT] <package> <launch_file> <launch_args...>``; with
    ``port``, roslaunch starts a master of its own on that port when none runs there."""
    return ["roslaunch"] + (["-p", str(port)] if port else []) + [package, launch_file] + list(launch_args)


def roslaunch(launch_file, launch_args=(), package="jackal_aic", port=None, **start_args):
    """start() ``roslaunch_command(launch_file, launch_args, package, port)``; ``start_args``:
    those of start() (stdout, stderr, env, ...). Returns the Popen."""
    return start(roslaunch_command(launch_file, launch_args, package, port), **start_args)


def interrupt(proc):
    """SIGINT to the process group of ``proc`` (started by start()), as Ctrl-C in a terminal
    would send it. Returns False when the group has ended already, else True."""
    try:
        os.killpg(proc.pid, signal.SIGINT)
    except ProcessLookupError:
        return False
    return True


def stop(proc, timeout=STOP_TIMEOUT):
    """Stop the process group of ``proc`` (a Popen from start()): SIGINT to the group, up to
    ``timeout`` [s] for ``proc`` to end, then SIGKILL to the group. Only this group is signalled,
    never a process this one did not start. Returns ``proc``'s exit status (negative: the
    signal that ended it)."""
    if not interrupt(proc):  # it ended by itself (e.g. roslaunch after a required node died)
        return proc.wait()
    try:
        return proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        return proc.wait()


@contextlib.contextmanager
def launched(launch_file, launch_args=(), log_path=None, timeout=STOP_TIMEOUT):
    """Context manager: start ``roslaunch jackal_aic <launch_file> <launch_args...>`` under its own
    master on a free port (ROS_MASTER_URI of this process set to it), yield the roslaunch Popen,
    and stop that roslaunch only (stop(): SIGINT to its process group, SIGKILL after ``timeout``
    s). ``log_path``: a file for roslaunch's output (the nodes' output="screen" included);
    default discarded."""
    port = free_port()
    os.environ["ROS_MASTER_URI"] = "http://localhost:%d" % port
    out = open(log_path, "w") if log_path else subprocess.DEVNULL
    launch = roslaunch(launch_file, launch_args, port=port, stdout=out)
    try:
        yield launch
    finally:
        stop(launch, timeout)
        if log_path:
            out.close()


def find_node(name, root):
    """PID of the process with the argument __name:=<name> among the descendants of process
    ``root`` (a roslaunch started here); the lowest PID when several have it, None when none."""
    arg = "__name:=" + name
    try:
        descendants = psutil.Process(root).children(recursive=True)
    except psutil.NoSuchProcess:
        return None
    found = []
    for p in descendants:
        try:
            if arg in p.cmdline():
                found.append(p.pid)
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
    return min(found) if found else None


def node_pid(name, caller="/jackal_aic_tools"):
    """PID of the running ROS node ``name`` (e.g. "/jackal_plant"), asked through its own XML-RPC
    API (getPid) on the master of this process's ROS_MASTER_URI; None when the master does not
    know the node or it does not answer. ``caller`` is the caller ID the requests carry."""
    import rosgraph
    import rosnode
    from xmlrpc.client import ServerProxy, Error
    try:
        uri = rosnode.get_api_uri(rosgraph.Master(caller), name)
        if not uri:
            return None
        code, _, pid = ServerProxy(uri).getPid(caller)
    except (rosnode.ROSNodeIOException, OSError, Error):
        return None
    return pid if code == 1 else None


def wait_for_nodes(names, launch, timeout=60.0):
    """{name: PID} of the nodes ``names`` started by ``launch`` (a roslaunch Popen), waiting up to
    ``timeout`` [s] of wall time; None when one of them did not appear."""
    deadline = time.time() + timeout
    while time.time() < deadline and launch.poll() is None:
        pids = {n: find_node(n, launch.pid) for n in names}
        if all(pids.values()):
            return pids
        time.sleep(0.5)
    return None


# ---- a launch file inside this process (roslaunch Python API) ------------------------------

class _DeathListener(object):
    """roslaunch process listener: remembers nodes that exit while the run is live."""

    def __init__(self):
        self.died = []
        self.armed = True

    def process_died(self, name, exit_code):
        if self.armed and not name.startswith("rosout"):
            self.died.append((name, exit_code))


class Simulator(object):
    """A launch file (e.g. sim.launch) with ``launch_args`` under its own master on a free port,
    started with the roslaunch Python API in this process. Use as a context manager. ``verbose``:
    roslaunch's summary and the nodes' logs on the screen; ``log``: the logger that reports the
    start (default this module's)."""

    def __init__(self, launch_file, launch_args, verbose=False, log=None):
        self.launch_file = launch_file
        self.launch_args = list(launch_args)
        self.verbose = verbose
        self.log = log or logging.getLogger(__name__)
        self.parent = None
        self.listener = _DeathListener()
        self.port = None

    def __enter__(self):
        import roslaunch
        import rosgraph.network
        self.port = free_port()
        uri = rosgraph.network.create_local_xmlrpc_uri(self.port)
        os.environ["ROS_MASTER_URI"] = uri
        uuid = roslaunch.rlutil.get_or_generate_uuid(None, False)
        roslaunch.configure_logging(uuid)
        self.log.info("starting %s %s with a master at %s", self.launch_file, " ".join(self.launch_args), uri)
        self.parent = roslaunch.parent.ROSLaunchParent(
            uuid, [(self.launch_file, self.launch_args)], port=self.port,
            process_listeners=[self.listener], force_log=not self.verbose, show_summary=self.verbose)
        self.parent.start(auto_terminate=False)
        import rospkg
        self.log_dir = os.path.join(rospkg.get_log_dir(), uuid)
        return self

    def deaths(self):
        """Nodes that died, with where their logs are."""
        if not self.listener.died:
            return []
        return ["%s (exit %s)" % d for d in self.listener.died] + ["logs: %s" % self.log_dir]

    def __exit__(self, *exc):
        self.listener.armed = False
        if self.parent is not None:
            self.parent.shutdown()
        return False
