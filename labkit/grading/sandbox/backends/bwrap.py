"""The default backend: a bubblewrap sandbox on this machine.

:func:`command` builds one notebook's ``bwrap`` command line: a new root with only the system and the Python
environment, read-only; small private tmpfs ``HOME`` and ``/tmp``; no network; its own ``/proc``, PID, IPC and UTS
namespaces; the seccomp filter; and no capability but the two the worker needs to become an unused uid
(:func:`sandbox_uid`). docs/grading-security.md says what each of these guards against.
"""

import itertools
import os
import shutil
import subprocess
import sys
from pathlib import Path

from .. import seccomp
from . import register
from .base import Backend, Box, Limits, SandboxUnavailable, course_mounts, environment_paths, processes_of_this_user

HOME = "/home/student"
INSTALL_HINT = (
    "install bubblewrap (Debian/Ubuntu: `sudo apt-get install bubblewrap`; Fedora: `sudo dnf install "
    "bubblewrap`) on a Linux machine that allows user namespaces, or grade inside a container that "
    "allows them; where each submission is already isolated (a pod or container of its own), "
    "`labkit grade --sandbox none` runs student code without a sandbox of labkit's own"
)
NAMESPACES = ("--unshare-pid", "--unshare-net", "--unshare-ipc", "--unshare-uts", "--unshare-cgroup-try")
FORKED_UIDS = 1_000_000_000  # forked workers' uids start here (far above sandbox_uid's; pids are below 2**22)
_FORKED = itertools.count()  # notebooks forked for this process so far


def _namespaces():
    user = [] if os.geteuid() == 0 else ["--unshare-user"]
    return [*user, *NAMESPACES, "--die-with-parent", "--new-session"]


def sandbox_uid():
    """An unused uid for this process's sandboxes (0 when not root: bwrap maps the caller's); one per process id, so
    no notebook's processes count against another's limit."""
    return 100_000 + os.getpid() if os.geteuid() == 0 else 0


def _parents(path, made):
    """--dir for every folder above `path` not made yet, world-readable (bwrap would make them 0700)."""
    args = []
    for parent in reversed(Path(path).parents):
        if str(parent) != "/" and parent not in made:
            args += ["--perms", "0755", "--dir", str(parent)]
            made.add(parent)
    return args


def command(argv, limits=None, seccomp_fd=None, zygote=False):
    """The bwrap command that runs `argv` in a new sandbox bounded by `limits` (the defaults when None); pass
    `seccomp_fd` to the process with pass_fds. A `zygote` (a fork server, as root only) keeps the
    capability to make namespaces and mount for the workers it forks."""
    limits = limits if limits is not None else Limits()
    args = [shutil.which("bwrap") or "bwrap", *_namespaces(), "--clearenv", "--cap-drop", "ALL"]
    if os.geteuid() == 0:
        args += ["--cap-add", "CAP_SETUID", "--cap-add", "CAP_SETGID"]
        if zygote:
            args += ["--cap-add", "CAP_SYS_ADMIN"]
    if seccomp_fd is not None:
        args += ["--seccomp", str(seccomp_fd)]
    # the private /tmp first: an environment that lives under /tmp is then mounted back on top of it
    args += ["--proc", "/proc", "--remount-ro", "/proc", "--dev", "/dev"]
    args += ["--perms", "1777", "--size", str(limits.tmp_size), "--tmpfs", "/tmp"]
    args += ["--ro-bind", "/usr", "/usr", "--ro-bind", "/etc", "/etc"]
    for name in ("bin", "sbin", "lib", "lib32", "lib64", "libx32"):
        top = Path("/") / name
        if top.is_symlink():
            args += ["--symlink", os.readlink(top), str(top)]
        elif top.is_dir():
            args += ["--ro-bind", str(top), str(top)]
    made = {Path("/tmp")}
    for origin, shown in [*((path, path) for path in environment_paths()), *course_mounts()]:
        args += [*_parents(shown, made), "--ro-bind", str(origin), str(shown)]
    args += [*_parents(HOME, made), "--perms", "1777", "--size", str(limits.home_size), "--tmpfs", HOME]
    args += ["--chdir", HOME]
    environment = {
        "HOME": HOME,
        "PATH": f"{Path(sys.executable).parent}:/usr/bin:/bin",
        "LANG": "C.UTF-8",
        "MPLBACKEND": "Agg",
        "MPLCONFIGDIR": f"{HOME}/.matplotlib",
        "PYTHONDONTWRITEBYTECODE": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
    }
    kept = ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE")  # set on some machines for correct results
    environment |= {name: os.environ[name] for name in kept if name in os.environ}
    for name, value in environment.items():
        args += ["--setenv", name, value]
    return args + ["--", *argv]


@register
class Bubblewrap(Backend):
    """Each notebook in a bubblewrap sandbox of its own on this machine (see the module's description)."""

    name = "bwrap"
    summary = (
        "bubblewrap on this machine: no network, a read-only system, private folders, a seccomp filter "
        "and resource limits"
    )

    def available(self):
        bwrap = shutil.which("bwrap")
        if bwrap is None:
            raise SandboxUnavailable(f"bwrap (bubblewrap) is not installed: {INSTALL_HINT}.")
        trial = [bwrap, *_namespaces(), "--ro-bind", "/", "/", "--proc", "/proc", "--dev", "/dev", "true"]
        probe = subprocess.run(trial, capture_output=True, text=True, timeout=30)
        if probe.returncode != 0:
            raise SandboxUnavailable(
                f"bwrap cannot create a sandbox here ({probe.stderr.strip()[:300]}): {INSTALL_HINT}."
            )

    def box(self, argv, limits):
        uid = sandbox_uid()
        # as root the worker becomes `uid`, a uid of its own; otherwise the caller's processes count too
        return _box([*argv, str(uid)], limits, processes_base=0 if uid else processes_of_this_user())

    def zygote_box(self, argv, limits, pass_fds):
        """As root only (else its workers could not each get a uid of their own): a fork server sandboxed alike."""
        return _box(list(argv), limits, pass_fds, zygote=True) if os.geteuid() == 0 else None

    def notebook_uid(self):
        """As :func:`sandbox_uid`, in a range of their own, and different for each notebook of one process."""
        return FORKED_UIDS + 16 * os.getpid() + next(_FORKED) % 16


def _box(argv, limits, pass_fds=(), processes_base=0, zygote=False):
    """The :class:`~.base.Box` that runs `argv` under bwrap, the sandbox's seccomp filter passed on a pipe."""
    seccomp_fd = seccomp.pipe_with_program()
    try:
        args = command(argv, limits, seccomp_fd, zygote=zygote)
    except BaseException:
        if seccomp_fd is not None:
            os.close(seccomp_fd)
        raise
    return Box(args, limits, pass_fds=(seccomp_fd, *pass_fds), processes_base=processes_base)
