"""The sandboxed side of grading: a pristine supervisor and the notebook's process it watches.

Run as ``python -I -m labkit.grading.sandbox.worker [UID]`` in a backend's sandbox (as root it becomes UID, an
otherwise unused uid, so the sandbox's process limit holds). The **supervisor** holds the grader's pipes, imports
what notebooks need once and never runs student code. It forks the **notebook's process**, which installs the
watch (:mod:`labkit.grading.sandbox.guard`) first and answers one JSON line per request (:mod:`.protocol`):
``setup`` (always first), ``run``, ``names``, ``get`` and ``call``. The supervisor forwards only answers the
watch attests for that very request; a refused call, tampering, a time limit or a dead notebook it answers
itself, and a dead notebook's process is replaced at the next request, which runs the cells again. The grader
checks all of it and computes every score.
"""

import contextlib
import hashlib
import hmac
import importlib
import io
import os
import select
import signal
import sys
import time

from . import guard, protocol, seccomp

NOTEBOOK_IMPORTS = ("scipy.interpolate", "ipywidgets", "labkit.check", "labkit.plots", "labkit.plots.explorers")
RESTARTS = 3  # new notebook processes after one died, per notebook
_GUARD_FILE = guard.__file__


class _Counter(io.TextIOBase):
    """A text stream that counts what is written and keeps nothing."""

    def __init__(self):
        self.chars = 0

    def writable(self):
        return True

    def write(self, text):
        self.chars += len(text)
        return len(text)


class _Interrupted(KeyboardInterrupt):
    pass


def _alarm(signum, frame):
    """A cell's time is up: interrupt it, unless the watch is running (it never raises), then a moment later."""
    if frame is not None and frame.f_code.co_filename == _GUARD_FILE:
        signal.setitimer(signal.ITIMER_REAL, 0.005)
        return
    raise _Interrupted()


def _error(kind, message, refused=None, **marks):
    """An error answer; the supervisor's own are marked ``grader=True``: the grader trusts the mark, never a kind's
    name, which a student's exception may share."""
    return {"error": {"kind": kind, "message": message, "refused": refused, **marks}}


def _describe(exc):
    kind = type(exc).__name__
    if isinstance(exc, _Interrupted):
        return "Timeout", "interrupted: it ran longer than the time limit"
    try:
        text = str(exc)
    except Exception:  # noqa: BLE001 - a hostile __str__
        text = ""
    return kind, text[:500]


def _failure(exc, lines=40):
    """An exception as the student's cell would show it: its kind, message and the last lines of its traceback."""
    import traceback

    kind, text = _describe(exc)
    try:
        trace = "".join(traceback.format_exception(exc))
    except Exception:  # noqa: BLE001 - a hostile exception
        trace = ""
    return {"kind": kind, "message": text, "traceback": "\n".join(trace.rstrip().splitlines()[-lines:])[-4000:]}


class NotebookProcess:
    """The student's namespace in an IPython shell, and the answers to the grader's requests about it."""

    def __init__(self, shell, output):
        self.shell, self.output = shell, output

    def answer(self, request, handoff):
        op = request.get("op")
        if op == "run":
            return self.run(request["cells"], request["cell_timeout"])
        if op == "names":
            return self.names(request["names"])
        if op == "get":
            return self.get(request["name"])
        if op == "call":
            return self.call(request["name"], request["args"], handoff)
        return _error("ProtocolError", f"unknown op {op!r}")

    def run(self, cells, cell_timeout):
        import matplotlib.pyplot as plt

        errors, start = [], time.perf_counter()
        for index, source in enumerate(cells):
            signal.setitimer(signal.ITIMER_REAL, float(cell_timeout))
            try:
                result = self.shell.run_cell(source, store_history=False, silent=False)
            except BaseException as exc:  # noqa: BLE001 - the timer may fire outside the cell's own handler
                result, failure = None, exc
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            failure = (result.error_before_exec or result.error_in_exec) if result is not None else failure
            if failure is not None:  # timeout: the worker's own time limit, not a name
                errors.append({"cell": index, **_failure(failure), "timeout": isinstance(failure, _Interrupted)})
            plt.close("all")  # as the inline backend does after each cell
        seconds = time.perf_counter() - start
        return {"errors": errors, "cells": len(cells), "output_chars": self.output.chars, "seconds": seconds}

    def names(self, names):
        namespace, kinds = self.shell.user_ns, {}
        for name in names:
            kinds[name] = "missing" if name not in namespace else "function" if callable(namespace[name]) else "data"
        return {"names": kinds}

    def get(self, name):
        if name not in self.shell.user_ns:
            return _error("NameError", f"{name} is not defined")
        return {"value": protocol.encode(self.shell.user_ns[name])}

    def call(self, name, args, handoff):
        function = self.shell.user_ns.get(name)
        if not callable(function):
            return _error("NameError", f"{name} is not a function")
        arguments = [protocol.decode(arg, functions=handoff) for arg in args]
        try:
            return {"value": protocol.encode(function(*arguments))}
        except BaseException as exc:  # noqa: BLE001 - the student's error is the answer
            if isinstance(exc, SystemExit):
                exc = RuntimeError(f"called sys.exit({exc.code!r})")
            return {"error": _failure(exc)}


def _serve_one(notebook, reader, answers):
    """Answer one request between the watch's sentinels; read only once the watch watches, so nothing the notebook
    left behind sees a request's data unwatched."""
    handoff = {}
    sys.audit(guard.BEGIN)
    line = reader.readline()
    if line is None:
        return False
    request = protocol.loads(line)
    sys.audit(guard.CHOSEN, request.get("id"), request.get("profile"), request.get("passables", []), handoff)
    try:
        answer = notebook.answer(request, handoff)
    except BaseException as exc:  # noqa: BLE001 - every request gets an answer
        answer = _error(*_describe(exc))
    answer["id"] = request.get("id")
    payload = protocol.dumps(answer)
    sys.audit(guard.END, payload)
    protocol.write_all(answers, payload)
    return True


def _notebook_main(shell, pipes, setup):
    """The notebook's process: its timer, seccomp, the watch, then requests until the pipe closes."""
    os.setpgrp()  # the supervisor stops it and everything it starts at once
    output = _Counter()
    sys.stdout = sys.stderr = output
    sys.stdin = io.StringIO("")
    signal.signal(signal.SIGALRM, _alarm)
    seccomp.install_for_notebook()
    passables = {name: protocol.passable(name) for name in setup["passables"]}
    key = pipes["key"][0]
    chain = (_serve_one.__code__, _notebook_main.__code__)
    guard.install(os.read(key, 32), pipes["verdict"][1], guard.unwire(setup["profiles"]), passables, chain=chain)
    os.close(key)
    notebook, reader = NotebookProcess(shell, output), protocol.Lines(pipes["requests"][0])
    while _serve_one(notebook, reader, pipes["answers"][1]):
        pass


class Supervisor:
    """Holds the grader's pipes, forks and watches the notebook's process, forwards attested answers."""

    def __init__(self, requests_fd, answers_fd, shell):
        self.requests, self.answers, self.shell = protocol.Lines(requests_fd), answers_fd, shell
        self.setup, self.run_request = None, None
        self.child, self.restarts, self.ended = None, 0, None
        self.tampered = None  # what the watch reported: from then on no answer of this notebook counts

    def serve(self):
        for line in iter(self.requests.readline, None):
            request = protocol.loads(line)
            if request.get("op") == "bye":
                break
            if request.get("op") == "setup":
                self.setup, answer = request, {"ready": True}
            else:
                answer = self.forward(request)
            protocol.write_all(self.answers, protocol.dumps({**answer, "id": request.get("id")}))
        self.stop()

    def start(self):
        pipes = {name: os.pipe() for name in ("key", "verdict", "requests", "answers")}
        pid = os.fork()
        if pid == 0:  # the child: nothing of the supervisor's pipes but its own ends
            try:
                os.close(self.requests.fd)
                os.close(self.answers)
                for name, (read, write) in pipes.items():
                    os.close(write if name in ("key", "requests") else read)
                _notebook_main(self.shell, pipes, self.setup)
            finally:
                os._exit(0)
        for name, (read, write) in pipes.items():
            os.close(read if name in ("key", "requests") else write)
        self.secret = os.urandom(32)  # made after the fork: it never existed in the notebook's memory
        os.write(pipes["key"][1], self.secret)
        os.close(pipes["key"][1])
        self.child = {
            "pid": pid,
            "requests": pipes["requests"][1],
            "answers": protocol.Lines(pipes["answers"][0]),
            "verdicts": protocol.Lines(pipes["verdict"][0], 1 << 16),
        }

    def stop(self, why=None):
        if self.child is None:
            return
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(self.child["pid"], signal.SIGKILL)
        _, status = os.waitpid(self.child["pid"], 0)
        for fd in (self.child["requests"], self.child["answers"].fd, self.child["verdicts"].fd):
            os.close(fd)
        self.child = None
        signal_number = os.WTERMSIG(status) if os.WIFSIGNALED(status) else None
        self.ended = why or protocol.ended(signal_number, os.WEXITSTATUS(status))

    def _ensure_child(self, op):
        if self.child is not None:
            return None
        if self.setup is None:
            return _error("ProtocolError", "the first request must be setup")
        if self.run_request is None or op == "run":
            self.start()
            return None
        if self.restarts >= RESTARTS:
            return _error("WorkerError", f"{self.ended}; no more answers from this notebook", grader=True)
        self.restarts += 1
        self.start()
        replayed = self._exchange(self.run_request, None)  # the cells again, in a new process
        if self.child is None:
            return _error("WorkerError", f"{self.ended} while its cells ran again", grader=True)
        return replayed if "errors" not in replayed and "error" in replayed else None

    def forward(self, request):
        op = request.get("op")
        if self.tampered:
            return _error("Tampered", self._tamper_text(), grader=True)
        if op == "run":
            self.run_request = request
        problem = self._ensure_child(op)
        if problem is not None:
            return problem
        timeout = request.get("timeout") if op in ("call", "get") else None
        return self._exchange(request, timeout)

    def _exchange(self, request, timeout):
        """Send one request to the notebook's process; its attested answer, or the supervisor's own."""
        op = request.get("op")
        profile = guard.RUN if op == "run" else request.get("profile") if op == "call" else None
        passables = [str(p) for p in request.get("passables", ())] if op == "call" else []
        message = {**request, "profile": profile, "passables": passables}
        try:
            protocol.write_all(self.child["requests"], protocol.dumps(message))
        except OSError:
            return self._stopped()
        until = None if timeout is None else time.monotonic() + float(timeout) + 1.0
        answers, verdicts = self.child["answers"], self.child["verdicts"]
        while True:
            try:
                # the watch's pipe is read while waiting, so nothing the notebook writes to it can stall it
                while b"\n" not in answers.buffer:
                    remaining = None if until is None else until - time.monotonic()
                    if remaining is not None and remaining <= 0:
                        raise TimeoutError()
                    ready = select.select([answers.fd, verdicts.fd], [], [], remaining)[0]
                    if verdicts.fd in ready and self._read_verdicts():
                        self.stop("the grader's watch reported tampering")
                        return _error("Tampered", self._tamper_text(), grader=True)
                    if answers.fd in ready:
                        break
                line = answers.readline(until)
            except TimeoutError:
                self.stop("stopped after the time limit: the notebook did not answer in time")
                # the grader raises its CellTimeout for the timeout mark, not the words
                return _error("Timeout", "interrupted: it ran longer than the time limit", grader=True, timeout=True)
            except protocol.ProtocolError as exc:
                return self._stopped(f"the notebook's process answered out of protocol ({exc})")
            if line is None:
                return self._stopped()
            try:
                answer = protocol.loads(line)
            except protocol.ProtocolError:
                continue  # not an answer: something the notebook wrote itself
            if answer.get("id") == request.get("id"):
                return self._verified(answer, line + b"\n", str(request.get("id")), profile, passables)

    def _stopped(self, why=None):
        """Stop the notebook's process; the grader's error saying how it ended."""
        self.stop(why)
        return _error("WorkerError", self.ended, grader=True)

    def _tamper_text(self):
        return (
            f"the notebook used {self.tampered}, so the grader cannot vouch for its answers (threads, "
            "processes, ctypes, profilers, debuggers and the garbage collector's lists are not allowed while "
            "a notebook is graded)"
        )

    def _read_verdicts(self):
        """File what the watch wrote: tampering (sticky, True when there is some) and attestations."""
        pending = self.child.setdefault("attestations", [])
        for line in self.child["verdicts"].available():
            text = line.decode("utf-8", "replace")
            if text.startswith("TAMPER\t"):
                self.tampered = self.tampered or text.split("\t", 1)[1][:200]
            else:
                pending.append(text)
        return bool(self.tampered)

    def _verified(self, answer, payload, rid, profile, passables):
        expected = guard.attestation_text(rid, profile, passables, None, hashlib.sha256(payload).hexdigest())
        if self._read_verdicts():
            self.stop("the grader's watch reported tampering")
            return _error("Tampered", self._tamper_text(), grader=True)
        pending, self.child["attestations"] = self.child["attestations"], []
        # exactly one line may speak for this request, and it must be the watch's: a second one, or one
        # that does not verify, means the notebook found the request's id and wrote to the watch's pipe
        mine = [text.split("\t") for text in pending if text.split("\t", 1)[0] == expected[0]]
        if not mine:
            why = "the answer came without the grader's watch (it was switched off, or the answer was forged)"
            return _error("Tampered", why, grader=True)
        *fields, signature = mine[0] if len(mine[0]) == 6 else [""] * 6
        matches = [fields[i] for i in (0, 1, 2, 4)] == [expected[i] for i in (0, 1, 2, 4)]  # all but the status
        if len(mine) > 1 or not matches or not hmac.compare_digest(signature, guard.sign(self.secret, *fields)):
            why = "the notebook wrote to the grader's watch, so the grader cannot vouch for its answers"
            return _error("Tampered", why, grader=True)
        status = fields[3]
        if status == "clean":
            if isinstance(answer.get("error"), dict):  # only the supervisor speaks as the grader
                answer["error"].pop("grader", None)
                answer["error"].pop("timeout", None)
            return answer
        what, _, detail = status.partition(":")
        if what == "refused":
            return _error(
                "RefusedReference", f"called {detail}, which is switched off while this part is graded", detail
            )
        self.tampered = self.tampered or detail
        return _error("Tampered", self._tamper_text(), grader=True)


def drop_privileges(uid):
    """As root inside the sandbox: become `uid`, so the process-count limit applies."""
    if os.getuid() == 0 and uid:
        os.setgroups([])
        os.setgid(uid)
        os.setuid(uid)


def not_dumpable():
    """No other process of the sandbox's user may read or write this one's memory (PR_SET_DUMPABLE 0)."""
    with contextlib.suppress(OSError, AttributeError):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(4, 0, 0, 0, 0)


def preload(everything=False):
    """Import what every notebook needs (with `everything`, the lab's imports too) once; the shell to fork with."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot
    import numpy  # noqa: F401

    # the watch learns the exact types of compiled routines (Cython's, f2py's) from the modules loaded at install
    import scipy.linalg
    import scipy.spatial  # noqa: F401
    from IPython.core.interactiveshell import InteractiveShell
    from traitlets.config import Config

    import labkit.plotdata  # noqa: F401 - what encode reads plots with

    # only in a fork server: a plain worker would pay for them in the notebook's time, imported or not
    for name in NOTEBOOK_IMPORTS if everything else ():
        with contextlib.suppress(ImportError):  # a course without the lab's extras still grades
            importlib.import_module(name)

    config = Config()
    config.HistoryManager.enabled = False
    shell = InteractiveShell.instance(config=config)
    # figures are built but never rendered: %matplotlib does nothing, the backend is Agg
    shell.register_magic_function(lambda line: None, "line", "matplotlib")
    return shell


def supervise(requests, answers, shell):
    """Answer the grader on `requests` and `answers` until bye; student code gets /dev/null for 0-2 and the working
    folder on its path, as in a kernel."""
    given = (requests, answers)
    requests, answers = os.dup(requests), os.dup(answers)
    for fd in given:  # the student's code must not find a second copy of the grader's pipes
        if fd > 2:
            os.close(fd)
    null = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(null, fd)
    if null > 2:
        os.close(null)
    sys.path.insert(0, os.getcwd())
    # the course modules a rubric names, for the notebook's self-checks
    for folder in [protocol.COURSE_FOLDER, *os.environ.pop(protocol.COURSE_PATH, "").split(os.pathsep)]:
        if folder and os.path.isdir(folder):
            sys.path.append(folder)
    os.environ["LABKIT_HEADLESS"] = "1"  # nothing shown here is seen (labkit.notebook.headless)
    Supervisor(requests, answers, shell).serve()


def main():
    drop_privileges(int(sys.argv[1]) if len(sys.argv) > 1 else 0)
    not_dumpable()
    supervise(0, 1, preload())


if __name__ == "__main__":
    main()
