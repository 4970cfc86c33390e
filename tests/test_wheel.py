"""labkit outside this repository: the wheel in a fresh venv with only the core dependencies.

Builds the wheel, installs it into a new virtual environment (no JupyterLab, no
nbclient), and there: ``labkit notebooks`` writes the student notebooks, each
runs with a plain ipykernel up to its first stub, the instructor notebooks run
to the end, ``import labkit`` pulls in nothing of JupyterLab's, and the
instructor's commands say which extra they need, then work once it is there.
The notebooks are driven by nbclient from this test's own environment.
"""

import os
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

pytestmark = pytest.mark.slow  # builds and installs a wheel

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
KERNEL = "labkit-fresh-venv"


def _run(*argv, timeout=900, **kwargs):
    run = subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=timeout, **kwargs)
    return run


@pytest.fixture(scope="module")
def fresh(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    built = _run(sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", tmp / "dist", ROOT)
    assert built.returncode == 0, built.stderr[-3000:]
    wheel = next((tmp / "dist").glob("labkit-*.whl"))
    venv = tmp / "venv"
    assert _run(sys.executable, "-m", "venv", venv).returncode == 0
    python = venv / "bin" / "python"
    start = time.perf_counter()
    installed = _run(python, "-m", "pip", "install", "--quiet", wheel)
    seconds = time.perf_counter() - start
    assert installed.returncode == 0, installed.stderr[-3000:]
    print(
        f"\nwheel {wheel.name}: {wheel.stat().st_size / 1024:.0f} KiB; core install into a fresh venv {seconds:.1f} s"
    )
    kernels = tmp / "kernels"
    spec = _run(python, "-m", "ipykernel", "install", "--prefix", kernels, "--name", KERNEL)
    assert spec.returncode == 0, spec.stderr
    return {
        "tmp": tmp,
        "wheel": wheel,
        "python": python,
        "bin": venv / "bin",
        "jupyter_path": kernels / "share" / "jupyter",
    }


def test_the_wheel_ships_the_student_notebooks_and_no_solved_one(fresh):
    names = zipfile.ZipFile(fresh["wheel"]).namelist()
    shipped = sorted(Path(n).name for n in names if n.endswith(".ipynb"))
    assert shipped == [p.name for p in NOTEBOOKS]
    assert all(n.startswith("labkit/student_notebooks/") for n in names if n.endswith(".ipynb"))
    for name in names:
        if name.endswith(".ipynb"):
            text = zipfile.ZipFile(fresh["wheel"]).read(name).decode()
            assert "### BEGIN SOLUTION" not in text and "### BEGIN HIDDEN TESTS" not in text
    assert "labkit/grading/store/rubric.toml" in names and "labkit/plots/editor.js" in names
    assert "labkit/py.typed" in names  # PEP 561: type checkers read labkit's annotations
    # the pages' templates, stylesheets and scripts (labkit.grading.pages): the feedback page labkit grade renders for
    # each student, the class report (labkit report) and the marking page (labkit mark)
    pages = ["feedback.html", "feedback.css", "class_report.html", "class_report.css", "class_report.js"]
    pages += ["marking.html", "marking_parts.html", "marking.css", "marking.js", "feedback.txt"]
    assert {f"labkit/grading/templates/{name}" for name in pages} <= set(names)


def test_the_core_install_has_no_jupyterlab_and_import_labkit_pulls_none_in(fresh):
    for package in ("jupyterlab", "nbclient", "notebook", "jupyter_server"):
        assert _run(fresh["python"], "-c", f"import {package}").returncode != 0, f"{package} came with the core"
    code = (
        "import sys, labkit, labkit.check, labkit.plots\n"
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'jupyterlab', 'nbclient', 'nbformat'}))"
    )
    run = _run(fresh["python"], "-c", code)
    assert run.returncode == 0 and run.stdout.strip() == "[]", run.stderr


def _client(nb, folder, fresh, monkeypatch):
    monkeypatch.setenv("JUPYTER_PATH", str(fresh["jupyter_path"]))
    return NotebookClient(nb, timeout=300, kernel_name=KERNEL, resources={"metadata": {"path": str(folder)}})


@pytest.fixture(scope="module")
def student_folder(fresh):
    folder = fresh["tmp"] / "lab"
    run = _run(fresh["bin"] / "labkit", "notebooks", folder)
    assert run.returncode == 0, run.stderr
    return folder


@pytest.mark.parametrize("name", [p.name for p in NOTEBOOKS])
def test_each_student_notebook_runs_to_the_end_past_its_stubs(fresh, student_folder, name, monkeypatch):
    # with the wheel alone installed, Run All of an untouched student copy reaches its last cell (its explorers):
    # the cells that raise are the release's tagged ones, and the first to raise is a stub's NotImplementedError
    nb = nbformat.read(student_folder / name, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    first_stub = next(i for i, c in enumerate(code) if "raise NotImplementedError()" in c.source)
    _client(nb, student_folder, fresh, monkeypatch).execute()
    assert all(c.execution_count for c in code)
    raised = [i for i, c in enumerate(code) if any(o.output_type == "error" for o in c.outputs)]
    assert raised and raised[0] >= first_stub
    assert [o.ename for o in code[raised[0]].outputs if o.output_type == "error"] == ["NotImplementedError"]
    assert all("raises-exception" in code[i].metadata.get("tags", []) for i in raised)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_the_instructor_notebooks_run_to_the_end_there(fresh, path, tmp_path, monkeypatch):
    nb = nbformat.read(path, as_version=4)
    _client(nb, tmp_path, fresh, monkeypatch).execute()
    assert all(c.execution_count for c in nb.cells if c.cell_type == "code")


def test_instructor_commands_name_their_extra_then_work_with_it(fresh, tmp_path):
    labkit = fresh["bin"] / "labkit"
    run = _run(labkit, "release", ROOT / "notebooks", "--out", tmp_path / "student")
    assert run.returncode == 2 and "pip install 'labkit[grade]'" in run.stderr, run.stderr
    extra = _run(fresh["python"], "-m", "pip", "install", "--quiet", f"labkit[grade] @ {fresh['wheel'].as_uri()}")
    assert extra.returncode == 0, extra.stderr[-3000:]
    run = _run(labkit, "release", ROOT / "notebooks", "--out", tmp_path / "student")
    assert run.returncode == 0, run.stderr
    assert sorted(p.name for p in (tmp_path / "student").glob("*.ipynb")) == [p.name for p in NOTEBOOKS]
    copy = tmp_path / "instructor"
    copy.mkdir()
    (copy / "06_bilinear.ipynb").write_bytes((ROOT / "notebooks" / "06_bilinear.ipynb").read_bytes())
    env = {**os.environ, "JUPYTER_PATH": ""}
    run = _run(labkit, "execute", copy, env=env)
    assert run.returncode == 0, run.stderr[-3000:]
    executed = nbformat.read(copy / "06_bilinear.ipynb", as_version=4)
    assert all(c.execution_count for c in executed.cells if c.cell_type == "code")
