"""Grading one notebook and one submission, on the grader's (trusted) side.

For each notebook: read it here (JSON only, nothing run), copy it into a
private folder, start the sandboxed worker on that folder, have it run the
code cells, then run every exercise's checks here through proxies into the
worker (:mod:`labkit.grading.remote`), with the exercise's reference
implementations switched off in the sandbox and named if the source reaches
for them (:mod:`labkit.grading.refusals`). Scores, hints and problems are
all computed on this side.
"""
import re
import shutil
import tempfile
import time
from pathlib import Path

from ..checks.exercises import EXERCISES, grade as run_checks
from ..notebooks import read_notebook
from . import refusals, remote, sandbox
from .report import SubmissionGrade

OUTPUT_LIMIT = 100_000  # characters a notebook may print before its feedback says so
SHOWN_ERRORS = 12  # failing cells named in the feedback (a bare release has up to 10 per notebook)
HEADING = re.compile(r"^#+\s*Exercise\s+(\d+)", re.MULTILINE)


def exercises_in(nb):
    """Graded exercises whose section heading ('## Exercise N') the notebook has."""
    found = {int(n) for cell in nb.cells if cell.cell_type == "markdown" for n in HEADING.findall(cell.source)}
    return sorted(found & set(EXERCISES))


def submission_notebooks(path):
    """The notebooks of a submission: one .ipynb file, or every .ipynb in a folder (no links followed)."""
    path = Path(path)
    if path.is_dir():
        notebooks = sorted(p for p in path.rglob("*.ipynb")
                           if ".ipynb_checkpoints" not in p.parts and p.is_file() and not p.is_symlink())
        if not notebooks:
            raise ValueError(f"{path} contains no notebooks (*.ipynb).")
        return notebooks
    if not path.exists():
        raise ValueError(f"{path} does not exist.")
    if path.suffix != ".ipynb":
        raise ValueError(f"{path} is not a notebook: give .ipynb files or folders of them.")
    return [path]


def _own_code(findings):
    """A failed check naming the references a graded function reaches for."""
    details = "; ".join(f"{function} (line {line} of its definition) reaches for {name}"
                        for function, line, name in findings)
    return {"name": "own code", "passed": False,
            "hint": "the exercise asks you to write this yourself; labkit.bracket and the helpers the lab "
                    "names stay available.",
            "steps": [{"step": "calls no reference implementation", "passed": False, "detail": details}]}


def _run_problems(name, ran, total_timeout):
    problems = []
    if ran["errors"]:
        shown = "; ".join(f"cell {e['cell'] + 1} raised {e['kind']}: {e['message'][:300]}"
                          for e in ran["errors"][:SHOWN_ERRORS])
        more = f"; and {len(ran['errors']) - SHOWN_ERRORS} more" if len(ran["errors"]) > SHOWN_ERRORS else ""
        problems.append(f"{name}: {len(ran['errors'])} cell(s) raised an error (graded as far as it got): "
                        f"{shown}{more}.")
    if ran["output_chars"] > OUTPUT_LIMIT:
        problems.append(f"{name}: printed {ran['output_chars']:,} characters of output (none of it is kept).")
    return problems


def grade_notebook(path, cell_timeout=60, total_timeout=600, seed=None, confined=True, limits=None):
    """Run one notebook in the sandbox and check it; returns ({exercise: grade dict}, [problems])."""
    name = Path(path).name
    try:
        nb = read_notebook(path)
    except ValueError as exc:
        return {}, [str(exc)]
    numbers = exercises_in(nb)
    if not numbers:
        return {}, []
    sources = [cell.source for cell in nb.cells if cell.cell_type == "code"]
    limits = limits or sandbox.Limits(cpu_seconds=int(total_timeout) + 30)
    deadline = time.monotonic() + total_timeout
    with tempfile.TemporaryDirectory(prefix="labkit-grade-") as workdir:
        shutil.copyfile(path, Path(workdir) / name)
        with remote.Notebook(workdir, limits, confined, deadline) as notebook:
            try:
                ran = notebook.request({"op": "run", "cells": sources, "cell_timeout": cell_timeout}, total_timeout)
            except remote.WorkerError as exc:
                why = (f"stopped after the total time limit of {total_timeout} s" if "total time limit" in str(exc)
                       else f"{exc} while running its cells")
                return {}, [f"{name}: {why}."]
            problems = _run_problems(name, ran, total_timeout) if "errors" in ran else []
            results = {}
            for number in numbers:
                exercise = EXERCISES[number]
                namespace = remote.Namespace(notebook, exercise.refused, cell_timeout)
                verdict = run_checks(number, namespace, seed=seed)
                findings = refusals.scan(sources, exercise.names, exercise.refused)
                if findings:
                    verdict["checks"].append(_own_code(findings))
                    verdict["passed"], verdict["points"], verdict["fraction"] = False, 0, 0.0
                results[number] = verdict
            if notebook.stopped:
                problems.append(f"{name}: {notebook.stopped} while its functions were being checked.")
    return results, problems


def grade_submission(path, cell_timeout=60, total_timeout=600, seed=None, confined=True, limits=None, rubric=None):
    """Grade one submission (a notebook or a folder of them), scored with `rubric` (the lab's when None)."""
    path = Path(path)
    grade = SubmissionGrade(path.stem if path.is_file() else path.name, seed=seed)
    if rubric is not None:
        grade.rubric = rubric
    for notebook in submission_notebooks(path):
        results, problems = grade_notebook(notebook, cell_timeout, total_timeout, seed, confined, limits)
        grade.problems.extend(problems)
        for number, verdict in results.items():
            best = grade.results.get(number)
            # an exercise may be mentioned in several notebooks: keep the one that scores,
            # or else the one that defines its functions
            if best is None or (verdict["points"], verdict["defined"]) > (best["points"], best["defined"]):
                grade.results[number] = verdict
    return grade
