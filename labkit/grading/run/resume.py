"""What a run into an output folder takes over from the one before it there (:func:`resumed`, :func:`carried_marks`),
and which part of a class it grades (:func:`shard`, for batch systems; ``labkit merge`` combines the parts).
"""

from dataclasses import dataclass, field
from pathlib import Path

from ...errors import InputError
from ..store import record as records
from ..store.model import ItemKey
from ..store.report import SubmissionGrade, labkit_version, one_line
from ..store.rubric import DEFAULT as DEFAULT_RUBRIC
from ..store.rubric import Rubric
from ..store.rubric import default as default_rubric
from ..submission.scoring import submission_notebooks


def content(path):
    """The digest of a submission's notebooks (:func:`labkit.grading.store.record.content_digest`); `path` a Path."""
    return records.content_digest(notebooks(path), path if path.is_dir() else path.parent)


def notebooks(path):
    """The submission's notebooks, or none when it has none to offer."""
    try:
        return submission_notebooks(path)
    except ValueError:
        return []


@dataclass
class Resumed:
    """What an earlier run into the same output folder leaves to this one (:func:`resumed`)."""

    done: dict  # {name: SubmissionGrade} kept: graded there, and its notebooks unchanged since
    seed: object  # the seed to grade with (the earlier run's), or None
    rubric: Rubric  # the rubric to grade with (the earlier run's, when none was given)
    record: object = None  # the earlier run's RunRecord, which this run goes on writing, or None
    changed: list = field(default_factory=list)  # the names graded there whose notebooks changed since
    refused: list = field(default_factory=list)  # (path, why) of result files its record does not vouch for
    # {name: its earlier grade} of the changed submissions: the marks a person gave them carry over where they apply
    earlier: dict = field(default_factory=dict)


def resumed(out, names, seed, rubric=None, fresh=False, contents=None):
    """What the earlier run in `out` leaves to this one: a :class:`Resumed`. Reads, never writes.

    The submissions graded there are kept unless their notebooks' digest differs from `contents` ({name: digest})
    or they could not be graded; the others are graded with the earlier run's seed and rubric, which `seed` and
    `rubric` (None: the recorded one) may repeat but not change. Another labkit version's folder, a merge's, results
    without a record, or a result of a name not in `names` are refused, saying what to do. With `fresh` nothing is
    kept (:func:`clear` deletes it)."""
    out = Path(out)
    files = sorted((out / "results").glob("*.json")) if (out / "results").is_dir() else []
    if fresh or not (out / records.RECORD).exists():
        if files and not fresh:
            raise InputError(
                f"{out} holds results but no run record ({records.RECORD}; an older labkit wrote none): give "
                "--fresh to grade every submission again there, or choose a new --out."
            )
        return Resumed({}, seed, rubric if rubric is not None else default_rubric())
    how = "give --fresh to grade every submission again, or choose a new --out"
    record = records.read(out)
    if record.kind != "grade":
        raise InputError(
            f"{out} holds a merge ({records.RECORD} says so), which is not resumed: grade into a new --out, or {how}."
        )
    if record.labkit != labkit_version():
        raise InputError(
            f"{out} was graded by labkit {one_line(record.labkit, 40)}, and this is labkit {labkit_version()}: "
            f"{how} with this version."
        )
    recorded = record.rubric_object(out)
    if rubric is None:
        rubric = recorded
    elif differ := recorded.differences(rubric):
        raise InputError(
            f"{out} was graded under the rubric recorded there ({recorded.title!r}), and {rubric.source} differs "
            f"from it in {' and '.join(differ)}: leave --rubric out to resume that run. "
            f"To grade under {rubric.source}, {how}; to apply only another [late] or [held] table to these results, "
            f"`labkit merge {out} --rubric {_file_of(rubric)} --out NEW`."
        )
    if seed is not None and record.seed is not None and int(seed) != int(record.seed):
        raise InputError(
            f"{out} holds results of a run with seed {record.seed}, not --seed {seed}: leave --seed out to resume "
            f"it, {how}."
        )
    stray = sorted(set(record.submissions) - set(names))
    if stray:
        raise InputError(
            f"{out} holds the result of {one_line(stray[0], 80)!r}, which is not among the submissions of this "
            "run: give the submissions (and --shard) of the run that wrote it to resume it, give --fresh to grade "
            "only these, or choose a new --out."
        )
    found, refused = records.results(out, record)
    done, before = {}, {}
    for name, (path, data) in found.items():
        grade = SubmissionGrade.from_dict(data, str(path), rubric)  # ValueError: another labkit version's
        if not grade.graded:
            continue
        if contents is not None and record.submissions[name].get("content") != contents.get(name):
            before[name] = grade
        else:
            done[name] = grade
    seed = record.seed if record.seed is not None else seed
    return Resumed(done, seed, rubric, record, sorted(before), refused, earlier=before)


def clear(out):
    """Delete the results, feedback and record of the run in the folder `out` (a Path; ``--fresh``)."""
    for folder, pattern in (("results", "*.json"), ("feedback", "*.txt"), ("feedback", "*.html")):
        for path in sorted((out / folder).glob(pattern)):
            path.unlink()
    for name in (records.RECORD, records.RUBRIC_COPY):
        (out / name).unlink(missing_ok=True)


def carried_marks(earlier, grade):
    """The marks of `earlier` (a submission's grade before its notebooks changed) that still apply to its new
    `grade`: an answer's while its text is the same, a held part's while it is still held, an exercise's
    excuse always; and how many no longer apply."""
    kept, dropped = {}, 0
    held = {ItemKey.held(number, part) for number, part, _, _ in grade.held()}
    for item, mark in earlier.marks.items():
        if item.kind == "answer":
            same = str(earlier.answers.get(item.answer, "")) == str(grade.answers.get(item.answer, ""))
        else:
            same = item.kind == "exercise" or item in held
        if same:
            kept[item] = mark
        else:
            dropped += 1
    return kept, dropped


def _file_of(rubric):
    """The TOML file a rubric was read from, for a command to show (the lab's own when it names none)."""
    source = Path(str(rubric.source))
    return source if source.suffix == ".toml" else DEFAULT_RUBRIC


def parse_shard(spec):
    """``(I, N)`` from ``"I/N"`` (or a pair): the I-th of N parts, counted from 1; ValueError says how to write it.

    >>> parse_shard("3/50")
    (3, 50)
    """
    how = "give --shard I/N with 1 <= I <= N, e.g. 3/50 for the third of 50 parts (a Slurm array: --array=1-50)"
    try:
        index, count = spec.split("/") if isinstance(spec, str) else spec
        index, count = int(index), int(count)
    except (TypeError, ValueError):
        raise InputError(f"{how}; got {one_line(spec, 40)!r}.") from None
    if not 1 <= index <= count:
        raise InputError(f"{how}; got {index}/{count}.")
    return index, count


def shard(names, index, count):
    """The `index`-th (from 1) of `count` parts of `names` (as :func:`parse_shard` checks them), in name order:
    every name is in exactly one part, the parts' sizes differ by at most one, and with more parts than names some
    are empty.

    >>> [shard(["d", "a", "c", "b", "e"], i, 2) for i in (1, 2)]
    [['a', 'b'], ['c', 'd', 'e']]
    >>> shard(["a"], 2, 3)
    []
    """
    index, count = parse_shard((index, count))
    ordered = sorted(names)
    return ordered[(index - 1) * len(ordered) // count : index * len(ordered) // count]
