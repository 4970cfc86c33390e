"""The fork server inside the sandbox: imports once, then a freshly isolated worker per notebook.

Started by the grader (:mod:`labkit.grading.sandbox.forkserver`) as
``python -I -m labkit.grading.sandbox.zygote FD`` inside a sandbox its backend made
(:meth:`labkit.grading.sandbox.backends.base.Backend.zygote_box`), with the
capabilities to make namespaces and to change uid. It imports what notebooks
need (:func:`labkit.grading.sandbox.worker.preload`), says ``ready`` on stdout and then
waits on the socket `FD` for requests, one datagram each: a small JSON text
(the notebook's uid and limits) and, passed along with it, the descriptors
of the new worker (its requests and answers pipes, a control pipe, a status
pipe and, where the grader made one, the files that put a process in the
notebook's cgroup). It never reads a line of a notebook, and no student code
ever runs in it.

For each request it forks; the child (the notebook's **keeper**) makes what
separates this notebook from every other one graded through the same
server, before any student code exists:

* new mount, network, IPC, UTS and PID namespaces;
* fresh, empty tmpfs on ``/tmp``, the home folder and ``/dev/shm``, so no
  file written by one notebook is ever seen by another;
* a new ``/proc`` (read-only) that shows only this notebook's processes.

The keeper then forks the **worker**, the first process of the new PID
namespace: it joins the notebook's cgroup, takes the notebook's rlimits,
closes every descriptor but its own pipes (the server's socket among them),
becomes the notebook's own uid (which drops every capability), sets
no-new-privileges and runs the worker's supervisor
(:class:`labkit.grading.sandbox.worker.Supervisor`) with the imports it inherited.
When the worker ends, the kernel ends every process of its namespace.

The keeper stays outside, as root, running only this module's code: it
writes ``S`` on the status pipe once the worker runs (or ``E`` and why it
could not), waits for the worker to end or for the control pipe to close
(the grader stopped the notebook, or died), kills the worker if it still
runs, and writes its wait status.
"""

import ctypes
import json
import os
import select
import signal
import socket
import struct
import sys

from ...errors import InputError
from . import worker
from .backends.base import Limits, apply_limits, environment_paths

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
    _checked(
        _libc.mount(
            source.encode(), target.encode(), kind.encode() if kind else None, flags, data.encode() if data else None
        ),
        f"mount {target}",
    )


def isolate(limits, home, keep=()):
    """In the keeper: new namespaces and empty private folders (see the module's description); the folders of
    `keep` (the Python environment and labkit, read-only) that lie inside one are mounted back into it."""
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


def _capabilities():
    """The worker's permitted, effective and ambient capability sets (from /proc/self/status), as numbers."""
    with open("/proc/self/status") as status:
        fields = dict(line.split(":", 1) for line in status if ":" in line)
    return [int(fields[name].strip(), 16) for name in ("CapPrm", "CapEff", "CapAmb")]


def _become_worker(fds, uid, limits):
    """In the worker, as the first process of the new PID namespace: everything up to the student's uid, then
    ``S`` on the status pipe (only then does the grader count on this worker)."""
    if uid <= 0:
        raise OSError(f"refusing to run a notebook as uid {uid}: a forked worker needs a uid of its own")
    _mount("proc", "/proc", "proc", MS_RDONLY | MS_NOSUID | MS_NODEV | MS_NOEXEC)
    for fd in fds["cgroup"]:
        os.write(fd, b"0")  # 0: the writing process
    # the worker's pipes at 3 and 4, its status pipe at 5, then nothing else: the server's socket, the
    # keeper's control pipe, the cgroup files and any other descriptor close
    wanted = [fds["requests"], fds["answers"], fds["status"]]
    moved = [os.dup(fd) for fd in wanted]
    for index, fd in enumerate(moved):
        os.dup2(fd, FIRST_FD + index)
    os.closerange(FIRST_FD + len(moved), 2**31 - 1)
    apply_limits(limits)
    worker.drop_privileges(uid)
    worker.not_dumpable()  # the change of uid made the process dumpable again (fs.suid_dumpable)
    _checked(_libc.prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), "no new privileges")
    if os.getuid() != uid or os.geteuid() != uid or any(_capabilities()):
        raise OSError("the worker kept root's uid or a capability")
    if _libc.prctl(PR_GET_DUMPABLE, 0, 0, 0, 0) != 0:
        raise OSError("the worker's memory would be readable by its notebook")
    _reseed()
    os.write(FIRST_FD + 2, b"S")
    os.close(FIRST_FD + 2)
    return FIRST_FD, FIRST_FD + 1


def _reseed():
    """Fresh random states, as a new Python would have: every worker forked from the server starts alike."""
    import random

    random.seed()
    if "numpy" in sys.modules:
        sys.modules["numpy"].random.seed()


def _keeper(fds, uid, limits, home, shell):
    """The child of the server for one notebook; never returns."""
    status = fds["status"]
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)
    try:
        isolate(limits, home, KEEP)
        pid = os.fork()
    except OSError as exc:
        os.write(status, f"E{exc}"[:500].encode("utf-8", "replace"))
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
                try:
                    os.write(fd, f"E{exc}"[:500].encode("utf-8", "replace"))
                    break
                except OSError:
                    continue
        os._exit(code)
    for name in ("requests", "answers"):
        os.close(fds[name])
    for fd in fds["cgroup"]:
        os.close(fd)
    try:
        watch = [os.pidfd_open(pid)]
    except (AttributeError, OSError):  # a kernel before 5.3: look at the worker ten times a second instead
        watch = []
    control = fds["control"]
    wait_status = None
    while wait_status is None:
        ready = select.select([*watch, control], [], [], None if watch else 0.1)[0]
        if not watch or watch[0] in ready:
            done, found = os.waitpid(pid, 0 if watch else os.WNOHANG)
            if done:
                wait_status = found
                break
        if control in ready:  # closed (or written to): the grader is done with this notebook
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            _, wait_status = os.waitpid(pid, 0)
    try:
        os.write(status, f"W{wait_status}".encode())
    except OSError:  # the grader is gone
        pass
    os._exit(0)


def _receive(server):
    """(request dict, [descriptors]) of the next request, or None when the grader closed its end."""
    space = socket.CMSG_SPACE(MAX_FDS * struct.calcsize("i"))
    data, ancillary, flags, _ = server.recvmsg(MAX_REQUEST, space)
    fds = []
    for level, kind, payload in ancillary:
        if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
            usable = len(payload) - len(payload) % struct.calcsize("i")
            fds += list(struct.unpack(f"{usable // struct.calcsize('i')}i", payload[:usable]))
    if not data and not fds:
        return None
    return data, fds, flags


def _parse(data, fds):
    """The request's fields, its descriptors named; ValueError when it is not a request of the grader's."""
    request = json.loads(data.decode("utf-8"))
    count = int(request.get("cgroup", 0))
    if len(fds) != 4 + count or not 0 <= count <= MAX_FDS - 4:
        raise InputError("a request with the wrong descriptors")
    named = dict(zip(("requests", "answers", "control", "status"), fds[:4]))
    named["cgroup"] = fds[4:]
    uid = int(request["uid"])
    limits = Limits(**{key: int(value) for key, value in request["limits"].items()})
    return named, uid, limits


def serve_forks(server, shell, home):
    """Fork an isolated worker for each request until the grader closes its end of the socket."""
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # keepers are reaped by the kernel
    while True:
        received = _receive(server)
        if received is None:
            return
        data, fds, flags = received
        try:
            if flags & (socket.MSG_TRUNC | socket.MSG_CTRUNC):
                raise InputError("a request larger than the server takes")
            named, uid, limits = _parse(data, fds)
        except Exception:  # noqa: BLE001 - not a request of the grader's: dropped (its sender sees the pipes close)
            for fd in fds:
                os.close(fd)
            continue
        try:
            pid = os.fork()
        except OSError as exc:
            try:
                os.write(named["status"], f"E{exc}"[:500].encode("utf-8", "replace"))
            except OSError:
                pass
            pid = None
        if pid == 0:
            try:
                server.close()
                _keeper(named, uid, limits, home, shell)
            finally:
                os._exit(1)
        for fd in fds:
            os.close(fd)


KEEP = ()  # the sandbox's read-only folders (the Python environment, labkit): set by main


def main(argv=None):
    global KEEP
    argv = sys.argv[1:] if argv is None else argv
    KEEP = tuple(str(path) for path in environment_paths())
    server = socket.socket(fileno=int(argv[0]))
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
