"""The rubric: how the exercises' results become a grade.

A rubric is data, TOML (``rubric.toml`` beside this module is the lab's own, its comments a guide): the exercises
everyone does, alternative branches of which the best counts towards full credit and each other one is extra
credit, and extra-credit exercises. An exercise's points are its parts' weights (:mod:`labkit.exercises`) unless a
``[points]`` table scales them. Optional tables: ``[late]``, the deadline and what lateness costs
(:mod:`labkit.grading.store.late`); ``[held]``, parts held for a person (:mod:`labkit.grading.submission.known`)
that a person released, ``release = {"ada" = [2, 10]}``; ``[answers]``, the points a person gives answers in words
(``labkit mark``), ``exercise12-answer-1 = 2`` by nbgrader grade id. :func:`load` reads and validates a rubric;
:meth:`Rubric.score` turns the fractions of an exercise's parts that passed into a grade.
"""

import functools
import hashlib
import json
import tomllib
from dataclasses import dataclass, field, replace
from operator import methodcaller
from pathlib import Path

from ...errors import InputError
from ...exercises.registry import LAB, Registry
from ...exercises.registry import load as load_registry
from . import late as lateness
from .text import is_number, points_text

DEFAULT = Path(__file__).with_name("rubric.toml")


@dataclass(frozen=True)
class Branch:
    name: str
    exercises: tuple


@dataclass(frozen=True)
class Score:
    """One submission's grade under a rubric."""

    points: dict  # exercise -> points earned (rounded to 0.01)
    required: float
    branch: str  # the branch that counted ("" without branches, "none" if no branch earned points)
    counted: float  # its points
    extra: dict  # what earned extra credit -> points
    full_credit: float

    @property
    def extra_total(self):
        return round(sum(self.extra.values()), 2)

    @property
    def total(self):
        return round(self.required + self.counted + self.extra_total, 2)


@dataclass(frozen=True)
class Rubric:
    title: str
    points: dict  # exercise -> points
    required: tuple
    branches: tuple = ()
    branch_extra: float = 0.0
    extra_credit: tuple = ()
    source: str = field(default="the lab's rubric", compare=False)
    registry: Registry = field(default=LAB, compare=False, repr=False)  # the exercises it grades
    late: lateness.Late | None = None  # the deadline and what lateness costs, when the rubric has a [late] table
    data: dict | None = field(default=None, compare=False, repr=False)  # the parsed TOML it was read from, as JSON data
    text: str | None = field(default=None, compare=False, repr=False)  # the TOML text itself, when read from a file
    # submission name -> the exercises whose held parts a person released ([held] release)
    released: dict = field(default_factory=dict)
    answers: dict = field(default_factory=dict)  # answer grade id -> the points a person gives it ([answers])
    # answer grade id -> the rubric lines the marking page shows beside the model answer ([answers])
    answer_lines: dict = field(default_factory=dict, compare=False)

    def worth(self, number):
        """Exercise `number`'s points: its parts' and its answers' in words ([answers])."""
        answers = sum(p for grade_id, p in self.answers.items() if self.registry.answers[grade_id][0] == number)
        return self.points[number] + answers

    @property
    def graded(self):
        """Every exercise the rubric counts, in order."""
        return sorted(self.points)

    @property
    def full_credit(self):
        branch = sum(self.worth(n) for n in self.branches[0].exercises) if self.branches else 0
        return sum(self.worth(n) for n in self.required) + branch

    @property
    def maximum(self):
        """Full credit plus every extra credit."""
        return (
            self.full_credit
            + self.branch_extra * max(len(self.branches) - 1, 0)
            + sum(self.worth(n) for n in self.extra_credit)
        )

    @property
    def digest(self):
        """A fingerprint of what the rubric grades and how: its title, exercises, groups and points. Results of
        different digests are not merged (:func:`.report.read_results`); the ``[late]`` table is left out, since
        ``labkit merge`` applies the given rubric's late rule to the submission times the results carry."""
        described = {
            "title": self.title,
            "exercises": self.registry.source,
            "points": {str(n): p for n, p in self.points.items()},
            "required": list(self.required),
            "branches": [[b.name, list(b.exercises)] for b in self.branches],
            "branch_extra": self.branch_extra,
            "extra_credit": list(self.extra_credit),
        }
        if self.answers:  # left out without answer points, so earlier runs' digests stand
            described["answers"] = dict(self.answers)
        return hashlib.sha256(json.dumps(described, sort_keys=True).encode("utf-8")).hexdigest()[:16]

    def differences(self, other):
        """What makes `other` grade differently from this rubric: a list of short phrases, empty when the two
        grade alike (the same :attr:`digest` and the same ``[late]`` rule, extensions included)."""
        found = []
        if self.digest != other.digest:
            found.append("its exercises, groups or points")
        if self.late != other.late:
            found.append("its [late] table" if self.late is not None and other.late is not None else "a [late] table")
        if self.released != other.released:
            found.append("the held parts its [held] table releases")
        return found

    def score(self, fractions, marked=None, excused=()):
        """The grade for `fractions` (exercise -> share of its parts' weight that passed, 0..1), with the points
        a person `marked` (exercise -> points of its answers in words) and the exercises `excused` (out of the
        total and of full credit)."""
        marked = marked or {}
        points = {
            n: 0.0 if n in excused else round(self.points[n] * float(fractions.get(n, 0.0)) + marked.get(n, 0.0), 2)
            for n in self.graded
        }
        required = round(sum(points[n] for n in self.required), 2)
        extra = {f"exercise {n}": points[n] for n in self.extra_credit}
        branch, counted = "", 0.0
        if self.branches:
            earned = [round(sum(points[n] for n in b.exercises), 2) for b in self.branches]
            best = max(range(len(self.branches)), key=lambda i: (earned[i], -i))
            branch, counted = (self.branches[best].name if earned[best] else "none"), earned[best]
            for i, other in enumerate(self.branches):
                if i != best:
                    full = sum(self.worth(n) for n in other.exercises if n not in excused)
                    share = earned[i] / full if full else 0.0
                    extra[f"branch {other.name}"] = round(self.branch_extra * share, 2)
        counts = set(self.required) | set(next((b.exercises for b in self.branches if b.name == branch), ()))
        if self.branches and branch in ("", "none"):
            counts |= set(self.branches[0].exercises)
        full_credit = self.full_credit - sum(self.worth(n) for n in excused if n in counts)
        return Score(points, required, branch, counted, extra, round(full_credit, 2))

    def describe(self):
        """The rubric in a few lines, for the feedback."""
        lines = [
            f"Rubric: {self.title}",
            f"  full credit {points_text(self.full_credit)}: exercises {_list(self.required)} for everyone",
        ]
        if self.branches:
            names = " or ".join(f"{b.name} ({_list(b.exercises)})" for b in self.branches)
            lines[-1] += f", plus one branch: {names}; the better branch counts"
            lines.append(f"  extra credit: the other branch, up to {points_text(self.branch_extra)}")
        if self.extra_credit:
            extra = ", ".join(f"exercise {n} ({points_text(self.worth(n))})" for n in self.extra_credit)
            lines.append(("  " if not self.branches else "  and ") + f"extra credit: {extra}")
        if self.answers:
            marked = ", ".join(f"{grade_id} ({points_text(p)})" for grade_id, p in self.answers.items())
            lines.append(f"  answers in words marked by a person: {marked}")
        if self.late is not None:
            lines.append(f"  {self.late.describe()}")
        return "\n".join(lines)


def _list(numbers):
    return ", ".join(map(str, numbers))


def _exercise(value, where, source, registry):
    try:
        number = int(value)
    except (TypeError, ValueError):
        raise InputError(f"{source}: {where} has {value!r}, which is not an exercise number.") from None
    if str(value).strip() != str(number) or number not in registry.exercises:
        known = ", ".join(map(str, sorted(registry.exercises)))
        raise InputError(
            f"{source}: {where} names exercise {value!r}, which labkit does not grade "
            f"(graded exercises: {known}; exercise 1 is not graded)."
        )
    return number


def _exercise_list(value, where, source, registry):
    if not isinstance(value, list):
        raise InputError(f"{source}: {where} must be a list of exercise numbers, e.g. [2, 3, 4].")
    numbers = [_exercise(v, where, source, registry) for v in value]
    if len(set(numbers)) != len(numbers):
        raise InputError(f"{source}: {where} lists an exercise twice.")
    return tuple(numbers)


def from_dict(data, source="the rubric"):
    """A validated :class:`Rubric` from parsed TOML; InputError says what is wrong and where."""
    known = {"title", "exercises", "required", "extra_credit", "points", "branches", "late", "held", "answers"}
    unknown = sorted(set(data) - known)
    if unknown:
        raise InputError(f"{source}: unknown key(s) {', '.join(unknown)}; a rubric has {', '.join(sorted(known))}.")
    named = data.get("exercises")
    if named is not None and not isinstance(named, str):
        raise InputError(f"{source}: exercises must be text, module:attribute of a Registry.")
    try:
        registry = load_registry(named)
    except ValueError as exc:
        raise InputError(f"{source}: {exc}") from None
    raw_points = data.get("points", {})
    if not isinstance(raw_points, dict):
        raise InputError(
            f"{source}: [points] must be a table of `N = points` lines (or left out: each exercise "
            "is then worth its parts' weights)."
        )
    points = {}
    for key, value in raw_points.items():
        number = _exercise(key, "[points]", source, registry)
        if not is_number(value):
            raise InputError(f"{source}: [points] gives exercise {number} {value!r}; points must be a finite number.")
        if value < 0:
            raise InputError(
                f"{source}: [points] gives exercise {number} negative points ({value}); "
                "use 0 to leave an exercise ungraded."
            )
        points[number] = float(value)
    required = _exercise_list(data.get("required", []), "required", source, registry)
    extra_credit = _exercise_list(data.get("extra_credit", []), "extra_credit", source, registry)
    branches, branch_extra = _branches(data.get("branches"), source, registry)
    groups = [("required", required), ("extra_credit", extra_credit)]
    groups += [(f"branch {b.name!r}", b.exercises) for b in branches]
    seen: dict[int, str] = {}
    for group, numbers in groups:
        for number in numbers:
            if number in seen:
                raise InputError(
                    f"{source}: exercise {number} is in {seen[number]} and in {group}; "
                    "each exercise belongs to one group (branches may not overlap)."
                )
            seen[number] = group
            points.setdefault(number, float(registry.points[number]))
    for number in points:
        if number not in seen:
            raise InputError(
                f"{source}: exercise {number} has points but is in no group: add it to required, "
                "extra_credit or a branch, or remove its points."
            )
    answers, answer_lines = _answers(data.get("answers"), source, registry, points)
    worth = {n: p + sum(a for g, a in answers.items() if registry.answers[g][0] == n) for n, p in points.items()}
    totals = {b.name: sum(worth[n] for n in b.exercises) for b in branches}
    if len(set(totals.values())) > 1:
        shown = ", ".join(f"{name} {points_text(total)}" for name, total in totals.items())
        raise InputError(
            f"{source}: the branches must be worth the same points, since either one gives full "
            f"credit; they are worth {shown}."
        )
    title = data.get("title", "rubric")
    if not isinstance(title, str):
        raise InputError(f"{source}: title must be text.")
    if not seen:
        raise InputError(f"{source}: grades nothing: list exercises in required, extra_credit or branches.")
    points = {number: points[number] for number in sorted(points)}
    late = lateness.from_dict(data["late"], source) if "late" in data else None
    released = _released(data.get("held"), source, registry, points)
    plain = json.loads(json.dumps(data, default=methodcaller("isoformat")))  # date-times as ISO 8601 text
    return Rubric(
        title, points, required, branches, branch_extra, extra_credit, source, registry, late, data=plain,
        released=released, answers=answers, answer_lines=answer_lines,
    )  # fmt: skip


def _answers(table, source, registry, points):
    """The [answers] table: ({answer grade id: points}, in the registry's order; {grade id: rubric lines})."""
    if table is None:
        return {}, {}
    example = "exercise12-answer-1 = 2"
    if not isinstance(table, dict):
        raise InputError(f"{source}: [answers] must be a table of `grade-id = points` lines, e.g. {example}.")
    found, lines = {}, {}
    for grade_id, value in table.items():
        if isinstance(value, dict):  # {points = 2, rubric = ["what earns a point", ...]}
            given = value.get("rubric", [])
            lined = isinstance(given, list) and all(isinstance(line, str) for line in given)
            if set(value) - {"points", "rubric"} or "points" not in value or not lined:
                raise InputError(
                    f"{source}: [answers] {grade_id} must be points, or a table of points and rubric lines: "
                    f'{grade_id} = {{points = 2, rubric = ["names the order", "says why"]}}.'
                )
            lines[grade_id] = tuple(given)
            value = value["points"]
        if grade_id not in registry.answers:
            known = ", ".join(registry.answers) or "none"
            raise InputError(
                f"{source}: [answers] names {grade_id!r}, which is no answer in words of these exercises "
                f"(their grade ids: {known})."
            )
        number = registry.answers[grade_id][0]
        if number not in points:
            raise InputError(f"{source}: [answers] gives {grade_id} points, but exercise {number} is in no group.")
        if not is_number(value) or value < 0:
            raise InputError(
                f"{source}: [answers] gives {grade_id} {value!r}; points must be a finite number, at least 0."
            )
        found[grade_id] = float(value)
    return {grade_id: found[grade_id] for grade_id in registry.answers if grade_id in found}, lines


def _released(table, source, registry, points):
    """The [held] table's releases: {submission name: frozenset of exercise numbers}."""
    if table is None:
        return {}
    example = 'release = {"ada" = [2, 10]}'
    if not isinstance(table, dict) or set(table) - {"release"}:
        raise InputError(
            f"{source}: [held] has one key, release: a table of submission names and the exercises whose "
            f"held parts a person looked at and released, e.g. {example}."
        )
    release = table.get("release", {})
    if not isinstance(release, dict):
        raise InputError(f"{source}: [held] release must be a table of submission names, e.g. {example}.")
    found = {}
    for name, numbers in release.items():
        where = f"[held] release for {name!r}"
        numbers = _exercise_list(numbers, where, source, registry)
        for number in numbers:
            if number not in points:
                raise InputError(f"{source}: {where} names exercise {number}, which this rubric does not grade.")
        found[str(name)] = frozenset(numbers)
    return found


def _branches(table, source, registry):
    if table is None:
        return (), 0.0
    if not isinstance(table, dict):
        raise InputError(f"{source}: [branches] must be a table with extra_credit and [[branches.choice]] entries.")
    unknown = sorted(set(table) - {"extra_credit", "choice"})
    if unknown:
        raise InputError(
            f"{source}: unknown key(s) {', '.join(unknown)} in [branches]; it has extra_credit and choice."
        )
    extra = table.get("extra_credit", 0)
    if not is_number(extra) or extra < 0:
        raise InputError(
            f"{source}: [branches] extra_credit must be a finite number of points, at least 0; got {extra!r}."
        )
    choices = table.get("choice", [])
    if not isinstance(choices, list) or len(choices) < 2:
        raise InputError(f"{source}: [branches] needs at least two [[branches.choice]] entries (alternatives).")
    branches = []
    for index, choice in enumerate(choices, start=1):
        if not isinstance(choice, dict) or not isinstance(choice.get("name"), str) or "exercises" not in choice:
            raise InputError(f"{source}: branch {index} needs a name and a list of exercises.")
        branches.append(
            Branch(choice["name"], _exercise_list(choice["exercises"], f"branch {choice['name']!r}", source, registry))
        )
    if len({b.name for b in branches}) != len(branches):
        raise InputError(f"{source}: two branches have the same name.")
    return tuple(branches), float(extra)


@functools.cache
def default():
    """The lab's own rubric (:data:`DEFAULT`)."""
    return load(DEFAULT)


def load(path=None):
    """The rubric in TOML file `path`, or the lab's own (:data:`DEFAULT`) when None."""
    path = DEFAULT if path is None else Path(path)
    source = "the lab's rubric" if path == DEFAULT else str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the rubric {path}: {exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{source} is not valid TOML: {exc}") from None
    return replace(from_dict(data, source), text=text)
