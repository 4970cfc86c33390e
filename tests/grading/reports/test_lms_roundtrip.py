"""From the LMS's download to the LMS's upload, with the commands docs/instructors.md shows, run as they stand.

A Canvas download zip (a late student, a student who uploaded a zip, a re-upload) and a Moodle folder (a late
student, an extension, a zipped submission, a folder with no notebook) are graded under a course rubric with a
[late] table and the LMS's times; a notebook is replaced and the class command resumes; one student is graded
again alone and merged; the report and the export read the run's record without --rubric. At the end every
exported number is grades.csv's total, and grades.csv is what a fresh run under the same rubric and seed gives.
"""

import csv
import os
import re
import shlex
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import nbformat
import pytest
from catalog import NOTEBOOKS, Planted, plant
from conftest import sandbox_or_skip
from docs_markdown import DOCS
from small_class import SLIP

from labkit import grading
from labkit.grading.store import late

DEADLINE = "2026-12-01T23:59:00+01:00"
COURSE = f'''title = "Lab 8 with a deadline"
required = [2, 3, 4]
extra_credit = [16]

[branches]
extra_credit = 10

[[branches.choice]]
name = "mesh generation"
exercises = [5, 6, 7, 8, 9]

[[branches.choice]]
name = "splines"
exercises = [10, 11, 12, 13, 14, 15]

[late]
deadline = "{DEADLINE}"
per = "day"
percent = 10
cap = 50
grace = 15

[late.extensions]
"Fay Fourier_106" = 48
'''
SOLVED = Planted("as handed out", "06_bilinear.ipynb", ())
MOODLE = {  # student -> (what they handed in, when: hours after the deadline)
    "Ada Lovelace_101": ("solved", -2),
    "Bob Babbage_102": ("slip", -1),
    "Carol Cauchy_103": ("zip", 0.1),  # within the grace
    "Dave Dirichlet_104": ("pdf", -3),
    "Eve Euler_105": ("solved", 30),  # two started days late
    "Fay Fourier_106": ("solved", 40),  # late, but within her 48-hour extension
}
CANVAS = {  # login -> (user id, what, hours late, Canvas's LATE marker)
    "lovelaceada": ("1815", "solved", -5, False),
    "hoppergrace": ("1906", "solved", 50, True),  # three started days late
    "turingalan": ("1912", "zip", -1, False),
}


def _commands():
    """The bash block of the section "From the LMS download to the LMS upload" of docs/instructors.md."""
    text = (DOCS / "instructors.md").read_text(encoding="utf-8")
    section = text.split("## From the LMS download to the LMS upload", 1)[1]
    block = re.search(r"```bash\n(.*?)```", section, re.S).group(1)
    steps, comment = [], ""
    for line in block.splitlines():
        if line.startswith("#"):
            comment = line
        elif line.strip():
            steps.append((comment, line))
    return steps


def _notebook(what, folder):
    folder.mkdir(parents=True, exist_ok=True)
    return plant(SOLVED if what != "slip" else SLIP, folder)


def _time(hours):
    from datetime import timedelta

    return late.time_text(late.parse_deadline(DEADLINE) + timedelta(hours=hours))


def _lay_out(root):
    """The files the commands name, in `root`."""
    scratch = root / "scratch"
    (root / "course.toml").write_text(COURSE)
    moodle = root / "moodle-submissions"
    for name, (what, _) in MOODLE.items():
        folder = moodle / f"{name}_assignsubmission_file_"
        folder.mkdir(parents=True)
        if what == "pdf":
            (folder / "notes.pdf").write_bytes(b"%PDF-1.4 my notes")
        elif what == "zip":
            made = _notebook("solved", scratch / name)
            with zipfile.ZipFile(folder / "work.zip", "w") as archive:
                archive.write(made, "lab/06_bilinear.ipynb")
        else:
            shutil.copy(_notebook(what, scratch / name), folder / "06_bilinear.ipynb")
    with open(root / "moodle-times.csv", "w", newline="") as handle:  # the LMS's export: other columns too
        writer = csv.writer(handle)
        writer.writerow(["submission", "time", "status"])
        writer.writerows([name, _time(hours), "Submitted"] for name, (what, hours) in MOODLE.items())
    (root / "moodle-roster.csv").write_text(
        "name,submission,id\n" + "".join(f"{n.split('_')[0]},{n},S{n[-3:]}\n" for n in MOODLE)
    )
    with zipfile.ZipFile(root / "canvas-submissions.zip", "w") as archive:
        for login, (uid, what, _, marked) in CANVAS.items():
            prefix = f"{login}{'_LATE' if marked else ''}_{uid}_{int(uid) * 7}"
            made = _notebook("slip" if what == "zip" else what, scratch / login)
            if what == "zip":
                inner = scratch / f"{login}.zip"
                with zipfile.ZipFile(inner, "w") as own:
                    own.write(made, "06_bilinear.ipynb")
                archive.write(inner, f"{prefix}_work.zip")
            else:
                stale = grading.release_notebook(nbformat.read(NOTEBOOKS / "06_bilinear.ipynb", as_version=4))
                stale_path = scratch / f"{login}-stale.ipynb"
                nbformat.write(stale, stale_path)
                archive.write(stale_path, f"{prefix}_06_bilinear.ipynb")  # the first upload
                newer = f"{login}{'_LATE' if marked else ''}_{uid}_{int(uid) * 7 + 1}"  # Canvas's file ids grow
                archive.write(made, f"{newer}_06_bilinear-1.ipynb")  # the re-upload: the one that counts
    (root / "canvas-times.csv").write_text(
        "submission,time\n" + "".join(f"{login},{_time(c[2])}\n" for login, c in CANVAS.items())
    )
    (root / "canvas-roster.csv").write_text(
        "submission,id\n" + "".join(f"{login},{uid}\n" for login, (uid, *_) in CANVAS.items())
    )
    (root / "gradebook.csv").write_text(
        "Student,ID,SIS User ID,SIS Login ID,Section,Lab 7 (41),Lab 8 (42),Current Score\n"
        "    Points Possible,,,,,10,100,(read only)\n"
        + "".join(f"{login},{uid},,{login}@uni.example,A,9,,90\n" for login, (uid, *_) in CANVAS.items())
    )
    shutil.rmtree(scratch)


def _bash(line, cwd):
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    return subprocess.run(
        ["bash", "-c", line], cwd=cwd, env=env, capture_output=True, text=True,
        timeout=600,
    )  # fmt: skip


def _rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return {row["submission"]: row for row in csv.DictReader(handle)}


def _snapshot(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(Path(folder).rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def class_run(tmp_path_factory):
    sandbox_or_skip()
    root = tmp_path_factory.mktemp("lms")
    _lay_out(root)
    given = _snapshot(root)
    runs = []
    for comment, line in _commands():
        if "replaced a notebook" in comment:  # Bob hands in a corrected notebook before the resumed command
            target = root / "moodle-submissions" / "Bob Babbage_102_assignsubmission_file_" / "06_bilinear.ipynb"
            shutil.copy(_notebook("solved", root / "scratch-bob"), target)
            shutil.rmtree(root / "scratch-bob")
            given = {**given, target.relative_to(root): target.read_bytes()}
        run = _bash(line, root)
        runs.append((line, run))
    return root, given, runs


def _run_of(runs, start):
    return [run for line, run in runs if line.startswith(start)]


@pytest.mark.slow  # starts a sandbox
def test_the_docs_commands_ran_and_never_wrote_into_what_the_lms_gave(class_run):
    root, given, runs = class_run
    assert len(runs) == 9
    for line, run in runs:
        assert run.returncode in (0, 1), (line, run.stderr)
        assert "Traceback" not in run.stderr, (line, run.stderr)
    now = _snapshot(root)
    assert {path: now[path] for path in given} == given  # the LMS's files are as they were
    assert not [p for p in root.rglob(".labkit-unpacked-*")]  # the grader's own unpacking is gone


@pytest.mark.slow  # starts a sandbox
def test_canvas_students_are_found_in_the_zip_and_the_export_is_grades_csvs_total(class_run):
    root, _, runs = class_run
    rows = _rows(root / "canvas-grades" / "grades.csv")
    assert sorted(rows) == sorted(CANVAS)  # one row per student, whatever files they uploaded
    assert rows["lovelaceada"]["total"] == "8" and rows["lovelaceada"]["lateness"] == "on time"
    assert rows["hoppergrace"]["raw total"] == "8" and rows["hoppergrace"]["penalty"] == "2.4"  # 3 days, 30%
    assert rows["hoppergrace"]["time source"] == late.FROM_CSV and rows["hoppergrace"]["total"] == "5.6"
    assert rows["turingalan"]["total"] == "7"  # the zip a student uploaded was opened, and the slip costs 1
    exported = list(csv.reader(open(root / "canvas-grades-canvas.csv", newline="", encoding="utf-8")))
    column = exported[0].index("Lab 8 (42)")
    by_id = {row[1]: row[column] for row in exported[2:]}
    assert {login: by_id[uid] for login, (uid, *_) in CANVAS.items()} == {n: r["total"] for n, r in rows.items()}
    (report,) = _run_of(runs, "labkit report canvas-grades/")
    assert report.returncode == 0 and (root / "canvas-grades" / "report.html").exists()


@pytest.mark.slow  # starts a sandbox
def test_moodle_student_without_a_notebook_is_not_graded_and_gets_no_number(class_run):
    root, _, runs = class_run
    rows = _rows(root / "moodle-final" / "grades.csv")
    assert rows["Dave Dirichlet_104"]["total"] == ""
    assert rows["Dave Dirichlet_104"]["status"] == "not graded: holds no notebook (it holds notes.pdf)"
    first = _run_of(runs, "labkit grade moodle-submissions/ --rubric")[0]
    assert first.returncode == 1 and "could not grade Dave Dirichlet_104: holds no notebook" in first.stderr
    exported = list(csv.reader(open(root / "moodle-final-moodle.csv", newline="", encoding="utf-8")))
    assert "S104" not in [row[0] for row in exported]  # no number, never a zero


@pytest.mark.slow  # starts a sandbox
def test_late_work_extension_and_grace_are_what_grades_csv_and_the_export_say(class_run):
    root, _, _ = class_run
    rows = _rows(root / "moodle-final" / "grades.csv")
    assert rows["Eve Euler_105"]["penalty"] == "1.6" and rows["Eve Euler_105"]["total"] == "6.4"  # 2 days, 20%
    assert rows["Fay Fourier_106"]["lateness"] == "on time" and rows["Fay Fourier_106"]["total"] == "8"
    assert rows["Carol Cauchy_103"]["lateness"].startswith("on time (within the 15-minute grace)")
    assert rows["Carol Cauchy_103"]["total"] == "8"  # her work.zip was opened
    exported = list(csv.reader(open(root / "moodle-final-moodle.csv", newline="", encoding="utf-8")))
    header, *lines = exported
    assert header == ["ID number", "Lab 8", "Feedback"]
    by_id = {line[0]: line for line in lines}
    for name, row in rows.items():
        if row["total"]:
            assert by_id[f"S{name[-3:]}"][1] == row["total"]
            assert by_id[f"S{name[-3:]}"][2].startswith(f"{row['total']} points")  # the feedback agrees
    assert "late" in by_id["S105"][2]  # Moodle's feedback states the penalty


@pytest.mark.slow  # starts a sandbox
def test_the_resumed_command_grades_again_only_the_changed_notebook(class_run):
    root, _, runs = class_run
    (again,) = _run_of(runs, "labkit grade moodle-submissions/ --out moodle-grades/")
    assert again.returncode == 1  # Dave still has nothing to grade
    assert "resumed" in again.stdout and "1 of them graded again because their notebooks changed" in again.stdout
    assert "4 submission(s) were graded there already and kept" in again.stdout
    rows = _rows(root / "moodle-grades" / "grades.csv")
    assert rows["Bob Babbage_102"]["total"] == "8"  # his corrected notebook, graded under the recorded rubric
    assert rows["Eve Euler_105"]["total"] == "6.4"  # the late rule was not forgotten by the resumed command


@pytest.mark.slow  # starts a sandbox
def test_the_regrade_replaces_one_result_and_the_merge_equals_a_fresh_run(class_run, tmp_path):
    root, _, runs = class_run
    (merge,) = _run_of(runs, "labkit merge")
    assert merge.returncode == 1 and "1 result(s) replaced" in merge.stdout and "Ada Lovelace_101" in merge.stdout
    final = _rows(root / "moodle-final" / "grades.csv")
    seed = (root / "moodle-grades" / "seed.txt").read_text().strip()
    fresh = _bash(
        "labkit grade moodle-submissions/ --rubric course.toml --times moodle-times.csv "
        f"--seed {seed} --out {shlex.quote(str(tmp_path / 'fresh'))} --quiet",
        root,
    )
    assert fresh.returncode == 1, fresh.stderr
    assert _rows(tmp_path / "fresh" / "grades.csv") == final
    (report,) = _run_of(runs, "labkit report moodle-final/")
    assert report.returncode == 0, report.stderr
    html = (root / "moodle-final" / "report.html").read_text()
    assert "Lab 8 with a deadline" in html and "Eve Euler_105" in html
