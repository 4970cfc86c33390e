"""The fork server inside the sandbox: imports once, then a freshly isolated worker per notebook.

Run by :mod:`labkit.grading.sandbox.forkserver` as ``python -I -m labkit.grading.sandbox.zygote FD`` in a sandbox
that may make namespaces and change uid, it preloads (:func:`~.worker.preload`), says ``ready``, then takes
requests on socket FD: a notebook's uid and limits with the new worker's descriptors. It never reads a notebook
and runs no student code. Per request a keeper isolates the notebook (:func:`isolate`) and forks the worker
(:func:`_become_worker`); docs/grading-security.md says what each step guards against.
"""

import contextlib
import ctypes
import json
import os
import random
import select
import signal
import socket
import sys

from ...errors import InputError
from . import worker
from .backends.base import Limits, apply_limits, environment_paths
from .forkserver import ENDED, FAILED, MAX_WHY, STARTED

CLONE_NEWNS, CLONE_NEWUTS, CLONE_NEWIPC = 0x00020000, 0x04000000, 0x08000000
CLONE_NEWPID, CLONE_NEWNET = 0x20000000, 0x40000000
MS_RDONLY, MS_NOSUID, MS_NODEV, MS_NOEXEC, MS_REMOUNT = 1, 2, 4, 8, 32
MS_BIND, MS_REC, MS_PRIVATE = 1 << 12, 0x4000, 0x40000
PR_SET_NO_NEW_PRIVS, PR_GET_DUMPABLE = 38, 3
MAX_REQUEST = 4 * 1024  # bytes of one request's text
MAX_FDS = 8  # descriptors passed with one request
FIRST_FD = 3  # where the worker's own descriptors are put before every other one is closed

_libc = ctypes.CDLL(None, use_errno=True)
_libc.mount.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_ulong, ctypes.c_char_p]
_libc.unshare.argtypes = [ctypes.c_int]


def _checked(result, what):
    if result != 0:
        number = ctypes.get_errno()
        raise OSError(number, f"{what}: {os.strerror(number)}")


def _mount(source, target, kind, flags, data=None):
    kind, data = (text.encode() if text else None for text in (kind, data))
    _checked(_libc.mount(source.encode(), target.encode(), kind, flags, data), f"mount {target}")


def isolate(limits, home, keep=()):
    """In the keeper: new namespaces and empty private folders; folders of `keep` inside one are mounted back."""
    _checked(_libc.unshare(CLONE_NEWNS | CLONE_NEWNET | CLONE_NEWIPC | CLONE_NEWUTS | CLONE_NEWPID), "unshare")
    _mount("none", "/", None, MS_REC | MS_PRIVATE)  # nothing mounted here reaches the server's view
    folders = [("/tmp", limits.tmp_size), (home, limits.home_size)]
    if os.path.isdir("/dev/shm"):
        folders.append(("/dev/shm", limits.tmp_size))
    inside = []
    for path in keep:
        for folder, _ in folders:
            if path.startswith(folder.rstrip("/") + "/"):
                inside.append((path, folder, os.open(path, os.O_PATH | os.O_DIRECTORY)))
    for path, size in folders:
        _mount("tmpfs", path, "tmpfs", MS_NOSUID | MS_NODEV, f"size={int(size)},mode=1777")
    for path, folder, held in inside:  # e.g. a clone under /tmp, whose .venv the sandbox had bound there
        os.makedirs(path, exist_ok=True)
        current = folder
        for part in os.path.relpath(path, folder).split(os.sep):  # root's and world-readable, as the sandbox made them
            current = os.path.join(current, part)
            os.chmod(current, 0o755)
        _mount(f"/proc/self/fd/{held}", path, None, MS_BIND | MS_REC)
        _mount("none", path, None, MS_REMOUNT | MS_BIND | MS_RDONLY | MS_NOSUID | MS_NODEV)
        os.close(held)
    if os.path.isdir("/dev/pts"):  # terminals of its own: the sandbox's one instance would be every notebook's
        _mount("devpts", "/dev/pts", "devpts", MS_NOSUID | MS_NOEXEC, "newinstance,ptmxmode=0666,mode=620,max=16")
    os.chdir(home)


def _say_failed(fd, exc):
    """Write why the worker could not start on the status pipe `fd`; False where it cannot be written."""
    try:
        os.write(fd, FAILED + str(exc)[: MAX_WHY - 1].encode("utf-8", "replace"))
    except OSError:
        return False
    return True


def _become_worker(fds, uid, limits):
    """In the worker (pid 1 of its namespace): everything up to the student's uid, then STARTED on the status pipe."""
    if uid <= 0:
        raise OSError(f"refusing to run a notebook as uid {uid}: a forked worker needs a uid of its own")
    _mount("proc", "/proc", "proc", MS_RDONLY | MS_NOSUID | MS_NODEV | MS_NOEXEC)
    for fd in fds["cgroup"]:
        os.write(fd, b"0")  # 0: the writing process
    # the worker's pipes at 3 and 4, its status pipe at 5; every other descriptor (the server's socket too) closes
    moved = [os.dup(fds[name]) for name in ("requests", "answers", "status")]
    for index, fd in enumerate(moved):
        os.dup2(fd, FIRST_FD + index)
    os.closerange(FIRST_FD + len(moved), 2**31 - 1)
    apply_limits(limits)
    worker.drop_privileges(uid)
    worker.not_dumpable()  # the change of uid made the process dumpable again (fs.suid_dumpable)
    _checked(_libc.prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), "no new privileges")
    with open("/proc/self/status") as status:
        fields = dict(line.split(":", 1) for line in status if ":" in line)
    capabilities = [int(fields[name], 16) for name in ("CapPrm", "CapEff", "CapAmb")]  # permitted, effective, ambient
    if os.getuid() != uid or os.geteuid() != uid or any(capabilities):
        raise OSError("the worker kept root's uid or a capability")
    if _libc.prctl(PR_GET_DUMPABLE, 0, 0, 0, 0) != 0:
        raise OSError("the worker's memory would be readable by its notebook")
    random.seed()  # fresh random states, as a new Python would have: every worker forked from the server starts alike
    if "numpy" in sys.modules:
        sys.modules["numpy"].random.seed()
    os.write(FIRST_FD + 2, STARTED)
    os.close(FIRST_FD + 2)
    return FIRST_FD, FIRST_FD + 1


def _keeper(fds, uid, limits, home, shell):
    """The child of the server for one notebook (never returns): it forks the worker, and kills it when the grader
    closes the control pipe; the worker's end, either way, goes on the status pipe."""
    status = fds["status"]
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)
    try:
        isolate(limits, home, [str(path) for path in environment_paths()])
        pid = os.fork()
    except OSError as exc:
        _say_failed(status, exc)
        os._exit(1)
    if pid == 0:
        code, running = 0, False
        try:
            requests, answers = _become_worker(fds, uid, limits)
            running = True
            worker.supervise(requests, answers, shell)
        except BaseException as exc:  # noqa: BLE001 - the worker's end, whatever it is, is its status
            code = 1
            for fd in () if running else (FIRST_FD + 2, status):  # why it could not start, if it can still say
                if _say_failed(fd, exc):
                    break
        os._exit(code)
    for fd in (fds["requests"], fds["answers"], *fds["cgroup"]):
        os.close(fd)
    try:
        watch = [os.pidfd_open(pid)]
    except (AttributeError, OSError):  # a kernel before 5.3: look at the worker ten times a second instead
        watch = []
    control = fds["control"]
    while True:
        ready = select.select([*watch, control], [], [], None if watch else 0.1)[0]
        if not watch or watch[0] in ready:
            done, wait_status = os.waitpid(pid, 0 if watch else os.WNOHANG)
            if done:
                break
        if control in ready:  # closed (or written to): the grader is done with this notebook
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            wait_status = os.waitpid(pid, 0)[1]
            break
    with contextlib.suppress(OSError):  # the grader is gone
        os.write(status, ENDED + str(wait_status).encode())
    os._exit(0)


def _parse(data, fds, flags):
    """The request's descriptors named, uid and limits; ValueError when it is not a request of the grader's."""
    if flags & (socket.MSG_TRUNC | socket.MSG_CTRUNC):
        raise InputError("a request larger than the server takes")
    request = json.loads(data.decode("utf-8"))
    count = int(request.get("cgroup", 0))
    if len(fds) != 4 + count or not 0 <= count <= MAX_FDS - 4:
        raise InputError("a request with the wrong descriptors")
    named = {**dict(zip(("requests", "answers", "control", "status"), fds)), "cgroup": fds[4:]}
    return named, int(request["uid"]), Limits(**{key: int(value) for key, value in request["limits"].items()})


def serve_forks(server, shell, home):
    """Fork an isolated worker for each request until the grader closes its end of the socket."""
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # keepers are reaped by the kernel
    while True:
        data, fds, flags, _ = socket.recv_fds(server, MAX_REQUEST, MAX_FDS)
        if not data and not fds:  # the grader closed its end
            return
        try:
            named, uid, limits = _parse(data, fds, flags)
        except Exception:  # noqa: BLE001 - not a request of the grader's: dropped (its sender sees the pipes close)
            for fd in fds:
                os.close(fd)
            continue
        try:
            pid = os.fork()
        except OSError as exc:
            _say_failed(named["status"], exc)
            pid = None
        if pid == 0:
            try:
                server.close()
                _keeper(named, uid, limits, home, shell)
            finally:
                os._exit(1)
        for fd in fds:
            os.close(fd)


def main():
    server = socket.socket(fileno=int(sys.argv[1]))
    worker.not_dumpable()
    null = os.open(os.devnull, os.O_RDWR)
    ready = os.dup(1)
    for fd in (0, 1, 2):
        os.dup2(null, fd)
    shell = worker.preload(everything=True)
    os.write(ready, b"ready\n")
    os.close(ready)
    serve_forks(server, shell, os.getcwd())


if __name__ == "__main__":
    main()
