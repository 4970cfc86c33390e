"""When each submission was handed in, read on the grader's side before any student code runs.

Where a time comes from, first match wins, is :func:`submission_time`'s (and ``docs/instructors.md``'s, "Late
work"); what a time costs is the store's (:mod:`labkit.grading.store.late`). This module only reads the times.
"""

import contextlib
import csv
import os
import re
from datetime import UTC, datetime
from pathlib import Path

from ...errors import InputError
from ..store.late import FORMAT, FROM_CSV, FROM_EXCHANGE, FROM_MTIME, FROM_NBGRADER, SHOWN, SubmissionTime, read_small

MAX_TIMES = 10 * 1024**2  # bytes of a --times file
MAX_TIMESTAMP = 256  # bytes: nbgrader writes about 30
TIMESTAMP = "timestamp.txt"  # nbgrader's name, in the submission's folder
MAX_INBOUND = 100_000  # entries of an exchange's inbound folder read
_NBGRADER = re.compile(
    r"(?P<date>\d{4}-\d{2}-\d{2})[T ](?P<time>\d{2}:\d{2}(?::\d{2}(?:[.,]\d{1,9})?)?)"
    r"\s*(?P<zone>Z|UTC|GMT|[+-]\d{2}:?\d{2}|[A-Za-z][A-Za-z0-9/_+-]{0,40})?"
)


def parse_timestamp(text: str) -> datetime:
    """The time nbgrader wrote in a ``timestamp.txt``, as a timezone-aware datetime.

    nbgrader writes ``"%Y-%m-%d %H:%M:%S.%f %Z"`` (older versions without the fraction), ``zip_collect`` an ISO
    time with an offset. A time without a zone, or with a zone name other than UTC or GMT (``CET`` names several),
    is an InputError: which moment it means cannot be known.

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
    if zone in ("UTC", "GMT"):
        zone = "Z"
    elif zone[0] in "+-" and (int(zone[1:3]) > 23 or int(zone[-2:]) > 59):
        raise InputError(f"{line!r} has the offset {zone}, which no time zone has")
    elif zone != "Z" and zone[0] not in "+-":
        raise InputError(
            f"{line!r} names the time zone {zone!r}, which labkit cannot place (only UTC, GMT and numeric "
            "offsets are unambiguous)"
        )
    try:  # fromisoformat reads a comma and cuts a fraction to microseconds
        return datetime.fromisoformat(f"{match['date']}T{match['time']}{zone}")
    except ValueError as exc:
        raise InputError(f"{line!r} is not a real time ({exc})") from None


def read_timestamp(submission: str | os.PathLike) -> SubmissionTime | None:
    """The time in nbgrader's ``timestamp.txt`` at the top of a submission's folder: None when there is no
    such file (a single notebook has none), a time whose ``problem`` says why when it cannot be read.
    """
    path = Path(submission) / TIMESTAMP
    if os.path.islink(submission) or not os.path.isdir(submission) or not os.path.lexists(path):
        return None
    try:
        return SubmissionTime(parse_timestamp(read_small(path, MAX_TIMESTAMP).decode("utf-8")), FROM_NBGRADER)
    except UnicodeDecodeError:
        return SubmissionTime(None, FROM_NBGRADER, f"{TIMESTAMP} is not text")
    except (OSError, ValueError) as exc:
        return SubmissionTime(None, FROM_NBGRADER, f"{TIMESTAMP}: {exc}")


def read_times(path: str | os.PathLike) -> dict[str, datetime]:
    """{submission name: datetime} from a CSV file with the columns ``submission`` and ``time`` (others are
    ignored); a time is ISO 8601 with a UTC offset, or as nbgrader writes it (``2026-12-01 23:59:59 UTC``).
    InputError when the file cannot be read, lacks a column, names a submission twice or has a bad time (naming
    the line).
    """
    path = Path(path)
    try:
        text = read_small(path, MAX_TIMES).decode("utf-8-sig")
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
    if not from_mtime:
        return None
    stamps = []
    for path in notebooks if notebooks is not None else [submission]:
        with contextlib.suppress(OSError):
            stamps.append(os.lstat(path).st_mtime)
    return SubmissionTime(datetime.fromtimestamp(max(stamps), UTC), FROM_MTIME) if stamps else None


def _inbound_time(inbound, folder, assignment):
    """The time in the name of an inbound folder of `assignment` (``student+assignment+time[+random]``), or None
    for another assignment's folder; InputError when it cannot be read."""
    problem = "its name is not student+assignment+time"
    for cut in (3, 2):
        parts = folder.rsplit("+", cut)
        if len(parts) == cut + 1 and parts[1] == assignment:
            try:
                return parse_timestamp(parts[2])
            except ValueError as exc:
                problem = str(exc)
    if f"+{assignment}+" in folder:
        raise InputError(f"{inbound}: the folder {folder[:SHOWN]!r} has no readable time ({problem}).")
    return None


def read_exchange(course: str | os.PathLike, assignment: str) -> dict[str, datetime]:
    """{student: the newest submission's time} of `assignment` in nbgrader's exchange, read there.

    The time is read from the name nbgrader's ``submit`` gives the work's folder in ``inbound/``
    (``student+assignment+timestamp[+random]``), never from a ``timestamp.txt`` that travelled with the work.
    `course` is the course's folder in the exchange or its ``inbound/``. InputError when there is no
    ``inbound/`` or a folder of that assignment has a time that cannot be read.
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
            when = _inbound_time(inbound, entry.name, assignment)
            if when is None:
                continue
            student = entry.name.split(f"+{assignment}+")[0]
            found[student] = max(when, found.get(student, when))
    return found
