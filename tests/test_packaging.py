"""Packaging: the dependency layout, the student notebooks shipped in the package, one repository URL."""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import nbformat
import pytest
import yaml

from labkit.grading import release_notebook
from labkit.student_notebooks import paths

pytestmark = pytest.mark.slow  # builds the package

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
REPOSITORY = PROJECT["urls"]["Repository"]


def _normalise(requirement):
    return re.sub(r"\s+", "", requirement).lower()


def test_environment_yml_is_the_core_plus_the_lab_extra():
    conda = yaml.safe_load((ROOT / "environment.yml").read_text())["dependencies"]
    conda_packages = {_normalise(d) for d in conda if isinstance(d, str)}
    conda_packages -= {"pip"} | {d for d in conda_packages if d.startswith("python")}
    wanted = PROJECT["dependencies"] + PROJECT["optional-dependencies"]["lab"]
    assert conda_packages == {_normalise(d) for d in wanted}


def test_environment_yml_python_matches_requires_python():
    conda = yaml.safe_load((ROOT / "environment.yml").read_text())["dependencies"]
    assert f"python{PROJECT['requires-python']}" in conda


def test_the_core_is_light_and_the_extras_hold_the_rest():
    core = {re.split(r"[<>=;\[ ]", d)[0].lower() for d in PROJECT["dependencies"]}
    assert core == {"numpy", "scipy", "matplotlib", "ipywidgets", "anywidget", "meshio", "ipykernel"}
    extras = PROJECT["optional-dependencies"]
    assert [d.split(">")[0] for d in extras["lab"]] == ["jupyterlab"]
    assert {d.split(">")[0] for d in extras["grade"]} == {
        "nbformat",
        "nbclient",
        "rich",
        "latex2mathml",
        "jinja2",
    }
    assert "labkit[lab,grade]" in extras["test"] and any(d.startswith("nbgrader") for d in extras["test"])
    assert "'.[lab,grade,test]'" in (ROOT / "Makefile").read_text()


def test_import_labkit_needs_neither_jupyterlab_nor_nbclient():
    code = (
        "import sys, labkit, labkit.check, labkit.plots\n"
        "heavy = sorted({m.split('.')[0] for m in sys.modules} & {'jupyterlab', 'nbclient', 'nbformat', "
        "'jupyter_server', 'notebook', 'nbconvert'})\n"
        "print(heavy)"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and run.stdout.strip() == "[]", run.stdout + run.stderr


def test_the_packaged_student_notebooks_are_the_release_of_the_instructor_notebooks():
    packaged = paths()
    assert [p.name for p in packaged] == [p.name for p in NOTEBOOKS]
    for source, shipped in zip(NOTEBOOKS, packaged):
        expected = nbformat.writes(release_notebook(nbformat.read(source, as_version=4), source.name)) + "\n"
        assert shipped.read_text() == expected, f"{shipped.name} is stale: run `make notebooks`"
        text = shipped.read_text()
        for marker in ("BEGIN SOLUTION", "END SOLUTION", "BEGIN HIDDEN TESTS", "assert labkit.check"):
            assert marker not in text, (shipped.name, marker)
        nb = nbformat.reads(text, as_version=4)
        assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code")


def test_no_solved_notebook_is_part_of_the_package():
    shipped = [p for p in (ROOT / "labkit").rglob("*.ipynb")]
    assert sorted(p.name for p in shipped) == [p.name for p in NOTEBOOKS]
    for path in shipped:
        assert "### BEGIN SOLUTION" not in path.read_text() and "### BEGIN HIDDEN TESTS" not in path.read_text()


def test_labkit_notebooks_writes_them_and_never_overwrites_work(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "notebooks", str(tmp_path / "lab")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    assert sorted(p.name for p in (tmp_path / "lab").iterdir()) == [p.name for p in NOTEBOOKS]
    (tmp_path / "lab" / "01_limacon.ipynb").write_text("my work")
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "notebooks", str(tmp_path / "lab")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 2 and "already exists" in run.stderr
    assert (tmp_path / "lab" / "01_limacon.ipynb").read_text() == "my work"


@pytest.mark.parametrize("command", ["execute", "release"])
def test_instructor_commands_take_the_instructor_folder(command, tmp_path):
    run = subprocess.run([sys.executable, "-m", "labkit.cli", command], capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and "notebooks" in run.stderr  # the folder is required: no repository is assumed


def test_one_repository_url_for_the_badges_and_the_install_line():
    readme = (ROOT / "README.md").read_text()
    students = (ROOT / "docs" / "students.md").read_text()  # the install lines for each front end
    owner_repo = REPOSITORY.removeprefix("https://github.com/")
    assert f"https://mybinder.org/v2/gh/{owner_repo}/HEAD" in readme
    assert f"https://colab.research.google.com/github/{owner_repo}/blob/main/labkit/student_notebooks/" in readme
    assert f'%pip install "labkit @ git+{REPOSITORY}"' in readme
    assert f'%pip install "labkit @ git+{REPOSITORY}"' in students
    assert f'pip install "labkit[grade] @ git+{REPOSITORY}"' in students

    def repositories(text):
        return set(
            re.findall(
                r"https://(?:github\.com|mybinder\.org/v2/gh|colab\.research\.google\.com/github)/"
                r"([\w.-]+/[\w.-]+)",
                text,
            )
        )

    assert repositories(readme) == {owner_repo}, repositories(readme)
    for path in [ROOT / "CHANGELOG.md", *sorted((ROOT / "docs").glob("*.md"))]:  # no other repository anywhere
        assert repositories(path.read_text()) <= {owner_repo}, (path.name, repositories(path.read_text()))
    for path in NOTEBOOKS + paths():
        assert (
            f'%pip install \\"labkit @ git+{REPOSITORY}\\"' in Path(path).read_text()
            or f'%pip install "labkit @ git+{REPOSITORY}"' in Path(path).read_text()
        ), path


def test_the_sandboxed_worker_imports_none_of_the_graders_tools():
    # every notebook starts a worker: what it imports is paid once per notebook graded
    code = (
        "import sys, labkit.grading.sandbox.worker\n"
        "print(sorted({m for m in sys.modules} & {'nbformat', 'nbclient', 'labkit.grading.run.classrun', "
        "'labkit.grading.submission.scoring', 'labkit.grading.store.report', 'concurrent.futures.process'}))"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and run.stdout.strip() == "[]", run.stdout + run.stderr
    from labkit import grading

    assert (
        callable(grading.release)
        and callable(grading.grade)
        and grading.store.report.safe_name("a b").startswith("a_b-")
    )


def test_every_package_of_labkit_is_in_the_wheel():
    listed = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    found = sorted(".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "labkit").rglob("__init__.py"))
    assert "labkit.grading.sandbox.backends" in found
    assert sorted(listed) == found
