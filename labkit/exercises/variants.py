"""Every student their own data: the parameters an exercise may vary, and each student's values.

An exercise declares the data it lets vary as :class:`Param` objects
(:attr:`labkit.exercises.model.Exercise.params`): a notebook name, a range,
the digits the notebook shows and the lab's own value. A student's values are
derived, never stored where the student can edit them: each is a keyed hash
(HMAC-SHA256) of the course's secret, the student's identifier in the roster,
the exercise, the parameter and a draw number, mapped into the range and
rounded to the shown digits. The references are computed from the rounded
value, so what the notebook shows is exactly what is graded.

The course's secret lives in a small TOML file the instructor keeps
(:class:`VariantsFile`)::

    # labkit variants: keep this file private (who has it can work out every student's data)
    secret = "3f9c..."

    [redraw]            # a student's fresh draw of an exercise (0, the first draw, when absent)
    "1815" = {4 = 1}

``labkit variants --new FILE`` writes one; ``labkit variants --redraw ID
--exercise N --variants FILE`` gives one student a fresh draw of one exercise
(a bad draw can be changed, which login-seeded variants cannot). Release and
grading both read the same file, so they always agree.

A datum several exercises use (the Runge function's scale, which every
convergence table measures) is one :class:`Param` with ``drawn_with`` naming
the exercise whose draw gives it, so a student has one value of it, and a
redraw of that exercise changes it everywhere.

Without a variants file nothing changes: the lab's values (:func:`lab_values`)
are what the notebooks hold and what the checks use.
"""

from __future__ import annotations

import hashlib
import hmac
import math
import os
import secrets
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

SECRET_BYTES = 32
MAX_DRAW = 10_000  # redraws of one exercise for one student: a handful in practice
MAX_FILE_BYTES = 1024**2


@dataclass(frozen=True)
class Param:
    """One datum an exercise lets vary from student to student.

    ``name`` is the notebook's variable holding it (assigned in the notebook's
    cell tagged :data:`DATA_TAG`), drawn uniformly from ``[low, high]`` and
    rounded to ``digits`` decimals, the way the notebook shows it. ``lab`` is
    the lab's own value, what every notebook holds without variants.

    >>> Param("r0", 1.05, 1.3, 2, lab=1.15).value(0.5)
    1.18
    >>> Param("r0", 1.3, 1.05, 2, lab=1.15)
    Traceback (most recent call last):
    ...
    labkit.errors.InputError: parameter 'r0': its range [1.3, 1.05] is empty; give low < high.
    """

    name: str
    low: float
    high: float
    digits: int
    lab: float
    # the exercise whose draw gives the value, when several exercises share one datum (the Runge function's
    # scale, which every convergence table uses); None: each exercise declaring it draws its own
    drawn_with: int | None = None

    def __post_init__(self):
        if not str(self.name).isidentifier():
            raise InputError(f"a parameter's name is the notebook variable holding it; {self.name!r} is not a name.")
        values = (self.low, self.high, self.lab)
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in values):
            raise InputError(f"parameter {self.name!r}: low, high and lab must be finite numbers; got {values}.")
        if self.drawn_with is not None and (isinstance(self.drawn_with, bool) or not isinstance(self.drawn_with, int)):
            raise InputError(f"parameter {self.name!r}: drawn_with is an exercise number; got {self.drawn_with!r}.")
        if not self.low < self.high:
            raise InputError(f"parameter {self.name!r}: its range [{self.low}, {self.high}] is empty; give low < high.")
        if isinstance(self.digits, bool) or not isinstance(self.digits, int) or not 0 <= self.digits <= 12:
            raise InputError(f"parameter {self.name!r}: digits is a whole number from 0 to 12; got {self.digits!r}.")
        if not self.low <= self.lab <= self.high:
            raise InputError(
                f"parameter {self.name!r}: the lab's value {self.lab} is outside [{self.low}, {self.high}]."
            )
        try:
            one = self.value(0.0) == self.value(1.0)
        except (OverflowError, ValueError):
            raise InputError(
                f"parameter {self.name!r}: [{self.low}, {self.high}] at {self.digits} digits holds too many values."
            ) from None
        if one:
            raise InputError(
                f"parameter {self.name!r}: [{self.low}, {self.high}] holds one value at {self.digits} digits; "
                "widen the range or show more digits."
            )

    def value(self, u: float) -> float:
        """The value at position `u` in [0, 1] of the range, rounded to the shown digits and kept inside it."""
        step = 10.0**-self.digits
        first, last = math.ceil(self.low / step - 1e-9), math.floor(self.high / step + 1e-9)
        k = first + min(int(u * (last - first + 1)), last - first)
        return round(k * step, self.digits)

    def shown(self, value: float) -> str:
        """The value as the notebook's data cell writes it."""
        return f"{value:.{self.digits}f}"

    def holds(self, found, value: float) -> bool:
        """Whether a notebook's `found` is `value` as shown (to half a unit of its last digit)."""
        try:
            found = float(found)
        except (TypeError, ValueError, OverflowError):
            return False
        return math.isfinite(found) and abs(found - value) <= 0.5 * 10.0**-self.digits * (1 - 1e-9)


DATA_TAG = "variant-data"  # the tag of a notebook's cells that assign the varied data, ``name = value``


def _uniform(key: bytes, *fields) -> float:
    """A number in [0, 1) from the keyed hash of `fields`."""
    message = "\x1f".join(str(f) for f in fields).encode("utf-8")
    digest = hmac.new(key, message, hashlib.sha256).digest()
    return int.from_bytes(digest[:8], "big") / 2.0**64


def draw(secret: bytes, student: str, exercise: int, params, number: int = 0) -> dict:
    """The values of exercise `exercise`'s `params` for `student` (the roster id), draw `number`.

    >>> p = (Param("r0", 1.05, 1.3, 2, lab=1.15),)
    >>> draw(b"k" * 32, "1815", 4, p) == draw(b"k" * 32, "1815", 4, p)
    True
    >>> draw(b"k" * 32, "1815", 4, p) != draw(b"j" * 32, "1815", 4, p) or "a rare tie"
    True
    """
    return {
        p.name: p.value(_uniform(secret, "labkit-variant", student, int(exercise), p.name, int(number))) for p in params
    }


def lab_values(registry) -> dict:
    """Exercise number -> {parameter: the lab's own value}, for every exercise that declares parameters."""
    return {e.number: {p.name: p.lab for p in e.params} for e in registry if e.params}


@dataclass(frozen=True)
class VariantsFile:
    """A course's variants: its secret and the students' redraws ({roster id: {exercise: draw}})."""

    path: Path
    secret: bytes
    redraw: dict

    @property
    def digest(self) -> str:
        """What a grading run records of the file: its secret and redraws, hashed (never the secret itself)."""
        text = repr(sorted((k, sorted(v.items())) for k, v in self.redraw.items())).encode()
        return hashlib.sha256(b"labkit-variants\0" + self.secret + b"\0" + text).hexdigest()[:16]

    def values(self, registry, student: str) -> dict:
        """Exercise number -> {parameter: value} of `student` (the roster id) for every varied exercise."""
        student = str(student)
        redraws = self.redraw.get(student, {})
        found: dict = {}
        for e in registry:
            if e.params:
                found[e.number] = {}
                for p in e.params:
                    key = drawn_with(e.number, p)
                    found[e.number].update(draw(self.secret, student, key, (p,), redraws.get(key, 0)))
        return found


def drawn_with(exercise: int, param: Param) -> int:
    """The exercise whose draw gives `param`'s value in exercise `exercise` (itself, unless the datum is shared)."""
    return exercise if param.drawn_with is None else param.drawn_with


def drawing(registry) -> dict:
    """Exercise number -> the parameters drawn with it: each datum once, shared ones with the exercise that
    draws them (what a redraw of that exercise changes)."""
    found: dict = {}
    for e in registry:
        for p in e.params:
            names = found.setdefault(drawn_with(e.number, p), [])
            if p.name not in names:
                names.append(p.name)
    return found


def ties(found: VariantsFile, registry, students) -> list:
    """(exercise, [roster ids]) of the students who drew the same data of an exercise: a copy between them
    cannot be told from their own work, so give all but one a fresh draw (:func:`redraw`). A datum several
    exercises share is reported once, under the exercise that draws it."""
    by_data: dict = {}
    drawn = drawing(registry)
    for student in dict.fromkeys(str(s) for s in students):
        values = {name: value for given in found.values(registry, student).values() for name, value in given.items()}
        for number, names in drawn.items():
            given = tuple((name, values[name]) for name in sorted(names))
            by_data.setdefault((number, given), []).append(student)
    return [(number, group) for (number, _), group in sorted(by_data.items()) if len(group) > 1]


def read(path) -> VariantsFile:
    """Read a variants file; ValueError saying what is wrong with it and how to make one."""
    path = Path(path)
    fix = (
        "put back the copy you kept: its secret must stay the same, or every student's data changes."
        if path.exists()
        else f"make one with `labkit variants --new {path}` and keep it private."
    )
    try:
        raw = path.read_bytes()[: MAX_FILE_BYTES + 1]
    except OSError as exc:
        raise InputError(f"cannot read the variants file {path} ({exc.strerror or exc}); {fix}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise InputError(f"the variants file {path} is larger than a variants file can be; {fix}")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise InputError(f"the variants file {path} is not TOML ({exc}); {fix}") from None
    unknown = sorted(set(data) - {"secret", "redraw"})
    if unknown:
        raise InputError(f"the variants file {path} has unknown keys {unknown}; it holds `secret` and `[redraw]` only.")
    secret = data.get("secret")
    try:
        key = bytes.fromhex(secret) if isinstance(secret, str) else b""
    except ValueError:
        key = b""
    if len(key) < 16:
        raise InputError(f"the variants file {path} needs `secret`, at least 32 hexadecimal digits; {fix}")
    redraw = {}
    table = data.get("redraw", {})
    if not isinstance(table, dict):
        raise InputError(f'in {path}, [redraw] must be a table: "<roster id>" = {{<exercise> = <draw>}}.')
    for student, draws in table.items():
        if not isinstance(draws, dict):
            raise InputError(f"in {path}, the redraws of {student!r} must be a table such as {{4 = 1}}.")
        found = {}
        for exercise, number in draws.items():
            text = str(exercise)
            if not (text.isascii() and text.isdecimal()) or isinstance(number, bool) or not isinstance(number, int):
                raise InputError(
                    f"in {path}, {student!r} = {{{exercise} = {number!r}}}: give an exercise number and a whole draw "
                    "number, such as {4 = 1}."
                )
            if not 0 <= number <= MAX_DRAW:
                raise InputError(f"in {path}, draw {number} of {student!r} is outside 0..{MAX_DRAW}.")
            found[int(exercise)] = number
        redraw[str(student)] = found
    return VariantsFile(path, key, redraw)


def new(path) -> VariantsFile:
    """Write a new variants file with a fresh random secret (never over an existing file); read it back."""
    path = Path(path)
    text = (
        "# labkit variants: keep this file private (who has it can work out every student's data)\n"
        f'secret = "{secrets.token_hex(SECRET_BYTES)}"\n\n'
        '[redraw]  # a student\'s fresh draw of an exercise: "<roster id>" = {<exercise> = <draw>}\n'
    )
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:
        raise InputError(
            f"{path} already exists; a new secret would change every student's data. Choose another path."
        ) from None
    with os.fdopen(fd, "w", encoding="utf-8") as handle:
        handle.write(text)
    return read(path)


def redraw(path, student: str, exercise: int, registry) -> int:
    """Give `student` the next draw of `exercise` in the variants file at `path`; the new draw number."""
    current = read(path)
    exercise = int(exercise)
    drawn = drawing(registry)
    if exercise not in drawn:
        shared = sorted(
            {drawn_with(exercise, p) for p in registry.exercises[exercise].params}
            if exercise in registry.exercises
            else ()
        )
        if shared:
            raise InputError(
                f"exercise {exercise}'s data are drawn with exercise {shared[0]}'s (they share them): "
                f"redraw exercise {shared[0]}."
            )
        raise InputError(f"exercise {exercise} has no variants; the varied exercises are {sorted(drawn)}.")
    student = str(student)
    if not student or not student.isprintable():
        raise InputError(f"{student!r} is not a roster id this file can hold; give the id as the roster has it.")
    redraws = {key: dict(value) for key, value in current.redraw.items()}
    draws = redraws.setdefault(student, {})
    draws[exercise] = draws.get(exercise, 0) + 1
    write(path, current.secret, redraws)
    return draws[exercise]


def write(path, secret: bytes, redraws: dict) -> VariantsFile:
    """Write a variants file of `secret` and `redraws` ({roster id: {exercise: draw}}) whole, through a file
    beside it that is read back first (the old file stays as it was if anything fails); read it back."""
    import json

    path = Path(path)
    lines = [
        "# labkit variants: keep this file private (who has it can work out every student's data)",
        f'secret = "{secret.hex()}"',
        "",
        '[redraw]  # a student\'s fresh draw of an exercise: "<roster id>" = {<exercise> = <draw>}',
    ]
    for student, draws in sorted(redraws.items()):
        entry = ", ".join(f"{n} = {d}" for n, d in sorted(draws.items()))
        lines.append(f"{json.dumps(student)} = {{{entry}}}")  # a JSON string is a TOML basic string
    partial = path.with_name(f".{path.name}.partial")
    partial.write_text("\n".join(lines) + "\n", encoding="utf-8")
    try:
        written = read(partial)
        if written.secret != secret or written.redraw != redraws:
            raise InputError(f"{path} could not be written as it should be; it was left as it was.")
        os.chmod(partial, 0o600)
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)
    return read(path)
