"""Explore first: a fresh student copy runs top to bottom (Run All) to its explorers before a line is written.

Every notebook of the release is executed as shipped, in a fresh kernel, with nbclient's defaults (an error
in a cell stops the run, as Run All stops in JupyterLab) except where a cell is tagged ``raises-exception``.
The run must reach every explorer and leave its picture; the cells that raise are exactly the tagged ones,
and they still show their error, while the self-checks print what fails. Each explorer opens on the
method its notebook teaches, after a prompt asking the student to predict before moving a control.
"""

import re
import shutil
from pathlib import Path

import nbformat
import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from labkit.execute import RAISES

nbclient = pytest.importorskip("nbclient")

ROOT = Path(__file__).resolve().parents[2]
STUDENT = sorted((ROOT / "labkit" / "student_notebooks").glob("*.ipynb"))
EXPLORE = re.compile(r"plots\.(\w+_explorer|patch_editor)\(")
PROMPT = "**Predict, then explore.**"
SELF_CHECK = re.compile(r"^labkit\.check\.\w+\(.*\)$")  # a self-check whose report is the cell's value


@pytest.fixture(scope="module")
def fresh_runs(tmp_path_factory):
    """Each release notebook executed as a student's fresh copy: in a folder of its own, errors stopping it."""
    folder = tmp_path_factory.mktemp("fresh")
    runs = {}
    for path in STUDENT:
        shutil.copy(path, folder / path.name)
        nb = nbformat.read(folder / path.name, as_version=4)
        client = nbclient.NotebookClient(
            nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(folder)}}
        )
        client.execute()  # CellExecutionError (the test fails) at the first error in an untagged cell
        runs[path.stem] = nb
    return runs


def _tagged(cell):
    return RAISES in cell.metadata.get("tags", [])


def _errors(cell):
    return [o for o in cell.get("outputs", []) if o.output_type == "error"]


def _text(cell):
    return "".join(o.get("text", "") + o.get("data", {}).get("text/plain", "") for o in cell.outputs)


@pytest.mark.parametrize("path", STUDENT, ids=lambda p: p.stem)
def test_run_all_reaches_every_explorer_of_a_fresh_copy(fresh_runs, path):
    nb = fresh_runs[path.stem]
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1)), "Run All stopped early"
    explorers = [c for c in code if EXPLORE.search(c.source)]
    assert explorers
    for cell in explorers:
        assert not _errors(cell) and not _tagged(cell), cell.source
        data = [o.get("data", {}) for o in cell.outputs]
        assert any("application/vnd.jupyter.widget-view+json" in d or "image/png" in d for d in data), cell.source


@pytest.mark.parametrize("path", STUDENT, ids=lambda p: p.stem)
def test_the_failures_on_the_way_are_still_shown(fresh_runs, path):
    nb = fresh_runs[path.stem]
    code = [c for c in nb.cells if c.cell_type == "code"]
    raised = [c for c in code if _errors(c)]
    # the cells tagged are exactly those that raise: none hides an error it does not have
    assert [c.source for c in raised] == [c.source for c in code if _tagged(c)]
    stubs = [c for c in raised if "raise NotImplementedError()" in c.source]
    assert stubs and any(_errors(c)[0].ename == "NotImplementedError" for c in stubs)
    for cell in raised:  # a traceback the student can read: what is missing, or which name is not defined yet
        assert _errors(cell)[0].ename in ("NotImplementedError", "NameError"), (cell.source[:80], _errors(cell))
    checks = [c for c in code if SELF_CHECK.match(c.source.strip().splitlines()[-1]) and not _tagged(c)]
    # in 01 and 03 every self-check shares its cell with a stub, whose NotImplementedError is shown instead
    assert checks or path.stem in ("01_limacon", "03_meshes")
    for cell in checks:  # a self-check of a stub says plainly that it fails, and does not stop the notebook
        assert "FAILED" in _text(cell), (cell.source, _text(cell)[:300])


def _controls(function):
    """The labels of the controls an explorer shows (its sliders, dropdowns and checkboxes)."""
    from labkit import plots

    if function == "patch_editor":
        return ["black dot", "red dot", "purple dot"]  # the editor's handles, as its own text names them
    return [control.description for control in getattr(plots, function)().controls.values()]


@pytest.mark.parametrize("path", STUDENT, ids=lambda p: p.stem)
def test_each_explorer_follows_a_prompt_to_predict_first(path, monkeypatch):
    monkeypatch.delenv("LABKIT_HEADLESS", raising=False)
    cells = nbformat.read(path, as_version=4).cells
    found = [(k, m.group(1)) for k, c in enumerate(cells) if c.cell_type == "code" and (m := EXPLORE.search(c.source))]
    assert found
    for index, function in found:
        prompt = cells[index - 1]
        assert prompt.cell_type == "markdown" and prompt.source.startswith(PROMPT), (path.name, function)
        text = prompt.source.lower()
        assert "write down" in text and "then" in text
        assert any(label.lower() in text for label in _controls(function)), (function, prompt.source)
        # a question, never its answer: no formula, no order, no rate
        assert "$" not in prompt.source and not re.search(r"\border\b|\brate\b|h\^|O\(", prompt.source)


def runge(x):
    return 1 / (1 + x**2), -2 * x / (1 + x**2) ** 2


def _largest(text, method):
    found = re.search(rf"{method} with (\d+) points: largest (\S+) at x = (\S+?)(?:;|$)", text)
    assert found, text
    return int(found[1]), float(found[2]), float(found[3])


def test_the_convergence_explorer_opens_on_the_hermite_cubic_of_02(monkeypatch):
    """02 teaches piecewise cubic Hermite interpolation: the first curve is its error, as scipy computes it."""
    monkeypatch.delenv("LABKIT_HEADLESS", raising=False)
    from labkit import plots

    title = nbformat.read(STUDENT[1], as_version=4).cells[0].source.splitlines()[0]
    assert "Hermite" in title
    explorer = plots.convergence_explorer()
    ndata, largest, at = _largest(explorer.description, "piecewise hermite cubic")
    x, xdata = np.linspace(0, 5, 1001), np.linspace(0, 5, ndata)
    hermite = np.abs(CubicHermiteSpline(xdata, *runge(xdata))(x) - runge(x)[0])
    natural = np.abs(CubicSpline(xdata, runge(xdata)[0], bc_type="natural")(x) - runge(x)[0])
    assert largest == pytest.approx(hermite.max(), rel=0.06) and at == pytest.approx(x[hermite.argmax()], abs=0.01)
    assert abs(largest - natural.max()) > 0.5 * natural.max()  # not the natural spline's error (it opened there)


TAUGHT = {  # notebook -> what its explorer's first picture shows (its alt text), the method its title names
    "01_limacon": ("hermite cubic", "limaçon"),
    "03_meshes": ("coons patch", "coons patch"),
    "04_splines": ("complete cubic spline", "complete"),
    "05_monotone": ("pchip", "pchip"),
    "06_bilinear": ("bilinear interpolation", "bilinear"),
}


@pytest.mark.parametrize("stem", sorted(TAUGHT))
def test_every_other_explorer_opens_on_its_notebooks_method(stem, monkeypatch):
    monkeypatch.delenv("LABKIT_HEADLESS", raising=False)
    from labkit import plots

    path = next(p for p in STUDENT if p.stem == stem)
    cells = nbformat.read(path, as_version=4).cells
    shown, named = TAUGHT[stem]
    assert named in cells[0].source.splitlines()[0].lower()
    (function,) = {m.group(1) for c in cells if (m := EXPLORE.search(c.source)) and "explorer" in m.group(1)}
    explorer = getattr(plots, function)() if function != "pchip_explorer" else plots.pchip_explorer()
    assert shown in explorer.description.lower(), explorer.description
    if stem == "01_limacon":  # the lab's method, not the linear one it is compared with
        assert explorer.values()["method"] == "pherm"
    if stem == "04_splines":  # all three splines the notebook teaches are shown
        assert all(explorer.values()[m] for m in ("complete", "natural", "notaknot"))
        assert all(f"{m} cubic spline" in explorer.description for m in ("complete", "natural", "not-a-knot"))
