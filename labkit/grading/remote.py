"""The grader's handle on one sandboxed notebook: start it, run it, call into it, stop it.

:class:`Notebook` starts the worker (:mod:`labkit.grading.worker`) inside the
sandbox, sends it requests and reads its answers with a deadline, and kills
the whole sandbox when it is done, stuck or misbehaving. :class:`Namespace`
is the mapping the checks read (``ns["eval_pherm"]``): a function comes back
as a :class:`Function` proxy that forwards each call into the sandbox, and
data come back decoded as plain numbers (:func:`labkit.grading.protocol.decode`).
So the checks of :mod:`labkit.checks` run unchanged on this side, never in
the student's process.
"""
import os
import secrets
import selectors
import signal
import subprocess
import sys
import time

from . import protocol, sandbox


class WorkerError(RuntimeError):
    """The sandboxed notebook stopped, hung or answered out of protocol."""

    kind = "WorkerError"


class StudentError(Exception):
    """An exception the student's code raised in the sandbox (its type name in ``kind``)."""

    def __init__(self, kind, message, refused=None):
        super().__init__(message)
        self.kind = kind
        self.refused = refused


class Notebook:
    """One worker process in its sandbox (or, unconfined, in a new session)."""

    def __init__(self, workdir, limits=sandbox.Limits(), confined=True, deadline=None):
        self.deadline = deadline if deadline is not None else time.monotonic() + 600
        self.stopped = None  # why the worker can no longer answer
        self._buffer = b""
        self._next_id = None
        argv = [sys.executable, "-I", "-m", "labkit.grading.worker"]
        if confined:
            uid = sandbox.sandbox_uid()
            if uid:
                os.chown(workdir, uid, uid)
                os.chmod(workdir, 0o711)  # bwrap enters it as root without capabilities
            argv = sandbox.command(workdir, argv + [str(uid)], uid, limits)
            base, cwd, env = (0 if uid else sandbox.processes_of_this_user()), None, None
        else:
            base, cwd = sandbox.processes_of_this_user(), workdir
            env = {**os.environ, "HOME": str(workdir), "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"}
        self.process = subprocess.Popen(
            argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, cwd=cwd, env=env,
            start_new_session=True, preexec_fn=lambda: sandbox.apply_limits(limits, base))
        self._selector = selectors.DefaultSelector()
        self._selector.register(self.process.stdout, selectors.EVENT_READ)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        """Stop the worker and everything it started."""
        if self.process.poll() is None:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                self.process.kill()
        self.process.wait()
        self._selector.close()
        for pipe in (self.process.stdin, self.process.stdout):
            try:
                pipe.close()
            except OSError:
                pass

    def _stop(self, why):
        self.stopped = why
        self.close()
        raise WorkerError(why)

    def request(self, message, timeout):
        """Send one request; its answer (a dict), or WorkerError after stopping the worker."""
        if self.stopped:
            raise WorkerError(self.stopped)
        self._next_id = secrets.token_hex(8)  # unguessable: a line the notebook forges cannot pose as the answer
        message = {**message, "id": self._next_id}
        try:
            self.process.stdin.write(protocol.dumps(message))
            self.process.stdin.flush()
        except (BrokenPipeError, OSError):
            self._stop(self._ended())
        until = min(self.deadline, time.monotonic() + timeout)
        while True:
            line = self._read_line(until)
            try:
                answer = protocol.loads(line)
            except protocol.ProtocolError as exc:
                self._stop(f"the notebook's process answered out of protocol ({exc})")
            if answer.get("id") == self._next_id:
                return answer
            # a line the notebook wrote itself: not an answer to this request

    def _ended(self):
        code = self.process.poll()
        if code is None:
            return "the notebook's process stopped answering"
        if code < 0:
            name = signal.Signals(-code).name if -code in signal.Signals._value2member_map_ else str(-code)
            return f"the notebook's process was killed by {name} (a resource limit, or os.kill)"
        return f"the notebook's process exited with status {code} (os._exit or a crash)"

    def _read_line(self, until):
        while b"\n" not in self._buffer:
            remaining = until - time.monotonic()
            if remaining <= 0:
                limit = "total time limit" if until >= self.deadline else "time limit"
                self._stop(f"stopped after the {limit}: the notebook did not answer in time")
            if not self._selector.select(remaining):
                continue
            chunk = os.read(self.process.stdout.fileno(), 1 << 20)
            if not chunk:
                self.process.wait(timeout=5) if self.process.poll() is None else None
                self._stop(self._ended())
            self._buffer += chunk
            if len(self._buffer) > protocol.MAX_LINE:
                self._stop("the notebook's process sent an answer larger than the protocol allows")
        line, _, self._buffer = self._buffer.partition(b"\n")
        return line


class Function:
    """Calls the student's function of this name inside the sandbox."""

    def __init__(self, notebook, name, refused, timeout):
        self.notebook, self.name, self.refused, self.timeout = notebook, name, tuple(refused), timeout
        self.__name__ = name

    def __call__(self, *args):
        request = {"op": "call", "name": self.name, "refused": list(self.refused), "timeout": self.timeout,
                   "args": [protocol.encode(arg) for arg in args]}
        answer = self.notebook.request(request, self.timeout + 5)
        return _value(answer)

    def __repr__(self):
        return f"<student function {self.name} in the sandbox>"


def _value(answer):
    if "error" in answer:
        error = answer["error"] if isinstance(answer["error"], dict) else {}
        kind, message = str(error.get("kind", "Error"))[:100], str(error.get("message", ""))[:500]
        refused = error.get("refused")
        if kind == "NotImplementedError" and not refused:
            raise NotImplementedError(message)
        raise StudentError(kind, message, str(refused)[:200] if refused else None)
    try:
        return protocol.decode(answer.get("value"))
    except protocol.ProtocolError as exc:
        return protocol.NotNumbers(f"a value out of protocol ({exc})")


class Namespace:
    """The student's variables, read through the sandbox: the mapping the checks take."""

    def __init__(self, notebook, refused=(), timeout=60):
        self.notebook, self.refused, self.timeout = notebook, refused, timeout
        self._kinds = {}

    def _kind(self, name):
        if name not in self._kinds:
            try:
                answer = self.notebook.request({"op": "names", "names": [name]}, self.timeout)
                kind = answer.get("names", {}).get(name, "missing")
            except WorkerError:
                kind = "function"  # every call on it then says why the notebook cannot answer
            self._kinds[name] = kind if kind in ("function", "data") else "missing"
        return self._kinds[name]

    def __contains__(self, name):
        return self._kind(name) != "missing"

    def __getitem__(self, name):
        kind = self._kind(name)
        if kind == "missing":
            raise KeyError(name)
        if kind == "function":
            return Function(self.notebook, name, self.refused, self.timeout)
        try:
            return _value(self.notebook.request({"op": "get", "name": name}, self.timeout))
        except (StudentError, WorkerError) as exc:
            return protocol.NotNumbers(f"nothing readable ({exc})")

    def get(self, name, default=None):
        return self[name] if name in self else default
