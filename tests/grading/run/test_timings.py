"""labkit.grading.sandbox.timings: each phase's seconds add up in the grading process, and the run's folder gathers every
grading process's figures into timings.json."""

import json
import time

from labkit.grading.sandbox import timings
from labkit.grading.store.report import write_timings


def test_phases_add_up_and_the_run_gathers_them(tmp_path):
    timings.reset()
    for _ in range(3):
        with timings.phase("calls"):
            time.sleep(0.01)
    try:
        with timings.phase("cells"):
            raise ValueError("a cell's failure still counts its time")
    except ValueError:
        pass
    taken = timings.taken()
    # three sleeps of 0.01 s take 0.03 s at least; no upper limit, which a busy machine would break
    assert taken["calls"]["count"] == 3 and taken["calls"]["seconds"] >= 0.03
    assert taken["cells"]["count"] == 1 and set(taken) == {"calls", "cells"}
    work, out = tmp_path / "work", tmp_path / "out"
    work.mkdir()
    out.mkdir()
    timings.write_beside(work / "ada-1.json")
    (work / "bob-1.timings.json").write_text("not json")  # a process killed while writing: left out
    write_timings(out, timings.collect(work))
    assert json.loads((out / "timings.json").read_text()) == {"ada-1": taken}
    timings.reset()
    assert timings.taken() == {}
    empty = tmp_path / "empty"
    empty.mkdir()
    write_timings(empty, timings.collect(empty))
    assert list(empty.iterdir()) == []  # nothing measured, nothing written
