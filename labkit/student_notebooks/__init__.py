"""The student notebooks, shipped with the package (``labkit notebooks DIR`` writes them out).

They are the student release of the course repository's instructor notebooks
(``notebooks/``): ``make notebooks`` regenerates them with ``labkit release``,
and tests/test_packaging.py checks that they are in sync and hold no solution
or hidden test. Do not edit them by hand. The solved notebooks are never
part of the package.
"""
from importlib.resources import files


def paths():
    """The packaged student notebooks, in teaching order."""
    return sorted((p for p in files(__name__).iterdir() if p.name.endswith(".ipynb")), key=lambda p: p.name)
