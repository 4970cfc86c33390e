"""The typed data of a run: a submission's results by exercise, part and step, its marks, and their keys.

:meth:`ExerciseResult.from_dict` reads :meth:`labkit.exercises.registry.Registry.check`'s plain JSON data once,
at the store's edge; :meth:`ExerciseResult.as_dict` gives the same data back for a result file.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ...errors import InputError
from .text import is_number, one_line

_EXERCISE_ITEM = re.compile(r"exercise(?P<number>[0-9]+)(?:/(?P<part>.+))?", re.DOTALL)


@dataclass(frozen=True)
class Step:
    """One step of a part's check: what it checked, whether it passed, the detail of a failure and its kind
    (:data:`labkit.exercises.result.KINDS`; None for a slip, which the hint names)."""

    step: str
    passed: bool
    detail: str = ""
    kind: str | None = None

    @classmethod
    def from_dict(cls, data: dict) -> Step:
        kind = data.get("kind")
        return cls(
            str(data["step"]), bool(data["passed"]), str(data.get("detail", "")), None if kind is None else str(kind)
        )

    def as_dict(self) -> dict:
        found = {"step": self.step, "passed": self.passed, "detail": self.detail}
        return found if self.kind is None else {**found, "kind": self.kind}


@dataclass(frozen=True)
class PartResult:
    """One part of an exercise as it was graded: its weight, its steps and hint; ``held`` is what a part held
    for a person matched (a :class:`labkit.grading.submission.known.Match` as a dict), ``figure`` the student's
    plot a failed part judged (:func:`labkit.plotdata.figure_data`)."""

    name: str
    passed: bool
    weight: float = 0
    hint: str = ""
    steps: tuple[Step, ...] = ()
    held: dict | None = None
    figure: list | None = None

    @classmethod
    def from_dict(cls, data: dict) -> PartResult:
        steps = data.get("steps", [])
        if not isinstance(steps, list):
            raise InputError(f"the steps of part {str(data.get('name'))[:80]!r} are not a list")
        held, weight = data.get("held"), data.get("weight", 0)
        if held is not None and not isinstance(held, dict):
            raise InputError(f"what part {str(data.get('name'))[:80]!r} was held for is not a table")
        if not is_number(weight):
            raise InputError(f"the weight of part {str(data.get('name'))[:80]!r} is not a finite number")
        return cls(
            str(data["name"]), bool(data["passed"]), weight, str(data.get("hint") or ""),
            tuple(Step.from_dict(step) for step in steps), held, data.get("figure"),
        )  # fmt: skip

    def as_dict(self) -> dict:
        """The part as a result file and :func:`labkit.exercises.result.part_kind` read it."""
        found = {"name": self.name, "passed": self.passed, "hint": self.hint,
                 "steps": [step.as_dict() for step in self.steps], "weight": self.weight}  # fmt: skip
        return {
            **found,
            **({"held": self.held} if self.held else {}),
            **({"figure": self.figure} if self.figure else {}),
        }

    @property
    def failed(self) -> tuple[Step, ...]:
        return tuple(step for step in self.steps if not step.passed)


@dataclass(frozen=True)
class ExerciseResult:
    """One exercise of a submission as it was graded: the share of its weight its parts earned, whether the
    notebook defined its names, its parts, and the data of another variant it holds ({parameter: [the
    notebook's, the student's]})."""

    number: int
    fraction: float
    parts: tuple[PartResult, ...] = ()
    passed: bool = False
    points: float = 0
    defined: bool = False
    other_variant: dict = field(default_factory=dict)

    @classmethod
    def from_dict(cls, data: dict, number: int, whose: str = "") -> ExerciseResult:
        """Read :meth:`Registry.check`'s result of exercise `number` of submission `whose`; InputError when it
        is not one."""
        checks = data.get("checks") if isinstance(data, dict) else None
        if not isinstance(checks, list) or not all(isinstance(check, dict) for check in checks):
            raise InputError(
                f"the result of {one_line(whose, 80)!r} for exercise {number} has no list of checks: it was not "
                "written by `labkit grade`; grade the submission again."
            )
        other = data.get("other_variant") or {}
        return cls(
            number, float(data.get("fraction", 0.0)), tuple(PartResult.from_dict(check) for check in checks),
            bool(data.get("passed")), data.get("points", 0), bool(data.get("defined")), dict(other),
        )  # fmt: skip

    def as_dict(self) -> dict:
        variant = {"other_variant": self.other_variant} if self.other_variant else {}
        return {**variant, "exercise": self.number, "passed": self.passed, "points": self.points,
                "fraction": self.fraction, "defined": self.defined,
                "checks": [part.as_dict() for part in self.parts]}  # fmt: skip


@dataclass(frozen=True, order=True)
class ItemKey:
    """What a person marks (``labkit mark``): an answer in words (its nbgrader grade id), a part held for a
    person (exercise and part), or a whole exercise (to excuse it). Its text is the item's name in
    ``marks.csv`` and the result files.

    >>> ItemKey.held(2, "eval_pherm"), str(ItemKey.exercise(12)), ItemKey.of("exercise12-answer-1").kind
    (ItemKey(number=2, part='eval_pherm', answer=''), 'exercise12', 'answer')
    >>> ItemKey.of("exercise2/eval_pherm") == ItemKey.held(2, "eval_pherm")
    True
    """

    number: int = 0
    part: str = ""
    answer: str = ""

    @classmethod
    def exercise(cls, number: int) -> ItemKey:
        return cls(int(number))

    @classmethod
    def held(cls, number: int, part: str) -> ItemKey:
        return cls(int(number), str(part))

    @classmethod
    def of_answer(cls, grade_id: str) -> ItemKey:
        return cls(answer=str(grade_id))

    @classmethod
    def of(cls, text: str) -> ItemKey:
        """The item a name in a file stands for: ``exerciseN``, ``exerciseN/part``, else an answer's grade id."""
        match = _EXERCISE_ITEM.fullmatch(str(text))
        if match is None:
            return cls.of_answer(text)
        return cls(int(match["number"]), match["part"] or "")

    @property
    def kind(self) -> str:
        """``"answer"``, ``"held"`` or ``"exercise"``."""
        return "answer" if self.answer else "held" if self.part else "exercise"

    def __str__(self) -> str:
        if self.answer:
            return self.answer
        return f"exercise{self.number}" + (f"/{self.part}" if self.part else "")


@dataclass(frozen=True)
class Mark:
    """What a person marked for one item: points (a number; ``excused`` or ``counted`` for an exercise,
    ``release`` or ``keep`` for a held part), a comment, and when it was first imported (ISO time)."""

    points: float | str
    comment: str = ""
    time: str = ""
