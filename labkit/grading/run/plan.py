"""A class run's plan: what it grades, with what, and what it takes over, worked out before anything runs.

:func:`plan` turns a :class:`Submissions` (what this run grades: data about one class), the output folder and the
run's :class:`~labkit.grading.options.GradeOptions` (its choices, the same for every submission) into a frozen
:class:`Plan`, reading and never writing: every refusal comes from here, before a file is touched.
"""

import os
import secrets
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from ...errors import InputError
from ..options import GradeOptions
from ..sandbox import backends
from ..store import record as records
from ..store.report import labkit_version, one_line
from ..store.rubric import Rubric
from ..store.rubric import load as load_rubric
from ..submission.scoring import known_sources, submission_name
from .processes import sandbox_problem
from .resume import Resumed, content, notebooks, parse_shard, resumed, shard
from .times import submission_time

if TYPE_CHECKING:
    from ...exercises.variants import VariantsFile


@dataclass(frozen=True)
class Submissions:
    """What one run is asked to grade: each submission (a notebook, or a folder of them) and its name (by default
    its folder's or notebook's); the students who handed in nothing to grade ({name: why}: reported as "could
    not be graded", never given a zero); the LMS's times (``--times``) and those read from nbgrader's exchange
    ({name: datetime}); a roster ({submission name: roster id}) with a variants file
    (:class:`labkit.exercises.variants.VariantsFile`): each submission is graded against its student's own
    data, derived from the roster id (never from the notebook), and one the roster lacks could not be graded."""

    paths: Sequence = ()
    names: Sequence | None = None
    ungradable: Mapping = field(default_factory=dict)
    times: Mapping | None = None
    exchange_times: Mapping | None = None
    roster: Mapping | None = None
    variants: "VariantsFile | None" = None


@dataclass(frozen=True)
class Plan:
    """A class run, worked out (:func:`plan`)."""

    out: Path
    options: GradeOptions  # what every grading process gets: the seed drawn, the rubric's copy, each one's data
    rubric: Rubric  # what the results are scored with
    record: records.RunRecord  # what record.json says as the run starts (the earlier run's, continued)
    order: list  # every name, as grades.csv lists them (a shard's in name order; the ungradable last)
    todo: list  # (path, name) of the submissions the engine grades
    ungradable: dict  # {name: why} of those that cannot be graded
    when: dict  # {name: its submission time or None}
    contents: dict  # {name: its notebooks' digest}, read before any student code runs
    earlier: Resumed  # what the earlier run in `out` leaves to this one
    submissions: Submissions  # as given, its times continued from the earlier run
    shard: tuple | None = None  # (I, N)


def plan(submissions, out_dir, options: GradeOptions) -> Plan:
    """The :class:`Plan` of grading `submissions` (a :class:`Submissions`, or the paths alone) into `out_dir` with
    `options`; ValueError for anything the run would refuse. Reads, never writes."""
    request = submissions if isinstance(submissions, Submissions) else Submissions(tuple(submissions))
    paths, names, ungradable, part = _named(request, options.shard)
    _check_backend(options.backend)
    out = Path(out_dir)
    contents = {name: content(path) for path, name in zip(paths, names)}
    given_rubric = None if options.rubric is None else load_rubric(options.rubric)
    earlier = resumed(out, [*names, *ungradable], options.seed, given_rubric, options.fresh, contents)
    rubric = earlier.rubric
    students = _variants(rubric.registry, names, request, ungradable)
    kept = [(path, name) for path, name in zip(paths, names) if name not in ungradable]
    _check_variants(out, earlier, request.variants, students)
    seed = secrets.randbits(63) if earlier.seed is None else int(earlier.seed)
    if options.exercises not in (None, rubric.registry.source):
        raise InputError(
            f"the options grade the exercises {options.exercises!r} but the rubric grades {rubric.registry.source!r}: "
            'name the course\'s exercises in its rubric (exercises = "module:attribute") and leave the option out.'
        )
    request, options = _continued(request, options, earlier.record)
    known = known_sources(rubric.registry, options.solutions)  # computed (or read from its cache) once, here
    recorded = earlier.record.known.get("digest") if earlier.record is not None else None
    if recorded and earlier.done and recorded != known.digest:
        raise InputError(
            f"{out} was graded against other known sources ({recorded}; now {known.digest}): the solutions given "
            "to --solutions, labkit or scipy changed since, so its held parts would be judged otherwise. Grade "
            "into a new --out, or again with --fresh."
        )
    options = replace(
        options,
        seed=seed,
        exercises=rubric.registry.source,
        rubric=str((out / records.RUBRIC_COPY).resolve()) if rubric.text is not None else options.rubric,
        variants=students if request.variants is not None else None,
    )
    order = [*[name for _, name in kept], *ungradable]
    todo = [(path, name) for path, name in kept if name not in earlier.done]
    record, when = _record(earlier, options, request, known.digest), _times(request, options, kept, ungradable)
    return Plan(out, options, rubric, record, order, todo, ungradable, when, contents, earlier, request, part)


def _named(request, part):
    """(paths, names, {name: why} ungradable, (I, N) or None) of the submissions `request` gives, and of shard
    `part` of them; ValueError for a path that is not a submission, or names that are missing or collide."""
    paths = [Path(s) for s in request.paths]
    for path in paths:
        if not os.path.lexists(path):
            raise InputError(f"{path} does not exist.")
        if not path.is_symlink() and path.is_file() and path.suffix != ".ipynb":
            raise InputError(f"{path} is not a notebook: give .ipynb files or folders of them.")
    names = [submission_name(p) for p in paths] if request.names is None else [str(n) for n in request.names]
    if len(names) != len(paths):
        raise InputError(f"{len(names)} names for {len(paths)} submissions; give one name per submission.")
    ungradable = dict(request.ungradable or {})
    every = names + list(ungradable)
    if len(set(every)) != len(every):
        raise InputError("two submissions have the same name; their feedback files would collide.")
    if part is None:
        return paths, names, ungradable, None
    part = parse_shard(part)
    chosen = set(shard(every, *part))
    by_name = dict(zip(names, paths))
    names = sorted(name for name in names if name in chosen)
    ungradable = {name: why for name, why in sorted(ungradable.items()) if name in chosen}
    return [by_name[name] for name in names], names, ungradable, part


def _check_backend(name):
    """ValueError when the sandbox backend `name` cannot run here; its warning (``none``'s) on stderr."""
    problem = sandbox_problem(name)
    if problem is not None:
        raise InputError(f"cannot grade in a sandbox: {problem}")
    warning = backends.get_backend(name).warning()
    if warning:
        sys.stderr.write(warning)


def _variants(registry, names, request, ungradable):
    """{name: {exercise (text): {parameter: value}}} of the submissions the roster names; the others go into
    `ungradable` with the reason. Empty without variants; ValueError for a roster without variants or the reverse."""
    roster, variants = request.roster, request.variants
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


def _check_variants(out, earlier, variants, students):
    """ValueError when the run resumed was graded with another variants file, or gave a student other data."""
    if earlier.record is None or not earlier.done:
        return
    recorded = earlier.record.variants
    digest = variants.digest if variants is not None else None
    if recorded.get("digest") != digest:
        before = f"with the variants {recorded['digest']}" if recorded else "without variants"
        now = f"with {digest}" if digest else "without"
        raise InputError(
            f"{out} was graded {before}, and now {now}: grade with the same --variants (and --roster) as "
            "before, into a new --out, or again with --fresh."
        )
    given = recorded.get("students", {})
    # a roster entry changed or gone: the result kept would be of other data than the record says
    moved = sorted(name for name in earlier.done if name in given and students.get(name, {}) != given[name])
    if moved:
        raise InputError(
            f"the roster gives {one_line(moved[0], 60)} other data than {out} was graded with (its id changed, "
            "or it left the roster): grade with the roster of that run, into a new --out, or again with --fresh."
        )


def _continued(request, options, record):
    """`request` and `options` with what the earlier run's `record` was given and is not given anew: its times,
    its switches for student-written times, its instructor notebooks."""
    if record is None:
        return request, options
    request = replace(
        request,
        times={**record.given_times("csv"), **(request.times or {})},
        exchange_times={**record.given_times("exchange"), **(request.exchange_times or {})},
    )
    options = replace(
        options,
        times_from_submission=options.times_from_submission or record.flags.get("times from submission", False),
        times_from_mtime=options.times_from_mtime or record.flags.get("times from mtime", False),
        solutions=options.solutions or record.known.get("solutions") or None,  # compared with them again
    )
    return request, options


def _record(earlier, options, request, known):
    """The run's record as it starts: the earlier run's (or a new one) with what this run was given."""
    record = earlier.record or records.new("grade", labkit_version(), options.seed, earlier.rubric)
    students = {**record.variants.get("students", {}), **(options.variants or {})}
    given = (("csv", request.times), ("exchange", request.exchange_times))
    return replace(
        record,
        times={source: {n: when.isoformat() for n, when in sorted(t.items())} for source, t in given if t},
        flags={
            "times from submission": bool(options.times_from_submission),
            "times from mtime": bool(options.times_from_mtime),
        },
        known={"digest": known, "solutions": options.solutions},
        variants={} if request.variants is None else {"digest": request.variants.digest, "students": students},
    )


def _times(request, options, kept, ungradable):
    """{name: its submission time} (:func:`labkit.grading.run.times.submission_time`)."""
    times, mtime, exchange = request.times, options.times_from_mtime, request.exchange_times
    how = {"from_submission": options.times_from_submission, "exchange": exchange}
    when = {
        name: submission_time(path, name, times, notebooks(path) if mtime else None, mtime, **how)
        for path, name in kept
    }
    return when | {name: submission_time(None, name, times, exchange=exchange) for name in ungradable}
