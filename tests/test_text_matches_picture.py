"""What the notebooks and docs/students.md say about a picture, a control or a call is what the code does:
the colours they name, the patch editor's starting corners and handle colours, the equations they cite, and
every ``plots.<name>(...)`` call they write (it binds to the function, and students.md's is the notebook's)."""

import ast
import inspect
import re
from pathlib import Path

import nbformat
import numpy as np
import pytest

from labkit import mesh, plots
from labkit.plots.editor import FIRST_PATCH

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
STUDENTS = (ROOT / "docs" / "students.md").read_text(encoding="utf-8")
EDITOR_JS = (ROOT / "labkit" / "plots" / "editor.js").read_text(encoding="utf-8")
CALL = re.compile(r"`(plots\.\w+\([^`]*\))`")
NAMED = {"#111": "black", "#d62728": "red", "#6a3d9a": "purple"}  # editor.js's handle colours, as the text names them


def _cells(kind):
    return {p.name: [c.source for c in nbformat.read(p, as_version=4).cells if c.cell_type == kind] for p in NOTEBOOKS}


MARKDOWN, CODE = _cells("markdown"), _cells("code")
TEXTS = {"docs/students.md": STUDENTS} | {name: "\n".join(cells) for name, cells in MARKDOWN.items()}


def _sentences(text, word):
    return [s for s in re.split(r"(?<=[.!?])\s+", " ".join(text.split())) if word in s]


def test_the_mesh_colours_named_are_the_ones_drawn():
    assert mesh.QUALITY_CMAP == "cividis" and mesh.FOLDED_STYLE["hatch"] and mesh.FOLDED_STYLE["edgecolor"] == "white"
    for where, text in TEXTS.items():
        for sentence in _sentences(text, "folded()") + _sentences(text, "coloured by quality"):
            assert not re.search(r"\b(red|green)\s+elements?\b", sentence), (where, sentence)
        for sentence in _sentences(text, "`mesh.folded()` reports"):
            assert "hatched" in sentence, (where, sentence)
    (explore,) = [s for s in MARKDOWN["03_meshes.ipynb"] if "mesh.folded()" in s]
    assert "cividis" in explore and "dark blue" in explore and "yellow" in explore


def test_the_editors_handles_are_the_colours_the_text_names():
    colours = re.search(r"const COLORS = \[([^\]]*)\]", EDITOR_JS).group(1)
    corner, ds, dt = (NAMED[c.strip().strip('"')] for c in colours.split(","))
    (editor,) = [s for s in MARKDOWN["03_meshes.ipynb"] if "Shape a patch by hand" in s]
    said = " ".join(editor.split())
    for colour, what in [(corner, "move a corner"), (ds, r"\partial/\partial s"), (dt, r"\partial/\partial t")]:
        assert re.search(rf"a {colour} dot to (change (that corner's|its) )?\$?{re.escape(what)}", said), (colour, what)
    docs = " ".join(STUDENTS.split())
    assert f"the four corners ({corner})" in docs and f"∂/∂s arrow ({ds})" in docs and f"∂/∂t arrow ({dt})" in docs


def test_the_editor_starts_from_the_corners_the_text_gives():
    (editor,) = [s for s in MARKDOWN["03_meshes.ipynb"] if "Shape a patch by hand" in s]
    said = re.findall(r"([ABCD]) \$\((-?[\d.]+), (-?[\d.]+)\)\$", editor)
    assert [name for name, _, _ in said] == list("ABCD")
    np.testing.assert_allclose([[float(x), float(y)] for _, x, y in said], [c.point for c in FIRST_PATCH])
    assert "unit square of Exercise 5." not in editor.split("starts from")[1].split(";")[0]
    assert "plots.patch_editor()" in [s.strip() for cell in CODE["03_meshes.ipynb"] for s in cell.splitlines()]


@pytest.mark.parametrize("where", sorted(TEXTS))
def test_every_plots_call_written_binds_to_its_function(where):
    for call in CALL.findall(TEXTS[where]):
        node = ast.parse(call, mode="eval").body
        function = getattr(plots, node.func.attr)
        args = [object() for _ in node.args]  # placeholders: only the call's shape is checked
        inspect.signature(function).bind(*args, **{k.arg: object() for k in node.keywords})


def test_the_docs_call_each_explorer_as_the_notebooks_do():
    code = {line.strip() for cells in CODE.values() for cell in cells for line in cell.splitlines()}
    called = {re.match(r"plots\.(\w+)\(", line).group(1): line for line in code if re.match(r"plots\.\w+\(", line)}
    for call in CALL.findall(STUDENTS):
        name = re.match(r"plots\.(\w+)", call).group(1)
        if name in called and "[A, B, C, D]" not in call:  # a call of the docs' own (corners of yours) is bound above
            assert call == called[name], (call, called[name])


def test_every_equation_cited_is_shown_in_the_same_notebook():
    for name, cells in MARKDOWN.items():
        text = "\n".join(cells)
        for number in re.findall(r"equation \((\d+)\)", text):
            assert rf"\tag{{{number}}}" in text, f"{name} cites equation ({number}) but shows no \\tag{{{number}}}"


def test_a_corner_is_shown_being_built_before_exercise_5_asks_for_one():
    cells = MARKDOWN["03_meshes.ipynb"]
    (first,) = [i for i, s in enumerate(cells) if "## Exercise 5" in s]
    example = re.search(r"`(Corner\(\[[^`]*\))`", cells[first].split("## Exercise 5")[1])  # with numbers
    assert example, "no Corner(...) example in Exercise 5's text"
    from labkit import Corner

    corner = eval(example.group(1), {"Corner": Corner})  # the example runs, as written
    assert corner.point.size == 2 and not np.array_equal(corner.ds, [1, 0])  # and gives no answer away
