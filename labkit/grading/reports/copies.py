"""Copies named plainly for the instructor's class report, never changing a grade: students whose graded
functions look alike, whose data a notebook of another variant holds, and solution markers handed in."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field

SOLUTION_MARKERS = ("### BEGIN SOLUTION", "### END SOLUTION", "### BEGIN HIDDEN TESTS")  # nbgrader's, in notebooks/


@dataclass(frozen=True)
class PairRow:
    """Two students and the graded functions of theirs that look alike (each a similarity Pair)."""

    first: str
    second: str
    alike: tuple  # Pair, most similar first
    both: int  # graded functions both of them define

    @property
    def words(self):
        alike = len(self.alike)
        return f"{self.first} – {self.second}: {alike} of {max(self.both, alike)} graded functions alike"


@dataclass
class Copies:
    """{submission: its graded functions}, (holder, whose data or "", exercises), (submission, marked functions)."""

    functions: dict = field(default_factory=dict)
    holders: list = field(default_factory=list)
    marked: list = field(default_factory=list)

    def holder_lines(self):
        """One line per notebook holding another's data, as the report shows it."""
        lines = []
        for holder, whose, numbers in self.holders:
            owner = f"{whose}'s data" if whose else "another variant's data (no classmate's)"
            plural = "s" if len(numbers) > 1 else ""
            lines.append(f"{holder} holds {owner} for exercise{plural} {', '.join(map(str, numbers))}")
        return lines


def find(grades, students=None, registry=None) -> Copies:
    """The copies of a class; `students`: the run's variant data ({name: {exercise: {parameter: value}}}) or None."""
    graded = [g for g in grades if g.graded]
    registry = registry or (graded[0].rubric.registry if graded else None)
    found = defaultdict(list)  # (holder, whose data) -> exercises
    for grade in graded:
        for number, verdict in sorted(grade.results.items()):
            other = verdict.other_variant
            if other and registry is not None and number in registry.exercises:
                whose = _whose(grade.name, registry.exercises[number], other, students or {})
                found[(grade.name, ", ".join(whose))].append(number)
    marked = [
        (g.name, sorted(f for f, s in g.sources.items() if any(m in str(s) for m in SOLUTION_MARKERS))) for g in graded
    ]
    return Copies(
        {g.name: frozenset(g.sources) for g in graded},
        [(holder, whose, tuple(numbers)) for (holder, whose), numbers in sorted(found.items())],
        [(name, tuple(functions)) for name, functions in marked if functions],
    )


def _whose(name, exercise, other, students):
    """The classmates whose data for `exercise` are the values `other` found ({parameter: (found, own)})."""
    params = {p.name: p for p in exercise.params}
    return [
        classmate
        for classmate, data in sorted(students.items())
        if classmate != name
        and all(
            param in params and params[param].holds(found, data.get(str(exercise.number), {}).get(param))
            for param, (found, _) in other.items()
        )
    ]


def pair_rows(pairs, functions) -> list[PairRow]:
    """The similar pairs grouped by the two students, most alike first (`functions`: :attr:`Copies.functions`)."""
    grouped = defaultdict(list)
    for pair in pairs:
        grouped[tuple(sorted((pair.first, pair.second)))].append(pair)
    both = {pair: len(functions.get(pair[0], set()) & functions.get(pair[1], set())) for pair in grouped}
    rows = [
        PairRow(a, b, tuple(sorted(found, key=lambda p: -p.score)), both[a, b]) for (a, b), found in grouped.items()
    ]
    return sorted(rows, key=lambda r: (-len(r.alike), -max(p.score for p in r.alike), r.first, r.second))
