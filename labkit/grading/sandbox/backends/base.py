"""What every sandbox backend provides, and what backends share.

Grading uses a backend only through :class:`Backend`, which makes a :class:`Box` per notebook: the worker in a
session of its own, in a memory cgroup of its own where one can be made (:mod:`labkit.grading.sandbox.cgroup`) and
under the rlimits (:func:`apply_limits`).
"""

import abc
import contextlib
import os
import resource
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from .. import cgroup, protocol

WORKER_IMPORTS = 512 * 1024**2  # bytes of a notebook's cgroup on top of its limit: the worker's own imports


class SandboxUnavailable(RuntimeError):
    """A backend cannot run sandboxes on this machine; the message says what to do instead."""


@dataclass(frozen=True)
class Limits:
    """Resource limits of one notebook's sandbox."""

    memory: int = 4 * 1024**3  # bytes of address space per process, and of the whole sandbox's cgroup
    cpu_seconds: int = 900  # per process
    processes: int = 64  # processes and threads of the sandbox's uid
    file_size: int = 64 * 1024**2  # bytes per file written
    open_files: int = 256
    tmp_size: int = 256 * 1024**2  # bytes of the private /tmp
    home_size: int = 256 * 1024**2  # bytes of the private home folder


def apply_limits(limits, processes_base=0):
    """Set the rlimits of the calling process (a child about to exec the sandbox or the worker)."""

    def cap(kind, value):
        hard = resource.getrlimit(kind)[1]
        value = value if hard == resource.RLIM_INFINITY else min(value, hard)
        resource.setrlimit(kind, (value, value))

    cap(resource.RLIMIT_AS, limits.memory)
    cap(resource.RLIMIT_CPU, limits.cpu_seconds)
    cap(resource.RLIMIT_NPROC, processes_base + limits.processes)
    cap(resource.RLIMIT_FSIZE, limits.file_size)
    cap(resource.RLIMIT_NOFILE, limits.open_files)


def environment_paths():
    """The folders of the Python environment a worker needs (its prefixes and labkit's package folder), outside
    /usr and /etc, none inside another: what a sandbox shows it read-only."""
    import labkit

    paths = {Path(p).resolve() for p in (sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix)}
    paths.add(Path(labkit.__file__).resolve().parent)
    paths.add(Path(sys.executable).resolve().parent.parent)
    system = (Path("/usr"), Path("/etc"))
    paths = {p for p in paths if p.exists() and not any(p == s or s in p.parents for s in system)}
    # a folder inside another one is mounted with it
    return sorted(p for p in paths if not any(q != p and q in p.parents for q in paths))


def course_mounts():
    """(course module's file or package, where the sandbox shows it) for each course module graded here and not in
    the environment: only the module, never the folder around it (with the course's submissions and grades)."""
    from ....exercises.registry import COURSES

    environment = environment_paths()
    mounts = []
    for name, origin in sorted(COURSES.items()):
        if origin.exists() and not any(origin == p or p in origin.parents for p in environment):
            mounts.append((origin, Path(protocol.COURSE_FOLDER) / (name if origin.is_dir() else origin.name)))
    return mounts


def processes_of_this_user():
    """How many processes the calling uid already has (the process limit counts them too)."""
    uid = os.getuid()
    count = 0
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            with contextlib.suppress(OSError):
                count += entry.stat().st_uid == uid
    return count


def remove_tree(path):
    """Delete a folder however deep it is and whatever its permissions, without Python's recursion."""
    if not os.path.lexists(path):
        return
    for command in (["chmod", "-R", "u+rwx"], ["rm", "-rf", "--one-file-system"]):
        subprocess.run([*command, "--", str(path)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


class Box:
    """One notebook's sandbox, from its worker's start to the cleanup: `argv` runs with `cwd`, `env` (the grader's
    when None) and `pass_fds` (closed here once passed); `processes_base` processes of its uid already count
    against the process limit; `cleanup` runs once after the worker is stopped."""

    def __init__(self, argv, limits, *, cwd=None, env=None, pass_fds=(), processes_base=0, cleanup=None):
        self.argv, self.limits, self.cwd, self.env = list(argv), limits, cwd, env
        self.pass_fds = tuple(fd for fd in pass_fds if fd is not None)
        self.processes_base, self._cleanup = processes_base, cleanup
        self.cgroup, self.process, self.closed = None, None, False

    def start(self):
        """Start the worker; its process (a Popen with pipes on stdin and stdout)."""
        self.cgroup = cgroup.create(self.limits.memory + WORKER_IMPORTS)

        def prepare():
            if self.cgroup is not None:
                self.cgroup.join()
            apply_limits(self.limits, self.processes_base)

        try:
            self.process = subprocess.Popen(
                self.argv,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                cwd=self.cwd,
                env=self.env,
                start_new_session=True,
                preexec_fn=prepare,
                pass_fds=self.pass_fds,
            )
        finally:
            self._close_passed()
        return self.process

    def _close_passed(self):
        for fd in self.pass_fds:
            with contextlib.suppress(OSError):
                os.close(fd)
        self.pass_fds = ()

    def stop(self):
        """Stop the worker and every process it started."""
        if self.process is None:
            return
        if self.process.poll() is None:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                self.process.kill()
        self.process.wait()

    def out_of_memory(self):
        """Whether the sandbox's memory cgroup ran out of memory (False where there is none)."""
        return self.cgroup is not None and self.cgroup.out_of_memory()

    def close(self):
        """After :meth:`stop`: close the worker's pipes and undo what was set up for it (nothing is left behind)."""
        if self.closed:
            return
        self.closed = True
        self._close_passed()
        for pipe in (self.process.stdin, self.process.stdout) if self.process is not None else ():
            with contextlib.suppress(OSError):
                pipe.close()
        if self.cgroup is not None:
            self.cgroup.remove()
        if self._cleanup is not None:
            self._cleanup()


class Backend(abc.ABC):
    """A way of running the grading worker in a sandbox: subclass it in ``backends/<name>.py``."""

    name: str | None = None  # what `labkit grade --sandbox` and GradeOptions.backend call it
    summary = ""  # one line for `labkit grade --help`

    @abc.abstractmethod
    def available(self):
        """Return if this backend can run sandboxes here; else raise SandboxUnavailable saying what to do."""

    def warning(self):
        """What to print on stderr once before a grading run (None: nothing)."""
        return None

    @abc.abstractmethod
    def box(self, argv, limits):
        """The :class:`Box` that runs the worker's command `argv` in a new sandbox bounded by `limits`."""

    def zygote_box(self, argv, limits, pass_fds):
        """The :class:`Box` of a fork server running `argv` with `pass_fds`, able to make namespaces, mount and change
        uid (:mod:`labkit.grading.sandbox.zygote`); None: no server, each notebook gets :meth:`box`."""
        return None

    def notebook_uid(self):
        """The uid a forked worker becomes (0: the server's own); unique among notebooks graded at once."""
        return 0

    def __repr__(self):
        return f"<sandbox backend {self.name}>"
