"""Every draw checked before it is handed out: ``labkit variants --check N``.

For N made-up students (and the roster's) the instructor notebooks run here (never a student's code) on each one's
data: the solution and each correct variation of a catalog (``CORRECT``) earn full marks; each slip (``MISTAKES``)
costs exactly its part (and its ``also``) with its ``hint`` said; only the solution on another student's data is
named as holding another variant, and it loses its varied parts; no two students of the roster drew alike; each
exercise's ``sound`` holds. A catalog (a course's ``tests/catalog.py``) lists entries with ``name``, ``notebook``,
``replace`` ((old, new) code pairs), ``exercise``, ``part``, ``hint``, ``also`` and ``full``.
"""

import contextlib
import importlib.util
import io
import linecache
import re
import warnings
from copy import deepcopy
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from ...execute import read_notebook
from ...exercises import variants as variant_data
from ...exercises.registry import LAB, Registry
from .release import BEGIN_HIDDEN, END_HIDDEN, with_values


@dataclass(frozen=True)
class Trouble:
    """One draw where something is not as it should be."""

    student: str
    values: dict  # {exercise: {parameter: value}}
    entry: str  # the solution, a catalog entry, or the copy check
    what: str

    def __str__(self):
        data = {p: v for given in self.values.values() for p, v in given.items()}  # a shared datum once
        shown = ", ".join(f"{p} = {v}" for p, v in data.items())
        return f"{self.student} ({shown}): {self.entry}: {self.what}"


def load_catalog(path):
    """(CORRECT, MISTAKES) of the catalog file at `path`; ValueError when it is not one."""
    path = Path(path)
    spec = importlib.util.spec_from_file_location(f"labkit_catalog_{abs(hash(str(path)))}", path)
    if spec is None or spec.loader is None or not path.is_file():
        raise InputError(f"{path} is not a Python file; give the catalog of correct variations and slips (.py).")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    found = getattr(module, "CORRECT", None), getattr(module, "MISTAKES", None)
    if not all(isinstance(entries, (list, tuple)) for entries in found):
        raise InputError(f"{path} defines no lists CORRECT and MISTAKES; it is not a catalog of variations and slips.")
    return tuple(found[0]), tuple(found[1])


def _planted(nb, replace, name):
    """Notebook `nb` with the (old, new) code replacements of a catalog entry (each old once in one code cell)."""
    nb = deepcopy(nb)
    for old, new in replace:
        hits = [cell for cell in nb.cells if cell.cell_type == "code" and old in cell.source]
        if len(hits) != 1 or hits[0].source.count(old) != 1:
            raise InputError(f"catalog entry {name!r}: {old[:60]!r} is not in one code cell once; fix the entry.")
        hits[0].source = hits[0].source.replace(old, new)
    return nb


def reading_rates(nb, registry=LAB):
    """Notebook `nb` (in place) with each experiment's whole-number rate answer (``rate_... = 4``) read off the
    student's own table as the printout is read (the mean of the last three log2 ratios, rounded)."""
    for experiment in registry.experiments.values():
        reading = (
            f"{experiment.rate} = int(np.rint(np.mean(np.log2(np.asarray({experiment.table}[-4:-1]) "
            f"/ np.asarray({experiment.table}[-3:])))))"
        )
        for cell in nb.cells:
            if cell.cell_type == "code":
                cell.source = re.sub(rf"^{experiment.rate} = \d+$", reading, cell.source, flags=re.MULTILINE)
    return nb


def _without_hidden_tests(source):
    kept, hidden = [], False
    for line in source.split("\n"):
        marker = line.strip()
        if marker in (BEGIN_HIDDEN, END_HIDDEN):
            hidden = marker == BEGIN_HIDDEN
        elif not hidden and not marker.startswith("%"):
            kept.append(line)
    return "\n".join(kept)


def run_cells(nb, names):
    """The names a notebook defines once its code cells (hidden tests and magics left out) have run here, up to the
    last that mentions `names`; a cell that raises is passed over, as in the grader."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    cells = [_without_hidden_tests(cell.source) for cell in nb.cells if cell.cell_type == "code"]
    last = max((i for i, source in enumerate(cells) if any(name in source for name in names)), default=-1)
    namespace = {"__name__": "__main__"}
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        for index, source in enumerate(cells[: last + 1]):
            # the cell's lines where a traceback looks for them (as in a kernel), so a hint can quote the line
            name = f"<labkit draws cell {index}>"
            linecache.cache[name] = (len(source), None, source.splitlines(True), name)
            with contextlib.suppress(Exception):  # a slip may raise; the checks say what it costs
                exec(compile(source, name, "exec"), namespace)  # noqa: S102 - the instructor's own code
    return namespace


def _said(checks, part):
    """The hint and step details `part`'s check gives."""
    said = [
        [c.get("hint") or ""] + [f"{s['step']}: {s['detail']}" for s in c["steps"]] for c in checks if c["name"] == part
    ]
    return " ".join(said[0]) if said else ""


def _failed(verdict):
    return {check["name"] for check in verdict["checks"] if not check["passed"]}


def check(variants, count, solutions, catalog=None, roster=None, registry=LAB, seed=0, progress=None):
    """The :class:`Trouble` found in `count` made-up students' draws (and the `roster`'s, {name: id}) of every
    varied exercise of `variants`, run on the instructor notebooks of `solutions` and the `catalog` file's entries.
    `progress` (a function of one text) hears of each draw."""
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise InputError(f"--check needs a whole number of draws, at least 1; got {count!r}.")
    correct, mistakes = load_catalog(catalog) if catalog is not None else ((), ())
    varied = {e.number: e for e in registry if e.params}
    if not varied:
        raise InputError("no exercise declares parameters (Exercise.params): there is nothing to draw.")
    students = [f"draw-{i}" for i in range(count)] + [str(key) for key in (roster or {}).values()]
    by_notebook: dict = {}
    for exercise in varied.values():
        by_notebook.setdefault(exercise.notebook, []).append(exercise)
    originals = {name: read_notebook(Path(solutions) / name) for name in by_notebook}
    troubles = _ties(variants, registry, roster)
    for index, student in enumerate(students):
        values = variants.values(registry, student)
        other = variants.values(registry, students[index - 1] if len(students) > 1 else f"{student}-other")
        draw = _Draw(student, values, other, {n: values[n] for n in varied}, seed + index, registry, troubles)
        for exercise in varied.values():
            why = exercise.sound(values[exercise.number]) if exercise.sound is not None else ""
            if why:
                draw.trouble(f"exercise {exercise.number}'s data", why)
        for notebook, exercises in by_notebook.items():
            _check_notebook(draw, originals[notebook], notebook, exercises, correct, mistakes)
        if progress is not None:
            progress(f"draw {index + 1} of {len(students)}: {student}")
    return troubles


@dataclass(frozen=True)
class _Draw:
    """One student's draw being checked: its data, another student's, and the troubles found so far."""

    student: str
    values: dict  # {exercise: {parameter: value}}
    other: dict  # another student's values, for the copy check
    mine: dict  # the values of the varied exercises, as a trouble shows them
    seed: int
    registry: Registry
    troubles: list

    def trouble(self, entry, what):
        self.troubles.append(Trouble(self.student, self.mine, entry, what))


def _ties(variants, registry, roster):
    """A trouble for each exercise that two students of the roster drew alike."""
    return [
        Trouble(
            tied[0],
            {number: variants.values(registry, tied[0])[number]},
            "a tie",
            f"exercise {number}: the same data as {', '.join(tied[1:])}, so a copy between them cannot be seen; "
            f"give all but one a fresh draw (labkit variants --redraw ID --exercise {number})",
        )
        for number, tied in variant_data.ties(variants, registry, (roster or {}).values())
    ]


def _check_notebook(draw, original, notebook, exercises, correct, mistakes):
    """Run one instructor notebook on the draw's data: the solution and each catalog entry, then the copy check."""
    import matplotlib.pyplot as plt

    numbers = {e.number for e in exercises}
    names = sorted({name for e in exercises for part in e.parts for name in (*e.names, *part.names())})
    # the catalog's students read their rates off their own tables, unless the entry keeps them as written
    entries = [("the solution", (), None, None, (), numbers, False)]
    entries += [
        (f"correct: {e.name}", e.replace, None, None, (), set(e.full) & numbers, not getattr(e, "keep_rates", False))
        for e in correct
        if e.notebook == notebook and set(e.full) & numbers
    ]
    entries += [
        (f"slip: {e.name}", e.replace, e.part, e.hint, tuple(e.also), {e.exercise}, not getattr(e, "keep_rates", False))
        for e in mistakes
        if e.notebook == notebook and e.exercise in numbers
    ]
    for label, replace, part, hint, also, judged, reads in entries:
        planted = _planted(original, replace, label)
        planted = reading_rates(planted, draw.registry) if reads else planted
        namespace = run_cells(with_values(planted, draw.values, notebook, draw.registry), names)
        for number in sorted(judged):
            _judge_entry(draw, namespace, number, label, part, (hint, also))
        plt.close("all")
    # the solution on another student's data: caught, and its varied parts lost
    copied = [e for e in exercises if draw.other[e.number] != draw.values[e.number]]
    if copied:
        namespace = run_cells(with_values(original, draw.other, notebook, draw.registry), names)
        for exercise in copied:
            _judge_copy(draw, namespace, exercise)
        plt.close("all")


def _judge_entry(draw, namespace, number, label, part, expected):
    """Exercise `number` of one run of a notebook: full marks for the solution and a correct variation, exactly
    `part` (and the parts of `expected`'s ``also``) lost for a slip, with its hint (`expected`'s first) said."""
    hint, also = expected
    verdict = draw.registry.check(number, namespace, seed=draw.seed, variant=draw.values[number])
    failed = _failed(verdict)
    if verdict.get("other_variant"):  # a notebook on its own data is never taken for a copy
        draw.trouble(label, f"exercise {number}: its own data named another's")
    if part is None and failed:
        draw.trouble(label, f"exercise {number} lost {sorted(failed)}")
    elif part is not None:
        lost = {part} | {p for n, p in also if n == number}
        if failed != lost:
            draw.trouble(label, f"failed {sorted(failed)}, not {sorted(lost)}")
        elif hint and hint not in _said(verdict["checks"], part):
            draw.trouble(label, f"the feedback does not say {hint!r}")


def _judge_copy(draw, namespace, exercise):
    """The solution run on another student's data: named as a copy, and its varied parts lost."""
    verdict = draw.registry.check(exercise.number, namespace, seed=draw.seed, variant=draw.values[exercise.number])
    passing = {part.name for part in exercise.parts if part.varied} - _failed(verdict)
    if not verdict.get("other_variant"):
        draw.trouble("a copy", "another student's data is not named")
    if passing:
        draw.trouble("a copy", f"{sorted(passing)} pass on another's data")
