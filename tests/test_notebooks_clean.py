"""The committed notebooks are the reference outputs: they must be clean."""

import re
from pathlib import Path

import nbformat
import pytest
from docs_markdown import exercise_table

from labkit.exercises.model import sections
from labkit.exercises.registry import LAB

pytestmark = pytest.mark.slow  # executes notebooks

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))
EXERCISES = [1, *LAB.exercises]  # exercise 1 (copying code) has a section but is not graded
EXPLORE = re.compile(r"plots\.(\w+_explorer|patch_editor)\(")


def test_there_is_a_notebook_per_topic():
    assert len(NOTEBOOKS) >= 6


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_is_clean(path):
    nb = nbformat.read(path, as_version=4)
    assert nb.metadata["kernelspec"]["name"] == "python3"
    assert "widgets" not in nb.metadata, "widget state stored: run `labkit execute`"
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1)), "not executed top to bottom"
    for cell in code:
        assert not any(o.output_type == "error" for o in cell.outputs), cell.source[:60]
        if EXPLORE.search(cell.source):
            # widgets differ between a kernel with a front end and nbval: outputs not compared;
            # without widgets (GitHub, nbviewer, nbconvert) the saved output is still a picture
            assert "nbval-ignore-output" in cell.metadata.get("tags", [])
            assert any("image/png" in o.get("data", {}) for o in cell.outputs), cell.source
        for output in cell.outputs:
            assert "interactive(" not in str(output.get("data", {}).get("text/plain", "")), cell.source


def test_every_notebook_ends_with_an_explorer():
    for path in NOTEBOOKS:
        sources = [c.source for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code"]
        assert any(EXPLORE.search(s) for s in sources), path.name


def test_no_checkpoint_folders_are_committed():
    root = Path(__file__).resolve().parents[1] / "notebooks"
    import subprocess

    tracked = subprocess.run(["git", "ls-files", str(root)], capture_output=True, text=True, cwd=root).stdout
    assert ".ipynb_checkpoints" not in tracked


def test_every_exercise_has_a_section_and_the_docs_map_it():
    headings = {}
    for path in NOTEBOOKS:
        for cell in nbformat.read(path, as_version=4).cells:
            if cell.cell_type == "markdown":
                for number in sections(cell.source):
                    headings.setdefault(number, path.name)
    assert set(headings) == set(EXERCISES)
    # docs/students.md's exercise table names, for each exercise, the notebook that holds its section
    documented = {int(row["exercise"]): row["notebook"] for row in exercise_table()}
    assert documented == headings
    # sections appear in order within each notebook
    for path in NOTEBOOKS:
        numbers = [
            number
            for cell in nbformat.read(path, as_version=4).cells
            if cell.cell_type == "markdown"
            for number in sections(cell.source)
        ]
        assert numbers == sorted(numbers), path.name


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_nbgrader_metadata_is_kept_and_valid(path):
    """`labkit execute` writes nbgrader's cell metadata (schema version 3); nbgrader's own validator accepts it."""
    import copy

    from labkit.grading.authoring.release import mark

    nb = nbformat.read(path, as_version=4)
    expected = mark(copy.deepcopy(nb), path.name)
    for cell, want in zip(nb.cells, expected.cells):
        assert cell.metadata.get("nbgrader") == want.metadata["nbgrader"], cell.source[:60]
        meta = cell.metadata["nbgrader"]
        assert meta["solution"] == ("### BEGIN SOLUTION" in cell.source)
        answer_in_words = cell.cell_type == "markdown" and meta["solution"]  # manually graded, 0 points
        assert meta["grade"] == ("### BEGIN HIDDEN TESTS" in cell.source or answer_in_words)
        assert meta["locked"] == (not meta["solution"])
    validator = pytest.importorskip("nbgrader.nbgraderformat").MetadataValidator()
    validator.validate_nb(nb)


def test_nbgrader_points_per_exercise_are_labkits():
    from labkit.check import EXERCISES

    points = {}
    for path in NOTEBOOKS:
        for cell in nbformat.read(path, as_version=4).cells:
            meta = cell.metadata["nbgrader"]
            if meta["grade"] and cell.cell_type == "code":
                number = int(re.search(r"# tests for exercise (\d+)", cell.source).group(1))
                points[number] = points.get(number, 0) + meta["points"]
    assert points == {n: e.points for n, e in EXERCISES.items()}


def test_the_first_code_cell_says_how_to_install_labkit():
    """The install guard is one line that calls labkit; without labkit, its failing line shows the install command."""
    import linecache
    import traceback

    for path in NOTEBOOKS:
        first = next(c for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code")
        guard = [line for line in first.source.splitlines() if "labkit" in line and not line.startswith("from labkit")]
        assert len(guard) == 1 and guard[0].startswith('import labkit; labkit.ready("'), (path.name, guard)
        source = "\n".join(line for line in first.source.splitlines() if not line.startswith("%"))
        source = source.replace("import labkit;", "import labkit_is_not_here_at_all as labkit;", 1)
        filename = f"<{path.name}>"
        linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)  # as IPython keeps cells
        with pytest.raises(ModuleNotFoundError) as missing:
            exec(compile(source, filename, "exec"), {})
        shown = "".join(traceback.format_exception(missing.value))
        assert '%pip install "labkit @ git+https://' in shown, shown
