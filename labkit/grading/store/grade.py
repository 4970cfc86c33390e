"""A submission's grade: its results (:mod:`.model`), its problems and marks, and its score under a rubric.

:class:`SubmissionGrade` is what a grading process hands back and what :meth:`SubmissionGrade.from_dict`, the
one reader of a result file, reads back; everything else reads its typed fields and properties.
"""

from __future__ import annotations

import functools
from dataclasses import asdict, dataclass, field

from ...errors import InputError
from ...exercises.result import KINDS
from ...notebook import installed_version
from . import feedback as feedbacks
from . import rubric as rubrics
from .late import Lateness, SubmissionTime
from .model import ExerciseResult, ItemKey, Mark
from .text import MAX_SOURCE_CHARS, one_line, printable

FORMAT = "labkit-grade/3"  # 3: a problem's kinds as codes ("problem_kinds"), a failed step's in its "kind"
OLD_FORMATS = ("labkit-grade/1", "labkit-grade/2")  # refused with a message to grade again


class ProblemText(str):
    """A problem of a submission: its text as the feedback shows it, and its ``kinds``, set where the problem is
    made: (kind, one-line description) pairs (:data:`labkit.exercises.result.KINDS`), one per thing that went
    wrong (each cell that raised, say). The class report reads the kinds, never the words.

    >>> p = ProblemText("a.ipynb: it stopped.", [("crash", "a.ipynb: it stopped.")])
    >>> p, p.kinds
    ('a.ipynb: it stopped.', (('crash', 'a.ipynb: it stopped.'),))
    >>> ProblemText("a.ipynb: it stopped.", [("stopped", "?")])
    Traceback (most recent call last):
    ...
    labkit.errors.InputError: a problem's kind is one of 'not done', 'raised', 'refused', 'timeout', 'crash', \
'tampered', 'other', 'another variant', not 'stopped'.
    """

    kinds: tuple[tuple[str, str], ...]

    def __new__(cls, text: str, kinds) -> ProblemText:
        self = super().__new__(cls, text)
        self.kinds = tuple((str(kind), str(description)) for kind, description in kinds)
        for kind, _ in self.kinds:
            if kind not in KINDS:
                raise InputError(f"a problem's kind is one of {', '.join(map(repr, KINDS))}, not {kind!r}.")
        return self

    @classmethod
    def one(cls, text: str, kind: str) -> ProblemText:
        """A problem of one kind, described by its first line."""
        return cls(text, [(kind, str(text).split("\n")[0])])


labkit_version = functools.cache(installed_version)  # the version recorded in every result file


@dataclass
class SubmissionGrade:
    """The checks' results for one submission, and its grade under a rubric.

    ``results`` maps an exercise's number to its :class:`~.model.ExerciseResult`; ``problems`` is what went
    wrong while running, per notebook; ``failure`` why it could not be graded at all (then it has no points,
    not zero); ``answers`` each answer in words by grade id; ``time`` when it was handed in (None when no
    source had one); ``sources`` each graded function's printable source, for the similarity search only;
    ``marks`` what a person marked (``labkit mark``). A result or mark given as the plain data of a result
    file is read into its class.
    """

    name: str
    results: dict[int, ExerciseResult] = field(default_factory=dict)
    problems: list = field(default_factory=list)
    seed: int | None = None
    rubric: rubrics.Rubric = field(default_factory=rubrics.default, repr=False, compare=False)
    failure: str | None = None
    answers: dict[str, str] = field(default_factory=dict)
    time: SubmissionTime | None = None
    sources: dict[str, str] = field(default_factory=dict)
    marks: dict[ItemKey, Mark] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.results = {
            int(n): v if isinstance(v, ExerciseResult) else ExerciseResult.from_dict(v, int(n), self.name)
            for n, v in self.results.items()
        }
        self.marks = {
            k if isinstance(k, ItemKey) else ItemKey.of(k): m if isinstance(m, Mark) else _mark(k, m)
            for k, m in self.marks.items()
        }

    @property
    def graded(self) -> bool:
        return self.failure is None

    def released(self, number: int, part: str) -> bool:
        """Whether the held `part` of exercise `number` is paid: a person's mark (release or keep) decides,
        else the rubric's ``[held] release`` table."""
        mark = self.marks.get(ItemKey.held(number, part))
        if mark is not None:
            return mark.points == "release"
        return number in self.rubric.released.get(self.name, ())

    @property
    def excused(self) -> frozenset[int]:
        """The exercises a person excused: out of this submission's total and full credit."""
        return frozenset(
            item.number for item, mark in self.marks.items() if item.kind == "exercise" and mark.points == "excused"
        )

    @property
    def marked(self) -> dict[int, float]:
        """Exercise -> the points a person gave its answers in words."""
        found: dict[int, float] = {}
        for grade_id, (number, _) in self.rubric.registry.answers.items():
            mark = self.marks.get(ItemKey.of_answer(grade_id))
            if mark is not None and isinstance(mark.points, (int, float)):
                found[number] = found.get(number, 0.0) + float(mark.points)
        return found

    @property
    def fractions(self) -> dict[int, float]:
        """The share of each exercise's weight that its parts earned, with the held parts released."""
        found = {}
        for number, verdict in self.results.items():
            total = sum(part.weight for part in verdict.parts)
            held = sum(
                part.weight for part in verdict.parts if part.held and part.passed and self.released(number, part.name)
            )
            found[number] = min(1.0, verdict.fraction + held / total) if total else verdict.fraction
        return found

    def held(self) -> list[tuple[int, str, dict, bool]]:
        """(exercise, part, what it matched, whether it is released) of each part held for a person."""
        return [
            (number, part.name, part.held, self.released(number, part.name))
            for number, verdict in sorted(self.results.items())
            for part in verdict.parts
            if part.held and part.passed
        ]

    @property
    def score(self) -> rubrics.Score:
        return self.rubric.score(self.fractions, self.marked, self.excused)

    @property
    def points(self) -> dict:
        """Points per graded exercise under the rubric."""
        return self.score.points

    @property
    def lateness(self) -> Lateness | None:
        """What the rubric's late rule makes of this submission (:class:`labkit.grading.store.late.Lateness`), or None
        when the rubric has no ``[late]`` table or the submission could not be graded."""
        if self.rubric.late is None or not self.graded:
            return None
        return self.rubric.late.assess(self.name, self.time, self.score.total)

    @property
    def raw_total(self) -> float:
        """The points under the rubric before any late penalty."""
        return self.score.total

    @property
    def total(self) -> float:
        """The points under the rubric, less the late penalty when the rubric has a ``[late]`` table."""
        lateness = self.lateness
        return self.score.total if lateness is None else lateness.total

    def feedback(self) -> str:
        """The feedback text a student reads: the total first (labkit.grading.store.feedback)."""
        return feedbacks.text(feedbacks.build(self))

    def as_dict(self) -> dict:
        """The grade as a result file's data (:data:`FORMAT`)."""
        score, lateness = self.score, self.lateness
        late = (
            {} if lateness is None else {"raw total": score.total, "late": lateness.note, "penalty": lateness.penalty}
        )
        return {
            "format": FORMAT,
            "labkit": labkit_version(),
            "rubric digest": self.rubric.digest,
            "submitted": None if self.time is None else self.time.as_dict(),
            "name": self.name,
            "seed": self.seed,
            "problems": [str(p) for p in self.problems],
            "problem_kinds": [[list(pair) for pair in feedbacks.problem_kinds(p)] for p in self.problems],
            "failure": self.failure,
            "answers": dict(self.answers),
            "sources": dict(self.sources),
            "marks": {str(item): asdict(mark) for item, mark in self.marks.items()},
            "results": {str(n): v.as_dict() for n, v in self.results.items()},
            "rubric": self.rubric.title,
            "points": {str(n): v for n, v in score.points.items()},
            "branch": score.branch,
            "extra_credit": score.extra,
            **late,
            "total": self.total,
        }

    @classmethod
    def from_dict(cls, data: dict, source: str = "a result file", rubric: rubrics.Rubric | None = None):
        """Read back what :meth:`as_dict` wrote (scored again with `rubric`); ValueError names the file. A result
        of an earlier format is refused, saying to grade again (its problems' kinds would be guesses)."""
        if isinstance(data, dict) and data.get("format") in OLD_FORMATS:
            raise InputError(
                f"{source} is in the results format {data['format']}, which keeps a problem's words but not its "
                f"kind (a time limit, a crash, an error raised, ...); this labkit reads {FORMAT} only. Grade "
                "those submissions again with this version: `labkit grade` with --fresh, or into a new --out."
            )
        try:
            grade = cls._read(data, rubric)
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

    @classmethod
    def _read(cls, data: dict, rubric: rubrics.Rubric | None) -> SubmissionGrade:
        if data.get("format") != FORMAT:
            raise InputError(f"format is {data.get('format')!r}, not {FORMAT!r}")
        for verdict in data["results"].values():
            float(verdict["fraction"])
        failure = data.get("failure")
        return cls(
            str(data["name"]),
            data["results"],  # each read by __post_init__
            _problems(data["problems"], data["problem_kinds"]),
            data.get("seed"),
            rubric or rubrics.default(),
            None if failure is None else str(failure),
            {str(k): str(v)[:4000] for k, v in dict(data.get("answers") or {}).items()},
            SubmissionTime.from_dict(data.get("submitted")),
            _sources(data.get("sources") or {}),  # results written before sources were kept have none
            dict(data.get("marks") or {}),  # each read by __post_init__
        )


def _mark(item, data: dict) -> Mark:
    """A result file's mark of `item`, {"points", "comment", "time"}; TypeError when it is not one."""
    points = data["points"]
    if isinstance(points, bool) or not isinstance(points, (int, float, str)):
        raise TypeError(f"the mark of {item!r} has points {points!r}")
    return Mark(points, printable(data.get("comment", ""))[:2000], str(data.get("time", "")))


def _sources(value: dict) -> dict[str, str]:
    """A result file's sources, bounded and printable; TypeError when they are not names and texts."""
    sources = dict(value)
    if not all(isinstance(k, str) and isinstance(v, str) for k, v in sources.items()):
        raise TypeError("its sources are not function names and source texts")
    return {printable(k)[:200]: printable(v)[:MAX_SOURCE_CHARS] for k, v in sources.items()}


def _problems(texts: list, kinds: list) -> list[ProblemText]:
    """A result file's problems, each with its kinds (ValueError when the two lists do not pair up)."""
    if not isinstance(texts, list) or not isinstance(kinds, list) or len(texts) != len(kinds):
        raise InputError("its problems and their kinds do not pair up")
    return [ProblemText(str(text), pairs) for text, pairs in zip(texts, kinds)]
