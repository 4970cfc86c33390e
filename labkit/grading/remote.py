"""The grader's handle on one sandboxed notebook: start it, run it, call into it, stop it.

:class:`Notebook` starts the worker (:mod:`labkit.grading.worker`) inside the
sandbox, in a memory cgroup of its own where one can be made, tells it what
the watch refuses, sends it requests and reads its answers with a deadline
and a size limit, and stops every process of the sandbox when it is done,
stuck or misbehaving. :class:`Namespace` is the mapping the checks read
(``ns["eval_pherm"]``): a function comes back as a :class:`Function` proxy
that forwards each call into the sandbox, and data come back decoded as
plain numbers (:func:`labkit.grading.protocol.decode`). So the checks of
:mod:`labkit.exercises` run unchanged on this side, never in the student's
process.
"""
import os
import secrets
import selectors
import signal
import subprocess
import sys
import tempfile
import time

from . import cgroup, protocol, refusals, sandbox, seccomp


class WorkerError(RuntimeError):
    """The sandboxed notebook stopped, hung or answered out of protocol."""

    kind = "WorkerError"


class WorkerTimeout(WorkerError):
    """The notebook did not answer in time; ``total`` says whether the whole notebook's time is used up."""

    kind = "Timeout"

    def __init__(self, message, total):
        super().__init__(message)
        self.total = total


class StudentError(Exception):
    """An exception the student's code raised in the sandbox (its type name in ``kind``)."""

    def __init__(self, kind, message, refused=None, traceback=""):
        super().__init__(message)
        self.kind = kind
        self.refused = refused
        self.traceback = traceback


def remove_tree(path):
    """Delete a folder however deep it is and whatever its permissions, without Python's recursion."""
    if not os.path.lexists(path):
        return
    subprocess.run(["chmod", "-R", "u+rwx", "--", str(path)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    subprocess.run(["rm", "-rf", "--one-file-system", "--", str(path)], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)


class Notebook:
    """One worker in its sandbox (or, unconfined, in a new session with a private folder)."""

    def __init__(self, limits=sandbox.Limits(), confined=True, deadline=None, profiles=None, passables=()):
        self.deadline = deadline if deadline is not None else time.monotonic() + 600
        self.passables = frozenset(passables)  # functions the checks may hand to student code, by name
        self.stopped = None  # why the worker can no longer answer
        self.tampered = None  # what the notebook did that voids its answers
        self._buffer = b""
        self._folder = None
        self.cgroup = cgroup.create(limits.memory + 512 * 1024**2)  # the worker's own imports on top
        uid = sandbox.sandbox_uid()
        argv = [sys.executable, "-I", "-m", "labkit.grading.worker"]
        seccomp_fd = None
        if confined:
            seccomp_fd = seccomp.pipe_with_program()
            argv = sandbox.command(argv + [str(uid)], limits, seccomp_fd)
            base, cwd, env = (0 if uid else sandbox.processes_of_this_user()), None, None
        else:
            self._folder = tempfile.mkdtemp(prefix="labkit-grade-")
            base, cwd = sandbox.processes_of_this_user(), self._folder
            env = {**os.environ, "HOME": self._folder, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"}
        group = self.cgroup

        def prepare():
            if group is not None:
                group.join()
            sandbox.apply_limits(limits, base)

        try:
            self.process = subprocess.Popen(
                argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, cwd=cwd, env=env,
                start_new_session=True, preexec_fn=prepare, pass_fds=(seccomp_fd,) if seccomp_fd is not None else ())
        finally:
            if seccomp_fd is not None:
                os.close(seccomp_fd)
        self._selector = selectors.DefaultSelector()
        self._selector.register(self.process.stdout, selectors.EVENT_READ)
        self.request({"op": "setup", "profiles": profiles if profiles is not None else refusals.wire(()),
                      "passables": sorted(self.passables)}, 120)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def peak_memory(self):
        return self.cgroup.peak() if self.cgroup is not None else None

    def close(self):
        """Stop the worker and everything it started; nothing of it is left on the machine."""
        if self.process.poll() is None:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                self.process.kill()
        self.process.wait()
        if self.cgroup is not None:
            if self.stopped is None and self.cgroup.out_of_memory():
                self.stopped = "the notebook ran out of memory"
            self.cgroup.remove()
        self._selector.close()
        for pipe in (self.process.stdin, self.process.stdout):
            try:
                pipe.close()
            except OSError:
                pass
        if self._folder is not None:
            remove_tree(self._folder)
            self._folder = None

    def _stop(self, why, error=WorkerError, **details):
        self.stopped = why
        self.close()
        raise error(why, **details)

    def request(self, message, timeout):
        """Send one request; its answer (a dict), or WorkerError after stopping the worker."""
        if self.stopped:
            raise WorkerError(self.stopped)
        rid = secrets.token_hex(8)  # unguessable: a line the notebook forges cannot pose as the answer
        try:
            self.process.stdin.write(protocol.dumps({**message, "id": rid}))
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
            if answer.get("id") == rid:
                error = answer.get("error") if isinstance(answer.get("error"), dict) else {}
                if error.get("kind") == "Tampered":
                    self.tampered = str(error.get("message", "tampering"))[:500]
                return answer

    def _ended(self):
        code = self.process.poll()
        if self.cgroup is not None and self.cgroup.out_of_memory():
            return "the notebook ran out of memory (the sandbox's limit)"
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
                total = until >= self.deadline
                limit = "total time limit" if total else "time limit"
                self._stop(f"stopped after the {limit}: the notebook did not answer in time", WorkerTimeout,
                           total=total)
            if not self._selector.select(remaining):
                continue
            chunk = os.read(self.process.stdout.fileno(), 1 << 20)
            if not chunk:
                try:
                    self.process.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    pass
                self._stop(self._ended())
            self._buffer += chunk
            if len(self._buffer) > protocol.MAX_LINE:
                self._stop("the notebook's process sent an answer larger than the protocol allows")
        line, _, self._buffer = self._buffer.partition(b"\n")
        return line


class Function:
    """Calls the student's function of this name inside the sandbox, with `refusal` switched off."""

    def __init__(self, notebook, name, refusal, timeout):
        self.notebook, self.name, self.refusal, self.timeout = notebook, name, refusal, timeout
        self.__name__ = name

    def __call__(self, *args):
        tags = [protocol.encode(arg, self.notebook.passables) for arg in args]
        request = {"op": "call", "name": self.name, "timeout": self.timeout, "args": tags,
                   "profile": self.refusal.name if self.refusal is not None else None,
                   "passables": sorted(protocol.function_names(tags))}
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
        raise StudentError(kind, message, str(refused)[:200] if refused else None,
                           str(error.get("traceback", ""))[:2000])
    try:
        return protocol.decode(answer.get("value"))
    except protocol.ProtocolError as exc:
        return protocol.NotNumbers(f"a value out of protocol ({exc})")


class Namespace:
    """The student's variables, read through the sandbox: the mapping the checks take.

    :meth:`refusing` sets what is switched off for the functions read after it
    (each part of an exercise says its own, :meth:`labkit.exercises.registry.Registry.check`).
    """

    def __init__(self, notebook, timeout=60):
        self.notebook, self.timeout = notebook, timeout
        self.refusal = None
        self._kinds = {}

    def refusing(self, refusal):
        self.refusal = refusal

    def _kind(self, name):
        if name not in self._kinds:
            try:
                answer = self.notebook.request({"op": "names", "names": [name]}, self.timeout)
                kind = answer.get("names", {}).get(name, "missing") if isinstance(answer.get("names"), dict) \
                    else "missing"
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
            return Function(self.notebook, name, self.refusal, self.timeout)
        try:
            return _value(self.notebook.request({"op": "get", "name": name, "timeout": self.timeout},
                                                self.timeout + 5))
        except (StudentError, WorkerError) as exc:
            return protocol.NotNumbers(f"nothing readable ({exc})")

    def get(self, name, default=None):
        return self[name] if name in self else default
