"""Grading a class: :func:`grade` plans the run (:mod:`.plan`), runs it on an engine, and writes the run folder.

:func:`grade` takes the run's :class:`~labkit.grading.options.GradeOptions`, built
once by its caller (the ``labkit grade`` command, or a script), and works the run
out first, touching nothing (:func:`.plan.plan`: the sandbox checked, an earlier
run resumed, the seed drawn, the students' data and times read). Then
:func:`run` hands the submissions still to grade to an engine (:mod:`.engines`:
a few grading processes at a time here, or on a Dask cluster), so a submission
that makes its grading crash, run out of memory or hang costs only its own
grade: its process is started once more, and if that fails too it is reported
as "could not be graded" with the reason. :class:`RunFolder` does every write:
each submission's ``results/<name>.json`` and feedback as soon as it is graded,
entered in the run's record; then ``grades.csv`` with every submission once,
and ``run.json`` (its seed, how many could not be graded, its time, the
engine's record, the grader's peak memory for one submission). A progress bar
with an ETA is drawn on a terminal (:mod:`..progress`).
"""

import contextlib
import csv
import json
import resource
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
from ..store.report import SubmissionGrade, csv_cell, one_line, write_report, write_result
from ..submission import refusals
from .engines import Batch, Engine, LocalEngine
from .plan import Plan, plan
from .resume import carried_marks, clear


def grade(submissions, out_dir, options: GradeOptions | None = None, *, engine: Engine | None = None, progress=True):
    """Grade submissions; write grades.csv, feedback/, results/, seed.txt and the run's record into `out_dir`.

    `submissions` is a :class:`~labkit.grading.run.plan.Submissions` (the paths with their names, the students
    who handed in nothing to grade, the times the LMS gave, a roster and variants file), or the paths alone.
    `options` (a :class:`~labkit.grading.options.GradeOptions`, the defaults when None) bound the run: its
    time and memory limits, its sandbox backend (``"none"``: student code runs unconfined, after a warning on
    stderr), its seed (a fresh one is drawn and written to ``seed.txt`` when it is None), its rubric (a TOML
    file; else the rubric recorded in `out_dir` by an earlier run, else the lab's), its shard (``"I/N"``: the
    I-th of N parts of the class, :func:`~labkit.grading.run.resume.shard`), and which student-written times
    count (:func:`labkit.grading.store.late.submission_time`).

    `engine` (an :class:`~labkit.grading.run.engines.Engine`) grades the submissions: by default a
    :class:`~labkit.grading.run.engines.LocalEngine` of ``options.jobs`` grading processes at a time here; a
    :class:`~labkit.grading.run.dask.DaskEngine` sends them to a Dask cluster. `progress` draws a bar with an
    ETA on a terminal.

    When `out_dir` already holds a run's record, only the submissions without a result there, or whose
    notebooks changed since, are graded, with that run's seed and rubric
    (:func:`~labkit.grading.run.resume.resumed`); ``options.fresh`` deletes those results first. Returns the
    grades in the order given (a shard's in name order; the ungradable last), those of an earlier run
    included; those with ``graded`` False could not be graded (their ``failure`` says why).
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
    graded, peaks = _on(engine, planned, progress, folder.add)
    for name, why in planned.ungradable.items():
        graded[name] = SubmissionGrade(name, seed=planned.options.seed, rubric=planned.rubric, failure=why)
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


def _on(engine, planned, progress, arrived):
    """({name: grade}, [peak bytes]) of the submissions `engine` graded, each handed to `arrived` as it came."""
    work = Path(tempfile.mkdtemp(prefix="labkit-run-"))
    graded, peaks = {}, []
    try:
        profiles_file = work / "profiles.json"
        profiles_file.write_text(json.dumps(refusals.wire(planned.rubric.registry.refusals)), encoding="utf-8")
        batch = Batch(planned.todo, planned.options, planned.rubric, profiles_file, work, planned.out)
        outcomes = contextlib.closing(engine.grade(batch))
        with Progress(len(planned.todo), "grading", enabled=progress) as bar, outcomes as each:
            for outcome in each:
                graded[outcome.grade.name] = outcome.grade
                peaks.append(outcome.peak)
                arrived(outcome.grade)
                bar.advance()
    finally:
        timings.collect(work, planned.out)  # where each submission's grading time went (never in its feedback)
        shutil.rmtree(work, ignore_errors=True)
    return graded, peaks


class RunFolder:
    """Every write of a class run into its output folder (:mod:`labkit.grading.store`): :meth:`begin` before the
    engine starts, :meth:`add` as each submission is graded (a stopped run resumes from them), :meth:`end`."""

    def __init__(self, planned: Plan):
        self.plan, self.out = planned, planned.out
        self.dropped: list[tuple[str, int]] = []

    def begin(self):
        if self.plan.options.fresh:
            clear(self.out)
        for folder in ("results", "feedback"):
            (self.out / folder).mkdir(parents=True, exist_ok=True)  # an empty shard's folder is a run's too
        records.write(self.out, self.plan.record)
        (self.out / "seed.txt").write_text(f"{self.plan.options.seed}\n", encoding="utf-8")

    def add(self, grade):
        grade.time = self.plan.when[grade.name]
        before = self.plan.earlier.earlier.get(grade.name)
        if before is not None and grade.graded:
            grade.marks, lost = carried_marks(before, grade)
            if lost:
                self.dropped.append((grade.name, lost))
        written = write_result(self.out, grade)
        records.note(self.out, self.plan.record, grade.name, written, self.plan.contents.get(grade.name))

    def end(self, grades, summary):
        write_report(self.out, grades, self.plan.record)
        request = self.plan.submissions
        if request.variants is not None:
            students = self.plan.record.variants["students"]
            _write_variants(self.out, grades, students, request.roster, self.plan.rubric.registry)
        for name, lost in self.dropped:
            sys.stderr.write(
                f"labkit grade: {one_line(name, 80)}'s notebooks changed; {lost} of the marks given to it no longer "
                "apply (an answer rewritten, a part no longer held): mark them again (labkit mark OUT).\n"
            )
        summary["grader process peak bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        (self.out / "run.json").write_text(json.dumps(summary, indent=1), encoding="utf-8")


VARIANTS_CSV = "variants.csv"


def _write_variants(out, grades, students, roster, registry):
    """``variants.csv``, for the instructor only: each submission's roster id and data, and the classmates
    whose data its notebooks hold instead (``another variant`` when no one in the class has them)."""
    varied = [e for e in registry if e.params]
    rows = []
    for grade in grades:
        mine = students.get(grade.name)
        if mine is None:
            continue
        holds = []
        for exercise in varied:
            other = (grade.results.get(exercise.number) or {}).get("other_variant") or {}
            if not other:
                continue
            params = {p.name: p for p in exercise.params}
            whose = [
                name
                for name, data in students.items()
                if name != grade.name
                and all(
                    param in params and params[param].holds(found, data.get(str(exercise.number), {}).get(param))
                    for param, (found, _) in other.items()
                )
            ]
            holds.append(f"exercise {exercise.number}: " + (", ".join(whose) if whose else "another variant"))
        shown = [", ".join(f"{p} = {v}" for p, v in mine.get(str(e.number), {}).items()) for e in varied]
        rows.append([grade.name, roster.get(grade.name, ""), *shown, "; ".join(holds)])
    with open(Path(out) / VARIANTS_CSV, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["submission", "id", *(f"exercise {e.number}" for e in varied), "holds the data of"])
        for row in rows:
            writer.writerow([csv_cell(cell) for cell in row])


class Graded(list):
    """The grades of a run (:func:`grade`), with what it resumed (:attr:`earlier`, a
    :class:`~labkit.grading.run.resume.Resumed`)."""

    def __init__(self, grades, earlier):
        super().__init__(grades)
        self.earlier = earlier


def report_failures(grades, stream=None):
    """Name every submission that could not be graded (printable, one line each, on stderr by default); how many
    there were."""
    stream = sys.stderr if stream is None else stream
    failed = [g for g in grades if not g.graded]
    for g in failed:
        stream.write(f"could not grade {one_line(g.name, 80)}: {one_line(g.failure, 300)}\n")
    return len(failed)
