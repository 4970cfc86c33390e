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


KEY = bytes(range(32))  # draw-0's r0 under this secret is not the lab's 1.15 (asserted below)


def test_a_check_that_ignores_the_student_s_data_fails_the_solution_and_is_reported(tmp_path):
    found = variants.write(tmp_path / "v.toml", KEY, {})
    assert found.values(LAB, "draw-0")[4]["r0"] != 1.15
    plot = dataclasses.replace(LAB.exercises[4].parts[1], varied=())
    blind = _lab_with_exercise_4(parts=(LAB.exercises[4].parts[0], plot))
    troubles = draws.check(found, 1, NOTEBOOKS, registry=blind)
    whats = {(t.entry, t.what) for t in troubles}
    # on its own data the solution passes only when the data are the lab's: the blind check judges it by the lab's
    assert any(entry == "the solution" and "['ax4']" in what for entry, what in whats), whats
    said = str(troubles[0])
    assert said.startswith("draw-0 (") and f"r0 = {found.values(LAB, 'draw-0')[4]['r0']}" in said
    assert said.count("runge_a = ") == 1  # the datum exercises 3, 11, 12, 13 and 15 share, said once
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


def test_students_of_the_roster_who_drew_the_same_data_are_reported(tmp_path):
    found = variants.write(tmp_path / "v.toml", KEY, {})
    seen: dict = {}
    for i in range(5000):  # two ids with the same r0: a tie the instructor must break
        r0 = found.values(LAB, str(i))[4]["r0"]
        if r0 in seen:
            pair = (seen[r0], str(i))
            break
        seen[r0] = str(i)
    only_4 = Registry([LAB.exercises[2], LAB.exercises[4]])
    troubles = draws.check(found, 1, NOTEBOOKS, roster={"ann": pair[0], "ben": pair[1]}, registry=only_4)
    assert [(t.student, t.entry) for t in troubles] == [(pair[0], "a tie")], troubles
    assert f"the same data as {pair[1]}" in troubles[0].what and "--redraw" in troubles[0].what
