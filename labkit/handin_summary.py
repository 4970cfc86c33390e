"""The last lines of ``labkit handin DIR``: which of the lab's notebooks the folder holds, which it lacks, and
which of those it needs, from the lab's rubric (the exercises everyone does, the branches of which one is
enough, the extra credit) and the notebook each exercise is in. The rubric is read as data, its TOML file;
the grader is never imported.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

RUBRIC = Path(__file__).with_name("grading") / "store" / "rubric.toml"


def _plan(rubric: Path = RUBRIC) -> dict:
    """{"required": notebooks, "branches": [(name, notebooks)], "extra": notebooks}, from the rubric's exercises."""
    from .exercises.registry import LAB

    where = {number: name for name, numbers in LAB.notebooks().items() for number in numbers}
    data = tomllib.loads(rubric.read_text(encoding="utf-8"))

    def notebooks(numbers) -> list:
        return sorted({where[n] for n in numbers if n in where})

    branches = (data.get("branches") or {}).get("choice") or []
    return {
        "required": notebooks(data.get("required") or []),
        "branches": [(str(b["name"]), notebooks(b["exercises"])) for b in branches],
        "extra": notebooks(data.get("extra_credit") or []),
    }


def _stems(names) -> str:
    return " + ".join(Path(n).stem for n in names)


def folder_lines(present, ready: int, rubric: Path = RUBRIC) -> list:
    """What the folder holds and lacks, given the lab notebook of each file run, `present` (a file name each), and
    how many of those files are `ready`.

    >>> lines = folder_lines(["01_limacon.ipynb", "02_convergence.ipynb"], 0)
    >>> print("\\n".join(lines))  # doctest: +NORMALIZE_WHITESPACE
    Ready to hand in: 0 of 2 notebook(s), as far as the self-checks can tell.
    The lab asks for 01_limacon + 02_convergence, and one branch: 03_meshes (mesh generation) or
    04_splines + 05_monotone (splines); 06_bilinear is extra credit.
    Not in this folder: 03_meshes.ipynb, 04_splines.ipynb, 05_monotone.ipynb, 06_bilinear.ipynb
    (a branch is still missing: 03_meshes, or 04_splines + 05_monotone).
    """
    plan, files, present = _plan(rubric), len(present), set(present)
    lines = [f"Ready to hand in: {ready} of {files} notebook(s), as far as the self-checks can tell."]
    branches = " or ".join(f"{_stems(names)} ({name})" for name, names in plan["branches"])
    asks = f"The lab asks for {_stems(plan['required'])}" + (f", and one branch: {branches}" if branches else "")
    extra = f"; {_stems(plan['extra'])} is extra credit" if plan["extra"] else ""
    lines.append(asks + extra + ".")
    known = set(plan["required"]) | set(plan["extra"]) | {n for _, names in plan["branches"] for n in names}
    missing = sorted(known - present)
    if missing:
        lines.append(f"Not in this folder: {', '.join(missing)} ({_needs(plan, present)}).")
    return lines


def _needs(plan: dict, present: set) -> str:
    """Whether the notebooks the folder lacks are needed: required ones, a branch, or only extra credit."""
    required = [n for n in plan["required"] if n not in present]
    if required:
        return f"needed by everyone: {', '.join(required)}"
    whole = [name for name, names in plan["branches"] if set(names) <= present]
    if plan["branches"] and not whole:
        options = ", or ".join(_stems(names) for _, names in plan["branches"])
        return f"a branch is still missing: {options}"
    if whole:
        return f"not needed: the {whole[0]} branch is here, and anything more is extra credit"
    return "not needed: only extra credit"
