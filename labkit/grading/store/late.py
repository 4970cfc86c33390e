"""Late work: the rubric's ``[late]`` table, when each submission was handed in, and the penalty.

A rubric may say when the work was due and what lateness costs::

    [late]
    deadline = "2026-12-01T23:59:00+01:00"  # ISO 8601 with its UTC offset
    per = "day"                             # the penalty counts started days ("day") or hours ("hour")
    percent = 10                            # percent of the submission's points lost per started day
    cap = 50                                # the most it can lose, in percent
    grace = 15                              # minutes after a deadline that still count as on time (optional)

    [late.extensions]                       # optional: a student's own deadline
    alice = "2026-12-03T23:59:00+01:00"     # a new deadline
    bob = 48                                # or hours added to the deadline

The penalty is a share of the submission's own points (its total under the
rubric, extra credit included): ``min(percent * started units, cap)`` percent
of it. Lateness is counted from the student's deadline; the grace decides
only whether a submission is late at all, so one 20 minutes late with 15
minutes' grace is one started hour (or day) late.

A submission's time (:class:`SubmissionTime`) comes, in this order of
precedence, from the instructor's ``--times TIMES.csv`` (columns
``submission`` and ``time``), from nbgrader's ``timestamp.txt`` at the top of
the submission's folder (:func:`parse_timestamp` reads every format nbgrader
writes with a UTC offset or UTC itself), and, only when the instructor asks for
it (``--times-from-mtime``), from the newest modification time of its
notebooks. A submission with no time while a deadline is set is graded and
not penalised, and the grades and the feedback say so; an unreadable
``timestamp.txt`` is reported the same way, with the reason, for the
instructor to give that time in ``--times``.
"""

import csv
import math
import os
import re
import stat
from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta, timezone, tzinfo
from pathlib import Path

from ...errors import InputError
from .text import points_text

UNITS = {"day": 86400, "hour": 3600}
TIMESTAMP = "timestamp.txt"  # nbgrader's name, in the submission's folder
MAX_TIMESTAMP = 256  # bytes: nbgrader writes about 30
MAX_TIMES = 10 * 1024**2  # bytes of a --times file
FORMAT = "ISO 8601 with a UTC offset, e.g. 2026-12-01T23:59:00+01:00 (or ...T22:59:00Z)"
FROM_CSV = "the --times file"
FROM_EXCHANGE = "nbgrader's exchange"
# written by the student's own process or tools (nbgrader's submit step writes timestamp.txt as the student)
FROM_NBGRADER = "timestamp.txt in the submission, student-supplied"
FROM_MTIME = "the notebooks' file times, student-supplied"
STUDENT_SUPPLIED = (FROM_NBGRADER, FROM_MTIME)
KEYS = {"deadline", "per", "percent", "cap", "grace", "extensions"}
SHOWN = 80  # characters of a name or a bad value quoted in a message
MINUTE = timedelta(minutes=1)

_ISO = re.compile(r"\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}(?::\d{2}(?:\.\d{1,6})?)?(?:Z|[+-]\d{2}:\d{2})")
# nbgrader: "%Y-%m-%d %H:%M:%S.%f %Z" (older: without .%f), or an ISO time (what `zip_collect` writes)
_NBGRADER = re.compile(
    r"(?P<date>\d{4}-\d{2}-\d{2})[T ](?P<time>\d{2}:\d{2}(?::\d{2}(?:[.,]\d{1,9})?)?)"
    r"\s*(?P<zone>Z|UTC|GMT|[+-]\d{2}:?\d{2}|[A-Za-z][A-Za-z0-9/_+-]{0,40})?"
)


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
        return datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError as exc:
        raise InputError(f"{where} is {value!r}, which is not a real time ({exc}): write it as {FORMAT}.") from None


def parse_timestamp(text: str) -> datetime:
    """The time nbgrader wrote in a ``timestamp.txt``, as a timezone-aware datetime.

    nbgrader writes ``"%Y-%m-%d %H:%M:%S.%f %Z"`` in its configured timezone, older versions without the
    fraction, ``nbgrader zip_collect`` an ISO time with an offset; all are read, as is a numeric offset. A time
    without a zone, or with a zone name other than UTC or GMT (``CET`` names several), is an InputError: which
    moment it means cannot be known.

    >>> parse_timestamp("2026-12-01 23:59:59.123456 UTC\\n").isoformat()
    '2026-12-01T23:59:59.123456+00:00'
    >>> parse_timestamp("2026-12-02 00:30:00+0100").isoformat()
    '2026-12-02T00:30:00+01:00'
    """
    line = str(text).strip().lstrip("\ufeff").strip()
    match = _NBGRADER.fullmatch(line)
    if not match:
        shown = line[:SHOWN] + ("..." if len(line) > SHOWN else "")
        raise InputError(f"{shown!r} is not a time as nbgrader writes it (e.g. 2026-12-01 23:59:59.123456 UTC)")
    zone = match["zone"]
    if zone is None:
        raise InputError(f"{line!r} has no time zone, so the moment it means is unknown")
    if zone in ("Z", "UTC", "GMT"):
        offset = UTC
    elif zone[0] in "+-":
        digits = zone[1:].replace(":", "")
        if int(digits[:2]) > 23 or int(digits[2:]) > 59:
            raise InputError(f"{line!r} has the offset {zone}, which no time zone has")
        offset = timezone((1 if zone[0] == "+" else -1) * timedelta(hours=int(digits[:2]), minutes=int(digits[2:])))
    else:
        raise InputError(
            f"{line!r} names the time zone {zone!r}, which labkit cannot place (only UTC, GMT and numeric "
            "offsets are unambiguous)"
        )
    clock = match["time"].replace(",", ".")
    if "." in clock:
        whole, fraction = clock.split(".")
        clock = f"{whole}.{fraction[:6].ljust(6, '0')}"
    try:
        naive = datetime.fromisoformat(f"{match['date']}T{clock}")
    except ValueError as exc:
        raise InputError(f"{line!r} is not a real time ({exc})") from None
    return naive.replace(tzinfo=offset)


def time_text(moment: datetime, zone: tzinfo | None = None) -> str:
    """A moment as ISO 8601 text to the second, in the offset of `zone` (a tzinfo) when given.

    Examples
    --------
    >>> time_text(parse_deadline("2026-12-01T22:59:00Z"), parse_deadline("2026-12-01T00:00+01:00").tzinfo)
    '2026-12-01T23:59:00+01:00'
    """
    return (moment.astimezone(zone) if zone is not None else moment).isoformat(timespec="seconds")


def duration_text(delta: timedelta) -> str:
    """A positive duration in days, hours and minutes (seconds below one minute).

    Examples
    --------
    >>> duration_text(timedelta(days=1, hours=2, minutes=5, seconds=30))
    '1 day 2 h 5 min'
    >>> duration_text(timedelta(seconds=42))
    '42 s'
    """
    if delta < MINUTE:
        return f"{int(delta.total_seconds())} s"
    days, rest = divmod(int(delta.total_seconds()), UNITS["day"])
    hours, rest = divmod(rest, UNITS["hour"])
    minutes = rest // int(MINUTE.total_seconds())
    parts = [f"{days} day{'s' if days != 1 else ''}"] if days else []
    parts += [f"{hours} h"] if hours else []
    parts += [f"{minutes} min"] if minutes else []
    return " ".join(parts)


@dataclass(frozen=True)
class SubmissionTime:
    """When a submission was handed in (timezone-aware; None when unknown), where that came from
    (:data:`FROM_CSV`, :data:`FROM_EXCHANGE`, :data:`FROM_NBGRADER` or :data:`FROM_MTIME`), and why it could not be
    read, when it could not.
    """

    when: datetime | None = None
    source: str | None = None
    problem: str | None = None

    def as_dict(self) -> dict:
        """The time as JSON data (UTC, ISO 8601), for a result file."""
        return {
            "time": None if self.when is None else self.when.astimezone(UTC).isoformat(),
            "source": self.source,
            "problem": self.problem,
        }

    @classmethod
    def from_dict(cls, data: dict | None) -> "SubmissionTime | None":
        """Read back :meth:`as_dict`'s data (None gives None); ValueError if it is not that."""
        if data is None:
            return None
        if not isinstance(data, dict) or set(data) - {"time", "source", "problem"}:
            raise InputError("its submission time is not a time, source and problem")
        when = data.get("time")
        if when is not None:
            when = parse_deadline(when, "its submission time")
        source, problem = data.get("source"), data.get("problem")
        if not all(v is None or isinstance(v, str) for v in (source, problem)):
            raise InputError("its submission time's source and problem must be text")
        return cls(when, source, problem)


@dataclass(frozen=True)
class Lateness:
    """What the late rule made of one submission: its deadline (the rubric's or an extension), when it came
    (``late_by`` is None when unknown, zero or less when on time), the started ``units`` counted, the ``percent``
    taken (the cap applied) of the ``raw_total``, the ``penalty`` in points (to 0.01), and a ``note`` for
    ``grades.csv``.
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
    """The rubric's late rule (the module's documentation gives its table): the deadline, the unit whose started
    ones count (``"day"`` or ``"hour"``), the percent lost per unit, the cap in percent, the grace in minutes, and
    each extension as a ``(name, deadline)`` pair.
    """

    deadline: datetime
    per: str
    percent: float
    cap: float
    grace: float = 0.0
    extensions: tuple = field(default=())

    def deadline_for(self, name: str) -> tuple[datetime, bool]:
        """(the deadline of submission `name`, whether it is an extension)."""
        for student, deadline in self.extensions:
            if student == name:
                return deadline, True
        return self.deadline, False

    def assess(self, name: str, time: SubmissionTime | None, raw_total: float) -> Lateness:
        """The :class:`Lateness` of submission `name`, handed in at `time` (a :class:`SubmissionTime` or
        None), whose points before the penalty are `raw_total`.

        Examples
        --------
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
        grace = timedelta(minutes=self.grace)
        if late_by <= timedelta(0) or late_by <= grace:
            note = "on time" if late_by <= timedelta(0) else f"on time (within the {_minutes(self.grace)} grace)"
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

    def feedback(self, lateness: Lateness) -> list[str]:
        """The lines of one submission's feedback about its lateness."""
        zone = self.deadline.tzinfo
        due = f"{time_text(lateness.deadline, zone)}{' (your extension)' if lateness.extended else ''}"
        if not lateness.known or lateness.time is None or lateness.time.when is None:
            return [
                f"Late work: due {due}; this submission's time is not known, so no late penalty was applied.",
            ]
        handed_in = f"handed in {time_text(lateness.time.when, zone)} ({lateness.time.source})"
        if not lateness.units:
            return [f"Late work: due {due}; {handed_in}: {lateness.note}."]
        return [
            f"Late work: due {due}; {handed_in}: {lateness.note}: "
            f"{points_text(lateness.penalty)} of {points_text(lateness.raw_total)} points.",
        ]


def _number(value):
    return f"{int(value)}" if float(value) == int(value) else f"{value:g}"


def _minutes(value):
    return f"{_number(value)}-minute" if value != 1 else "1-minute"


def _amount(table, key, source, low=0.0, high=None, unit=""):
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{source}: [late] {key} must be a number{unit}; got {value!r}.")
    if value < low or (high is not None and value > high):
        bound = f"between {_number(low)} and {_number(high)}" if high is not None else f"at least {_number(low)}"
        raise InputError(f"{source}: [late] {key} must be {bound}{unit}; got {value!r}.")
    return float(value)


def from_dict(table: dict, source: str = "the rubric") -> Late:
    """A validated :class:`Late` from the rubric's parsed ``[late]`` table (``deadline``, ``per``, ``percent`` and
    ``cap``; ``grace`` and ``extensions`` optional); InputError saying which key is wrong and what it must be.
    """
    if not isinstance(table, dict):
        raise InputError(f"{source}: [late] must be a table with deadline, per, percent and cap.")
    unknown = sorted(map(str, set(table) - KEYS))
    if unknown:
        raise InputError(f"{source}: unknown key(s) {', '.join(unknown)} in [late]; it has {', '.join(sorted(KEYS))}.")
    missing = [key for key in ("deadline", "per", "percent", "cap") if key not in table]
    if missing:
        raise InputError(
            f'{source}: [late] needs {", ".join(missing)} (e.g. deadline = "2026-12-01T23:59:00+01:00", '
            'per = "day", percent = 10, cap = 50).'
        )
    deadline = parse_deadline(table["deadline"], f"{source}: [late] deadline")
    per = table["per"]
    if per not in UNITS:
        raise InputError(
            f'{source}: [late] per must be "day" or "hour" (what a started unit of lateness is); got {per!r}.'
        )
    percent = _amount(table, "percent", source, 0, 100, " (percent of the points per started unit)")
    cap = _amount(table, "cap", source, 0, 100, " (the largest penalty, in percent)")
    grace = _amount(table, "grace", source, 0, unit=" of minutes") if "grace" in table else 0.0
    extensions = table.get("extensions", {})
    if not isinstance(extensions, dict):
        raise InputError(
            f'{source}: [late.extensions] must be a table of `name = "new deadline"` or `name = hours` lines.'
        )
    granted = []
    for name, value in extensions.items():
        if not isinstance(name, str) or not name.strip():
            raise InputError(
                f"{source}: [late.extensions] has the name {name!r}; a name is a submission's name, as text."
            )
        where = f"{source}: [late.extensions] {name[:SHOWN]!r}"
        if isinstance(value, (str, datetime)):
            new = parse_deadline(value, where)
        elif isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
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
        chunks, size = [], 0
        while size < limit:
            chunk = os.read(fd, limit - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


def read_timestamp(submission: str | os.PathLike) -> SubmissionTime | None:
    """The time in nbgrader's ``timestamp.txt`` at the top of a submission's folder: None when there is no
    such file (a single notebook has none), a time whose ``problem`` says why when it cannot be read.
    """
    path = Path(submission) / TIMESTAMP
    try:
        if not stat.S_ISDIR(os.lstat(submission).st_mode):
            return None
        os.lstat(path)
    except OSError:
        return None
    try:
        raw = read_small(path, MAX_TIMESTAMP)
        return SubmissionTime(parse_timestamp(raw.decode("utf-8")), FROM_NBGRADER)
    except UnicodeDecodeError:
        return SubmissionTime(None, FROM_NBGRADER, f"{TIMESTAMP} is not text")
    except (OSError, ValueError) as exc:
        return SubmissionTime(None, FROM_NBGRADER, f"{TIMESTAMP}: {exc}")


def modification_time(notebooks: list) -> SubmissionTime | None:
    """The newest modification time of a submission's notebooks (only on the instructor's explicit
    request: the student sets it); None when there are none.
    """
    times = []
    for path in notebooks:
        try:
            times.append(os.lstat(path).st_mtime)
        except OSError:
            continue
    if not times:
        return None
    return SubmissionTime(datetime.fromtimestamp(max(times), UTC), FROM_MTIME)


def read_times(path: str | os.PathLike) -> dict[str, datetime]:
    """{submission name: datetime} from a CSV file with the columns ``submission`` and ``time`` (others are
    ignored); a time is ISO 8601 with a UTC offset, or as nbgrader writes it (``2026-12-01 23:59:59 UTC``).
    InputError when the file cannot be read, lacks a column, names a submission twice or has a bad time (naming
    the line).
    """
    path = Path(path)
    try:
        raw = read_small(path, MAX_TIMES)
        text = raw.decode("utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"the times file {path} does not exist.") from None
    except (OSError, ValueError) as exc:  # UnicodeDecodeError is a ValueError
        raise InputError(f"cannot read the times file {path}: {exc}.") from None
    rows = csv.reader(text.splitlines())
    header = [cell.strip().lower() for cell in next(rows, [])]
    if "submission" not in header or "time" not in header:
        raise InputError(
            f"{path} needs a header row with the columns submission and time "
            "(e.g. `submission,time` then `alice,2026-12-01T23:10:00+01:00`)."
        )
    who, when = header.index("submission"), header.index("time")
    times = {}
    for line, row in enumerate(rows, start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) <= max(who, when):
            raise InputError(f"{path}, line {line}: it has {len(row)} cell(s), fewer than the header's columns.")
        name = row[who].strip()
        if not name:
            raise InputError(f"{path}, line {line}: the submission's name is empty.")
        if name in times:
            raise InputError(f"{path}, line {line}: {name[:SHOWN]!r} is listed twice; keep one time per submission.")
        try:
            times[name] = parse_timestamp(row[when])
        except ValueError as exc:
            raise InputError(f"{path}, line {line} ({name[:SHOWN]!r}): {exc}; write it as {FORMAT}.") from None
    return times


def submission_time(
    submission: str | os.PathLike | None,
    name: str,
    times: dict | None = None,
    notebooks: list | None = None,
    from_mtime: bool = False,
    *,
    from_submission: bool = False,
    exchange: dict | None = None,
) -> SubmissionTime | None:
    """The time of one submission (None when no source has one), by the module's precedence: `times`
    ({name: datetime}, the LMS's, which the student cannot write), then `exchange` (read by labkit from nbgrader's
    exchange, :func:`read_exchange`), then, only with `from_submission`, the ``timestamp.txt`` in its folder, then,
    only with `from_mtime`, its `notebooks`' modification time. The last two are written by the student's own
    process, and marked student-supplied. `submission` is None when it has nothing on disk.
    """
    if times and name in times:
        return SubmissionTime(times[name], FROM_CSV)
    if exchange and name in exchange:
        return SubmissionTime(exchange[name], FROM_EXCHANGE)
    if submission is None:
        return None
    if from_submission:
        found = read_timestamp(submission)
        if found is not None:
            return found
    if from_mtime:
        return modification_time(notebooks if notebooks is not None else [submission])
    return None


def _inbound_time(folder, assignment):
    """The time in the name of an inbound folder of `assignment` (``student+assignment+time[+random]``), why it
    cannot be read (text), or None for another assignment's folder."""
    problem = "its name is not student+assignment+time"
    for cut in (3, 2):
        parts = folder.rsplit("+", cut)
        if len(parts) == cut + 1 and parts[1] == assignment:
            try:
                return parse_timestamp(parts[2])
            except ValueError as exc:
                problem = str(exc)
    return problem if f"+{assignment}+" in folder else None


MAX_INBOUND = 100_000  # entries of an exchange's inbound folder read


def read_exchange(course: str | os.PathLike, assignment: str) -> dict[str, datetime]:
    """{student: the newest submission's time} of `assignment` in nbgrader's exchange, read there.

    nbgrader's ``submit`` copies a student's work into the course's ``inbound/`` folder, in a folder named
    ``student+assignment+timestamp`` (newer versions add ``+random``), and ``collect`` takes each student's
    newest; the time is read from that folder's name in the exchange itself, never from a ``timestamp.txt`` that
    travelled with the work. `course` is the course's folder in the exchange (it holds ``inbound/``) or
    ``inbound/`` itself. InputError when there is no ``inbound/`` or a folder of that assignment has a time
    that cannot be read.
    """
    course = Path(course)
    inbound = course if course.name == "inbound" else course / "inbound"
    if not inbound.is_dir():
        raise InputError(
            f"{course} is not a course folder of nbgrader's exchange (it has no inbound/): give "
            "--times-from-exchange EXCHANGE/COURSE_ID, e.g. /srv/nbgrader/exchange/course101."
        )
    found: dict = {}
    with os.scandir(inbound) as entries:
        for count, entry in enumerate(entries):
            if count >= MAX_INBOUND:
                raise InputError(f"{inbound} holds more than {MAX_INBOUND:,} entries; it is not an exchange folder.")
            if not entry.is_dir(follow_symlinks=False):
                continue
            when = _inbound_time(entry.name, assignment)
            if when is None:
                continue
            if isinstance(when, str):
                raise InputError(f"{inbound}: the folder {entry.name[:SHOWN]!r} has no readable time ({when}).")
            student = entry.name.split(f"+{assignment}+")[0]
            if student not in found or when > found[student]:
                found[student] = when
    return found


def unknown_times(grades: list) -> list[tuple[str, str, bool]]:
    """(name, note, whether it is an error) of each graded submission that a rubric's deadline applies to
    but whose time is unknown; an error is a time that could not be read.
    """
    found = []
    for grade in grades:
        lateness = grade.lateness
        if grade.graded and lateness is not None and not lateness.known:
            found.append((grade.name, lateness.note, bool(lateness.time and lateness.time.problem)))
    return found
