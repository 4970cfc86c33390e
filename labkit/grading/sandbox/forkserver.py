"""The grader's side of the fork server: imports paid once per run, not once per notebook.

A :class:`ForkServer` runs one zygote (:mod:`labkit.grading.sandbox.zygote`) that imports what notebooks need once
and forks each notebook a worker isolated from every other. A grading run passes its socket to each grading
process (:data:`ENV`), where :func:`box` makes a :class:`ForkedBox`; without a server, or when it cannot give a
worker, the notebook gets a plain sandbox: a broken server costs time, never a grade.
"""

import array
import contextlib
import json
import os
import select
import socket
import subprocess
import sys
import time

from . import cgroup
from .backends.base import WORKER_IMPORTS, Box

ENV = "LABKIT_FORK_SERVER"  # the descriptor of a fork server's socket, in a grading process
ZYGOTE = (sys.executable, "-I", "-m", "labkit.grading.sandbox.zygote")
READY_TIMEOUT = 180  # seconds for a new server to import what notebooks need
START_TIMEOUT = 30  # seconds for one forked worker to be isolated and running
# what a worker's keeper writes on its status pipe: STARTED once the worker runs, or FAILED and why (MAX_WHY
# characters at most); then, at the worker's end, ENDED and its wait status
STARTED, FAILED, ENDED = b"S", b"E", b"W"
MAX_WHY = 500
_client = None  # (socket, backend name, whether each notebook needs a cgroup) of the server this process asks


class ForkServerError(RuntimeError):
    """The fork server could not start, or could not give a worker."""


def _wait_readable(fd, until):
    remaining = until - time.monotonic()
    return remaining > 0 and bool(select.select([fd], [], [], remaining)[0])


class ForkServer:
    """One zygote in a sandbox of `backend` bounded by `limits` (a context manager); while it runs, :func:`box` here
    and in processes given :meth:`environment` and :attr:`fd` forks workers from it."""

    def __init__(self, backend, limits):
        self.backend, self.limits = backend, limits
        self.box, self.socket = None, None

    @property
    def fd(self):
        """The descriptor a grading process asks the server through (pass it with ``pass_fds``)."""
        return self.socket.fileno()

    def environment(self):
        """What to add to a grading process's environment so that it uses this server."""
        return {ENV: f"{self.fd}:{self.backend.name}:{int(self.needs_cgroup)}"}

    @property
    def needs_cgroup(self):
        """Whether each notebook needs a cgroup of its own: a notebook's memory must never fill the server's."""
        return self.box is not None and self.box.cgroup is not None

    def start(self, wait=True):
        """Start the server; with `wait`, :meth:`wait_ready` too (else call it later)."""
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        zygote_fd = theirs.detach()
        try:
            self.box = self.backend.zygote_box([*ZYGOTE, str(zygote_fd)], self.limits, (zygote_fd,))
            if self.box is None:
                raise ForkServerError(f"the {self.backend.name} sandbox offers no fork server")
        except BaseException:
            os.close(zygote_fd)
            ours.close()
            raise
        self.socket = ours
        try:
            self.box.start()
        except OSError as exc:
            self.stop()
            raise ForkServerError(f"the fork server could not start ({exc})") from None
        return self.wait_ready() if wait else self

    def wait_ready(self):
        """Wait until the server is ready and let this process ask it; else stop it and raise ForkServerError."""
        said = self.box.process.stdout.fileno()  # "ready" comes in one write, so in one read
        if not (_wait_readable(said, time.monotonic() + READY_TIMEOUT) and os.read(said, 64) == b"ready\n"):
            self.stop()
            raise ForkServerError("the fork server did not get ready (it could not import what notebooks need)")
        global _client
        self._previous, _client = _client, (self.socket, self.backend.name, self.needs_cgroup)
        return self

    def stop(self):
        global _client
        if _client is None or _client[0] is self.socket:  # asked, or found broken while asked
            _client = getattr(self, "_previous", None)  # a server started before this one is asked again
        if self.socket is not None:
            self.socket.close()  # the server ends when its socket's other end closes
        if self.box is not None:
            self.box.stop()
            self.box.close()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


def client():
    """(socket, backend name, whether each notebook needs a cgroup) of the server this process may ask, or None."""
    global _client
    fd, name, needs = (os.environ.get(ENV, "").split(":") + ["", "", ""])[:3]
    if _client is None and fd.isdigit() and name:
        try:
            server = socket.socket(fileno=int(fd))
            if server.family != socket.AF_UNIX or server.type != socket.SOCK_SEQPACKET:
                server.detach()
                raise OSError("not a fork server's socket")
            _client = (server, name, needs == "1")
        except OSError:
            os.environ.pop(ENV, None)
    return _client


def _broken(server):
    """Ask the server `server` no more in this process (it is gone or does not answer): the plain way from now."""
    global _client
    if _client is not None and _client[0] is server:
        _client = None
        os.environ.pop(ENV, None)


def box(backend, limits):
    """A :class:`ForkedBox` for one notebook when a fork server runs for `backend`, else None."""
    found = client()
    if found is None or found[1] != backend.name:
        return None
    return ForkedBox(found[0], limits, backend.notebook_uid(), needs_cgroup=found[2])


class ForkedBox(Box):
    """One notebook's worker, forked by the server on `server` and isolated by it. The box is the worker's process
    too: the part of a Popen that :class:`labkit.grading.sandbox.remote.NotebookHandle` uses."""

    def __init__(self, server, limits, uid, needs_cgroup=False):
        super().__init__([], limits)
        self.server, self.uid, self.needs_cgroup = server, uid, needs_cgroup
        self.stdin = self.stdout = self.control = self.status = self.returncode = None
        self._said = b""

    def start(self):
        self.cgroup = cgroup.create(self.limits.memory + WORKER_IMPORTS)
        if self.cgroup is None and self.needs_cgroup:  # it would share the server's, and could take it down
            raise ForkServerError("no cgroup of its own could be made for the notebook")
        (requests_r, requests_w), (answers_r, answers_w), (control_r, control_w), (status_r, status_w) = (
            os.pipe() for _ in range(4)
        )
        theirs = [requests_r, answers_w, control_r, status_w]  # closed here once sent, as the cgroup's files
        ours = [requests_w, answers_r, control_w, status_r]
        try:
            for folder in self.cgroup.folders if self.cgroup is not None else ():
                theirs.append(os.open(folder / "cgroup.procs", os.O_WRONLY))
            text = json.dumps({"uid": self.uid, "limits": vars(self.limits), "cgroup": len(theirs) - 4}).encode()
            try:
                # never blocks on a server that stopped reading: its socket is shared, so it cannot be made
                # non-blocking for everyone; wait until it can take the request, then send without waiting
                if not select.select([], [self.server], [], START_TIMEOUT)[1]:
                    raise OSError("it takes no requests")
                message = [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", theirs))]
                self.server.sendmsg([text], message, socket.MSG_DONTWAIT)
            except OSError as exc:
                _broken(self.server)
                raise ForkServerError(f"the fork server is gone ({exc})") from None
        except BaseException:
            for fd in ours:
                os.close(fd)
            raise
        finally:
            for fd in theirs:
                os.close(fd)
        self.stdin, self.stdout = os.fdopen(requests_w, "wb"), os.fdopen(answers_r, "rb", buffering=0)
        self.control, self.status = control_w, status_r
        self.process = self  # closed by close(), whether the worker starts or not
        said = b""
        if _wait_readable(status_r, time.monotonic() + START_TIMEOUT):
            said = os.read(status_r, 1)
            if said == FAILED:
                said += os.read(status_r, MAX_WHY)
        if said != STARTED:
            if not said:  # no answer at all: the server dropped the request, or is stuck
                _broken(self.server)
            why = said[1:].decode("utf-8", "replace") if said.startswith(FAILED) else "no answer"
            raise ForkServerError(f"the fork server could not isolate a worker ({why})")
        return self.process

    def _read_status(self, until):
        while self.returncode is None:
            if until is not None and not _wait_readable(self.status, until):
                return
            chunk = os.read(self.status, 64)
            if not chunk:  # the keeper is gone without saying how the worker ended
                self.returncode = -9
                return
            self._said += chunk
            if self._said.startswith(ENDED) and self._said[1:].lstrip(b"-").isdigit():
                self.returncode = os.waitstatus_to_exitcode(int(self._said[1:]))

    def poll(self):
        self._read_status(time.monotonic())
        return self.returncode

    def wait(self, timeout=None):
        self._read_status(None if timeout is None else time.monotonic() + timeout)
        if self.returncode is None:
            raise subprocess.TimeoutExpired("forked worker", timeout)
        return self.returncode

    def stop(self):
        """Close the control pipe: the keeper stops the worker and every process of its namespace."""
        if self.process is None:
            return
        if self.control is not None:
            os.close(self.control)
            self.control = None
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.wait(timeout=10)

    def close(self):
        for fd in (self.control, self.status):
            if fd is not None:
                os.close(fd)
        self.control = self.status = None
        super().close()
