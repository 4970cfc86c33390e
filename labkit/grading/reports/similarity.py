"""Copies and similar code between classmates, named for a person to judge in the class report (never a grade).

A graded function's versions are fingerprinted as written (so that shared lines can be marked) and compared
pairwise; the release's code (:func:`boilerplate`) and code much of the class wrote alike are no evidence.
:func:`find_copies` names whose data a notebook of another variant holds, and the solution markers handed in.
"""

from __future__ import annotations

import functools
import math
import os
from collections import defaultdict, namedtuple
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError
from ..store.report import one_line, printable
from ..store.text import MAX_SOURCE_CHARS
from ..submission import fingerprint

DEFAULT_THRESHOLD = 0.8  # similarity (0..1) from which a pair is shown
COMMON_SHARE = 0.2  # a fingerprint in more than this share of a function's versions and more than COMMON_MIN
COMMON_MIN = 5  # of them is the class's common code, set aside like the release's
SOLUTION_MARKERS = ("### BEGIN SOLUTION", "### END SOLUTION", "### BEGIN HIDDEN TESTS")  # nbgrader's, in notebooks/


@dataclass(frozen=True)
class Pair:
    """Two submissions' alike versions of a `function`: `score` (0..1) shared, ``shared_*`` lines (0-based)."""

    function: str
    first: str
    second: str
    score: float
    first_lines: tuple
    second_lines: tuple
    shared_first: frozenset
    shared_second: frozenset


# what a release gives everyone: the hashes of its code, and its stripped lines (a stub's are never shared)
Boilerplate = namedtuple("Boilerplate", "hashes lines")
# two students, their graded functions that look alike (Pair, most similar first), and how many both define
PairRow = namedtuple("PairRow", "first second alike both")
# one student's version of a function, with its own fingerprints (fingerprint.own)
_Version = namedtuple("_Version", "name text where hashes positions")


def unavailable() -> str | None:
    """Why the search cannot run here (pygments cannot be imported), or None.

    >>> unavailable() is None
    True
    """
    try:
        import pygments.lexers  # noqa: F401
    except ImportError as exc:
        return (
            f"the similarity search needs pygments, which cannot be imported here ({one_line(exc, 120)}): "
            "install labkit's grade extra, pip install 'labkit[grade]'"
        )
    return None


def similar_pairs(grades, threshold: float = DEFAULT_THRESHOLD, release=None, progress=None) -> list[Pair] | None:
    """The pairs of `grades` (with a ``name`` and ``sources``) whose versions of a graded function score
    `threshold` (0..1) or more (never 0), by score, function and names, ``first`` sorting first. `release` is
    what everyone was given (:func:`boilerplate`); `progress` advances per function. None if :func:`unavailable`.

    >>> from labkit.grading.store.report import SubmissionGrade
    >>> mine = "def area(width, height):\\n    return 0.5 * (width + height) * abs(width - height) ** 2 / 3"
    >>> theirs = "def area(w, h):\\n    # renamed\\n    return 0.5*(w+h)*abs(w-h)**2/3"
    >>> own = "def area(a, b):\\n    s = min(a, b)\\n    return s * s + max(a, b) - 7"
    >>> grades = [SubmissionGrade(n, sources={"area": s}) for n, s in [("ada", mine), ("bo", theirs), ("cy", own)]]
    >>> [(p.first, p.second, round(p.score, 2), sorted(p.shared_second)) for p in similar_pairs(grades, release=[])]
    [('ada', 'bo', 1.0, [0, 2])]
    """
    number = not isinstance(threshold, bool) and isinstance(threshold, (int, float, np.integer, np.floating))
    if not (number and math.isfinite(threshold) and 0 <= threshold <= 1):
        raise InputError(f"threshold must be a number from 0 to 1 (a share of the code); got {threshold!r}.")
    by_function = _by_function(grades)
    if unavailable() is not None:
        return None
    given, pairs = boilerplate(release), []
    for function, versions in by_function.items():
        pairs += _function_pairs(function, versions, given, float(threshold))
        if progress is not None:
            progress.advance()
    return sorted(pairs, key=lambda pair: (-pair.score, pair.function, pair.first, pair.second))


def _by_function(grades) -> dict:
    """{function: [(submission, its cleaned source)]} of the grades, checked."""
    try:
        grades = list(grades)
    except TypeError:
        raise InputError(f"grades must be a list of SubmissionGrade; got {type(grades).__name__}.") from None
    by_function: dict = {}
    seen: set = set()
    for index, grade in enumerate(grades):
        name, sources = getattr(grade, "name", None), getattr(grade, "sources", None)
        if not isinstance(name, str) or not isinstance(sources, dict):
            raise InputError(
                f"grade {index} is a {type(grade).__name__}, not a SubmissionGrade with a name and sources: "
                "give the grades that labkit.grading.grade or read_results returns."
            )
        if name in seen:
            raise InputError(f"two grades are both named {one_line(name, 80)!r}: keep one result per submission.")
        seen.add(name)
        for function, source in sources.items():
            if not isinstance(function, str) or not isinstance(source, str):
                kinds = f"{type(function).__name__}: {type(source).__name__}"
                raise InputError(
                    f"the sources of {one_line(name, 80)!r} are not function names and source texts ({kinds})."
                )
            by_function.setdefault(function, []).append((name, _clean(source)))
    return by_function


def _clean(text):
    """A source as the pairs show it: one kind of line end, printable, at most MAX_SOURCE_CHARS characters."""
    text = str(text)[: 2 * MAX_SOURCE_CHARS].replace("\r\n", "\n").replace("\r", "\n")
    return printable(text)[:MAX_SOURCE_CHARS]


def boilerplate(release=None) -> Boilerplate:
    """The boilerplate (stubs and given code) of a student release: a folder of notebooks, one notebook, code
    texts, or None for the packaged student notebooks.

    >>> stub = "def f(x):\\n    # YOUR CODE HERE\\n    raise NotImplementedError()"
    >>> sorted(boilerplate([stub]).lines)
    ['# YOUR CODE HERE', 'def f(x):', 'raise NotImplementedError()']
    """
    if release is None:
        return _packaged()
    if isinstance(release, (str, os.PathLike)):
        from ..submission.scoring import submission_notebooks

        release = _notebook_code(submission_notebooks(release))
    try:
        texts = list(release)
    except TypeError:
        texts = None
    if texts is None or not all(isinstance(text, str) for text in texts):
        raise InputError(
            f"release must be a folder of notebooks, a notebook, or a list of code texts; got {release!r:.100}."
        )
    texts = [_clean(text) for text in texts]
    lines = frozenset(line.strip() for text in texts for line in text.split("\n") if line.strip())
    return Boilerplate(fingerprint.release_grams(texts, rewrite=str), lines)


@functools.cache
def _packaged():
    from ...student_notebooks import paths

    return boilerplate(_notebook_code([Path(str(p)) for p in paths()]))


def _notebook_code(paths):
    from ..submission.scoring import read_cells

    code = []
    for path in paths:
        try:
            code += read_cells(path)[0]
        except OSError as exc:
            raise InputError(f"the release notebook {path} cannot be read ({exc}).") from None
    return code


def _version(name, text, given):
    """The :class:`_Version` of a source without the hashes `given`; None when nothing is left."""
    version = _Version(name, text, *fingerprint.own(text, given))
    return version if version.hashes.size else None


def shares(versions) -> np.ndarray:
    """``S[i, j]``: the share of version i's fingerprinted code that fingerprints j has too cover (0 if i == j)."""
    from scipy import sparse

    sizes = [v.hashes.size for v in versions]
    _, column = np.unique(np.concatenate([v.hashes for v in versions]), return_inverse=True)
    rows = np.repeat(np.arange(len(versions)), sizes)
    index = sparse.csc_matrix((np.ones(rows.size, dtype=bool), (rows, column)), shape=(len(versions), column.max() + 1))
    result = np.zeros((len(versions), len(versions)))
    for i, (version, which) in enumerate(zip(versions, np.split(column, np.cumsum(sizes)[:-1]))):
        has = index[:, which].toarray()  # has[j, a]: version j has the fingerprint at position a of version i
        has[i] = False
        others = np.flatnonzero(has.any(axis=1))
        if others.size:
            whole = fingerprint.coverage(version.positions, np.ones((1, which.size), dtype=bool))
            result[i, others] = fingerprint.coverage(version.positions, has[others]) / whole
    return result


def _function_pairs(function, versions, given, threshold):
    """The pairs of one function's versions [(submission, source)] at `threshold` or more, common code aside."""
    kept = [v for v in (_version(name, text, given.hashes) for name, text in versions) if v is not None]
    distinct = np.concatenate([np.unique(v.hashes) for v in kept]) if kept else np.zeros(0, np.uint64)
    hashes, counts = np.unique(distinct, return_counts=True)
    common = hashes[counts > max(COMMON_MIN, COMMON_SHARE * len(kept))]
    if common.size:
        masks = [(v, ~np.isin(v.hashes, common)) for v in kept]
        kept = [v._replace(hashes=v.hashes[k], positions=v.positions[k]) for v, k in masks if k.any()]
    if len(kept) < 2:
        return []
    scores = shares(kept)
    both = np.minimum(np.maximum(scores, scores.T), 1.0)
    pairs = []
    for i, j in zip(*np.nonzero(np.triu((both > 0) & (both >= threshold), k=1))):
        one, other = sorted((kept[i], kept[j]), key=lambda version: version.name)
        lines = (tuple(one.text.split("\n")), tuple(other.text.split("\n")))
        marked = (_lines(one, other, given.lines), _lines(other, one, given.lines))
        pairs.append(Pair(function, one.name, other.name, float(both[i, j]), *lines, *marked))
    return pairs


def _lines(version, other, given):
    """0-based numbers of `version`'s lines its fingerprints shared with `other` cover, less those `given`."""
    positions = version.positions[np.isin(version.hashes, other.hashes)]
    lines = version.text.split("\n")
    return frozenset(
        n for n in fingerprint.shared_lines(version.text, version.where, positions) if lines[n].strip() not in given
    )


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


def find_copies(grades, students=None) -> Copies:
    """The copies of a class; `students`: the run's variant data ({name: {exercise: {parameter: value}}}) or None."""
    graded = [g for g in grades if g.graded]
    found = defaultdict(list)  # (holder, whose data) -> exercises
    for grade in graded:
        exercises = grade.rubric.registry.exercises
        for number, verdict in sorted(grade.results.items()):
            if verdict.other_variant and number in exercises:
                whose = _whose(grade.name, exercises[number], verdict.other_variant, students or {})
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
