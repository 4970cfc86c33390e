"""A made-up class's grading results, for the class report's browser test, its benchmark and the docs picture.

:func:`synthetic_class` builds :class:`~labkit.grading.store.report.SubmissionGrade` objects for the lab's
exercises as `labkit grade` writes them: students of varying skill, a branch each, stubs left as
released, slips named with the catalog's hints (``tests/catalog.py``), errors raised, time limits,
refused references, cells that raised, a crash and a submission that could not be graded, all worded
as the grader words them. :func:`synthetic_sources` makes each student's source of a few graded
functions: independent variants, plus a few copies. Nothing here is graded for real (that is
tests/exercises/test_catalog.py's job); it is realistic input for the report, made in milliseconds.
"""

import numpy as np
from catalog import MISTAKES

from labkit.exercises.result import NOT_DONE
from labkit.exercises.result import RAISED as RAISED_KIND
from labkit.grading.store.model import ExerciseResult
from labkit.grading.store.report import ProblemText, SubmissionGrade
from labkit.grading.store.rubric import default

FIRST = ("Ada", "Ben", "Chloé", "Dmitri", "Eun-ji", "Farah", "Goran", "Hana", "Iker", "Jun", "Kofi", "Lena")
LAST = ("Abara", "Berg", "Costa", "Diaz", "Eriksen", "Fujita", "García", "Haddad", "Ivanova", "Jensen")
RAISED = (
    ("ZeroDivisionError", "float division by zero", "d = 2 / (xk1 - xk)"),
    ("IndexError", "index 5 is out of bounds for axis 0 with size 5", "h = xdata[k + 1] - xdata[k]"),
    ("ValueError", "operands could not be broadcast together with shapes (4,) (5,)", "A[k, k - 1] = h / 6"),
    ("NameError", "name 'xk' is not defined", "return y0 * h1 + y1 * h3"),
)
REFERENCES = ("scipy.interpolate.CubicSpline", "scipy.interpolate.CubicHermiteSpline", "numpy.interp")


def _step(step, detail, kind=None):
    """A failed step; `kind` is the code the grader sets where it makes a step that is no slip."""
    return {"step": step, "passed": False, "detail": detail, **({"kind": kind} if kind else {})}


def _failed(name, weight, steps, hint):
    return {"name": name, "passed": False, "hint": hint, "weight": weight, "steps": steps}


def _outcome(rng, part, weight, skill, slips):
    """One part's check as the grader records it, for a student of `skill` (0..1) who attempted it."""
    if rng.random() < skill**0.6:
        return {
            "name": part,
            "passed": True,
            "hint": "",
            "weight": weight,
            "steps": [_step("runs", "") | {"passed": True}],
        }
    draw = rng.random()
    if draw < 0.72 and slips:
        weights = 1.0 / np.arange(1, len(slips) + 1) ** 1.2  # a few slips are common, the rest rare
        hint = slips[rng.choice(len(slips), p=weights / weights.sum())]
        return _failed(part, weight, [_step("the values at fresh points", "off by 3.1e-01")], hint)
    if draw < 0.84:
        kind, message, line = RAISED[rng.integers(len(RAISED))]
        where = f"in {part}, line {rng.integers(3, 20)}: `{line}`"
        return _failed(
            part,
            weight,
            [_step(f"{part}(...) runs", f"raised {kind}: {message} ({where})", RAISED_KIND)],
            f"the error happened {where}: look at that line.",
        )
    if draw < 0.91:
        return _failed(
            part,
            weight,
            [_step(f"{part}(...) runs", "interrupted: it ran longer than the time limit", "timeout")],
            "see what the feedback says about the notebook above.",
        )
    if draw < 0.97:
        reference = REFERENCES[rng.integers(len(REFERENCES))]
        return _failed(
            part,
            weight,
            [
                _step(
                    f"{part}(...) runs",
                    f"called {reference}, which is switched off while this exercise is graded",
                    "refused",
                )
            ],
            f"the exercise asks you to write this yourself: do not call {reference}.",
        )
    return _failed(
        part,
        weight,
        [_step(f"{part} is defined", "not defined when the notebook finished", NOT_DONE)],
        f"run the cell that defines {part} (and keep its name); a cell that raised stops it.",
    )


def _stub(part, weight):
    return _failed(
        part,
        weight,
        [_step(f"{part}(...) runs", "not implemented yet", NOT_DONE)],
        "replace the `raise NotImplementedError()` with your code.",
    )


def _verdict(number, checks, points):
    earned = sum(c["weight"] for c in checks if c["passed"])
    return {
        "exercise": number,
        "passed": earned == points,
        "points": earned,
        "fraction": earned / points,
        "defined": True,
        "checks": checks,
    }


def names(count, rng):
    """`count` distinct, plausible student names."""
    out, seen = [], set()
    while len(out) < count:
        name = f"{FIRST[rng.integers(len(FIRST))]} {LAST[rng.integers(len(LAST))]}"
        name = name if name not in seen else f"{name} {len(out)}"
        seen.add(name)
        out.append(name)
    return out


def synthetic_class(count, seed=0, rubric=None, extra_names=()):
    """A class of `count` graded submissions (plus `extra_names`, e.g. a hostile one), as SubmissionGrade objects.

    Deterministic for a seed. About one in a hundred could not be graded; the rest have a branch, stubs,
    slips, errors, time limits and refused references in realistic proportions."""
    rng = np.random.default_rng(seed)
    rubric = rubric or default()
    registry = rubric.registry
    slips = {}
    for mistake in MISTAKES:
        slips.setdefault((mistake.exercise, mistake.part), []).append(mistake.hint)
    branches = [b.exercises for b in rubric.branches] or [()]
    grades = []
    for name in [*names(count, rng), *extra_names]:
        grade = SubmissionGrade(name, seed=20261122, rubric=rubric)
        if rng.random() < 0.01:
            grade.failure = "its grading ran out of memory (the grader's limit of 3072 MiB) and was stopped"
            grades.append(grade)
            continue
        skill = rng.beta(5, 2)
        chosen = set(branches[rng.choice(len(branches), p=[0.4, 0.6] if len(branches) == 2 else None)])
        if rng.random() < 0.05:
            chosen |= {n for b in branches for n in b}
        attempted = set(rubric.required) | chosen | ({16} if rng.random() < 0.4 and 16 in rubric.points else set())
        for number in rubric.graded:
            exercise = registry.exercises[number]
            if number not in attempted and rng.random() < 0.3:
                continue  # the notebook was not handed in
            checks = [
                _outcome(rng, part.name, part.weight, skill, slips.get((number, part.name), ()))
                if number in attempted
                else _stub(part.name, part.weight)
                for part in exercise.parts
            ]
            grade.results[number] = ExerciseResult.from_dict(_verdict(number, checks, exercise.points), number)
        if rng.random() < 0.12:
            kind, message, line = RAISED[rng.integers(len(RAISED))]
            cell = rng.integers(5, 40)
            grade.problems.append(
                ProblemText(
                    f"04_splines.ipynb: 1 cell(s) raised an error (graded as far as it got):\n"
                    f"    cell {cell} raised {kind}: {message}\n      | ----> 3 {line}",
                    [(RAISED_KIND, f"04_splines.ipynb: cell {cell} raised {kind}: {message}")],
                )
            )
        if rng.random() < 0.03:
            grade.problems.append(
                ProblemText.one("03_meshes.ipynb: stopped after the submission's time limit of 600 s.", "timeout")
            )
        if rng.random() < 0.015:
            grade.problems.append(
                ProblemText.one(
                    "02_convergence.ipynb: the notebook's process was killed by SIGKILL (a resource limit, or "
                    "os.kill) while running its cells.",
                    "crash",
                )
            )
        grades.append(grade)
    return grades


# a graded function's source in the styles students write it; {a}, {b}, ... are the student's own names
TEMPLATES = {
    "eval_pherm": (
        "def eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    {k} = labkit.bracket(xdata, xval)\n"
        "    {h} = xdata[{k} + 1] - xdata[{k}]\n"
        "    {t} = (xval - xdata[{k}]) / {h}\n"
        "    h1 = 2 * {t}**3 - 3 * {t}**2 + 1\n"
        "    h2 = ({t}**3 - 2 * {t}**2 + {t}) * {h}\n"
        "    h3 = -2 * {t}**3 + 3 * {t}**2\n"
        "    h4 = ({t}**3 - {t}**2) * {h}\n"
        "    return ydata[{k}] * h1 + ypdata[{k}] * h2 + ydata[{k} + 1] * h3 + ypdata[{k} + 1] * h4\n",
        "def eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    {out} = np.zeros(len(xval))\n"
        "    for {i} in range(len(xval)):\n"
        "        {k} = labkit.bracket(xdata, xval[{i}])\n"
        "        x0, x1 = xdata[{k}], xdata[{k} + 1]\n"
        "        {h} = x1 - x0\n"
        "        {s} = xval[{i}] - x0\n"
        "        {t} = x1 - xval[{i}]\n"
        "        {out}[{i}] = (ydata[{k}] * {t}**2 * (2 * {s} + {h}) + ydata[{k} + 1] * {s}**2 * (2 * {t} + {h})) / {h}**3\n"
        "        {out}[{i}] += (ypdata[{k}] * {s} * {t}**2 - ypdata[{k} + 1] * {s}**2 * {t}) / {h}**2\n"
        "    return {out}\n",
    ),
    "complete_system": (
        "def complete_system(xdata, ydata, {a}, {b}):\n"
        "    {n} = len(xdata)\n"
        "    {h} = np.diff(xdata)\n"
        "    A = np.zeros(({n}, {n}))\n"
        "    D = np.zeros({n})\n"
        "    A[0, 0], A[0, 1] = {h}[0] / 3, {h}[0] / 6\n"
        "    D[0] = (ydata[1] - ydata[0]) / {h}[0] - {a}\n"
        "    for {k} in range(1, {n} - 1):\n"
        "        A[{k}, {k} - 1] = {h}[{k} - 1] / 6\n"
        "        A[{k}, {k}] = ({h}[{k} - 1] + {h}[{k}]) / 3\n"
        "        A[{k}, {k} + 1] = {h}[{k}] / 6\n"
        "        D[{k}] = (ydata[{k} + 1] - ydata[{k}]) / {h}[{k}] - (ydata[{k}] - ydata[{k} - 1]) / {h}[{k} - 1]\n"
        "    A[-1, -2], A[-1, -1] = {h}[-1] / 6, {h}[-1] / 3\n"
        "    D[-1] = {b} - (ydata[-1] - ydata[-2]) / {h}[-1]\n"
        "    return A, D\n",
        "def complete_system(xdata, ydata, {a}, {b}):\n"
        "    xdata = np.asarray(xdata, dtype=float)\n"
        "    ydata = np.asarray(ydata, dtype=float)\n"
        "    {n} = xdata.size\n"
        "    {h} = xdata[1:] - xdata[:-1]\n"
        "    {s} = (ydata[1:] - ydata[:-1]) / {h}\n"
        "    A = np.diag(np.r_[{h}[0], {h}[:-1] + {h}[1:], {h}[-1]] / 3)\n"
        "    A += np.diag({h} / 6, 1) + np.diag({h} / 6, -1)\n"
        "    D = np.r_[{s}[0] - {a}, np.diff({s}), {b} - {s}[-1]]\n"
        "    return A, D\n",
    ),
}
FILLERS = {
    "k": ("k", "idx", "j", "interval", "seg"),
    "h": ("h", "dx", "width", "hk", "step"),
    "t": ("t", "u", "tau", "r", "w"),
    "s": ("s", "left", "dl", "p", "q"),
    "i": ("i", "m", "ii", "pos", "c"),
    "out": ("out", "yval", "result", "values", "y"),
    "n": ("n", "npts", "N", "size", "m"),
    "a": ("a", "slope0", "fp0", "d0", "sa"),
    "b": ("b", "slope1", "fpn", "dn", "sb"),
}
COMMENTS = ("    # Hermite basis on the interval\n", "    # the lab's formulas\n", "    # see section 3.2\n", "")


def synthetic_sources(students, seed=0, copies=4):
    """{function: {student: source}}: each student's own variant of each function, and `copies` pairs of
    students whose sources are copies (one verbatim, the others with names changed and a comment added).

    Returns the sources and the copied pairs as [(function, original, copy)]."""
    rng = np.random.default_rng(seed)
    sources, copied = {}, []
    for function, templates in TEMPLATES.items():
        mine = {}
        for student in students:
            template = templates[rng.integers(len(templates))]
            fill = {key: choices[rng.integers(len(choices))] for key, choices in FILLERS.items()}
            lines = template.format(**fill).splitlines(keepends=True)
            lines.insert(1, COMMENTS[rng.integers(len(COMMENTS))])
            if rng.random() < 0.5:
                lines.insert(len(lines) - 1, "\n")
            mine[student] = "".join(lines)
        for number in range(copies):
            original, copy = rng.choice(len(students), size=2, replace=False)
            text = mine[students[original]]
            if number % 2:
                text = text.replace("    # ", "    # my own notes: ") + "\n# checked against the notes\n"
            mine[students[copy]] = text
            copied.append((function, students[original], students[copy]))
        sources[function] = mine
    return sources, copied


def pair_of(function, first, second, first_source, second_source):
    """A :class:`~labkit.grading.reports.similarity.Pair` of two sources, the lines they share found with difflib
    (a stand-in for the similarity search, to show pairs in the report without it)."""
    import difflib

    from labkit.grading.reports.similarity import Pair

    a, b = first_source.splitlines(), second_source.splitlines()
    matcher = difflib.SequenceMatcher(None, [line.strip() for line in a], [line.strip() for line in b], autojunk=False)
    shared_a, shared_b = set(), set()
    for block in matcher.get_matching_blocks():
        shared_a.update(range(block.a, block.a + block.size))
        shared_b.update(range(block.b, block.b + block.size))
    score = max(len(shared_a) / max(len(a), 1), len(shared_b) / max(len(b), 1))
    return Pair(function, first, second, score, tuple(a), tuple(b), frozenset(shared_a), frozenset(shared_b))


def class_with_pairs(count, seed=0, extra_names=()):
    """A synthetic class and the pairs of its copied sources (:func:`pair_of`), ready for the class report."""
    grades = synthetic_class(count, seed, extra_names=extra_names)
    sources, copied = synthetic_sources([g.name for g in grades if g.graded], seed, copies=2)
    return grades, [pair_of(function, a, b, sources[function][a], sources[function][b]) for function, a, b in copied]
