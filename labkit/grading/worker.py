"""The sandboxed side of grading: run a student's notebook, then answer the grader's calls.

Started by the grader as ``python -I -m labkit.grading.worker [UID]`` inside the
sandbox (:mod:`labkit.grading.sandbox`). Requests arrive one JSON line at a time
on standard input, answers leave on standard output (:mod:`labkit.grading.protocol`);
both are moved to private descriptors before any student code runs, and the
student's own output goes to a counter that keeps none of it.

Requests:

* ``{"op": "run", "cells": [...], "cell_timeout": s}``: run the code cells in
  an IPython shell, in order, each interrupted after ``s`` seconds;
* ``{"op": "names", "names": [...]}``: which are functions, data or missing;
* ``{"op": "get", "name": n}``: the value of a variable, as plain numbers;
* ``{"op": "call", "name": n, "args": [...], "refused": [...], "timeout": s}``:
  call a function with the references in ``refused`` switched off.

Everything this process says is only evidence: the grader checks it and
computes every score itself.
"""
import io
import os
import signal
import sys
import time

from . import protocol
from .refusals import RefusedReference, switched_off


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
    raise _Interrupted()


def _error(kind, message, refused=None):
    return {"error": {"kind": kind, "message": message, "refused": refused}}


def _describe(exc):
    kind = type(exc).__name__
    if isinstance(exc, _Interrupted):
        return "Timeout", "interrupted: it ran longer than the time limit"
    try:
        text = str(exc)
    except Exception:  # noqa: BLE001 - a hostile __str__
        text = ""
    return kind, text[:500]


class Worker:
    def __init__(self, answers, output):
        from IPython.core.interactiveshell import InteractiveShell
        from traitlets.config import Config

        config = Config()
        config.HistoryManager.enabled = False
        self.answers = answers
        self.shell = InteractiveShell.instance(config=config)
        # figures are built but never rendered: %matplotlib does nothing, the backend is Agg
        self.shell.register_magic_function(lambda line: None, "line", "matplotlib")
        self.output = output

    def reply(self, message):
        data = protocol.dumps(message)
        view = memoryview(data)
        while view:
            written = os.write(self.answers, view)
            view = view[written:]

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
            if failure is not None:
                kind, text = _describe(failure)
                errors.append({"cell": index, "kind": kind, "message": text})
            plt.close("all")  # as the inline backend does after each cell
        return {"errors": errors, "cells": len(cells), "output_chars": self.output.chars,
                "seconds": time.perf_counter() - start}

    def names(self, names):
        namespace, kinds = self.shell.user_ns, {}
        for name in names:
            if name not in namespace:
                kinds[name] = "missing"
            else:
                kinds[name] = "function" if callable(namespace[name]) else "data"
        return {"names": kinds}

    def call(self, name, args, refused, timeout):
        function = self.shell.user_ns.get(name)
        if not callable(function):
            return _error("NameError", f"{name} is not a function")
        arguments = [protocol.decode(arg, functions=True) for arg in args]
        with switched_off(refused) as attempts:
            signal.setitimer(signal.ITIMER_REAL, float(timeout))
            try:
                value = function(*arguments)
                encoded = protocol.encode(value)
            except RefusedReference as exc:
                return _error("RefusedReference", str(exc), exc.refused)
            except BaseException as exc:  # noqa: BLE001 - the student's error is the answer
                if isinstance(exc, SystemExit):
                    exc = RuntimeError(f"called sys.exit({exc.code!r})")
                return _error(*_describe(exc), attempts[0] if attempts else None)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            if attempts:
                return _error("RefusedReference", f"tried to call {attempts[0]}", attempts[0])
            return {"value": encoded}

    def get(self, name):
        if name not in self.shell.user_ns:
            return _error("NameError", f"{name} is not defined")
        return {"value": protocol.encode(self.shell.user_ns[name])}

    def serve(self, requests):
        for line in requests:
            request = None
            try:
                request = protocol.loads(line)
                op = request.get("op")
                if op == "run":
                    answer = self.run(request["cells"], request["cell_timeout"])
                elif op == "names":
                    answer = self.names(request["names"])
                elif op == "get":
                    answer = self.get(request["name"])
                elif op == "call":
                    answer = self.call(request["name"], request["args"], request["refused"], request["timeout"])
                elif op == "bye":
                    return
                else:
                    answer = _error("ProtocolError", f"unknown op {op!r}")
            except BaseException as exc:  # noqa: BLE001 - the worker answers every request
                answer = _error(*_describe(exc))
            answer["id"] = request.get("id") if isinstance(request, dict) else None
            self.reply(answer)


def _drop_privileges(uid):
    """As root inside the sandbox: become `uid`, so the process-count limit applies."""
    if os.getuid() == 0 and uid:
        os.setgroups([])
        os.setgid(uid)
        os.setuid(uid)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    _drop_privileges(int(argv[0]) if argv else 0)
    # the protocol gets private descriptors; 0, 1 and 2 become /dev/null for the student
    requests = os.fdopen(os.dup(0), "rb")
    answers = os.dup(1)
    null = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(null, fd)
    output = _Counter()
    sys.stdout = sys.stderr = output
    sys.stdin = io.StringIO("")
    worker = Worker(answers, output)
    signal.signal(signal.SIGALRM, _alarm)
    sys.path.insert(0, os.getcwd())  # as in a kernel, the notebook's folder is importable
    worker.serve(iter(requests.readline, b""))


if __name__ == "__main__":
    main()
