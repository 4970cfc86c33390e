"""What an exercise is: the pieces every exercise declaration is made of.

An exercise is declared once, in the topic module it belongs to
(:mod:`~labkit.exercises.hermite`, :mod:`~labkit.exercises.patches`,
:mod:`~labkit.exercises.splines`, :mod:`~labkit.exercises.monotone`,
:mod:`~labkit.exercises.bilinear`), as an
:class:`Exercise` of :class:`Part` objects. A part says which of the
notebook's names its check reads, the check itself (a ``check_...`` function,
which the student calls as ``labkit.check....``), its weight, the functions the
check hands to student code, and the references it switches off. Everything
else (the grader's registry, the sandbox's list of functions that may cross,
nbgrader's points, the notebooks' self-check names) is derived from the
declarations by :class:`labkit.exercises.registry.Registry`.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError

CHECK_PREFIX = "check_"
# a notebook's section of exercise N: a markdown heading of any level, "## Exercise N", with or without a title
SECTION = re.compile(r"^#+[ \t]*Exercise[ \t]+(\d{1,3})(?!\d)", re.MULTILINE)


def sections(markdown: str) -> list[int]:
    r"""The numbers of the exercise sections one markdown text opens, in order.

    The grader, nbgrader's marking of the notebooks and the tests all read the sections with this one
    function. A section is a heading line ``## Exercise N`` of any level, a title after the number or
    not; numbers of more than three digits are no section (a submission's heading cannot make the
    grader look for exercise 10**9).

    >>> sections("# Notebook\n## Exercise 17: secants\ntext\n### Exercise 3\nExercise 4 in a sentence")
    [17, 3]
    >>> sections("## Exercise 12345")
    []
    """
    return [int(number) for number in SECTION.findall(str(markdown))]


@dataclass(frozen=True)
class Refusal:
    """What a graded function may not reach while the grader calls it: whole modules, not names.

    ``modules`` are module prefixes: every Python function, method and
    compiled routine in them is switched off, private helpers included.
    ``functions`` are single functions of other modules (numpy's linear
    ``interp``). ``allowed`` are the few functions of those modules that the
    lab lets students reuse. :mod:`labkit.grading.submission.refusals` turns this into
    what the sandbox recognises, and the source scan reads the same lists.
    """

    name: str
    modules: tuple
    functions: tuple = ()
    allowed: tuple = ()


# the lab's answers and the grader's own references: refused in every graded call that has a refusal
GRADER = ("labkit.exercises", "labkit.check")
INTERPOLANTS = Refusal(
    "library interpolants",
    modules=(
        "scipy.interpolate",
        "scipy.ndimage",
        "scipy.signal._bsplines",
        "scipy.signal._spline",
        "scipy.signal._spline_filters",
        "labkit.piecewise",
        "labkit.splines",
        "labkit.monotone",
        "labkit.bilinear",
        "labkit.patches",
        "labkit.convergence",
        "labkit.functions",
    )
    + GRADER,
    functions=(
        "numpy.lib._function_base_impl.interp",
        "numpy._core._multiarray_umath.interp",
        "numpy._core._multiarray_umath.interp_complex",
    ),
    allowed=("labkit.piecewise.bracket",),
)
OWN_FUNCTIONS = Refusal("the lab's functions", modules=("labkit.functions",) + GRADER)
OWN_PATCH = Refusal(
    "labkit's patch", modules=("labkit.patches",) + GRADER, allowed=("labkit.patches.Corner", "labkit.patches._vector")
)
EXPERIMENTS = Refusal("labkit's experiments", modules=("labkit.convergence",) + GRADER)


@dataclass(frozen=True)
class Optional:
    """A name the check reads if the notebook defines it (None otherwise)."""

    name: str


@dataclass(frozen=True)
class Together:
    """Several of the notebook's names handed to the check as one list.

    When one is missing: the part fails as "not defined" (``required``), or
    the check gets None and judges without them.
    """

    names: tuple
    required: bool = True


def read(namespace: Mapping, spec: str | Optional | Together) -> Any:
    """The value a check gets for one of :attr:`Part.reads` (KeyError: a name the notebook lacks)."""
    if isinstance(spec, Optional):
        return namespace.get(spec.name)
    if isinstance(spec, Together):
        if not spec.required:
            values = [namespace.get(name) for name in spec.names]
            return None if any(value is None for value in values) else values
        return [namespace[name] for name in spec.names]
    return namespace[spec]


def names_read(spec: str | Optional | Together) -> tuple:
    """The notebook names one of :attr:`Part.reads` stands for."""
    if isinstance(spec, Optional):
        return (spec.name,)
    if isinstance(spec, Together):
        return tuple(spec.names)
    return (spec,)


def facade_name(check: Callable) -> str:
    """The name a check has in :mod:`labkit.check`: its own name without ``check_``."""
    name = check.__name__
    if not name.startswith(CHECK_PREFIX):
        raise InputError(f"a part's check must be a function named {CHECK_PREFIX}<name>; got {name!r}.")
    return name[len(CHECK_PREFIX) :]


@dataclass(frozen=True)
class Part:
    """One graded piece of an exercise: a check of some of the notebook's names, and its weight.

    ``check(*values, seed=seed)`` (``seed`` only when ``seeded``) returns one
    :class:`~labkit.exercises.result.CheckResult`, or, for parts that share
    one check (``index`` set: the parts of one plot), a list of them, run once
    for all. ``reads`` are the notebook's names passed to it, in order: a name,
    an :class:`Optional` name, or names :class:`Together`. The weights of an
    exercise's parts are its points; a rubric that gives the exercise other
    points scales them (:mod:`labkit.grading.store.rubric`).

    ``passes`` are labkit's functions the check hands to the student's code
    (the only functions that may cross into the sandbox); ``refused`` is
    what is switched off while the grader calls the student's functions for
    this part; ``functions`` are the student's functions the part calls, when
    not just the one named like it (the grader scans their source).

    ``uses`` are the student's earlier functions that the part's check, or the
    student's code under it, relies on (``two_patches`` calls the student's
    ``coons``): each is graded in a part of its own (some part's ``name`` or
    ``functions``), and a slip in it is charged there only, so the check
    protects itself from it (:attr:`labkit.exercises.registry.Registry.dependencies`).
    """

    name: str
    weight: int
    check: Callable
    reads: tuple = ()
    seeded: bool = False
    index: int | None = None
    refused: Refusal | None = None
    functions: tuple = ()
    passes: tuple = ()
    keywords: tuple = ()  # (keyword, spec) pairs: notebook names handed to the check by keyword
    uses: tuple = ()  # the student's earlier functions this part relies on, each graded in a part of its own
    varied: tuple = ()  # the exercise's parameters (Exercise.params) the check takes by keyword: the student's data

    def __post_init__(self):
        facade_name(self.check)
        if int(self.weight) < 0:
            raise InputError(f"part {self.name!r} has a negative weight {self.weight}.")
        if isinstance(self.uses, str) or not all(isinstance(name, str) for name in self.uses):
            raise InputError(f"part {self.name!r}: uses must be a tuple of the student's function names, as strings.")

    @property
    def scanned(self) -> tuple:
        """The student's names whose source the grader reads for refused references."""
        return self.functions or (self.name,)

    @property
    def self_check(self) -> str:
        """The part's check as the notebook calls it: ``labkit.check.<self_check>``."""
        return facade_name(self.check)

    @property
    def shared(self) -> tuple:
        """Parts with the same key run their check once (with ``index`` picking each one's result)."""
        return (self.check, self.reads)

    def names(self) -> tuple:
        """Every notebook name the part reads."""
        specs = tuple(self.reads) + tuple(spec for _, spec in self.keywords)
        return tuple(name for spec in specs for name in names_read(spec))

    def run(self, namespace: Mapping, seed: int | None = None, variant: Mapping | None = None) -> Any:
        """The check's result on the notebook's names; `variant` ({parameter: value}) is the student's data,
        the check's own defaults (the lab's) when None."""
        values = [read(namespace, spec) for spec in self.reads]
        keywords = {keyword: read(namespace, spec) for keyword, spec in self.keywords}
        if self.seeded:
            keywords["seed"] = seed
        for name in self.varied:
            if variant is not None and name in variant:
                keywords[name] = variant[name]
        return self.check(*values, **keywords)


@dataclass(frozen=True)
class Exercise:
    """One graded exercise.

    ``names`` are what the student's notebook defines (any of them present
    means the notebook is the exercise's own). ``parts`` are its checks with
    their weights. ``answers`` are the remarks and explanations the student
    writes in words: no check reads them, the feedback lists them for the
    instructor, and ``grades.csv`` has an empty column for each.
    ``notebook`` is the notebook the exercise is in. ``params`` are the
    data it lets vary per student (:mod:`labkit.exercises.variants`); the
    parts that read them name them in :attr:`Part.varied`. ``withheld`` is what the
    student is asked to find, written as it would appear in a text (an order,
    a derived formula, a worked value): no string the student can see may
    contain one (``tests/exercises/test_giveaways.py``). An entry is a string, or a
    function of no arguments returning strings (values computed from labkit's
    references only when the answer key is asked for).
    """

    number: int
    names: tuple
    parts: tuple
    notebook: str
    answers: tuple = ()
    topic: str = field(default="", compare=False)
    withheld: tuple = field(default=(), compare=False)
    # the data it lets vary per student (labkit.exercises.variants.Param), each assigned in a data cell
    params: tuple = field(default=(), compare=False)
    # why a draw of the params would not teach the exercise's lesson ('' when it does), for `labkit variants --check`
    sound: Callable | None = field(default=None, compare=False)
    # what the data cell shows that follows from the params ({params} -> {notebook name: Python text}): the lab
    # gives a value worked out from the data (Exercise 7's twist), so a variant gives its own
    derived: Callable | None = field(default=None, compare=False)

    def __post_init__(self):
        seen = [part.name for part in self.parts]
        if len(set(seen)) != len(seen):
            raise InputError(f"exercise {self.number} has two parts with the same name.")
        if not self.parts:
            raise InputError(f"exercise {self.number} has no parts: give it at least one checked part.")
        if self.points <= 0:
            raise InputError(f"exercise {self.number} is worth no points: give its parts positive weights.")
        declared = [getattr(param, "name", None) for param in self.params]
        if len(set(declared)) != len(declared):
            raise InputError(f"exercise {self.number} declares a parameter twice: give each its own name.")
        for part in self.parts:
            for name in part.varied:
                if name not in declared:
                    raise InputError(
                        f"part {part.name!r} of exercise {self.number} varies {name!r}, which the exercise does not "
                        f"declare: add a Param named {name!r} to its params."
                    )

    @property
    def points(self) -> int:
        return sum(part.weight for part in self.parts)
