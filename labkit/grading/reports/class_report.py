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
changes a grade, it is for a person to judge). Without copydetect, which the
similarity search needs, the page is written all the same and its similar code
section says "not computed", and why.

The page needs nothing but itself: its figures are inline PNG images drawn
with matplotlib's Agg canvas (no pyplot state), its style and its one small
script (``templates/class_report.*``) are inline, and it names no other
resource. Everything a submission could have influenced (its name, a hint that
quotes its values, a problem's text, its code) is data: made printable and
bounded in length (:func:`labkit.grading.store.report.one_line`), then escaped
by the template (:mod:`labkit.grading.pages`, autoescape on).
"""

from __future__ import annotations

import base64
import io
import os
import statistics
import tempfile
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field
from datetime import timedelta
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
from .. import pages
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
# the kinds of problem, in the order the page lists them (its words for each are in the template)
KINDS = (TIMEOUT, CRASH, RAISED, REFUSED, TAMPERED, VARIANT, NOT_GRADED, OTHER)


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


@dataclass(frozen=True)
class LateEntry(lateness.Lateness):
    """What the rubric's late rule made of one graded submission (a :class:`~labkit.grading.store.late.Lateness`),
    named, as the instructor sees it."""

    student: str = ""

    @property
    def submitted(self):
        """When it was handed in; None when the time is unknown."""
        return self.time.when if self.time is not None else None

    @property
    def source(self):
        """Where the time came from (labkit.grading.store.late's ``FROM_...``), None when unknown."""
        return self.time.source if self.time is not None else None

    @property
    def late(self):
        """Late past the deadline and its grace (so penalised, unless it had no points)."""
        return self.units > 0

    @property
    def student_supplied(self):
        """Whether its time is the student's own word (``timestamp.txt``, the notebooks' file times), never the
        instructor's or the LMS's: :data:`labkit.grading.store.late.STUDENT_SUPPLIED`."""
        return self.source in lateness.STUDENT_SUPPLIED


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
    entries = (LateEntry(**vars(g.lateness), student=g.name) for g in sorted(graded, key=lambda g: g.name))
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

    @property
    def mine(self):
        return [pair[0] for pair in self.lines]

    @property
    def theirs(self):
        return [pair[1] for pair in self.lines]

    @property
    def matched(self):
        """The lines of the source shown as matched: those facing a line of the student's."""
        return {i for i, line in enumerate(self.theirs) if line}

    @classmethod
    def of(cls, grade):
        """The parts of `grade` held for a person."""
        return [
            cls(grade.name, number, str(part), str(what.get("definition", "")), str(what.get("source", "")),
                float(what.get("share", 0) or 0), released,
                tuple(tuple(map(str, pair)) for pair in what.get("lines", ()) if len(pair) == 2))
            for number, part, what, released in grade.held()
        ]  # fmt: skip


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
    return read_results([folder], rubric_for([folder], rubric, "the class report"))


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
    return None if verdict is None else [part.as_dict() for part in verdict.parts]


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


@dataclass
class _Tally:
    """What :func:`summarise` gathers while it reads the parts of each graded submission."""

    failed: dict  # student -> "exercise part" labels of the parts attempted and failed
    not_done: defaultdict = field(default_factory=lambda: defaultdict(int))
    slips: defaultdict = field(default_factory=lambda: defaultdict(list))  # (number, index, part, hint) -> students
    problems: defaultdict = field(default_factory=lambda: defaultdict(list))  # (kind, student) -> texts

    def part(self, grade, number, name, index, check):
        """What became of part `name` of exercise `number` in `grade`, noted where the page shows it."""
        outcome = check_outcome(check) if check else NOT_DONE
        if outcome == NOT_DONE:
            self.not_done[grade.name] += 1
        elif outcome != PASSED:
            self.failed[grade.name].append(f"{number} {name}")
        if outcome == SLIP:
            hint = one_line(check.get("hint") or "", MAX_TEXT) or _failed_text(check, number)
            self.slips[(number, index, name, hint)].append(grade.name)
        elif outcome not in (PASSED, NOT_DONE):
            self.problems[(outcome, grade.name)].append(_failed_text(check, number))
        return outcome

    def exercise(self, rubric, number, graded):
        """The class's rate of exercise `number` and of each of its parts."""
        names = _part_names(rubric, number, graded)
        counts = {name: defaultdict(int) for name in names}
        found = attempted = passed = 0
        for grade in graded:
            checks = _checks(grade, number)
            if checks is None:
                for name in names:
                    counts[name]["missing"] += 1
                continue
            found += 1
            by_name = {one_line(c.get("name", "?"), MAX_TEXT): c for c in checks}
            outcomes = [self.part(grade, number, name, i, by_name.get(name) or {}) for i, name in enumerate(names)]
            for name, outcome in zip(names, outcomes):
                counts[name][outcome] += 1
            attempted += any(outcome != NOT_DONE for outcome in outcomes)
            passed += bool(outcomes) and all(outcome == PASSED for outcome in outcomes)
        weights = _weights(rubric, number)
        parts = [
            PartRate(number, name, weights.get(name, 0.0), c[PASSED], c[SLIP], sum(c[kind] for kind in KINDS),
                     c[NOT_DONE], c["missing"])
            for name, c in counts.items()
        ]  # fmt: skip
        return ExerciseRate(number, len(graded), found, attempted, passed), parts

    def run_problems(self, grades):
        """The problems of the run itself: grading that failed, and each notebook's (a stub's cell is counted per
        part, as not done)."""
        for grade in grades:
            if not grade.graded:
                self.problems[(NOT_GRADED, grade.name)].append(one_line(grade.failure, MAX_TEXT))
            for text in grade.problems if grade.graded else ():
                for kind, line in problem_kinds(text):
                    if kind != NOT_DONE:
                        self.problems[(kind, grade.name)].append(line)

    def by_kind(self):
        """Each kind's problems, by student."""
        found = {kind: [] for kind in KINDS}
        for (kind, student), texts in sorted(self.problems.items()):
            found[kind].append(Problem(kind, student, tuple(dict.fromkeys(texts))))
        return {kind: rows for kind, rows in found.items() if rows}

    def slip_list(self):
        """The slips, most frequent first."""
        ordered = sorted(self.slips.items(), key=lambda item: (-len(set(item[1])), item[0][0], item[0][1], item[0][3]))
        return [Slip(number, name, hint, tuple(sorted(set(who)))) for (number, _, name, hint), who in ordered]

    def most_failed(self, totals):
        struggles = (
            Struggle(name, totals[name], tuple(labels), self.not_done[name])
            for name, labels in self.failed.items()
            if labels
        )
        return sorted(struggles, key=lambda s: (-len(s.failed), s.total, s.student))[:MOST_FAILED]


def _checked(grades):
    """`grades` as a list, refused when empty, not SubmissionGrade objects or scored under several rubrics."""
    grades = list(grades)
    if not grades:
        raise InputError("there are no submissions to report on: grade some first (`labkit grade`).")
    for grade in grades:
        if not isinstance(grade, SubmissionGrade):
            raise InputError(
                f"a class report is made of SubmissionGrade objects (labkit.grading.store.report); got "
                f"{type(grade).__name__}: read a run's results with labkit.grading.reports.class_report.read."
            )
    if any(grade.rubric != grades[0].rubric for grade in grades):
        raise InputError("the grades are scored under different rubrics: read them all with one rubric.")
    return grades


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
    submissions = _checked(grades)
    rubric = submissions[0].rubric
    graded = [g for g in submissions if g.graded]
    tally = _Tally({g.name: [] for g in graded})
    exercises, parts = [], []
    for number in rubric.graded:
        rate, part_rates = tally.exercise(rubric, number, graded)
        exercises.append(rate)
        parts += part_rates
    tally.run_problems(submissions)
    totals = {g.name: g.total for g in graded}
    return ClassSummary(
        rubric=rubric,
        totals=totals,
        not_graded={g.name: g.failure for g in submissions if not g.graded},
        exercises=exercises,
        parts=parts,
        slips=tally.slip_list(),
        problems=tally.by_kind(),
        most_failed=tally.most_failed(totals),
        seeds=sorted({g.seed for g in submissions if isinstance(g.seed, int)}),
        late=_late_summary(rubric, graded),
        copies=find_copies(submissions),
        held=[held for g in graded for held in Held.of(g)],
    )


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


def histogram_of_totals(summary: ClassSummary) -> tuple[str, list[tuple[float, float, int]]]:
    """The histogram of the graded totals: (base64 PNG, [(low, high, count)]).

    Parameters
    ----------
    summary : ClassSummary

    Returns
    -------
    tuple
        The picture, with a dashed line at full credit, and the bins it shows (the page says them in words
        and as a table).
    """
    import numpy as np
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    totals, full_credit = list(summary.totals.values()), summary.rubric.full_credit
    edges = _bins(totals, summary.rubric.maximum)
    counts, _ = np.histogram(totals, bins=edges)
    figure = Figure(figsize=(6.4, 2.8), layout="constrained")
    axes = figure.subplots()
    axes.hist(totals, bins=edges, color="#2b5797", edgecolor="white")
    axes.axvline(full_credit, color="black", linestyle="--", linewidth=1.2)
    axes.annotate(f"full credit {points_text(full_credit)}", (full_credit, 1.0), xycoords=("data", "axes fraction"),
                  xytext=(0, 3), textcoords="offset points", ha="center", va="bottom", fontsize=9)  # fmt: skip
    axes.set_xlabel("total points")
    axes.set_ylabel("submissions")
    axes.yaxis.set_major_locator(MaxNLocator(integer=True))
    axes.set_xlim(edges[0], edges[-1])
    return _png(figure), [(float(lo), float(hi), int(n)) for lo, hi, n in zip(edges[:-1], edges[1:], counts)]


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


def pass_rate_figures(summary: ClassSummary) -> list[str]:
    """Bar charts of the pass rates as base64 PNGs: the exercises', then the parts' (the page gives every rate
    in numbers in their alt text).

    Parameters
    ----------
    summary : ClassSummary

    Returns
    -------
    list of str
    """
    exercises, parts = summary.exercises, summary.parts
    return [
        _bars(
            [f"exercise {e.exercise}" for e in exercises], [e.rate for e in exercises], [e.attempted for e in exercises]
        ),
        _bars([p.label for p in parts], [p.rate for p in parts], [p.attempted for p in parts]),
    ]


# ---------------------------------------------------------------------------------------------- the page


def _text(value, limit=MAX_TEXT):
    """A submission's (or the grader's) text as the page shows it: printable, one line, bounded."""
    return one_line(value, limit)


def _who(name):
    """A submission's name as the page shows it: shortened with a hash of the whole name, so two names sharing a
    beginning never look alike (:func:`labkit.grading.store.names.shown_name`)."""
    return shown_name(name, MAX_NAME)


def _code_rows(lines, shared):
    """A side of a pair of code as (gutter, line, shared) rows, bounded, and how many lines are left out."""
    width = len(str(min(len(lines), MAX_LINES)))
    rows = [
        (f"{n + 1:>{width}} {'=' if n in shared else ' '} ", printable(str(line)).replace("\t", "    ")
         .replace("\n", " ")[:MAX_LINE], n in shared)
        for n, line in enumerate(lines[:MAX_LINES])
    ]  # fmt: skip
    return rows, max(len(lines) - MAX_LINES, 0)


def _shared(indices, lines):
    """The indices of a pair's shared lines that are lines of `lines`."""
    return {i for i in indices if isinstance(i, int) and 0 <= i < len(lines)}


def _totals(summary):
    """The graded totals in figures, for the table and the histogram's alt text."""
    totals, rubric = list(summary.totals.values()), summary.rubric
    image, bins = histogram_of_totals(summary)
    quartiles = statistics.quantiles(totals, n=4, method="inclusive") if len(totals) > 1 else totals * 3
    return {
        "image": image, "bins": bins, "count": len(totals), "median": statistics.median(totals),
        "mean": statistics.fmean(totals), "lowest": min(totals), "highest": max(totals),
        "quartiles": ", ".join(map(points_text, quartiles)),
        "full": sum(t >= rubric.full_credit for t in totals), "largest": max(bins, key=lambda b: (b[2], -b[0])),
    }  # fmt: skip


def render(
    summary: ClassSummary,
    pairs: Iterable[Pair] | None = None,
    *,
    threshold: float = DEFAULT_THRESHOLD,
    similarity_note: str | None = None,
) -> str:
    """The class report as one HTML document (a string), figures inline (``templates/class_report.html``).

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
    copies = summary.copies or Copies()
    return pages.render(
        "class_report.html",
        s=summary,
        rubric=summary.rubric,
        late=summary.late,
        limits={name: value for name, value in globals().items() if name.startswith("MAX_")},
        totals=_totals(summary) if summary.totals else None,
        rate_figures=pass_rate_figures(summary) if summary.totals else None,
        rate_text=_rate_text,
        held_threshold=THRESHOLD,
        copy_lines=copies.holder_lines(),
        copies_marked=copies.marked,
        pair_rows=None if pairs is None else pair_rows(pairs, copies.functions),
        threshold=threshold,
        similarity_note=similarity_note,
        text=_text,
        who=_who,
        points=points_text,
        time_text=lateness.time_text,
        duration_text=lateness.duration_text,
        code_rows=_code_rows,
        shared=_shared,
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
