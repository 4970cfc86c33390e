"""Where a submission's grading time goes: seconds per phase (starting sandboxes, cells, the checks' calls and
reads, recognising known code, whole notebooks), measured in the grading process. The class run keeps them per
submission (the store's ``timings.json``) for the instructor and ``benchmarks/``, never for a student's feedback.
"""

import contextlib
import json
import time
from pathlib import Path

SUFFIX = ".timings.json"  # beside a grading process's result file
_taken: dict[str, tuple[float, int]] = {}  # {phase: (seconds, count)}


@contextlib.contextmanager
def phase(name):
    """Add the seconds the block takes to phase `name`."""
    start = time.perf_counter()
    try:
        yield
    finally:
        seconds, count = _taken.get(name, (0.0, 0))
        _taken[name] = (seconds + time.perf_counter() - start, count + 1)


def reset():
    _taken.clear()


def taken():
    """{phase: {"seconds": s, "count": n}} of what this process measured since :func:`reset`."""
    return {name: {"seconds": round(seconds, 4), "count": count} for name, (seconds, count) in _taken.items()}


def write_beside(result):
    """Write :func:`taken` beside a grading process's result file (`result`, a path)."""
    Path(result).with_suffix(SUFFIX).write_text(json.dumps(taken()), encoding="utf-8")


def collect(work):
    """The grading processes' figures in `work`, by submission: {result file's stem: :func:`taken`}."""
    found = {}
    for path in sorted(Path(work).glob("*" + SUFFIX)):
        try:
            found[path.name[: -len(SUFFIX)]] = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
    return found
