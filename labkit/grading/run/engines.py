"""Where a class run's submissions are graded: the :class:`Engine` interface, and the local engine.

An engine takes a :class:`Batch` (the submissions still to grade, the run's
options, rubric and refusals) and yields one :class:`Outcome` per submission
as each is graded, in any order; the class run (:mod:`.classrun`) writes each
result as it arrives. :class:`LocalEngine`, the default, grades them here, a
few grading processes at a time; :class:`labkit.grading.run.dask.DaskEngine`
sends them to a Dask cluster. Both grade a submission the same way, in a
grading process of its own (:class:`.processes.Job`); a Dask task calls
:func:`grade_one`. Both stop starting submissions when the temporary or
output folder runs low on space (:func:`.processes.low_space`) and report the
rest as not graded, saying why: a resumed run grades them.
"""

import time
from abc import ABC, abstractmethod
from collections.abc import Generator
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from ..options import GradeOptions
from ..sandbox import backends
from ..store.report import SubmissionGrade
from ..store.rubric import Rubric
from .processes import Job, low_space, settled
from .warm import kept, warm


@dataclass(frozen=True)
class Batch:
    """What an engine grades: the (path, name) pairs in `todo`, with the run's `options` (its seed drawn, its
    rubric the run record's copy) and `rubric`; `profiles_file` holds the refusals as JSON
    (:func:`labkit.grading.submission.refusals.wire`), `work` is a folder for the grading processes' files, and `out`
    the output folder, whose free space is watched."""

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
    """Grade one submission in a grading process of its own (started once more if it breaks); blocks.

    What a Dask task runs (:mod:`.dask`); the local engine runs the same steps (:class:`.processes.Job`) a few
    at a time. `options` is the run's :class:`GradeOptions` (its seed drawn), `profiles_file` the refusals as
    JSON, `work` a folder for the process's files. Returns plain data: ``{"name", "result": the result file's
    data or None, "failure": why it could not be graded or None, "attempts", "peak": the grading process's peak
    memory in bytes or None}``; :func:`.processes.settled` makes a :class:`SubmissionGrade` of it under a
    rubric. The fork server and launcher are this thread's, kept between calls (:func:`.warm.kept`)."""
    server, launcher = kept(options)
    job = Job(path, name, Path(work), options, profiles_file, server, launcher)
    while True:
        job.start()
        job.wait()
        if job.conclude():
            return job.message()


class LocalEngine(Engine):
    """Grade on this machine, `jobs` grading processes at a time (``labkit grade --jobs``), each forked by the
    run's launcher from one warm Python when it can be (:mod:`.warm`)."""

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
