"""A cgroup per sandbox: a memory limit that counts every page, a CPU limit, and a list of every process.

``RLIMIT_AS`` counts what one process maps, not an anonymous file's or a tmpfs's pages, nor children together; a
memory cgroup counts them all and lists every process, and one core per sandbox keeps a spinning submission from
slowing a classmate. Where no cgroup can be made (v2, or v1's memory and cpu hierarchies) :func:`create` returns
None.
"""

import contextlib
import os
import signal
import time
from pathlib import Path

ROOT = Path("/sys/fs/cgroup")
PARENT = "LABKIT_CGROUP_PARENT"  # where a grading process makes its sandboxes' cgroups (beside its own)


def _own(controller):
    """The grading process's cgroup in the v1 hierarchy of `controller`, or in v2 ("v2"); None if none."""
    try:
        lines = Path("/proc/self/cgroup").read_text().splitlines()
    except OSError:
        return None
    for line in lines:
        number, controllers, path = line.split(":", 2)
        if (number == "0" and controllers == "") if controller == "v2" else controller in controllers.split(","):
            return path
    return None


def _candidates():
    """(version, folder in which to make sandbox cgroups) in the order to try."""
    given = os.environ.get(PARENT, "")
    if given.count(":") == 1:
        version, folder = given.split(":")
        if os.path.isdir(folder):
            return [(version, Path(folder))]
    found = []
    v1 = _own("memory")
    if v1 is not None and (ROOT / "memory").is_dir():
        found.append(("v1", ROOT / "memory" / v1.lstrip("/")))
    v2 = _own("v2")
    if v2 is not None:
        for mount in (ROOT, ROOT / "unified"):
            if (mount / "cgroup.controllers").exists():
                found.append(("v2", mount / v2.lstrip("/")))
                break
    return found


class MemoryCgroup:
    """One sandbox's cgroup with a memory limit (and, with v1, a cpu cgroup beside it)."""

    def __init__(self, version, path, cpu_path=None):
        self.version, self.path, self.cpu_path = version, path, cpu_path
        self.folders = [folder for folder in (path, cpu_path) if folder is not None]

    def sibling_environment(self):
        """What to put in the environment of a process in this cgroup so its own cgroups are made beside it."""
        found = {PARENT: f"{self.version}:{self.path.parent}"}
        if self.cpu_path is not None:
            found[PARENT + "_CPU"] = str(self.cpu_path.parent)
        return found

    def join(self):
        """Move the calling process (and so everything it starts) into the cgroup: call it in the child."""
        for folder in self.folders:
            with open(folder / "cgroup.procs", "w") as handle:
                handle.write(str(os.getpid()))

    def peak(self):
        """The most memory the cgroup held at once, in bytes (None if the kernel does not say)."""
        name = "memory.max_usage_in_bytes" if self.version == "v1" else "memory.peak"
        try:
            return int((self.path / name).read_text().split()[0])
        except (OSError, ValueError, IndexError):
            return None

    def out_of_memory(self):
        """Whether the kernel stopped a process of the cgroup for going over the limit."""
        try:
            name = "memory.oom_control" if self.version == "v1" else "memory.events"
            events = dict(line.split() for line in (self.path / name).read_text().splitlines() if line.strip())
            return int(events.get("oom_kill", 0)) > 0
        except (OSError, ValueError):
            return False

    def remove(self):
        """Stop every process still in the cgroup and remove it."""
        for _ in range(200):
            try:
                pids = [int(p) for p in (self.path / "cgroup.procs").read_text().split()]
            except (OSError, ValueError):
                pids = []
            if not pids:
                break
            for pid in pids:
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.kill(pid, signal.SIGKILL)
            time.sleep(0.005)  # a killed process leaves its cgroup within milliseconds
        for folder in self.folders:
            for _ in range(50):
                try:
                    folder.rmdir()
                    break
                except FileNotFoundError:
                    break
                except OSError:
                    time.sleep(0.02)


def _cpu_v1(name, cores):
    """A v1 cpu cgroup limited to `cores` cores beside our own, or None."""
    own = _own("cpu")
    root = ROOT / "cpu"
    if own is None or not (root / "cpu.cfs_quota_us").exists():
        return None
    given = os.environ.get(PARENT + "_CPU", "")
    parent = Path(given) if given and os.path.isdir(given) else root / own.lstrip("/")
    path = parent / name
    try:
        path.mkdir()
        period = int((path / "cpu.cfs_period_us").read_text())
        (path / "cpu.cfs_quota_us").write_text(str(int(period * cores)))
    except (OSError, ValueError):
        with contextlib.suppress(OSError):
            path.rmdir()
        return None
    return path


def create(limit, label="labkit", cores=1):
    """A new cgroup of `limit` bytes (and `cores` cores where possible) for one sandbox, or None where none can be."""
    for version, parent in _candidates():
        name = f"{label}-{os.getpid()}-{time.monotonic_ns()}"
        path = parent / name
        try:
            path.mkdir()
        except OSError:
            continue
        if version == "v1":
            limit_file, settings = "memory.limit_in_bytes", {"memory.memsw.limit_in_bytes": str(int(limit))}
        else:
            limit_file, settings = "memory.max", {"memory.swap.max": "0"}
            if cores:
                settings["cpu.max"] = f"{int(100_000 * cores)} 100000"
        try:
            (path / limit_file).write_text(str(int(limit)))
        except OSError:
            with contextlib.suppress(OSError):
                path.rmdir()
            continue
        for setting, value in settings.items():  # where the kernel has them: no swapping past the limit, cores
            with contextlib.suppress(OSError):
                (path / setting).write_text(value)
        cpu = _cpu_v1(name, cores) if version == "v1" and cores else None
        return MemoryCgroup(version, path, cpu)
    return None
