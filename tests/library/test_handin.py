"""Ready to hand in? (labkit.handin, the notebooks' last cell, and `labkit handin DIR`).

The notebooks run in real kernels (nbclient), as a student's would: the solved instructor notebook,
the bare student release, and a half-done notebook made from the release by pasting in some of the
instructor's solution cells, one with a slip from tests/catalog.py, one with a typo that raises.
docs/students.md shows the half-done notebook's table; a test regenerates it.
"""

import re
import shutil
import sys
from pathlib import Path

import nbformat
import numpy as np
import pytest
from catalog import MISTAKES
from docs_markdown import DOCS

import labkit
from labkit import handin, notebook
from labkit.cli import main
from labkit.exercises.registry import LAB
from labkit.handin import DONE, FAILING, NOT_STARTED

pytestmark = pytest.mark.slow  # executes notebooks

ROOT = Path(__file__).resolve().parents[2]
INSTRUCTOR = ROOT / "notebooks"
RELEASE = ROOT / "labkit" / "student_notebooks"
NAME = "02_convergence.ipynb"
SLIP = next(m for m in MISTAKES if m.name == "runge_derivative_sign")
TYPO = ("for n in ndata]", "for n in n_data]")  # the table's cell raises NameError
DOCS_MARKER = "<!-- ready to hand in: the half-done notebook's table, checked by tests/library/test_handin.py -->"


def _solved(source):
    """An instructor cell as a student who wrote the solution would have it: without nbgrader's markers."""
    return "\n".join(
        line for line in source.split("\n") if line.strip() not in ("### BEGIN SOLUTION", "### END SOLUTION")
    )


def _instructor_cell(marker):
    teacher = nbformat.read(INSTRUCTOR / NAME, as_version=4)
    (index,) = [i for i, c in enumerate(teacher.cells) if c.cell_type == "code" and marker in c.source]
    return index, _solved(teacher.cells[index].source)


def half_done(folder):
    """02_convergence from the release: eval_pherm solved, runge with a slip, the table's cell raising, the rate
    and the answer in words left as handed out."""
    student = nbformat.read(RELEASE / NAME, as_version=4)
    teacher = nbformat.read(INSTRUCTOR / NAME, as_version=4)
    assert [c.cell_type for c in teacher.cells] == [c.cell_type for c in student.cells]

    def paste(marker, *replace):
        index, source = _instructor_cell(marker)
        for old, new in replace:
            assert source.count(old) == 1, old
            source = source.replace(old, new)
        student.cells[index].source = source

    paste("def eval_pherm(")
    paste("def runge(", *SLIP.replace)
    paste("errors_pherm = [", TYPO)
    path = Path(folder) / NAME
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(student, path)
    return path


@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    """{solved, bare, half}: folders with 02_convergence in each state (bare holds the whole release)."""
    root = tmp_path_factory.mktemp("handin")
    (root / "solved").mkdir()
    shutil.copy(INSTRUCTOR / NAME, root / "solved" / NAME)
    shutil.copytree(RELEASE, root / "bare", ignore=shutil.ignore_patterns("__init__.py", "__pycache__"))
    half_done(root / "half")
    return {"solved": root / "solved", "bare": root / "bare", "half": root / "half"}


@pytest.fixture(scope="module")
def half(folders):
    return handin.run_notebook(folders["half"] / NAME)


def _statuses(result):
    return {p.part: p.status for p in result.parts}


# --- in a kernel, as a student runs it ---------------------------------------------------------------------


def test_a_solved_notebook_is_ready(folders):
    result = handin.run_notebook(folders["solved"] / NAME)
    assert [p.part for p in result.parts] == [p.name for n in (2, 3) for p in LAB.exercises[n].parts]
    assert set(_statuses(result).values()) == {DONE}
    assert result.raised == [] and result.empty_answers == [] and result.ready
    assert "so your grade may differ." in result.text().splitlines()[-1]


@pytest.mark.parametrize("name", sorted(LAB.notebooks()))
def test_the_bare_release_is_not_started_anywhere(folders, name):
    result = handin.run_notebook(folders["bare"] / name)
    numbers = LAB.notebooks()[name]
    assert [p.part for p in result.parts] == [p.name for n in numbers for p in LAB.exercises[n].parts]
    assert set(_statuses(result).values()) == {NOT_STARTED}
    declared = [f"exercise {n}: {about}" for n, about in LAB.answers.values() if n in numbers]
    assert result.empty_answers == declared
    assert result.raised and any(cell.error == "NotImplementedError" for cell in result.raised)
    assert not result.ready


def test_a_half_done_notebook_says_what_is_left(half):
    assert _statuses(half) == {
        "eval_pherm": DONE,
        "runge": FAILING,
        "test_pherm_interpolate": DONE,
        "errors_pherm": NOT_STARTED,
        "rate_pherm": NOT_STARTED,
    }
    runge = next(p for p in half.parts if p.part == "runge")
    assert SLIP.hint in runge.detail  # the self-check's hint for this slip
    wrong = {"np": np, "eval_pherm": None, "runge_a": 1.0}  # the data cell, as released
    exec(_instructor_cell("def runge(")[1].replace(*SLIP.replace[0]), wrong)  # the slip, run here
    assert runge.detail == labkit.check.runge(wrong["runge"]).hint
    # the typo's cell and the untouched rate cell raised; nothing else did
    assert [(c.error, c.message) for c in half.raised] == [
        ("NameError", "name 'n_data' is not defined"),
        ("NotImplementedError", ""),
    ]
    typo = half.raised[0]
    assert typo.source.splitlines()[typo.line - 1].strip().startswith("errors_pherm = [")
    errors = next(p for p in half.parts if p.part == "errors_pherm")
    assert errors.detail == f"errors_pherm is not defined: cell [{typo.number}] raised"
    assert half.empty_answers == ["exercise 3: the order the table shows, against piecewise linear"]
    text = half.text()
    assert f"[{typo.number}] line {typo.line}: errors_pherm = [test_pherm_interpolate(n) for n in n_data]" in text
    assert "2 of 5 parts pass their self-checks, 1 fail, 2 not done." in text
    assert not half.ready


def test_the_students_docs_show_the_half_done_table(half):
    """docs/students.md's example is this very output, so it cannot go stale."""
    lines = (DOCS / "students.md").read_text(encoding="utf-8").splitlines()
    assert lines.count(DOCS_MARKER) == 1
    start = lines.index(DOCS_MARKER) + 1
    assert lines[start] == "```text"
    end = lines.index("```", start + 1)
    assert "\n".join(lines[start + 1 : end]) == half.text()


# --- labkit handin DIR -------------------------------------------------------------------------------------


def test_handin_exits_0_when_every_notebook_is_ready(folders, capsys):
    assert main(["handin", str(folders["solved"])]) == 0
    out = capsys.readouterr().out
    assert out.count("Ready to hand in? ") == 1 and "Ready to hand in: 1 of 1 notebook(s)" in out


def test_handin_prints_each_notebooks_table_and_exits_1_when_something_is_left(folders, half, tmp_path, capsys):
    mixed = tmp_path / "mixed"
    shutil.copytree(folders["half"], mixed)
    shutil.copy(folders["solved"] / NAME, mixed / "01_renamed_copy.ipynb")  # found by its last cell's call
    (mixed / "scratch.ipynb").write_text(nbformat.writes(nbformat.v4.new_notebook()))
    assert main(["handin", str(mixed)]) == 1
    captured = capsys.readouterr()
    assert half.text() in captured.out  # the same table as the notebook's last cell gives
    assert "Ready to hand in? 01_renamed_copy.ipynb (02_convergence.ipynb)" in captured.out
    assert "Not lab notebooks, not run: scratch.ipynb." in captured.out
    assert "Ready to hand in: 1 of 2 notebook(s)" in captured.out
    assert "running 02_convergence.ipynb" in captured.err


def test_handin_reports_a_notebook_whose_kernel_dies(folders, tmp_path, capsys):
    nb = nbformat.read(folders["solved"] / NAME, as_version=4)
    nb.cells.insert(2, nbformat.v4.new_code_cell("import os; os._exit(3)"))
    nbformat.write(nb, tmp_path / NAME)
    assert main(["handin", str(tmp_path)]) == 1
    out = capsys.readouterr().out
    assert "could not run it: DeadKernelError" in out and "Traceback" not in out


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda tmp: tmp / "missing", "there is no"),
        (lambda tmp: tmp, "holds no notebooks"),
        (lambda tmp: (tmp / "notes.txt", (tmp / "notes.txt").write_text("x"))[0], "holds no notebooks"),
        (
            lambda tmp: (
                tmp / "other.ipynb",
                (tmp / "other.ipynb").write_text(nbformat.writes(nbformat.v4.new_notebook())),
            )[0],
            "none of the notebooks",
        ),
    ],
    ids=["missing folder", "empty folder", "not a notebook", "not a lab notebook"],
)
def test_handin_refuses_bad_input_with_a_message(tmp_path, capsys, make, message):
    assert main(["handin", str(make(tmp_path))]) == 2
    err = capsys.readouterr().err
    assert err.startswith("labkit handin: ") and message in err and "Traceback" not in err


def test_handin_refuses_a_timeout_below_a_second(folders, capsys):
    assert main(["handin", str(folders["solved"]), "--timeout", "0"]) == 2
    assert "--timeout must be at least 1 second" in capsys.readouterr().err


# --- in this process: the function itself --------------------------------------------------------------------


def _namespace(name=NAME):
    """The names the solved notebook defines, its code run here (no kernel; magics and plots left out)."""
    import matplotlib

    matplotlib.use("Agg")
    namespace = {}
    for cell in nbformat.read(INSTRUCTOR / name, as_version=4).cells:
        if cell.cell_type == "code" and "explorer(" not in cell.source and "ready_to_hand_in" not in cell.source:
            exec("\n".join(x for x in cell.source.splitlines() if not x.startswith("%")), namespace)
    return namespace


def test_only_the_self_checks_run_never_the_grader(monkeypatch):
    namespace = _namespace()
    for module in [m for m in sys.modules if m == "labkit.grading" or m.startswith("labkit.grading.")]:
        monkeypatch.setitem(sys.modules, module, None)  # importing any of them now raises ImportError
    monkeypatch.setitem(sys.modules, "labkit.grading", None)
    seeds = []
    real = LAB.check
    monkeypatch.setattr(
        LAB, "check", lambda number, ns, seed=None, variant=None: seeds.append(seed) or real(number, ns, seed, variant)
    )
    result = labkit.ready_to_hand_in("02_convergence", namespace=namespace, path=INSTRUCTOR / NAME)
    assert set(_statuses(result).values()) == {DONE}
    assert seeds == [None, None]  # exercises 2 and 3, on the self-checks' fixed data (a seed draws the grader's)


def test_import_labkit_stays_light():
    import subprocess

    code = "import sys, labkit; print(sorted(m for m in sys.modules if m.startswith(('labkit.exercises', 'labkit.handin', 'labkit.grading', 'nbclient'))))"
    assert (
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "[]"
    )


def test_the_notebooks_own_names_are_read_by_default():
    namespace = _namespace()
    exec("import labkit\nresult = labkit.ready_to_hand_in('02_convergence.ipynb')", namespace)
    assert set(_statuses(namespace["result"]).values()) == {DONE}


def test_the_answers_are_read_from_the_working_folder(monkeypatch, tmp_path):
    shutil.copy(RELEASE / NAME, tmp_path / NAME)
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("JPY_SESSION_NAME", raising=False)
    result = labkit.ready_to_hand_in("02_convergence", namespace={})
    assert result.empty_answers == ["exercise 3: the order the table shows, against piecewise linear"]
    assert result.answers_from == f"in {NAME} as last saved"
    (tmp_path / NAME).unlink()  # not saved anywhere it can be found: said so, not guessed
    result = labkit.ready_to_hand_in("02_convergence", namespace={})
    assert result.empty_answers is None and "pass path=" in result.text()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"notebook": "07_secants"}, "not one of the lab's notebooks"),
        ({"notebook": "02_convergence", "namespace": [1, 2]}, "namespace must be a mapping"),
        ({"notebook": "02_convergence", "namespace": {}, "path": "/no/such/notebook.ipynb"}, "is not a file"),
    ],
)
def test_bad_arguments_say_what_to_give(kwargs, message):
    with pytest.raises(ValueError, match=message):
        labkit.ready_to_hand_in(**kwargs)


def test_the_cells_that_raised_are_noted_by_the_first_cells_hook(monkeypatch):
    """labkit.ready registers the hook; a cell that raised and then ran cleanly (same cell id) is dropped."""
    from IPython.core.interactiveshell import InteractiveShell

    monkeypatch.setattr(notebook, "CELLS", None)
    shell = InteractiveShell.instance()
    try:
        shell.run_cell('import labkit; labkit.ready("0.1")', cell_id="first")
        shell.run_cell("x = 1 / 0", cell_id="a")
        shell.run_cell("y = (", cell_id="b")  # raised before it ran
        shell.run_cell("z = undefined_name", cell_id="c")
        shell.run_cell("z = 2", cell_id="c")  # fixed and run again
        shell.run_cell("r = labkit.ready_to_hand_in('02_convergence', path=%r)" % str(INSTRUCTOR / NAME))
        result = shell.user_ns["r"]
    finally:
        shell.events.unregister("post_run_cell", notebook.CELLS)
        InteractiveShell.clear_instance()
    assert [(c.error, c.line) for c in result.raised] == [("ZeroDivisionError", 1), ("SyntaxError", 1)]
    assert "x = 1 / 0" in result.text() and "ZeroDivisionError: division by zero" in result.text()
    assert result.never_ran and "did not run in this kernel" in result.text()  # none of that notebook's cells ran


def _hand_in_after_running(path, skip=()):
    """The hand-in table of the saved notebook at `path` after its code cells ran in a fresh shell, each with its
    id as JupyterLab sends it (those at indices `skip` left out), its last cell, the hand-in call, last."""
    from IPython.core.interactiveshell import InteractiveShell

    cells = nbformat.read(path, as_version=4).cells
    shell = InteractiveShell.instance()
    try:
        for index, cell in enumerate(cells[:-1]):
            if cell.cell_type == "code" and index not in skip:
                shell.run_cell(cell.source.replace("%matplotlib inline", ""), cell_id=cell.id)
        call = f"r = labkit.ready_to_hand_in('02_convergence', path={str(path)!r})"
        shell.run_cell(call, cell_id=cells[-1].id)
        return shell.user_ns["r"]
    finally:
        shell.events.unregister("post_run_cell", notebook.CELLS)
        InteractiveShell.clear_instance()


def test_the_run_all_advice_appears_only_when_a_cell_did_not_run(monkeypatch):
    cells = nbformat.read(RELEASE / NAME, as_version=4).cells
    numbers = notebook.prompt_numbers(cells)
    code = sorted(numbers)
    for skip in [(), (code[-3], code[-2])]:
        monkeypatch.setattr(notebook, "CELLS", None)
        result = _hand_in_after_running(RELEASE / NAME, skip)
        assert result.raised  # the release's stubs raised, as in any Run All of it
        assert result.never_ran == [numbers[i] for i in skip]
        advice = (
            f"2 cell(s) of the saved notebook did not run in this kernel ([{numbers[code[-3]]}], [{numbers[code[-2]]}])"
        )
        assert (advice in result.text()) == bool(skip) and ("did not run" in result.text()) == bool(skip)


def test_a_stub_cell_leaves_its_names_not_started():
    names, stub = handin._assigned(
        "%matplotlib inline\nfig4, ax4 = plt.subplots()\n# YOUR CODE HERE\nraise NotImplementedError()"
    )
    assert stub and names == {"fig4", "ax4"}
    names, stub = handin._assigned("def f(x):\n    raise NotImplementedError()\ny = f(1)")
    assert not stub and names == {"f", "y"}  # the raise is in a function: the cell itself is not a stub


def test_a_result_survives_the_trip_out_of_the_kernel(half):
    again = handin.HandIn.from_dict(half.as_dict())
    assert again == half and again.text() == half.text() and re.search(r"^Ready to hand in\? 02_", again.text())


def test_where_nothing_is_seen_the_table_is_not_made(monkeypatch):
    """In the grader's sandbox (LABKIT_HEADLESS=1) the last cell runs no self-check: nobody reads it there."""
    import labkit.handin

    monkeypatch.setenv("LABKIT_HEADLESS", "1")
    calls = []
    monkeypatch.setattr(labkit.handin, "_parts", lambda *args: calls.append(args) or [])
    result = labkit.handin.ready_to_hand_in("02_convergence", namespace={})
    assert calls == [] and not result.ready and "not checked here" in repr(result)
    monkeypatch.delenv("LABKIT_HEADLESS")
    labkit.handin.ready_to_hand_in("02_convergence", namespace={})
    assert len(calls) == 1


# --- the folder's last lines: what it lacks, and whether that is needed ------------------------------------


@pytest.mark.parametrize(
    ("present", "needs"),
    [
        (["02_convergence.ipynb"], "needed by everyone: 01_limacon.ipynb"),
        (
            ["01_limacon.ipynb", "02_convergence.ipynb"],
            "a branch is still missing: 03_meshes, or 04_splines + 05_monotone",
        ),
        (["01_limacon.ipynb", "02_convergence.ipynb", "04_splines.ipynb"], "a branch is still missing"),
        (["01_limacon.ipynb", "02_convergence.ipynb", "03_meshes.ipynb"], "not needed: the mesh generation branch"),
        (["01_limacon.ipynb", "02_convergence.ipynb", "04_splines.ipynb", "05_monotone.ipynb"], "the splines branch"),
    ],
)
def test_the_folders_summary_names_the_missing_notebooks_and_knows_the_branches(present, needs):
    from labkit.handin_summary import folder_lines

    lines = folder_lines(present, 0)
    missing = sorted(set(LAB.notebooks()) - set(present))
    assert lines[0].startswith(f"Ready to hand in: 0 of {len(present)} notebook(s)")
    assert lines[-1].startswith(f"Not in this folder: {', '.join(missing)} (") and needs in lines[-1]
    # the branches are the rubric's: its exercises, in the notebooks the exercises declare
    for name, exercises in [("mesh generation", range(5, 10)), ("splines", range(10, 16))]:
        notebooks = sorted({LAB.exercises[n].notebook for n in exercises})
        assert f"{' + '.join(n[:-6] for n in notebooks)} ({name})" in lines[1]


def test_a_whole_folder_lacks_nothing():
    from labkit.handin_summary import folder_lines

    lines = folder_lines(sorted(LAB.notebooks()), 6)
    assert len(lines) == 2 and not any("Not in this folder" in line for line in lines)
