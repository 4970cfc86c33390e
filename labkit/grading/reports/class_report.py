"""The class report: one self-contained HTML page about a grading run (``labkit report OUT``).

:func:`read` reads a run's results back (a merged run's too), :func:`summarise` counts what the class did and
:func:`write` renders ``templates/class_report.*`` into ``OUT/report.html``. Figures are inline PNGs drawn on
matplotlib's Agg canvas; every text a submission could have influenced is made printable and bounded, then escaped.
"""

from __future__ import annotations

import base64
import io
import os
import statistics
from collections import Counter, defaultdict, namedtuple
from collections.abc import Iterable
from dataclasses import dataclass, field
from datetime import timedelta
from pathlib import Path

import numpy as np

from ...errors import InputError
from ...exercises.result import (
    CRASH,
    ERROR,
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
from ..store import record as records
from ..store.names import shown_name
from ..store.report import SubmissionGrade, one_line, printable, read_results
from ..store.report import problem_kinds as kinds_of
from ..store.rubric import Rubric
from ..store.text import points_text
from ..submission.known import THRESHOLD
from .similarity import DEFAULT_THRESHOLD, Copies, Pair, find_copies, pair_rows, unavailable

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
# the problem a part that failed with an error met: the first of these among its failed steps' kinds
OUTCOMES = (REFUSED, TAMPERED, TIMEOUT, CRASH, RAISED, OTHER)
# the kinds of problem, in the order the page lists them (its words for each are in the template)
KINDS = (TIMEOUT, CRASH, RAISED, REFUSED, TAMPERED, VARIANT, NOT_GRADED, OTHER)
BLUE = "#2b5797"


class _Rated:
    @property
    def rate(self):
        """The share of the submissions that attempted it which passed it (None when nobody attempted it)."""
        return self.passed / self.attempted if self.attempted else None


@dataclass(frozen=True)
class ExerciseRate(_Rated):
    """How the class did on one exercise: of the graded submissions, how many attempted and passed it."""

    exercise: int
    graded: int
    found: int  # submissions that have the exercise
    attempted: int  # that have something other than stubs in it (a part passed, slipped or met a problem)
    passed: int  # that passed every part


@dataclass(frozen=True)
class PartRate(_Rated):
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


# one hint of one part, and the students whose work failed the part with it
Slip = namedtuple("Slip", "exercise part hint students")
# what went wrong for one student, of one kind (its texts as the grader worded them)
Problem = namedtuple("Problem", "student texts")
# a student's failed parts: "exercise part" labels of those attempted and failed, and how many not done
Struggle = namedtuple("Struggle", "student total failed not_done")


@dataclass(frozen=True)
class LateEntry(lateness.Lateness):
    """What the rubric's late rule made of one graded submission, named."""

    student: str = ""


@dataclass(frozen=True)
class LateSummary:
    """The class under the rubric's ``[late]`` table: one :class:`LateEntry` per graded submission, by name, and
    the groups the page lists (see :meth:`of`)."""

    rule: lateness.Late
    entries: tuple
    late: list  # latest first
    on_time: list
    within_grace: list
    unknown: list
    extended: list
    student_supplied: list  # known times the student supplied (:data:`labkit.grading.store.late.STUDENT_SUPPLIED`)
    penalty: float
    unused_extensions: list  # names in ``[late.extensions]`` no graded submission has (a typo in the rubric?)

    @classmethod
    def of(cls, rubric, graded):
        """The late view of `graded`; None when the rubric has no ``[late]`` table."""
        if rubric.late is None:
            return None
        entries = [LateEntry(**vars(g.lateness), student=g.name) for g in sorted(graded, key=lambda g: g.name)]
        on_time = [e for e in entries if e.known and e.units <= 0]
        names = {e.student for e in entries}
        return cls(
            rule=rubric.late,
            entries=tuple(entries),
            late=sorted((e for e in entries if e.units > 0), key=lambda e: (-e.late_by, e.student)),
            on_time=on_time,
            within_grace=[e for e in on_time if e.late_by > timedelta(0)],
            unknown=[e for e in entries if not e.known],
            extended=[e for e in entries if e.extended],
            student_supplied=[e for e in entries if e.known and e.time.source in lateness.STUDENT_SUPPLIED],
            penalty=round(sum(e.penalty for e in entries), 2),
            unused_extensions=[name for name, _ in rubric.late.extensions if name not in names],
        )


@dataclass(frozen=True)
class Held:
    """A part whose check passed but whose code is mostly a known source's (:mod:`labkit.grading.submission.known`),
    held for a person until the rubric's ``[held]`` table releases it."""

    student: str
    exercise: int
    part: str
    definition: str  # the notebook's definition that matched
    source: str  # what it matched
    share: float
    released: bool
    mine: tuple  # the student's lines
    theirs: tuple  # the source's lines, each facing one of the student's ("" where none does)

    @property
    def matched(self):
        return {i for i, line in enumerate(self.theirs) if line}

    @classmethod
    def of(cls, grade):
        """The parts of `grade` held for a person."""
        found = []
        for number, part, what, released in grade.held():
            lines = [tuple(map(str, pair)) for pair in what.get("lines", ()) if len(pair) == 2]
            found.append(cls(grade.name, number, str(part), str(what.get("definition", "")),
                             str(what.get("source", "")), float(what.get("share", 0) or 0), released,
                             tuple(mine for mine, _ in lines), tuple(theirs for _, theirs in lines)))  # fmt: skip
        return found


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
    seeds: list
    late: LateSummary | None  # when the rubric has a [late] table
    held: list  # Held
    copies: Copies  # whose data, solution markers, each student's graded functions


def read(folder: str | Path, rubric: Rubric | None = None) -> list[SubmissionGrade]:
    """The grades, in name order, of a grading run's ``--out`` folder (``labkit grade`` or ``labkit merge``),
    scored under `rubric`: the recorded one when None; another one is refused.

    Raises
    ------
    ValueError
        If the folder does not exist or holds too many or no results, or a result is not labkit's.

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
    return read_results([folder], records.rubric_for([folder], rubric, "the class report"))


def check_outcome(check: dict) -> str:
    """What became of one part in one submission (`check`, one entry of an exercise's ``checks`` in a result):
    ``"passed"``, ``"slip"``, ``"not done"``, ``"another variant"`` or a problem's kind (:data:`OUTCOMES`;
    ``"other"``: a fault of the check itself).

    Examples
    --------
    >>> check_outcome({"passed": False, "hint": "h", "steps": [{"step": "s", "passed": False,
    ...     "detail": "not implemented yet", "kind": "not done"}]})
    'not done'
    >>> check_outcome({"passed": False, "hint": "h", "steps": [{"step": "s", "passed": False,
    ...     "detail": "ran past the time limit"}]})  # the words alone: no kind, so the check's slip
    'slip'
    """
    kind = part_kind(check)  # the one place a part's kind is decided: the feedback and labkit handin agree
    if kind != ERROR:
        return kind
    kinds = {s.get("kind") for s in check["steps"] if isinstance(s, dict) and not s.get("passed")}
    return next((kind for kind in OUTCOMES if kind in kinds), OTHER)


def problem_kinds(problem: str) -> list[tuple[str, str]]:
    """The (kind, description) pairs of one of a submission's ``problems``, each description one printable
    line; the kinds are the codes the grader set (:class:`~labkit.grading.store.report.ProblemText`), "other"
    for a bare text.

    Examples
    --------
    >>> from labkit.grading.store.report import ProblemText
    >>> problem_kinds(ProblemText.one("a.ipynb: stopped after the submission's time limit of 600 s.", "timeout"))
    [('timeout', "a.ipynb: stopped after the submission's time limit of 600 s.")]
    >>> problem_kinds("a.ipynb: it ran past the time limit")
    [('other', 'a.ipynb: it ran past the time limit')]
    """
    return [(kind, one_line(description, MAX_TEXT)) for kind, description in kinds_of(problem)]


def _failed_text(check, number):
    details = [
        f"{one_line(s.get('step', ''), 100)}: {one_line(s.get('detail', ''), MAX_TEXT)}"
        for s in check["steps"]
        if not s.get("passed")
    ]
    return one_line(f"exercise {number}, {check.get('name', '?')}: " + ("; ".join(details) or "failed"), MAX_TEXT)


@dataclass
class _Tally:
    """What :func:`summarise` gathers while it reads the parts of each graded submission."""

    failed: dict  # student -> "exercise part" labels of the parts attempted and failed
    not_done: Counter = field(default_factory=Counter)
    slips: defaultdict = field(default_factory=lambda: defaultdict(list))  # (number, index, part, hint) -> students
    problems: defaultdict = field(default_factory=lambda: defaultdict(list))  # (kind, student) -> texts

    def part(self, grade, number, name, index, check):
        """What became of part `name` of exercise `number` in `grade`, noted where the page shows it."""
        outcome = check_outcome(check)
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
        """The class's rate of exercise `number` and of each of its parts (as declared, then any other the
        results hold)."""
        declared = getattr(rubric.registry.exercises.get(number), "parts", ())
        found = [
            (g, {one_line(part.name, MAX_TEXT): part.as_dict() for part in g.results[number].parts})
            for g in graded
            if number in g.results
        ]
        names = list(dict.fromkeys([*(part.name for part in declared),
                                    *(name for _, checks in found for name in checks)]))  # fmt: skip
        counts = {name: Counter(missing=len(graded) - len(found)) for name in names}
        attempted = passed = 0
        for grade, checks in found:
            outcomes = [self.part(grade, number, n, i, checks.get(n, {})) for i, n in enumerate(names)]
            for name, outcome in zip(names, outcomes):
                counts[name][outcome] += 1
            attempted += any(outcome != NOT_DONE for outcome in outcomes)
            passed += bool(outcomes) and all(outcome == PASSED for outcome in outcomes)
        total = sum(part.weight for part in declared) or 1
        weights = {part.name: rubric.points.get(number, 0) * part.weight / total for part in declared}
        parts = [
            PartRate(number, name, weights.get(name, 0.0), c[PASSED], c[SLIP], sum(c[kind] for kind in KINDS),
                     c[NOT_DONE], c["missing"])
            for name, c in counts.items()
        ]  # fmt: skip
        return ExerciseRate(number, len(graded), len(found), attempted, passed), parts

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
        found = {kind: [] for kind in KINDS}
        for (kind, student), texts in sorted(self.problems.items()):
            found[kind].append(Problem(student, tuple(dict.fromkeys(texts))))
        return {kind: rows for kind, rows in found.items() if rows}

    def slip_list(self):
        ordered = sorted(self.slips.items(), key=lambda item: (-len(set(item[1])), item[0][0], item[0][1], item[0][3]))
        return [Slip(number, name, hint, tuple(sorted(set(who)))) for (number, _, name, hint), who in ordered]

    def most_failed(self, totals):
        struggles = (Struggle(name, totals[name], tuple(labels), self.not_done[name])
                     for name, labels in self.failed.items() if labels)  # fmt: skip
        return sorted(struggles, key=lambda s: (-len(s.failed), s.total, s.student))[:MOST_FAILED]


def summarise(grades: Iterable[SubmissionGrade], students: dict | None = None) -> ClassSummary:
    """Count what a class did: totals, pass rates, slips, problems and the most failed parts, of `grades` (one
    SubmissionGrade per submission, all scored under one rubric, as :func:`read` gives them); `students` is the
    run's variant data, for the copies (:func:`~labkit.grading.reports.similarity.find_copies`).

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
    submissions = list(grades)
    if not submissions:
        raise InputError("there are no submissions to report on: grade some first (`labkit grade`).")
    for grade in submissions:
        if not isinstance(grade, SubmissionGrade):
            raise InputError(
                f"a class report is made of SubmissionGrade objects (labkit.grading.store.report); got "
                f"{type(grade).__name__}: read a run's results with labkit.grading.reports.class_report.read."
            )
    rubric = submissions[0].rubric
    if any(grade.rubric != rubric for grade in submissions):
        raise InputError("the grades are scored under different rubrics: read them all with one rubric.")
    graded = [g for g in submissions if g.graded]
    tally = _Tally({g.name: [] for g in graded})
    rates = [tally.exercise(rubric, number, graded) for number in rubric.graded]
    tally.run_problems(submissions)
    totals = {g.name: g.total for g in graded}
    return ClassSummary(
        rubric=rubric,
        totals=totals,
        not_graded={g.name: g.failure for g in submissions if not g.graded},
        exercises=[exercise for exercise, _ in rates],
        parts=[part for _, parts in rates for part in parts],
        slips=tally.slip_list(),
        problems=tally.by_kind(),
        most_failed=tally.most_failed(totals),
        seeds=sorted({g.seed for g in submissions if isinstance(g.seed, int)}),
        late=LateSummary.of(rubric, graded),
        copies=find_copies(submissions, students),
        held=[held for g in graded for held in Held.of(g)],
    )


def _figure(width, height):
    """A matplotlib Figure and its one Axes, on no pyplot state (the figure is garbage once drawn)."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    return figure, figure.subplots()


def _png(figure):
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100, metadata={"Software": None})
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def _bins(totals, maximum):
    """Bin edges of a round width, about twenty bins from 0 to the largest possible total."""
    top = max([float(maximum), *map(float, totals), 1.0])
    width = next(w for w in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 10**9) if top / w <= 25)
    return np.arange(int(np.ceil(top / width)) + 1) * float(width)


def _histogram(summary):
    """The graded totals' histogram (a dashed line at full credit) as a base64 PNG, and its [(low, high, count)]."""
    from matplotlib.ticker import MaxNLocator

    totals, full_credit = list(summary.totals.values()), summary.rubric.full_credit
    edges = _bins(totals, summary.rubric.maximum)
    figure, axes = _figure(6.4, 2.8)
    counts, _, _ = axes.hist(totals, bins=edges, color=BLUE, edgecolor="white")
    axes.axvline(full_credit, color="black", linestyle="--", linewidth=1.2)
    axes.annotate(f"full credit {points_text(full_credit)}", (full_credit, 1.0), xycoords=("data", "axes fraction"),
                  xytext=(0, 3), textcoords="offset points", ha="center", va="bottom", fontsize=9)  # fmt: skip
    axes.set(xlabel="total points", ylabel="submissions", xlim=(edges[0], edges[-1]))
    axes.yaxis.set_major_locator(MaxNLocator(integer=True))
    return _png(figure), [(float(lo), float(hi), int(n)) for lo, hi, n in zip(edges[:-1], edges[1:], counts)]


def _rate_text(rate, attempted):
    return "nobody attempted it" if rate is None else f"{rate:.0%} of {attempted}"


def _bars(rated):
    """Bars of the pass rates of `rated` (ExerciseRate or PartRate), each labelled, its rate written beside it."""
    labels = [f"{r.exercise} {r.part}" if isinstance(r, PartRate) else f"exercise {r.exercise}" for r in rated]
    figure, axes = _figure(7.5, 0.9 + 0.26 * len(labels))
    positions = range(len(labels))
    axes.barh(positions, [100 * (r.rate or 0.0) for r in rated], color=BLUE, height=0.7)
    for y, r in zip(positions, rated):
        axes.text(100 * (r.rate or 0) + 1, y, _rate_text(r.rate, r.attempted), va="center", fontsize=8, color="black")
    axes.set_yticks(positions, [one_line(label, 40) for label in labels], fontsize=8)
    axes.invert_yaxis()
    axes.set_xticks([0, 25, 50, 75, 100], ["0%", "25%", "50%", "75%", "100%"])
    axes.set(xlabel="passed, of the submissions that attempted it", xlim=(0, 125))
    return _png(figure)


def _shared(indices, lines):
    """The indices of a pair's shared lines that are lines of `lines`."""
    return {i for i in indices if isinstance(i, int) and 0 <= i < len(lines)}


def _totals(summary):
    """The graded totals in figures, for the table and the histogram's alt text."""
    totals = list(summary.totals.values())
    image, bins = _histogram(summary)
    quartiles = statistics.quantiles(totals, n=4, method="inclusive") if len(totals) > 1 else totals * 3
    return {
        "image": image, "bins": bins, "count": len(totals), "median": statistics.median(totals),
        "mean": statistics.fmean(totals), "lowest": min(totals), "highest": max(totals),
        "quartiles": ", ".join(map(points_text, quartiles)),
        "full": sum(t >= summary.rubric.full_credit for t in totals),
        "largest": max(bins, key=lambda b: (b[2], -b[0])),
    }  # fmt: skip


def render(
    summary: ClassSummary,
    pairs: Iterable[Pair] | None = None,
    *,
    threshold: float = DEFAULT_THRESHOLD,
    similarity_note: str | None = None,
) -> str:
    """The class report as one HTML document, figures inline (``templates/class_report.html``): `pairs` are the
    similar code to show side by side (None when the search was not made), listed from similarity `threshold`;
    `similarity_note` says why `pairs` is None (by default, why the search cannot run here, if it cannot)."""
    if not isinstance(summary, ClassSummary):
        raise InputError(f"render takes the ClassSummary of summarise(grades); got {type(summary).__name__}.")
    pairs = _check_pairs(pairs)
    if pairs is None and similarity_note is None:
        similarity_note = unavailable()
    return pages.render(
        "class_report.html",
        s=summary,
        limits={name: value for name, value in globals().items() if name.startswith("MAX_")},
        totals=_totals(summary) if summary.totals else None,
        rate_figures=[_bars(summary.exercises), _bars(summary.parts)] if summary.totals else None,
        rate_text=_rate_text,
        held_threshold=THRESHOLD,
        pair_rows=None if pairs is None else pair_rows(pairs, summary.copies.functions),
        threshold=threshold,
        similarity_note=similarity_note,
        text=lambda value, limit=MAX_TEXT: one_line(value, limit),
        who=lambda name: shown_name(name, MAX_NAME),
        points=points_text,
        time_text=lateness.time_text,
        duration_text=lateness.duration_text,
        printable=printable,
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


def write(
    out_dir: str | Path,
    grades: Iterable[SubmissionGrade],
    pairs: Iterable[Pair] | None = None,
    *,
    threshold: float = DEFAULT_THRESHOLD,
) -> Path:
    """Write ``report.html`` into a grading run's ``--out`` folder `out_dir`, through a temporary file renamed over
    an earlier report, and return its path; the folder's other files are neither read nor touched. `grades` are the
    class (:func:`read` reads them), `pairs` and `threshold` (in (0, 1]) as for :func:`render`.

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
    try:
        students = records.read(out).variants.get("students", {})  # each student's variant data, for the copies
    except ValueError:
        students = {}  # no variants or no record
    page = render(summarise(grades, students), pairs, threshold=float(threshold))
    records.replace_text(target, page, mode=0o644)
    return target
