"""The roster, and reading the CSV files an instructor gives: the roster joins each submission's name to the
student's id in the LMS (a UTF-8 CSV with the columns ``submission`` and ``id``; ``id`` is the LMS's ``--key``)."""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

from ...errors import InputError
from ..store.report import one_line

XLSX_MAGIC = b"PK\x03\x04"
ROSTER_FIX = "save the roster as CSV (UTF-8) with a header row 'submission,id' and one student per line."


def read_text(path, what, fix):
    """The UTF-8 text of `path` (a byte-order mark removed), whether it had one, and its line ending."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {what} {path}: {exc.strerror or exc}.") from None
    if data.startswith(XLSX_MAGIC):
        raise InputError(f"{path} is an Excel workbook, not CSV: {fix}")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{path} is not UTF-8 text (byte {exc.start} is {data[exc.start : exc.start + 1]!r}): {fix}"
        ) from None
    if "\x00" in text:
        raise InputError(f"{path} is not a CSV text file (it holds NUL bytes): {fix}")
    return text, data.startswith(b"\xef\xbb\xbf"), "\r\n" if "\r\n" in text else "\n"


def csv_rows(text, path, delimiter, fix):
    """The rows of CSV `text`; ValueError saying how to `fix` it when it is not valid CSV."""
    try:
        return list(csv.reader(io.StringIO(text, newline=""), delimiter=delimiter, strict=True))
    except csv.Error as exc:
        raise InputError(f"{path} is not valid CSV ({exc}): {fix}") from None


def first_row(text, delimiter):
    """The first row of CSV `text` read with `delimiter`, or [] when it cannot be read so."""
    try:
        return next(csv.reader(io.StringIO(text, newline=""), delimiter=delimiter), [])
    except csv.Error:
        return []


def read_roster(path: str | os.PathLike) -> dict[str, str]:
    """The roster at `path`: {submission name: the student's id in the LMS}, in the file's order; other columns
    are ignored. ValueError when it is not UTF-8 CSV, lacks a column or a value, or names one twice.

    >>> import pathlib, tempfile
    >>> roster = pathlib.Path(tempfile.mkdtemp()) / "roster.csv"
    >>> _ = roster.write_text("name,submission,id\\nAda Lovelace,ada,1815\\n", encoding="utf-8")
    >>> read_roster(roster)
    {'ada': '1815'}
    """
    text, _, _ = read_text(path, "the roster", ROSTER_FIX)
    for delimiter in (",", ";", "\t"):
        header = [cell.strip().lower() for cell in first_row(text, delimiter)]
        if {"submission", "id"} <= set(header):
            break
    else:
        found = ", ".join(repr(one_line(c, 40)) for c in first_row(text, ",")[:8]) or "nothing"
        raise InputError(
            f"the roster {path} needs a header row with the columns 'submission' (the names in grades.csv) and 'id' "
            f"(the students' ids in the LMS); its first row has {found}. For example:\n    submission,id\n    ada,1815"
        )
    for name in ("submission", "id"):
        if header.count(name) > 1:
            raise InputError(f"the roster {path} has two '{name}' columns; keep one.")
    rows = csv_rows(text, path, delimiter, ROSTER_FIX)
    at_name, at_id = header.index("submission"), header.index("id")
    roster: dict = {}
    lines_of: dict = {}
    names_of: dict = {}
    for number, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        name = row[at_name].strip() if at_name < len(row) else ""
        key = row[at_id].strip() if at_id < len(row) else ""
        if not name or not key:
            missing = "submission" if not name else "id"
            raise InputError(f"the roster {path}, row {number}: the {missing} is empty; give both, or delete the row.")
        if name in roster:
            lines = f"rows {lines_of[name]} and {number}"
            raise InputError(
                f"the roster {path} names the submission {one_line(name, 80)!r} twice ({lines}); keep one."
            )
        if key in names_of:
            lines = f"rows {lines_of[names_of[key]]} and {number}"
            both = f"{one_line(names_of[key], 60)!r} and {one_line(name, 60)!r}, {lines}"
            raise InputError(
                f"the roster {path} gives the id {one_line(key, 60)!r} to two submissions ({both}); correct one."
            )
        roster[name], lines_of[name], names_of[key] = key, number, name
    if not roster:
        raise InputError(f"the roster {path} has a header but no student: add one row per submission.")
    return roster
