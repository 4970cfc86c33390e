"""Similar code between submissions, flagged for a person to judge (it never changes a grade).

For each graded function, the students' sources are compared pairwise (each
source is the function's definition followed by the notebook's definitions it
reaches, :func:`labkit.grading.submission.scan.reached_function_sources`, so a
copy moved into a helper is compared too); pairs
above a threshold are listed in the class report (:mod:`labkit.grading.reports.class_report`)
side by side, with the lines they share marked.

How two sources are compared is copydetect's (winnowing, Schleimer, Wilkerson
and Aiken 2003): the code is tokenised and normalised (every variable,
attribute and function name becomes one letter, strings another; comments and
white space go), each run of :data:`NOISE` normalised characters is hashed,
and winnowing keeps a few of those hashes, the fingerprints, so that any
shared run of :data:`GUARANTEE` characters shares one. Renaming the
variables, re-wrapping the lines or rewriting the comments changes no
fingerprint. What the student release gives everyone (the stubs, the lab's
given code) is boilerplate: a fingerprint that occurs anywhere in it is
dropped. A pair's score, for each side, is the share of that side's
fingerprinted code that the other side shares; the pair's score is the larger
of the two. Code that a large part of the class wrote alike (a fingerprint in
more than :data:`COMMON_SHARE` of a function's versions, and in more than
:data:`COMMON_MIN` of them) is set aside too, as a person reading the pairs
would: the obvious way to write a short function is no evidence.

The work is bounded: each source is at most
:data:`~labkit.grading.submission.scan.MAX_SOURCE_CHARS` characters, tokenised (never
parsed, never run) and fingerprinted once; the scores of all pairs of one
function are then computed together from an inverted index of the
fingerprints (which submissions have each one), exactly as copydetect's
:func:`copydetect.compare_files` computes them, and only the pairs at or
above the threshold are compared by copydetect itself, for their shared lines.
"""

from __future__ import annotations

import io
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InputError
from ..store.report import one_line, printable
from ..store.text import MAX_SOURCE_CHARS

DEFAULT_THRESHOLD = 0.8  # similarity (0..1) from which a pair is shown
NOISE = 25  # normalised characters hashed into one fingerprint (copydetect's noise threshold): shorter runs never count
GUARANTEE = 30  # a shared run of this many normalised characters always shares a fingerprint (copydetect's default)
SLACK = 1e-9  # the vectorised scores and copydetect's may differ by rounding
# code most of a class writes alike is no evidence of copying (a two-line runge comes out the same from
# everyone): a fingerprint found in more than this share of a function's versions, and in more than
# COMMON_MIN of them, is set aside like the release's boilerplate
COMMON_SHARE = 0.2
COMMON_MIN = 5


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


def unavailable() -> str | None:
    """Why the similarity search cannot run here, or None when it can.

    The search is copydetect's (labkit's ``grade`` extra); without it,
    :func:`similar_pairs` returns None and the class report says the
    similar code was not computed, and why.

    Returns
    -------
    str or None
        One line for the report, or None when copydetect can be imported.

    Examples
    --------
    >>> unavailable() is None  # labkit's tests install every extra
    True
    """
    try:
        import copydetect  # noqa: F401
    except ImportError as exc:
        return (
            f"the similarity search needs copydetect, which cannot be imported here ({one_line(exc, 120)}): "
            "install labkit's grade extra, pip install 'labkit[grade]'"
        )
    return None


def similar_pairs(grades, threshold: float = DEFAULT_THRESHOLD, release=None, progress=None) -> list[Pair] | None:
    """The pairs of submissions whose versions of a graded function look alike, most similar first.

    Each submission's ``sources`` (the graded functions' definitions, kept
    by the grader) are compared, function by function, with every other
    submission's. Nothing is run, and no grade changes: the pairs are for a
    person to judge.

    Parameters
    ----------
    grades : iterable of SubmissionGrade
        The class's grades (:class:`labkit.grading.store.report.SubmissionGrade`,
        or any objects with a ``name`` and a ``sources`` dict of function
        name to source text); names must differ.
    threshold : float, optional
        The score (0..1) from which a pair is listed; a pair that shares no
        fingerprint is never listed.
    release : path or sequence of str, optional
        The boilerplate every student was given: a folder of notebooks or one
        notebook (all their code cells), or the code texts themselves. None
        (the default) is the lab's packaged student release
        (``labkit/student_notebooks``).
    progress : labkit.grading.progress.Progress, optional
        Advanced by one after each graded function (the functions named in
        the grades' sources).

    Returns
    -------
    list of Pair or None
        By score, highest first (then by function and names); in each pair,
        ``first`` is the name that sorts first. None when copydetect cannot
        be imported (:func:`unavailable` says why): the search was not made.

    Raises
    ------
    ValueError
        If `threshold` is not a number from 0 to 1, `grades` is not a list
        of grades, a grade has no name or sources, two grades share a name,
        or `release` cannot be read.

    Examples
    --------
    >>> from labkit.grading.store.report import SubmissionGrade
    >>> mine = "def area(width, height):\\n    return 0.5 * (width + height) * abs(width - height) ** 2 / 3"
    >>> theirs = "def area(w, h):\\n    # renamed\\n    return 0.5*(w+h)*abs(w-h)**2/3"
    >>> own = "def area(a, b):\\n    s = min(a, b)\\n    return s * s + max(a, b) - 7"
    >>> grades = [SubmissionGrade(n, sources={"area": s}) for n, s in [("ada", mine), ("bo", theirs), ("cy", own)]]
    >>> [(p.first, p.second, round(p.score, 2), sorted(p.shared_second)) for p in similar_pairs(grades, release=[])]
    [('ada', 'bo', 1.0, [0, 2])]
    """
    threshold = _threshold(threshold)
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
                raise InputError(
                    f"the sources of {one_line(name, 80)!r} are not function names and source texts "
                    f"({type(function).__name__}: {type(source).__name__})."
                )
            by_function.setdefault(function, []).append((name, _clean(source)))
    if unavailable() is not None:
        return None
    given = boilerplate(release)
    pairs = []
    for function, versions in by_function.items():
        pairs += _function_pairs(function, versions, given, threshold)
        if progress is not None:
            progress.advance()
    return sorted(pairs, key=lambda pair: (-pair.score, pair.function, pair.first, pair.second))


def _threshold(threshold):
    if isinstance(threshold, bool) or not isinstance(threshold, (int, float, np.integer, np.floating)):
        raise InputError(f"threshold must be a number from 0 to 1 (a share of the code); got {threshold!r}.")
    if not (math.isfinite(threshold) and 0 <= threshold <= 1):
        raise InputError(f"threshold must be a number from 0 to 1 (a share of the code); got {threshold!r}.")
    return float(threshold)


def _clean(text):
    """A source as the pairs show it: one kind of line end, printable, at most MAX_SOURCE_CHARS characters."""
    text = str(text)[: 2 * MAX_SOURCE_CHARS].replace("\r\n", "\n").replace("\r", "\n")
    return printable(text)[:MAX_SOURCE_CHARS]


_PACKAGED: dict = {}  # the packaged release's boilerplate, computed once per process (Python's hash() is per process)


@dataclass(frozen=True)
class Boilerplate:
    """What a release gives every student: never evidence of copying.

    ``hashes`` are the hashes of every run of :data:`NOISE` normalised
    characters of each of its code cells (not only those winnowing would
    keep), so that a student's copy of a stub, which the student's own code
    cuts off at other places, leaves no fingerprint behind; they are valid in
    this process only (Python salts its string hashes per process).
    ``lines`` are its lines of code, stripped: a line of a student's source
    that the release has word for word (a stub's ``def`` line, its docstring)
    is never marked as shared.
    """

    hashes: frozenset
    lines: frozenset


def boilerplate(release=None) -> Boilerplate:
    """The boilerplate of a student release: the stubs of the graded functions and the lab's given code.

    Parameters
    ----------
    release : path or sequence of str, optional
        A folder of notebooks (``*.ipynb``, read as the grader reads
        submissions, never run) or one notebook, or code texts; None for the
        lab's packaged student notebooks (``labkit/student_notebooks``).

    Returns
    -------
    Boilerplate
        Its fingerprint hashes and its lines.

    Raises
    ------
    ValueError
        If `release` is neither, or its notebooks cannot be read.

    Examples
    --------
    >>> stub = "def f(x):\\n    # YOUR CODE HERE\\n    raise NotImplementedError()"
    >>> sorted(boilerplate([stub]).lines)
    ['# YOUR CODE HERE', 'def f(x):', 'raise NotImplementedError()']
    """
    if release is None:
        if None not in _PACKAGED:
            from ...student_notebooks import paths

            _PACKAGED[None] = _boilerplate_of(_notebook_code([Path(str(p)) for p in paths()]))
        return _PACKAGED[None]
    if isinstance(release, (str, os.PathLike)):
        from ..submission.scoring import submission_notebooks

        return _boilerplate_of(_notebook_code(submission_notebooks(release)))
    try:
        texts = list(release)
    except TypeError:
        texts = None
    if texts is None or not all(isinstance(text, str) for text in texts):
        raise InputError(
            f"release must be a folder of notebooks, a notebook, or a list of code texts; got {release!r:.100}."
        )
    return _boilerplate_of(texts)


def _notebook_code(paths):
    from ..submission.scoring import read_cells

    code = []
    for path in paths:
        try:
            code += read_cells(path)[0]
        except OSError as exc:
            raise InputError(f"the release notebook {path} cannot be read ({exc}).") from None
    return code


def _boilerplate_of(texts):
    from copydetect.utils import filter_code, hashed_kgrams

    hashes, lines = set(), set()
    for text in map(_clean, texts):
        filtered, _ = filter_code(text, "release.py", "python")
        hashes.update(int(h) for h in hashed_kgrams(filtered, NOISE))
        lines.update(line.strip() for line in text.split("\n") if line.strip())
    return Boilerplate(frozenset(hashes), frozenset(lines))


def _fingerprint(text, hashes):
    """copydetect's fingerprint of one source, the boilerplate's hashes taken out (None: nothing of its own left).

    The boilerplate is taken out here rather than by copydetect's own
    ``boilerplate`` argument, which also drops a fingerprint that occurs
    twice in the source (its set intersection assumes unique hashes)."""
    from copydetect import CodeFingerprint

    fingerprint = CodeFingerprint("source.py", NOISE, GUARANTEE - NOISE + 1, fp=io.StringIO(text), language="python")
    return _without(fingerprint, hashes)


def _without(fingerprint, hashes):
    """The fingerprint with `hashes` taken out and its coverage recomputed (None: nothing of its own left)."""
    from copydetect.utils import get_token_coverage

    fingerprint.hash_idx = {
        int(h): list(map(int, where)) for h, where in fingerprint.hash_idx.items() if int(h) not in hashes
    }
    fingerprint.hashes = set(fingerprint.hash_idx)
    fingerprint.token_coverage = get_token_coverage(fingerprint.hash_idx, NOISE, len(fingerprint.filtered_code))
    return fingerprint if fingerprint.token_coverage > 0 else None


def shares(fingerprints) -> np.ndarray:
    """``S[i, j]``: the share of source i's fingerprinted code that source j shares, for all pairs at once.

    The same number as copydetect's :func:`~copydetect.compare_files` (its
    similarity of the first file when i is first), computed from an inverted
    index of the fingerprints: a character of i is shared with j when a
    fingerprint of i that j has too covers it (a fingerprint covers the
    :data:`NOISE` normalised characters it hashes). Sources that share
    nothing with i cost nothing beyond the index's lookups.

    Parameters
    ----------
    fingerprints : sequence of copydetect.CodeFingerprint
        With ``hash_idx`` (hash -> positions) and ``token_coverage`` > 0.

    Returns
    -------
    numpy.ndarray
        n x n, zeros on the diagonal.
    """
    from scipy import sparse

    n = len(fingerprints)
    columns: dict = {}
    rows: list = []
    cols: list = []
    layout: list = []
    for i, fingerprint in enumerate(fingerprints):
        where, which = [], []
        for h, positions in fingerprint.hash_idx.items():
            column = columns.setdefault(h, len(columns))
            rows.append(i)
            cols.append(column)
            where += positions
            which += [column] * len(positions)
        order = np.argsort(where, kind="stable")
        layout.append((np.asarray(where, dtype=float)[order], np.asarray(which, dtype=np.int64)[order]))
    index = sparse.csc_matrix((np.ones(len(rows), dtype=bool), (rows, cols)), shape=(n, max(len(columns), 1)))
    result = np.zeros((n, n))
    for i, (spots, which) in enumerate(layout):
        has = index[:, which].toarray()  # has[j, a]: source j has the fingerprint at position a of source i
        has[i] = False
        others = np.flatnonzero(has.any(axis=1))
        if not len(others):
            continue
        has = has[others]
        at = np.where(has, spots, np.inf)
        after = np.minimum.accumulate(at[:, ::-1], axis=1)[:, ::-1]  # the first shared position from a on
        following = np.concatenate([after[:, 1:], np.full((len(others), 1), np.inf)], axis=1)
        covered = np.where(has, np.minimum(NOISE, following - spots), 0.0).sum(axis=1)
        result[i, others] = covered / fingerprints[i].token_coverage
    return result


def _function_pairs(function, versions, given, threshold):
    """The pairs of one function's versions [(submission, source)] at or above the threshold."""
    from copydetect import compare_files

    kept = [(name, text, _fingerprint(text, given.hashes)) for name, text in versions]
    kept = [version for version in kept if version[2] is not None]
    counts = {}
    for _, _, fingerprint in kept:
        for h in fingerprint.hashes:
            counts[h] = counts.get(h, 0) + 1
    limit = max(COMMON_MIN, COMMON_SHARE * len(kept))
    common = {h for h, count in counts.items() if count > limit}
    if common:
        kept = [(name, text, _without(fingerprint, common)) for name, text, fingerprint in kept]
        kept = [version for version in kept if version[2] is not None]
    if len(kept) < 2:
        return []
    scores = shares([fingerprint for _, _, fingerprint in kept])
    both = np.maximum(scores, scores.T)
    pairs = []
    for i, j in zip(*np.nonzero(np.triu(both >= max(threshold - SLACK, SLACK), k=1))):
        (one, one_text, one_print), (other, other_text, other_print) = sorted((kept[i], kept[j]))
        _, both_ways, slices = compare_files(one_print, other_print)
        score = min(1.0, float(max(both_ways)))
        if score <= 0 or score < threshold:
            continue
        pairs.append(
            Pair(
                function,
                one,
                other,
                score,
                tuple(one_text.split("\n")),
                tuple(other_text.split("\n")),
                _lines(one_text, slices[0], given.lines),
                _lines(other_text, slices[1], given.lines),
            )
        )
    return pairs


def _lines(text, slices, given=frozenset()):
    """0-based numbers of the lines of `text` with code in copydetect's copied slices (character ranges).

    A line counts when a slice covers a character of it that is code: a
    blank line, a comment line, the indentation a slice ends on and a line
    the release gives (in `given`, stripped) do not."""
    lines = text.split("\n")
    starts = np.cumsum([0] + [len(line) + 1 for line in lines[:-1]])
    shared = set()
    for start, end in zip(*(np.asarray(s, dtype=np.int64) for s in slices)):
        first = int(np.searchsorted(starts, start, side="right")) - 1
        last = int(np.searchsorted(starts, max(end - 1, start), side="right")) - 1
        for number in range(max(first, 0), min(last, len(lines) - 1) + 1):
            covered = text[max(start, starts[number]) : min(end, starts[number] + len(lines[number]))].strip()
            line = lines[number].strip()
            if covered and not line.startswith("#") and line not in given:
                shared.add(number)
    return frozenset(shared)
