"""Each submission's grading process, forked from one process that has imported the grader once.

A grading run (:mod:`labkit.grading.batch`) grades every submission in a
process of its own, so that a submission that makes its grading crash, run
out of memory or hang costs only its own grade. Started as
``python -m labkit.grading.submission.scoring SPEC``, each of those processes would
import labkit's checks, numpy and scipy again. :class:`Launcher` starts
``python -m labkit.grading.launcher`` once per run instead: it imports all
that, then forks one child per submission, which puts itself in a session,
cgroup and address-space limit of its own (what ``Popen``'s ``preexec_fn``
did before) and runs :func:`labkit.grading.submission.scoring.main`. No student code
runs here: student code runs only in the sandboxes the child starts.

The launcher reads one request per line on stdin
(``{"spec", "log", "memory", "cgroups", "environment"}``) and writes one line
per event on stdout: ``{"started": pid, "id": i}`` and ``{"ended": pid, "id": i, "code": c}``, `i`
the request's own ``id`` (a pid can be used again once its process has ended)
(``c`` as Popen's returncode). When its stdin closes (the run is over, or
the grader died) it stops every child still running and ends.
"""

import json
import os
import resource
import select
import signal
import sys
import time

REQUEST_LIMIT = 1 << 16  # bytes of one request line


def _warm(exercises):
    """Import what grading a submission needs, once."""
    from .options import GradeOptions
    from .submission import scoring

    scoring.load_registry(GradeOptions(exercises=exercises).exercises)
    import scipy.interpolate  # the checks compare with it
    import scipy.linalg  # noqa: F401


def _child(request):
    """The submission's grading process; never returns."""
    code = 1
    try:
        os.setsid()
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG: die with the launcher
        if os.getppid() != request["launcher"]:  # it died before the line above
            os._exit(1)
        for procs in request.get("cgroups", ()):
            with open(procs, "w") as handle:
                handle.write(str(os.getpid()))
        memory = int(request["memory"])
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
        null = os.open(os.devnull, os.O_RDWR)
        log = os.open(request["log"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(null, 0)
        os.dup2(null, 1)
        os.dup2(log, 2)
        os.close(null)
        os.close(log)
        sys.stdin = open(os.devnull)  # noqa: SIM115 - for the rest of this process's life
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115
        sys.stderr = os.fdopen(2, "w", buffering=1)
        os.environ.clear()
        os.environ.update(request["environment"])
        from .submission import scoring

        code = int(scoring.main([request["spec"]]) or 0)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    except BaseException:  # noqa: BLE001 - written to the log, as an unforked process would have
        import traceback

        try:
            traceback.print_exc()
            sys.stderr.flush()
        except Exception:  # noqa: BLE001
            pass
    os._exit(code)


def _say(message):
    os.write(1, (json.dumps(message) + "\n").encode())


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    _warm(argv[0] if argv and argv[0] else None)
    _say({"ready": True})
    children, buffer = {}, b""  # pid -> the request's id
    try:
        while True:
            readable = select.select([0], [], [], 0.05)[0]
            for pid in list(children):
                try:
                    done, status = os.waitpid(pid, os.WNOHANG)
                except ChildProcessError:
                    done, status = pid, 0
                if done and pid in children:
                    _say({"ended": pid, "id": children.pop(pid), "code": os.waitstatus_to_exitcode(status)})
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
            try:
                os.killpg(pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        deadline = time.monotonic() + 5
        while children and time.monotonic() < deadline:
            for pid in list(children):
                try:
                    if os.waitpid(pid, os.WNOHANG)[0]:
                        children.pop(pid)
                except ChildProcessError:
                    children.pop(pid)
            time.sleep(0.02)


if __name__ == "__main__":
    sys.exit(main())
