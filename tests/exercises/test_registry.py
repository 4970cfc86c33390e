"""Every exercise is declared once: each place derived from the declarations agrees with them.

The walk goes through :data:`labkit.exercises.registry.LAB` and checks the
self-check facade, the functions that may cross into the sandbox, the rubric's
points, nbgrader's points in the committed notebooks, the notebooks' own
sections, names and self-check calls, and the exercise table in the docs.
"""

import ast
import inspect
import re
from pathlib import Path

import nbformat
import pytest
from docs_markdown import exercise_table

import labkit
import labkit.check
from labkit import convergence
from labkit.exercises import model
from labkit.exercises.registry import LAB, Registry, function_name, load
from labkit.grading.authoring.release import CHECK_CALL
from labkit.grading.sandbox import protocol
from labkit.grading.store.rubric import default

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = {path.name: path for path in sorted((ROOT / "notebooks").glob("*.ipynb"))}


def _cells(name, kind="code"):
    return [cell.source for cell in nbformat.read(NOTEBOOKS[name], as_version=4).cells if cell.cell_type == kind]


def _defined_names(sources):
    """Top-level names a notebook's code defines (assignments, functions, imports, for targets)."""
    names = set()
    for source in sources:
        code = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
        for node in ast.walk(ast.parse(code)):
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                names.add(node.id)
    return names


def test_the_registry_is_the_declarations_of_the_topic_modules():
    from labkit.exercises import registry

    declared = [exercise for topic in registry.TOPICS for exercise in topic.EXERCISES]
    assert [e.number for e in LAB] == sorted(e.number for e in declared)
    assert len(LAB) == len(declared)
    for topic in registry.TOPICS:  # each topic module declares the exercises it checks
        for exercise in topic.EXERCISES:
            for part in exercise.parts:
                assert part.check.__module__.startswith("labkit.exercises."), part


@pytest.mark.parametrize("exercise", list(LAB), ids=lambda e: f"exercise {e.number}")
def test_every_part_is_self_checked_by_its_declared_name(exercise):
    facade = labkit.check
    for part in exercise.parts:
        assert part.self_check in facade.__all__, part.name
        experiment = getattr(part, "experiment", None)
        if experiment is None:
            # the part's check, run as it is unless in the grader's sandbox (labkit.check._not_in_the_grader)
            assert getattr(facade, part.self_check).__wrapped__ is part.check
        else:
            assert LAB.experiment(experiment.key) is experiment
        if part.refused is not None:  # the grader scans the source of names the notebook defines
            assert set(part.scanned) <= set(exercise.names) | set(part.names()), part.name


@pytest.mark.parametrize("exercise", list(LAB), ids=lambda e: f"exercise {e.number}")
def test_each_notebook_holds_its_exercises_defines_their_names_and_self_checks_every_part(exercise):
    assert exercise.notebook in NOTEBOOKS
    headings = {n for text in _cells(exercise.notebook, "markdown") for n in model.sections(text)}
    assert exercise.number in headings
    code = _cells(exercise.notebook)
    missing = [
        name
        for part in exercise.parts
        for name in part.names() + part.scanned
        if name.split(":")[0] not in _defined_names(code)
    ]
    assert not missing, f"the notebook does not define {missing}"
    calls = [(function, key) for source in code for function, key in CHECK_CALL.findall(source)]
    checked = {
        part.name for function, key in calls for part in LAB.parts_checked(exercise.number, function, key or None)
    }
    assert checked == {part.name for part in exercise.parts}, "parts the notebook never self-checks"


def test_the_functions_that_may_cross_the_sandbox_are_the_ones_the_checks_hand_over():
    declared = {function for exercise in LAB for part in exercise.parts for function in part.passes}
    assert LAB.passable == {function_name(f) for f in declared}
    for function in declared:
        assert protocol.passable(function_name(function)) is function  # found by its name on the other side
        assert protocol.encode(function, LAB.passable) == ["fn", function_name(function)]
    # every function a check hands a driver is declared, and both test functions of each experiment cross
    for experiment in LAB.experiments.values():
        assert {function_name(f) for f in experiment.passes} <= LAB.passable


def test_each_experiment_names_its_method_with_the_librarys_title():
    for key, experiment in LAB.experiments.items():
        if key != "bilinear":
            assert experiment.title == convergence.METHOD_TITLES[key]
        assert experiment.order == experiment.observed_order, key


def test_points_have_one_source_the_rubric_and_nbgrader_derive_theirs():
    rubric = default()
    assert rubric.points == {n: float(p) for n, p in LAB.points.items()}
    grouped = set(rubric.required) | set(rubric.extra_credit) | {n for b in rubric.branches for n in b.exercises}
    assert grouped == set(LAB.exercises)
    tested = {}
    for name in NOTEBOOKS:
        for cell in nbformat.read(NOTEBOOKS[name], as_version=4).cells:
            meta = cell.metadata.get("nbgrader", {})
            if cell.cell_type == "code" and meta.get("grade"):
                number = int(re.search(r"# tests for exercise (\d+)", cell.source).group(1))
                tested[number] = tested.get(number, 0) + meta["points"]
                assert LAB.exercises[number].notebook == name
    assert tested == LAB.points


def test_the_docs_exercise_table_is_the_declarations():
    rows = {int(row["exercise"]): row for row in exercise_table()}
    assert set(rows) == {1} | set(LAB.exercises)  # exercise 1 (copying code) is in the lab but not graded
    assert int(rows[1]["points"]) == 0
    for number, exercise in LAB.exercises.items():
        assert int(rows[number]["points"]) == exercise.points, number
        assert rows[number]["notebook"].strip("`") == exercise.notebook, number


def test_the_answers_in_words_are_the_notebooks_answer_cells():
    from labkit.grading.authoring.release import answer_ids

    found = {grade_id for path in NOTEBOOKS.values() for grade_id in answer_ids(nbformat.read(path, as_version=4))}
    assert found == set(LAB.answers)


def test_a_declaration_refuses_what_would_break_the_derivations():
    def check_thing(value):
        return value

    def thing(value):
        return value

    with pytest.raises(ValueError, match="named check_<name>"):
        model.Part("thing", 1, thing, ("thing",))
    with pytest.raises(ValueError, match="negative weight"):
        model.Part("thing", -1, check_thing, ("thing",))
    part = model.Part("thing", 1, check_thing, ("thing",))
    with pytest.raises(ValueError, match="two parts with the same name"):
        model.Exercise(40, ("thing",), (part, part), notebook="x.ipynb")
    with pytest.raises(ValueError, match="no parts"):
        model.Exercise(40, ("thing",), (), notebook="x.ipynb")
    exercise = model.Exercise(40, ("thing",), (part,), notebook="x.ipynb")
    with pytest.raises(ValueError, match="exercise 40 is declared twice"):
        Registry([exercise, exercise])
    with pytest.raises(ValueError, match="cannot load the exercises"):
        load("no.such.module:REGISTRY")
    with pytest.raises(ValueError, match="unknown experiment 'akima'"):
        LAB.experiment("akima")
    with pytest.raises(ValueError, match="worth no points"):
        model.Exercise(41, ("thing",), (model.Part("thing", 0, check_thing, ("thing",)),), notebook="x.ipynb")


def check_table(value):  # named like a function the facade defines itself
    return value


def check_elsewhere(value):
    return value


@pytest.mark.parametrize(
    "part, message",
    [
        (lambda: model.Part("p", 1, check_elsewhere, ("p",), passes=(lambda x: x,)), "only module-level functions"),
        (lambda: model.Part("p", 1, check_elsewhere, ("p",), passes=(np_sin(),)), "only module-level functions"),
        (lambda: model.Part("p", 1, check_elsewhere, ("p",), passes=(check_elsewhere,)), "only module-level functions"),
        (lambda: model.Part("p", 1, check_elsewhere, ("p",), passes=(grading_grade(),)), "only module-level functions"),
        (lambda: model.Part("p", 1, check_table, ("p",)), "labkit.check.table is taken by labkit itself"),
        (
            lambda: model.Part(
                "eval_pherm",
                1,
                check_elsewhere,
                ("eval_pherm",),
                refused=model.Refusal(model.INTERPOLANTS.name, ("numpy",)),
            ),
            "two different refusals",
        ),
    ],
)
def test_the_registry_refuses_what_the_sandbox_or_the_facade_could_not_honour(part, message):
    with pytest.raises(ValueError, match=message):
        Registry([*LAB, model.Exercise(40, ("p",), (part(),), notebook="x.ipynb")])


def np_sin():
    import numpy as np

    return np.sin


def grading_grade():
    from labkit.grading import grade

    return grade


def test_a_second_check_under_an_existing_name_is_refused():
    from labkit.exercises.hermite import check_runge

    def check_runge_again(fn, seed=None):
        return check_runge(fn, seed)

    check_runge_again.__name__ = "check_runge"
    part = model.Part("runge", 1, check_runge_again, ("runge",))
    with pytest.raises(ValueError, match="two different checks would both be labkit.check.runge"):
        Registry([*LAB, model.Exercise(40, ("runge",), (part,), notebook="x.ipynb")])


def test_every_name_the_facade_exports_exists_and_the_checks_keep_their_signatures():
    namespace = {}
    exec("from labkit.check import *", namespace)
    assert set(labkit.check.__all__) <= set(namespace)
    # the second positional argument of the ncspline check is still the seed, as before
    assert list(inspect.signature(labkit.check.ncspline).parameters) == ["fn", "seed", "system"]


def test_the_self_check_facade_keeps_the_notebooks_names():
    # the names the committed notebooks call, each a function of the facade
    called = {
        function
        for path in NOTEBOOKS.values()
        for cell in nbformat.read(path, as_version=4).cells
        if cell.cell_type == "code"
        for function, _ in CHECK_CALL.findall(cell.source)
    }
    assert called <= set(labkit.check.__all__)
    for name in called:
        assert inspect.isfunction(getattr(labkit.check, name)), name


def test_the_old_name_of_check_exercise_is_gone():
    """``labkit.check.grade`` was ``exercise``'s name before any release; ``labkit.grading.grade`` grades a class."""
    import labkit.check

    assert not hasattr(labkit.check, "grade") and "grade" not in labkit.check.__all__
    assert callable(labkit.check.exercise)
