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
    runge = {"runge_a": 1.0}
    assert variants.lab_values(LAB) == {
        3: runge,
        4: {"r0": 1.15},
        7: {"xC": 1.0, "yC": 0.5, "xD": 0.0, "yD": 1.0},
        11: runge,
        12: runge,
        13: runge,
        14: {"rise": 1.0, "boil": 2.0},
        15: runge,
        16: {"runge2d_a": 1.0},
    }
    # the Runge function's scale is one datum, drawn with Exercise 3 for every table on it
    assert variants.drawing(LAB) == {
        3: ["runge_a"],
        4: ["r0"],
        7: ["xC", "yC", "xD", "yD"],
        14: ["rise", "boil"],
        16: ["runge2d_a"],
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


RUNGE_EXPERIMENTS = ("pherm", "complete", "natural", "notaknot", "pchip")


def test_the_runge_scale_is_one_datum_drawn_with_exercise_3_and_redrawn_there(tmp_path):
    path = tmp_path / "course.toml"
    made = variants.new(path)
    ids = [str(i) for i in range(40)]
    for student in ids:
        values = made.values(LAB, student)
        scales = {values[n]["runge_a"] for n in (3, 11, 12, 13, 15)}
        assert len(scales) == 1  # every table of a student is on the same function
    assert len({made.values(LAB, s)[3]["runge_a"] for s in ids}) > 30  # and students differ
    before = made.values(LAB, "7")
    variants.redraw(path, "7", 3, LAB)
    after = variants.read(path).values(LAB, "7")
    assert after[3]["runge_a"] != before[3]["runge_a"] or "a rare tie"
    assert all(after[n]["runge_a"] == after[3]["runge_a"] for n in (11, 12, 13, 15))
    assert after[4] == before[4]  # the other exercises' data stay
    with pytest.raises(ValueError, match="drawn with exercise 3"):
        variants.redraw(path, "7", 12, LAB)
    # a tie in the shared datum is reported once, under the exercise that draws it
    tied = variants.ties(variants.VariantsFile(Path("x"), KEY, {}), LAB, [str(i) for i in range(400)])
    assert tied and not any(number in (11, 12, 13, 15) for number, _ in tied)


def test_two_exercises_cannot_declare_one_datum_two_ways():
    from labkit.exercises.experiments import RUNGE_A

    three, eleven = LAB.exercises[3], LAB.exercises[11]
    other = dataclasses.replace(RUNGE_A, high=3.0)
    with pytest.raises(ValueError, match="not alike"):
        Registry([three, dataclasses.replace(eleven, params=(other,))])
    with pytest.raises(ValueError, match="drawn_with"):
        Registry([three, dataclasses.replace(eleven, params=(dataclasses.replace(RUNGE_A, drawn_with=None),))])
    # a course that takes exercise 11 without 3 still draws the scale under exercise 3's number
    alone = Registry([LAB.exercises[10], eleven])
    made = variants.VariantsFile(Path("x"), KEY, {})
    assert made.values(alone, "s1")[11] == made.values(LAB, "s1")[3] and variants.drawing(alone) == {3: ["runge_a"]}


@pytest.mark.parametrize("a", [0.5, 0.73, 1.0, 1.5, 2.0])
def test_every_table_on_the_range_of_scales_shows_the_lab_s_order(a):
    """The orders are the lab's question: over the whole range of the Runge function's scale, labkit's table of
    every experiment on it shows the order the lab expects (4, 4, 2, 4, 2), so only the data change."""
    from labkit import convergence
    from labkit.exercises.experiments import RUNGE_A

    assert RUNGE_A.low <= a <= RUNGE_A.high
    for key in RUNGE_EXPERIMENTS:
        method = LAB.experiment(key)
        f = lambda x, a=a: (
            1 / (1 + a * np.asarray(x) ** 2),
            -2 * a * np.asarray(x) / (1 + a * np.asarray(x) ** 2) ** 2,
        )
        table = convergence.convergence_table(key, list(method.ndata), f)
        assert table.order == method.order, (key, a)
        assert method.sound({"runge_a": a}) == ""
    # far outside the range (a sharp peak the lab's sizes barely resolve) Hermite's table no longer shows its
    # order: sound can say no
    assert "shows order 3, not the lab's 4" in LAB.experiment("pherm").sound({"runge_a": 400.0})


def _convergence_notebook(a, runge_source=None):
    """Notebook 02's solution with `a` in its data cell, run here (its runge replaced by `runge_source`)."""
    from labkit.grading.authoring.draws import reading_rates, run_cells

    nb = with_values(
        nbformat.read(NOTEBOOKS / "02_convergence.ipynb", as_version=4), {3: {"runge_a": a}}, "02_convergence.ipynb"
    )
    if runge_source is not None:
        cell = next(c for c in nb.cells if c.cell_type == "code" and c.source.startswith("def runge(x):"))
        cell.source = runge_source + cell.source[cell.source.index("\n\ndef test_pherm_interpolate") :]
        reading_rates(nb)  # the student reads the rate off their own table, as the printout shows it
    return run_cells(nb, ("rate_pherm",))


def test_a_variant_s_tables_are_its_own_function_s_and_a_copy_loses_them():
    mine = _convergence_notebook(1.437)
    assert mine["runge_a"] == 1.437
    verdict = LAB.check(3, mine, seed=3, variant={"runge_a": 1.437})
    assert verdict["passed"] and "other_variant" not in verdict
    # the table differs from the lab's: it is the student's own experiment
    lab_table = LAB.experiment("pherm").reference(LAB.experiment("pherm").ndata)
    assert not np.allclose(mine["errors_pherm"], lab_table, rtol=1e-3)
    # the same notebook handed in by a student whose scale is 0.812: named, and its data-dependent parts lost
    verdict = LAB.check(3, mine, seed=3, variant={"runge_a": 0.812})
    assert verdict["other_variant"] == {"runge_a": [1.437, 0.812]}
    assert _failed(verdict) == {"runge", "errors_pherm", "rate_pherm"}  # the driver is checked on labkit's f
    table = next(c for c in verdict["checks"] if c["name"] == "errors_pherm")
    assert "runge_a = 0.812" in table["hint"] + str(table.get("steps", ""))


def test_a_copy_between_two_close_draws_loses_its_tables_though_they_agree_to_the_digits_shown():
    """Two students whose scales are 1.4064 and 1.4073 (a pair a fresh course drew, in CI): the complete spline's
    errors on the two differ by 2e-6 at the size where the driver check compares the driver's own f with the
    student's, so the table on the one passed as the other's. The copy is named and every part that depends on
    the data is lost, with the reason in the feedback."""
    from labkit.grading.authoring.draws import run_cells

    nb = with_values(nbformat.read(NOTEBOOKS / "04_splines.ipynb", as_version=4), {11: {"runge_a": 1.4064}},
                     "04_splines.ipynb")  # fmt: skip
    namespace = run_cells(nb, ("rate_complete",))
    assert LAB.check(11, namespace, seed=3, variant={"runge_a": 1.4064})["passed"]
    method = LAB.experiment("complete")
    near = method.reference(method.ndata[1:2], a=1.4073)[0]
    assert abs(namespace["errors_complete"][1] - near) < 2e-6 * near  # the size the driver check compares at
    verdict = LAB.check(11, namespace, seed=3, variant={"runge_a": 1.4073})
    assert verdict["other_variant"] == {"runge_a": [1.4064, 1.4073]}
    varied = {part.name for part in LAB.exercises[11].parts if part.varied}
    assert varied and _failed(verdict) == varied
    for check in verdict["checks"]:
        if check["name"] in varied:
            assert check["hint"].startswith("set the data cell back") and "another variant" in str(check["steps"])


RUNGE_SLIPS = {
    "leaves out runge_a": "    return 1.0 / (1.0 + x**2), -2.0 * x / (1.0 + x**2) ** 2\n",
    "lacks the factor runge_a": "    return 1.0 / (1.0 + runge_a * x**2), -2.0 * x / (1.0 + runge_a * x**2) ** 2\n",
    # the scale left out and the derivative's sign wrong: runge's first failing step is the values
    "leaves out runge_a ": "    return 1.0 / (1.0 + x**2), 2.0 * x / (1.0 + x**2) ** 2\n",
}


@pytest.mark.parametrize("named", sorted(RUNGE_SLIPS))
def test_a_runge_slip_with_the_scale_costs_only_runge(named):
    """A slip in runge on a student's own scale is marked in runge, named, and not charged again through the
    table and the rate, which are the driver's honest measurement of the student's function."""
    source = "def runge(x):\n    x = np.asarray(x, dtype=float)\n" + RUNGE_SLIPS[named]
    slipped = _convergence_notebook(1.4372, source)
    verdict = LAB.check(3, slipped, seed=3, variant={"runge_a": 1.4372})
    assert _failed(verdict) == {"runge"} and "other_variant" not in verdict
    runge = next(c for c in verdict["checks"] if c["name"] == "runge")
    assert named.strip() in runge["hint"]


def test_a_splines_notebook_on_the_lab_s_function_is_not_the_student_s_experiment():
    """Where the notebook gives runge (04, 05), a table on the lab's function (an old notebook, or the data cell
    changed back) is not the student's experiment: it loses the table and the rate."""
    from labkit.grading.authoring.draws import run_cells

    nb = nbformat.read(NOTEBOOKS / "04_splines.ipynb", as_version=4)
    namespace = run_cells(nb, ("rate_complete",))
    assert namespace["runge_a"] == 1.0
    verdict = LAB.check(11, namespace, seed=3, variant={"runge_a": 1.4372})
    assert verdict["other_variant"] == {"runge_a": [1.0, 1.4372]}
    assert _failed(verdict) == {"errors_complete", "rate_complete"}
    assert LAB.check(11, namespace, seed=3)["passed"]  # without variants it is the lab's work, full marks


@pytest.mark.parametrize("a", [0.5, 0.81, 1.0, 1.6543, 2.0])
def test_the_bilinear_table_shows_order_two_over_the_range_of_its_scale(a):
    from labkit import convergence
    from labkit.exercises.experiments import RUNGE2D_A

    assert RUNGE2D_A.low <= a <= RUNGE2D_A.high
    method = LAB.experiment("bilinear")
    f = lambda x, y: 1 / (1 + a * (np.asarray(x) + np.asarray(y)) ** 2)  # written out, not labkit's
    table = convergence.bilinear_convergence(list(method.ndata), f, (0.0, 5.0), method.ntest)
    assert convergence.ConvergenceTable("bilinear", np.array(method.ndata), table.errors).order == 2
    assert method.sound({"runge2d_a": a}) == ""


def _bilinear_notebook(a, runge2d_source=None):
    from labkit.grading.authoring.draws import reading_rates, run_cells

    nb = with_values(
        nbformat.read(NOTEBOOKS / "06_bilinear.ipynb", as_version=4), {16: {"runge2d_a": a}}, "06_bilinear.ipynb"
    )
    if runge2d_source is not None:
        cell = next(c for c in nb.cells if c.cell_type == "code" and c.source.startswith("def runge2d(x, y):"))
        cell.source = runge2d_source + cell.source[cell.source.index("\n\ndef eval_pbilin") :]
        reading_rates(nb)
    return run_cells(nb, ("rate_bilinear",))


def test_a_bilinear_variant_is_graded_on_its_own_function_and_a_copy_loses_its_table():
    mine = _bilinear_notebook(1.6543)
    verdict = LAB.check(16, mine, seed=5, variant={"runge2d_a": 1.6543})
    assert verdict["passed"] and "other_variant" not in verdict
    method = LAB.experiment("bilinear")
    assert not np.allclose(mine["errors_bilinear"], method.reference(method.ndata), rtol=1e-3)
    verdict = LAB.check(16, mine, seed=5, variant={"runge2d_a": 0.9021})
    assert verdict["other_variant"] == {"runge2d_a": [1.6543, 0.9021]}
    assert _failed(verdict) == {"runge2d", "errors_bilinear", "rate_bilinear"}  # phi, eval_pbilin, the driver kept


@pytest.mark.parametrize(
    "body, named",
    [
        ("    return 1.0 / (1.0 + (x + y) ** 2)\n", "leaves out runge2d_a"),
        ("    return 1.0 / (1.0 + runge2d_a * (x * y) ** 2)\n", "squares the product"),
    ],
)
def test_a_runge2d_slip_on_the_scale_costs_only_runge2d(body, named):
    source = "def runge2d(x, y):\n    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)\n" + body
    verdict = LAB.check(16, _bilinear_notebook(1.6543, source), seed=5, variant={"runge2d_a": 1.6543})
    assert _failed(verdict) == {"runge2d"}
    assert named in next(c for c in verdict["checks"] if c["name"] == "runge2d")["hint"]


def test_the_experiment_checks_take_only_their_own_scale():
    from labkit import check

    with pytest.raises(ValueError, match="takes runge2d_a="):
        check.table("bilinear", [1.0], lambda n: 1.0, runge_a=1.2)
    with pytest.raises(ValueError, match="takes runge_a="):
        check.rate("pherm", 4, [1.0], lambda n: 1.0, runge2d_a=1.2)


@pytest.mark.parametrize(
    "notebook, number, lost",
    [
        ("02", 3, {"runge", "errors_pherm", "rate_pherm"}),
        ("06", 16, {"runge2d", "errors_bilinear", "rate_bilinear"}),
    ],
)
def test_the_class_release_on_the_lab_s_scale_handed_in_for_a_variant_loses_its_tables(notebook, number, lost):
    """A notebook still on the lab's scale (last year's, or the release for everyone) is no slip of a student whose
    scale is another: named, and its tables and rates lost, not forgiven as a function that ignores the scale."""
    name = {"02": "runge_a", "06": "runge2d_a"}[notebook]
    lab = _convergence_notebook(1.0) if notebook == "02" else _bilinear_notebook(1.0)
    verdict = LAB.check(number, lab, seed=5, variant={name: 1.4372})
    assert verdict["other_variant"] == {name: [1.0, 1.4372]}
    assert _failed(verdict) == lost


def test_a_bilinear_driver_that_ignores_its_f_costs_only_the_driver_on_a_variant():
    from labkit.grading.authoring.draws import reading_rates, run_cells

    nb = with_values(
        nbformat.read(NOTEBOOKS / "06_bilinear.ipynb", as_version=4), {16: {"runge2d_a": 1.6543}}, "06_bilinear.ipynb"
    )
    cell = next(c for c in nb.cells if c.cell_type == "code" and "def test_pbilin_interpolate(" in c.source)
    old = "    exact = f(XT, YT)\n    return np.max(np.abs(interpolate(f, grid, grid, test, test) - exact))"
    assert old in cell.source
    cell.source = cell.source.replace(
        old,
        "    exact = runge2d(XT, YT)\n    return np.max(np.abs(interpolate(runge2d, grid, grid, test, test) - exact))",
    )
    namespace = run_cells(reading_rates(nb), ("rate_bilinear",))
    verdict = LAB.check(16, namespace, seed=5, variant={"runge2d_a": 1.6543})
    assert _failed(verdict) == {"test_pbilin_interpolate"}
    driver = next(c for c in verdict["checks"] if c["name"] == "test_pbilin_interpolate")
    assert "passed in as `f`" in driver["hint"]
