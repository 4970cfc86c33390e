"""Where a class run's submissions are graded: the :class:`Engine` interface and the local engine.

An engine takes a :class:`Batch` and yields one :class:`Outcome` per submission as each is graded, in any order:
:class:`LocalEngine` here, :class:`.dask.DaskEngine` on a Dask cluster. Both grade each submission in a grading
process of its own (:class:`.processes.Job`), and stop starting them when the temporary or output folder runs low on
space (:func:`.processes.low_space`), reporting the rest as not graded, saying why: a resumed run grades them.
"""

import contextlib
import time
from abc import ABC, abstractmethod
from collections.abc import Generator
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from ..options import GradeOptions
from ..sandbox import backends, forkserver
from ..store.report import SubmissionGrade, one_line
from ..store.rubric import Rubric
from .launcher import Launcher
from .processes import Job, low_space


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

    def outcome(self, message):
        """The :class:`Outcome` of a grading process's plain data (:meth:`.processes.Job.message`), scored with the
        rubric; a result that cannot be read (another labkit version's, say) is not graded, saying why."""
        name, peak = message["name"], message.get("peak")
        if message.get("result") is None:
            return Outcome(self.not_graded(name, str(message.get("failure"))), peak)
        try:
            grade = SubmissionGrade.from_dict(message["result"], one_line(name, 80), self.rubric)
        except ValueError as exc:
            return Outcome(self.not_graded(name, f"its result could not be read ({exc})"), peak)
        grade.name = name
        return Outcome(grade, peak)


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


class LocalEngine(Engine):
    """Grade on this machine, `jobs` grading processes at a time (``labkit grade --jobs``), each forked by the
    run's launcher from one warm Python when it can be (:func:`start_warm`)."""

    name = "local"

    def __init__(self, jobs: int = 2):
        if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
            raise InputError(f"jobs must be a whole number of grading processes, at least 1; got {jobs!r}.")
        self.jobs = jobs
        self._record: dict = {"engine": self.name, "jobs": jobs}

    def record(self) -> dict:
        return dict(self._record)

    def grade(self, batch: Batch) -> Generator[Outcome, None, None]:
        server, launcher = start_warm(batch.options)
        self._record.update({"fork server": server is not None, "forked grading processes": launcher is not None})
        try:
            pending = [
                Job(path, name, batch.work, batch.options, batch.profiles_file, server, launcher)
                for path, name in reversed(batch.todo)
            ]
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
                    if job.poll():
                        running.remove(job)
                        if job.conclude():
                            yield batch.outcome(job.message())
                        else:
                            pending.append(job)  # once more, in a fresh process
        finally:
            stop_warm(server, launcher)


def start_warm(options):
    """(fork server, launcher) for `options`, both started at once. Either is None where it is switched off
    (``fork_server=False``) or cannot start: grading then goes the plain way (a sandbox of its own for every notebook,
    a new Python for every grading process), slower and as safe."""
    if not options.fork_server:
        return None, None
    server = launcher = None
    with contextlib.suppress(forkserver.ForkServerError):
        server = forkserver.ForkServer(backends.get_backend(options.backend), options.limits).start(wait=False)
    with contextlib.suppress(OSError, ValueError):
        launcher = Launcher(options, server)
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
