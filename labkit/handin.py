"""Ready to hand in? What a lab notebook still lacks, from the students' own self-checks.

The last cell of every lab notebook is ``labkit.ready_to_hand_in("02_convergence")``. Run after
*Restart and run all*, it shows one table for the notebook: each graded part of its exercises done
and passing its self-check, done but failing (with the check's hint), or not done; the cells
that raised; the answers in words left empty. It runs only the self-checks students call
(:mod:`labkit.check`, on their fixed data); it never imports the grader (:mod:`labkit.grading`),
whose hidden checks draw fresh data, so it says that the grade may differ.

``labkit handin DIR`` (:func:`run_notebook`) runs each notebook of a folder in a fresh kernel, every
cell even after one raised, and prints the same table.
"""

from __future__ import annotations

import ast
import contextlib
import io
import json
import math
import os
import re
import sys
import textwrap
import warnings
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from numbers import Real
from pathlib import Path

from . import notebook as _notebook
from .errors import InputError
from .exercises.model import sections
from .exercises.result import NOT_DONE, NOT_IMPLEMENTED, part_kind

DONE, FAILING, NOT_STARTED = "done, passes its self-check", "done but failing", NOT_DONE  # as part_kind names it
ANSWER_STUB = "YOUR ANSWER HERE"  # what labkit release (and nbgrader) leave in an answer in words
CALL = re.compile(r"""ready_to_hand_in\(\s*["']([\w.\-]+)["']""")
WIDTH = 100


@dataclass
class PartStatus:
    """One graded part: its exercise, name, status (:data:`DONE`, :data:`FAILING`, :data:`NOT_STARTED`) and why."""

    exercise: int
    part: str
    status: str
    detail: str = ""  # the check's hint when failing; what is missing when not done


@dataclass
class HandIn:
    """What :func:`ready_to_hand_in` found in one notebook; prints as the table students read.

    ``raised`` is None when the cells that raised are not known (no notebook, or its first cell never
    ran); ``empty_answers`` is None when the notebook's file was not found (``answers_from`` says why).
    """

    notebook: str
    parts: list
    raised: list | None = None
    empty_answers: list | None = None
    answers_from: str = ""
    every_cell_ran: bool = False  # run by `labkit handin`: no cell was skipped after one raised
    never_ran: list | None = None  # the saved notebook's code cells that did not run in this kernel, when known
    problem: str = ""  # `labkit handin` could not run the notebook: why

    @property
    def ready(self) -> bool:
        """Every part done and passing, no cell raised, no answer in words left empty (as far as known)."""
        return (
            not self.problem
            and bool(self.parts)
            and all(p.status == DONE for p in self.parts)
            and not self.raised
            and not self.empty_answers
        )

    def counts(self) -> dict:
        """How many parts are in each status."""
        return {status: sum(p.status == status for p in self.parts) for status in (DONE, FAILING, NOT_STARTED)}

    def text(self) -> str:
        """The table as plain text."""
        lines = [f"Ready to hand in? {self.notebook}"]
        if self.problem:
            lines.append(_wrapped(f"could not run it: {self.problem}", "  "))
            return "\n".join(lines)
        width = max([len("part")] + [len(p.part) for p in self.parts])
        lines.append(f"exercise  {'part':<{width}}  status")
        indent = " " * (10 + width + 2)
        for p in self.parts:
            lines.append(
                f"{p.exercise:>8}  {p.part:<{width}}  {p.status}"
                + (f" ({p.detail})" * (p.status == NOT_STARTED and bool(p.detail)))
            )
            if p.status == FAILING and p.detail:
                lines.append(_wrapped(f"hint: {p.detail}", indent))
        lines.append("")
        if self.raised is None:
            lines.append("Cells that raised: not known (the notebook's first cell, with labkit.ready, did not run).")
        elif not self.raised:
            lines.append("Cells that raised: none.")
        else:
            lines.append("Cells that raised:")
            stubs = [c for c in self.raised if c.error == "NotImplementedError"]
            if stubs:
                numbers = ", ".join(f"[{c.number}]" if c.number is not None else "[ ]" for c in stubs)
                lines.append(_wrapped(f"NotImplementedError (work still to do): {numbers}", "  "))
            for cell in self.raised:
                if cell.error != "NotImplementedError":
                    lines.append(f"  {_cell_label(cell)}")
                    lines.append(_wrapped(_error_text(cell), "      "))
        if self.empty_answers is None:
            lines.append(_wrapped(f"Answers in words: not checked ({self.answers_from}).", ""))
        elif not self.empty_answers:
            lines.append(f"Answers in words left empty: none ({self.answers_from}).")
        else:
            advice = "" if self.every_cell_ran else "; written just now? Save, then run this cell again"
            lines.append(f"Answers in words left empty ({self.answers_from}{advice}):")
            lines.extend(_wrapped(answer, "  ") for answer in self.empty_answers)
        lines.append("")
        count = self.counts()
        if self.ready:
            lines.append(f"All {len(self.parts)} parts pass their self-checks.")
        else:
            lines.append(
                f"{count[DONE]} of {len(self.parts)} parts pass their self-checks, {count[FAILING]} fail, "
                f"{count[NOT_STARTED]} not done."
            )
        if self.never_ran and not self.every_cell_ran:
            lines.append(_not_run_advice(self.never_ran))
        lines.append(
            "Only the self-checks ran, on fixed data; the grader uses fresh data too, so your grade may differ."
        )
        return "\n".join(line if line.startswith(" ") else _wrapped(line, "") for line in lines)

    def __repr__(self) -> str:
        return self.text()

    def as_dict(self) -> dict:
        """Plain data (what ``labkit handin`` reads back from the kernel)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping) -> HandIn:
        """The result :meth:`as_dict` gave."""
        data = dict(data)
        data["parts"] = [PartStatus(**p) for p in data.get("parts", [])]
        if data.get("raised") is not None:
            data["raised"] = [_notebook.RaisedCell(**c) for c in data["raised"]]
        return cls(**data)


def notebook_file(notebook: str) -> str:
    """The lab notebook's file name (``"02_convergence"`` -> ``"02_convergence.ipynb"``); ValueError if none.

    >>> notebook_file("03_meshes")
    '03_meshes.ipynb'
    """
    from .exercises.registry import LAB

    known = LAB.notebooks()
    name = str(notebook).strip()
    name = Path(name).name if name.endswith(".ipynb") else f"{Path(name).name}.ipynb"
    if name not in known:
        stems = ", ".join(f'"{Path(n).stem}"' for n in sorted(known))
        raise InputError(f"{notebook!r} is not one of the lab's notebooks; give one of {stems}.")
    return name


def ready_to_hand_in(notebook: str, namespace: Mapping | None = None, path: str | os.PathLike | None = None) -> HandIn:
    """Is this notebook ready to hand in? Its graded parts, the cells that raised, the empty answers in words.

    Call it as the last cell, after Restart and run all: ``labkit.ready_to_hand_in("02_convergence")``.
    Each graded part of the notebook's exercises is run through its self-check (the one the notebook
    calls, :mod:`labkit.check`, on its fixed data), on the names the notebook defined: `namespace`,
    the caller's globals by default. The cells that raised are those the notebook's first cell
    (``labkit.ready``) saw. The answers in words are read from the notebook's file: `path`, or the
    file the front end names (VS Code, JupyterLab), or ``<notebook>.ipynb`` in the working folder, as
    last saved. The grader is never run. The result prints as a table.

    >>> result = ready_to_hand_in("02_convergence", namespace={})
    >>> [p.status for p in result.parts] == ["not done"] * 5
    True
    >>> result.ready
    False
    """
    name = notebook_file(notebook)
    if namespace is None:
        namespace = sys._getframe(1).f_globals  # the notebook's variables: a cell runs in them
    if not isinstance(namespace, Mapping):
        raise InputError(
            f"namespace must be a mapping of the notebook's names (globals()); got {type(namespace).__name__}."
        )
    if _notebook.headless():  # the grader's sandbox: nobody reads the table there, and the grade is its own
        return HandIn(name, [], problem="not checked here: nothing shown here is read (LABKIT_HEADLESS=1)")
    raised = _notebook.CELLS.cells() if _notebook.CELLS is not None else None
    _notebook.track_cells()  # from now on, if the first cell did not
    cells, answers_from = _read_notebook(name, namespace, path)
    empty = _empty_answers(name, cells) if cells is not None else None
    result = HandIn(name, _parts(name, namespace, raised or []), raised, empty, answers_from)
    if cells is not None and _notebook.CELLS is not None:
        result.never_ran = [n for n in _notebook.CELLS.never_ran(cells) if n != _hand_in_cell(cells)]
    return result


def _hand_in_cell(cells: list) -> int | None:
    """The number of the cell that calls ready_to_hand_in (it is running, not yet noted as run)."""
    numbers = _notebook.prompt_numbers(cells)
    found = [numbers[i] for i in numbers if "ready_to_hand_in(" in _text(cells[i])]
    return found[-1] if found else None


def _not_run_advice(numbers: list) -> str:
    shown = ", ".join(f"[{n}]" for n in numbers[:8]) + (", ..." if len(numbers) > 8 else "")
    return (
        f"{len(numbers)} cell(s) of the saved notebook did not run in this kernel ({shown}): what they define "
        "shows as not done. Restart and run all; if it stops at a cell that raises, fix that cell and run all "
        "again."
    )


def _parts(name: str, namespace: Mapping, raised: list) -> list:
    from .exercises.registry import LAB  # the exercises' declarations and their self-checks; never the grader

    stubbed: set = set()
    failed: dict = {}  # names of cells still holding their stub; of the other cells that raised
    for cell in raised:
        names, stub = _assigned(cell.source)
        if stub and cell.error == "NotImplementedError":
            stubbed |= names
        else:
            failed.update(dict.fromkeys(names - set(failed), cell.number))
    parts = []
    sink = io.StringIO()
    for number in LAB.notebooks()[name]:
        exercise = LAB.exercises[number]
        with warnings.catch_warnings(), contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
            warnings.simplefilter("ignore")  # the student's warnings were shown where their cells ran
            # seed None: the self-checks' own fixed data; the notebook's own data where its exercise varies them
            found = LAB.check(number, namespace, variant=_own_data(exercise, namespace))
        for part, check in zip(exercise.parts, found["checks"]):
            parts.append(_status(number, part, check, namespace, stubbed, failed))
    return parts


def _own_data(exercise, namespace: Mapping) -> dict:
    """The notebook's values of the data its exercise lets vary (a variant notebook's own, or the lab's), as
    numbers; a name that is missing or not a number is left to the check's default, the lab's value."""
    found = {}
    for param in exercise.params:
        value = namespace.get(param.name)
        if isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value):
            found[param.name] = float(value)
    return found


def _status(number: int, part, check: Mapping, namespace: Mapping, stubbed: set, failed: dict) -> PartStatus:
    missing = sorted((n for n in _required(part) if n not in namespace), key=lambda n: n != part.name)
    if missing:
        cell = f": cell [{failed[missing[0]]}] raised" if failed.get(missing[0]) is not None else ""
        return PartStatus(number, part.name, NOT_STARTED, f"{missing[0]} is not defined{cell}")
    left = [n for n in part.names() if n in stubbed]
    if left:
        return PartStatus(number, part.name, NOT_STARTED, f"the cell of {left[0]} still raises NotImplementedError")
    if check["passed"]:
        return PartStatus(number, part.name, DONE)
    steps = [s for s in check["steps"] if not s["passed"]]
    left = [s for s in steps if s.get("kind") == NOT_DONE]  # a stub called, or a name the check reads not defined
    if part_kind(check) == NOT_DONE:
        stub = left[0]["detail"] == NOT_IMPLEMENTED  # which of the two, for the words only
        why = "it still raises NotImplementedError" if stub else f"{left[0]['step']}: {left[0]['detail']}"
        return PartStatus(number, part.name, NOT_STARTED, why)
    hint = check["hint"] or (f"{steps[0]['step']}: {steps[0]['detail']}" if steps else "")
    return PartStatus(number, part.name, FAILING, " ".join(str(hint).split()))


def _required(part) -> list:
    """The notebook names a part cannot be checked without (not its Optional ones)."""
    from .exercises.model import Optional, Together, names_read

    specs = tuple(part.reads) + tuple(spec for _, spec in part.keywords)
    return [
        n
        for spec in specs
        if not isinstance(spec, Optional) and not (isinstance(spec, Together) and not spec.required)
        for n in names_read(spec)
    ]


def _python(source: str) -> str:
    """A cell's source as Python (IPython's magics turned into calls), for the ast module."""
    try:
        from IPython.core.inputtransformer2 import TransformerManager

        return TransformerManager().transform_cell(source)
    except Exception:  # noqa: BLE001 - without IPython, drop the magic and shell lines
        return "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))


def _assigned(source: str) -> tuple:
    """(the names a cell assigns at its top level, whether it holds a top-level ``raise NotImplementedError``)."""
    try:
        tree = ast.parse(_python(source))
    except SyntaxError:
        return set(), False

    def top(nodes):  # statements of the cell itself, not of the functions or classes it defines
        for node in nodes:
            yield node
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                for child in ("body", "orelse", "finalbody", "handlers"):
                    yield from top(getattr(node, child, []) or [])

    statements = list(top(tree.body))
    stub = any(
        isinstance(s, ast.Raise)
        and s.exc is not None
        and "NotImplementedError" in {n.id for n in ast.walk(s.exc) if isinstance(n, ast.Name)}
        for s in statements
    )
    names = set()
    for s in statements:
        if isinstance(s, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(s.name)
        targets = getattr(s, "targets", None) or [getattr(s, "target", None)]
        for target in targets:
            if target is not None:
                names.update(n.id for n in ast.walk(target) if isinstance(n, ast.Name))
    return names, stub


def _read_notebook(name: str, namespace: Mapping, path) -> tuple:
    """(the notebook's cells, where they were read from), or (None, why not)."""
    stem = Path(name).stem
    if path is not None:
        file = Path(path)
        if not file.is_file():
            raise InputError(f"path {str(path)!r} is not a file; give the path of the saved notebook, or leave it out.")
        cells = _cells(file)
        if cells is None:
            raise InputError(f"{file.name} is not a notebook (.ipynb) that can be read.")
        return cells, f"in {file.name} as saved"
    colab = _colab_cells()
    if colab is not None:
        return colab, "in the notebook open in Colab"
    candidates = [namespace.get("__vsc_ipynb_file__"), os.environ.get("JPY_SESSION_NAME"), Path.cwd() / name]
    for candidate in candidates:
        if not candidate or not str(candidate).endswith(".ipynb") or not Path(candidate).is_file():
            continue
        cells = _cells(Path(candidate))
        if cells is not None and any(stem in _text(c) for c in cells if c.get("cell_type") == "code"):
            return cells, f"in {Path(candidate).name} as last saved"
    return None, f"{name} was not found in the working folder; pass path= to the saved notebook"


def _cells(file: Path) -> list | None:
    try:
        cells = json.loads(file.read_text(encoding="utf-8")).get("cells")
    except (OSError, ValueError, AttributeError):
        return None
    return cells if isinstance(cells, list) else None


def _colab_cells() -> list | None:
    """The cells of the notebook open in Colab, as the browser has them (Colab keeps no file on the kernel's disk)."""
    if "google.colab" not in sys.modules:
        return None
    try:
        from google.colab import _message

        found = _message.blocking_request("get_ipynb", request="", timeout_sec=10)
        return found["ipynb"]["cells"]
    except Exception:  # noqa: BLE001 - an older or newer Colab: the answers go unchecked
        return None


def _text(cell: Mapping) -> str:
    source = cell.get("source", "")
    return "".join(source) if isinstance(source, list) else str(source)


def _empty_answers(name: str, cells: list) -> list:
    """The answers in words of the notebook's exercises left empty, as 'exercise N: what it is about'."""
    from .exercises.registry import LAB

    numbers = set(LAB.notebooks()[name])
    empty, section = [], None
    for cell in cells:
        if cell.get("cell_type") != "markdown":
            continue
        text = _text(cell)
        headings = sections(text)
        if headings:
            section = headings[-1]
        meta = (cell.get("metadata") or {}).get("nbgrader") or {}
        declared = LAB.answers.get(str(meta.get("grade_id")))
        is_answer = (meta.get("solution") and meta.get("grade")) or text.strip() == ANSWER_STUB
        if not is_answer or text.strip() not in ("", ANSWER_STUB):
            continue
        if declared is not None and declared[0] in numbers:
            empty.append(f"exercise {declared[0]}: {declared[1]}")
        elif section in numbers:
            empty.append(f"exercise {section}: an answer in words")
    return empty


def _cell_label(cell) -> str:
    number = f"[{cell.number}]" if cell.number is not None else "[ ]"
    lines = cell.source.splitlines()
    if cell.line is not None and 1 <= cell.line <= len(lines) and lines[cell.line - 1].strip():
        line, where = lines[cell.line - 1].strip(), f"line {cell.line}"
    else:
        code = [s.strip() for s in lines if s.strip() and not s.strip().startswith("#")]
        line, where = (code[0] if code else ""), "first line"
    if len(line) > 60:
        line = line[:59] + "…"
    return f"{number} {where}: {line}"


def _error_text(cell) -> str:
    if cell.error == "KeyboardInterrupt" and not cell.message:
        return "KeyboardInterrupt: stopped (it ran longer than the time allowed, or was interrupted)"
    return f"{cell.error}: {cell.message}" if cell.message else cell.error


def _wrapped(text: str, indent: str) -> str:
    return textwrap.fill(text, WIDTH, initial_indent=indent, subsequent_indent=indent)


# --- labkit handin DIR: the notebooks of a folder, each in a fresh kernel ------------------------------------

MARK = "labkit-handin:"
SETUP = '__import__("labkit.notebook", fromlist=["track_cells"]).track_cells()'


def lab_notebook_of(file: Path) -> str | None:
    """Which lab notebook a file is: the one its last cell names, else its own name; None if neither."""
    cells = _cells(Path(file)) or []
    for cell in reversed(cells):
        found = CALL.search(_text(cell)) if cell.get("cell_type") == "code" else None
        if found:
            try:
                return notebook_file(found.group(1))
            except ValueError:
                return None
    try:
        return notebook_file(Path(file).stem)
    except ValueError:
        return None


def run_notebook(file: str | os.PathLike, timeout: int = 300) -> HandIn:
    """Run a saved notebook in a fresh kernel in its own folder, every cell even after one raised, then
    :func:`ready_to_hand_in` in that kernel; the result (with ``problem`` set if it could not run)."""
    import nbformat  # nbclient brings it
    from nbclient import NotebookClient

    file = Path(file)
    name = lab_notebook_of(file)
    if name is None:
        raise InputError(f"{file.name} is not one of the lab's notebooks.")
    nb = nbformat.read(file, as_version=4)
    numbers = _notebook.prompt_numbers(nb.cells)  # the student's numbering, the hand-in cell still in place
    ran = [(i, c) for i, c in enumerate(nb.cells) if not (c.cell_type == "code" and "ready_to_hand_in(" in c.source)]
    nb.cells = [c for _, c in ran]
    client = NotebookClient(
        nb,
        timeout=timeout,
        kernel_name="python3",
        allow_errors=True,
        interrupt_on_timeout=True,
        resources={"metadata": {"path": str(file.parent.resolve())}},
    )
    try:
        with client.setup_kernel(stdout=_devnull(), stderr=_devnull()):
            client.execute_cell(nbformat.v4.new_code_cell(SETUP), 0, store_history=False)
            for index, cell in enumerate(nb.cells):
                if cell.cell_type == "code":
                    client.execute_cell(cell, index)
            final = _final_cell(name, file, _kernel_counts(ran, numbers))
            nb.cells.append(final)
            client.execute_cell(final, len(nb.cells) - 1, store_history=False)
    except Exception as exc:  # noqa: BLE001 - a kernel that died or never started is reported, not raised
        message = " ".join(str(exc).split())[:300]
        return HandIn(name, [], problem=f"{type(exc).__name__}: {message}" if message else type(exc).__name__)
    for output in final.get("outputs", []):
        if output.get("name") == "stdout" and MARK in output.get("text", ""):
            data = json.loads(output["text"].split(MARK, 1)[1].strip().splitlines()[0])
            result = HandIn.from_dict(data)
            result.every_cell_ran = True
            return result
    errors = [
        f"{o.get('ename')}: {o.get('evalue')}" for o in final.get("outputs", []) if o.get("output_type") == "error"
    ]
    return HandIn(name, [], problem=errors[0] if errors else "the notebook's kernel gave no result")


def _kernel_counts(ran: list, numbers: dict) -> dict:
    """{the kernel's count of each (index, cell) that ran: its number in the notebook's order}; the kernel's
    count is one ahead of Jupyter's (the hand-in's own setup ran first), so the table uses the notebook's."""
    return {c.execution_count: numbers[i] for i, c in ran if c.get("execution_count") is not None and i in numbers}


def _final_cell(name: str, file: Path, counts: dict):
    """The cell that renumbers the cells that raised (:func:`_kernel_counts`) and prints the table as data."""
    import nbformat

    return nbformat.v4.new_code_cell(
        f'__import__("labkit.notebook", fromlist=["x"]).CELLS.renumber({counts!r})\n'
        f'print({MARK!r} + __import__("json").dumps(__import__("labkit.handin", fromlist=["x"])'
        f".ready_to_hand_in({name!r}, path={str(file.resolve())!r}).as_dict()))"
    )


def _devnull():
    import subprocess

    return subprocess.DEVNULL
