"""The run folder: the store is the one reader and writer of everything a run keeps there.

Layout of an output folder::

    grades.csv               one row per submission (:func:`write_csv`): points per exercise, branch, extra
                             credit, total under the rubric; with a [late] table the time, lateness and penalty
    feedback/<name>.txt      the student's feedback (labkit.grading.store.feedback); .html the same as one page
    results/<name>.json      the same grade as data (:class:`~.grade.SubmissionGrade`), read by :func:`read_results`
    seed.txt, run.json       the seed of the run's random test data; how the run went (:func:`write_run`)
    record.json, rubric.toml the run's record: rubric, seed, version, each result's hash (labkit.grading.store.record)
    merge.json               (labkit merge only) the folders merged and the results a later one replaced

``labkit grade`` writes through :func:`enter` and the ``write_*`` functions, ``labkit merge`` is :func:`merge`,
``labkit mark`` is :func:`.marks.import_marks`; each file is replaced whole (:func:`.record.replace_text`).
Nothing in a run folder comes from a student's process but plain numbers and short texts, and those are data:
a name becomes a file name through :func:`safe_name`, every text is stripped of control characters
(:func:`printable`), and every CSV cell a spreadsheet would run as a formula is neutralised (:func:`csv_cell`).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import re
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from . import feedback as feedbacks
from . import record as records
from . import rubric as rubrics
from .feedback import HELD_STEP, problem_kinds  # noqa: F401 - where the scoring and the class report find them
from .grade import FORMAT, ProblemText, SubmissionGrade, labkit_version  # noqa: F401 - where callers find them
from .late import FROM_CSV, Lateness, SubmissionTime, time_text
from .model import ItemKey
from .record import replace_text
from .text import CONTROL, one_line, points_text, printable  # noqa: F401 - printable where callers find it

FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def safe_name(name):
    """A submission's name as a file name: safe characters, at most 60 of them, and a hash of the whole name,
    so two students never share a file ("jane doe" and "jane_doe" differ)."""
    readable = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._-")[:60] or "submission"
    return f"{readable}-{hashlib.sha256(str(name).encode('utf-8', 'surrogatepass')).hexdigest()[:10]}"


PLAIN_NAME = re.compile(r"^(?!.*-[0-9a-f]{10}$)[A-Za-z0-9][A-Za-z0-9._-]{0,59}$")


def file_stem(name: str) -> str:
    """The name of a submission's feedback files: its own name when it is a plain file name (letters, digits,
    ``.``, ``_``, ``-``; at most 60, never ending as a hashed one does), else :func:`safe_name`'s.

    >>> file_stem("lovelaceada"), file_stem("Ada Lovelace_101")
    ('lovelaceada', 'Ada_Lovelace_101-8dd2908744')
    """
    return name if PLAIN_NAME.match(name) else safe_name(name)


def csv_cell(value):
    """A cell a spreadsheet shows as text: one starting like a formula gets a leading apostrophe (OWASP)."""
    text = one_line(value, 500) if isinstance(value, str) else value
    return "'" + text if isinstance(text, str) and text.startswith(FORMULA_START) else text


def name_cell(name):
    """A submission's name as a CSV cell: whole (it is the key: labkit.grading.store.names), with an apostrophe
    before a start a spreadsheet would run as a formula and control characters spelled ``\\xNN``.

    >>> name_cell("=1+1 eve"), name_cell("a" * 600) == "a" * 600
    ("'=1+1 eve", True)
    """
    text = CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", str(name))
    return "'" + text if text.startswith(FORMULA_START) else text


def csv_text(rows) -> str:
    """`rows` as CSV text, in the csv module's dialect (its lines end in ``\\r\\n``)."""
    buffer = io.StringIO()
    csv.writer(buffer).writerows(rows)
    return buffer.getvalue()


CSV_TAIL = ["required", "branch", "branch points", "extra credit", "total", "full credit", "status"]
# with a [late] table, between "extra credit" and "total" (which is then the total after the penalty)
CSV_LATE = ["raw total", "submitted", "time source", "deadline", "hours late", "lateness", "penalty"]


def _late_cells(grade: SubmissionGrade, lateness: Lateness) -> list:
    """The cells of CSV_LATE for one graded submission."""
    zone = grade.rubric.late.deadline.tzinfo if grade.rubric.late is not None else None
    time = lateness.time if lateness.known else None
    when = time.when if time is not None else None
    hours = max(lateness.late_by.total_seconds() / 3600, 0.0) if lateness.late_by is not None else None
    return [
        points_text(lateness.raw_total),
        "" if when is None else time_text(when, zone),
        "" if when is None or time is None else csv_cell(time.source),
        time_text(lateness.deadline, zone),
        "" if hours is None else f"{hours:.2f}",
        csv_cell(lateness.note),
        points_text(lateness.penalty),
    ]


CSV_HELD = "held for a person"  # only when a submission of the run has a part held (labkit.grading.submission.known)


def held_text(grade: SubmissionGrade) -> str:
    """grades.csv's cell of held parts: "exercise 2 eval_pherm (labkit.piecewise.eval_pherm, 97%)"; ...."""
    return "; ".join(
        f"exercise {number} {one_line(part, 60)} ({one_line(held.get('source', '?'), 80)}, "
        f"{float(held.get('share', 0)):.0%}{', released' if released else ''})"
        for number, part, held, released in grade.held()
    )


def _csv_row(grade: SubmissionGrade, graded: list, width: int, held: bool, answers: list[ItemKey]) -> list:
    """One submission's row of grades.csv; `width` is the number of cells after its points, `answers` the answers
    in words to read, a column each for the points a person gave (empty until then)."""
    if not grade.graded:
        return (
            [name_cell(grade.name)] + [""] * (len(graded) + width - 1)
            + [csv_cell(f"not graded: {grade.failure}")] + [""] * (held + len(answers))
        )  # fmt: skip
    s, lateness = grade.score, grade.lateness
    return (
        [name_cell(grade.name)]
        + [points_text(s.points[n]) for n in graded]
        + [points_text(s.required), csv_cell(s.branch), points_text(s.counted), points_text(s.extra_total)]
        + (_late_cells(grade, lateness) if lateness is not None else [])
        + [points_text(grade.total), points_text(s.full_credit), "graded"]
        + ([csv_cell(held_text(grade))] if held else [])
        + ["" if key not in grade.marks else points_text(grade.marks[key].points) for key in answers]
    )


def write_csv(path: str | Path, grades: list[SubmissionGrade]) -> None:
    """grades.csv (its columns in the module's docstring); a submission that could not be graded has empty
    points and says why in its status."""
    rubric = grades[0].rubric if grades else None
    graded = rubric.graded if rubric is not None else []
    answers = rubric.registry.answers.items() if rubric is not None else ()
    to_read = {
        ItemKey.of_answer(grade_id): f"to read: exercise {n}, {what}" for grade_id, (n, what) in answers if n in graded
    }
    tail = CSV_TAIL[:4] + CSV_LATE + CSV_TAIL[4:] if rubric is not None and rubric.late is not None else CSV_TAIL
    held = any(g.graded and g.held() for g in grades)
    header = ["submission"] + [f"exercise {n}" for n in graded] + tail + [CSV_HELD] * held + list(to_read.values())
    rows = [_csv_row(g, graded, len(tail), held, list(to_read)) for g in grades]
    replace_text(Path(path), csv_text([header, *rows]))


def prepare(out_dir: str | Path) -> None:
    """The run folder's results/ and feedback/ (an empty shard's folder is a run's too)."""
    for folder in ("results", "feedback"):
        (Path(out_dir) / folder).mkdir(parents=True, exist_ok=True)


def enter(out_dir: str | Path, record: records.RunRecord, grade: SubmissionGrade, content=None, save=True) -> None:
    """Write `grade`'s results/<name>.json and feedback/<name>.txt and .html, and enter the result in the run's
    `record` (:func:`.record.note`), which is written too unless `save` is False (the caller writes it)."""
    out = Path(out_dir)
    prepare(out)
    model, stem = feedbacks.build(grade), file_stem(grade.name)
    replace_text(out / "feedback" / f"{stem}.txt", feedbacks.text(model))
    replace_text(out / "feedback" / f"{stem}.html", feedbacks.html(model))
    path, text = out / "results" / f"{safe_name(grade.name)}.json", json.dumps(grade.as_dict(), indent=1)
    replace_text(path, text)
    records.note(record, grade.name, path, text, content)
    if save:
        records.write(out, record)


def write_report(out_dir: str | Path, grades: list[SubmissionGrade], record: records.RunRecord | None = None):
    """Write grades.csv plus each submission's result and feedback files, each entered in the run's `record` (a new
    one of the grades' rubric and seeds when None), which is written too; the record."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if record is None:
        rubric = grades[0].rubric if grades else rubrics.default()
        seeds = sorted({g.seed for g in grades if g.seed is not None})
        seed = None if not seeds else seeds[0] if len(seeds) == 1 else seeds  # several seeds: a merge's grades
        record = records.new("merge" if isinstance(seed, list) else "grade", labkit_version(), seed, rubric)
    for grade in grades:
        enter(out, record, grade, record.submissions.get(grade.name, {}).get("content"), save=False)
    records.write(out, record)
    write_csv(out / "grades.csv", grades)
    return record


def write_seed(out_dir: str | Path, seeds: int | list[int] | None) -> None:
    """seed.txt: the run's seed (a merge's seeds), one a line."""
    seeds = seeds if isinstance(seeds, list) else [] if seeds is None else [seeds]
    replace_text(Path(out_dir) / "seed.txt", "".join(f"{s}\n" for s in seeds))


def write_timings(out_dir: str | Path, found: dict) -> None:
    """timings.json: where each submission's grading time went, by phase (only when something was measured)."""
    if found:
        replace_text(Path(out_dir) / "timings.json", json.dumps(found, indent=1))


def write_run(out_dir: str | Path, summary: dict) -> None:
    """run.json: how the run went (its seed, counts, time and the engine's record)."""
    replace_text(Path(out_dir) / "run.json", json.dumps(summary, indent=1))


@dataclass(frozen=True)
class Replaced:
    """A submission's result file that a later folder's replaced in a merge, and whether the later result kept
    the earlier one's submission time (it had none)."""

    name: str
    earlier: Path
    later: Path
    time_kept: bool = False


class Merged(list):
    """Grades read from output folders, in name order, with the results a later folder replaced
    (:attr:`replaced`) and the result files that were not read (:attr:`refused`: (path, why) pairs)."""

    def __init__(self, grades, replaced=(), refused=(), rubric=None):
        super().__init__(grades)
        self.replaced = tuple(replaced)
        self.refused = tuple(refused)
        self.rubric = rubric


def _folders(folders) -> list[Path]:
    """The folders to read, each a folder and given once."""
    folders = [Path(folder) for folder in folders]
    given = set()
    for folder in folders:
        if not folder.is_dir():
            raise InputError(f"{folder} is not a folder: give the --out folder of a `labkit grade` run.")
        if folder.resolve() in given:
            raise InputError(f"{folder} is given twice; give each folder once.")
        given.add(folder.resolve())
    return folders


def _vouched(folder: Path, rubric: rubrics.Rubric) -> records.RunRecord:
    """`folder`'s record, when its labkit and rubric are this one's and `rubric`."""
    record = records.read(folder)
    if record.labkit != labkit_version():
        raise InputError(
            f"{folder} was graded by labkit {one_line(record.labkit, 40)}, and this is labkit "
            f"{labkit_version()}: results of another version are not mixed in (its checks may grade "
            "differently); grade those submissions again with this version."
        )
    recorded = record.rubric_object(folder)
    if recorded.digest != rubric.digest:
        raise InputError(
            f"{folder} was graded under the rubric {recorded.title!r} ({recorded.digest}), not "
            f"{rubric.title!r} ({rubric.digest}): results of different rubrics (their exercises, groups or "
            "points) are not merged. Grade again with the --rubric of the class's run; the [late] table may "
            "differ, as labkit merge applies the one it is given."
        )
    return record


def read_results(folders, rubric: rubrics.Rubric | None = None) -> Merged:
    """Every result of the output `folders` that their run records vouch for, in name order, scored with `rubric`
    (their recorded one when None).

    A submission in several folders counts from the last, keeping the earlier time when the later result has none
    (each replacement is listed in ``replaced``). A result file a record does not name with that hash is
    never read but listed in ``refused``. InputError when a folder has no record or is given twice, none has
    results, they come from another labkit, or their rubrics differ from each other or from `rubric` in exercises,
    groups or points (their ``[late]`` tables may differ: `rubric`'s applies).
    """
    folders = _folders(folders)
    if rubric is None:
        rubric = records.rubric_for(folders, None, "reading these folders")
    grades: dict[str, SubmissionGrade] = {}
    files: dict[str, Path] = {}
    refused: list = []
    replaced: list[Replaced] = []
    for folder in folders:
        found, bad = records.results(folder, _vouched(folder, rubric))
        refused += bad
        for name in sorted(found):
            path, data = found[name]
            grade = SubmissionGrade.from_dict(data, str(path), rubric)
            if data.get("rubric digest") != rubric.digest:
                refused.append((path, "it was scored under another rubric than its run's record"))
                continue
            earlier = grades.get(grade.name)
            if earlier is not None:
                kept = grade.time is None and earlier.time is not None
                if kept:
                    grade.time = earlier.time
                replaced.append(Replaced(grade.name, files[grade.name], path, kept))
            grades[grade.name], files[grade.name] = grade, path
    if not grades:
        what = "no result their records vouch for" if refused else "no results (only empty shards)"
        raise InputError(
            f"{', '.join(map(str, folders))} hold {what}: give the --out folders of earlier `labkit grade` runs."
        )
    return Merged([grades[name] for name in sorted(grades)], replaced, refused, rubric)


def _merged_record(read: list[records.RunRecord], grades: Merged) -> records.RunRecord:
    """The record of a merge of the folders whose records are `read`: their seeds, known sources, deliveries and
    variants as one, a later folder's students replacing an earlier one's."""
    record = records.new(
        "merge", labkit_version(), sorted({g.seed for g in grades if g.seed is not None}), grades.rubric
    )
    record.known = {
        key: " ".join(sorted({r.known.get(key) or "" for r in read} - {""})) or None for key in ("digest", "solutions")
    }
    layouts = {r.delivery.get("layout") for r in read if r.delivery}
    if len(layouts) == 1:  # none when the runs came in different layouts
        students = {name: key for r in read for name, key in r.delivery.get("students", {}).items()}
        record.delivery = {"layout": layouts.pop(), "students": students}
    drawn = {r.variants.get("digest") for r in read}
    if drawn != {None}:
        students = {name: data for r in read for name, data in r.variants.get("students", {}).items()}
        record.variants = {"digest": drawn.pop(), "students": students}
    return record


def merge(folders, out_dir, rubric=None, times=None, progress=False) -> Merged:
    """Combine the results of several grading runs' `folders` (batch jobs, say, or a run and a regrade) into the
    new folder `out_dir` as :func:`read_results` reads them, scored with `rubric` (a Rubric or a TOML path; None:
    the recorded one), whose ``[late]`` table applies. `times` ({name: datetime},
    :func:`labkit.grading.run.times.read_times`) replace the stored times of the submissions they name. The grades,
    with the results a later folder replaced (also in ``merge.json``) and the files not merged.
    """
    from ..progress import Progress

    out = Path(out_dir)
    if out.resolve() in {Path(folder).resolve() for folder in folders}:
        raise InputError(f"{out} is one of the folders merged; write the merge into a new folder (--out).")
    if rubric is not None and not isinstance(rubric, rubrics.Rubric):
        rubric = rubrics.load(rubric)
    read = [records.read(folder) for folder in folders]
    if len({r.variants.get("digest") for r in read}) > 1:
        raise InputError(
            "the folders were graded with different variants (or some without): each student's data would differ "
            "from one result to the next. Merge only runs graded with the same --variants file."
        )
    grades = read_results(folders, rubric)
    contents = {name: entry.get("content") for r in read for name, entry in r.submissions.items()}
    record = _merged_record(read, grades)
    with Progress(len(grades), "merging", enabled=progress) as bar:
        for grade in grades:  # each scored with grades.rubric already (read_results)
            if times and grade.name in times:
                grade.time = SubmissionTime(times[grade.name], FROM_CSV)
            enter(out, record, grade, contents.get(grade.name), save=False)  # makes `out`
            bar.advance()
    records.write(out, record)
    write_csv(out / "grades.csv", grades)
    write_seed(out, record.seed)
    merged = {
        "folders": [str(folder) for folder in folders],
        "replaced": [
            {"submission": r.name, "earlier": str(r.earlier), "later": str(r.later), "time kept": r.time_kept}
            for r in grades.replaced
        ],
        "not merged": [{"file": str(path), "why": why} for path, why in grades.refused],
    }
    replace_text(out / "merge.json", json.dumps(merged, indent=1))
    return grades
