"""What grading writes: a submission's grade, its feedback text, its JSON, grades.csv, and merging.

Layout of an output folder::

    grades.csv               one row per submission: points per exercise, the branch that
                             counted, the extra credit, the total (under the rubric); with a
                             [late] table also the raw total, the time, the lateness and penalty
    feedback/<name>.txt      the total, the exercises' points, what failed in the student's words and its
                             hint, the errors of cells the student changed; .html the same as one page
    results/<name>.json      the same grade as data: merged by ``labkit merge``
    seed.txt                 the seed of the run's random test data
    record.json, rubric.toml the run's record: rubric, seed, version, each result's hash (labkit.grading.store.record)
    merge.json               (labkit merge only) the folders merged and the results a later one replaced

Every file here is written by the grader from its own results; nothing in
it comes from a student's process but plain numbers and short texts, and
those are data: a submission's name becomes a file name through
:func:`safe_name` (a hash keeps two students apart), every text is stripped
of control characters (:func:`printable`) before it reaches a file or a
terminal, and every CSV cell that a spreadsheet would run as a formula is
neutralised (:func:`csv_cell`).
"""

import csv
import functools
import hashlib
import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import InputError
from ...exercises.result import KINDS
from . import feedback as feedbacks
from . import record as records
from . import rubric as rubrics
from .feedback import HELD_STEP, problem_kinds  # noqa: F401 - HELD_STEP for the grader's scoring
from .late import FROM_CSV, SubmissionTime, time_text
from .text import CONTROL, MAX_SOURCE_CHARS, one_line, points_text, printable

FORMAT = "labkit-grade/3"  # 3: a problem's kinds as codes ("problem_kinds"), a failed step's in its "kind"
OLD_FORMATS = ("labkit-grade/1", "labkit-grade/2")  # refused with a message to grade again (SubmissionGrade.from_dict)


class ProblemText(str):
    """A problem of a submission: its text as the feedback shows it, and its ``kinds``, the codes of what went
    wrong (:data:`labkit.exercises.result.KINDS`), set where the problem is made: (kind, one-line
    description) pairs, one per thing that went wrong (each cell that raised, say). The class report reads the
    kinds, never the words.

    Examples
    --------
    >>> p = ProblemText("a.ipynb: it stopped.", [("crash", "a.ipynb: it stopped.")])
    >>> p, p.kinds
    ('a.ipynb: it stopped.', (('crash', 'a.ipynb: it stopped.'),))
    >>> ProblemText("a.ipynb: it stopped.", [("stopped", "?")])
    Traceback (most recent call last):
    ...
    labkit.errors.InputError: a problem's kind is one of 'not done', 'raised', 'refused', 'timeout', 'crash', \
'tampered', 'other', 'another variant', not 'stopped'.
    """

    kinds: tuple

    def __new__(cls, text, kinds):
        self = super().__new__(cls, text)
        pairs = []
        for kind, description in kinds:
            if kind not in KINDS:
                raise InputError(f"a problem's kind is one of {', '.join(map(repr, KINDS))}, not {kind!r}.")
            pairs.append((str(kind), str(description)))
        self.kinds = tuple(pairs)
        return self

    @classmethod
    def one(cls, text, kind):
        """A problem of one kind, described by its first line."""
        return cls(text, [(kind, str(text).split("\n")[0])])


@dataclass
class SubmissionGrade:
    """The checks' results for one submission, and its grade under a rubric."""

    name: str
    results: dict = field(default_factory=dict)  # exercise -> grade dict from Registry.check
    problems: list = field(default_factory=list)  # what went wrong while running, per notebook
    seed: int | None = None
    rubric: rubrics.Rubric = field(default_factory=rubrics.default, repr=False, compare=False)
    failure: str | None = None  # why the submission could not be graded at all (then it has no points, not zero)
    answers: dict = field(default_factory=dict)  # grade id -> the student's answer in words, for the instructor
    time: SubmissionTime | None = (
        None  # when it was handed in (labkit.grading.store.late), None when no source had a time
    )
    # graded function -> the source of its definition (printable, at most MAX_SOURCE_CHARS), for the similarity
    # search (labkit.grading.reports.similarity); never part of the grade
    sources: dict = field(default_factory=dict)
    # item -> what a person marked (labkit.grading.reports.marking): {"points": number or "excused"/"counted"/"release"/
    # "keep", "comment": text, "time": ISO time}; items are answer grade ids, "exerciseN" and "exerciseN/part"
    marks: dict = field(default_factory=dict)

    @property
    def graded(self):
        return self.failure is None

    def released(self, number, part):
        """Whether the held `part` of exercise `number` is paid: a person's mark (``exerciseN/part``, release or
        keep) decides, else the rubric's ``[held] release`` table."""
        mark = self.marks.get(f"exercise{number}/{part}")
        if mark is not None:
            return mark.get("points") == "release"
        return self.rubric.releases(self.name, number)

    @property
    def excused(self):
        """The exercises a person excused: out of this submission's total and full credit."""
        return frozenset(
            int(item[len("exercise") :])
            for item, mark in self.marks.items()
            if "/" not in item and "-" not in item and mark.get("points") == "excused"
        )

    @property
    def marked(self):
        """Exercise -> the points a person gave its answers in words."""
        found = {}
        for grade_id, (number, _) in self.rubric.registry.answers.items():
            mark = self.marks.get(grade_id)
            if mark is not None and isinstance(mark.get("points"), (int, float)):
                found[number] = found.get(number, 0.0) + float(mark["points"])
        return found

    @property
    def fractions(self):
        """The share of each exercise's weight that its parts earned, with the held parts released."""
        found = {}
        for number, verdict in self.results.items():
            fraction = float(verdict.get("fraction", 0.0))
            checks = verdict.get("checks", [])
            total = sum(check.get("weight", 0) for check in checks)
            held = sum(
                check.get("weight", 0)
                for check in checks
                if check.get("held") and check.get("passed") and self.released(number, check.get("name"))
            )
            fraction = min(1.0, fraction + held / total) if total else fraction
            found[number] = fraction
        return found

    def held(self):
        """(exercise, part, what it matched, whether it is released) of each part held for a person."""
        return [
            (number, check["name"], check["held"], self.released(number, check["name"]))
            for number, verdict in sorted(self.results.items())
            for check in verdict.get("checks", [])
            if check.get("held") and check.get("passed")
        ]

    @property
    def score(self):
        return self.rubric.score(self.fractions, self.marked, self.excused)

    @property
    def points(self):
        """Points per graded exercise under the rubric."""
        return self.score.points

    @property
    def lateness(self):
        """What the rubric's late rule makes of this submission (:class:`labkit.grading.store.late.Lateness`), or None
        when the rubric has no ``[late]`` table or the submission could not be graded."""
        if self.rubric.late is None or not self.graded:
            return None
        return self.rubric.late.assess(self.name, self.time, self.score.total)

    @property
    def raw_total(self):
        """The points under the rubric before any late penalty."""
        return self.score.total

    @property
    def total(self):
        """The points under the rubric, less the late penalty when the rubric has a ``[late]`` table."""
        lateness = self.lateness
        return self.score.total if lateness is None else lateness.total

    def feedback(self):
        """The feedback text a student reads: the total first (labkit.grading.store.feedback)."""
        return feedbacks.text(feedbacks.build(self))

    def _summary(self):
        score, rubric = self.score, self.rubric
        lines = [
            f"Exercises {', '.join(map(str, rubric.required))}: {points_text(score.required)} / "
            f"{points_text(sum(rubric.worth(n) for n in rubric.required if n not in self.excused))}"
        ]
        if score.branch == "none":
            lines.append("Branch that counts: none yet (no exercise of either branch earned points)")
        elif score.branch:
            full = sum(rubric.worth(n) for n in next(b for b in rubric.branches if b.name == score.branch).exercises)
            lines.append(
                f"Branch that counts: {score.branch}, {points_text(score.counted)} / {points_text(full)} "
                "(the better of the branches)"
            )
        for what, value in score.extra.items():
            lines.append(f"Extra credit, {what}: {points_text(value)}")
        lateness = self.lateness
        if lateness is not None:
            lines += rubric.late.feedback(lateness)
            if lateness.penalty:
                lines.append(
                    f"Total: {points_text(lateness.total)} ({points_text(score.total)} less "
                    f"{points_text(lateness.penalty)} for late work; full credit is {points_text(score.full_credit)})"
                )
                return "\n".join(lines)
        lines.append(f"Total: {points_text(score.total)} (full credit is {points_text(score.full_credit)})")
        return "\n".join(lines)

    def as_dict(self):
        score = self.score
        late = {}
        if self.lateness is not None:
            late = {"raw total": score.total, "late": self.lateness.note, "penalty": self.lateness.penalty}
        return {
            "format": FORMAT,
            "labkit": labkit_version(),
            "rubric digest": self.rubric.digest,
            "submitted": None if self.time is None else self.time.as_dict(),
            "name": self.name,
            "seed": self.seed,
            "problems": [str(p) for p in self.problems],
            "problem_kinds": [[list(pair) for pair in problem_kinds(p)] for p in self.problems],
            "failure": self.failure,
            "answers": dict(self.answers),
            "sources": dict(self.sources),
            "marks": dict(self.marks),
            "results": {str(n): v for n, v in self.results.items()},
            "rubric": self.rubric.title,
            "points": {str(n): v for n, v in score.points.items()},
            "branch": score.branch,
            "extra_credit": score.extra,
            **late,
            "total": self.total,
        }

    @classmethod
    def from_dict(cls, data, source="a result file", rubric=None):
        """Read back what :meth:`as_dict` wrote (scored again with `rubric`); ValueError names the file.

        A result of an earlier format is refused, saying to grade again: ``labkit-grade/2`` kept its problems as
        words only, and guessing their kinds from the words is what format 3 ended."""
        if isinstance(data, dict) and data.get("format") in OLD_FORMATS:
            raise InputError(
                f"{source} is in the results format {data['format']}, which keeps a problem's words but not its "
                f"kind (a time limit, a crash, an error raised, ...); this labkit reads {FORMAT} only. Grade "
                "those submissions again with this version: `labkit grade` with --fresh, or into a new --out."
            )
        try:
            if data.get("format") != FORMAT:
                raise InputError(f"format is {data.get('format')!r}, not {FORMAT!r}")
            results = {int(n): v for n, v in data["results"].items()}
            for verdict in results.values():
                float(verdict["fraction"])
            grade = cls(
                str(data["name"]),
                results,
                _problems(data["problems"], data["problem_kinds"]),
                data.get("seed"),
                rubric or rubrics.default(),
                data.get("failure"),
                {str(k): str(v)[:4000] for k, v in dict(data.get("answers") or {}).items()},
                sources=_sources(data.get("sources") or {}),  # results written before sources were kept have none
            )
            if grade.failure is not None:
                grade.failure = str(grade.failure)
            grade.time = SubmissionTime.from_dict(data.get("submitted"))
            grade.marks = _marks(data.get("marks") or {})
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{source} is not a labkit grade result ({exc}).") from None
        if data.get("labkit") != labkit_version():
            written = f"labkit {one_line(data['labkit'], 40)}" if data.get("labkit") else "a labkit that did not say"
            raise InputError(
                f"{source} was written by {written}, and this is labkit {labkit_version()}: results of another "
                "version are not mixed in (its checks may grade differently); grade those submissions again "
                "with this version."
            )
        known = grade.rubric.registry.exercises
        if not set(grade.results) <= set(known):
            raise InputError(
                f"{source} grades exercises {sorted(grade.results)}, not {sorted(known)}: "
                "it was written by another version of labkit."
            )
        return grade


def _marks(value):
    """A result file's marks: {item: {"points", "comment", "time"}}; TypeError when they are not."""
    marks = {}
    for item, mark in dict(value).items():
        points = mark["points"]
        if isinstance(points, bool) or not isinstance(points, (int, float, str)):
            raise TypeError(f"the mark of {item!r} has points {points!r}")
        marks[str(item)] = {"points": points, "comment": printable(mark.get("comment", ""))[:2000],
                            "time": str(mark.get("time", ""))}  # fmt: skip
    return marks


def _sources(value):
    """A result file's sources, bounded and printable; TypeError when they are not names and texts."""
    sources = dict(value)
    if not all(isinstance(k, str) and isinstance(v, str) for k, v in sources.items()):
        raise TypeError("its sources are not function names and source texts")
    return {printable(k)[:200]: printable(v)[:MAX_SOURCE_CHARS] for k, v in sources.items()}


def _problems(texts, kinds):
    """A result file's problems, each with its kinds (ValueError when the two lists do not pair up)."""
    if not isinstance(texts, list) or not isinstance(kinds, list) or len(texts) != len(kinds):
        raise InputError("its problems and their kinds do not pair up")
    return [ProblemText(str(text), [(str(k), str(d)) for k, d in pairs]) for text, pairs in zip(texts, kinds)]


def _problem_lines(problem):
    first, *rest = str(problem).split("\n") or [""]
    return [f"! {one_line(first, 1000)}"] + [
        "    " + printable(line).replace("\t", " ")[:1000] if line.startswith(" ") else "    | " + one_line(line, 1000)
        for line in rest[:40]
    ]


FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def safe_name(name):
    """A submission's name as a file name: safe characters, at most 60 of them, and a hash of the whole name,
    so two students never share a file ("jane doe" and "jane_doe" differ)."""
    readable = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._-")[:60] or "submission"
    return f"{readable}-{hashlib.sha256(str(name).encode('utf-8', 'surrogatepass')).hexdigest()[:10]}"


PLAIN_NAME = re.compile(r"^(?!.*-[0-9a-f]{10}$)[A-Za-z0-9][A-Za-z0-9._-]{0,59}$")


def file_stem(name: str) -> str:
    """The name of a submission's feedback files, ``feedback/<stem>.txt`` and ``.html``: the submission's own
    name when it is a plain file name (letters, digits, ``.``, ``_``, ``-``; at most 60), else
    :func:`~labkit.grading.store.report.safe_name`'s, with a hash of the whole name. A plain name never ends
    as a hashed one does, so two submissions never share a file.

    >>> file_stem("lovelaceada"), file_stem("Ada Lovelace_101")
    ('lovelaceada', 'Ada_Lovelace_101-8dd2908744')
    """
    return name if PLAIN_NAME.match(name) else safe_name(name)


def csv_cell(value):
    """A cell a spreadsheet shows as text: one starting like a formula gets a leading apostrophe (OWASP)."""
    text = one_line(value, 500) if isinstance(value, str) else value
    if isinstance(text, str) and text.startswith(FORMULA_START):
        return "'" + text
    return text


def name_cell(name):
    """A submission's name as a CSV cell: whole (it is the key: labkit.grading.store.names), with an apostrophe
    before a start a spreadsheet would run as a formula and control characters spelled ``\\xNN``.

    >>> name_cell("=1+1 eve"), name_cell("a" * 600) == "a" * 600
    ("'=1+1 eve", True)
    """
    text = CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", str(name))
    return "'" + text if text.startswith(FORMULA_START) else text


CSV_TAIL = ["required", "branch", "branch points", "extra credit", "total", "full credit", "status"]
# with a [late] table, between "extra credit" and "total" (which is then the total after the penalty)
CSV_LATE = ["raw total", "submitted", "time source", "deadline", "hours late", "lateness", "penalty"]


@functools.cache
def labkit_version():
    """The installed labkit's version, recorded in every result file ("0+unknown" in a tree never installed)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("labkit")
    except PackageNotFoundError:
        return "0+unknown"


def _late_cells(grade, lateness):
    """The cells of CSV_LATE for one graded submission."""
    zone = grade.rubric.late.deadline.tzinfo
    when = lateness.time.when if lateness.known else None
    hours = max(lateness.late_by.total_seconds() / 3600, 0.0) if lateness.known else None
    return [
        points_text(lateness.raw_total),
        "" if when is None else time_text(when, zone),
        "" if when is None else csv_cell(lateness.time.source),
        time_text(lateness.deadline, zone),
        "" if hours is None else f"{hours:.2f}",
        csv_cell(lateness.note),
        points_text(lateness.penalty),
    ]


CSV_HELD = "held for a person"  # only when a submission of the run has a part held (labkit.grading.submission.known)


def held_text(grade):
    """grades.csv's cell of held parts: "exercise 2 eval_pherm (labkit.piecewise.eval_pherm, 97%)"; ...."""
    return "; ".join(
        f"exercise {number} {one_line(part, 60)} ({one_line(held.get('source', '?'), 80)}, "
        f"{float(held.get('share', 0)):.0%}{', released' if released else ''})"
        for number, part, held, released in grade.held()
    )


def read_columns(graded, registry):
    """One empty column per answer in words of the graded exercises, for the instructor to fill in."""
    return [f"to read: exercise {number}, {what}" for number, what in registry.answers.values() if number in graded]


def _read_ids(graded, registry):
    """The grade ids of :func:`read_columns`, in their order."""
    return [grade_id for grade_id, (number, _) in registry.answers.items() if number in graded]


def _mark_cell(grade, grade_id):
    """An answer's cell in grades.csv: the points a person gave it, empty until then."""
    mark = grade.marks.get(grade_id)
    return "" if mark is None else points_text(mark["points"])


def write_csv(path, grades):
    """One row per submission: points per exercise, the branch that counted, extra credit, total, status.

    A submission that could not be graded has empty points and says why in its status."""
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        graded = grades[0].rubric.graded if grades else []
        to_read = read_columns(graded, grades[0].rubric.registry if grades else None) if grades else []
        late = bool(grades) and grades[0].rubric.late is not None
        tail = CSV_TAIL[:4] + CSV_LATE + CSV_TAIL[4:] if late else CSV_TAIL
        held = [CSV_HELD] if any(g.graded and g.held() for g in grades) else []
        writer.writerow(["submission"] + [f"exercise {n}" for n in graded] + tail + held + to_read)
        for g in grades:
            if not g.graded:
                writer.writerow(
                    [name_cell(g.name)]
                    + [""] * (len(graded) + len(tail) - 1)
                    + [csv_cell(f"not graded: {g.failure}")]
                    + [""] * (len(held) + len(to_read))
                )
                continue
            s = g.score
            lateness = g.lateness
            writer.writerow(
                [name_cell(g.name)]
                + [points_text(s.points[n]) for n in graded]
                + [points_text(s.required), csv_cell(s.branch), points_text(s.counted), points_text(s.extra_total)]
                + (_late_cells(g, lateness) if lateness is not None else [])
                + [points_text(g.total), points_text(s.full_credit), "graded"]
                + ([csv_cell(held_text(g))] if held else [])
                + [_mark_cell(g, grade_id) for grade_id in _read_ids(graded, g.rubric.registry)]
            )


def write_result(out_dir, grade):
    """results/<name>.json and feedback/<name>.txt of one submission, each replaced whole (a run killed while
    writing leaves the earlier file or none, never half of one); the result file and the SHA-256 of what was
    written (:class:`labkit.grading.store.record.Written`), for the run's record."""
    out = Path(out_dir)
    for folder in ("results", "feedback"):
        (out / folder).mkdir(parents=True, exist_ok=True)
    _write_feedback(out / "feedback", grade)
    path = out / "results" / f"{safe_name(grade.name)}.json"
    text = json.dumps(grade.as_dict(), indent=1)
    _replace(path, text)
    return records.Written(path, hashlib.sha256(text.encode("utf-8")).hexdigest())


def _write_feedback(folder, grade):
    """feedback/<submission>.txt and .html (labkit.grading.store.feedback)."""
    model, stem = feedbacks.build(grade), file_stem(grade.name)
    _replace(folder / f"{stem}.txt", feedbacks.text(model))
    _replace(folder / f"{stem}.html", feedbacks.html(model))


def _replace(path, text):
    partial = path.with_name(f".{path.name}.partial")
    partial.write_text(text, encoding="utf-8")
    os.replace(partial, path)


def write_report(out_dir, grades, record=None):
    """grades.csv plus each submission's result and feedback files, each entered in the run's `record`
    (:mod:`labkit.grading.store.record`; a new one of the grades' rubric and seeds when None), which is
    written too."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if record is None:
        rubric = grades[0].rubric if grades else rubrics.default()
        seed = _seed_of(grades)  # grades of several seeds are a merge's
        record = records.new("merge" if isinstance(seed, list) else "grade", labkit_version(), seed, rubric)
    for grade in grades:
        written = write_result(out, grade)
        content = record.submissions.get(grade.name, {}).get("content")
        records.note(out, record, grade.name, written, content, save=False)
    records.write(out, record)
    write_csv(out / "grades.csv", grades)
    return record


def _seed_of(grades):
    """The seed of a run's grades: one number, the list of them (a merge's), or None when none has one."""
    seeds = sorted({g.seed for g in grades if g.seed is not None})
    return None if not seeds else seeds[0] if len(seeds) == 1 else seeds


def _merged_delivery(deliveries):
    """The merged runs' delivery records (labkit.grading.lms.delivery) as one, a later run's students
    replacing an earlier one's; none when the runs came in different layouts."""
    layouts = {d.get("layout") for d in deliveries if d}
    if len(layouts) != 1:
        return {}
    students: dict = {}
    for delivery in deliveries:
        students.update(delivery.get("students", {}))
    return {"layout": layouts.pop(), "students": students}


@dataclass(frozen=True)
class Replaced:
    """A submission's result that a later folder's result replaced in a merge.

    Attributes
    ----------
    name : str
        The submission.
    earlier, later : pathlib.Path
        The result file replaced, and the one that counts.
    time_kept : bool
        Whether the later result had no submission time and kept the earlier one's.
    """

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

    def refused_lines(self):
        """One printable line per result file that was not read, and why."""
        return [f"not read: {one_line(path, 200)}: {one_line(why, 300)}" for path, why in self.refused]


def read_results(folders, rubric=None, replaced=None):
    """Every result of the given output folders that their run records vouch for, in name order, scored with
    `rubric` (their recorded rubric when None; :mod:`labkit.grading.store.record`).

    A submission with a result in several folders counts from the last of them, in the order given (a
    regrade replaces the class's result); a later result without a submission time keeps the earlier one's.
    Each replacement is appended to `replaced` (a list) when it is given. A result file that a folder's record
    does not name with that hash (its run never graded that submission, or the file changed since) is never
    read: it is listed in the returned :class:`Merged`'s ``refused``. ValueError when a folder has no record,
    no folder has results, a folder is given twice, the results come from another labkit version, or the
    folders' rubrics differ from each other or from `rubric` in their exercises, groups or points (the
    ``[late]`` table may differ when `rubric` is given: it is the one applied)."""
    folders = [Path(folder) for folder in folders]
    given = set()
    for folder in folders:
        if not folder.is_dir():
            raise InputError(f"{folder} is not a folder: give the --out folder of a `labkit grade` run.")
        if folder.resolve() in given:
            raise InputError(f"{folder} is given twice; give each folder once.")
        given.add(folder.resolve())
    if rubric is None:
        rubric = records.rubric_for(folders, None, "reading these folders")
    grades, files, refused = {}, {}, []
    for folder in folders:
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
        found, bad = records.results(folder, record)
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
                if replaced is not None:
                    replaced.append(Replaced(grade.name, files[grade.name], path, kept))
            grades[grade.name], files[grade.name] = grade, path
    if not grades:
        what = "no result their records vouch for" if refused else "no results (only empty shards)"
        raise InputError(
            f"{', '.join(map(str, folders))} hold {what}: give the --out folders of earlier `labkit grade` runs."
        )
    return Merged([grades[name] for name in sorted(grades)], replaced or (), refused, rubric)


def merge(folders, out_dir, rubric=None, times=None, progress=False):
    """Combine the results of several grading runs (e.g. one per batch job, or a class's run and a regrade)
    into one output folder, scored with `rubric` (the folders' recorded rubric when None).

    Parameters
    ----------
    folders : list of path-like
        The ``--out`` folders of earlier runs. A submission in several of them counts from the last one
        (:func:`read_results`); a result file a folder's record does not vouch for is never merged.
    out_dir : path-like
        The merged output folder (not one of `folders`).
    rubric : Rubric or path-like, optional
        Scores every result, and its ``[late]`` table applies to the submission times they carry; its
        exercises, groups and points must be the folders' own.
    times : dict, optional
        {submission name: datetime} (:func:`labkit.grading.store.late.read_times`): these times replace the
        stored ones of the submissions they name.
    progress : bool
        Show a progress bar with an ETA on a terminal (:mod:`labkit.grading.progress`).

    Returns
    -------
    Merged
        The grades in name order; its ``replaced`` lists the results a later folder replaced, which
        ``merge.json`` in `out_dir` records as well, and its ``refused`` the result files not merged.
    """
    from ..progress import Progress

    out = Path(out_dir)
    if out.resolve() in {Path(folder).resolve() for folder in folders}:
        raise InputError(f"{out} is one of the folders merged; write the merge into a new folder (--out).")
    if rubric is not None and not isinstance(rubric, rubrics.Rubric):
        rubric = rubrics.load(rubric)
    drawn = {records.read(folder).variants.get("digest") for folder in folders}
    if len(drawn) > 1:
        raise InputError(
            "the folders were graded with different variants (or some without): each student's data would differ "
            "from one result to the next. Merge only runs graded with the same --variants file."
        )
    replaced = []
    grades = read_results(folders, rubric, replaced)
    rubric = grades.rubric
    contents = {}
    for folder in folders:
        for name, entry in records.read(folder).submissions.items():
            contents[name] = entry.get("content")
    for grade in grades:
        if times and grade.name in times:
            grade.time = SubmissionTime(times[grade.name], FROM_CSV)
    out.mkdir(parents=True, exist_ok=True)
    record = records.new("merge", labkit_version(), sorted({g.seed for g in grades if g.seed is not None}), rubric)
    known = [records.read(folder).known for folder in folders]
    record.known = {
        "digest": " ".join(sorted({k.get("digest") or "" for k in known} - {""})) or None,
        "solutions": " ".join(sorted({k.get("solutions") or "" for k in known} - {""})) or None,
    }
    record.delivery = _merged_delivery([records.read(folder).delivery for folder in folders])
    if drawn != {None}:
        students: dict = {}
        for folder in folders:  # a later folder's data replace an earlier one's, as its results do
            students.update(records.read(folder).variants.get("students", {}))
        record.variants = {"digest": drawn.pop(), "students": students}
    with Progress(len(grades), "merging", enabled=progress) as bar:
        for grade in grades:
            grade.rubric = rubric
            records.note(out, record, grade.name, write_result(out, grade), contents.get(grade.name), save=False)
            bar.advance()
    records.write(out, record)
    write_csv(out / "grades.csv", grades)
    (out / "seed.txt").write_text("".join(f"{s}\n" for s in record.seed), encoding="utf-8")
    merged = {
        "folders": [str(folder) for folder in folders],
        "replaced": [
            {"submission": r.name, "earlier": str(r.earlier), "later": str(r.later), "time kept": r.time_kept}
            for r in replaced
        ],
        "not merged": [{"file": str(path), "why": why} for path, why in grades.refused],
    }
    (out / "merge.json").write_text(json.dumps(merged, indent=1), encoding="utf-8")
    return Merged(list(grades), replaced, grades.refused, rubric)
