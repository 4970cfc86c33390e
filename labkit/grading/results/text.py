"""Numbers as the grader writes them in feedback, reports and exports."""

from __future__ import annotations

MAX_SOURCE_CHARS = 20_000  # characters kept of one graded function's source (a lab function is a few hundred)


def points_text(value) -> str:
    """Points as text: whole numbers without a decimal point, others to two decimals at most.

    >>> points_text(12.0), points_text(7.25), points_text(1 / 3)
    ('12', '7.25', '0.33')
    """
    value = round(float(value), 2)
    return f"{int(value)}" if value == int(value) else f"{value:g}"
