"""A student's feedback, in the order a student reads it: the total first, then what to fix, errors last.

:func:`build` turns a :class:`~labkit.grading.store.report.SubmissionGrade` into a :class:`Feedback`, the one
model both forms are rendered from by autoescaped Jinja templates (:mod:`labkit.grading.pages`): :func:`text`
(``feedback/<submission>.txt``) and :func:`html` (``feedback/<submission>.html``, one self-contained page).
Every text in the model is printable and bounded (:func:`one_line`); a part's kind is
:func:`labkit.exercises.result.part_kind`'s, as in the class report and ``labkit handin``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ...exercises.result import ERROR, HELD, NOT_DONE, OTHER, PASSED, VARIANT, part_kind
from .model import ItemKey
from .text import one_line, points_text, printable

NO_ANSWER = "YOUR ANSWER HERE"  # an answer in words as released
DONE, PARTLY = "done", "partly"  # an exercise's status in the score table (or NOT_DONE, "excused", "held")
STUB_CELL = re.compile(r"raised NotImplementedError$")


@dataclass(frozen=True)
class Part:
    """One part of an exercise as the feedback shows it: its kind (:data:`labkit.exercises.result.PART_KINDS`),
    the points it is worth, its failed steps ((step, detail) pairs), the hint, and extra lines (a held part's)."""

    name: str
    kind: str
    worth: float
    failed: tuple = ()
    hint: str = ""
    notes: tuple = ()
    figure: tuple = ()  # the student's own plot that the part judged: ((svg points, joined), ...), see _figure


@dataclass(frozen=True)
class Exercise:
    """One graded exercise: its points, what it is worth, its status, and its parts."""

    number: int
    points: float
    worth: float
    status: str
    parts: tuple = ()
    other_branch: bool = False  # of the branch that is not the better one (extra credit at most)

    @property
    def to_fix(self):
        """The parts the student has to look at: every part that did not pass, and a part a person looked at."""
        return tuple(part for part in self.parts if part.kind != PASSED or part.notes)


@dataclass(frozen=True)
class Feedback:
    """Everything a student's feedback says, in reading order."""

    name: str
    total: str  # "32.5 / 40 points", or "not graded"
    headline: tuple  # lines after the total: extra credit, the late penalty
    exercises: tuple = ()
    summary: tuple = ()  # the branch that counts, extra credit, the late rule's lines
    answers: tuple = ()  # (title, marked, lines, comment) of each answer in words
    errors: tuple = ()  # one line per error of a cell the student changed, or another problem
    stubs: int = 0  # cells that still raise NotImplementedError
    seed: int | None = None
    failure: str = ""


def blank(answer) -> bool:
    """Whether an answer in words is none: empty, or left as released ("YOUR ANSWER HERE")."""
    return str(answer or "").strip().upper() in ("", NO_ANSWER)


def build(grade) -> Feedback:
    """The feedback of one graded (or ungradable) submission."""
    name = one_line(grade.name, 120)
    if not grade.graded:
        return Feedback(name, "not graded", (), failure=one_line(grade.failure, 500))
    score, rubric = grade.score, grade.rubric
    other = _other_branch(rubric, score.branch)
    exercises = tuple(_exercise(grade, number, number in other) for number in rubric.graded)
    total = f"{points_text(grade.total)} / {points_text(score.full_credit)} points"
    return Feedback(
        name, total, _headline(grade), exercises, _summary(grade), _answers(grade), *_run_errors(grade), grade.seed
    )


def _other_branch(rubric, branch):
    """The exercises of the branches that do not count (none when no branch earned points yet)."""
    if not branch or branch == "none":
        return set()
    return {n for b in rubric.branches if b.name != branch for n in b.exercises}


def _headline(grade):
    score, lateness = grade.score, grade.lateness
    lines = []
    if score.extra_total:
        lines.append(f"including {points_text(score.extra_total)} extra credit")
    if lateness is not None and lateness.penalty:
        lines.append(
            f"{points_text(lateness.penalty)} off for late work ({points_text(score.total)} before the penalty)"
        )
    return tuple(lines)


def _exercise(grade, number, other_branch):
    points, worth = grade.points.get(number, 0.0), grade.rubric.worth(number)
    if number in grade.excused:
        return Exercise(number, 0.0, 0.0, "excused")
    verdict = grade.results.get(number)
    if verdict is None:  # no notebook has its section ("## Exercise N"), or it never ran
        return Exercise(number, 0.0, worth, NOT_DONE, other_branch=other_branch)
    parts = tuple(_part(grade, number, part, verdict.parts) for part in verdict.parts)
    kinds = {part.kind for part in parts}
    if worth and points >= worth - 1e-9:
        status = DONE
    elif points <= 0 and kinds <= {NOT_DONE}:
        status = NOT_DONE
    else:
        status = PARTLY
    if HELD in kinds:
        status = HELD
    return Exercise(number, points, worth, status, parts, other_branch=other_branch)


def _part(grade, number, part, parts):
    released = bool(part.held) and grade.released(number, part.name)
    kind = part_kind(part.as_dict(), released or not part.held)
    total = sum(p.weight for p in parts) or 1
    worth = grade.rubric.points[number] * (part.weight or 0) / total
    failed = tuple(
        (one_line(s.step, 300), one_line(s.detail, 1000)) for s in part.failed if not (released and s.step == HELD_STEP)
    )
    notes: tuple = ()
    if part.held and part.passed:
        notes = tuple(line.strip() for line in _held_lines(part, released))
        mark = grade.marks.get(ItemKey.held(number, part.name))
        if mark and mark.comment:
            notes += (f"your instructor: {one_line(mark.comment, 1000)}",)
    hint = one_line(part.hint, 1000) if kind not in (PASSED, HELD) else ""
    figure = _figure(part.figure) if kind not in (PASSED, HELD, NOT_DONE) else ()
    return Part(one_line(part.name, 100), kind, worth, failed, hint, notes, figure)


FIGURE_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000")  # Okabe and Ito
FIGURE_BOX = (320.0, 200.0, 10.0)  # the feedback page's picture of a plot: width, height and margin, in SVG units


def _figure(lines) -> tuple:
    """A plot the grader read (:func:`labkit.plotdata.figure_data`) as SVG points in :data:`FIGURE_BOX`, the data's
    range filling it with y upwards: ``((points, joined), ...)``; nothing for what is not such data. At most 8
    lines of 300 finite points are taken, whatever the result file holds."""
    if not isinstance(lines, list):
        return ()
    kept = []
    for line in lines[:8]:
        x, y = (_numbers(line.get(key)) if isinstance(line, dict) else [] for key in ("x", "y"))
        if x and len(x) == len(y):
            kept.append((x, y, line.get("joined") is not False))
    if not kept:
        return ()
    xs, ys = [v for x, _, _ in kept for v in x], [v for _, y, _ in kept for v in y]
    width, height, margin = FIGURE_BOX
    x0, y0 = min(xs), min(ys)
    sx = (width - 2 * margin) / ((max(xs) - x0) or 1.0)
    sy = (height - 2 * margin) / ((max(ys) - y0) or 1.0)
    return tuple(
        (" ".join(f"{margin + (a - x0) * sx:.1f},{height - margin - (b - y0) * sy:.1f}" for a, b in zip(x, y)), joined)
        for x, y, joined in kept
    )


def _numbers(values) -> list:
    """The finite numbers of a list read back from a result file (at most 300), or [] when it holds anything else."""
    if not isinstance(values, list) or not all(type(v) in (int, float) and math.isfinite(v) for v in values[:300]):
        return []
    return [float(v) for v in values[:300]]


def _summary(grade) -> tuple:
    """The lines under the score table: the required exercises, the branch that counts, extra credit, the late
    rule's line, the total, then the rubric in words."""
    score, rubric, lateness = grade.score, grade.rubric, grade.lateness
    lines = [
        f"Exercises {', '.join(map(str, rubric.required))}: {points_text(score.required)} / "
        f"{points_text(sum(rubric.worth(n) for n in rubric.required if n not in grade.excused))}"
    ]
    if score.branch == "none":
        lines.append("Branch that counts: none yet (no exercise of either branch earned points)")
    elif score.branch:
        full = sum(rubric.worth(n) for n in next(b for b in rubric.branches if b.name == score.branch).exercises)
        lines.append(
            f"Branch that counts: {score.branch}, {points_text(score.counted)} / {points_text(full)} "
            "(the better of the branches)"
        )
    lines += [f"Extra credit, {what}: {points_text(value)}" for what, value in score.extra.items()]
    if lateness is not None and rubric.late is not None:
        lines.append(rubric.late.feedback(lateness))
    if lateness is not None and lateness.penalty:
        lines.append(
            f"Total: {points_text(lateness.total)} ({points_text(score.total)} less "
            f"{points_text(lateness.penalty)} for late work; full credit is {points_text(score.full_credit)})"
        )
    else:
        lines.append(f"Total: {points_text(score.total)} (full credit is {points_text(score.full_credit)})")
    return tuple("\n".join([*lines, rubric.describe()]).split("\n"))


def _answers(grade):
    found = []
    for grade_id, (number, what) in grade.rubric.registry.answers.items():
        if number not in grade.rubric.points or number not in grade.results:  # a notebook not handed in
            continue
        text = str(grade.answers.get(grade_id, "")).strip()
        empty = blank(text)
        mark, worth = grade.marks.get(ItemKey.of_answer(grade_id)), grade.rubric.answers.get(grade_id, 0.0)
        if mark is not None:
            marked = f"{points_text(mark.points)} / {points_text(worth)} points"
        elif empty:
            marked = "no answer" + (f", 0 / {points_text(worth)} points" if worth else "")
        else:
            marked = f"not marked yet, worth {points_text(worth)}" if worth else "not scored"
        lines = () if empty else tuple(one_line(line, 300) for line in text.splitlines()[:20])
        comment = one_line(mark.comment, 1000) if mark and mark.comment else ""
        found.append((f"Exercise {number}, {what}", marked, lines, comment))
    return tuple(found)


def _run_errors(grade) -> tuple[tuple, int]:
    """(one line per error of a cell the student changed or other problem, cells that still raise
    NotImplementedError): the cells of the release left as they were are not listed."""
    stubs, errors = 0, []
    for problem in grade.problems:
        for kind, line in problem_kinds(problem):
            if kind == NOT_DONE:
                stubs += bool(STUB_CELL.search(line))
            elif kind != VARIANT or line not in errors:
                errors.append(one_line(line, 1000))
    return tuple(errors), stubs


def text(feedback: Feedback) -> str:
    """The feedback as plain text (``templates/feedback.txt``): the total on the first line."""
    return printable(_render("feedback.txt", feedback))


def html(feedback: Feedback) -> str:
    """The feedback as one self-contained HTML page (no request, everything escaped)."""
    return _render("feedback.html", feedback)


def _render(template: str, feedback: Feedback) -> str:
    from ..pages import render

    values = {"points": points_text, "box": FIGURE_BOX, "colours": FIGURE_COLOURS}
    return render(template, feedback=feedback, kind_words=lambda kind: KIND_WORDS.get(kind, kind), **values)


KIND_WORDS = {ERROR: "an error", VARIANT: "another variant's data", HELD: "held for your instructor", PASSED: "passed"}


def problem_kinds(problem):
    """The kinds of a submission's problem: its own (a :class:`ProblemText`), or "other" for a bare text."""
    kinds = getattr(problem, "kinds", None)
    return kinds if kinds else ((OTHER, str(problem).split("\n")[0]),)


SIDE = 56  # characters of a line shown on each side of a held part's shared lines
# the step a held part fails until it is released (labkit.grading.submission.known)
HELD_STEP = "is the student's own code"


def _held_lines(part, released):
    """A held part's lines in the feedback: what it matched, and the shared lines side by side."""
    held = part.held
    source = one_line(held.get("source", "?"), 120)
    if released:
        lines = [f"    released: your instructor looked at {one_line(held.get('definition', '?'), 80)} and paid it."]
    else:
        lines = [
            f"    HELD: {float(held.get('share', 0)):.0%} of the code of {one_line(held.get('definition', '?'), 80)} "
            f"and what it calls is, names aside, the same as {source}'s; its points wait for your instructor.",
            f"    hint: {one_line(part.hint, 1000)}",
        ]
    pairs = [pair for pair in held.get("lines", ()) if isinstance(pair, (list, tuple)) and len(pair) == 2]
    if pairs and held.get("public", True):
        width = min(SIDE, max(len(one_line(mine, SIDE)) for mine, _ in pairs))
        lines.append(f"      {'yours':<{width}} | {source}")
        lines += [f"      {one_line(mine, SIDE):<{width}} | {one_line(theirs, SIDE)}" for mine, theirs in pairs]
    elif pairs:  # the solutions' lines are for the instructor's report only
        lines.append("      your lines that are the same, names aside:")
        lines += [f"      {one_line(mine, 2 * SIDE)}" for mine, _ in pairs]
    return lines
