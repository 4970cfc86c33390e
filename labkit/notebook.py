"""The first line of every lab notebook: ``import labkit; labkit.ready("0.1")``.

If labkit is not installed, that line itself fails, and Jupyter shows it with
its comment, which holds the install command. When labkit is there,
:func:`ready` checks what the notebook needs from the kernel and says how to
fix it when something is missing. In an IPython kernel it also starts noting
the cells that raise (:data:`CELLS`), which the notebook's last cell,
``labkit.ready_to_hand_in(...)``, lists (:mod:`labkit.handin`).
"""

from __future__ import annotations

import importlib.util
import os
import sys
import warnings
from dataclasses import dataclass, replace

from .errors import InputError


class VersionWarning(UserWarning):
    """The kernel's labkit is another version than the one the notebook was written for."""


INSTALL = '%pip install "labkit @ git+https://github.com/labkit-course/labkit"'
HEADLESS = "LABKIT_HEADLESS"  # set to 1 where nothing a notebook shows is seen: the grader's sandbox


def headless() -> bool:
    """Whether nothing this notebook shows is ever seen (``LABKIT_HEADLESS=1``, which the grader's sandbox
    sets): the explorers then build nothing, and the hand-in table is not made."""
    return os.environ.get(HEADLESS) == "1"


NEEDED = ("numpy", "scipy", "matplotlib", "ipywidgets", "anywidget")


def installed_version() -> str:
    """The installed labkit's version (a notebook's and the grader's), "0+unknown" in a tree never installed."""
    from importlib.metadata import PackageNotFoundError, version  # only when asked, not on import

    try:
        return version("labkit")
    except PackageNotFoundError:
        return "0+unknown"


def ready(written_for: str) -> None:
    """Check that this kernel can run a notebook written for labkit `written_for` (``"major.minor"``).

    Warns (:class:`VersionWarning`), saying how to fix it, when the installed
    labkit is another major.minor version than the notebook's: the notebook
    goes on, and most of it will likely work (a course's grader may run a newer
    labkit than the notebook was handed out with). Raises ValueError when a
    package the notebooks use cannot be imported. Returns None.

    >>> ready("0.1")
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     ready("9.0")
    >>> print(caught[0].message)  # doctest: +ELLIPSIS
    this notebook was written for labkit 9.0, but the kernel has labkit 0.1...
    """
    wanted = str(written_for).strip()
    parts = wanted.split(".")
    if len(parts) != 2 or not all(part.isdigit() for part in parts):
        raise InputError(
            f'give the labkit version the notebook was written for as "major.minor", e.g. "0.1"; got {written_for!r}.'
        )
    have = installed_version()
    if have != "0+unknown" and have.split(".")[:2] != parts:
        warnings.warn(
            f"this notebook was written for labkit {wanted}, but the kernel has labkit {have}: if something "
            f"fails, install the matching version in a cell,\n    {INSTALL}\nthen restart the kernel "
            "(Kernel > Restart) and run the notebook again.",
            VersionWarning,
            stacklevel=2,
        )
    track_cells()
    missing = [name for name in NEEDED if importlib.util.find_spec(name) is None]
    if missing:
        raise InputError(
            f"the kernel lacks {', '.join(missing)}, which the notebooks use: install labkit with "
            f"its dependencies in a cell,\n    {INSTALL}\nthen restart the kernel."
        )


@dataclass(frozen=True)
class RaisedCell:
    """A cell whose last run raised: its number as Jupyter shows it (``[n]``), its source and the error."""

    number: int | None
    source: str
    error: str  # the exception's type
    message: str  # the first line of its message
    line: int | None  # the line of the cell where it was raised, when known


class CellErrors:
    """IPython's ``post_run_cell`` hook: the cells whose last run raised, since the kernel started.

    A cell is known by the id the front end sends with it (JupyterLab, Notebook 7 and VS Code send
    one), so a cell that raised and then ran cleanly is dropped; without an id, by its source.
    Only text is kept, never the exception (whose traceback holds the cell's variables).
    """

    def __init__(self):
        self.raised = {}
        self.ran: set = set()  # the ids (or, without one, the sources) of every cell run since the kernel started

    def __call__(self, result=None) -> None:
        try:  # a hook that raises would print its traceback under every cell
            self._note(result)
        except Exception:  # noqa: BLE001 - the notebook goes on without this cell noted
            pass

    def _note(self, result) -> None:
        info = getattr(result, "info", None)
        source = str(getattr(info, "raw_cell", "") or "")
        key = getattr(info, "cell_id", None) or ("source", source)
        self.ran.add(key)
        error = getattr(result, "error_before_exec", None) or getattr(result, "error_in_exec", None)
        if error is None:
            self.raised.pop(key, None)
            return
        self.raised.pop(key, None)  # re-inserted last: the order is the order of the runs
        self.raised[key] = RaisedCell(
            getattr(result, "execution_count", None),
            source,
            type(error).__name__,
            _first_line(error),
            _line_in_cell(error),
        )

    def never_ran(self, cells) -> list:
        """The numbers (:func:`prompt_numbers`) of the code cells of saved notebook `cells` that never ran in this
        kernel (a cell is known by its id, or by its source where the front end sent no id)."""
        sources = {key[1] for key in self.ran if isinstance(key, tuple)}
        left = []
        for index, number in prompt_numbers(cells).items():
            source = cells[index].get("source", "")
            source = "".join(source) if isinstance(source, list) else str(source)
            if cells[index].get("id") not in self.ran and source not in sources:
                left.append(number)
        return left

    def renumber(self, numbers: dict) -> None:
        """Give each noted cell the number `numbers` maps its number to ({kernel's count: ``[n]``}), e.g. the
        :func:`prompt_numbers` of the cells ``labkit handin`` ran in a kernel whose count had moved on."""
        for key, cell in self.raised.items():
            if cell.number in numbers:
                self.raised[key] = replace(cell, number=int(numbers[cell.number]))

    def cells(self) -> list:
        """The cells that raised, in the order of their numbers (then of their runs)."""
        found = list(self.raised.values())
        return sorted(found, key=lambda cell: (cell.number is None, cell.number or 0))


def prompt_numbers(cells) -> dict:
    """{index in `cells`: the number Jupyter shows beside that code cell after Restart and Run All, ``[n]``}.

    The one numbering labkit names cells by (``labkit handin``, the notebook's hand-in table, the grader's
    feedback): code cells counted from 1 in the notebook's order, leaving out blank ones, which JupyterLab,
    VS Code and nbclient do not run. `cells` are a notebook's cells (dicts or nbformat cells), or the
    sources of its code cells only (strings).

    >>> prompt_numbers([{"cell_type": "markdown", "source": "# A"}, {"cell_type": "code", "source": "x = 1"},
    ...                 {"cell_type": "code", "source": ["  \\n"]}, "y = 2"])
    {1: 1, 3: 2}
    """
    numbers, count = {}, 0
    for index, cell in enumerate(cells):
        if isinstance(cell, str):
            cell = {"cell_type": "code", "source": cell}
        source = cell.get("source", "")
        source = "".join(source) if isinstance(source, list) else str(source)
        if cell.get("cell_type") == "code" and source.strip():
            count += 1
            numbers[index] = count
    return numbers


CELLS: CellErrors | None = None  # set by track_cells() in an IPython kernel


def track_cells() -> bool:
    """Start noting the cells that raise (once per kernel); False when not in IPython."""
    global CELLS
    ipython = sys.modules.get("IPython")  # never imported here: a notebook's kernel has it already
    shell = ipython.get_ipython() if ipython is not None else None
    if shell is None:
        return False
    if CELLS is None or CELLS not in shell.events.callbacks.get("post_run_cell", []):
        CELLS = CELLS or CellErrors()
        shell.events.register("post_run_cell", CELLS)
    return True


def _first_line(error) -> str:
    try:
        text = str(error)
    except Exception:  # noqa: BLE001 - a student's exception class may break str()
        return ""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[0][:200] if lines else ""


def _line_in_cell(error) -> int | None:
    """The line of the cell itself (its module level) where `error` was raised."""
    if isinstance(error, SyntaxError):
        return error.lineno
    tb = getattr(error, "__traceback__", None)
    while tb is not None:  # the cell's own frame is the first module-level one (an import's come later)
        if tb.tb_frame.f_code.co_name == "<module>":
            return tb.tb_lineno
        tb = tb.tb_next
    return None
