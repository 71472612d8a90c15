"""The ideal controller's runs kept between benchmark runs (doc/results/ideal_runs.json).

The ideal controller (plant_limits.ideal_command: `closed_loop_run --controller ideal`, eight
learning runs per profile) depends on the plant, its YAMLs, the profile and the tool, never on the
AIC's settings, and takes ~7 x an AIC run. Its results are kept in a JSON file, each under a key
made of its command line with every file argument replaced by the SHA-256 of the file's bytes;
the file as a whole is valid only for the sources it was written from: the SHA-256 over the
repository's files the ideal run is built from (IDEAL_SOURCES). Any change to one of them (or a
tree without them, such as an install space) makes every entry a miss, so a kept result is
never used for a plant or a tool that differs from the one that made it: the run is repeated.

Written by `aic_scorecard.py --doc` (doc/tools.md, 'Plant-limited pairs'); read by every
driving.Runner that is given an IdealCache.
"""
import hashlib
import json
import os
import threading

#: Repository-relative files and folders the ideal controller's result is built from: the plant,
#: the closed loop with the ideal controller, the tool and its metrics, this package's ideal command.
IDEAL_SOURCES = (
    "sim/plant", "sim/harness", "sim/urdf",
    "tools/src/closed_loop_run.cpp", "tools/lib", "tools/include",
    "include/jackal_aic/analysis", "src/analysis", "include/jackal_aic/base/json_number.hpp",
    "include/jackal_aic/overrides", "src/overrides",
    "src/jackal_aic_tools/track/plant_limits.py",
)
#: The kept runs, relative to the repository root.
IDEAL_RUNS = os.path.join("doc", "results", "ideal_runs.json")


def file_digest(path):
    """SHA-256 (hex) of the bytes of the file ``path``. Raises OSError when it cannot be read."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 16), b""):
            h.update(block)
    return h.hexdigest()


def sources_digest(root, sources=IDEAL_SOURCES):
    """SHA-256 (hex) over every file of ``sources`` (paths relative to ``root``, folders walked),
    in sorted order of their relative paths, each path and its bytes' digest hashed in. None when
    one of them is missing (e.g. an install space without the sources): nothing can be kept."""
    files = []
    for rel in sources:
        path = os.path.join(root, rel)
        if os.path.isfile(path):
            files.append(rel)
        elif os.path.isdir(path):
            for d, _, names in os.walk(path):
                files += [os.path.relpath(os.path.join(d, n), root) for n in names]
        else:
            return None
    h = hashlib.sha256()
    for rel in sorted(f.replace(os.sep, "/") for f in files):
        h.update(rel.encode() + b"\0" + file_digest(os.path.join(root, rel)).encode() + b"\n")
    return h.hexdigest()


def command_key(cmd):
    """The key of one ideal run's command line ``cmd`` (closed_loop_run's argument list): the
    executable dropped, every argument naming an existing file replaced by "sha256:" and the
    digest of its bytes, the rest as given, joined by NUL. The same plant YAML, overlay and profile
    under other paths give the same key."""
    parts = []
    for arg in list(cmd)[1:]:
        parts.append("sha256:" + file_digest(arg) if os.path.isfile(arg) else str(arg))
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()


class IdealCache:
    """Kept results of the ideal controller for one repository tree (thread-safe).

    root: the repository root; path: the JSON file (default root/IDEAL_RUNS). On construction the
    file's entries are loaded when its "sources" equal sources_digest(root); otherwise (missing,
    unreadable, other sources) the cache starts empty. get()/put() by command line; hits and misses
    are counted; save() writes the entries with the sources they belong to."""

    def __init__(self, root, path=None):
        self.root = root
        self.path = path or os.path.join(root, IDEAL_RUNS)
        self.sources = sources_digest(root)
        self.entries = {}
        self.hits = self.misses = 0
        self.status = "no sources: every ideal run repeated" if self.sources is None else "no kept runs"
        self._lock = threading.Lock()
        if self.sources is None or not os.path.isfile(self.path):
            return
        try:
            with open(self.path) as f:
                data = json.load(f)
            kept = data.get("sources") if isinstance(data, dict) else None
            entries = data.get("entries") if isinstance(data, dict) else None
        except (OSError, ValueError) as e:
            self.status = "unreadable (%s): every ideal run repeated" % e
            return
        if kept != self.sources or not isinstance(entries, dict):
            self.status = "written from other sources: every ideal run repeated"
            return
        self.entries = entries
        self.status = "%d kept runs, sources unchanged" % len(entries)

    def get(self, cmd):
        """The kept result (closed_loop_run's JSON dict) of the command line ``cmd``, or None."""
        if self.sources is None:
            return None
        key = command_key(cmd)
        with self._lock:
            hit = self.entries.get(key)
            if hit is None:
                self.misses += 1
            else:
                self.hits += 1
            return hit

    def put(self, cmd, result):
        """Keep ``result`` (a JSON-serializable dict) for the command line ``cmd``."""
        if self.sources is None:
            return
        key = command_key(cmd)
        with self._lock:
            self.entries[key] = result

    def save(self):
        """Write the entries with the sources digest to self.path. Raises RuntimeError when there
        are no sources to key them by, OSError when the file cannot be written."""
        if self.sources is None:
            raise RuntimeError("ideal runs: no sources under %s to key them by" % self.root)
        with self._lock:
            entries = dict(self.entries)
        os.makedirs(os.path.dirname(os.path.abspath(self.path)), exist_ok=True)
        with open(self.path, "w") as f:
            json.dump({"written_by": "scripts/aic_scorecard.py --driving --doc", "sources": self.sources,
                       "entries": entries}, f, indent=1, sort_keys=True)
            f.write("\n")
