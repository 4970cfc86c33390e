"""Numbers as the grader reads them from a rubric and writes them in feedback, reports and exports."""

from __future__ import annotations

import math
import re

MAX_SOURCE_CHARS = 20_000  # characters kept of one graded function's source (a lab function is a few hundred)


def is_number(value) -> bool:
    """Whether a rubric's `value` is a finite int or float (True, False, NaN, infinity and an int no float can
    hold are not)."""
    try:
        return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    except OverflowError:
        return False


def points_text(value) -> str:
    """Points as text: whole numbers without a decimal point, others to two decimals at most.

    >>> points_text(12.0), points_text(7.25), points_text(1 / 3)
    ('12', '7.25', '0.33')
    """
    value = round(float(value), 2)
    return f"{int(value)}" if value == int(value) else f"{value:g}"


# control characters, and the invisible ones that break or reorder lines (line and paragraph separators, bidi marks)
CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200b-\u200f\u2028-\u202e\u2060-\u2069\ufeff\ufff9-\ufffb]")


def printable(text):
    """`text` without control characters but newline and tab (no escape sequence reaches a terminal), and
    with bytes that were not UTF-8 (a file name from an old zip) spelled out as escapes."""
    text = str(text).encode("utf-8", "backslashreplace").decode("utf-8")
    return CONTROL.sub("\ufffd", text)


def one_line(text, limit=200):
    """A submission's text as one printable line (a name in a table or a terminal)."""
    line = printable(str(text)).replace("\n", " ").replace("\t", " ")
    return line if len(line) <= limit else line[: limit - 1] + "\u2026"
