"""Every student their own lab (issue 34), end to end in the sandbox with the `labkit` command: three students
released and graded, each solution full marks on its own variant; a notebook copied to a fourth student flagged,
losing only its data-dependent part; edited metadata changing nothing; `labkit variants --check` over the lab."""

import csv
import html
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from conftest import sandbox_or_skip

from labkit.exercises import variants
from labkit.exercises.registry import LAB
from labkit.grading.authoring.release import release_notebook, with_values
from labkit.grading.store.report import file_stem

pytestmark = pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")
ROOT = Path(__file__).resolve().parents[3]
NOTEBOOKS = ROOT / "notebooks"
NOTEBOOK = "01_limacon.ipynb"
# the notebooks of exercises 3 (the Runge function's scale, and the tables on it: 15 too), 4, 7, 14 and 16
VARIED = ("01_limacon.ipynb", "02_convergence.ipynb", "03_meshes.ipynb", "05_monotone.ipynb", "06_bilinear.ipynb")
ROSTER = {"ada": "1815", "bob": "1816", "cy": "1817", "dan": "1818"}
ANOTHER = "another variant"


def _cli(*args, timeout=900):
    return subprocess.run(
        [sys.executable, "-m", "labkit.cli", *map(str, args)], capture_output=True, text=True, timeout=timeout, cwd=ROOT
    )


def _rows(out):
    with open(out / "grades.csv", newline="", encoding="utf-8") as handle:
        header, *rows = list(csv.reader(handle))
    return {row[0]: dict(zip(header, row)) for row in rows}


def _data_cell(nb):
    return next(c.source for c in nb.cells if variants.DATA_TAG in c.metadata.get("tags", []))


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    sandbox_or_skip()
    tmp = tmp_path_factory.mktemp("variants")
    secret = tmp / "course-variants.toml"
    assert _cli("variants", "--new", secret).returncode == 0
    roster = tmp / "roster.csv"
    roster.write_text("name,submission,id\n" + "".join(f"Student {n},{n},{i}\n" for n, i in ROSTER.items()))
    # two students may draw the same r0 (1 in 2501 for a pair): the instructor redraws one, as the docs say
    while True:
        found = variants.read(secret)
        values = {name: found.values(LAB, key) for name, key in ROSTER.items()}
        drawn = [v[4]["r0"] for v in values.values()]
        tied = [key for (name, key), r0 in zip(ROSTER.items(), drawn) if drawn.count(r0) > 1]
        if values["ada"][14]["boil"] == values["dan"][14]["boil"]:  # the copy must show another boiling point
            tied, number = ["1818"], 14
        elif values["ada"][3]["runge_a"] == values["dan"][3]["runge_a"]:  # and another Runge function
            tied, number = ["1818"], 3
        elif values["ada"][16]["runge2d_a"] == values["dan"][16]["runge2d_a"]:
            tied, number = ["1818"], 16
        elif not tied:
            break
        else:
            number = 4
        ran = _cli("variants", "--redraw", tied[-1], "--exercise", number, "--variants", secret, "--roster", roster)
        assert ran.returncode == 0 and "now has draw" in ran.stdout, ran.stderr
    released = tmp / "released"
    ran = _cli("release", NOTEBOOKS, "--out", released, "--roster", roster, "--variants", secret)
    assert ran.returncode == 0, ran.stderr
    submitted = tmp / "submitted"
    for name in ("ada", "bob", "cy"):  # each works the released notebooks: the solutions on their own data
        (submitted / name).mkdir(parents=True)
        for notebook in VARIED:
            solution = nbformat.read(NOTEBOOKS / notebook, as_version=4)
            nbformat.write(with_values(solution, values[name], notebook), submitted / name / notebook)
    # bob edits his notebook's metadata to claim ada's data, and strips the data cell's tag
    bob = nbformat.read(submitted / "bob" / NOTEBOOK, as_version=4)
    bob.metadata["labkit"] = {"variant": {"student": "1815", "r0": values["ada"][4]["r0"]}}
    for cell in bob.cells:
        if variants.DATA_TAG in cell.metadata.get("tags", []):
            cell.metadata["tags"] = []
            cell.metadata["labkit"] = {"r0": values["ada"][4]["r0"]}
    nbformat.write(bob, submitted / "bob" / NOTEBOOK)
    # dan hands in ada's notebooks, their metadata edited to name him
    (submitted / "dan").mkdir()
    for notebook in VARIED:
        dan = nbformat.read(submitted / "ada" / notebook, as_version=4)
        dan.metadata["labkit"] = {"variant": {"student": "1818", **values["dan"][4], **values["dan"][7]}}
        nbformat.write(dan, submitted / "dan" / notebook)
    out = tmp / "graded"
    folders = [submitted / n for n in ROSTER]
    ran = _cli("grade", *folders, "--out", out, "--roster", roster, "--variants", secret, "--seed", 34, "--quiet")
    assert ran.returncode in (0, 1), ran.stderr
    return {
        "tmp": tmp, "secret": secret, "roster": roster, "released": released, "values": values,
        "out": out, "folders": folders, "rows": _rows(out),
    }  # fmt: skip


@pytest.mark.slow  # starts a sandbox
def test_the_release_gives_each_student_a_folder_whose_notebooks_hold_their_own_data(course):
    common = {p.name: release_notebook(nbformat.read(p, as_version=4), p.name) for p in NOTEBOOKS.glob("*.ipynb")}
    for name, values in course["values"].items():
        folder = course["released"] / name
        assert sorted(p.name for p in folder.iterdir()) == sorted(common)
        for path in folder.iterdir():
            mine = nbformat.read(path, as_version=4)
            assert with_values(common[path.name], values, path.name) == mine  # only the data cells differ
            if path.name == NOTEBOOK:
                assert _data_cell(mine).startswith(f"r0 = {values[4]['r0']:.4f}  #")
                others = [c.source for c in mine.cells if variants.DATA_TAG not in c.metadata.get("tags", [])]
                assert not re.search(r"(?<![\d.])1\.15(?!\d)", "\n".join(others))  # the lab's r0 is nowhere else
            elif path.name == "05_monotone.ipynb":
                cell = _data_cell(mine)
                assert f"rise = {values[14]['rise']:.2f}  #" in cell and f"boil = {values[14]['boil']:.2f}  #" in cell
                scales = [c.source for c in mine.cells if c.source.startswith("runge_a = ")]
                assert len(scales) == 1 and scales[0].startswith(f"runge_a = {values[15]['runge_a']:.4f}  #")
            elif path.name in ("02_convergence.ipynb", "04_splines.ipynb"):
                assert _data_cell(mine).startswith(f"runge_a = {values[3]['runge_a']:.4f}  #")
            elif path.name == "06_bilinear.ipynb":
                assert _data_cell(mine).startswith(f"runge2d_a = {values[16]['runge2d_a']:.4f}  #")
            elif path.name == "03_meshes.ipynb":
                cell, quad = _data_cell(mine), values[7]
                assert f"xC = {quad['xC']:.2f}  #" in cell and f"yD = {quad['yD']:.2f}\n" in cell
                twist = (-2 + quad["xC"] - quad["xD"], quad["yC"] - quad["yD"])  # A - B + C - D, as the lab gives it
                assert f"twist7 = ({twist[0]:.2f}, {twist[1]:.2f})  #" in cell
            else:
                assert mine == common[path.name]  # nothing else differs from the class's release


@pytest.mark.slow  # starts a sandbox
def test_each_solution_earns_full_marks_on_its_own_variant_whatever_its_metadata_says(course):
    for name in ("ada", "bob", "cy"):
        row = course["rows"][name]
        for number in (2, 3, 4, 5, 6, 7, 8, 9, 14, 15, 16):  # 2, 5, 6, 8 and 9 do not vary: each beside one that does
            assert float(row[f"exercise {number}"]) == LAB.exercises[number].points, (number, row)
        feedback = (course["out"] / "feedback" / f"{file_stem(name)}.txt").read_text(encoding="utf-8")
        assert ANOTHER not in feedback


@pytest.mark.slow  # starts a sandbox
def test_a_copy_is_flagged_and_loses_only_its_data_dependent_part(course):
    row = course["rows"]["dan"]
    parts = {p.name: p.weight for p in LAB.exercises[4].parts}
    assert float(row["exercise 4"]) == parts["limacon_derivatives"], row  # the plot of ada's limaçon is lost
    assert float(row["exercise 14"]) == 0, row  # every part of the boiling plot is of ada's data
    assert float(row["exercise 7"]) == 0, row  # the straight quadrilateral is ada's
    for number in (2, 5, 6, 8, 9):  # the same for everyone: kept
        assert float(row[f"exercise {number}"]) == LAB.exercises[number].points, (number, row)
    # the tables (and runge) are of ada's Runge function; the drivers are checked on labkit's: kept
    for number, experiment in ((3, "pherm"), (15, "pchip"), (16, "bilinear")):
        driver = LAB.experiment(experiment).driver
        # the bilinear exercise's phi table and eval_pbilin do not depend on the data either
        same = {driver, "phi_table", "eval_pbilin"}
        kept = sum(p.weight for p in LAB.exercises[number].parts if p.name in same)
        assert float(row[f"exercise {number}"]) == kept, (number, row)
    feedback = (course["out"] / "feedback" / f"{file_stem('dan')}.txt").read_text(encoding="utf-8")
    assert "this notebook holds the data of another variant" in feedback
    ada, dan = course["values"]["ada"][4]["r0"], course["values"]["dan"][4]["r0"]
    assert f"r0 = {ada:g} where yours is {dan:g}" in feedback
    assert "exercise 14: this notebook holds the data of another variant (boil = " in feedback
    with open(course["out"] / "variants.csv", newline="", encoding="utf-8") as handle:
        rows = {row["submission"]: row for row in csv.DictReader(handle)}
    assert rows["dan"]["holds the data of"] == (  # the instructor's file
        "exercise 3: ada; exercise 4: ada; exercise 7: ada; exercise 14: ada; exercise 15: ada; exercise 16: ada"
    )
    assert rows["dan"]["id"] == "1818" and rows["dan"]["exercise 4"] == f"r0 = {dan}"
    assert [rows[n]["holds the data of"] for n in ("ada", "bob", "cy")] == ["", "", ""]
    assert not re.search(r"\bada\b", feedback)  # the student's feedback never names the classmate
    ran = _cli("report", course["out"])
    assert ran.returncode == 0, ran.stderr
    page = (course["out"] / "report.html").read_text(encoding="utf-8")
    assert "Another variant's data" in html.unescape(page)


@pytest.mark.slow  # starts a sandbox
def test_the_run_records_the_file_s_digest_and_each_student_s_data_never_the_secret(course):
    record = json.loads((course["out"] / "record.json").read_text(encoding="utf-8"))
    found = variants.read(course["secret"])
    assert record["variants"]["digest"] == found.digest
    assert record["variants"]["students"]["dan"] == {str(n): v for n, v in course["values"]["dan"].items()}
    assert found.secret.hex() not in (course["out"] / "record.json").read_text(encoding="utf-8")
    # resuming needs the same variants: without them, or with a redrawn student, the run is refused
    ran = _cli("grade", *course["folders"], "--out", course["out"], "--quiet")
    assert ran.returncode != 0 and "same --variants" in ran.stderr
    other = course["tmp"] / "other.toml"
    other.write_bytes(course["secret"].read_bytes())
    variants.redraw(other, "1816", 4, LAB)
    ran = _cli("grade", *course["folders"], "--out", course["out"], "--roster", course["roster"], "--variants", other)
    assert ran.returncode != 0 and "same --variants" in ran.stderr


@pytest.mark.slow  # starts a sandbox
def test_labkit_variants_check_passes_over_the_lab(course):
    ran = _cli(
        "variants", "--check", 2, "--variants", course["secret"], "--roster", course["roster"],
        "--catalog", ROOT / "tests" / "catalog.py", "--solutions", NOTEBOOKS,
    )  # fmt: skip
    assert ran.returncode == 0, ran.stdout + ran.stderr
    assert "every draw is as it should be" in ran.stdout and ran.stdout.count("draw ") >= 6


@pytest.mark.slow  # starts a sandbox
def test_a_roster_without_variants_or_the_reverse_is_refused_with_what_to_give(course):
    for command in (
        ["release", NOTEBOOKS, "--out", course["tmp"] / "x"],
        ["grade", *course["folders"], "--out", course["tmp"] / "y"],
    ):
        for extra in (["--roster", course["roster"]], ["--variants", course["secret"]]):
            ran = _cli(*command, *extra)
            assert ran.returncode != 0 and "give both --roster and --variants" in ran.stderr, ran.stderr
    ran = _cli("variants", "--show", "--variants", course["secret"])
    assert ran.returncode != 0 and "--show needs --roster" in ran.stderr


@pytest.mark.slow  # starts a sandbox
def test_a_resume_with_another_roster_and_a_merge_with_other_variants_are_refused(course):
    changed = course["tmp"] / "changed.csv"
    changed.write_text("submission,id\n" + "".join(f"{n},{i}\n" for n, i in ROSTER.items()).replace("1816", "9999"))
    ran = _cli("grade", *course["folders"], "--out", course["out"], "--roster", changed, "--variants", course["secret"])
    assert ran.returncode != 0 and "the roster gives bob other data" in ran.stderr, ran.stderr
    shrunk = course["tmp"] / "shrunk.csv"
    shrunk.write_text("submission,id\nada,1815\ncy,1817\ndan,1818\n")
    ran = _cli("grade", *course["folders"], "--out", course["out"], "--roster", shrunk, "--variants", course["secret"])
    assert ran.returncode != 0 and "the roster gives bob other data" in ran.stderr, ran.stderr
    # a merge keeps each student's data; runs graded without variants (or with others) are not merged with it
    merged = course["tmp"] / "merged"
    assert _cli("merge", course["out"], "--out", merged).returncode == 0
    record = json.loads((merged / "record.json").read_text(encoding="utf-8"))
    assert record["variants"] == json.loads((course["out"] / "record.json").read_text(encoding="utf-8"))["variants"]
    plain = course["tmp"] / "plain"
    ran = _cli("grade", course["folders"][0], "--out", plain, "--quiet")
    assert ran.returncode in (0, 1), ran.stderr
    ran = _cli("merge", course["out"], plain, "--out", course["tmp"] / "mixed")
    assert ran.returncode != 0 and "graded with different variants" in ran.stderr, ran.stderr
