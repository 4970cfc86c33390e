"""Each submission's grading process, as the grader supervises it: its limits, its end, its outcome.

A :class:`Job` starts ``python -m labkit.grading.submission.scoring SPEC`` (or has the run's launcher fork it,
:mod:`.launcher`) in an address-space limit and a memory cgroup of its own, and stops it when it overruns the
submission's time limit plus a grace for the checks. No student code runs here.
"""

import contextlib
import ctypes
import functools
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict
from pathlib import Path

from ...errors import InputError
from ..sandbox import backends, cgroup, forkserver
from ..sandbox.backends.base import SandboxUnavailable
from ..store import record as records
from ..store.late import read_small
from ..store.report import FORMAT, one_line, safe_name

MIN_FREE = 512 * 1024**2  # bytes free in the temporary and output folders before a submission starts
ATTEMPTS = 2  # a grading process that breaks is started once more


def low_space(out):
    """Why grading cannot go on (a folder with too little free space), or None."""
    for folder in (Path(tempfile.gettempdir()), out):
        try:
            free = shutil.disk_usage(folder).free
        except OSError:
            continue
        if free < MIN_FREE:
            return (
                f"only {free / 1024**2:.0f} MiB free in {folder} (grading needs {MIN_FREE // 1024**2} MiB); "
                "free some space and grade these submissions again, then combine the runs with `labkit merge`"
            )
    return None


class Job:
    """One submission's grading process: `server` is the run's fork server (labkit.grading.sandbox.forkserver)
    and `launcher` its :class:`.launcher.Launcher`, each None where there is none (the plain way)."""

    def __init__(self, path, name, work, options, profiles_file, server=None, launcher=None):
        self.path, self.name, self.attempt = Path(path), name, 0
        self.work, self.options, self.profiles_file = work, options, profiles_file
        self.server, self.launcher = server, launcher
        self.process, self.cgroup, self.started, self.peaks = None, None, None, []

    def start(self):
        self.attempt += 1
        stem = self.work / f"{safe_name(self.name)}-{self.attempt}"
        self.result, spec, self.log = Path(f"{stem}.json"), Path(f"{stem}.spec.json"), Path(f"{stem}.log")
        origin = None if self.options.backend in backends.BUILTIN else backends.origin(self.options.backend)
        given = {
            "submission": str(self.path),
            "name": self.name,
            "result": str(self.result),
            "profiles": str(self.profiles_file),
            "options": asdict(self.options),
            "backend_origin": origin,
        }
        spec.write_text(json.dumps(given), encoding="utf-8")
        memory = self.options.grader_memory
        group = self.cgroup = cgroup.create(memory, label="labkit-grader", cores=None)
        folders = [group.path, group.cpu_path] if group is not None else []
        cgroups = [str(folder / "cgroup.procs") for folder in folders if folder is not None]
        environment = one_thread()
        if group is not None:  # the sandboxes' cgroups go beside the grading process's, not inside its limit
            environment.update(group.sibling_environment())
        environment.pop(forkserver.ENV, None)
        if self.server is not None:
            environment.update(self.server.environment())
        if self.launcher is not None:
            request = {"spec": str(spec), "log": str(self.log), "memory": memory, "cgroups": cgroups}
            try:
                self.process = self.launcher.launch({**request, "environment": environment})
                self.started = time.monotonic()
                return
            except OSError:  # the launcher is gone: this submission and the next start the plain way
                self.launcher = None
        with open(self.log, "wb") as log:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "labkit.grading.submission.scoring", str(spec)],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=log,
                start_new_session=True,
                preexec_fn=functools.partial(confine, os.getpid(), memory, cgroups),
                env=environment,
                pass_fds=(self.server.fd,) if self.server is not None else (),
            )
        self.started = time.monotonic()

    @property
    def limit(self):
        return self.options.total_timeout + self.options.grader_grace

    def last_words(self):
        """The last line the grading process wrote to stderr (a Python error's summary), as one printable line."""
        try:
            with open(self.log, "rb") as log:
                log.seek(max(0, os.path.getsize(self.log) - 4096))
                lines = log.read().decode("utf-8", "replace").strip().splitlines()
        except OSError:
            return ""
        return f": {one_line(lines[-1], 200)}" if lines else ""

    def poll(self):
        """Whether this attempt is over: its process ended, or overran its limit and was killed with everything it
        started (its sandboxes die with it)."""
        running = self.process.poll() is None
        if running and time.monotonic() - self.started <= self.limit:
            return False
        self.timed_out = running
        if running:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait()
        self.out_of_memory, peak = False, None
        if self.cgroup is not None:
            self.out_of_memory, peak = self.cgroup.out_of_memory(), self.cgroup.peak()
            self.cgroup.remove()
        self.peaks.append(peak)
        return True

    def conclude(self):
        """After an attempt: True when the submission is done (:meth:`message`), False when its grading process is
        to be started once more (:data:`ATTEMPTS`)."""
        self.data, self.why = self.read()
        return self.data is not None or self.attempt >= ATTEMPTS

    def message(self):
        """The submission's outcome as plain data (what a Dask task sends back): its result file's data, or
        why it could not be graded."""
        return {
            "name": self.name,
            "result": self.data,
            "failure": None if self.data is not None else f"{self.why} (tried {self.attempt} times)",
            "attempts": self.attempt,
            "peak": max((p for p in self.peaks if p), default=None),
        }

    def read(self):
        """(the result file's data, None), or (None, why the grading process failed)."""
        code = self.process.returncode
        if self.timed_out:
            return None, (
                f"its grading took longer than {self.limit} s (the submission's time limit plus "
                f"{self.options.grader_grace} s for the checks) and was stopped"
            )
        if code != 0 or not self.result.exists():
            if self.out_of_memory or code in (-signal.SIGKILL, -signal.SIGSEGV):
                return None, (
                    "its grading ran out of memory (the grader's limit of "
                    f"{self.options.grader_memory // 1024**2} MiB) and was stopped"
                    if self.out_of_memory or code == -signal.SIGKILL
                    else f"its grading process crashed ({signal.Signals(-code).name})"
                )
            if code is not None and code < 0:
                name = signal.Signals(-code).name if -code in signal.Signals._value2member_map_ else str(-code)
                return None, f"its grading process was killed by {name}"
            return None, f"its grading process ended with status {code} without a result{self.last_words()}"
        try:
            raw = read_small(self.result, records.MAX_RESULT)  # ValueError when larger than the grader accepts
            data = json.loads(raw.decode("utf-8"))
            if not isinstance(data, dict) or data.get("format") != FORMAT:
                raise InputError(f"format {data.get('format') if isinstance(data, dict) else data!r:.60}")
        except (OSError, ValueError) as exc:
            return None, f"its result could not be read ({str(exc)[:200]})"
        return data, None


def peak_bytes():
    """This process's peak resident memory in bytes (the grader's, or a Dask worker's; not its children's)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def one_thread():
    """The grader's environment, with numpy's libraries held to one thread (a grading process, the launcher)."""
    return {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


_LIBC = ctypes.CDLL(None, use_errno=True) if sys.platform.startswith("linux") else None


def confine(parent, memory, cgroups):
    """In a grading process before it runs (Popen's ``preexec_fn``, or forked by the launcher): join its `cgroups`
    (their ``cgroup.procs`` files), limit its address space to `memory` bytes, and die with `parent`."""
    for procs in cgroups:
        with open(procs, "w") as handle:
            handle.write(str(os.getpid()))
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    die_with(parent)


def sandbox_problem(backend):
    """Why the sandbox backend named `backend` cannot run here, or None."""
    try:
        backends.get_backend(backend).available()
    except SandboxUnavailable as exc:
        return str(exc)
    return None


def die_with(parent):
    """In a grading process before it runs: be killed when the thread that started it dies (the grader, or
    a Dask worker killed mid-task), so no grading outlives its grader; Linux only."""
    if _LIBC is not None:
        _LIBC.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # the grader died before the line above
            os._exit(1)
