"""Code every student has on disk (labkit's, scipy's, the solutions' if they leak), recognised in a graded part.

The scan and the sandbox refuse *calls* of that code; this module recognises renamed or reordered *copies*
(fingerprinted, each file's cached), so that a part built on one is held for a person (:func:`.scoring.judge_known`)."""

from __future__ import annotations

import ast
import contextlib
import functools
import hashlib
import json
import os
from collections import namedtuple
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..store.record import replace_text
from . import fingerprint
from .fingerprint import canonical, normalise
from .refusals import _module_files
from .scan import python_source

# measured on copies, independent solutions and honest variants (docs/grading-security.md):
# honest work shares at most 46 fingerprints; the copies tried, 98 or more
THRESHOLD = 0.5
MIN_SHARED = 70
SHOWN = 12  # shared lines shown side by side
VERSION = "labkit-known/5"  # the cache's format and normalisation: a change here recomputes every fingerprint


# a known function or method: its name as the feedback names it (labkit.piecewise.eval_pherm), its file, its
# lines (1-based), and a notebook's text (a module's is read from its file when shown)
Unit = namedtuple("Unit", "name path first last text", defaults=[None])


@dataclass(frozen=True)
class Corpus:
    """The fingerprints of the known sources: sorted hashes, one entry per (hash, unit), and each one's unit."""

    units: tuple
    hashes: np.ndarray
    unit_of: np.ndarray
    digest: str  # what the corpus was made of (its files' SHA-256), for the run's record

    def holders(self, hashes):
        """The entries of the corpus that have one of the distinct `hashes`."""
        left = np.searchsorted(self.hashes, hashes, side="left")
        counts = np.searchsorted(self.hashes, hashes, side="right") - left
        return np.repeat(left - np.cumsum(np.r_[0, counts[:-1]]), counts) + np.arange(counts.sum())


def _definitions(text, prefix, source=None):
    """[name, first line, last line, text] of each function and class method of `text` (or bytes `source`)."""
    try:
        tree = ast.parse(text if source is None else source)
    except (SyntaxError, ValueError):
        return []  # it cannot run either: it defines nothing
    lines, found = text.split("\n"), []
    for node in tree.body:
        for inner in node.body if isinstance(node, ast.ClassDef) else [node]:
            if isinstance(inner, (ast.FunctionDef, ast.AsyncFunctionDef)):
                first = min([inner.lineno] + [d.lineno for d in inner.decorator_list])
                name = inner.name if inner is node else f"{node.name}.{inner.name}"
                last = inner.end_lineno
                found.append([f"{prefix}{name}", first, last, "\n".join(lines[first - 1 : last])])
    return found


def _cached(name, raw, compute):
    """``(compute(), key)``: JSON data cached under `key`, the SHA-256 of `raw`, `name` and the versions."""
    import pygments

    key = hashlib.sha256(f"{VERSION} pygments {pygments.__version__}\0{name}\0".encode() + raw).hexdigest()
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    folder = Path(os.environ.get("LABKIT_CACHE") or os.path.join(cache, "labkit")) / "known"
    path = folder / f"{key}.json"
    with contextlib.suppress(OSError, ValueError):  # none yet, or one that cannot be read: computed again
        return json.loads(path.read_text(encoding="utf-8")), key
    data = compute()
    with contextlib.suppress(OSError):  # a cache that cannot be written only costs time
        folder.mkdir(parents=True, exist_ok=True)
        replace_text(path, json.dumps(data), mode=0o600)  # it may hold the solutions
    return data, key


def _entry(found, with_text):
    """JSON data: the units `found` ([name, first line, last line, text] each; the text kept `with_text`), and the
    distinct fingerprints of each one's text with its index."""
    hashes = [np.unique(fingerprint.fingerprints(normalise(canonical(unit[3]))[0])[0]).tolist() for unit in found]
    unit_of = [index for index, each in enumerate(hashes) for _ in each]
    units = found if with_text else [unit[:3] for unit in found]
    return {"units": units, "hashes": [h for each in hashes for h in each], "unit_of": unit_of}


def _module_entry(module, path):
    """The units (their text left out) and fingerprints of one Python source file, cached."""
    raw = Path(path).read_bytes()
    return _cached(module, raw, lambda: _entry(_definitions(raw.decode("utf-8", "replace"), f"{module}.", raw), False))


def _notebook_entry(name, cells):
    """The units and fingerprints of one instructor notebook's code cells, as the grader reads them, cached."""

    def compute():
        return _entry([unit for cell in cells for unit in _definitions(python_source(cell) or "", f"{name}: ")], True)

    return _cached(name, json.dumps([name, list(cells)]).encode("utf-8"), compute)


@functools.lru_cache(maxsize=4)
def corpus(refusals=(), solutions=()):
    """The :class:`Corpus` of labkit's library (but its grader: no answer there), the modules `refusals` refuse,
    and the instructor notebooks `solutions`, ((name, cells),) as :func:`.scoring.known_sources` reads them."""
    modules = {}  # file: module
    for prefix in dict.fromkeys(["labkit"] + [p for r in refusals for p in r.modules if not p.startswith("labkit")]):
        for module, path in _module_files(prefix):
            if not module.startswith("labkit.grading"):
                modules.setdefault(str(path), module)
    entries = [(path, _module_entry(module, path)) for module, path in sorted((m, p) for p, m in modules.items())]
    entries += [(name, _notebook_entry(name, cells)) for name, cells in solutions]
    units, hashes, unit_of = [], [np.zeros(0, dtype=np.uint64)], [np.zeros(0, dtype=np.int64)]
    for path, (data, _) in entries:
        unit_of.append(np.asarray(data["unit_of"], dtype=np.int64) + len(units))
        units += [Unit(name, path, int(a), int(b), *rest) for name, a, b, *rest in data["units"]]
        hashes.append(np.asarray(data["hashes"], dtype=np.uint64))
    order = np.argsort(np.concatenate(hashes), kind="stable")
    digest = hashlib.sha256("\n".join(sorted(key for _, (_, key) in entries)).encode()).hexdigest()[:16]
    return Corpus(tuple(units), np.concatenate(hashes)[order], np.concatenate(unit_of)[order], digest)


@dataclass(frozen=True)
class Match:
    """A `definition` of the notebook that is mostly known code: `shared` fingerprints, `share` (0..1) of its
    own, are known, most from `source`; `lines` are (student's, known) lines; `public`: not the solutions."""

    definition: str
    source: str
    share: float
    shared: int
    lines: tuple
    public: bool = True


def own_reader(cells):
    """:func:`.fingerprint.own` of a text, never counting what the release's code `cells` give everyone
    (:func:`.fingerprint.release_grams`); one per run, it reads each text once."""
    given = fingerprint.release_grams(cells)
    return functools.lru_cache(maxsize=256)(functools.partial(fingerprint.own, given=given))


def match(known, definitions, own, threshold=THRESHOLD, minimum=MIN_SHARED):
    """The :class:`Match` of `definitions` ([(name, source)] of a graded function and what it reaches), or None.
    Each unit (:func:`.fingerprint.units`) is set against the unit of `known` that has most of its own
    fingerprints (as `own`, an :func:`own_reader`, reads them). It matches when those have `threshold` of its
    own fingerprints and at least `minimum`: the lab's formulas make short code alike in everyone, so only a long
    shared stretch is evidence."""
    total, judged = 0, []
    for name, text in fingerprint.units(definitions):
        where, hashes, positions = own(text)
        distinct = np.unique(hashes)
        total += distinct.size
        entries = known.holders(distinct) if distinct.size else distinct
        if entries.size:
            units, counts = np.unique(known.unit_of[entries], return_counts=True)
            judged.append((int(counts.max()), name, text, where, hashes, positions, int(units[np.argmax(counts)])))
    shared = sum(entry[0] for entry in judged)
    if not judged or shared / total < threshold or shared < minimum:
        return None
    _, name, text, where, hashes, positions, unit = max(judged, key=lambda entry: entry[0])
    lines = fingerprint.shared_lines(text, where, positions[np.isin(hashes, known.hashes[known.unit_of == unit])])
    unit = known.units[unit]
    return Match(name, unit.name, round(shared / total, 3), shared, _side_by_side(text, lines, unit), unit.text is None)


def _side_by_side(text, numbers, unit):
    """Up to :data:`SHOWN` pairs (student's line `numbers` of `text`, the next known line of the same shape)."""
    theirs = [""]
    with contextlib.suppress(OSError, IndexError, ValueError):
        whole = Path(unit.path).read_text(encoding="utf-8", errors="replace") if unit.text is None else None
        theirs = unit.text.split("\n") if whole is None else whole.split("\n")[unit.first - 1 : unit.last]
    mine, their_normal = text.split("\n"), [normalise(line)[0] for line in theirs]
    pairs, after = [], 0
    for number in numbers:
        line = mine[number].strip()
        normal = normalise(line)[0]
        if not normal:
            continue
        order = list(range(after, len(their_normal))) + list(range(after))
        found = next((i for i in order if their_normal[i] == normal), None)
        if found is not None:
            after = found + 1
        pairs.append((line[:120], "" if found is None else theirs[found].strip()[:120]))
        if len(pairs) == SHOWN:
            break
    return tuple(pairs)
