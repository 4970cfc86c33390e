"""Re-execute the kit's notebooks and save them clean (the committed reference outputs).

Clean means: executed top to bottom in a fresh ``python3`` kernel, no widget
state stored in the metadata (it churns on every run), no error outputs.
Used by ``labkit execute`` and checked by tests/test_notebooks_clean.py.

A cell tagged ``raises-exception`` (:data:`RAISES`) lets Run All go on past its error in JupyterLab,
nbclient and nbval. ``labkit execute`` tags the cells that raise in the student's fresh copy (its
stubs, and what uses their names), found with :func:`raising_cells`; the instructor's own run
ignores the tag, so an error there still stops it.
"""

import subprocess
from pathlib import Path

from .errors import InputError

KERNEL = "python3"
RAISES = "raises-exception"
KERNELSPEC = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": KERNEL}


def notebook_paths(directory):
    """The notebooks of a folder, in teaching order, skipping checkpoint copies."""
    paths = sorted(Path(directory).glob("*.ipynb"))
    if not paths:
        raise InputError(f"no notebooks (*.ipynb) in {directory}.")
    return paths


def read_notebook(path):
    """A notebook file as an nbformat v4 object; ValueError if it is not text or not a notebook."""
    import nbformat  # the [grade] extra; imported here so that `import labkit` stays light

    try:
        text = Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{Path(path).name} is not a text file, so not a notebook.") from None
    try:
        return nbformat.reads(text, as_version=4)
    except Exception as exc:  # noqa: BLE001 - nbformat raises several kinds for broken files
        raise InputError(
            f"{Path(path).name} is not a valid notebook ({type(exc).__name__}: {str(exc)[:200]})."
        ) from None


def execute(path, timeout=300, before_save=None):
    """Run one notebook in a fresh kernel in its own folder and save it cleaned.

    `before_save(nb, name)` may add to the notebook before it is written (``labkit
    execute`` gives the cells nbgrader's metadata)."""
    import nbformat
    from nbclient import NotebookClient

    path = Path(path)
    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:
        set_tag(cell, RAISES, False)  # the instructor's notebook runs without an error anywhere
    client = NotebookClient(nb, timeout=timeout, kernel_name=KERNEL, resources={"metadata": {"path": str(path.parent)}})
    client.execute(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # kernel log noise only
    clean(nb)
    if before_save is not None:
        before_save(nb, path.name)
    nbformat.write(nb, path)
    return nb


def clean(nb):
    """Drop widget state and volatile metadata; pin the kernelspec."""
    nb.metadata.pop("widgets", None)
    nb.metadata["kernelspec"] = dict(KERNELSPEC)
    for cell in nb.cells:
        cell.metadata.pop("execution", None)
        if cell.cell_type == "code":
            for output in cell.get("outputs", []):
                data = output.get("data", {})
                data.pop("application/vnd.jupyter.widget-view+json", None)
    return nb


def set_tag(cell, tag, on):
    """Add (`on`) or remove the tag `tag` of a cell, in place; an emptied tag list is dropped."""
    tags = [t for t in cell.metadata.get("tags", []) if t != tag] + ([tag] if on else [])
    if tags:
        cell.metadata["tags"] = tags
    else:
        cell.metadata.pop("tags", None)


def raising_cells(nb, folder, timeout=300):
    """The indices of the code cells of `nb` that end in an error when it runs top to bottom in `folder`.

    Runs a copy in a fresh kernel, errors allowed; `nb` itself is left as it is."""
    import copy

    from nbclient import NotebookClient

    run = copy.deepcopy(nb)
    client = NotebookClient(
        run, timeout=timeout, kernel_name=KERNEL, allow_errors=True, resources={"metadata": {"path": str(folder)}}
    )
    client.execute(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return [
        index
        for index, cell in enumerate(run.cells)
        if cell.cell_type == "code" and any(output.output_type == "error" for output in cell.outputs)
    ]
