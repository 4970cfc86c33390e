"""Grading a class: :func:`grade`, every submission in a grading process of its own, by an engine.

:func:`grade` takes the run's :class:`~labkit.grading.options.GradeOptions`,
built once by its caller (the ``labkit grade`` command, or a script), checks
the sandbox backend once (:mod:`labkit.grading.sandbox.backends`), resumes an earlier
run into the same output folder (:mod:`.resume`), draws the run's seed (or
takes the one given or recorded), computes what the sandbox refuses once, and
hands the submissions still to grade to an engine (:mod:`.engines`: here, a
few grading processes at a time, or on a Dask cluster). So a submission that
makes its grading crash, run out of memory or hang costs only its own grade:
its process is started once more, and if that fails too the submission is
reported as "could not be graded" with the reason, while every other
submission is graded as usual.

Each submission's time (for a rubric's ``[late]`` table) is read here, on the
grader's side (:func:`labkit.grading.run.times.submission_time`), and saved with
its result, so that ``labkit merge`` can apply a late rule later. Each
submission's ``results/<name>.json`` and feedback are written as soon as it
is graded, and entered in the run's record; the output folder always gets a
``grades.csv`` with every submission once, and ``run.json`` says how the run
went (its seed, how many could not be graded, its time, the engine's record,
the grader's peak memory for one submission). A progress bar with an ETA is
drawn on a terminal (:mod:`.progress`).
"""

import contextlib
import json
import os
import resource
import secrets
import shutil
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from ...errors import InputError
from ..options import GradeOptions
from ..progress import Progress
from ..sandbox import backends, timings
from ..sandbox.backends.base import SandboxUnavailable
from ..store import record as records
from ..store import report as run_folder
from ..store.report import SubmissionGrade, labkit_version, one_line, write_report
from ..store.rubric import load as load_rubric
from ..submission import refusals
from ..submission.scoring import known_sources, submission_name
from .engines import Batch, Engine, LocalEngine
from .resume import carried_marks, content, notebooks, parse_shard, resumed, shard_of
from .times import submission_time


def grade(
    submissions,
    out_dir,
    options: GradeOptions | None = None,
    *,
    jobs: int = 2,
    engine: Engine | None = None,
    progress: bool = True,
    names=None,
    ungradable=None,
    shard=None,
    fresh: bool = False,
    times=None,
    exchange_times=None,
    times_from_submission: bool = False,
    times_from_mtime: bool = False,
    roster=None,
    variants=None,
):
    """Grade submissions; write grades.csv, feedback/, results/, seed.txt and the run's record into `out_dir`.

    `options` (a :class:`~labkit.grading.options.GradeOptions`, the defaults
    when None) bound the run: its time and memory limits, its sandbox backend
    (``"none"``: student code runs unconfined, after a warning on stderr), its
    seed (a fresh one is drawn and written to ``seed.txt`` when it is None) and
    its rubric (a TOML file; else the rubric recorded in `out_dir` by an
    earlier run, else the lab's), which turns the checks' results into grades.
    `names` gives each submission its name (by default its folder's or
    notebook's), and `ungradable` ({name: why}) adds students who handed in
    nothing to grade: they are reported as "could not be graded", never given
    a zero.

    `engine` (an :class:`~labkit.grading.run.engines.Engine`) grades the
    submissions: by default a :class:`~labkit.grading.run.engines.LocalEngine`
    of `jobs` grading processes at a time here; a
    :class:`~labkit.grading.run.dask.DaskEngine` sends them to a Dask cluster.
    `progress` draws a bar with an ETA on a terminal.

    Each submission's time comes from `times` ({name: datetime}, the LMS's
    times in the instructor's ``--times`` file), else from `exchange_times`
    (read by labkit from nbgrader's exchange), else, only with
    `times_from_submission`, from the ``timestamp.txt`` in its folder, else,
    only with `times_from_mtime`, from its notebooks' modification time
    (:func:`labkit.grading.run.times.submission_time`); the last two are written
    by the student and marked "student-supplied" wherever they are shown.

    With `variants` (a :class:`labkit.exercises.variants.VariantsFile`) and
    `roster` ({submission name: roster id}), each submission is graded against
    its student's own data, derived here from the roster id (never from the
    notebook); a submission the roster lacks could not be graded. The run
    records the file's digest and each student's data; resuming it needs the
    same file again.

    Each submission's result and feedback are written as soon as it is
    graded, and entered in ``record.json`` (:mod:`labkit.grading.store.record`).
    When `out_dir` already holds a run's record, only the submissions without
    a result there, or whose notebooks changed since, are graded, with that
    run's seed and rubric (:func:`~labkit.grading.run.resume.resumed`);
    `fresh` deletes those results first. `shard`, ``(I, N)`` or ``"I/N"``,
    grades only the I-th of N parts of the class
    (:func:`~labkit.grading.run.resume.shard`). Returns the grades in the order
    given (a shard's in name order; the ungradable last), those of an earlier
    run included; those with ``graded`` False could not be graded (their
    ``failure`` says why).
    """
    if options is None:
        options = GradeOptions()
    if not isinstance(options, GradeOptions):
        raise InputError(f"options must be a GradeOptions (labkit.grading.options); got {options!r}.")
    if engine is None:
        engine = LocalEngine(jobs)
    elif not isinstance(engine, Engine):
        raise InputError(f"engine must be a labkit.grading.run.engines.Engine; got {engine!r}.")
    submissions = [Path(s) for s in submissions]
    for path in submissions:
        if not os.path.lexists(path):
            raise InputError(f"{path} does not exist.")
        if not path.is_symlink() and path.is_file() and path.suffix != ".ipynb":
            raise InputError(f"{path} is not a notebook: give .ipynb files or folders of them.")
    names = [submission_name(p) for p in submissions] if names is None else [str(n) for n in names]
    if len(names) != len(submissions):
        raise InputError(f"{len(names)} names for {len(submissions)} submissions; give one name per submission.")
    ungradable = dict(ungradable or {})
    every = names + list(ungradable)
    if len(set(every)) != len(every):
        raise InputError("two submissions have the same name; their feedback files would collide.")
    if shard is not None:
        shard = parse_shard(shard)
        chosen = set(shard_of(every, every, shard)[1])
        by_name = dict(zip(names, submissions))
        names = sorted(name for name in names if name in chosen)
        submissions = [by_name[name] for name in names]
        ungradable = {name: why for name, why in sorted(ungradable.items()) if name in chosen}
    backend = backends.get_backend(options.backend)
    try:
        backend.available()
    except SandboxUnavailable as exc:
        raise InputError(f"cannot grade in a sandbox: {exc}") from None
    warning = backend.warning()
    if warning:
        sys.stderr.write(warning)

    out = Path(out_dir)
    # read before any student code runs, as collected
    contents = {name: content(path) for path, name in zip(submissions, names)}
    given_rubric = None if options.rubric is None else load_rubric(options.rubric)
    earlier = resumed(out, [*names, *ungradable], options.seed, given_rubric, fresh, contents)
    done, rubric = earlier.done, earlier.rubric
    students = _variants(rubric.registry, names, roster, variants, ungradable)
    kept = [(path, name) for path, name in zip(submissions, names) if name not in ungradable]
    submissions, names = [path for path, _ in kept], [name for _, name in kept]
    recorded_variants = earlier.record.variants if earlier.record is not None else {}
    if earlier.record is not None and earlier.done:
        digest = variants.digest if variants is not None else None
        if recorded_variants.get("digest") != digest:
            before = f"with the variants {recorded_variants['digest']}" if recorded_variants else "without variants"
            now = f"with {digest}" if digest else "without"
            raise InputError(
                f"{out} was graded {before}, and now {now}: grade with the same --variants (and --roster) as "
                "before, into a new --out, or again with --fresh."
            )
        recorded = recorded_variants.get("students", {})
        moved = sorted(
            name for name in earlier.done if name in recorded and students.get(name, {}) != recorded[name]
        )  # a roster entry changed or gone: the result kept would be of other data than the record says
        if moved:
            raise InputError(
                f"the roster gives {one_line(moved[0], 60)} other data than {out} was graded with (its id changed, "
                "or it left the roster): grade with the roster of that run, into a new --out, or again with --fresh."
            )
    seed = secrets.randbits(63) if earlier.seed is None else int(earlier.seed)
    if options.exercises not in (None, rubric.registry.source):
        raise InputError(
            f"the options grade the exercises {options.exercises!r} but the rubric grades {rubric.registry.source!r}: "
            'name the course\'s exercises in its rubric (exercises = "module:attribute") and leave the option out.'
        )
    solutions = options.solutions
    if earlier.record is not None:  # the times an earlier run was given count again, unless given anew
        times = {**earlier.record.given_times("csv"), **(times or {})}
        exchange_times = {**earlier.record.given_times("exchange"), **(exchange_times or {})}
        times_from_submission = times_from_submission or earlier.record.flags.get("times from submission", False)
        times_from_mtime = times_from_mtime or earlier.record.flags.get("times from mtime", False)
        if solutions is None and earlier.record.known.get("solutions"):  # compared with them again
            solutions = earlier.record.known["solutions"]
    known = known_sources(rubric.registry, solutions)  # computed (or read from its cache) once, here
    recorded = earlier.record.known.get("digest") if earlier.record is not None else None
    if recorded and earlier.done and recorded != known.digest:
        raise InputError(
            f"{out} was graded against other known sources ({recorded}; now {known.digest}): the solutions given "
            "to --solutions, labkit or scipy changed since, so its held parts would be judged otherwise. Grade "
            "into a new --out, or again with --fresh."
        )
    handed_in = [
        submission_time(
            path,
            name,
            times,
            notebooks(path) if times_from_mtime else None,
            times_from_mtime,
            from_submission=times_from_submission,
            exchange=exchange_times,
        )
        for path, name in zip(submissions, names)
    ]
    run_folder.prepare(out)
    record = earlier.record or records.new("grade", labkit_version(), seed, rubric)
    record.times = {
        source: {name: when.isoformat() for name, when in sorted((given or {}).items())}
        for source, given in (("csv", times), ("exchange", exchange_times))
        if given
    }
    record.flags = {"times from submission": bool(times_from_submission), "times from mtime": bool(times_from_mtime)}
    record.known = {"digest": known.digest, "solutions": solutions}
    record.variants = (
        {"digest": variants.digest, "students": {**recorded_variants.get("students", {}), **students}}
        if variants is not None
        else {}
    )
    records.write(out, record)
    # The options every grading process gets, settled once: the seed drawn, the rubric's exercises loaded
    # there, and the rubric read from the record's copy (the one the results are scored with here).
    options = replace(
        options,
        seed=seed,
        exercises=rubric.registry.source,
        solutions=solutions,
        rubric=str((out / records.RUBRIC_COPY).resolve()) if rubric.text is not None else options.rubric,
        variants=students if variants is not None else None,
    )
    run_folder.write_seed(out, seed)
    when = dict(zip(names, handed_in))
    when.update({name: submission_time(None, name, times, exchange=exchange_times) for name in ungradable})
    todo = [(path, name) for path, name in zip(submissions, names) if name not in done]

    dropped = []

    def arrived(grade):
        """Write a submission's result and feedback as soon as it is graded (a stopped run resumes from them)."""
        grade.time = when[grade.name]
        if grade.name in earlier.earlier and grade.graded:
            grade.marks, lost = carried_marks(earlier.earlier[grade.name], grade)
            if lost:
                dropped.append((grade.name, lost))
        run_folder.enter(out, record, grade, contents.get(grade.name))

    work = Path(tempfile.mkdtemp(prefix="labkit-run-"))
    start, peaks, graded = time.monotonic(), [], {}
    try:
        profiles_file = work / "profiles.json"
        profiles_file.write_text(json.dumps(refusals.wire(rubric.registry.refusals)), encoding="utf-8")
        batch = Batch(todo, options, rubric, profiles_file, work, out)
        outcomes = contextlib.closing(engine.grade(batch))
        with Progress(len(todo), "grading", enabled=progress) as bar, outcomes as each:
            for outcome in each:
                graded[outcome.grade.name] = outcome.grade
                peaks.append(outcome.peak)
                arrived(outcome.grade)
                bar.advance()
    finally:
        timings.collect(work, out)  # where each submission's grading time went (never in its feedback)
        shutil.rmtree(work, ignore_errors=True)
    for name, why in ungradable.items():
        graded[name] = SubmissionGrade(name, seed=seed, rubric=rubric, failure=why)
    ordered = [graded[name] if name in graded else done[name] for name in [*names, *ungradable]]
    for grade in ordered:
        grade.time = when[grade.name]
    write_report(out, ordered, record)
    if variants is not None:
        _write_variants(out, ordered, record.variants["students"], roster, rubric.registry)
    for name, lost in dropped:
        sys.stderr.write(
            f"labkit grade: {one_line(name, 80)}'s notebooks changed; {lost} of the marks given to it no longer "
            "apply (an answer rewritten, a part no longer held): mark them again (labkit mark OUT).\n"
        )
    run_folder.write_run(
        out,
        {
            "seed": seed,
            "submissions": len(ordered),
            "graded now": len(graded) - len(ungradable),
            "already graded": len(done),
            "graded again, changed": len(earlier.changed),
            "handed in nothing to grade": len(ungradable),
            "shard": None if shard is None else f"{shard[0]}/{shard[1]}",
            "not graded": sum(not g.graded for g in ordered),
            "seconds": round(time.monotonic() - start, 1),
            **engine.record(),
            "grader peak bytes": max((p for p in peaks if p), default=None),
            "grader process peak bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
        },
    )
    return Graded(ordered, earlier)


def _variants(registry, names, roster, variants, ungradable):
    """{name: {exercise (text): {parameter: value}}} of the submissions a roster names; the others go into
    `ungradable` with the reason. Empty without variants; ValueError for a roster without variants or the reverse."""
    if (roster is None) != (variants is None):
        raise InputError("give both --roster and --variants to grade each student against their own data, or neither.")
    if variants is None:
        return {}
    found = {}
    for name in names:
        if name not in roster:
            ungradable[name] = (
                "no roster entry, so its data cannot be worked out: add the submission to the roster (the "
                "columns submission and id) and grade again."
            )
            continue
        values = variants.values(registry, roster[name])
        found[name] = {str(number): dict(given) for number, given in values.items()}
    return found


VARIANTS_CSV = "variants.csv"


def _write_variants(out, grades, students, roster, registry):
    """``variants.csv``, for the instructor only: each submission's roster id and data, and the classmates
    whose data its notebooks hold instead (``another variant`` when no one in the class has them)."""
    import csv

    from ..store.report import csv_cell

    varied = [e for e in registry if e.params]
    rows = []
    for grade in grades:
        mine = students.get(grade.name)
        if mine is None:
            continue
        holds = []
        for exercise in varied:
            other = getattr(grade.results.get(exercise.number), "other_variant", {})
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
