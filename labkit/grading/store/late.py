"""Late work: the rubric's ``[late]`` table (:func:`from_dict`), the submission times it reads, and the penalty.

The table and its rule are documented for instructors in ``docs/instructors.md`` ("Late work");
:meth:`Late.assess` applies the rule to one submission, counting lateness from the student's own deadline.
"""

import math
import os
import re
import stat
from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta, tzinfo
from pathlib import Path

from ...errors import InputError
from .text import is_number, points_text

UNITS = {"day": 86400, "hour": 3600}
MINUTE = int(timedelta(minutes=1).total_seconds())
FORMAT = "ISO 8601 with a UTC offset, e.g. 2026-12-01T23:59:00+01:00 (or ...T22:59:00Z)"
FROM_CSV = "the --times file"
FROM_EXCHANGE = "nbgrader's exchange"
# written by the student's own process or tools (nbgrader's submit step writes timestamp.txt as the student)
FROM_NBGRADER = "timestamp.txt in the submission, student-supplied"
FROM_MTIME = "the notebooks' file times, student-supplied"
STUDENT_SUPPLIED = (FROM_NBGRADER, FROM_MTIME)
KEYS = {"deadline", "per", "percent", "cap", "grace", "extensions"}
SHOWN = 80  # characters of a name or a bad value quoted in a message

_ISO = re.compile(r"\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}(?::\d{2}(?:\.\d{1,6})?)?(?:Z|[+-]\d{2}:\d{2})")


def parse_deadline(value: str | datetime, where: str = "the deadline") -> datetime:
    """A deadline as a timezone-aware datetime, from ISO 8601 text with a UTC offset (``Z`` is ``+00:00``, the
    seconds may be left out) or a TOML offset date-time; InputError naming `where` for anything else.

    >>> parse_deadline("2026-12-01T23:59:00+01:00").isoformat()
    '2026-12-01T23:59:00+01:00'
    >>> parse_deadline("2026-12-01T23:59")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    labkit.errors.InputError: the deadline is '2026-12-01T23:59', which has no UTC offset: write it as ISO 8601...
    """
    if isinstance(value, datetime):
        if value.tzinfo is None or value.utcoffset() is None:
            raise InputError(f"{where} is {value.isoformat()}, which has no UTC offset: write it as {FORMAT}.")
        return value
    if not isinstance(value, str):
        raise InputError(f"{where} is {value!r}, not a time: write it as {FORMAT}.")
    text = value.strip()
    if not _ISO.fullmatch(text):
        plain = re.fullmatch(r"\d{4}-\d{2}-\d{2}(?:[T ]\d{2}:\d{2}(?::\d{2}(?:\.\d+)?)?)?", text)
        why = "which has no UTC offset" if plain else "which is not in that format"
        raise InputError(f"{where} is {value[:SHOWN]!r}, {why}: write it as {FORMAT}.")
    try:
        return datetime.fromisoformat(text)
    except ValueError as exc:
        raise InputError(f"{where} is {value!r}, which is not a real time ({exc}): write it as {FORMAT}.") from None


def time_text(moment: datetime, zone: tzinfo | None = None) -> str:
    """A moment as ISO 8601 text to the second, in the offset of `zone` (a tzinfo) when given.

    >>> time_text(parse_deadline("2026-12-01T22:59:00Z"), parse_deadline("2026-12-01T00:00+01:00").tzinfo)
    '2026-12-01T23:59:00+01:00'
    """
    return (moment.astimezone(zone) if zone is not None else moment).isoformat(timespec="seconds")


def duration_text(delta: timedelta) -> str:
    """A positive duration in days, hours and minutes (seconds below one minute).

    >>> duration_text(timedelta(days=1, hours=2, minutes=5, seconds=30))
    '1 day 2 h 5 min'
    >>> duration_text(timedelta(seconds=42))
    '42 s'
    """
    seconds = int(delta.total_seconds())
    if seconds < MINUTE:
        return f"{seconds} s"
    days, rest = divmod(seconds, UNITS["day"])
    hours, rest = divmod(rest, UNITS["hour"])
    parts = [f"{days} day{'s' if days != 1 else ''}"] if days else []
    parts += [f"{hours} h"] if hours else []
    parts += [f"{rest // MINUTE} min"] if rest >= MINUTE else []
    return " ".join(parts)


@dataclass(frozen=True)
class SubmissionTime:
    """When a submission was handed in (timezone-aware; None when unknown), where that came from
    (:data:`FROM_CSV`, :data:`FROM_EXCHANGE`, :data:`FROM_NBGRADER` or :data:`FROM_MTIME`), and why it could not
    be read, when it could not.
    """

    when: datetime | None = None
    source: str | None = None
    problem: str | None = None

    def as_dict(self) -> dict:
        """The time as JSON data (UTC, ISO 8601), for a result file."""
        time = None if self.when is None else self.when.astimezone(UTC).isoformat()
        return {"time": time, "source": self.source, "problem": self.problem}

    @classmethod
    def from_dict(cls, data: dict | None) -> "SubmissionTime | None":
        """Read back :meth:`as_dict`'s data (None gives None); ValueError if it is not that."""
        if data is None:
            return None
        if not isinstance(data, dict) or set(data) - {"time", "source", "problem"}:
            raise InputError("its submission time is not a time, source and problem")
        when = None if data.get("time") is None else parse_deadline(data["time"], "its submission time")
        source, problem = data.get("source"), data.get("problem")
        if not all(v is None or isinstance(v, str) for v in (source, problem)):
            raise InputError("its submission time's source and problem must be text")
        return cls(when, source, problem)


@dataclass(frozen=True)
class Lateness:
    """What the late rule made of one submission: its deadline (the rubric's or an extension), when it came
    (``late_by`` is None when unknown, zero or less when on time), the started ``units`` counted, the
    ``percent`` taken (the cap applied) of the ``raw_total``, the ``penalty`` in points (to 0.01), and a
    ``note`` for ``grades.csv``.
    """

    deadline: datetime
    extended: bool
    time: SubmissionTime | None
    late_by: timedelta | None
    units: int
    percent: float
    raw_total: float
    penalty: float
    note: str

    @property
    def total(self) -> float:
        """The points after the penalty."""
        return round(self.raw_total - self.penalty, 2)

    @property
    def known(self) -> bool:
        """Whether the submission's time is known."""
        return self.late_by is not None


@dataclass(frozen=True)
class Late:
    """The rubric's late rule (``docs/instructors.md`` gives its table): the deadline, the unit whose started
    ones count (``"day"`` or ``"hour"``), the percent lost per unit, the cap in percent, the grace in minutes,
    and each extension as a ``(name, deadline)`` pair.
    """

    deadline: datetime
    per: str
    percent: float
    cap: float
    grace: float = 0.0
    extensions: tuple = field(default=())

    def deadline_for(self, name: str) -> tuple[datetime, bool]:
        """(the deadline of submission `name`, whether it is an extension)."""
        extended = dict(self.extensions).get(name)
        return (self.deadline, False) if extended is None else (extended, True)

    def assess(self, name: str, time: SubmissionTime | None, raw_total: float) -> Lateness:
        """The :class:`Lateness` of submission `name`, handed in at `time` (a :class:`SubmissionTime` or
        None), whose points before the penalty are `raw_total`.

        >>> rule = from_dict({"deadline": "2026-12-01T23:59:00+01:00", "per": "day", "percent": 10, "cap": 50})
        >>> handed_in = SubmissionTime(parse_deadline("2026-12-03T08:00:00+01:00"), FROM_CSV)
        >>> late = rule.assess("ada", handed_in, 80)
        >>> late.units, late.percent, late.penalty, late.total
        (2, 20.0, 16.0, 64.0)
        """
        deadline, extended = self.deadline_for(name)
        if time is None or time.when is None:
            why = f"its submission time could not be read ({time.problem})" if time and time.problem else None
            note = f"{why or 'no submission time'}: not penalised"
            return Lateness(deadline, extended, time, None, 0, 0.0, raw_total, 0.0, note)
        late_by = time.when - deadline
        if late_by <= timedelta(minutes=self.grace):  # the grace is never negative (from_dict)
            note = "on time" if late_by <= timedelta(0) else f"on time (within the {_number(self.grace)}-minute grace)"
            return Lateness(deadline, extended, time, late_by, 0, 0.0, raw_total, 0.0, note)
        units = math.ceil(late_by.total_seconds() / UNITS[self.per])
        percent = min(units * self.percent, self.cap)
        penalty = round(raw_total * percent / 100, 2)
        capped = " (the cap)" if units * self.percent > self.cap else ""
        note = (
            f"late by {duration_text(late_by)}: {units} started {self.per}{'s' if units != 1 else ''}, "
            f"{_number(percent)}% off{capped}"
        )
        if extended:
            note += " (after an extension)"
        return Lateness(deadline, extended, time, late_by, units, float(percent), raw_total, penalty, note)

    def describe(self) -> str:
        """The rule in one line, for the feedback: it names no student (extensions are private)."""
        grace = f", with {_number(self.grace)} minute{'s' if self.grace != 1 else ''} of grace" if self.grace else ""
        return (
            f"late work: due {time_text(self.deadline)}{grace}; {_number(self.percent)}% of the points "
            f"off per started {self.per} late, at most {_number(self.cap)}%"
        )

    def feedback(self, lateness: Lateness) -> str:
        """The line of one submission's feedback about its lateness."""
        zone = self.deadline.tzinfo
        due = f"{time_text(lateness.deadline, zone)}{' (your extension)' if lateness.extended else ''}"
        if not lateness.known or lateness.time is None or lateness.time.when is None:
            return f"Late work: due {due}; this submission's time is not known, so no late penalty was applied."
        handed_in = f"handed in {time_text(lateness.time.when, zone)} ({lateness.time.source})"
        off = f": {points_text(lateness.penalty)} of {points_text(lateness.raw_total)} points" if lateness.units else ""
        return f"Late work: due {due}; {handed_in}: {lateness.note}{off}."


def _number(value):
    return f"{int(value)}" if float(value) == int(value) else f"{value:g}"


def _amount(table, key, source, high=None, unit=""):
    value = table[key]
    if not is_number(value):
        raise InputError(f"{source}: [late] {key} must be a number{unit}; got {value!r}.")
    if value < 0 or (high is not None and value > high):
        bound = f"between 0 and {_number(high)}" if high is not None else "at least 0"
        raise InputError(f"{source}: [late] {key} must be {bound}{unit}; got {value!r}.")
    return float(value)


def from_dict(table: dict, source: str = "the rubric") -> Late:
    """A validated :class:`Late` from the rubric's parsed ``[late]`` table (``deadline``, ``per``, ``percent`` and
    ``cap``; ``grace`` and ``extensions`` optional); InputError saying which key is wrong and what it must be.
    """
    section = f"{source}: [late]"
    if not isinstance(table, dict):
        raise InputError(f"{section} must be a table with deadline, per, percent and cap.")
    unknown = sorted(map(str, set(table) - KEYS))
    if unknown:
        raise InputError(f"{source}: unknown key(s) {', '.join(unknown)} in [late]; it has {', '.join(sorted(KEYS))}.")
    missing = [key for key in ("deadline", "per", "percent", "cap") if key not in table]
    if missing:
        raise InputError(
            f'{section} needs {", ".join(missing)} (e.g. deadline = "2026-12-01T23:59:00+01:00", '
            'per = "day", percent = 10, cap = 50).'
        )
    deadline = parse_deadline(table["deadline"], f"{section} deadline")
    per = table["per"]
    if per not in UNITS:
        raise InputError(f'{section} per must be "day" or "hour" (what a started unit of lateness is); got {per!r}.')
    percent = _amount(table, "percent", source, 100, " (percent of the points per started unit)")
    cap = _amount(table, "cap", source, 100, " (the largest penalty, in percent)")
    grace = _amount(table, "grace", source, unit=" of minutes") if "grace" in table else 0.0
    extensions, listing = table.get("extensions", {}), f"{source}: [late.extensions]"
    if not isinstance(extensions, dict):
        raise InputError(f'{listing} must be a table of `name = "new deadline"` or `name = hours` lines.')
    granted = []
    for name, value in extensions.items():
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"{listing} has the name {name!r}; a name is a submission's name, as text.")
        where = f"{listing} {name[:SHOWN]!r}"
        if isinstance(value, (str, datetime)):
            new = parse_deadline(value, where)
        elif is_number(value):
            if value <= 0:
                raise InputError(f"{where} gives {value!r} hours; an extension adds more than 0 hours.")
            new = deadline + timedelta(hours=value)
        else:
            raise InputError(f"{where} is {value!r}: give a new deadline ({FORMAT}) or a number of hours.")
        if new <= deadline:
            raise InputError(
                f"{where} is {time_text(new, deadline.tzinfo)}, not after the deadline {time_text(deadline)}; "
                "an extension gives more time."
            )
        granted.append((name, new))
    return Late(deadline, per, percent, cap, grace, tuple(granted))


def read_small(path, limit):
    """The bytes of regular file `path`, never following a link nor waiting on a pipe; ValueError says why not
    (FileNotFoundError when there is none)."""
    path = Path(path)
    if stat.S_ISLNK(os.lstat(path).st_mode):
        raise InputError(f"{path.name} is a symbolic link; links are never followed")
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | getattr(os, "O_NONBLOCK", 0))
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise InputError(f"{path.name} is not a file")
        if info.st_size > limit:
            raise InputError(f"{path.name} is {info.st_size:,} bytes, more than the {limit:,} it can be")
        with os.fdopen(fd, "rb", closefd=False) as handle:
            return handle.read(limit)
    finally:
        os.close(fd)


def unknown_times(grades: list) -> list[tuple[str, str, bool]]:
    """(name, note, whether it is an error) of each graded submission that a rubric's deadline applies to
    but whose time is unknown; an error is a time that could not be read.
    """
    return [
        (grade.name, lateness.note, bool(lateness.time and lateness.time.problem))
        for grade in grades
        if grade.graded and (lateness := grade.lateness) is not None and not lateness.known
    ]
