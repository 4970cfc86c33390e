"""Where a class run's submissions are graded: the :class:`Engine` interface, the local engine, the warm helpers.

An engine takes a :class:`Batch` and yields one :class:`Outcome` per submission as each is graded, in any
order. :class:`LocalEngine` grades here, a few grading processes at a time; :class:`.dask.DaskEngine` on a
Dask cluster, whose task calls :func:`grade_one`. Both grade each submission in a grading process of its
own (:class:`.processes.Job`), and stop starting them when the temporary or output folder runs low on
space (:func:`.processes.low_space`), reporting the rest as not graded, saying why: a resumed run grades them.

The warm helpers, the fork server and the launcher, are started once per local run (:func:`warm`), or
kept per thread by a process that grades one submission per call (a Dask worker: :func:`kept`). Either may
be None, switched off (``fork_server=False``) or unable to start: grading then goes the plain way (a
sandbox of its own for every notebook, a new Python for every grading process), slower and as safe.
"""

import atexit
import contextlib
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Generator
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from ..options import GradeOptions
from ..sandbox import backends, forkserver
from ..store.report import SubmissionGrade
from ..store.rubric import Rubric
from .launcher import Launcher
from .processes import Job, low_space, settled


@dataclass(frozen=True)
class Batch:
    """What an engine grades: (path, name) pairs in `todo`, the run's settled `options` and `rubric`, the refusals
    as JSON in `profiles_file`, a `work` folder for the grading processes' files, and `out`, whose space is watched."""

    todo: list
    options: GradeOptions
    rubric: Rubric
    profiles_file: Path
    work: Path
    out: Path

    def not_graded(self, name, why):
        """The grade of a submission that could not be graded, saying why."""
        return SubmissionGrade(name, seed=self.options.seed, rubric=self.rubric, failure=why)


@dataclass
class Outcome:
    """One submission's grade, as an engine hands it back, and its grading process's peak memory (bytes, or
    None where it was not measured)."""

    grade: SubmissionGrade
    peak: int | None = None


class Engine(ABC):
    """Grades the submissions of a :class:`Batch`: :meth:`grade`; :meth:`record` says how, for ``run.json``."""

    name = "engine"

    @abstractmethod
    def grade(self, batch: Batch) -> Generator[Outcome, None, None]:
        """One :class:`Outcome` per submission of `batch`, each as soon as it is graded (in any order)."""

    def record(self) -> dict:
        """What ``run.json`` records of the run this engine made (after :meth:`grade`)."""
        return {"engine": self.name}


def grade_one(path, name, options, profiles_file, work):
    """Grade one submission in a grading process of its own (started once more if it breaks); blocks. What a
    Dask task runs (:mod:`.dask`), with this thread's kept fork server and launcher (:func:`kept`).

    Returns plain data: ``{"name", "result": the result file's data or None, "failure": why it could not be
    graded or None, "attempts", "peak": the grading process's peak bytes or None}`` (:func:`.processes.settled`)."""
    server, launcher = kept(options)
    job = Job(path, name, Path(work), options, profiles_file, server, launcher)
    while True:
        job.start()
        job.wait()
        if job.conclude():
            return job.message()


class LocalEngine(Engine):
    """Grade on this machine, `jobs` grading processes at a time (``labkit grade --jobs``), each forked by the
    run's launcher from one warm Python when it can be (:func:`warm`)."""

    name = "local"

    def __init__(self, jobs: int = 2):
        if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
            raise InputError(f"jobs must be a whole number of grading processes, at least 1; got {jobs!r}.")
        self.jobs = jobs
        self._record: dict = {"engine": self.name, "jobs": jobs}

    def record(self) -> dict:
        return dict(self._record)

    def grade(self, batch: Batch) -> Generator[Outcome, None, None]:
        options = batch.options
        with warm(backends.get_backend(options.backend), options) as (server, launcher):
            self._record.update({"fork server": server is not None, "forked grading processes": launcher is not None})
            pending = [
                Job(path, name, batch.work, options, batch.profiles_file, server, launcher) for path, name in batch.todo
            ]
            pending.reverse()
            running: list[Job] = []
            stopped = None
            while pending or running:
                while pending and len(running) < self.jobs and stopped is None:
                    stopped = low_space(batch.out)
                    if stopped is None:
                        job = pending.pop()
                        job.start()
                        running.append(job)
                if stopped is not None and not running:
                    for job in pending:
                        yield Outcome(batch.not_graded(job.name, stopped))
                    return
                time.sleep(0.05)
                for job in list(running):
                    if not job.poll():
                        continue
                    running.remove(job)
                    if not job.conclude():
                        pending.append(job)  # once more, in a fresh process
                        continue
                    message = job.message()
                    yield Outcome(settled(message, batch.rubric, options.seed), message["peak"])


def start_warm(backend, options):
    """(fork server, launcher) for `options`, each None where it is off or cannot start; both start at once."""
    if not options.fork_server:
        return None, None
    try:
        server = forkserver.ForkServer(backend, options.limits).start(wait=False)
    except forkserver.ForkServerError:
        server = None
    try:
        launcher = Launcher(options, server, wait=False)
    except (OSError, ValueError):
        launcher = None
    if server is not None:
        try:
            server.wait_ready()
        except forkserver.ForkServerError:
            server = None
    if launcher is not None:
        try:
            launcher.wait_ready()
        except OSError:
            launcher = None
    return server, launcher


def stop_warm(server, launcher):
    for thing in (launcher, server):
        if thing is not None:
            thing.stop()


@contextlib.contextmanager
def warm(backend, options):
    """The run's fork server and launcher (:func:`start_warm`), stopped at the end."""
    server, launcher = start_warm(backend, options)
    try:
        yield server, launcher
    finally:
        stop_warm(server, launcher)


_KEPT: dict = {}  # (backend, limits, exercises, thread) -> (fork server, launcher) kept (a Dask worker's)
_KEPT_LOCK = threading.Lock()


def kept(options):
    """The fork server and launcher this process keeps for :func:`.engines.grade_one` (a Dask worker grades one
    submission per task): started on first use, started again if they died, stopped when the process
    ends; (None, None) with ``fork_server`` off or where they cannot start."""
    if not options.fork_server:
        return None, None
    # one pair per thread: a worker's threads never stop each other's, and the pair dies with its thread
    # (the sandbox and the launcher are set to die with the thread that started them)
    key = (options.backend, options.limits, options.exercises, threading.get_ident())
    with _KEPT_LOCK:
        found = _KEPT.get(key)
        server, launcher = found or (None, None)
        died = (server is not None and server.box.process.poll() is not None) or (
            launcher is not None and launcher.process.poll() is not None
        )
        if found is None or died:  # none started yet (or none could be: then none is tried again), or one died
            stop_warm(server, launcher)
            server, launcher = start_warm(backends.get_backend(options.backend), options)
            if key not in _KEPT:
                atexit.register(_stop_kept, key)
            _KEPT[key] = (server, launcher)
        return server, launcher


def _stop_kept(key):
    stop_warm(*_KEPT.pop(key, (None, None)))
