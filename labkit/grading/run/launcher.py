"""The launcher: one warm Python that forks each submission's grading process; its client and its server.

Started as ``python -m labkit.grading.submission.scoring SPEC``, each grading process (:mod:`.processes`) would
import labkit's checks, numpy and scipy again. Instead :class:`Launcher` starts ``python -m
labkit.grading.run.launcher EXERCISES SOLUTIONS`` once per run: its server (:func:`main`) imports all that and
fingerprints the known code (:func:`~labkit.grading.submission.scoring.warm`), then forks one child per
submission, which puts itself in a session, cgroup and address-space limit of its own and runs
:func:`labkit.grading.submission.scoring.main`. No student code runs here: only in the child's sandboxes.

The server reads one request per line on stdin (``{"spec", "log", "memory", "cgroups", "environment", "id"}``) and
writes one line per event on stdout: ``{"ready": true}`` once, then ``{"started": pid, "id": i}`` and ``{"ended":
pid, "id": i, "code": c}``, `i` the request's own ``id`` (a pid can be used again), ``c`` as Popen's returncode.
When its stdin closes (the run is over, or the grader died) it stops every child still running and ends.
"""

import contextlib
import json
import os
import secrets
import select
import signal
import subprocess
import sys
import threading
import time

from ..sandbox import protocol
from .processes import confine, die_with, one_thread

LAUNCH_TIMEOUT = 30  # seconds for the launcher to fork one grading process
LAUNCHER_READY = 120  # seconds for the launcher to import the grader and fingerprint the known code
REQUEST_LIMIT = 1 << 16  # bytes of one request line


# The client: in the grader's process (or a Dask worker's).


class _Launched:
    """The part of a Popen that :class:`.processes.Job` uses, for a grading process the :class:`Launcher` forked."""

    def __init__(self, launcher, pid, key):
        self.launcher, self.pid, self.key = launcher, pid, key  # `key`: its request's id, never used twice

    @property
    def returncode(self):
        return self.launcher.ended.get(self.key)

    def poll(self, wait=0):
        if not self.launcher.pump(wait) and self.launcher.process.poll() is not None:
            self.launcher.ended.setdefault(self.key, -signal.SIGKILL)  # the launcher is gone, and its children
        return self.returncode

    def wait(self):
        while self.poll(0.05) is None:
            pass
        return self.returncode


class Launcher:
    """One warm process that forks each submission's grading process (its server: :func:`main`)."""

    def __init__(self, options, server):
        self.ended, self._lock = {}, threading.RLock()
        parent = os.getpid()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "labkit.grading.run.launcher", options.exercises or "", options.solutions or ""],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
            env=one_thread(),
            pass_fds=(server.fd,) if server is not None else (),
            preexec_fn=lambda: die_with(parent),
        )
        self._lines = protocol.Lines(self.process.stdout.fileno(), REQUEST_LIMIT)

    def wait_ready(self):
        """Wait until the launcher has imported the grader; OSError (and the launcher stopped) when it does not."""
        if self._next(time.monotonic() + LAUNCHER_READY) != {"ready": True}:
            self.stop()
            raise OSError("the launcher of grading processes did not start")

    def _next(self, until):
        """The launcher's next message, or None when `until` passes or it is gone."""
        if self.process.stdout.closed:  # stopped
            return None
        try:
            line = self._lines.readline(until)
        except (TimeoutError, protocol.ProtocolError):  # nothing yet, or not the launcher's message
            return None
        return None if line is None else json.loads(line)

    def pump(self, wait):
        """File every ended process the launcher reported (waiting up to `wait` s for one); whether any."""
        with self._lock:
            found, message = False, self._next(time.monotonic() + wait)
            while message is not None:
                found = self._filed(message) or found
                message = self._next(time.monotonic())
            return found

    def _filed(self, message):
        """Whether `message` says a grading process ended (then filed)."""
        if "ended" in message:
            self.ended[message.get("id")] = int(message["code"])
        return "ended" in message

    def launch(self, request):
        """Fork a grading process for `request`; a :class:`_Launched` (OSError when the launcher is gone)."""
        with self._lock:
            key = request["id"] = secrets.token_hex(8)
            try:
                self.process.stdin.write((json.dumps(request) + "\n").encode())
                self.process.stdin.flush()
            except ValueError:  # closed: stopped
                raise OSError("the launcher of grading processes was stopped") from None
            while True:
                message = self._next(time.monotonic() + LAUNCH_TIMEOUT)
                if message is None:
                    raise OSError("the launcher of grading processes stopped answering")
                if not self._filed(message) and "started" in message and message.get("id") == key:
                    return _Launched(self, int(message["started"]), key)

    def stop(self):
        with contextlib.suppress(OSError):
            self.process.stdin.close()  # it stops every grading process still running, then ends
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.process.stdout.close()


# The server: ``python -m labkit.grading.run.launcher [EXERCISES [SOLUTIONS]]``, a process of its own.


def _child(request):
    """The submission's grading process; never returns."""
    code = 1
    try:
        os.setsid()
        confine(request["launcher"], int(request["memory"]), request.get("cgroups", ()))
        null = os.open(os.devnull, os.O_RDWR)
        log = os.open(request["log"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        for fd, target in ((null, 0), (null, 1), (log, 2)):
            os.dup2(fd, target)
        os.close(null)
        os.close(log)
        sys.stdin = open(os.devnull)  # noqa: SIM115 - for the rest of this process's life
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115
        sys.stderr = os.fdopen(2, "w", buffering=1)
        os.environ.clear()
        os.environ.update(request["environment"])
        from ..submission import scoring

        code = int(scoring.main([request["spec"]]) or 0)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    except BaseException:  # noqa: BLE001 - written to the log, as an unforked process would have
        import traceback

        with contextlib.suppress(Exception):
            traceback.print_exc()
            sys.stderr.flush()
    os._exit(code)


def _say(message):
    os.write(1, (json.dumps(message) + "\n").encode())


def _reaped(children):
    """[(pid, its request's id, wait status)] of the `children` that ended, taken out of `children`."""
    ended = []
    for pid in list(children):
        try:
            done, status = os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            done, status = pid, 0
        if done:
            ended.append((pid, children.pop(pid), status))
    return ended


def main():
    from ..submission import scoring  # what grading a submission needs, imported once

    exercises, solutions = (sys.argv[1:] + ["", ""])[:2]
    registry = scoring.load_registry(exercises or None)
    with contextlib.suppress(ValueError, OSError):  # then each grading process meets it and says what is wrong
        scoring.warm(registry, solutions or None)  # once here, not once per submission
    import scipy.interpolate  # the checks compare with it
    import scipy.linalg  # noqa: F401

    _say({"ready": True})
    children, buffer = {}, b""  # pid -> the request's id
    try:
        while True:
            readable = select.select([0], [], [], 0.05)[0]
            for pid, key, status in _reaped(children):
                _say({"ended": pid, "id": key, "code": os.waitstatus_to_exitcode(status)})
            if not readable:
                continue
            chunk = os.read(0, 1 << 16)
            if not chunk:
                return 0
            buffer += chunk
            if len(buffer) > REQUEST_LIMIT and b"\n" not in buffer:
                return 1
            *lines, buffer = buffer.split(b"\n")
            for line in lines:
                request = json.loads(line)
                request["launcher"] = os.getpid()
                pid = os.fork()
                if pid == 0:
                    _child(request)
                children[pid] = request.get("id")
                _say({"started": pid, "id": request.get("id")})
    finally:
        for pid in children:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(pid, signal.SIGKILL)
        deadline = time.monotonic() + 5
        while children and time.monotonic() < deadline:
            _reaped(children)
            time.sleep(0.02)


if __name__ == "__main__":
    sys.exit(main())
