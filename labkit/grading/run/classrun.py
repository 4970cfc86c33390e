"""Grading a class: :func:`grade` plans the run (:mod:`.plan`), runs it on an engine (:mod:`.engines`), and
:class:`RunFolder` writes the run folder: each submission's result and feedback as soon as it is graded, then
``grades.csv`` and ``run.json``, how the run went (its seed, counts, time, engine, peak memory).
"""

import contextlib
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

from ...errors import InputError
from ..options import GradeOptions
from ..progress import Progress
from ..sandbox import timings
from ..store import record as records
from ..store import report as store
from ..store.report import one_line, write_report
from ..store.variants import write_variants
from ..submission import refusals
from .engines import Batch, Engine, LocalEngine
from .plan import Plan, plan
from .processes import peak_bytes
from .resume import carried_marks, clear


def grade(submissions, out_dir, options: GradeOptions | None = None, *, engine: Engine | None = None, progress=True):
    """Grade submissions; write grades.csv, feedback/, results/, seed.txt and the run's record into `out_dir`.

    `submissions` is a :class:`~labkit.grading.run.plan.Submissions`, or the paths alone. `options` (a
    :class:`~labkit.grading.options.GradeOptions`, the defaults when None) bound the run: a seed None is drawn, a
    rubric None is the one an earlier run recorded in `out_dir`, else the lab's; with backend ``"none"`` student
    code runs unconfined, after a warning on stderr. `engine` grades: by default a
    :class:`~labkit.grading.run.engines.LocalEngine` of ``options.jobs`` processes here. `progress` draws a bar
    with an ETA on a terminal. Each submission is graded in a process of its own, so one that crashes, runs out of
    memory or hangs costs only its own grade ("could not be graded", saying why).

    A run into a folder with a run's record resumes it (:func:`~labkit.grading.run.resume.resumed`). Returns the
    grades in the order given (a shard's in name order; the ungradable last), an earlier run's included; those
    with ``graded`` False say why (``failure``).
    """
    if options is None:
        options = GradeOptions()
    if not isinstance(options, GradeOptions):
        raise InputError(f"options must be a GradeOptions (labkit.grading.options); got {options!r}.")
    if engine is None:
        engine = LocalEngine(options.jobs)
    elif not isinstance(engine, Engine):
        raise InputError(f"engine must be a labkit.grading.run.engines.Engine; got {engine!r}.")
    return run(plan(submissions, out_dir, options), engine, progress)


def run(planned: Plan, engine: Engine, progress=True):
    """Run `planned` on `engine`, writing the run folder as each submission arrives; the grades (:class:`Graded`)."""
    folder = RunFolder(planned)
    folder.begin()
    start = time.monotonic()
    graded, peaks = {}, []
    work = Path(tempfile.mkdtemp(prefix="labkit-run-"))
    try:
        profiles_file = work / "profiles.json"
        profiles_file.write_text(json.dumps(refusals.wire(planned.rubric.registry.refusals)), encoding="utf-8")
        batch = Batch(planned.todo, planned.options, planned.rubric, profiles_file, work, planned.out)
        outcomes = contextlib.closing(engine.grade(batch))
        with Progress(len(planned.todo), "grading", enabled=progress) as bar, outcomes as each:
            for outcome in each:
                graded[outcome.grade.name] = outcome.grade
                peaks.append(outcome.peak)
                folder.add(outcome.grade)
                bar.advance()
    finally:
        store.write_timings(planned.out, timings.collect(work))  # where each submission's time went (not feedback)
        shutil.rmtree(work, ignore_errors=True)
    for name, why in planned.ungradable.items():
        graded[name] = batch.not_graded(name, why)
    ordered = [graded[name] if name in graded else planned.earlier.done[name] for name in planned.order]
    for grade in ordered:
        grade.time = planned.when[grade.name]
    summary = {
        "seed": planned.options.seed,
        "submissions": len(ordered),
        "graded now": len(graded) - len(planned.ungradable),
        "already graded": len(planned.earlier.done),
        "graded again, changed": len(planned.earlier.changed),
        "handed in nothing to grade": len(planned.ungradable),
        "shard": None if planned.shard is None else f"{planned.shard[0]}/{planned.shard[1]}",
        "not graded": sum(not g.graded for g in ordered),
        "seconds": round(time.monotonic() - start, 1),
        **engine.record(),
        "grader peak bytes": max((p for p in peaks if p), default=None),
    }
    folder.end(ordered, summary)
    return Graded(ordered, planned.earlier)


class RunFolder:
    """Every write of a class run into its output folder (:mod:`labkit.grading.store`): :meth:`begin` before the
    engine starts, :meth:`add` as each submission is graded (a stopped run resumes from them), :meth:`end`."""

    def __init__(self, planned: Plan):
        self.plan, self.out = planned, planned.out
        self.dropped: list[tuple[str, int]] = []

    def begin(self):
        if self.plan.options.fresh:
            clear(self.out)
        store.prepare(self.out)
        records.write(self.out, self.plan.record)
        store.write_seed(self.out, self.plan.options.seed)

    def add(self, grade):
        grade.time = self.plan.when[grade.name]
        before = self.plan.earlier.earlier.get(grade.name)
        if before is not None and grade.graded:
            grade.marks, lost = carried_marks(before, grade)
            if lost:
                self.dropped.append((grade.name, lost))
        store.enter(self.out, self.plan.record, grade, self.plan.contents.get(grade.name))

    def end(self, grades, summary):
        write_report(self.out, grades, self.plan.record)
        request = self.plan.submissions
        if request.variants is not None:
            students = self.plan.record.variants["students"]
            write_variants(self.out, grades, students, request.roster, self.plan.rubric.registry)
        for name, lost in self.dropped:
            sys.stderr.write(
                f"labkit grade: {one_line(name, 80)}'s notebooks changed; {lost} of the marks given to it no longer "
                "apply (an answer rewritten, a part no longer held): mark them again (labkit mark OUT).\n"
            )
        summary["grader process peak bytes"] = peak_bytes()
        store.write_run(self.out, summary)


class Graded(list):
    """The grades of a run (:func:`grade`), with what it resumed (:attr:`earlier`, a
    :class:`~labkit.grading.run.resume.Resumed`)."""

    def __init__(self, grades, earlier):
        super().__init__(grades)
        self.earlier = earlier


def report_failures(grades):
    """Name every submission that could not be graded (printable, one line each, on stderr); how many there were."""
    failed = [g for g in grades if not g.graded]
    for g in failed:
        sys.stderr.write(f"could not grade {one_line(g.name, 80)}: {one_line(g.failure, 300)}\n")
    return len(failed)
