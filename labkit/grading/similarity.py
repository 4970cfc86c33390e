"""Similar code between submissions, flagged for a person to judge (it never changes a grade).

For each graded function, the students' sources are compared pairwise; pairs
above a threshold are listed in the class report (:mod:`labkit.grading.class_report`)
side by side, with the lines they share marked.
"""

from __future__ import annotations

from dataclasses import dataclass

DEFAULT_THRESHOLD = 0.8  # similarity (0..1) from which a pair is shown


@dataclass(frozen=True)
class Pair:
    """Two submissions' versions of one graded function that look alike."""

    function: str  # the graded function's name, e.g. "eval_pherm"
    first: str  # submission names
    second: str
    score: float  # 0..1: how much of the code is shared (the larger of the two directions)
    first_lines: tuple  # the two sources, line by line
    second_lines: tuple
    shared_first: frozenset  # 0-based numbers of the lines each shares with the other
    shared_second: frozenset
