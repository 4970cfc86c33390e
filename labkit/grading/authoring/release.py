"""The student version of the instructor notebooks.

Code between ``### BEGIN SOLUTION`` / ``### END SOLUTION`` becomes a stub
that raises ``NotImplementedError``; in a markdown cell the same region is
an answer in words (a remark, an explanation) and becomes ``YOUR ANSWER
HERE``, for the student to write and the instructor to read. Hidden tests
between ``### BEGIN HIDDEN TESTS`` / ``### END HIDDEN TESTS`` disappear,
outputs are cleared. The markers and the stubs are nbgrader's.

The cells that raise in the release (the stubs, and the cells that use what the stubs
leave undefined) carry the tag ``raises-exception``, which :func:`tag_raising`
gives the instructor notebook (``labkit execute`` calls it): Run All then goes on to
the Explore section of a notebook nobody has written in yet, the self-checks saying
what fails on the way, and nbgrader's release (which keeps tags) does the same.
"""

import json
from pathlib import Path

from ...execute import RAISES, notebook_paths, raising_cells, read_notebook, set_tag

BEGIN_SOLUTION, END_SOLUTION = "### BEGIN SOLUTION", "### END SOLUTION"
BEGIN_HIDDEN, END_HIDDEN = "### BEGIN HIDDEN TESTS", "### END HIDDEN TESTS"
STUB = ["# YOUR CODE HERE", "raise NotImplementedError()"]
TEXT_STUB = ["YOUR ANSWER HERE"]


def strip_solutions(source, where="cell", stub=STUB):
    """Replace solution regions by stubs and drop hidden-test regions in one cell's source."""
    lines, out, region = source.split("\n"), [], None
    for number, line in enumerate(lines, start=1):
        marker = line.strip()
        if marker in (BEGIN_SOLUTION, BEGIN_HIDDEN):
            if region:
                raise ValueError(f"{where}, line {number}: {marker!r} inside an open {region!r} region.")
            region = marker
            if marker == BEGIN_SOLUTION:
                indent = line[: len(line) - len(line.lstrip())]
                out.extend(indent + line for line in stub)
        elif marker in (END_SOLUTION, END_HIDDEN):
            expected = BEGIN_SOLUTION if marker == END_SOLUTION else BEGIN_HIDDEN
            if region != expected:
                raise ValueError(f"{where}, line {number}: {marker!r} without a matching {expected!r}.")
            region = None
        elif region is None:
            out.append(line)
    if region:
        raise ValueError(f"{where}: the {region!r} region is never closed.")
    return "\n".join(out)


def release_notebook(nb, name="notebook"):
    """The student version of an instructor notebook (a new object)."""
    import nbformat  # the [grade] extra

    student = nbformat.from_dict(json.loads(json.dumps(nb)))
    student.metadata.pop("widgets", None)
    for index, cell in enumerate(student.cells):
        if cell.cell_type == "code":
            cell.source = strip_solutions(cell.source, f"{name}, cell {index}")
            cell.outputs = []
            cell.execution_count = None
        elif cell.cell_type == "markdown" and BEGIN_SOLUTION in cell.source:
            cell.source = strip_solutions(cell.source, f"{name}, cell {index}", TEXT_STUB)
    return student


def tag_raising(nb, folder, name="notebook", timeout=300):
    """Tag ``raises-exception`` the cells of instructor notebook `nb` that raise in its release, in place.

    The release is run in `folder` (the notebook's own, for its data files); a cell that no longer
    raises loses the tag. Returns the indices of the tagged cells."""
    raising = set(raising_cells(release_notebook(nb, name), folder, timeout))
    for index, cell in enumerate(nb.cells):
        if cell.cell_type == "code":
            set_tag(cell, RAISES, index in raising)
    return sorted(raising)


def release(notebook_dir, out_dir):
    """Write the student version of every notebook of `notebook_dir` into `out_dir`."""
    import nbformat

    paths = notebook_paths(notebook_dir)
    out = Path(out_dir)
    if out.resolve() == Path(notebook_dir).resolve():
        raise ValueError("--out must differ from the notebook folder; the release would overwrite the solutions.")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in paths:
        student = release_notebook(read_notebook(path), path.name)
        target = out / path.name
        nbformat.write(student, target)
        written.append(target)
    return written
