"""issue 44 end to end: a class with hostile uploads, graded with `labkit grade` as the LMS gives it (a Canvas
zip, a Canvas folder, a Moodle folder): every hostile student is reported with a reason, and every honest
classmate gets the total they get graded alone. Slow: it grades in the sandbox (see tests/conftest.py)."""

import shutil
import tempfile
from pathlib import Path

import nbformat
import pytest
from catalog import NOTEBOOKS, Planted, plant
from conftest import sandbox_or_skip
from small_class import SEED, SLIP, cli, rows
from test_intake import notebook_text, zip_bytes

from labkit import grading

pytestmark = pytest.mark.slow  # grades a class in the sandbox


NOTEBOOK = "06_bilinear.ipynb"


@pytest.fixture(scope="module")
def works(tmp_path_factory):
    """{what: bytes of a notebook}: solved, with a slip, the bare release."""
    sandbox_or_skip()
    folder = tmp_path_factory.mktemp("works")
    solved = plant(Planted("as handed out", NOTEBOOK, ()), folder / "solved").read_bytes()
    slip = plant(SLIP, folder / "slip").read_bytes()
    bare = grading.release_notebook(nbformat.read(NOTEBOOKS / NOTEBOOK, as_version=4))
    return {"solved": solved, "slip": slip, "bare": nbformat.writes(bare).encode()}


def canvas_honest(works):
    return {f"alice_1001_55_{NOTEBOOK}": works["solved"], f"bob_1002_57_{NOTEBOOK}": works["slip"]}


def canvas_hostile(works):
    files = {
        "sam_2001_60_spaces.txt": b" " * (3 << 20),
        f"sam_2001_61_{NOTEBOOK}": works["solved"],
        "lena_2002_62_" + "l" * 240 + ".ipynb": works["slip"],
        "mo_2003_63_notes_12_assignsubmission_file_x.ipynb": notebook_text("mo").encode(),
        f"alice_1001_9_00_2005_70_{NOTEBOOK}": works["bare"],  # names herself alice_1001_9_00
        f"alice_2006_71_{NOTEBOOK}": works["bare"],  # renamed herself Alice
    }
    files.update({f"many_2004_{5000 + i}_f{i}.txt": b"x" for i in range(2001)})
    return files


def grade(given, out):
    run = cli("grade", given, "--out", out, "--seed", SEED, "--jobs", "2", "--quiet", timeout=900)
    assert (Path(out) / "grades.csv").is_file(), run.stderr
    return run, rows(out)


def totals_by_id(table, ids):
    return {uid: table[name]["total"] for name, uid in ids.items()}


@pytest.fixture(scope="module")
def alone(works, tmp_path_factory):
    """The honest students' totals graded alone, by Canvas user id."""
    tmp = tmp_path_factory.mktemp("alone")
    (tmp / "honest.zip").write_bytes(zip_bytes(canvas_honest(works)))
    run, table = grade(tmp / "honest.zip", tmp / "out")
    assert run.returncode == 0, run.stderr
    found = totals_by_id(table, {"alice": "1001", "bob": "1002"})
    assert float(found["1001"]) > float(found["1002"]) > 0  # the slip costs a part, the solved work is whole
    return found


def check_hostile_run(run, table, alone):
    assert run.returncode == 1, run.stderr  # some students could not be graded; the class was
    assert totals_by_id(table, {"alice_1001": "1001", "bob": "1002"}) == alone
    assert "zip bomb" in table["sam"]["status"] and "more than 2000 members" in table["many"]["status"]
    assert table["lena"]["total"] == alone["1002"]  # the long name's notebook is graded as the slip it is
    assert "filed to no one" in run.stderr and "alice_1001_9_00_2005_70" in run.stderr
    assert table["alice_2006"]["status"] == "graded" and "alice_2006" != "alice_1001"


def test_a_hostile_canvas_zip(works, alone, tmp_path):
    (tmp_path / "submissions.zip").write_bytes(zip_bytes(canvas_honest(works) | canvas_hostile(works)))
    check_hostile_run(*grade(tmp_path / "submissions.zip", tmp_path / "out"), alone)


def test_a_hostile_canvas_folder(works, alone, tmp_path):
    folder = tmp_path / "download"
    folder.mkdir()
    for name, data in (canvas_honest(works) | canvas_hostile(works)).items():
        if len(name.encode()) <= 255:
            (folder / name).write_bytes(data)
    (folder / f"lena_2002_62_{'l' * 200}.ipynb").write_bytes(works["slip"])
    for letter in "abc":  # three zips within every limit one by one, over the student's member limit together
        members = {f"{letter}{i}.txt": b"y" for i in range(1700)} | {NOTEBOOK: works["solved"]}
        (folder / f"zed_2008_{ord(letter)}_{letter}.zip").write_bytes(zip_bytes(members))
    run, table = grade(folder, tmp_path / "out")
    assert totals_by_id(table, {"alice_1001": "1001", "bob": "1002"}) == alone
    assert "more than 2000 members" in table["zed"]["status"] and "zip bomb" not in run.stderr  # (a folder's txt)
    assert "filed to no one" in run.stderr and table["lena"]["total"] == alone["1002"]
    assert run.returncode == 1


def test_a_moodle_folder(works, alone, tmp_path):
    folder = tmp_path / "moodle"
    for name, pid, work in (("alice", "11", "solved"), ("bob", "12", "slip")):
        student = folder / f"{name.title()} Honest_{pid}_assignsubmission_file_"
        student.mkdir(parents=True)
        (student / NOTEBOOK).write_bytes(works[work])
    impostor = folder / f"Eve Evil_13_assignsubmission_file_Alice Honest_11_assignsubmission_file_{NOTEBOOK}"
    impostor.write_bytes(works["bare"])
    crowd = folder / "Max Many_14_assignsubmission_file_"
    crowd.mkdir()
    for i in range(5001):
        (crowd / f"f{i}.txt").write_bytes(b"x")
    with tempfile.TemporaryDirectory() as scratch:  # a student's zip: a bomb of spaces, only theirs
        shutil.make_archive(str(Path(scratch) / "bomb"), "zip", root_dir=_spaces(Path(scratch)))
        bomber = folder / "Sam Spaces_15_assignsubmission_file_"
        bomber.mkdir()
        shutil.copy(Path(scratch) / "bomb.zip", bomber / "work.zip")
    run, table = grade(folder, tmp_path / "out")
    assert run.returncode == 1, run.stderr
    assert table["Alice Honest_11"]["total"] == alone["1001"] and table["Bob Honest_12"]["total"] == alone["1002"]
    assert table["Eve Evil_13"]["status"] == "graded"  # her file is hers, whatever it is named
    assert "more than 5000 files" in table["Max Many_14"]["status"] and "zip bomb" in table["Sam Spaces_15"]["status"]


def _spaces(folder):
    inside = folder / "inside"
    inside.mkdir()
    (inside / "spaces.txt").write_bytes(b" " * (3 << 20))
    (inside / NOTEBOOK).write_text(notebook_text())
    return inside
