"""The first line of every lab notebook: ``import labkit; labkit.ready("0.1")``.

If labkit is not installed, that line itself fails, and Jupyter shows it with
its comment, which holds the install command. When labkit is there,
:func:`ready` checks what the notebook needs from the kernel and says how to
fix it when something is missing.
"""

from __future__ import annotations

import importlib.util
import warnings


class VersionWarning(UserWarning):
    """The kernel's labkit is another version than the one the notebook was written for."""


INSTALL = '%pip install "labkit @ git+https://github.com/labkit-course/labkit"'
NEEDED = ("numpy", "scipy", "matplotlib", "ipywidgets", "anywidget")


def _installed_version() -> str:
    from importlib.metadata import PackageNotFoundError, version  # only when a notebook starts

    try:
        return version("labkit")
    except PackageNotFoundError:  # run from a source tree that was never installed
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
        raise ValueError(
            f'give the labkit version the notebook was written for as "major.minor", e.g. "0.1"; got {written_for!r}.'
        )
    have = _installed_version()
    if have != "0+unknown" and have.split(".")[:2] != parts:
        warnings.warn(
            f"this notebook was written for labkit {wanted}, but the kernel has labkit {have}: if something "
            f"fails, install the matching version in a cell,\n    {INSTALL}\nthen restart the kernel "
            "(Kernel > Restart) and run the notebook again.",
            VersionWarning,
            stacklevel=2,
        )
    missing = [name for name in NEEDED if importlib.util.find_spec(name) is None]
    if missing:
        raise ValueError(
            f"the kernel lacks {', '.join(missing)}, which the notebooks use: install labkit with "
            f"its dependencies in a cell,\n    {INSTALL}\nthen restart the kernel."
        )
