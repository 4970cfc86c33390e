"""Code every student has on disk, recognised in a graded function however it is renamed or reordered.

A student has labkit's own source (every helper of it, private ones
included), scipy's, and, if they ever leak, the instructor notebooks'
solutions. A graded function that is one of those with its names changed,
its docstring gone, its statements moved about or split into helpers is not
the student's work. The source scan (:mod:`labkit.grading.submission.scan`) and the
sandbox's watch (:mod:`labkit.grading.sandbox.guard`) refuse *calls* of that code;
this module recognises *copies* of it, so that a part built on one is held
for a person (:func:`labkit.grading.submission.scoring.grade_notebook`) instead of paid.

How code is compared (winnowing, Schleimer, Wilkerson and Aiken 2003, as
copydetect and MOSS do it, with hashes of labkit's own so that they are the
same in every process):

0. :func:`labkit.grading.submission.fingerprint.canonical` first writes each
   definition back from its syntax tree with what does nothing taken out
   (dead stores, statements with no effect, ``getattr`` with a literal name,
   staticmethods and namespace classes), and
   :func:`~labkit.grading.submission.fingerprint.units` splits a part's code
   into functions, a class's methods each alone, trivial wrappers left out.
1. :func:`normalise` tokenises a source with pygments (never runs it) and
   writes every token as one or a few characters: a variable or
   argument name is ``V``, a function's name ``F``, a class's ``O``, a string
   ``S``; comments, docstrings and white space go. Keywords, operators,
   numbers, builtins and the attribute after a dot (``np.searchsorted``'s
   ``searchsorted``) stay as they are: they are what the code does.
2. :func:`fingerprints` hashes every run of :data:`NOISE` normalised
   characters and keeps the smallest hash of each :data:`WINDOW` consecutive
   ones, so that any shared run of ``NOISE + WINDOW - 1`` characters shares a
   fingerprint, wherever it sits in either source.
3. A graded part's code is every definition its graded names reach in the
   notebook (:func:`labkit.grading.submission.scan.reached_sources`). Each definition's
   own fingerprints (those the student release does not give everyone, each
   counted once) are set against the one known unit (a function or method)
   that has most of them. The part matches (:class:`Match`) when those units
   have :data:`THRESHOLD` of all its own fingerprints and at least
   :data:`MIN_SHARED` of them: the lab's formulas make short code come out
   alike from everyone, so only a long shared stretch is evidence.

The known sources are fingerprinted once per source file and kept in a
cache folder (:func:`cache_folder`) under the file's SHA-256, so a grading
run pays only for what changed since the last one.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import fingerprint
from .fingerprint import canonical

NOISE = 25  # normalised characters hashed together: a shorter shared run is never evidence
WINDOW = 6  # winnowing window: a shared run of NOISE + WINDOW - 1 = 30 characters always shares a fingerprint
# a part is held for a person when known units have THRESHOLD or more of its own fingerprints and it shares
# MIN_SHARED or more with them: measured on copies, on independent solutions and on honest variants written
# for the purpose (docs/grading-security.md). Honest work shares at most 46; the copies tried, 98 or more.
THRESHOLD = 0.5
MIN_SHARED = 70
SHOWN = 12  # shared lines shown side by side
VERSION = "labkit-known/4"  # the cache's format and normalisation: a change here recomputes every fingerprint

PARENTHESES = {"(", ")"}
BASE = np.uint64(1_000_003)
POWERS = BASE ** np.arange(NOISE - 1, -1, -1, dtype=np.uint64)  # wraps modulo 2**64, as the hashes do


def normalise(text):
    """``(normalised, where)``: `text`'s tokens as :func:`fingerprints` reads them, and the index in `text`
    of each normalised character.

    Examples
    --------
    >>> normalise("def area(w, h):\\n    '''Doc.'''\\n    return w * h  # cm2")[0]
    'defFV,V:returnV*V'
    >>> normalise("y = np.searchsorted(x, 'a')")[0]
    'V=V.searchsortedV,S'
    """
    from pygments import lexers, token

    lexer = lexers.get_lexer_by_name("python")
    out, where, previous = [], [], None
    for start, kind, value in lexer.get_tokens_unprocessed(str(text)):
        if kind in token.Text or kind in token.Comment or kind in token.String.Doc or value in PARENTHESES:
            continue  # round brackets too: a formatter adds and drops them around tuples and long lines
        if kind in token.String:
            if previous != "S":
                out.append("S")
                where.append(start)
            previous = "S"
            continue
        if kind in token.Name.Function:
            piece = "F"
        elif kind in token.Name.Class:
            piece = "O"
        elif kind in token.Name and kind not in token.Name.Builtin and previous != ".":
            piece = "V"
        else:
            piece = value
        out.append(piece)
        where.extend(range(start, start + len(piece)) if piece == value else [start])
        previous = piece
    return "".join(out), np.asarray(where, dtype=np.int64)


def fingerprints(normalised):
    """``(hashes, positions)``: the winnowed fingerprints of a normalised text, in order of position.

    Examples
    --------
    >>> hashes, positions = fingerprints("V=V+1" * 20)
    >>> bool(len(hashes)) and bool(np.all(np.diff(positions) > 0))
    True
    >>> fingerprints("V=1")[0].size  # shorter than NOISE: nothing to fingerprint
    0
    """
    grams = kgrams(normalised)
    if grams.size == 0:
        return grams, np.zeros(0, dtype=np.int64)
    width = min(WINDOW, grams.size)
    windows = np.lib.stride_tricks.sliding_window_view(grams, width)
    # robust winnowing: the rightmost smallest hash of each window
    chosen = np.arange(windows.shape[0]) + (width - 1 - np.argmin(windows[:, ::-1], axis=1))
    chosen = np.unique(chosen)
    return grams[chosen], chosen


def kgrams(normalised):
    """The hash of every run of :data:`NOISE` characters of a normalised text (the same in every process)."""
    codes = np.frombuffer(str(normalised).encode("utf-32-le"), dtype=np.uint32).astype(np.uint64)
    if codes.size < NOISE:
        return np.zeros(0, dtype=np.uint64)
    windows = np.lib.stride_tricks.sliding_window_view(codes, NOISE)
    return windows @ POWERS


def _covered(positions, length):
    """How many characters of a text of `length` the fingerprints at `positions` cover, and the mask."""
    marks = np.zeros(length + NOISE + 1, dtype=np.int64)
    np.add.at(marks, positions, 1)
    np.add.at(marks, positions + NOISE, -1)
    mask = np.cumsum(marks)[:length] > 0
    return int(mask.sum()), mask


# -- the known sources -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Unit:
    """One definition of a known source: a function, or a method of a class."""

    name: str  # as the feedback names it: labkit.piecewise.eval_pherm, scipy.interpolate._cubic.pchip...
    path: str  # its file
    first: int  # its lines in the file (1-based, inclusive)
    last: int
    text: str | None = None  # a notebook's definition itself (a module's is read from its file when shown)


@dataclass(frozen=True)
class Corpus:
    """The fingerprints of the known sources: which unit and which source (file) each one comes from."""

    units: tuple  # Unit
    sources: tuple  # the names of the known sources: a module or a notebook
    hashes: np.ndarray  # sorted fingerprint hashes, one entry per (hash, unit)
    unit_of: np.ndarray  # the unit of each entry
    source_of: np.ndarray  # its source (an index into `sources`)
    digest: str  # what the corpus was made of (its files' SHA-256), for the run's record

    def holders(self, hashes):
        """For each hash, the entries of the corpus that have it: (index of the hash, entry) pairs."""
        left = np.searchsorted(self.hashes, hashes, side="left")
        right = np.searchsorted(self.hashes, hashes, side="right")
        counts = right - left
        which = np.repeat(np.arange(len(hashes)), counts)
        entries = np.repeat(left - np.cumsum(np.r_[0, counts[:-1]]), counts) + np.arange(counts.sum())
        return which, entries


def cache_folder():
    """Where the known sources' fingerprints are kept between runs: ``$LABKIT_CACHE`` or the user's cache."""
    base = os.environ.get("LABKIT_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "labkit"
    )
    return Path(base) / "known"


def _definitions(tree, prefix):
    """(name, first line, last line) of each top-level function and each method of a top-level class."""
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            yield f"{prefix}{node.name}", first, node.end_lineno
        elif isinstance(node, ast.ClassDef):
            for inner in node.body:
                if isinstance(inner, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    first = min([inner.lineno] + [d.lineno for d in inner.decorator_list])
                    yield f"{prefix}{node.name}.{inner.name}", first, inner.end_lineno


def _fingerprint_units(texts):
    """[(unit text, hashes)] → the unit index and hash arrays of their fingerprints."""
    hashes, units = [], []
    for index, text in enumerate(texts):
        found = np.unique(fingerprints(normalise(canonical(text))[0])[0])
        hashes.append(found)
        units.append(np.full(found.size, index, dtype=np.int32))
    if not hashes:
        return np.zeros(0, dtype=np.uint64), np.zeros(0, dtype=np.int32)
    return np.concatenate(hashes), np.concatenate(units)


@functools.cache
def _tokeniser():
    from importlib.metadata import version

    return f"{VERSION} pygments {version('pygments')}"


def _cached(name, raw, compute):
    """`compute()` (JSON data), kept in the cache folder under the SHA-256 of `raw`, its `name`,
    :data:`VERSION` and the tokeniser's version (pygments')."""
    key = hashlib.sha256(f"{_tokeniser()}\0{name}\0".encode() + raw).hexdigest()
    folder = cache_folder()
    path = folder / f"{key}.json"
    try:
        return json.loads(path.read_text(encoding="utf-8")), key
    except (OSError, ValueError):
        pass
    data = compute()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        handle, partial = tempfile.mkstemp(dir=folder, suffix=".partial")
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            json.dump(data, stream)
        os.replace(partial, path)
    except OSError:
        pass  # a cache that cannot be written only costs time
    return data, key


def _module_entry(module, path):
    """The units and fingerprints of one Python source file, cached."""
    raw = Path(path).read_bytes()

    def compute():
        try:
            tree = ast.parse(raw)
        except (SyntaxError, ValueError):
            return {"units": [], "hashes": [], "unit_of": []}
        lines = raw.decode("utf-8", "replace").split("\n")
        found = [list(unit) for unit in _definitions(tree, f"{module}.")]
        hashes, unit_of = _fingerprint_units(["\n".join(lines[a - 1 : b]) for _, a, b in found])
        return {"units": found, "hashes": hashes.tolist(), "unit_of": unit_of.tolist()}

    return _cached(module, raw, compute)


def _notebook_entry(name, cells):
    """The units and fingerprints of one instructor notebook's code cells, cached."""
    raw = json.dumps([name, list(cells)]).encode("utf-8")

    def compute():
        from .scan import python_source

        units, texts = [], []
        for cell in cells:
            text = python_source(cell)  # as the grader reads a notebook: magics and shell lines left out
            try:
                tree = ast.parse(text or "")
            except (SyntaxError, ValueError):
                continue  # IPython could not run it either: it defines nothing
            lines = text.split("\n")
            for unit, first, last in _definitions(tree, f"{name}: "):
                texts.append("\n".join(lines[first - 1 : last]))
                units.append([unit, first, last, texts[-1]])
        hashes, unit_of = _fingerprint_units(texts)
        return {"units": units, "hashes": hashes.tolist(), "unit_of": unit_of.tolist()}

    return _cached(name, raw, compute)


def known_modules(refusals):
    """(module, file) of every Python source a student has that the lab's answers are in: labkit's library
    (its grader left out: it holds no answer) and the Python modules the refusals switch off."""
    from .refusals import _module_files

    prefixes = ["labkit"] + [p for r in refusals for p in r.modules if not p.startswith("labkit")]
    found = {}
    for prefix in dict.fromkeys(prefixes):
        for module, path in _module_files(prefix):
            if not module.startswith("labkit.grading"):
                found.setdefault(str(path), module)
    return sorted((module, path) for path, module in found.items())


@functools.lru_cache(maxsize=4)
def corpus(refusals=(), solutions=()):
    """The known sources' fingerprints: labkit's library and the refused modules' Python sources, and the
    definitions of the instructor notebooks' code cells.

    `refusals` are :class:`labkit.exercises.model.Refusal` objects; `solutions` is a tuple of (notebook
    name, tuple of its code cells), the instructor notebooks as the grader reads them
    (:func:`labkit.grading.submission.scoring.solutions`)."""
    entries = [(module, str(path), _module_entry(module, path)) for module, path in known_modules(refusals)]
    entries += [(f"the solutions' {name}", name, _notebook_entry(name, cells)) for name, cells in solutions]
    units, sources, hashes, unit_of, source_of, keys = [], [], [], [], [], []
    for source, path, (data, key) in entries:
        keys.append(key)
        offset = len(units)
        for unit in data["units"]:
            name, first, last = unit[:3]
            units.append(Unit(name, path, int(first), int(last), unit[3] if len(unit) > 3 else None))
        hashes.append(np.asarray(data["hashes"], dtype=np.uint64))
        unit_of.append(np.asarray(data["unit_of"], dtype=np.int64) + offset)
        source_of.append(np.full(len(data["hashes"]), len(sources), dtype=np.int64))
        sources.append(source)
    hashes = np.concatenate(hashes) if hashes else np.zeros(0, dtype=np.uint64)
    order = np.argsort(hashes, kind="stable")
    cat = (lambda parts: np.concatenate(parts)[order]) if hashes.size else (lambda parts: np.zeros(0, np.int64))
    digest = hashlib.sha256("\n".join(sorted(keys)).encode()).hexdigest()[:16]
    return Corpus(tuple(units), tuple(sources), hashes[order], cat(unit_of), cat(source_of), digest)


# -- a notebook's code against them ------------------------------------------------------------------------


@dataclass(frozen=True)
class Match:
    """A definition of the notebook that is, for the most part, a known source's code."""

    definition: str  # the notebook's name that holds it (the graded function or a helper it reaches)
    source: str  # the known unit it shares most with, e.g. "labkit.piecewise.eval_pherm"
    share: float  # 0..1: the part of the part's own fingerprints that known units have
    shared: int  # how many fingerprints they share
    lines: tuple  # (the student's line, the known source's line) pairs of shared code, at most SHOWN
    public: bool = True  # whether the source is on every student's disk (labkit, scipy), not the solutions

    def as_dict(self):
        return {
            "definition": self.definition,
            "source": self.source,
            "share": self.share,
            "shared": self.shared,
            "lines": self.lines,
            "public": self.public,
        }


class Given:
    """Every :data:`NOISE`-character hash of the release's code cells: what every student was given."""

    def __init__(self, cells):
        found = [kgrams(normalise(canonical(cell))[0]) for cell in cells]
        self.array = np.unique(np.concatenate(found)) if found else np.zeros(0, dtype=np.uint64)


def release_grams(cells):
    """:class:`Given` of a release's code cells (one per run: :func:`match` caches by it)."""
    return Given(cells)


def match(known, definitions, given, threshold=THRESHOLD, minimum=MIN_SHARED):
    """The :class:`Match` of a part's code, when known sources have :data:`THRESHOLD` or more of it; else None.

    The part's code is `definitions`, the graded function and every definition it reaches. What counts is
    each definition's own code: its distinct fingerprints that the release does not give everyone (a run
    repeated in the student's code counts once). Each definition is set against the one known unit (a
    function or method of labkit, scipy or the solutions) that has most of its fingerprints; the part's
    share is the part of all its own fingerprints that those units have. It matches when that share is
    `threshold` or more and at least `minimum` fingerprints are shared: short code that the lab's formulas
    dictate is written alike by everyone, so it is never evidence.

    Parameters
    ----------
    known : Corpus
        The known sources (:func:`corpus`).
    definitions : iterable of (str, str)
        (name, source text) of the notebook's definitions to judge: a graded function and what it reaches.
    given : Given
        :func:`release_grams` of what every student was given: code that only repeats it is nobody's.
    threshold : float, optional
        The share from which the part matches (:data:`THRESHOLD`; 0 gives the best sources whatever the share).
    minimum : int, optional
        The fingerprints the part must share at least (:data:`MIN_SHARED`).
    """
    judged, total, shared = [], 0, 0
    for name, text in fingerprint.units(definitions):
        normalised, where, hashes, positions = _read(text, given)
        distinct = np.unique(hashes)
        if not distinct.size:
            continue
        total += distinct.size
        which, entries = known.holders(distinct)
        if not entries.size:
            continue
        units, counts = np.unique(known.unit_of[entries], return_counts=True)
        unit = int(units[np.argmax(counts)])
        judged.append((int(counts.max()), name, text, where, hashes, positions, unit))
        shared += int(counts.max())
    if not judged or not total:
        return None
    share = shared / total
    if share < threshold or shared < minimum:
        return None
    count, name, text, where, hashes, positions, unit = max(judged, key=lambda entry: entry[0])
    theirs = known.hashes[known.unit_of == unit]
    _, mask = _covered(positions[np.isin(hashes, theirs)], len(where))
    unit = known.units[unit]
    return Match(name, unit.name, round(share, 3), shared, _side_by_side(text, where, mask, unit), unit.text is None)


@functools.lru_cache(maxsize=256)
def _read(text, given):
    """A definition's normalised text, and its fingerprints that the release does not give. (`given` is
    hashed by identity: one per run.)"""
    normalised, where = normalise(text)
    hashes, positions = fingerprints(normalised)
    mine = ~np.isin(hashes, given.array)
    return normalised, where, hashes[mine], positions[mine]


def _unit_text(unit):
    if unit.text is not None:
        return unit.text
    lines = Path(unit.path).read_text(encoding="utf-8", errors="replace").split("\n")
    return "\n".join(lines[unit.first - 1 : unit.last])


def _shared_lines(text, where, mask):
    """The lines of `text` (0-based numbers) with a normalised character that `mask` marks."""
    starts = np.cumsum([0] + [len(line) + 1 for line in text.split("\n")[:-1]])
    return sorted(set((np.searchsorted(starts, where[mask], side="right") - 1).tolist()))


def _side_by_side(text, where, mask, unit):
    """Up to :data:`SHOWN` pairs of shared lines: the student's, and the known unit's line most like it."""
    try:
        theirs = _unit_text(unit)
    except (OSError, IndexError, ValueError):
        theirs = ""
    mine_lines = text.split("\n")
    their_lines = theirs.split("\n")
    their_normal = [normalise(line)[0] for line in their_lines]
    pairs, after = [], 0
    for number in _shared_lines(text, where, mask):
        line = mine_lines[number].strip()
        normal = normalise(line)[0]
        if not normal:
            continue
        # the known line of the same shape, the first after the last one paired (copies keep their order)
        order = list(range(after, len(their_normal))) + list(range(after))
        found = next((i for i in order if their_normal[i] == normal), None)
        if found is not None:
            after = found + 1
        pairs.append((line[:120], "" if found is None else their_lines[found].strip()[:120]))
        if len(pairs) == SHOWN:
            break
    return tuple(pairs)
