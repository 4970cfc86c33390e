"""Self-checks for the functions students write, with the lab's debugging steps.

Each check takes the student's function (or data), runs the lab's own
verification and, when something is wrong, narrows it down the way the lab's
debugging hints do, then says which step failed and what to look at. The
reference is always labkit's own implementation or the mathematics (a
polynomial the method must reproduce), never a stored output.

In a notebook, put ``labkit.check.eval_pherm(eval_pherm)`` right after the
function: the result prints as a short report. ``labkit grade`` runs the
same checks from outside the notebook's process, calling the student's
functions through a proxy into a sandbox.

This module is built from the exercises' declarations
(:mod:`labkit.exercises.registry`): every part's check is here under its
name without ``check_``, and a convergence experiment's three checks take
the experiment's key first: ``labkit.check.table("pherm", errors_pherm,
test_pherm_interpolate)``.
"""

import functools

from .errors import InputError
from .exercises import experiments as _experiments
from .exercises.model import Exercise  # noqa: F401 - part of the facade (__all__)
from .exercises.registry import FACADE as _FACADE
from .exercises.registry import LAB as _LAB
from .exercises.result import TOLERANCE, CheckResult  # noqa: F401 - part of the facade (__all__)
from .notebook import headless as _headless

EXERCISES = _LAB.exercises
NAMES = _LAB.names
POINTS = _LAB.points


def _not_in_the_grader(check, name=None):
    """`check` as a notebook calls it: in the grader's sandbox (:func:`labkit.notebook.headless`) it runs nothing and
    reports so.
    The grader runs the same check from outside, on the same functions, and nobody reads a self-check's report
    there: run in the cells too, the student's functions would be computed twice."""

    @functools.wraps(check)
    def self_check(*args, **kwargs):
        if _headless():  # (a hidden test's assert on it holds: the grader's own check is what counts)
            result = CheckResult(name or check.__name__)
            result.step("not run in the grader's sandbox: the grader runs this check itself", True)
            return result
        return check(*args, **kwargs)

    return self_check


globals().update({name: _not_in_the_grader(check, name) for name, check in _LAB.self_checks.items()})


@_not_in_the_grader
def driver(key, fn, seed=None):
    """Check the driver of the convergence experiment `key` (``"pherm"``, ``"complete"``, ...)."""
    return _experiments.check_driver(_LAB.experiment(key), fn, seed)


def _scale(experiment, data):
    """The notebook's scale of the experiment's test function, given as ``runge_a=...`` (``runge2d_a=...`` for
    the bilinear one); None (the lab's) when not given."""
    name = experiment.scale.name
    unknown = sorted(set(data) - {name})
    if unknown:
        raise InputError(
            f"the {experiment.key!r} experiment's check takes {name}= (the notebook's data cell), not "
            f"{', '.join(unknown)}=: pass {name}={name}."
        )
    return data.get(name)


@_not_in_the_grader
def table(key, errors, fn, **data):
    """Check the error table of experiment `key` against what the student's driver `fn` returns
    (``runge_a=runge_a``, or ``runge2d_a=runge2d_a`` for the bilinear table: the scale of the notebook's test
    function, when its data cell has one)."""
    experiment = _LAB.experiment(key)
    return _experiments.check_table(experiment, errors, fn, _scale(experiment, data))


@_not_in_the_grader
def rate(key, answer, errors, fn, **data):
    """Check the rate answer of experiment `key`, read from the table `errors` of the driver `fn`
    (the scale as for :func:`table`)."""
    experiment = _LAB.experiment(key)
    return _experiments.check_rate(experiment, answer, errors, fn, _scale(experiment, data))


def exercise(number, namespace, seed=None):
    """Run every check of exercise `number` on a mapping of the notebook's names (what the grader runs).

    ``labkit.check.exercise(2, globals())`` checks Exercise 2 the way ``labkit grade`` does, except that
    the grader also runs the notebook in a sandbox and draws fresh test data."""
    return _LAB.check(number, namespace, seed)


__all__ = sorted({*_FACADE, *_LAB.self_checks})
