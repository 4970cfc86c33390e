"""`labkit variants --check` (issue 34) can fail: a check that ignores the student's data is reported with the
draw's values (the pass over the lab is in
tests/grading/run/test_variants_class.py)."""

import dataclasses
from pathlib import Path

import pytest

from labkit.exercises import variants
from labkit.exercises.registry import LAB, Registry
from labkit.grading.authoring import draws

NOTEBOOKS = Path(__file__).resolve().parents[3] / "notebooks"


def _lab_with_exercise_4(**changes):
    exercise = dataclasses.replace(LAB.exercises[4], **changes)
    return Registry([exercise if e.number == 4 else e for e in LAB])


def test_a_check_that_ignores_the_student_s_data_fails_the_solution_and_is_reported(tmp_path):
    found = variants.new(tmp_path / "v.toml")
    plot = dataclasses.replace(LAB.exercises[4].parts[1], varied=())
    blind = _lab_with_exercise_4(parts=(LAB.exercises[4].parts[0], plot))
    troubles = draws.check(found, 1, NOTEBOOKS, registry=blind)
    whats = {(t.entry, t.what) for t in troubles}
    # on its own data the solution passes only when the data are the lab's: the blind check judges it by the lab's
    assert any(entry == "the solution" and "['ax4']" in what for entry, what in whats), whats
    assert str(troubles[0]).startswith("draw-0 (r0 = ")
    assert draws.check(found, 1, NOTEBOOKS) == []  # the lab's own exercise 4: nothing to report


def test_bad_counts_and_catalogs_are_refused(tmp_path):
    found = variants.new(tmp_path / "v.toml")
    with pytest.raises(ValueError, match="at least 1"):
        draws.check(found, 0, NOTEBOOKS)
    (tmp_path / "c.py").write_text("X = 1\n")
    with pytest.raises(ValueError, match="no lists CORRECT and MISTAKES"):
        draws.check(found, 1, NOTEBOOKS, catalog=tmp_path / "c.py")
    with pytest.raises(ValueError, match="nothing to draw"):
        draws.check(found, 1, NOTEBOOKS, registry=Registry([LAB.exercises[2]]))
