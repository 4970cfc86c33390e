"""The class report: one self-contained HTML page about a grading run (``labkit report OUT``).

:func:`read` reads a grading run's ``results/`` back (a merged run's too),
:func:`summarise` counts what the class did, and :func:`write` writes
``OUT/report.html``: the distribution of totals (after any late penalty:
``grades.csv``'s ``total``), with a rubric's ``[late]`` table a late view
(who was late, by how much and what it cost, extensions, unknown times and
times the student supplied, :class:`LateSummary`), each exercise's and part's
pass rate, the slips the checks named (most frequent first, with who made
them), the problems (time limits, crashes, cells that raised, refused
references, ...; each read from the kind code the grader set where it made
the failed step or the problem, :data:`labkit.exercises.result.KINDS`, never
from its words), the students with the most failed parts, and pairs of
similar code side by side (:mod:`labkit.grading.reports.similarity`; similarity never
changes a grade, it is for a person to judge). Without pygments, which the
similarity search needs, the page is written all the same and its similar code
section says "not computed", and why.

The page needs nothing but itself: its figures are inline PNG images drawn
with matplotlib's Agg canvas (no pyplot state), its style and its one small
script are inline, and it names no other resource. Everything a submission
could have influenced (its name, a hint that quotes its values, a problem's
text, its code) is data: made printable and bounded in length
(:func:`labkit.grading.store.report.one_line`), then HTML-escaped.
"""

from __future__ import annotations

import base64
import html
import io
import os
import statistics
import tempfile
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field
from datetime import datetime, timedelta
from pathlib import Path

from ...errors import InputError
from ...exercises.result import (
    CRASH,
    HELD,
    NOT_DONE,
    OTHER,
    PASSED,
    RAISED,
    REFUSED,
    SLIP,
    TAMPERED,
    TIMEOUT,
    VARIANT,
    part_kind,
)
from ..store import late as lateness
from ..store.names import shown_name
from ..store.record import rubric_for
from ..store.report import SubmissionGrade, one_line, printable, read_results
from ..store.report import problem_kinds as kinds_of
from ..store.rubric import Rubric
from ..store.text import points_text
from ..submission.known import THRESHOLD
from .copies import Copies, pair_rows
from .copies import find as find_copies
from .similarity import DEFAULT_THRESHOLD, Pair, unavailable

REPORT = "report.html"
MAX_SUBMISSIONS = 20_000  # result files in one folder
MAX_NAME = 80  # characters of a submission's name shown
MAX_TEXT = 300  # characters of a hint, a problem or a failed step shown
MAX_NAMES = 300  # names listed under one slip or problem (then "and N more")
MAX_ROWS = 200  # slips shown (the rarest are counted, not listed)
MAX_TEXTS = 6  # problems shown per student and kind
MOST_FAILED = 10  # students listed under "most failed parts"
MAX_PAIRS = 50  # similar pairs shown side by side
MAX_LINES = 200  # lines of each side of a pair shown
MAX_LINE = 160  # characters of one line of code shown
MAX_LABEL = 64  # characters of a part's label in the list of a student's failed parts
MAX_FAILED_SHOWN = 50  # failed parts listed per student

NOT_GRADED = "not graded"  # a submission whose grading failed (its `failure`): no points, not zero
# what a failed part's steps say became of it, the first kind found winning (no kind at all: a slip)
OUTCOMES = (REFUSED, TAMPERED, TIMEOUT, CRASH, RAISED, OTHER, NOT_DONE)
# the kinds of problem, in the order the page lists them: (heading, what it means)
KINDS = {
    TIMEOUT: ("Time limits", "A cell, a call of a graded function or the whole submission ran past its time limit"),
    CRASH: (
        "Crashes",
        "The notebook's process died (killed, exited, out of memory) or stopped answering the grader",
    ),
    RAISED: ("Errors raised", "A cell of the notebook, or a graded function the grader called, raised an exception"),
    REFUSED: (
        "Refused references",
        "A graded function called, or its source reached for, a reference implementation the exercise switches off",
    ),
    TAMPERED: ("Answers voided", "The notebook interfered with the grader's watch, so none of its answers count"),
    VARIANT: (
        "Another variant's data",
        "The notebook holds data other than its student's variant: copied, or worked on another's notebook",
    ),
    NOT_GRADED: (
        "Could not be graded",
        "The grading itself failed twice; these submissions have no points (not zero) and no other row here",
    ),
    OTHER: (
        "Other problems",
        "A flood of output, a notebook too large to grade, a sandbox that could not start, a fault of a check",
    ),
}


@dataclass(frozen=True)
class ExerciseRate:
    """How the class did on one exercise: of the graded submissions, how many attempted and passed it."""

    exercise: int
    graded: int  # graded submissions
    found: int  # that have the exercise
    attempted: int  # that have something other than stubs in it (a part passed, slipped or met a problem)
    passed: int  # that passed every part

    @property
    def rate(self):
        """The share of the submissions that attempted it which passed it (None when nobody attempted it)."""
        return self.passed / self.attempted if self.attempted else None


@dataclass(frozen=True)
class PartRate:
    """How the class did on one part: what became of it in each graded submission."""

    exercise: int
    part: str
    weight: float
    passed: int
    slipped: int  # failed, with the check's hint
    problem: int  # failed through a problem: a time limit, a crash, an error, a refused reference
    not_done: int  # a stub left as released, or the name not defined
    missing: int  # the submission has no notebook with the exercise

    @property
    def attempted(self):
        return self.passed + self.slipped + self.problem

    @property
    def rate(self):
        """The share of the submissions that attempted the part which passed it (None when nobody did)."""
        return self.passed / self.attempted if self.attempted else None

    @property
    def label(self):
        return f"{self.exercise} {self.part}"


@dataclass(frozen=True)
class Slip:
    """One hint of one part, and the students whose work failed the part with it."""

    exercise: int
    part: str
    hint: str
    students: tuple


@dataclass(frozen=True)
class Problem:
    """What went wrong for one student, of one kind (its texts as the grader worded them)."""

    kind: str
    student: str
    texts: tuple


@dataclass(frozen=True)
class Struggle:
    """A student's failed parts (of the exercises the submission has)."""

    student: str
    total: float
    failed: tuple  # "exercise part" labels of the parts attempted and failed (a slip or a problem)
    not_done: int  # parts left as released or not defined, counted apart


def _student_supplied(time: lateness.SubmissionTime | None) -> bool:
    """Whether a submission's time is the student's own word rather than the instructor's or the LMS's.

    The ``timestamp.txt`` in a submission is written by the student's own process (nbgrader's submit step
    runs as the student), and a notebook's modification time is whatever the student's files say
    (:data:`labkit.grading.store.late.STUDENT_SUPPLIED`); the LMS's ``--times`` and nbgrader's exchange, read by
    labkit itself, are not. The one place that decides it, for the report's late view.

    Examples
    --------
    >>> from labkit.grading.store.late import FROM_CSV, FROM_MTIME, SubmissionTime
    >>> _student_supplied(SubmissionTime(None, FROM_MTIME)), _student_supplied(SubmissionTime(None, FROM_CSV))
    (True, False)
    """
    return time is not None and time.source in lateness.STUDENT_SUPPLIED


@dataclass(frozen=True)
class LateEntry:
    """One graded submission under the rubric's late rule, as the instructor sees it (extensions named)."""

    student: str
    deadline: datetime  # the student's deadline: the rubric's, or their extension
    extended: bool
    submitted: datetime | None  # None when the time is unknown
    source: str | None  # where the time came from (labkit.grading.store.late's FROM_...)
    late_by: timedelta | None  # None when the time is unknown; zero or less when on time
    units: int  # started days or hours counted (0: on time, within the grace, or unknown)
    percent: float  # the penalty in percent of raw_total
    penalty: float  # points off
    raw_total: float  # the points before the penalty
    total: float  # after it: grades.csv's total
    note: str  # what the late rule made of it, as grades.csv says
    student_supplied: bool  # the time is the student's own word (:func:`_student_supplied`)

    @property
    def known(self):
        return self.late_by is not None

    @property
    def late(self):
        """Late past the deadline and its grace (so penalised, unless it had no points)."""
        return self.units > 0


@dataclass(frozen=True)
class LateSummary:
    """The class under the rubric's ``[late]`` table: one :class:`LateEntry` per graded submission."""

    rule: lateness.Late
    entries: tuple  # LateEntry, by name

    @property
    def late(self):
        """The late submissions, latest first."""
        return sorted((e for e in self.entries if e.late), key=lambda e: (-e.late_by, e.student))

    @property
    def on_time(self):
        return [e for e in self.entries if e.known and not e.late]

    @property
    def within_grace(self):
        return [e for e in self.on_time if e.late_by > timedelta(0)]

    @property
    def unknown(self):
        return [e for e in self.entries if not e.known]

    @property
    def extended(self):
        return [e for e in self.entries if e.extended]

    @property
    def student_supplied(self):
        """Submissions whose known time the student supplied (an unknown time is listed as unknown)."""
        return [e for e in self.entries if e.known and e.student_supplied]

    @property
    def penalty(self):
        """Points taken off the class in all."""
        return round(sum(e.penalty for e in self.entries), 2)

    @property
    def unused_extensions(self):
        """Names in ``[late.extensions]`` that no graded submission has (a typo in the rubric?)."""
        names = {e.student for e in self.entries}
        return [name for name, _ in self.rule.extensions if name not in names]


def _late_summary(rubric, graded):
    if rubric.late is None:
        return None
    entries = []
    for grade in sorted(graded, key=lambda g: g.name):
        late = grade.lateness
        time = late.time
        entries.append(
            LateEntry(
                student=grade.name,
                deadline=late.deadline,
                extended=late.extended,
                submitted=time.when if time is not None else None,
                source=time.source if time is not None else None,
                late_by=late.late_by,
                units=late.units,
                percent=late.percent,
                penalty=late.penalty,
                raw_total=late.raw_total,
                total=late.total,
                note=late.note,
                student_supplied=_student_supplied(time),
            )
        )
    return LateSummary(rubric.late, tuple(entries))


@dataclass(frozen=True)
class Held:
    """A part held for a person: its check passed, but its code is mostly a known source's
    (:mod:`labkit.grading.submission.known`); its points count only once the rubric's ``[held]`` table releases them."""

    student: str
    exercise: int
    part: str
    definition: str  # the notebook's definition that matched
    source: str  # what it matched
    share: float
    released: bool
    lines: tuple  # (the student's line, the source's line) pairs


@dataclass
class ClassSummary:
    """Everything the page shows, counted from the grades (see :func:`summarise`)."""

    rubric: Rubric
    totals: dict  # graded submission -> total
    not_graded: dict  # submission -> why
    exercises: list  # ExerciseRate, in the rubric's order
    parts: list  # PartRate, in the declarations' order
    slips: list  # Slip, most frequent first
    problems: dict  # kind -> [Problem], by student
    most_failed: list  # Struggle, most failed parts first
    seeds: list = field(default_factory=list)
    late: LateSummary | None = None  # the late view, when the rubric has a [late] table
    held: list = field(default_factory=list)  # Held: parts held for a person (their code matched a known source)
    copies: Copies | None = None  # whose data, solution markers, each student's graded functions (copies.py)

    @property
    def submissions(self):
        return len(self.totals) + len(self.not_graded)


def read(folder: str | Path, rubric: Rubric | None = None) -> list[SubmissionGrade]:
    """The grades of a grading run's output folder (``labkit grade ... --out OUT``, merged runs too).

    Parameters
    ----------
    folder : str or Path
        The ``--out`` folder of ``labkit grade`` (or of ``labkit merge``).
    rubric : Rubric, optional
        The rubric the run was scored with (the lab's when None).

    Returns
    -------
    list of SubmissionGrade
        In name order.

    Raises
    ------
    ValueError
        If the folder does not exist or holds no results, a result file is not a regular file or is too
        large, a result is not labkit's (another version wrote it, or it grades exercises the rubric's
        course does not have), or the results were scored under another rubric than `rubric`.

    Examples
    --------
    >>> read("no/such/folder")
    Traceback (most recent call last):
    ...
    labkit.errors.InputError: no/such/folder is not a folder: give the --out folder of a `labkit grade` run.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder} is not a folder: give the --out folder of a `labkit grade` run.")
    if (folder / "results").is_dir() and len(os.listdir(folder / "results")) > MAX_SUBMISSIONS:
        raise InputError(
            f"{folder / 'results'} holds more than {MAX_SUBMISSIONS:,} result files, more than a class report "
            "shows: split the class and report on each part."
        )
    # the run's record gives the rubric (a different one is refused) and vouches for each result file
    grades = read_results([folder], rubric_for([folder], rubric, "the class report"))
    return grades


def check_outcome(check: dict) -> str:
    """What became of one part in one submission: ``"passed"``, ``"slip"``, ``"not done"`` or a problem's kind.

    Parameters
    ----------
    check : dict
        One entry of an exercise's ``checks`` in a result: ``name``, ``passed``, ``hint``, ``steps`` (a
        failed step that is not a slip has its ``kind``, :data:`labkit.exercises.result.KINDS`).

    Returns
    -------
    str
        ``"passed"``; ``"slip"`` (the check named what is wrong); ``"not done"`` (a stub or a missing
        name); or one of the problem kinds ``"timeout"``, ``"crash"``, ``"raised"``, ``"refused"``,
        ``"tampered"``, ``"other"`` (a fault of the check itself).

    Examples
    --------
    >>> check_outcome({"passed": False, "hint": "h", "steps": [{"step": "s", "passed": False,
    ...     "detail": "not implemented yet", "kind": "not done"}]})
    'not done'
    >>> check_outcome({"passed": False, "hint": "h", "steps": [{"step": "s", "passed": False,
    ...     "detail": "ran past the time limit"}]})  # the words alone: no kind, so the check's slip
    'slip'
    >>> check_outcome({"passed": False, "hint": "divide by the interval's length", "steps": [
    ...     {"step": "the values at 5 points", "passed": False, "detail": "off by 0.3"}]})
    'slip'
    """
    if not isinstance(check, dict):
        raise InputError(f"a part's result must be a dict with 'passed' and 'steps'; got {type(check).__name__}.")
    kind = part_kind(check)  # the one place a part's kind is decided: the feedback and labkit handin agree
    if kind in (PASSED, HELD):
        return PASSED
    if kind in (NOT_DONE, VARIANT, SLIP):
        return kind
    kinds = {s.get("kind") for s in _steps(check) if not s.get("passed")}  # each failed step's code, set where made
    return next((kind for kind in OUTCOMES if kind in kinds), OTHER)


def problem_kinds(problem: str) -> list[tuple[str, str]]:
    """The kinds of a problem the grader recorded for a submission, each with the words to show.

    The kinds are the codes the grader set where it made the problem (a
    :class:`labkit.grading.store.report.ProblemText`), never read from its words: a
    notebook whose cells raised has one (kind, description) per cell, a cell
    the worker stopped at its time limit a time limit, the others errors
    raised. A bare text, with no codes, is "other".

    Parameters
    ----------
    problem : str
        One of a submission's ``problems``.

    Returns
    -------
    list of (str, str)
        (kind, description) pairs; the description is one printable line, bounded.

    Examples
    --------
    >>> from labkit.grading.store.report import ProblemText
    >>> problem_kinds(ProblemText.one("a.ipynb: stopped after the submission's time limit of 600 s.", "timeout"))
    [('timeout', "a.ipynb: stopped after the submission's time limit of 600 s.")]
    >>> problem_kinds("a.ipynb: it ran past the time limit")
    [('other', 'a.ipynb: it ran past the time limit')]
    """
    return [(kind, one_line(description, MAX_TEXT)) for kind, description in kinds_of(problem)]


def _steps(check):
    steps = check.get("steps", [])
    return [s for s in steps if isinstance(s, dict)] if isinstance(steps, list) else []


def _checks(grade, number):
    verdict = grade.results.get(number)
    if verdict is None:
        return None
    checks = verdict.get("checks") if isinstance(verdict, dict) else None
    if not isinstance(checks, list) or not all(isinstance(c, dict) for c in checks):
        raise InputError(
            f"the result of {one_line(grade.name, MAX_NAME)!r} for exercise {number} has no list of checks: "
            "it was not written by `labkit grade`; grade the submission again."
        )
    return checks


def _part_names(rubric, number, grades):
    """The exercise's parts as declared, then any other part name the results hold, in order."""
    exercise = rubric.registry.exercises.get(number)
    names = [part.name for part in exercise.parts] if exercise is not None else []
    for grade in grades:
        for check in _checks(grade, number) or []:
            name = one_line(check.get("name", "?"), MAX_TEXT)
            if name not in names:
                names.append(name)
    return names


def _weights(rubric, number):
    exercise = rubric.registry.exercises.get(number)
    if exercise is None:
        return {}
    total = sum(part.weight for part in exercise.parts) or 1
    return {part.name: rubric.points.get(number, 0) * part.weight / total for part in exercise.parts}


def _failed_text(check, number):
    details = [
        f"{one_line(s.get('step', ''), 100)}: {one_line(s.get('detail', ''), MAX_TEXT)}"
        for s in _steps(check)
        if not s.get("passed")
    ]
    return one_line(f"exercise {number}, {check.get('name', '?')}: " + ("; ".join(details) or "failed"), MAX_TEXT)


def summarise(grades: Iterable[SubmissionGrade]) -> ClassSummary:
    """Count what a class did: totals, pass rates, slips, problems and the most failed parts.

    Parameters
    ----------
    grades : list of SubmissionGrade
        One per submission, all scored under one rubric (:func:`read` gives them).

    Returns
    -------
    ClassSummary

    Raises
    ------
    ValueError
        If `grades` is empty, holds something other than SubmissionGrade, or mixes rubrics.

    Examples
    --------
    >>> from labkit.grading.store.report import SubmissionGrade
    >>> summarise([SubmissionGrade("ann", {2: {"fraction": 1.0, "passed": True, "checks": [
    ...     {"name": "eval_pherm", "passed": True, "hint": "", "weight": 10, "steps": []}]}})]).totals
    {'ann': 10.0}
    """
    grades = list(grades)
    if not grades:
        raise InputError("there are no submissions to report on: grade some first (`labkit grade`).")
    for grade in grades:
        if not isinstance(grade, SubmissionGrade):
            raise InputError(
                f"a class report is made of SubmissionGrade objects (labkit.grading.store.report); got "
                f"{type(grade).__name__}: read a run's results with labkit.grading.reports.class_report.read."
            )
    rubric = grades[0].rubric
    if any(grade.rubric != rubric for grade in grades):
        raise InputError("the grades are scored under different rubrics: read them all with one rubric.")
    graded = [g for g in grades if g.graded]
    exercises, parts = [], []
    slips = defaultdict(list)
    problems = defaultdict(list)  # (kind, student) -> texts
    failed: dict = {g.name: [] for g in graded}
    not_done: defaultdict = defaultdict(int)
    for number in rubric.graded:
        names = _part_names(rubric, number, graded)
        weights = _weights(rubric, number)
        counts: dict = {name: defaultdict(int) for name in names}
        found = attempted = passed = 0
        for grade in graded:
            checks = _checks(grade, number)
            if checks is None:
                for name in names:
                    counts[name]["missing"] += 1
                continue
            found += 1
            by_name = {one_line(c.get("name", "?"), MAX_TEXT): c for c in checks}
            outcomes = []
            for name in names:
                check = by_name.get(name) or {}
                outcome = check_outcome(check) if check else NOT_DONE
                outcomes.append(outcome)
                counts[name][outcome] += 1
                if outcome == PASSED:
                    continue
                if outcome == NOT_DONE:
                    not_done[grade.name] += 1
                    continue
                failed[grade.name].append(f"{number} {name}")
                if outcome == SLIP:
                    hint = one_line(check.get("hint") or "", MAX_TEXT) or _failed_text(check, number)
                    slips[(number, names.index(name), name, hint)].append(grade.name)
                else:
                    problems[(outcome, grade.name)].append(_failed_text(check, number))
            attempted += any(outcome not in (NOT_DONE,) for outcome in outcomes)
            passed += all(outcome == PASSED for outcome in outcomes) and bool(outcomes)
        exercises.append(ExerciseRate(number, len(graded), found, attempted, passed))
        for name in names:
            c = counts[name]
            problem = sum(c[kind] for kind in KINDS)
            parts.append(
                PartRate(number, name, weights.get(name, 0.0), c[PASSED], c[SLIP], problem, c[NOT_DONE], c["missing"])
            )
    for grade in grades:
        if not grade.graded:
            problems[(NOT_GRADED, grade.name)].append(one_line(grade.failure, MAX_TEXT))
            continue
        for text in grade.problems:
            for kind, line in problem_kinds(text):
                if kind != NOT_DONE:  # a stub's cell, or a cell as released: work not done, counted per part
                    problems[(kind, grade.name)].append(line)
    by_kind: dict = {kind: [] for kind in KINDS}
    for (kind, student), texts in sorted(problems.items(), key=lambda item: (item[0][0], item[0][1])):
        by_kind[kind].append(Problem(kind, student, tuple(dict.fromkeys(texts))))
    ordered = sorted(slips.items(), key=lambda item: (-len(set(item[1])), item[0][0], item[0][1], item[0][3]))
    slip_list = [
        Slip(number, name, hint, tuple(sorted(set(students)))) for (number, _, name, hint), students in ordered
    ]
    totals = {g.name: g.total for g in graded}
    struggles = sorted(
        (Struggle(name, totals[name], tuple(labels), not_done[name]) for name, labels in failed.items() if labels),
        key=lambda s: (-len(s.failed), s.total, s.student),
    )
    return ClassSummary(
        rubric=rubric,
        totals=totals,
        not_graded={g.name: g.failure for g in grades if not g.graded},
        exercises=exercises,
        parts=parts,
        slips=slip_list,
        problems={kind: rows for kind, rows in by_kind.items() if rows},
        most_failed=struggles[:MOST_FAILED],
        seeds=sorted({g.seed for g in grades if isinstance(g.seed, int)}),
        late=_late_summary(rubric, graded),
        copies=find_copies(grades),
        held=[
            Held(
                g.name, number, str(part), str(what.get("definition", "")), str(what.get("source", "")),
                float(what.get("share", 0) or 0), released,
                tuple(tuple(map(str, pair)) for pair in what.get("lines", ()) if len(pair) == 2),
            )
            for g in graded
            for number, part, what, released in g.held()
        ],
    )  # fmt: skip


# ---------------------------------------------------------------------------------------------- figures


def _png(figure):
    """A matplotlib Figure as a base64 PNG (no pyplot: the figure is garbage once drawn)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(figure)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100, metadata={"Software": None})
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def _bins(totals, maximum):
    """Bin edges of a round width, about twenty bins from 0 to the largest possible total."""
    import numpy as np

    top = max([float(maximum), *map(float, totals), 1.0])
    width = next(w for w in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 10**9) if top / w <= 25)
    edges = np.arange(0.0, top + width, float(width))
    if edges[-1] < top:
        edges = np.append(edges, edges[-1] + width)
    return edges


def histogram_of_totals(summary: ClassSummary) -> tuple[str, str, list[tuple[float, float, int]]]:
    """The histogram of the graded totals: (base64 PNG, alt text, [(low, high, count)]).

    Parameters
    ----------
    summary : ClassSummary

    Returns
    -------
    tuple
        The picture, its alt text (the figures in words: how many, median, mean, range, full credit,
        the largest bin) and the bins it shows.
    """
    import numpy as np
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    totals = list(summary.totals.values())
    rubric = summary.rubric
    edges = _bins(totals, rubric.maximum)
    counts, _ = np.histogram(totals, bins=edges)
    bins = [(float(lo), float(hi), int(n)) for lo, hi, n in zip(edges[:-1], edges[1:], counts)]
    figure = Figure(figsize=(6.4, 2.8), layout="constrained")
    axes = figure.subplots()
    axes.hist(totals, bins=edges, color="#2b5797", edgecolor="white")
    axes.axvline(rubric.full_credit, color="black", linestyle="--", linewidth=1.2)
    axes.annotate(
        f"full credit {points_text(rubric.full_credit)}",
        (rubric.full_credit, 1.0),
        xycoords=("data", "axes fraction"),
        xytext=(0, 3),
        textcoords="offset points",
        ha="center",
        va="bottom",
        fontsize=9,
    )
    axes.set_xlabel("total points")
    axes.set_ylabel("submissions")
    axes.yaxis.set_major_locator(MaxNLocator(integer=True))
    axes.set_xlim(edges[0], edges[-1])
    image = _png(figure)
    if totals:
        low, high, count = max(bins, key=lambda b: (b[2], -b[0]))
        full = sum(t >= rubric.full_credit for t in totals)
        alt = (
            f"Histogram of {len(totals)} totals: median {points_text(statistics.median(totals))}, "
            f"mean {statistics.fmean(totals):.1f}, lowest {points_text(min(totals))}, "
            f"highest {points_text(max(totals))}; {full} of {len(totals)} reach full credit "
            f"({points_text(rubric.full_credit)} points). The largest bin, {points_text(low)} to "
            f"{points_text(high)} points, holds {count}."
        )
    else:
        alt = "Histogram of totals: empty, no submission could be graded."
    return image, alt, bins


def _rate_text(rate, attempted):
    return "nobody attempted it" if rate is None else f"{rate:.0%} of {attempted}"


def _bars(labels, rates, attempted):
    from matplotlib.figure import Figure

    height = 0.9 + 0.26 * len(labels)
    figure = Figure(figsize=(7.5, height), layout="constrained")
    axes = figure.subplots()
    positions = list(range(len(labels)))
    values = [100 * (r or 0.0) for r in rates]
    axes.barh(positions, values, color="#2b5797", height=0.7)
    for y, rate, n in zip(positions, rates, attempted):
        axes.text(
            (100 * rate if rate is not None else 0) + 1, y, _rate_text(rate, n), va="center", fontsize=8, color="black"
        )
    axes.set_yticks(positions, [one_line(label, 40) for label in labels], fontsize=8)
    axes.invert_yaxis()
    axes.set_xlim(0, 125)
    axes.set_xticks([0, 25, 50, 75, 100], ["0%", "25%", "50%", "75%", "100%"])
    axes.set_xlabel("passed, of the submissions that attempted it")
    return _png(figure)


def pass_rate_figures(summary: ClassSummary) -> list[tuple[str, str, str]]:
    """Bar charts of the pass rates: [(base64 PNG, alt text, caption)], exercises then parts.

    Parameters
    ----------
    summary : ClassSummary

    Returns
    -------
    list of tuple
        Each figure with an alt text that gives every rate in numbers.
    """
    exercises, parts = summary.exercises, summary.parts
    exercise_alt = (
        "Bar chart of the pass rate of each exercise among the submissions that attempted it: "
        + "; ".join(f"exercise {e.exercise} {_rate_text(e.rate, e.attempted)}" for e in exercises)
        + "."
    )
    part_alt = (
        "Bar chart of the pass rate of each part among the submissions that attempted it: "
        + "; ".join(f"exercise {p.label} {_rate_text(p.rate, p.attempted)}" for p in parts)
        + "."
    )
    return [
        (
            _bars(
                [f"exercise {e.exercise}" for e in exercises],
                [e.rate for e in exercises],
                [e.attempted for e in exercises],
            ),
            exercise_alt,
            "Each exercise: passed (every part) of the submissions that attempted it.",
        ),
        (
            _bars([p.label for p in parts], [p.rate for p in parts], [p.attempted for p in parts]),
            part_alt,
            "Each part, labelled with its exercise: passed of the submissions that attempted it.",
        ),
    ]


# ---------------------------------------------------------------------------------------------- HTML


def _e(value, limit=MAX_TEXT):
    """A submission's (or the grader's) text as HTML: printable, one line, bounded, escaped."""
    return html.escape(one_line(value, limit), quote=True)


def _name(value):
    """A submission's name as HTML: shortened for reading with a hash of the whole name, so two names sharing a
    beginning never look alike (:func:`labkit.grading.store.names.shown_name`), escaped."""
    return html.escape(shown_name(value, MAX_NAME), quote=True)


def _percent(rate):
    return "&ndash;" if rate is None else f"{rate:.0%}"


def _names(names, noun="students"):
    names = list(names)
    if len(names) <= 3:
        return ", ".join(_name(name) for name in names)
    shown = "".join(f"<li>{_name(name)}</li>" for name in names[:MAX_NAMES])
    more = f"<li>and {len(names) - MAX_NAMES} more</li>" if len(names) > MAX_NAMES else ""
    one = noun[:-1] if noun.endswith("s") else noun
    return (
        f"<details><summary>{len(names)} {one if len(names) == 1 else noun}</summary>"
        f'<ul class="names">{shown}{more}</ul></details>'
    )


def _figure(image, alt, caption):
    return (
        f'<figure><img src="data:image/png;base64,{image}" alt="{html.escape(alt, quote=True)}">'
        f"<figcaption>{html.escape(caption)}</figcaption></figure>"
    )


def _totals_section(summary):
    totals = list(summary.totals.values())
    rubric = summary.rubric
    parts = ['<section aria-labelledby="totals"><h2 id="totals">Totals</h2>']
    if not totals:
        parts.append("<p>No submission could be graded, so there are no totals.</p></section>")
        return "".join(parts)
    image, alt, bins = histogram_of_totals(summary)
    parts.append('<div class="row">')
    parts.append(_figure(image, alt, "The distribution of the graded submissions' totals under the rubric."))
    quartiles = statistics.quantiles(totals, n=4, method="inclusive") if len(totals) > 1 else [totals[0]] * 3
    rows = [
        ("graded", str(len(totals))),
        ("could not be graded", str(len(summary.not_graded))),
        ("median", points_text(statistics.median(totals))),
        ("mean", f"{statistics.fmean(totals):.1f}"),
        ("lowest, highest", f"{points_text(min(totals))}, {points_text(max(totals))}"),
        ("quartiles", ", ".join(points_text(q) for q in quartiles)),
        (f"full credit ({points_text(rubric.full_credit)}) or more", str(sum(t >= rubric.full_credit for t in totals))),
        ("the most possible, with extra credit", points_text(rubric.maximum)),
    ]
    parts.append('<table class="narrow"><caption>The totals in figures</caption><tbody>')
    parts += [f'<tr><th scope="row">{html.escape(k)}</th><td class="num">{v}</td></tr>' for k, v in rows]
    parts.append("</tbody></table></div>")
    if summary.late is not None:
        parts.append(
            "<p>The totals are after the late penalty, as in grades.csv's <code>total</code> column; "
            '<a href="#late">Late work</a> gives the points before it.</p>'
        )
    parts.append(
        '<details><summary>The histogram as a table</summary><table class="narrow"><caption>Submissions per '
        'range of totals</caption><thead><tr><th scope="col">total points</th><th scope="col">submissions</th>'
        "</tr></thead><tbody>"
    )
    parts += [
        f"<tr><td>{points_text(lo)} to {'under ' if i < len(bins) - 1 else ''}{points_text(hi)}</td>"
        f'<td class="num">{n}</td></tr>'
        for i, (lo, hi, n) in enumerate(bins)
    ]
    parts.append("</tbody></table></details></section>")
    return "".join(parts)


def _when(moment, rule):
    """A moment in the deadline's offset, as grades.csv writes it (or a dash when unknown)."""
    return "&ndash;" if moment is None else _e(lateness.time_text(moment, rule.deadline.tzinfo), 64)


def _units(entry, rule):
    return f"{entry.units} started {rule.per}{'' if entry.units == 1 else 's'}"


def _table(caption, columns, rows):
    """A table with a caption and column headers; each row's first cell is its header. Bounded."""
    head = "".join(f'<th scope="col">{html.escape(c)}</th>' for c in columns)
    body = "".join(
        f'<tr><th scope="row">{row[0]}</th>' + "".join(f"<td{cls}>{cell}</td>" for cls, cell in row[1:]) + "</tr>"
        for row in rows[:MAX_NAMES]
    )
    more = len(rows) - MAX_NAMES
    tail = f"<p>and {more} more.</p>" if more > 0 else ""
    return (
        f"<table><caption>{html.escape(caption)}</caption><thead><tr>{head}</tr></thead>"
        f"<tbody>{body}</tbody></table>{tail}"
    )


NUM, TEXT = ' class="num"', ""


def _late_section(summary):
    view = summary.late
    rule = view.rule
    count = len(view.entries)
    out = ['<section aria-labelledby="late"><h2 id="late">Late work</h2>']
    out.append(
        f"<p>The rubric's rule: {_e(rule.describe())}. The penalty is a share of the submission's own points "
        "(extra credit included), taken off its total; every total on this page and in grades.csv is after it. "
        "Extensions are named here, for you; no student's feedback names another's.</p>"
    )
    if not count:
        out.append("<p>No submission could be graded, so there is nothing to say about lateness.</p></section>")
        return "".join(out)
    late = view.late
    figures = [
        ("graded submissions", str(count)),
        ("on time", f"{len(view.on_time)}" + (f" ({len(view.within_grace)} within the grace)" if rule.grace else "")),
        ("late", str(len(late))),
        ("points taken off, in all", points_text(view.penalty)),
        ("with an extension", str(len(view.extended))),
        ("no known time (not penalised)", str(len(view.unknown))),
        ("a time the student supplied", str(len(view.student_supplied))),
    ]
    out.append('<table class="narrow"><caption>Late work in figures</caption><tbody>')
    out += [f'<tr><th scope="row">{html.escape(k)}</th><td class="num">{v}</td></tr>' for k, v in figures]
    out.append("</tbody></table>")

    out.append(f'<h3 id="late-late">Late: {len(late)} submission{"" if len(late) == 1 else "s"}</h3>')
    if late:
        rows = [
            (
                _name(e.student),
                (TEXT, _when(e.deadline, rule) + (" (extension)" if e.extended else "")),
                (TEXT, _when(e.submitted, rule)),
                (TEXT, _e(e.source or "", 64)),
                (TEXT, _e(lateness.duration_text(e.late_by), 64)),
                (NUM, _units(e, rule)),
                (NUM, f"{points_text(e.percent)}%"),
                (NUM, points_text(e.penalty)),
                (NUM, points_text(e.raw_total)),
                (NUM, points_text(e.total)),
            )
            for e in late
        ]
        out.append(
            _table(
                "Late submissions, latest first",
                [
                    "student",
                    "deadline",
                    "handed in",
                    "time from",
                    "late by",
                    "counted",
                    "penalty (percent)",
                    "penalty (points)",
                    "points before",
                    "total",
                ],
                rows,
            )
        )
    else:
        out.append("<p>No submission was late.</p>")

    extended = view.extended
    out.append(
        f'<h3 id="late-extensions">Extensions: {len(extended)} submission{"" if len(extended) == 1 else "s"}</h3>'
    )
    if extended:
        rows = [
            (
                _name(e.student),
                (TEXT, _when(e.deadline, rule)),
                (TEXT, _when(e.submitted, rule)),
                (TEXT, _e(e.note)),
            )
            for e in extended
        ]
        out.append(
            _table("Submissions with an extension", ["student", "their deadline", "handed in", "lateness"], rows)
        )
    else:
        out.append("<p>No graded submission has an extension.</p>")
    unused = view.unused_extensions
    if unused:
        out.append(
            f"<p>The rubric's <code>[late.extensions]</code> names {len(unused)} submission"
            f"{'' if len(unused) == 1 else 's'} this run has no graded result for (a misspelt name?): "
            f"{_names(unused, 'names')}.</p>"
        )

    unknown = view.unknown
    out.append(f'<h3 id="late-unknown">No known time: {len(unknown)} submission{"" if len(unknown) == 1 else "s"}</h3>')
    if unknown:
        out.append(
            "<p>Graded and not penalised. Give their times in <code>--times TIMES.csv</code> and merge again "
            "(<code>labkit merge</code>) to apply the rule.</p>"
        )
        rows = [(_name(e.student), (TEXT, _e(e.note))) for e in unknown]
        out.append(_table("Submissions with no known time", ["student", "why"], rows))
    else:
        out.append("<p>Every graded submission has a time.</p>")

    supplied = view.student_supplied
    out.append(
        f'<h3 id="late-supplied">Times the student supplied: {len(supplied)} submission'
        f"{'' if len(supplied) == 1 else 's'}</h3>"
    )
    if supplied:
        out.append(
            "<p>These times come from the submission itself (nbgrader's <code>timestamp.txt</code> in the folder, "
            "or the notebooks' modification time), so a student could have set them. Check them against the "
            "LMS, and give the right ones in <code>--times</code> where they differ.</p>"
        )
        rows = [
            (
                _name(e.student),
                (TEXT, _e(e.source or "", 64)),
                (TEXT, _when(e.submitted, rule)),
                (TEXT, _e(e.note)),
            )
            for e in supplied
        ]
        out.append(
            _table(
                "Submissions whose time the student supplied", ["student", "time from", "handed in", "lateness"], rows
            )
        )
    else:
        out.append("<p>No time came from the submission itself.</p>")
    out.append("</section>")
    return "".join(out)


def _rates_section(summary):
    out = ['<section aria-labelledby="pass-rates"><h2 id="pass-rates">Pass rates</h2>']
    out.append(
        "<p>A submission <em>attempted</em> an exercise or part when it holds more than the released stub: "
        "the part passed, failed with a hint, or met a problem. Parts left as released or not defined are "
        "counted as <em>not done</em>; exercises in no notebook of a submission as <em>not found</em>.</p>"
    )
    if summary.totals:
        for image, alt, caption in pass_rate_figures(summary):
            out.append(_figure(image, alt, caption))
    out.append(
        '<table><caption>Each exercise</caption><thead><tr><th scope="col">exercise</th>'
        '<th scope="col">points</th><th scope="col">found</th><th scope="col">attempted</th>'
        '<th scope="col">passed</th><th scope="col">pass rate (of attempted)</th>'
        '<th scope="col">pass rate (of graded)</th></tr></thead><tbody>'
    )
    for e in summary.exercises:
        of_graded = e.passed / e.graded if e.graded else None
        out.append(
            f'<tr><th scope="row">{e.exercise}</th><td class="num">'
            f"{points_text(summary.rubric.worth(e.exercise) if e.exercise in summary.rubric.points else 0)}</td>"
            f'<td class="num">{e.found}</td><td class="num">{e.attempted}</td><td class="num">{e.passed}</td>'
            f'<td class="num">{_percent(e.rate)}</td><td class="num">{_percent(of_graded)}</td></tr>'
        )
    out.append("</tbody></table>")
    out.append(
        '<table><caption>Each part</caption><thead><tr><th scope="col">exercise</th><th scope="col">part</th>'
        '<th scope="col">points</th><th scope="col">passed</th><th scope="col">failed with a hint</th>'
        '<th scope="col">problem</th><th scope="col">not done</th><th scope="col">not found</th>'
        '<th scope="col">pass rate (of attempted)</th></tr></thead><tbody>'
    )
    for p in summary.parts:
        out.append(
            f'<tr><td class="num">{p.exercise}</td><th scope="row">{_e(p.part)}</th>'
            f'<td class="num">{points_text(p.weight)}</td><td class="num">{p.passed}</td>'
            f'<td class="num">{p.slipped}</td><td class="num">{p.problem}</td><td class="num">{p.not_done}</td>'
            f'<td class="num">{p.missing}</td><td class="num">{_percent(p.rate)}</td></tr>'
        )
    out.append("</tbody></table></section>")
    return "".join(out)


def _slips_section(summary):
    out = ['<section aria-labelledby="slips"><h2 id="slips">Slips the checks named</h2>']
    slips = summary.slips
    if not slips:
        out.append("<p>No part failed with a hint.</p></section>")
        return "".join(out)
    out.append(
        f"<p>{len(slips)} different hints, most frequent first. A slip is a failed part with the hint its check "
        "gave; each student is counted once per slip.</p>"
    )
    out.append(
        '<table><caption>Slips, most frequent first</caption><thead><tr><th scope="col">students</th>'
        '<th scope="col">exercise</th><th scope="col">part</th><th scope="col">the hint</th>'
        '<th scope="col">who</th></tr></thead><tbody>'
    )
    for slip in slips[:MAX_ROWS]:
        count = len(slip.students)
        out.append(
            f'<tr><td class="num">{count}</td><td class="num">{slip.exercise}</td><th scope="row">{_e(slip.part)}</th>'
            f"<td>{_e(slip.hint)}: <strong>{count} student{'' if count == 1 else 's'}</strong></td>"
            f"<td>{_names(slip.students)}</td></tr>"
        )
    out.append("</tbody></table>")
    if len(slips) > MAX_ROWS:
        rest = slips[MAX_ROWS:]
        out.append(
            f"<p>{len(rest)} rarer slips ({sum(len(s.students) for s in rest)} failed parts) are not listed; "
            "each student's feedback file names them.</p>"
        )
    out.append("</section>")
    return "".join(out)


def _problems_section(summary):
    out = ['<section aria-labelledby="problems"><h2 id="problems">Problems</h2>']
    if not summary.problems:
        out.append("<p>No time limit, crash, error, refused reference or other problem.</p></section>")
        return "".join(out)
    out.append("<ul>")
    for kind, rows in summary.problems.items():
        heading, _ = KINDS[kind]
        out.append(
            f'<li><a href="#problem-{kind.replace(" ", "-")}">{heading}</a>: {len(rows)} '
            f"student{'' if len(rows) == 1 else 's'}</li>"
        )
    out.append("</ul>")
    for kind, rows in summary.problems.items():
        heading, meaning = KINDS[kind]
        anchor = f"problem-{kind.replace(' ', '-')}"
        out.append(
            f'<h3 id="{anchor}">{heading}: {len(rows)} student{"" if len(rows) == 1 else "s"}</h3>'
            f"<p>{html.escape(meaning)}.</p>"
        )
        out.append(
            f"<details{' open' if len(rows) <= 10 else ''}><summary>Who, and what happened ({len(rows)})</summary>"
            f'<table><caption>{heading}</caption><thead><tr><th scope="col">student</th>'
            '<th scope="col">what happened</th></tr></thead><tbody>'
        )
        for row in rows[:MAX_NAMES]:
            texts = "".join(f"<li>{_e(text)}</li>" for text in row.texts[:MAX_TEXTS])
            more = f"<li>and {len(row.texts) - MAX_TEXTS} more</li>" if len(row.texts) > MAX_TEXTS else ""
            out.append(f'<tr><th scope="row">{_name(row.student)}</th><td><ul>{texts}{more}</ul></td></tr>')
        out.append("</tbody></table>")
        if len(rows) > MAX_NAMES:
            out.append(f"<p>and {len(rows) - MAX_NAMES} more students.</p>")
        out.append("</details>")
    out.append("</section>")
    return "".join(out)


def _most_failed_section(summary):
    out = ['<section aria-labelledby="most-failed"><h2 id="most-failed">The most failed parts</h2>']
    if not summary.most_failed:
        out.append("<p>No graded submission failed a part.</p></section>")
        return "".join(out)
    out.append(
        f"<p>The {len(summary.most_failed)} students with the most failed parts: parts they attempted that "
        "failed, with a hint or through a problem. Parts left as released or not defined (the other branch, "
        "say) are counted apart, as <em>not done</em>.</p>"
        '<table><caption>Students with the most failed parts</caption><thead><tr><th scope="col">student</th>'
        '<th scope="col">failed parts</th><th scope="col">not done</th><th scope="col">total</th>'
        '<th scope="col">the failed parts</th></tr></thead><tbody>'
    )
    for s in summary.most_failed:
        labels = ", ".join(_e(label, MAX_LABEL) for label in s.failed[:MAX_FAILED_SHOWN])
        extra = len(s.failed) - MAX_FAILED_SHOWN
        more = f", and {extra} more" if extra > 0 else ""
        out.append(
            f'<tr><th scope="row">{_name(s.student)}</th><td class="num">{len(s.failed)}</td>'
            f'<td class="num">{s.not_done}</td><td class="num">{points_text(s.total)}</td>'
            f"<td>{labels}{more}</td></tr>"
        )
    out.append("</tbody></table></section>")
    return "".join(out)


def _code_side(name, lines, shared):
    rows = []
    width = len(str(min(len(lines), MAX_LINES)))
    for number, line in enumerate(lines[:MAX_LINES]):
        text = html.escape(printable(str(line)).replace("\t", "    ").replace("\n", " ")[:MAX_LINE])
        gutter = (
            f'<span class="gutter" aria-hidden="true">{number + 1:>{width}} {"=" if number in shared else " "} </span>'
        )
        rows.append(f"{gutter}<mark>{text}</mark>" if number in shared else f"{gutter}{text}")
    if len(lines) > MAX_LINES:
        rows.append(f"\u2026 and {len(lines) - MAX_LINES} more lines")
    return f"<figure><figcaption>{_e(name, MAX_NAME)}</figcaption><pre>" + "\n".join(rows) + "</pre></figure>"


def _held_section(summary):
    out = ['<section aria-labelledby="held"><h2 id="held">Held for a person</h2>']
    out.append(
        "<p>A part is held when its check passed but its code is, names aside, mostly code every student has "
        f"on disk: labkit's, scipy's, or the solutions' given to <code>--solutions</code> (a share of "
        f"{THRESHOLD:.2f} or more of the part's own code; see <code>docs/grading-security.md</code>). Its points "
        "are not in the total until you release them: list the student and the exercise in the rubric's "
        '<code>[held]</code> table (<code>release = {"ada" = [2]}</code>) and run '
        "<code>labkit merge OUT --rubric RUBRIC --out NEW</code>.</p>"
    )
    if not summary.held:
        out.append("<p>No part of this class is held.</p></section>")
        return "\n".join(out)
    rows = [
        [_name(s.student)]
        + [(TEXT, _e(cell, MAX_NAME)) for cell in (f"{s.exercise} {s.part}", s.definition, s.source)]
        + [(NUM, f"{s.share:.0%}"), (TEXT, "released" if s.released else "held")]
        for s in summary.held
    ]
    out.append(_table("Parts held for a person", ["Student", "Part", "Definition", "Matched", "Share", "State"], rows))
    for entry in summary.held[:MAX_PAIRS]:
        mine = [pair[0] for pair in entry.lines]
        theirs = [pair[1] for pair in entry.lines]
        out.append(
            f"<h3>{_e(entry.student, MAX_NAME)}: exercise {entry.exercise}, {_e(entry.part, MAX_NAME)}</h3>"
            '<div class="pair">'
            + _code_side(f"{entry.student}: {entry.definition}", mine, set(range(len(mine))))
            + _code_side(entry.source, theirs, {i for i, line in enumerate(theirs) if line})
            + "</div>"
        )
    out.append("</section>")
    return "\n".join(out)


def _pair_details(pair):
    """One graded function of a pair of students, its two versions side by side on demand."""
    shared_first = {i for i in pair.shared_first if isinstance(i, int) and 0 <= i < len(pair.first_lines)}
    shared_second = {i for i in pair.shared_second if isinstance(i, int) and 0 <= i < len(pair.second_lines)}
    return (
        f"<details><summary><code>{_e(pair.function, 100)}</code>, similarity {pair.score:.2f}: "
        f"{len(shared_first)} of {len(pair.first_lines)} lines and {len(shared_second)} of "
        f'{len(pair.second_lines)} shared</summary><div class="sides">'
        + _code_side(pair.first, pair.first_lines, shared_first)
        + _code_side(pair.second, pair.second_lines, shared_second)
        + "</div></details>"
    )


def _copies_section(copies):
    """Whose data a notebook holds and the submissions with the solutions' markers (instructor only)."""
    out = ['<section aria-labelledby="copies"><h2 id="copies">Copies</h2>']
    lines = copies.holder_lines() if copies is not None else []
    marked = copies.marked if copies is not None else []
    if not lines and not marked:
        out.append("<p>No notebook holds a classmate's data or the solutions' markers.</p></section>")
        return "".join(out)
    items = [f"<li>{_e(line, 400)}</li>" for line in lines]
    items += [
        f"<li>{_e(name, MAX_NAME)} holds the instructor solutions' markers (<code>### BEGIN SOLUTION</code>) in "
        f"{_e(', '.join(found), 300)}: the instructor notebooks were handed in</li>"
        for name, found in marked
    ]
    out.append(f"<ul>{''.join(items)}</ul></section>")
    return "".join(out)


def _similar_section(pairs, threshold, note, copies=None):
    out = ['<section aria-labelledby="similar"><h2 id="similar">Similar code</h2>']
    out.append(
        "<p><strong>Similarity never changes a grade.</strong> These pairs are for a person to judge: shared "
        "code can be innocent (the lab's template, a formula everyone writes alike, work done together where "
        "that is allowed).</p>"
    )
    if pairs is None:
        why = f" ({_e(note)})" if note else ""
        out.append(f"<p>Not computed{why}.</p></section>")
        return "".join(out)
    if not pairs:
        out.append(f"<p>No pair of submissions is similar at the threshold {threshold:.2f} or above.</p></section>")
        return "".join(out)
    rows = pair_rows(pairs, copies.functions if copies is not None else {})
    out.append(
        f"<p>{len(rows)} pair{'' if len(rows) == 1 else 's'} of students with graded functions alike at a similarity "
        f"of {threshold:.2f} or above, most functions alike first; open a function to see both versions, shared "
        "lines highlighted and marked <code>=</code> after their line number.</p>"
    )
    for index, row in enumerate(rows[:MAX_PAIRS], 1):
        out.append(
            f'<article class="pair" aria-labelledby="pair-{index}"><h3 id="pair-{index}">'
            f"{_e(row.words, 2 * MAX_NAME + 80)}</h3>"
            + "".join(_pair_details(pair) for pair in row.alike[:MAX_PAIRS])
            + "</article>"
        )
    if len(rows) > MAX_PAIRS:
        out.append(f"<p>and {len(rows) - MAX_PAIRS} pairs with fewer functions alike, not shown.</p>")
    out.append("</section>")
    return "".join(out)


STYLE = """
:root { color: #1b1b1b; background: #fff; font-family: system-ui, sans-serif; line-height: 1.45; }
body { max-width: 72rem; margin: 0 auto; padding: 0 1rem 3rem; }
.skip { position: absolute; left: -100vw; top: 0.5rem; background: #fff; color: #0b3d91; padding: 0.5rem; }
.skip:focus { left: 0.5rem; z-index: 1; }
:focus-visible { outline: 3px solid #0b3d91; outline-offset: 2px; }
a { color: #0b3d91; }
h1 { font-size: 1.7rem; } h2 { margin-top: 2.5rem; border-bottom: 2px solid #1b1b1b; } h3 { margin-top: 1.5rem; }
table { border-collapse: collapse; margin: 1rem 0; width: 100%; }
table.narrow { width: auto; }
caption { text-align: left; font-weight: bold; padding: 0.3rem 0; }
th, td { border: 1px solid #8a8a8a; padding: 0.25rem 0.5rem; text-align: left; vertical-align: top; }
thead th { background: #e8ecf3; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 1rem 0; } figure img { max-width: 100%; height: auto; }
figcaption { font-style: italic; }
ul.names { columns: 14rem; margin: 0.3rem 0; }
nav ul { display: flex; flex-wrap: wrap; gap: 0.3rem 1.5rem; list-style: none; padding: 0; }
.row { display: flex; flex-wrap: wrap; gap: 0 2rem; align-items: flex-start; }
.row figure { flex: 0 1 38rem; }
details > summary { cursor: pointer; }
.sides { display: grid; grid-template-columns: 1fr 1fr; gap: 1rem; }
.sides figure { margin: 0; min-width: 0; }
pre { white-space: pre-wrap; overflow-wrap: anywhere; background: #f6f6f6; border: 1px solid #8a8a8a;
  padding: 0.5rem; font-size: 0.85rem; margin: 0; }
mark { background: #ffe680; color: #000; font-weight: bold; }
.gutter { color: #4a4a4a; user-select: none; }
.pair { border-top: 1px solid #8a8a8a; margin-top: 1.5rem; }
@media (max-width: 50rem) { .sides { grid-template-columns: 1fr; } }
@media print {
  :root { font-size: 10pt; }
  body { max-width: none; padding: 0; }
  .skip, nav { display: none; }
  a { color: inherit; }
  thead th, pre { background: none; }
  mark { background: none; text-decoration: underline; }
  details > summary { list-style: none; font-weight: bold; }
  details::details-content { display: contents; content-visibility: visible; }
  figure, tr, .pair h3 { break-inside: avoid; }
  h2, h3 { break-after: avoid; }
}
"""

# open every <details> while printing (and close again those that were closed): print shows every list
SCRIPT = """
addEventListener("beforeprint", () => { for (const d of document.querySelectorAll("details")) {
  if (!d.open) { d.dataset.printed = "1"; d.open = true; } } });
addEventListener("afterprint", () => { for (const d of document.querySelectorAll("details[data-printed]")) {
  d.open = false; delete d.dataset.printed; } });
"""


def render(
    summary: ClassSummary,
    pairs: Iterable[Pair] | None = None,
    *,
    threshold: float = DEFAULT_THRESHOLD,
    similarity_note: str | None = None,
) -> str:
    """The class report as one HTML document (a string), figures inline.

    Parameters
    ----------
    summary : ClassSummary
        From :func:`summarise`.
    pairs : list of Pair, optional
        Similar code to show side by side; None when the search was not made.
    threshold : float
        The similarity from which pairs were listed (said on the page).
    similarity_note : str, optional
        Why the pairs were not computed, when `pairs` is None; when not given, the reason the similarity
        search cannot run here, if it cannot (:func:`labkit.grading.reports.similarity.unavailable`).

    Returns
    -------
    str
    """
    if not isinstance(summary, ClassSummary):
        raise InputError(f"render takes the ClassSummary of summarise(grades); got {type(summary).__name__}.")
    pairs = _check_pairs(pairs)
    if pairs is None and similarity_note is None:
        similarity_note = unavailable()
    rubric = summary.rubric
    seeds = ", ".join(str(s) for s in summary.seeds[:20]) or "not recorded"
    sections = [
        ("totals", "Totals"),
        *([("late", "Late work")] if summary.late is not None else []),
        ("pass-rates", "Pass rates"),
        ("slips", "Slips the checks named"),
        ("problems", "Problems"),
        ("most-failed", "The most failed parts"),
        ("held", "Held for a person"),
        ("copies", "Copies"),
        ("similar", "Similar code"),
    ]
    nav = "".join(f'<li><a href="#{anchor}">{title}</a></li>' for anchor, title in sections)
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>Class report: {_e(rubric.title, 200)}</title>\n<style>{STYLE}</style>\n"
        f"<script>{SCRIPT}</script>\n</head>\n<body>\n"
        '<a class="skip" href="#main">Skip to the report</a>\n'
        f"<header><h1>Class report</h1><p>{_e(rubric.title, 200)}: {summary.submissions} submissions, "
        f"{len(summary.totals)} graded, {len(summary.not_graded)} could not be graded. Random test data from "
        f"seed {seeds}. Full credit is {points_text(rubric.full_credit)} points; with every extra credit "
        f"{points_text(rubric.maximum)}.</p>\n"
        f'<nav aria-label="Sections of the report"><ul>{nav}</ul></nav></header>\n'
        '<main id="main" tabindex="-1">\n'
        + "\n".join(
            [
                _totals_section(summary),
                *([_late_section(summary)] if summary.late is not None else []),
                _rates_section(summary),
                _slips_section(summary),
                _problems_section(summary),
                _most_failed_section(summary),
                _held_section(summary),
                _copies_section(summary.copies),
                _similar_section(pairs, threshold, similarity_note, summary.copies),
            ]
        )
        + "\n</main>\n<footer><p>Written by <code>labkit report</code> from the grading run's "
        "<code>results/</code>; each student's feedback file has the details.</p></footer>\n</body>\n</html>\n"
    )


def _check_pairs(pairs):
    if pairs is None:
        return None
    if isinstance(pairs, (str, bytes, dict)):
        raise InputError(
            f"pairs must be a list of labkit.grading.reports.similarity.Pair (or None); got {type(pairs).__name__}."
        )
    pairs = list(pairs)
    for pair in pairs:
        if not isinstance(pair, Pair):
            raise InputError(
                f"pairs must be labkit.grading.reports.similarity.Pair objects (similarity.similar_pairs gives them); "
                f"got {type(pair).__name__}."
            )
        if not isinstance(pair.score, (int, float)) or not 0.0 <= float(pair.score) <= 1.0:
            raise InputError(f"a pair's score is a similarity from 0 to 1; got {pair.score!r} for {pair.function!r}.")
    return pairs


def _variant_students(out):
    """Each student's variant data, as the run in `out` recorded them ({} without variants or a record)."""
    from ..store.record import read as read_record

    try:
        return read_record(out).variants.get("students", {})
    except ValueError:
        return {}


def write(
    out_dir: str | Path,
    grades: Iterable[SubmissionGrade],
    pairs: Iterable[Pair] | None = None,
    *,
    threshold: float = DEFAULT_THRESHOLD,
    similarity_note: str | None = None,
) -> Path:
    """Write ``report.html`` into a grading run's output folder; its path.

    The folder's other files (grades.csv, feedback/, results/, ...) are neither read here nor touched:
    the page is written to a temporary file in the folder, then renamed over an earlier report.

    Parameters
    ----------
    out_dir : str or Path
        The run's ``--out`` folder (it must exist).
    grades : list of SubmissionGrade
        The class (:func:`read` reads them from `out_dir`).
    pairs : list of Pair, optional
        Similar code, shown side by side; None says "not computed".
    threshold : float
        The similarity from which `pairs` were listed, between 0 and 1.
    similarity_note : str, optional
        Why the pairs were not computed.

    Returns
    -------
    Path
        ``out_dir/report.html``.

    Raises
    ------
    ValueError
        For a folder that does not exist, a ``report.html`` that is not a file, no grades, a threshold
        outside (0, 1], or pairs that are not :class:`~labkit.grading.reports.similarity.Pair` objects.
    """
    out = Path(out_dir)
    if not out.is_dir():
        raise InputError(f"{out} is not a folder: give the --out folder of a `labkit grade` run.")
    if not isinstance(threshold, (int, float)) or not 0.0 < float(threshold) <= 1.0:
        raise InputError(f"the similarity threshold is a number above 0 and at most 1; got {threshold!r}.")
    target = out / REPORT
    if target.is_symlink() or (target.exists() and not target.is_file()):
        raise InputError(f"{target} exists and is not a plain file: move it away, then run labkit report again.")
    grades = list(grades)
    summary = summarise(grades)
    summary.copies = find_copies(grades, _variant_students(out))
    page = render(summary, pairs, threshold=float(threshold), similarity_note=similarity_note)
    handle = tempfile.NamedTemporaryFile(  # noqa: SIM115 - closed below, then renamed into place
        "w", encoding="utf-8", dir=out, prefix=".report-", suffix=".html.tmp", delete=False
    )
    try:
        with handle:
            handle.write(page)
        os.chmod(handle.name, 0o644)
        os.replace(handle.name, target)
    except BaseException:
        Path(handle.name).unlink(missing_ok=True)
        raise
    return target
