"""The graded exercises, gathered from their declarations, and everything derived from them.

:data:`LAB` is the lab's registry: the exercises the topic modules declare.
A course that adds an exercise declares it in a topic module and lists the
module in :data:`TOPICS`; a toy course (the tests') builds its own
:class:`Registry` from its own exercises and names it to the grader as
``module:attribute``.

The same registry serves a student's notebook and ``labkit grade``:
:meth:`Registry.check` only reads names from a mapping, which is the notebook's
own variables in the notebook and a proxy into the sandboxed notebook in the
grader (:mod:`labkit.grading.sandbox.remote`).
"""

from __future__ import annotations

import importlib
import math
import sys
import types
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..plotdata import Line, figure_data
from . import bilinear, hermite, monotone, patches, splines
from .model import Exercise, read
from .result import NOT_DONE, OTHER, VARIANT, CheckResult

TOPICS = (hermite, patches, splines, monotone, bilinear)  # in the order of the exercises they declare
# names labkit.check defines itself: no part's check may take one
FACADE = (
    "CheckResult",
    "EXERCISES",
    "Exercise",
    "NAMES",
    "POINTS",
    "TOLERANCE",
    "driver",
    "exercise",
    "rate",
    "table",
)


def function_name(function) -> str:
    """How both sides of the sandbox name a function that may cross it: ``module:qualname``."""
    return f"{function.__module__}:{function.__qualname__}"


class Registry:
    """A course's exercises by number, and what is derived from them.

    Attributes
    ----------
    exercises : dict
        :class:`~labkit.exercises.model.Exercise` by number.
    points : dict
        Each exercise's points: the sum of its parts' weights.
    names : dict
        What each exercise's notebook defines.
    answers : dict
        ``exerciseN-answer-K`` (nbgrader's grade id) -> (N, what the answer is about).
    refusals : tuple
        Every :class:`~labkit.exercises.model.Refusal` some part uses.
    passable : frozenset
        ``module:qualname`` of every function a check hands to student code:
        the only functions that may cross into the sandbox.
    self_checks : dict
        ``labkit.check`` name -> the check function.
    experiments : dict
        The convergence experiments by key.
    dependencies : list
        ``(part, upstream)`` pairs of part names: `part` relies on the student's function graded in
        `upstream` (:attr:`~labkit.exercises.model.Part.uses`), so a slip there is charged in `upstream` only.
    """

    def __init__(self, exercises: Iterable[Exercise], source: str | None = None):
        exercises = list(exercises)
        numbers = [exercise.number for exercise in exercises]
        duplicated = sorted({n for n in numbers if numbers.count(n) > 1})
        if duplicated:
            raise InputError(f"exercise {duplicated[0]} is declared twice: give each exercise its own number.")
        self.source = source
        self.exercises = {exercise.number: exercise for exercise in sorted(exercises, key=lambda e: e.number)}
        self.points = {n: e.points for n, e in self.exercises.items()}
        self.names = {n: list(e.names) for n, e in self.exercises.items()}
        self.answers = {
            f"exercise{e.number}-answer-{k}": (e.number, text)
            for e in self.exercises.values()
            for k, text in enumerate(e.answers, start=1)
        }
        parts = [part for e in self.exercises.values() for part in e.parts]
        self.refusals = tuple(sorted({p.refused for p in parts if p.refused}, key=lambda refusal: refusal.name))
        names = [refusal.name for refusal in self.refusals]
        if len(set(names)) != len(names):
            raise InputError(
                f"two different refusals are named {sorted(n for n in names if names.count(n) > 1)[0]!r}: "
                "give each Refusal a name of its own (the sandbox knows them by name)."
            )
        for part in parts:
            for function in part.passes:
                _check_passable(function, part.name)
        _check_shared_params(self.exercises)
        self.passable = frozenset(function_name(f) for p in parts for f in p.passes)
        self.dependencies = _dependencies(parts)
        self.experiments: dict = {}
        for part in parts:
            experiment = getattr(part, "experiment", None)
            if experiment is not None:
                self.experiments.setdefault(experiment.key, experiment)
        self.self_checks: dict = {}
        for part in parts:
            if getattr(part, "experiment", None) is not None:
                continue
            name = part.self_check
            if name in FACADE:
                raise InputError(
                    f"part {part.name!r}: labkit.check.{name} is taken by labkit itself; name the check "
                    f"check_<something else>."
                )
            if self.self_checks.setdefault(name, part.check) is not part.check:
                raise InputError(f"two different checks would both be labkit.check.{name}: give one another name.")

    def __iter__(self):
        return iter(self.exercises.values())

    def __len__(self) -> int:
        return len(self.exercises)

    def notebooks(self) -> dict:
        """Notebook file name -> the numbers of the exercises in it."""
        found: dict = {}
        for exercise in self:
            found.setdefault(exercise.notebook, []).append(exercise.number)
        return found

    def upstream(self, part: str) -> list:
        """The parts whose student's functions part `part` relies on (ValueError for an unknown part)."""
        known = {p.name for e in self for p in e.parts}
        if part not in known:
            raise InputError(f"no part is named {part!r}; choose one of {', '.join(map(repr, sorted(known)))}.")
        return [upstream for dependent, upstream in self.dependencies if dependent == part]

    def experiment(self, key: str):
        """The convergence experiment `key`; ValueError naming the choices otherwise."""
        if key not in self.experiments:
            raise InputError(f"unknown experiment {key!r}; choose one of {', '.join(map(repr, self.experiments))}.")
        return self.experiments[key]

    def parts_checked(self, number: int, function: str, first: str | None = None) -> list:
        """The parts of exercise `number` that ``labkit.check.<function>(first, ...)`` checks.

        For ``driver``, ``table`` and ``rate`` the first argument is the
        experiment's key; otherwise the function's name is enough.
        """
        found = []
        for part in self.exercises[number].parts:
            experiment = getattr(part, "experiment", None)
            if part.self_check == function and (experiment is None or experiment.key == first):
                found.append(part)
        return found

    def answer_key(self) -> dict:
        """Exercise number -> the texts the student is asked to find (:attr:`Exercise.withheld`, expanded).

        A computed entry (a function) is called here, so the reference values
        are worked out only when the key is asked for (the release scan).
        """
        key = {}
        for exercise in self:
            texts: list = []
            for entry in exercise.withheld:
                found = entry() if callable(entry) else (entry,)
                texts.extend(str(text) for text in found)
            key[exercise.number] = tuple(dict.fromkeys(texts))
        return key

    def check(self, number: int, namespace: Mapping, seed: int | None = None, variant: Mapping | None = None) -> dict:
        """Run the checks of exercise `number` on a notebook's variables; a dict for the grader.

        `namespace` is any mapping of names to the student's functions and
        data. ``defined`` says whether the notebook defines any of the
        exercise's names, so the grader can tell the exercise's own notebook
        from one that only mentions it. Each check in ``checks`` carries its
        part's ``weight``; ``fraction`` is the share of the weight that passed
        and ``points`` the weights that passed. `seed` draws the random test
        data afresh (see :func:`labkit.exercises.result.case_rng`).

        `variant` ({parameter: value}) is the student's own data
        (:mod:`labkit.exercises.variants`): the parts that vary are checked
        against it, and ``other_variant`` lists, as {parameter: [the notebook's
        value, the student's]}, each parameter whose value in the notebook is
        not the student's (a notebook worked on another student's data). With
        no `variant` the checks use the lab's data and nothing is compared.
        """
        exercise = self.exercises[number]
        defined = any(name in namespace for name in exercise.names)
        other = {}
        for param in exercise.params:
            if variant is not None and param.name in variant and param.name in namespace:
                found = _shown(namespace[param.name])
                # only a number is data: a name the notebook no longer answers for (stopped, timed out) reads as
                # a function proxy, and is no sign of anyone else's data
                if isinstance(found, float) and not param.holds(found, variant[param.name]):
                    other[param.name] = [found, variant[param.name]]
        checks, shared = [], {}
        refusing = getattr(namespace, "refusing", None)  # the grader's proxy switches references off per part
        for part in exercise.parts:
            if refusing is not None:
                refusing(part.refused)
            try:
                if part.index is None:
                    result = part.run(namespace, seed, variant)
                else:
                    if part.shared not in shared:
                        shared[part.shared] = part.run(namespace, seed, variant)
                    result = shared[part.shared][part.index]
            except KeyError as exc:
                result = _missing(str(exc).strip("'\""))
                result.name = part.name
            except Exception as exc:  # noqa: BLE001 - a fault of the check itself costs this part, not the others
                result = CheckResult(part.name)
                result.fail(
                    "the grader could check this part",
                    f"the check failed inside labkit ({type(exc).__name__})",
                    "this is a fault of the grader, not of your work: tell your instructor.",
                    OTHER,
                )
            _on_another_variant(result, part, other)
            check = {**result.as_dict(), "name": part.name, "weight": part.weight}  # as the student names it
            checks.append({**check, **_student_figure(part, namespace, check)})
        points = sum(check["weight"] for check in checks if check["passed"])
        return {
            **({"other_variant": other} if other else {}),
            "exercise": number,
            "passed": points == exercise.points,
            "points": points,
            "fraction": points / exercise.points if exercise.points else 1.0,
            "defined": defined,
            "checks": checks,
        }


def _student_figure(part, namespace, check) -> dict:
    """``{"figure": ...}``: the student's own plot that a failed part judged (as :func:`labkit.plotdata.figure_data`
    keeps it), for the feedback page; empty for a part that passed or was not done, or that judges no plot."""
    if check["passed"] or any(step.get("kind") == NOT_DONE for step in check["steps"]):
        return {}
    for spec in part.reads:
        try:
            value = read(namespace, spec)
        except Exception:  # noqa: BLE001 - a value the check could not read has no figure to show
            continue
        if isinstance(value, list) and value and all(isinstance(line, Line) for line in value):
            return {"figure": figure_data(value)}
    return {}


def _on_another_variant(result, part, other) -> None:
    """Fail `part`'s `result` when the notebook holds another variant's value of data the part depends on
    (`other`: {parameter: [the notebook's, the student's]}): work on someone else's data earns nothing, even
    where it agrees with the student's own to the digits shown (two close draws)."""
    shown = sorted(name for name in part.varied if name in other)
    if not shown:
        return
    values = "; ".join(f"{name} = {other[name][0]:g} where yours is {other[name][1]:g}" for name in shown)
    result.fail(
        "worked on your own data",
        f"the notebook holds another variant's data ({values})",
        "set the data cell back to the values your notebook was handed out with, and run the notebook again.",
        VARIANT,
    )


def _shown(value) -> Any:
    """A notebook's value of a varied parameter as plain data: a finite float when it is one number (a Python
    or numpy number, or an array of one), else the name of its type."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number, np.ndarray)):
        return str(type(value).__name__)[:40]
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        return str(type(value).__name__)[:40]
    return number if math.isfinite(number) else "not finite"


def _dependencies(parts) -> list:
    """(part, upstream part) name pairs from the parts' ``uses``, in the order they are declared; ValueError for
    a name no part grades."""
    graded: dict = {}
    for part in parts:
        for name in part.scanned:
            graded.setdefault(name, part.name)
    found = []
    for part in parts:
        for name in part.uses:
            if name not in graded:
                raise InputError(
                    f"part {part.name!r} uses {name!r}, which no part grades: name a function some part "
                    "checks (its name or one of its functions), or declare the part that grades it."
                )
            pair = (part.name, graded[name])
            if graded[name] != part.name and pair not in found:
                found.append(pair)
    return found


def _check_shared_params(exercises: dict) -> None:
    """Parameters of one name are one datum: declared alike by every exercise, and a shared one is drawn with an
    exercise that declares it (its draw, and a redraw of it, give every exercise the same value). A course that
    takes only some of the sharing exercises still draws the datum under the drawing exercise's number."""
    by_name: dict = {}
    for number, exercise in exercises.items():
        for param in exercise.params:
            first = by_name.setdefault(param.name, (number, param))
            if first[1] != param:
                raise InputError(
                    f"exercises {first[0]} and {number} both declare {param.name!r} but not alike: a name is one "
                    "datum, so declare one Param (with drawn_with) and use it in both."
                )
            if first[0] != number and param.drawn_with is None:
                raise InputError(
                    f"exercises {first[0]} and {number} both declare {param.name!r}, each drawing its own: give the "
                    "Param drawn_with=<the exercise that draws it>, or give the two data different names."
                )
            drawing = exercises.get(param.drawn_with)
            if drawing is not None and not any(p == param for p in drawing.params):
                raise InputError(
                    f"{param.name!r} is drawn with exercise {param.drawn_with}, which does not declare it: declare "
                    "it there too."
                )


def _check_passable(function, part: str) -> None:
    """A function a check hands to student code must be one the sandbox can find by name: a module-level function
    of labkit's own (not of the grader), as its module has it."""
    module, qualname = getattr(function, "__module__", None), getattr(function, "__qualname__", None)
    ok = False
    if isinstance(function, types.FunctionType) and isinstance(module, str) and isinstance(qualname, str):
        ok = module.startswith("labkit.") and not module.startswith("labkit.grading") and qualname.isidentifier()
        try:
            ok = ok and getattr(importlib.import_module(module), qualname, None) is function
        except ImportError:
            ok = False
    if not ok:
        raise InputError(
            f"part {part!r} passes {function!r} to student code: only module-level functions of labkit's "
            "own modules (outside labkit.grading) can be handed into the sandbox, by their name."
        )


def _missing(name: str) -> CheckResult:
    result = CheckResult(name)
    return result.fail(
        f"{name} is defined",
        "not defined when the notebook finished",
        f"run the cell that defines {name} (and keep its name); a cell that raised stops it.",
        NOT_DONE,
    )


LAB = Registry((exercise for topic in TOPICS for exercise in topic.EXERCISES), source="labkit.exercises.registry:LAB")


def load(source: str | None = None) -> Registry:
    """The registry named ``module:attribute`` (the lab's when None); ValueError if it is not one."""
    if source is None or source == LAB.source:
        return LAB
    module, _, attribute = str(source).partition(":")
    try:
        found: Any = getattr(importlib.import_module(module), attribute or "REGISTRY")
    except (ImportError, AttributeError) as exc:
        raise InputError(
            f"cannot load the exercises {source!r} ({exc}); give module:attribute of a Registry, "
            "with the module importable."
        ) from None
    if not isinstance(found, Registry):
        raise InputError(f"{source!r} is a {type(found).__name__}, not a labkit Registry of exercises.")
    if found.source is None:
        found.source = source
    top = module.split(".")[0]
    origin = getattr(sys.modules.get(top), "__file__", None)
    if origin:
        origin = Path(origin).resolve()
        COURSES[top] = origin.parent if origin.name == "__init__.py" else origin
    return found


# course modules whose registries :func:`load` has loaded in this process: top-level name -> the package's
# folder or the module's file; the grader's sandbox shows them to the student's notebook (which imports the
# course module for its self-checks), read-only, and nothing else of the folder they are in
COURSES: dict[str, Path] = {}
