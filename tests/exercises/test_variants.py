"""Per-student variants (issue 34): each student's data derived from the course's secret and the roster id, the
data cells rewritten for a release, the varied parts checked against the student's own data, and nothing changed
without variants."""

import copy
import dataclasses
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import nbformat
import numpy as np
import pytest

from labkit import eval_pherm
from labkit.exercises import variants
from labkit.exercises.model import Exercise, Part
from labkit.exercises.registry import LAB, Registry
from labkit.functions import limacon
from labkit.grading.authoring.release import release_notebook, with_values

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"
R0 = LAB.exercises[4].params[0]
KEY = bytes(range(32))


def test_the_lab_declares_the_limacon_offset_and_its_own_value_is_the_notebook_s():
    assert variants.lab_values(LAB) == {
        4: {"r0": 1.15},
        7: {"xC": 1.0, "yC": 0.5, "xD": 0.0, "yD": 1.0},
        14: {"rise": 1.0, "boil": 2.0},
    }
    assert (R0.low, R0.high, R0.digits) == (1.05, 1.3, 4)
    assert LAB.exercises[14].sound({"rise": 1.0, "boil": 2.0}) == ""  # the lab's data teach the lesson
    assert "overshoots" in LAB.exercises[14].sound({"rise": 1.9, "boil": 2.0})  # nearly straight up to boiling
    nb = nbformat.read(NOTEBOOKS / "01_limacon.ipynb", as_version=4)
    cells = [c for c in nb.cells if variants.DATA_TAG in c.metadata.get("tags", [])]
    assert len(cells) == 1 and cells[0].source.startswith("r0 = 1.15 ")
    # every varied exercise's notebook has a data cell for each of its parameters (with_values refuses otherwise)
    for exercise in LAB:
        if exercise.params:
            source = nbformat.read(NOTEBOOKS / exercise.notebook, as_version=4)
            with_values(source, {exercise.number: {p.name: p.lab for p in exercise.params}}, exercise.notebook)


def test_a_draw_is_the_same_every_time_and_changes_with_the_secret_the_student_the_exercise_and_the_draw():
    params = LAB.exercises[4].params
    one = variants.draw(KEY, "1815", 4, params)
    assert one == variants.draw(KEY, "1815", 4, params)
    students = [variants.draw(KEY, f"s{i}", 4, params)["r0"] for i in range(400)]
    secrets_ = [variants.draw(i.to_bytes(2, "big") * 16, "1815", 4, params)["r0"] for i in range(400)]
    redraws = [variants.draw(KEY, "1815", 4, params, n)["r0"] for n in range(400)]
    exercises = [variants.draw(KEY, "1815", n, params)["r0"] for n in range(400)]
    for values in (students, secrets_, redraws, exercises):
        assert len(set(values)) > 350  # of the range's 2501 values at four digits: spread, not stuck
        assert min(values) >= R0.low and max(values) <= R0.high
        assert min(values) < 1.07 and max(values) > 1.28  # both ends of the range are reached
        assert all(v == round(v, 4) for v in values)  # rounded to what the notebook shows


def test_a_parameter_rounds_into_its_range_and_refuses_a_range_it_cannot_draw_from():
    p = variants.Param("a", 0.5, 2.0, 1, lab=1.0)
    assert p.value(0.0) == 0.5 and p.value(0.999999) == 2.0
    assert sorted({p.value(u) for u in np.linspace(0, 0.999999, 1000)}) == [round(0.5 + 0.1 * k, 1) for k in range(16)]
    assert p.shown(1.0) == "1.0" and p.holds(1.04, 1.0) and not p.holds(1.06, 1.0) and not p.holds("x", 1.0)
    for bad, words in [
        (dict(name="1a", low=0, high=1, digits=1, lab=0.5), "not a name"),
        (dict(name="a", low=1, high=0, digits=1, lab=0.5), "empty"),
        (dict(name="a", low=0, high=1, digits=1, lab=2), "outside"),
        (dict(name="a", low=0, high=0.01, digits=0, lab=0), "one value"),
        (dict(name="a", low=0, high=math.inf, digits=1, lab=0), "finite"),
    ]:
        with pytest.raises(ValueError, match=words):
            variants.Param(**bad)


def test_the_variants_file_is_made_once_read_strictly_and_redraws_one_student_s_exercise(tmp_path):
    path = tmp_path / "course.toml"
    made = variants.new(path)
    assert len(made.secret) == 32 and made.secret.hex() not in made.digest
    with pytest.raises(ValueError, match="already exists"):
        variants.new(path)
    before = {s: made.values(LAB, s) for s in ("1815", "1816")}
    assert variants.redraw(path, "1816", 4, LAB) == 1
    after = variants.read(path)
    assert after.values(LAB, "1815") == before["1815"]
    redrawn = after.values(LAB, "1816")[4]
    assert redrawn == variants.draw(made.secret, "1816", 4, LAB.exercises[4].params, 1)
    assert after.digest != made.digest and after.secret == made.secret
    with pytest.raises(ValueError, match="no variants"):
        variants.redraw(path, "1816", 2, LAB)
    for text, words in [
        ("secret = 12", "at least 32 hexadecimal"),
        ('secret = "abc"', "at least 32"),
        ("secret = [", "not TOML"),
        ('secret = "' + "ab" * 32 + '"\nother = 1', "unknown keys"),
        ('secret = "' + "ab" * 32 + '"\n[redraw]\n"1815" = {four = 1}', "exercise number"),
    ]:
        path.write_text(text)
        with pytest.raises(ValueError, match=words):
            variants.read(path)
    with pytest.raises(ValueError, match="labkit variants --new"):
        variants.read(tmp_path / "missing.toml")


def test_a_release_with_values_changes_the_data_cell_and_nothing_else():
    nb = release_notebook(nbformat.read(NOTEBOOKS / "01_limacon.ipynb", as_version=4), "01_limacon.ipynb")
    mine = with_values(nb, {4: {"r0": 1.237}}, "01_limacon.ipynb")
    changed = [i for i, (a, b) in enumerate(zip(nb.cells, mine.cells)) if a != b]
    assert len(mine.cells) == len(nb.cells) and len(changed) == 1
    assert mine.cells[changed[0]].source == "r0 = 1.2370  # the limaçon's offset: r = r0 + cos t"
    assert mine.metadata == nb.metadata  # the grader never reads the notebook for the data: nothing is written there
    other = copy.deepcopy(nb)
    for cell in other.cells:
        cell.metadata.get("tags", []).clear()
    with pytest.raises(ValueError, match="no data cell assigning r0"):
        with_values(other, {4: {"r0": 1.2}}, "01_limacon.ipynb")
    assert with_values(nb, {4: {"r0": 1.2}}, "02_convergence.ipynb") == nb  # another notebook's data: untouched


def _limacon_axes(r0):
    """The Hermite limaçon of 21 points at r0, drawn as Exercise 4 asks, and the data it was drawn from."""
    t = np.linspace(0, 2 * np.pi, 21)
    x, y, dx, dy = limacon(t, r0=r0)
    tval = np.linspace(0, 2 * np.pi, 210)
    _, ax = plt.subplots()
    ax.plot(eval_pherm(t, x, dx, tval), eval_pherm(t, y, dy, tval))
    return {"ax4": ax, "tdata": t, "xdata": x, "ydata": y, "xpdata": dx, "ypdata": dy, "r0": r0}


def _failed(verdict):
    return {c["name"] for c in verdict["checks"] if not c["passed"]}


def test_the_plot_is_checked_against_the_student_s_own_data_and_another_s_is_named():
    def deriv(t, r0):
        return limacon(t, r0=r0)[2:]

    own = {**_limacon_axes(1.237), "limacon_derivatives": deriv}
    verdict = LAB.check(4, own, seed=1, variant={"r0": 1.237})
    assert verdict["passed"] and "other_variant" not in verdict
    # the lab's data, or another student's, do not pass for this student's; the notebook's r0 is named
    for variant in ({"r0": 1.15}, {"r0": 1.201}):
        verdict = LAB.check(4, own, seed=1, variant=variant)
        assert _failed(verdict) == {"ax4"}  # the derivatives are checked on test data, not the student's
        assert verdict["other_variant"] == {"r0": [1.237, variant["r0"]]}
    # without variants: the lab's data, nothing compared (as before variants)
    lab = {**_limacon_axes(1.15), "limacon_derivatives": deriv}
    assert LAB.check(4, lab, seed=1)["passed"] and "other_variant" not in LAB.check(4, own, seed=1)
    plt.close("all")


def test_a_part_can_vary_only_what_its_exercise_declares():
    part = LAB.exercises[4].parts[1]
    with pytest.raises(ValueError, match="does not declare"):
        Exercise(40, ("ax4",), (dataclasses.replace(part, varied=("a",)),), "x.ipynb", params=LAB.exercises[4].params)
    with pytest.raises(ValueError, match="twice"):
        Exercise(40, ("ax4",), (part,), "x.ipynb", params=LAB.exercises[4].params * 2)
    alone = dataclasses.replace(part, uses=())
    assert Registry([Exercise(40, ("ax4",), (alone,), "x.ipynb", params=LAB.exercises[4].params)])
    assert isinstance(part, Part) and part.varied == ("r0",)


def test_ready_to_hand_in_judges_a_variant_notebook_by_its_own_data():
    from labkit.handin import DONE, FAILING, ready_to_hand_in

    def deriv(t, r0):
        return limacon(t, r0=r0)[2:]

    own = {**_limacon_axes(1.237), "limacon_derivatives": deriv}  # r0 = 1.237 in the notebook, its plot of it
    assert [p.status for p in ready_to_hand_in("01_limacon", namespace=own).parts] == [DONE, DONE]
    wrong = {**own, "r0": 1.15}  # the notebook says the lab's r0 but drew another limaçon
    assert [p.status for p in ready_to_hand_in("01_limacon", namespace=wrong).parts] == [DONE, FAILING]
    plt.close("all")


def test_only_a_number_in_the_notebook_can_be_another_variant_s_data():
    """A name the notebook no longer answers for (a stopped notebook's proxy), text, an array or a value that is not
    finite is no sign of another student's data: nothing is named, whatever the plot's part says."""

    def deriv(t, r0):
        return limacon(t, r0=r0)[2:]

    own = {**_limacon_axes(1.2), "limacon_derivatives": deriv}
    for held in (deriv, "1.3", np.array([1.3, 1.1]), math.nan, math.inf, None, True):
        verdict = LAB.check(4, {**own, "r0": held}, seed=1, variant={"r0": 1.2})
        assert "other_variant" not in verdict, held
    for held in (np.float64(1.3), np.array(1.3), 1):  # numbers, as the sandbox hands them over
        verdict = LAB.check(4, {**own, "r0": held}, seed=1, variant={"r0": 1.2})
        assert verdict["other_variant"] == {"r0": [float(held), 1.2]}
    plt.close("all")


@pytest.mark.parametrize(
    "layout",
    ["[redraw]\n1815 = {4 = 1}", "[redraw]\n'1815' = {4 = 2}", '[redraw]\n  "1815"={14 = 1}', "redraw = {}", ""],
)
def test_a_redraw_keeps_a_hand_edited_file_readable_with_its_secret(tmp_path, layout):
    path = tmp_path / "course.toml"
    made = variants.new(path)
    path.write_text(f'secret = "{made.secret.hex()}"\n{layout}\n')
    before = variants.read(path).redraw.get("1815", {})
    assert variants.redraw(path, "1815", 4, LAB) == before.get(4, 0) + 1
    assert variants.redraw(path, 'odd "id" \\ ü', 7, LAB) == 1
    after = variants.read(path)
    assert after.secret == made.secret
    assert after.redraw == {"1815": {**before, 4: before.get(4, 0) + 1}, 'odd "id" \\ ü': {7: 1}}
    assert [p.name for p in tmp_path.iterdir()] == ["course.toml"]  # no partial file left beside it


def test_bad_input_is_refused_with_what_to_do():
    with pytest.raises(ValueError, match="too many values"):
        variants.Param("x", 0, 1e300, 12, lab=1)
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell("x = 1\rr0 = 1.15  # ü\r\ny = 2")  # ast counts a lone \r as a line break
    cell.metadata["tags"] = [variants.DATA_TAG]
    nb.cells = [cell]
    assert with_values(nb, {4: {"r0": 1.2}}, "01_limacon.ipynb").cells[0].source == "x = 1\rr0 = 1.2000  # ü\r\ny = 2"
    for source in ("r0 = -x", "r0 = 'abc'", "r0 = (1.2,\n 1.3)"):
        cell.source = source
        with pytest.raises(ValueError, match="r0 must be assigned"):
            with_values(nb, {4: {"r0": 1.2}}, "01_limacon.ipynb")


def test_students_who_drew_the_same_data_are_found():
    made = variants.VariantsFile(Path("x"), KEY, {})
    ids = [str(i) for i in range(300)]
    found = variants.ties(made, LAB, ids)
    by_r0: dict = {}
    for key in ids:
        by_r0.setdefault(made.values(LAB, key)[4]["r0"], []).append(key)
    assert [group for number, group in found if number == 4] == sorted(
        (g for g in by_r0.values() if len(g) > 1), key=lambda g: made.values(LAB, g[0])[4]["r0"]
    )
    assert found and all(len(group) > 1 for _, group in found)  # 300 students over 2501 values: some tie


def test_ready_to_hand_in_leaves_a_value_that_is_not_finite_to_the_lab_s_data():
    from labkit.handin import DONE, ready_to_hand_in

    def deriv(t, r0):
        return limacon(t, r0=r0)[2:]

    lab = {**_limacon_axes(1.15), "limacon_derivatives": deriv, "r0": math.nan}
    assert [p.status for p in ready_to_hand_in("01_limacon", namespace=lab).parts] == [DONE, DONE]
    plt.close("all")
