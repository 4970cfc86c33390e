"""Charged once, everywhere (issue 30): a slip in a student's earlier function costs its own part only.

Every dependency between parts (:attr:`labkit.exercises.registry.Registry.dependencies`, derived from the
parts' ``uses``) has a slip planted upstream here, in the instructor notebook written the way a student may
write it (two_patches meshing with the student's own coons, ncspline's slopes from equation (9)): the
upstream part fails, and every part that relies on it keeps its points, with feedback that does not blame it.
The notebooks run in this process (no sandbox) and are checked through the registry; one class of these
plants is graded in the sandbox too.
"""

import os
from pathlib import Path

import matplotlib
import nbformat
import pytest
from catalog import MISTAKES, Planted, plant
from conftest import sandbox_or_skip

from labkit import grading
from labkit.exercises.registry import LAB
from labkit.grading.store.rubric import default

SEED = 20261201
BY_NAME = {entry.name: entry for entry in MISTAKES}
PART_OF = {part.name: (exercise.number, part) for exercise in LAB for part in exercise.parts}

# two_patches written with the student's own coons (the instructor's meshes with labkit.patch)
OWN_COONS = (
    (
        "first = labkit.quad_mesh(*labkit.patch(A, B, C, D, np.linspace(0, 1, 20), np.linspace(0, 1, 30)))",
        "first = labkit.quad_mesh(*coons(A, B, C, D, np.linspace(0, 1, 20), np.linspace(0, 1, 30)))",
    ),
    (
        "second = labkit.quad_mesh(*labkit.patch(a, b, c, d, np.linspace(0, 1, 30), np.linspace(0, 1, 20)))",
        "second = labkit.quad_mesh(*coons(a, b, c, d, np.linspace(0, 1, 30), np.linspace(0, 1, 20)))",
    ),
)
# ncspline's slopes from equation (9) at every knot but the first, (8) there: the lab allows it equally
SLOPES_FROM_9 = (
    (
        "    sprime[:-1] = -M[:-1] * h / 3 - M[1:] * h / 6 + secant  # equation (8)\n"
        "    sprime[-1] = M[-1] * h[-1] / 3 + M[-2] * h[-1] / 6 + secant[-1]  # equation (9)\n",
        "    sprime[1:] = M[1:] * h / 3 + M[:-1] * h / 6 + secant  # equation (9)\n"
        "    sprime[0] = -M[0] * h[0] / 3 - M[1] * h[0] / 6 + secant[0]  # equation (8)\n",
    ),
)


def _also(name, *replace, part=None):
    """Catalog slip `name` planted with the extra replacements `replace` (how the student wrote the rest)."""
    entry = BY_NAME[name]
    return Planted(
        f"{name}+{len(replace)}", entry.notebook, entry.replace + tuple(replace), entry.exercise, part or entry.part
    )


# upstream part -> slips planted in it (the catalog's, in a notebook whose dependents really call it)
# issue 47: a wrong term of dy/dt cost the plot too (judged on labkit's limaçon), and a mirror that reflects the
# derivative vectors but not the points cost region too (judged on the lab's patches); their siblings with them
SLIPS = {
    "eval_pherm": (
        BY_NAME["wrong_denominator"],
        BY_NAME["values_and_slopes_swapped"],
        BY_NAME["h4_times_the_slope_at_xk"],
    ),
    "runge": (BY_NAME["runge_derivative_sign"],),
    "limacon_derivatives": (
        BY_NAME["limacon_dydt_sign"],
        BY_NAME["dydt_second_term_with_sin"],
        BY_NAME["dxdt_first_term_with_sin"],
    ),
    "coons": (_also("coons_without_twists", *OWN_COONS), _also("coons_dc_from_c_to_d", *OWN_COONS)),
    "two_patches": (
        BY_NAME["mirror_without_swapping"],
        _also("mirror_keeps_the_derivative_vectors", *OWN_COONS),
        BY_NAME["mirror_leaves_the_points"],
        _also("mirror_leaves_the_points", *OWN_COONS),
        BY_NAME["second_patch_counts_swapped"],
    ),
    "ccspline": (BY_NAME["complete_h_subscript"], _also("complete_h_subscript", *SLOPES_FROM_9)),
    "ncspline": (BY_NAME["natural_rows_in_a_only"], BY_NAME["natural_end_slopes_set_to_zero"]),
    "eval_pbilin": (BY_NAME["pbilin_corner_values_swapped"], BY_NAME["pbilin_one_cell_for_every_point"]),
    "runge2d": (BY_NAME["runge2d_with_a_product"],),
}
CASES = [
    (entry, dependent, upstream)
    for upstream, entries in SLIPS.items()
    for entry in entries
    for dependent, up in LAB.dependencies
    if up == upstream
]
RUNS = {}


def _namespace(entry, folder):
    """The names the planted notebook defines, its code run here (magics, explorers and hidden tests left out;
    a cell that raises is skipped, as the grader's run goes on after it)."""
    matplotlib.use("Agg")
    if entry.name not in RUNS:
        path = plant(entry, Path(folder) / entry.name)
        namespace = {}
        for cell in nbformat.read(path, as_version=4).cells:
            if cell.cell_type != "code" or "explorer(" in cell.source or "HIDDEN TESTS" in cell.source:
                continue
            try:
                exec("\n".join(x for x in cell.source.splitlines() if not x.startswith("%")), namespace)
            except Exception:  # noqa: BLE001 - the slip may make a cell raise
                pass
        RUNS[entry.name] = namespace
    return RUNS[entry.name]


def _checks(entry, number, folder):
    return {c["name"]: c for c in LAB.check(number, _namespace(entry, folder), seed=SEED)["checks"]}


def test_every_dependency_between_parts_is_covered_by_a_planted_slip():
    assert {(dependent, upstream) for _, dependent, upstream in CASES} == set(LAB.dependencies)
    assert all(up in SLIPS for _, up in LAB.dependencies)


def test_the_registry_derives_the_dependencies_from_the_declarations():
    assert ("two_patches", "coons") in LAB.dependencies
    assert ("ncspline", "ccspline") in LAB.dependencies  # complete_system is graded in ccspline's part
    assert LAB.upstream("region") == ["two_patches", "coons"]
    assert LAB.upstream("coons") == []
    with pytest.raises(ValueError, match="no part is named"):
        LAB.upstream("nothing")


@pytest.mark.parametrize(("entry", "dependent", "upstream"), CASES, ids=[f"{d}<-{u}:{e.name}" for e, d, u in CASES])
def test_a_slip_upstream_costs_only_its_own_part(tmp_path_factory, entry, dependent, upstream):
    folder = tmp_path_factory.getbasetemp() / "charged_once"
    number, _ = PART_OF[upstream]
    assert not _checks(entry, number, folder)[upstream]["passed"], f"the slip {entry.name} is not one"
    number, _ = PART_OF[dependent]
    check = _checks(entry, number, folder)[dependent]
    assert check["passed"], check
    assert not check.get("hint") and all(step["passed"] for step in check["steps"]), check


def test_the_lab_still_charges_a_table_whose_driver_is_not_real(tmp_path_factory):
    # the driver measures only at the data (error 0): with labkit's pieces too, so it shows no experiment
    folder = tmp_path_factory.getbasetemp() / "charged_once"
    checks = _checks(BY_NAME["driver_only_at_the_data"], 3, folder)
    assert not checks["errors_pherm"]["passed"] and not checks["rate_pherm"]["passed"]


# the issue's three double charges, graded in the sandbox: (the slip, the upstream part, the exercise it cost too)
GRADED = (
    (_also("coons_dc_from_c_to_d", *OWN_COONS), (5, "coons"), 9),
    (_also("complete_h_subscript", *SLOPES_FROM_9), (10, "ccspline"), 12),
    (BY_NAME["wrong_denominator"], (2, "eval_pherm"), 3),
)


@pytest.mark.slow  # starts a sandbox
@pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")
def test_the_sandbox_charges_the_issues_three_slips_once(tmp_path):
    sandbox_or_skip()
    folders = []
    for entry, _, _ in GRADED:
        plant(entry, tmp_path / entry.name)
        folders.append(tmp_path / entry.name)
    grades = grading.grade(folders, tmp_path / "out", grading.GradeOptions(seed=SEED, jobs=2), progress=False)
    rubric = default()
    for grade, (entry, (number, part), downstream) in zip(grades, GRADED):
        failed = {(n, c.name) for n, v in grade.results.items() for c in v.parts if not c.passed}
        assert failed == {(number, part)}, (entry.name, grade.feedback())
        assert grade.points[downstream] == rubric.points[downstream], grade.feedback()


def check_toy(fn):  # a toy part's check, for the registry's validation below
    return fn


def test_a_part_that_uses_a_function_no_part_grades_is_refused():
    from labkit.exercises.model import Exercise, Part
    from labkit.exercises.registry import Registry

    first = Exercise(40, ("toy",), (Part("toy", 1, check_toy, ("toy",)),), notebook="toy.ipynb")
    later = Exercise(41, ("later",), (Part("later", 1, check_toy, ("later",), uses=("toy",)),), notebook="toy.ipynb")
    assert Registry([first, later]).dependencies == [("later", "toy")]
    stray = Exercise(41, ("later",), (Part("later", 1, check_toy, ("later",), uses=("nobody",)),), notebook="t.ipynb")
    with pytest.raises(ValueError, match="'nobody', which no part grades"):
        Registry([first, stray])
    with pytest.raises(ValueError, match="tuple of the student's function names"):
        Part("later", 1, check_toy, ("later",), uses="toy")


def _hermite_driver(interpolate):
    """A real driver of Exercise 3 (the lab's experiment with the pieces it is given), `interpolate` by default."""
    import numpy as np

    import labkit

    def test_pherm_interpolate(ndata, f=labkit.runge, interpolate=interpolate):
        xdata, xtest = np.linspace(0, 5, ndata), np.linspace(0, 5, 4001)
        ydata, ypdata = f(xdata)
        exact = f(xtest)[0]
        return np.max(np.abs(exact - interpolate(xdata, ydata, ypdata, xtest))) / np.max(np.abs(exact))

    return test_pherm_interpolate


def test_an_honest_table_keeps_its_points_and_its_rate_is_read_off_it_or_the_labs():
    import numpy as np

    import labkit
    from labkit import convergence
    from labkit.exercises import experiments

    method = LAB.experiment("pherm")
    # values and slopes swapped: the errors stand still, but the driver is real
    driver = _hermite_driver(lambda x, y, yp, xv: labkit.eval_pherm(x, yp, y, xv))
    errors = [driver(n) for n in method.ndata]
    assert experiments.supported_order(method, errors) is None  # the table shows no experiment
    read_off = int(np.rint(np.mean(np.log2(np.asarray(errors[-4:-1]) / np.asarray(errors[-3:])))))
    lab = convergence.convergence_table("pherm", list(method.ndata), labkit.runge).order
    for answer in {read_off, lab}:
        table, rate = experiments.check_experiment(method, errors, answer, driver)
        assert table.passed and rate.passed, (table, rate)
        assert "measures the experiment" in repr(table)
    wrong = next(p for p in range(-3, 9) if p not in {read_off, lab})
    table, rate = experiments.check_experiment(method, errors, wrong, driver)
    assert table.passed and not rate.passed
    # the same table next to a driver that ignores the pieces it is given is no experiment: it earns nothing
    fake = lambda n, *rest: driver(n)
    table, rate = experiments.check_experiment(method, errors, read_off, fake)
    assert not table.passed and not rate.passed and "shows no experiment" in repr(table)
