"""The grader's handle on one sandboxed notebook: start it, run it, call into it, stop it.

:class:`NotebookHandle` runs the worker (:mod:`labkit.grading.sandbox.worker`) in a sandbox; :class:`Namespace` is
the mapping the checks read, its functions :class:`Function` proxies that call into the sandbox, so the checks of
:mod:`labkit.exercises` run unchanged here, never in the student's process.
"""

import contextlib
import secrets
import subprocess
import sys
import time
from typing import Protocol

from ...exercises.result import CRASH, TAMPERED, TIMEOUT
from . import backends, forkserver, protocol, timings
from .backends.base import Limits

WORKER = (sys.executable, "-I", "-m", "labkit.grading.sandbox.worker")  # the worker's command, run inside the sandbox
SETUP_TIMEOUT = 120  # seconds for a new worker to import what notebooks need and answer its setup


class WorkerError(RuntimeError):
    """The sandboxed notebook stopped, hung or answered out of protocol: the grading error of one notebook."""

    kind = "WorkerError"
    grader_kind = CRASH  # the kind of a failed step (labkit.exercises.result.grader_kind): no StudentError has one


class WorkerTimeout(WorkerError):
    """The notebook did not answer in time (one of the two kinds below)."""

    kind = "Timeout"
    grader_kind = TIMEOUT
    total = False  # whether the submission's whole time is used up


class CellTimeout(WorkerTimeout):
    """A cell, a request or one call of a student's function ran past its own time limit."""


class NotebookTimeout(WorkerTimeout):
    """The submission's total time limit is used up: nothing more of it can run."""

    total = True


class StudentError(Exception):
    """An exception of the student's code (type name in ``kind``), or a call the grader ended (the subclasses)."""

    grader_kind: str | None = None  # an exception the student's code raised: whatever its name, no kind of the grader's

    def __init__(self, kind, message, refused=None, traceback=""):
        super().__init__(message)
        self.kind, self.refused, self.traceback = kind, refused, traceback


class CallEnded(StudentError):
    """A call its process never answered (it ended or could answer no more), said in the supervisor's marked
    answer, never an exception's name; it costs only itself (the notebook restarts for the next request)."""

    grader_kind = CRASH  # the kind of a failed step (labkit.exercises.result.grader_kind)


class Tampered(StudentError):
    """A call the watch cannot vouch for (switched off, gone round, its pipe written to): every answer is void."""

    grader_kind = TAMPERED


class Settings(Protocol):
    """What a sandboxed notebook needs of the run's options (the fields of GradeOptions it reads)."""

    @property
    def backend(self) -> str: ...  # the sandbox backend's name
    @property
    def limits(self) -> Limits: ...
    @property
    def fork_server(self) -> bool: ...
    @property
    def cell_timeout(self) -> float: ...  # seconds
    @property
    def total_timeout(self) -> float: ...  # seconds


# benchmarks/bench_grading_styles.py only, in its own process: no refusal asked. No option, variable or file sets it.
_UNWATCHED = False
MEMO_BYTES = 64 * 1024**2  # the calls whose answers a notebook's handle keeps, in bytes of the calls


class NotebookHandle:
    """One worker in the sandbox `options` name, until `deadline` (monotonic); `profiles` are what the watch refuses
    (:func:`labkit.grading.submission.refusals.wire`), `passables` what the checks may hand to student code."""

    def __init__(self, options: Settings, deadline=None, profiles=None, passables=()):
        self.options = options
        self.deadline = deadline if deadline is not None else time.monotonic() + self.options.total_timeout
        self.passables = frozenset(passables)  # functions the checks may hand to student code, by name
        self.stopped = None  # why the worker can no longer answer
        self.stopped_kind = CRASH  # the kind of problem it is (labkit.exercises.result.KINDS), once stopped
        self.tampered = None  # what the notebook did that voids its answers
        self._answers: dict[bytes, dict] = {}  # the answers to calls, by the call (see answered)
        self._kept = 0  # the bytes of the calls kept
        self.backend = backends.get_backend(self.options.backend)
        # a worker from this process's fork server when there is one, else from a sandbox of its own
        self.box = forkserver.box(self.backend, self.options.limits) if self.options.fork_server else None
        if self.box is not None:
            try:
                self.process = self.box.start()
            except (forkserver.ForkServerError, OSError):
                self.box.close()
                self.box = None
        if self.box is None:
            self.box = self.backend.box(list(WORKER), self.options.limits)
            try:
                self.process = self.box.start()
            except OSError as exc:
                self.box.close()
                raise WorkerError(f"the {self.backend.name} sandbox could not start the worker ({exc})") from None
            except BaseException:
                self.box.stop()
                self.box.close()
                raise
        self._lines = protocol.Lines(self.process.stdout.fileno())  # each answer at most protocol.MAX_LINE
        self.request({"op": "setup", "profiles": profiles or {}, "passables": sorted(self.passables)}, SETUP_TIMEOUT)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        """Stop the worker and everything it started; nothing of it is left on the machine."""
        self.box.stop()
        if self.stopped is None and not self.box.closed and self.box.out_of_memory():
            self.stopped, self.stopped_kind = "the notebook ran out of memory", CRASH
        self.box.close()

    def _stop(self, why, error=WorkerError):
        self.stopped, self.stopped_kind = why, error.grader_kind
        self.close()
        raise error(why)

    def request(self, message, timeout):
        """Send one request; its answer (a dict), or WorkerError after stopping the worker."""
        if self.stopped:
            raise WorkerError(self.stopped)
        rid = secrets.token_hex(8)  # unguessable: a line the notebook forges cannot pose as the answer
        try:
            self.process.stdin.write(protocol.dumps({**message, "id": rid}))
            self.process.stdin.flush()
        except OSError:
            self._stop(self._ended())
        until = min(self.deadline, time.monotonic() + timeout)
        while True:
            try:
                line = self._lines.readline(until)
            except TimeoutError:
                error = NotebookTimeout if until >= self.deadline else CellTimeout
                limit = "total time limit" if error.total else "time limit"
                self._stop(f"stopped after the {limit}: the notebook did not answer in time", error)
            except protocol.ProtocolError:
                self._stop("the notebook's process sent an answer larger than the protocol allows")
            if line is None:
                with contextlib.suppress(subprocess.TimeoutExpired):
                    self.process.wait(timeout=5)
                self._stop(self._ended())
            try:
                answer = protocol.loads(line)
            except protocol.ProtocolError as exc:
                self._stop(f"the notebook's process answered out of protocol ({exc})")
            if answer.get("id") == rid:
                error = answer.get("error") if isinstance(answer.get("error"), dict) else {}
                if error.get("kind") == "Tampered" and error.get("grader"):  # the supervisor's word, not a name
                    self.tampered = str(error.get("message", "tampering"))[:500]
                return answer

    def answered(self, call, timeout):
        """The answer to a call: the earlier answer to the very same call (parts call on the same sizes), else a
        new one. An answer the grader gave up on is never kept."""
        key = protocol.dumps(call)
        if key not in self._answers:
            with timings.phase("calls"):
                answer = self.request(call, timeout)
            if len(key) + self._kept > MEMO_BYTES:
                return answer
            self._answers[key], self._kept = answer, self._kept + len(key)
        return self._answers[key]

    def _ended(self):
        code = self.process.poll()
        if self.box.out_of_memory():
            return "the notebook ran out of memory (the sandbox's limit)"
        if code is None:
            return "the notebook's process stopped answering"
        return protocol.ended(-code if code < 0 else None, code)


class Function:
    """Calls the student's function of this name inside the sandbox, with `refusal` switched off."""

    def __init__(self, notebook, name, refusal, timeout):
        self.notebook, self.name, self.refusal, self.timeout = notebook, name, refusal, timeout
        self.__name__ = name

    def __call__(self, *args):
        tags = [protocol.encode(arg, self.notebook.passables) for arg in args]
        request = {
            "op": "call",
            "name": self.name,
            "timeout": self.timeout,
            "args": tags,
            "profile": self.refusal.name if self.refusal is not None and not _UNWATCHED else None,
            "passables": sorted(protocol.function_names(tags)),
        }
        return _value(self.notebook.answered(request, self.timeout + 5))

    def __repr__(self):
        return f"<student function {self.name} in the sandbox>"


def _value(answer):
    if "error" in answer:
        error = answer["error"] if isinstance(answer["error"], dict) else {}
        kind, message = str(error.get("kind", "Error"))[:100], str(error.get("message", ""))[:500]
        refused = error.get("refused")
        if error.get("grader") is True:  # the supervisor's own errors, marked as such (never a name's say-so)
            if error.get("timeout") is True:  # it stopped the call at its time limit
                raise CellTimeout(message)
            raise (Tampered if kind == Tampered.__name__ else CallEnded)(kind, message)
        if kind == "NotImplementedError" and not refused:
            raise NotImplementedError(message)
        raise StudentError(
            kind, message, str(refused)[:200] if refused else None, str(error.get("traceback", ""))[:2000]
        )
    try:
        return protocol.decode(answer.get("value"))
    except protocol.ProtocolError as exc:
        return protocol.NotNumbers(f"a value out of protocol ({exc})")


class Namespace:
    """The student's variables, read through the sandbox: the mapping the checks take; :meth:`refusing` sets what
    is switched off for the functions read after it."""

    def __init__(self, notebook, timeout=None):
        self.notebook = notebook
        self.timeout = timeout if timeout is not None else notebook.options.cell_timeout
        self.refusal = None
        self._kinds = {}

    def refusing(self, refusal):
        self.refusal = refusal

    def _kind(self, name):
        if name not in self._kinds:
            try:
                with timings.phase("reads"):
                    names = self.notebook.request({"op": "names", "names": [name]}, self.timeout).get("names")
                kind = names.get(name) if isinstance(names, dict) else None
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
            with timings.phase("reads"):
                answer = self.notebook.request({"op": "get", "name": name, "timeout": self.timeout}, self.timeout + 5)
            return _value(answer)
        except (StudentError, WorkerError) as exc:
            return protocol.NotNumbers(f"nothing readable ({exc})")

    def get(self, name, default=None):
        return self[name] if name in self else default
