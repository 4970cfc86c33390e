"""The check framework: a check's result, calling student code safely, comparing numbers.

Every exercise's check is a function of the student's function (or data)
that returns a :class:`CheckResult`. It calls the student's code only through
:func:`call`, so whatever the code does (raise, return nonsense, refuse a
reference implementation while being graded) becomes a failed step with a
hint, never an exception. The same check runs in a student's notebook, on
the real function, and in ``labkit grade``, on a proxy that forwards the call
into the sandboxed notebook: see :mod:`labkit.grading.sandbox.remote`.
"""

import hashlib
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError

TOLERANCE = 1e-9
NOT_IMPLEMENTED = "not implemented yet"  # the failed step of a function that still raises NotImplementedError
STUB = "replace the `raise NotImplementedError()` with your code."
ABOUT_THE_NOTEBOOK = "see what the feedback says about the notebook above."  # timed out, tampered, worker failed

# What became of a part, and the kind of a failed step or of a submission's problem, as codes: set where the
# step or the problem is made, and read by the class report (never its words, which may change)
PASSED, SLIP = "passed", "slip"  # a part passed; a part failed with the check's hint
NOT_DONE = "not done"  # a stub left as released, or a name not defined
RAISED = "raised"  # the student's code raised an exception
REFUSED = "refused"  # the student's code called, or its source reached for, a refused reference
TIMEOUT = "timeout"  # a cell, a call or the submission ran past its time limit
CRASH = "crash"  # the notebook's process died or stopped answering the grader
TAMPERED = "tampered"  # the notebook interfered with the grader's watch
OTHER = "other"  # a fault of the check itself, or a problem of none of the kinds above
VARIANT = "another variant"  # the notebook holds data other than its student's own (labkit.exercises.variants)
KINDS = (NOT_DONE, RAISED, REFUSED, TIMEOUT, CRASH, TAMPERED, OTHER, VARIANT)  # of a failed step or a problem


# A part's kind as everything that shows it names it (the feedback, the class report's slips and pass rates,
# `labkit handin`, the grades): :func:`part_kind` is the one place that decides it
ERROR, HELD, LATE = "error", "held", "late"  # the student's code failed to run; held for a person; handed in late
PART_KINDS = (PASSED, NOT_DONE, SLIP, ERROR, HELD, VARIANT)  # of one part; LATE is the whole submission's
ERRORS = (RAISED, REFUSED, TIMEOUT, CRASH, TAMPERED, OTHER)  # the failed steps' kinds a part shows as an error


def part_kind(check, released=True):
    """What became of one part, as the student and the instructor read it: one of :data:`PART_KINDS`.

    `check` is a part's entry in a result (``passed``, ``steps``, each failed step that is not a slip with its
    ``kind``; ``held`` when it matched code it may be copied from), or None for a part the results lack (its
    section never ran). A part is "not done" when a failed step is a stub left as released or a name never
    defined, whatever else failed; "another variant" when the notebook holds another student's data; an
    "error" when the student's code raised, ran out of time or was refused; "held" when it passed but waits
    for a person (`released` False); else a "slip", whose hint names it.

    Examples
    --------
    >>> part_kind({"passed": False, "steps": [{"passed": False, "kind": "not done"}, {"passed": False}]})
    'not done'
    >>> part_kind({"passed": False, "steps": [{"passed": False, "detail": "off by 0.3"}]})
    'slip'
    >>> part_kind({"passed": True, "held": {"share": 0.97}, "steps": []}, released=False)
    'held'
    >>> part_kind(None)
    'not done'
    """
    if not isinstance(check, dict) or not check:
        return NOT_DONE
    if check.get("passed"):
        return HELD if check.get("held") and not released else PASSED
    steps = check.get("steps") if isinstance(check.get("steps"), list) else []
    kinds = {s.get("kind") for s in steps if isinstance(s, dict) and not s.get("passed")}
    if NOT_DONE in kinds:
        return NOT_DONE
    if VARIANT in kinds:
        return VARIANT
    return ERROR if kinds & set(ERRORS) else SLIP


@dataclass
class CheckResult:
    """Outcome of one check: the steps run, whether all passed, and a hint if not."""

    name: str
    steps: list = field(default_factory=list)  # (description, passed, detail)
    hint: str = ""
    # why the part was judged against labkit's reference rather than the student's earlier work: said with the
    # hint when the part fails (see :func:`judged_by_the_lab`)
    note: str = ""
    # the kind (one of KINDS) of a failed step that is not a slip, by the step's index in `steps`
    kinds: dict = field(default_factory=dict)

    @property
    def passed(self):
        return bool(self.steps) and all(ok for _, ok, _ in self.steps)

    def step(self, description, ok, detail="", kind=None):
        """Record a step; the detail explains a failure, so a passed step drops it. A failed step that is not
        a slip the check names (a stub, an error raised, a time limit, ...) gives its `kind`, one of
        :data:`KINDS`."""
        if kind is not None and kind not in KINDS:
            raise InputError(f"a failed step's kind is one of {', '.join(map(repr, KINDS))}, not {kind!r}.")
        self.steps.append((description, bool(ok), "" if ok else detail))
        if kind is not None and not ok:
            self.kinds[len(self.steps) - 1] = kind
        return bool(ok)

    def fail(self, description, detail, hint, kind=None):
        self.step(description, False, detail, kind)
        self.hint = hint
        return self

    def add_steps(self, other):
        """Record `other`'s steps after this result's own, each failed one with its kind."""
        for index, (description, ok, detail) in enumerate(other.steps):
            self.step(description, ok, detail, other.kinds.get(index))

    @property
    def advice(self):
        """The hint as the student reads it: after the note, when the part failed and has one."""
        if self.note and not self.passed:
            return f"{self.note} {self.hint[:1].upper()}{self.hint[1:]}".strip()
        return self.hint

    def __repr__(self):
        verdict = "all checks passed" if self.passed else "FAILED"
        lines = [f"{self.name}: {verdict}"]
        for description, ok, detail in self.steps:
            lines.append(f"  [{'ok' if ok else 'FAIL'}] {description}" + (f": {detail}" if detail else ""))
        if self.advice:
            lines.append(f"  hint: {self.advice}")
        return "\n".join(lines)

    def as_dict(self):
        return {
            "name": self.name,
            "passed": self.passed,
            "hint": self.advice,
            "steps": [
                {"step": d, "passed": ok, "detail": det, **({"kind": self.kinds[i]} if i in self.kinds else {})}
                for i, (d, ok, det) in enumerate(self.steps)
            ],
        }


def judged_by_the_lab(result, why, lab):
    """Note in `result` that the part was judged against `lab` (labkit's reference) instead of the student's
    earlier work, because that work is no attempt at its task: `why` says what it is, in the student's words
    ("your tdata, ... are not the lab's 21 points"). The feedback gives the note with the hint when the part fails.

    "One mistake, one part" lets a part follow the student's earlier work only when that work is an attempt at
    the same task (the lab's, or within a slip the checks name): trivial earlier work is never a reference.
    """
    result.note = (
        f"{why[:1].upper()}{why[1:]}: that is not an attempt at the lab's task, so this part was judged "
        f"against {lab} instead of your own earlier work."
    )
    return result


class Results(list):
    """Several check results shown together, such as the parts of one plot."""

    @property
    def passed(self):
        return bool(self) and all(result.passed for result in self)

    def __repr__(self):
        return "\n".join(map(repr, self))


def case_rng(seed, name):
    """Random test data of the check `name` (its full name, e.g. ``"drivers.driver.pherm"``): fixed in a
    notebook's self-check, fresh per grading run.

    Each check has a stream of its own, keyed by a stable hash of its name, so
    no two checks share one. ``labkit grade`` passes its run's seed, so the
    data differ from run to run (no table of answers can be prepared) yet a
    run can be repeated exactly.
    """
    key = int.from_bytes(hashlib.sha256(str(name).encode()).digest()[:8], "little")
    return np.random.default_rng(key if seed is None else [int(seed), key])


def call(result, description, fn, *args):
    """Run student code; an exception becomes a failed step (never escapes).

    Returns ``(True, value)``, or ``(False, None)`` after recording the failure.
    Errors that come back from a sandboxed notebook carry the student's
    exception type in ``kind``; a refused reference implementation carries
    ``refused``. The grader's own errors (a time limit, a notebook that died or
    was tampered with) are exceptions of labkit's sandbox whose class gives the
    step's kind in ``grader_kind`` (:func:`grader_kind`); no exception of the
    student's, whatever its name or message, passes for one: it is an error
    raised.
    """
    try:
        return True, fn(*args)
    except NotImplementedError:
        result.fail(description, NOT_IMPLEMENTED, STUB, NOT_DONE)
    except Exception as exc:  # noqa: BLE001 - any student error is reported, not raised
        kind = getattr(exc, "kind", type(exc).__name__)
        refused = getattr(exc, "refused", None)
        own = grader_kind(exc)
        if own is None and refused:
            result.fail(
                description,
                f"called {refused}, which is switched off while this exercise is graded",
                f"the exercise asks you to write this yourself: do not call {refused}.",
                REFUSED,
            )
        elif own is not None:
            result.fail(description, _text(exc), ABOUT_THE_NOTEBOOK, own)
        else:
            where, slip = _where(exc), _raised_slip(kind, _text(exc))
            result.fail(
                description,
                f"raised {kind}: {_text(exc)}" + (f" ({where})" if where else ""),
                (f"the error happened {where}: " if where else "")
                + (
                    f"{slip}."
                    if slip
                    else "look at that line."
                    if where
                    else "run the cell with the error on its own: the traceback shows where it happened."
                ),
                RAISED,
            )
    return False, None


def grader_kind(exc):
    """The kind of a failed step an exception of the grader's own sandbox stands for (a time limit, a notebook
    that died or was tampered with), None for any other exception: the class of one of
    :mod:`labkit.grading.sandbox.remote`'s errors says it in ``grader_kind``, which no student's exception carries
    (an exception the student's code raised in the sandbox comes back as a plain ``StudentError``, whatever
    its name; the grader's own verdicts on a call come from the supervisor's marked answers, never a name).

    Examples
    --------
    >>> class Timeout(Exception):  # a student's own
    ...     grader_kind = TIMEOUT
    >>> grader_kind(Timeout("it ran past the time limit")) is None
    True
    """
    kind = getattr(type(exc), "grader_kind", None)
    own = type(exc).__module__.startswith("labkit.grading.")
    return kind if own and kind in KINDS else None


def gave_up(result):
    """True if the last call `result` recorded failed in a way no further call of the same code can explain: a
    stub, or a notebook that ran out of time, failed or was tampered with. A check that probes further to name
    a slip stops there (another call would only wait for the time limit again)."""
    return result.hint in (STUB, ABOUT_THE_NOTEBOOK)


def _raised_slip(kind, message):
    """The slip an exception of student code names by itself, in the student's words ('' for none): an index
    one past the end of an array (Python counts from 0), or ``^`` taken for a power (it is bitwise xor)."""
    import re

    found = re.search(r"index (-?\d+) is out of bounds for axis \d+ with size (\d+)", message or "")
    if kind == "IndexError" and found:
        index, size = int(found[1]), int(found[2])
        if index == size:
            return (
                f"index {index} is one past the last entry of an array of {size} entries (Python counts from 0, so "
                f"its last index is {size - 1}, or -1)"
            )
        return f"index {index} is outside an array of {size} entries (its indices are 0 to {size - 1})"
    if kind == "TypeError" and "bitwise_xor" in (message or ""):
        return "`^` is bitwise xor in Python, not a power: write a power with `**`"
    return ""


def _text(exc):
    """An exception's message, whatever its ``__str__`` does."""
    try:
        return str(exc)
    except Exception:  # noqa: BLE001 - a student's exception class may break str()
        return f"(an exception of type {type(exc).__name__}, whose message cannot be shown)"


def _where(exc):
    """Where the student's code raised `exc`: 'in f, line 7: `d = 2 / s`', from its traceback (local or remote)."""
    import re
    import traceback

    text = getattr(exc, "traceback", None)
    if not isinstance(text, str):
        try:
            text = "".join(traceback.format_tb(exc.__traceback__)) if exc.__traceback__ is not None else ""
        except Exception:  # noqa: BLE001 - a hostile traceback
            text = ""
    frames = re.findall(r'File "([^"]*)", line (\d+), in (\S+)\n\s*(.*)', text or "")
    own = [f for f in frames if "site-packages" not in f[0] and "/labkit/" not in f[0]]
    if not own:
        return ""
    _, line, function, source = own[-1]
    return f"in {function}, line {line}: `{source.strip()[:120]}`" if source.strip() else f"in {function}, line {line}"


class NotNumbers(TypeError):
    """A student's value that is not real numbers; the message says what it is instead."""


def floats(value):
    """A student's value as a float ndarray: the one conversion every check uses.

    Raises :class:`NotNumbers` (a TypeError, never a warning) for what is not
    real numbers, with a message that says what it is instead: complex values,
    text, ragged lists, numbers too large for a float, or a value from a
    sandboxed notebook that was not numbers.
    """
    if getattr(value, "not_numbers", False):  # a value from a sandboxed notebook that was not numbers
        raise NotNumbers(str(value))
    if isinstance(value, (str, bytes)):
        raise NotNumbers(f"got {type(value).__name__}, not numbers")
    try:
        if np.iscomplexobj(value):
            raise NotNumbers("got complex numbers, not real ones")
        return np.asarray(value, dtype=float)
    except NotNumbers:
        raise
    except OverflowError:
        raise NotNumbers("got numbers too large for a float") from None
    except (TypeError, ValueError):
        raise NotNumbers(f"got {type(value).__name__}, not numbers") from None


def several(value, count):
    """The `count` values a function returned together, or None.

    The lab's functions return several arrays (``[y, yprime] = runge(x)`` in
    MATLAB): a tuple, a list, or an array whose first axis has `count` rows all
    count, as in Python any of them unpacks the same way.
    """
    if getattr(value, "not_numbers", False) or isinstance(value, (str, bytes)):
        return None
    if isinstance(value, (tuple, list)) and len(value) == count:
        return tuple(value)
    if isinstance(value, np.ndarray) and value.ndim >= 1 and value.shape[0] == count:
        return tuple(value)
    return None


def close(actual, expected, tol=TOLERANCE):
    """True if `actual` is a finite float array of `expected`'s shape and agrees to `tol`."""
    try:
        actual = floats(actual)
    except NotNumbers:
        return False
    expected = np.asarray(expected, dtype=float)
    return (
        actual.shape == expected.shape
        and bool(np.all(np.isfinite(actual)))
        and bool(np.allclose(actual, expected, rtol=tol, atol=tol))
    )


def worst(actual, expected):
    """Why `actual` is not `expected`: what it is instead, or the largest difference."""
    try:
        actual = floats(actual)
    except NotNumbers as exc:
        return str(exc)
    expected = np.asarray(expected, dtype=float)
    if actual.shape != expected.shape:
        return f"expected shape {expected.shape}, got {actual.shape}"
    if not np.all(np.isfinite(actual)):
        return f"{int(np.sum(~np.isfinite(actual)))} value(s) are NaN or infinite"
    return f"largest difference {np.max(np.abs(actual - expected)):.2e}"


def shown(value):
    """Short text of a student's value for a failure message (rounded numbers, or what it is)."""
    try:
        values = floats(value)
    except NotNumbers as exc:
        return str(exc)
    with np.errstate(all="ignore"):  # 1e308 rounds to inf: shown as such, with no warning
        finite = np.abs(values[np.isfinite(values)])
        plain = np.all(finite < 1e6) and not np.any((finite > 0) & (finite < 1e-4))  # else numpy's e-notation
        return str(np.round(values, 6)) if plain else str(values)
