"""Data generators shared by the tests (imported as ``from helpers import ...``)."""

from pathlib import Path

import numpy as np
from hypothesis import strategies as st


def processes_with(marker):
    """(pid, command line) of every process whose command line holds `marker`."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if marker in cmdline:
                found.append((entry.name, cmdline))
    return found


def unequal_knots(rng, n, start=-2.0):
    """Strictly increasing knots with spacings between 0.05 and 1."""
    return start + np.concatenate(([0.0], np.cumsum(rng.uniform(0.05, 1.0, n - 1))))


@st.composite
def knots(draw, min_size=2, max_size=25):
    """Hypothesis strategy: strictly increasing, well-separated abscissae."""
    gaps = draw(st.lists(st.floats(0.05, 5.0), min_size=min_size - 1, max_size=max_size - 1))
    start = draw(st.floats(-10.0, 10.0))
    return start + np.concatenate(([0.0], np.cumsum(gaps)))
