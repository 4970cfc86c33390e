"""The conda environment and the pip metadata must ask for the same packages."""
import re
import tomllib
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def _normalise(requirement):
    return re.sub(r"\s+", "", requirement).lower()


def test_environment_yml_lists_the_runtime_dependencies_of_pyproject():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    conda = yaml.safe_load((ROOT / "environment.yml").read_text())["dependencies"]
    conda_packages = {_normalise(d) for d in conda if isinstance(d, str)}
    conda_packages -= {"pip"} | {d for d in conda_packages if d.startswith("python")}
    assert conda_packages == {_normalise(d) for d in project["dependencies"]}


def test_environment_yml_python_matches_requires_python():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    conda = yaml.safe_load((ROOT / "environment.yml").read_text())["dependencies"]
    assert f"python{project['requires-python']}" in conda
