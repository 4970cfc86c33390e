"""One cell numbering wherever labkit names a cell: the [n] Jupyter shows beside it after Restart and Run All.

`labkit handin` and the grader's feedback name the cells that raised; both are compared here with the
numbers a real kernel gives the same notebook run top to bottom by nbclient (as JupyterLab's Run All runs
it: blank cells are not run and get no number), on a student notebook with blank code cells put in.
"""

import json
import re

import nbformat
import pytest
from nbclient import NotebookClient

from labkit.grading.submission.scoring import _run_problems
from labkit.handin import run_notebook
from labkit.notebook import prompt_numbers
from labkit.student_notebooks import paths

pytestmark = pytest.mark.slow  # executes a notebook

RELEASED = {p.name: p for p in paths()}


def _with_blank_cells(tmp_path):
    """01_limacon as released, with a blank code cell before its first stub and another further down."""
    nb = nbformat.reads(RELEASED["01_limacon.ipynb"].read_text(encoding="utf-8"), as_version=4)
    nb.cells.insert(2, nbformat.v4.new_code_cell("  \n"))
    nb.cells.insert(6, nbformat.v4.new_code_cell(""))
    file = tmp_path / "01_limacon.ipynb"
    nbformat.write(nb, file)
    return file


def _jupyters_numbers(file):
    """{cell's source: its execution count} of the cells that raised, run top to bottom in a fresh kernel."""
    nb = nbformat.read(file, as_version=4)
    NotebookClient(nb, timeout=300, kernel_name="python3", allow_errors=True).execute(cwd=str(file.parent))
    raised = [c for c in nb.cells if c.cell_type == "code" and any(o.output_type == "error" for o in c.outputs)]
    counted = [c.execution_count for c in nb.cells if c.cell_type == "code" and c.execution_count]
    assert counted == list(range(1, len(counted) + 1))  # nothing skipped, nothing counted twice
    return nb, {c.source: c.execution_count for c in raised}


def test_the_numbering_is_jupyters_after_run_all(tmp_path):
    nb, raised = _jupyters_numbers(_with_blank_cells(tmp_path))
    numbers = prompt_numbers(nb.cells)
    assert {i: c.execution_count for i, c in enumerate(nb.cells) if c.get("execution_count")} == numbers
    assert len(raised) >= 3


def test_labkit_handin_names_the_cells_as_jupyter_numbers_them(tmp_path):
    file = _with_blank_cells(tmp_path)
    _, expected = _jupyters_numbers(file)
    result = run_notebook(file)
    assert {cell.source: cell.number for cell in result.raised} == expected
    stubs = sorted(c.number for c in result.raised if c.error == "NotImplementedError")
    assert stubs and f"NotImplementedError (work still to do): {', '.join(f'[{n}]' for n in stubs)}" in result.text()


def test_the_graders_feedback_names_the_cells_as_jupyter_numbers_them():
    code = ["import labkit", "", "x = 1", "   ", "raise ValueError('no')"]
    ran = {"errors": [{"cell": 4, "kind": "ValueError", "message": "no"}, {"cell": 2, "kind": "Timeout"}]}
    text = str(_run_problems("a.ipynb", ran, code)[0])
    assert "cell 3 raised ValueError: no" in text and "cell 2 raised Timeout" in text
    assert prompt_numbers(code) == {0: 1, 2: 2, 4: 3}


@pytest.mark.parametrize("name", sorted(RELEASED))
def test_every_released_code_cell_has_a_number(name):
    cells = json.loads(RELEASED[name].read_text(encoding="utf-8"))["cells"]
    code = [i for i, c in enumerate(cells) if c["cell_type"] == "code"]
    assert list(prompt_numbers(cells)) == code and re.match(r"\d\d_", name)
