"""Regrading one student (nbgrader#1858), end to end in the sandbox, as docs/instructors.md tells it: a class of
two graded with a late rule, one notebook fixed and graded again into a folder of its own, the two runs merged
(the later result replaces the earlier one), and results of another rubric or another labkit version refused."""

import csv
import json
import os
import shutil
import subprocess
import sys

import pytest
from catalog import MISTAKES, Planted, plant
from conftest import sandbox_or_skip

from labkit.grading.store import late
from labkit.grading.store import rubric as rubrics
from labkit.grading.store.report import SubmissionGrade, file_stem, safe_name, write_report

pytestmark = pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")
SEED = "4242"
RUBRIC = """title = "bilinear, with a deadline"
required = [16]

[late]
deadline = "2026-12-01T23:59:00+01:00"
per = "day"
percent = 10
cap = 50
"""
SLIP = next(entry for entry in MISTAKES if entry.name == "phi_corners_numbered_clockwise")  # costs phi_table, 1 of 8


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "labkit.cli", *args], capture_output=True, text=True, timeout=300)


def _submission(folder, entry, timestamp):
    plant(entry, folder)
    (folder / "timestamp.txt").write_text(timestamp)  # as nbgrader's exchange writes it
    return folder


def _rows(out):
    with open(out / "grades.csv", newline="", encoding="utf-8") as handle:
        header, *rows = list(csv.reader(handle))
    return {row[0]: dict(zip(header, row)) for row in rows}


@pytest.fixture(scope="module")
def regraded(tmp_path_factory):
    sandbox_or_skip()
    tmp = tmp_path_factory.mktemp("regrade")
    rubric = tmp / "course.toml"
    rubric.write_text(RUBRIC)
    correct = Planted("as handed out", "06_bilinear.ipynb", ())
    alice = _submission(tmp / "submitted" / "alice", SLIP, "2026-12-01 21:00:00.000000 UTC")  # on time
    # bob's folder came by e-mail with a timestamp.txt of his own; the times file has when it really came
    bob = _submission(tmp / "submitted" / "bob", correct, "2026-12-01 20:00:00.000000 UTC")
    times = tmp / "times.csv"
    times.write_text("submission,time\nbob,2026-12-02 10:30:00.250000 UTC\n")  # 11 h 31 min late
    # 1. the class, graded with the course's rubric (no --quiet: its output is not a terminal here)
    first = _cli(
        "grade", str(alice), str(bob), "--out", str(tmp / "class"), "--rubric", str(rubric), "--seed", SEED,
        "--times", str(times), "--times-from-submission",
    )  # fmt: skip
    assert first.returncode == 0, first.stderr
    # 2. alice's notebook fixed (say the collected copy was damaged), graded alone into a folder of its own
    fixed = tmp / "fixed" / "alice"
    plant(correct, fixed)
    shutil.copy(alice / "timestamp.txt", fixed / "timestamp.txt")
    again = _cli(
        "grade", str(fixed), "--out", str(tmp / "regrade-alice"), "--rubric", str(rubric), "--seed", SEED, "--quiet",
        "--times-from-submission",
    )  # fmt: skip
    assert again.returncode == 0, again.stderr
    # 3. the two runs merged: the later folder's result for alice replaces the class's
    merged = _cli(
        "merge", str(tmp / "class"), str(tmp / "regrade-alice"), "--out", str(tmp / "final"),
        "--rubric", str(rubric),
    )  # fmt: skip
    return tmp, first, merged


@pytest.mark.slow  # starts a sandbox
def test_grading_prints_no_progress_bar_when_the_output_is_not_a_terminal(regraded):
    _, first, _ = regraded
    assert "━" not in first.stderr and "ETA" not in first.stderr and "grading" not in first.stderr


@pytest.mark.slow  # starts a sandbox
def test_the_class_run_charges_the_slip_and_the_late_day_from_the_times_file_before_timestamp_txt(regraded):
    tmp, *_ = regraded
    rows = _rows(tmp / "class")
    # alice: the phi table's part (1 of 8 points) lost, on time
    assert (rows["alice"]["raw total"], rows["alice"]["lateness"], rows["alice"]["total"]) == ("7", "on time", "7")
    # bob: full marks, handed in 11 h 31 min after 23:59 +01:00, one started day: 10% of 8
    assert rows["bob"]["raw total"] == "8" and rows["bob"]["penalty"] == "0.8" and rows["bob"]["total"] == "7.2"
    assert rows["bob"]["submitted"] == "2026-12-02T11:30:00+01:00" and rows["bob"]["hours late"] == "11.52"
    feedback = {name: (tmp / "class" / "feedback" / f"{file_stem(name)}.txt").read_text() for name in rows}
    assert f"handed in 2026-12-01T22:00:00+01:00 ({late.FROM_NBGRADER}): on time." in feedback["alice"]
    assert rows["alice"]["time source"] == late.FROM_NBGRADER and "student-supplied" in late.FROM_NBGRADER
    assert "handed in 2026-12-02T11:30:00+01:00 (the --times file): late by 11 h 31 min" in feedback["bob"]
    assert "Total: 7.2 (8 less 0.8 for late work; full credit is 8)" in feedback["bob"]


@pytest.mark.slow  # starts a sandbox
def test_the_merge_has_the_new_result_for_the_regraded_student_and_the_old_for_the_other(regraded):
    tmp, _, merged = regraded
    assert merged.returncode == 0, merged.stderr
    before, after = _rows(tmp / "class"), _rows(tmp / "final")
    assert after["alice"]["exercise 16"] == after["alice"]["total"] == "8" and after["alice"]["lateness"] == "on time"
    assert after["bob"] == before["bob"]
    name = f"{file_stem('alice')}.txt"
    assert (tmp / "final" / "feedback" / name).read_text() == (tmp / "regrade-alice" / "feedback" / name).read_text()
    # the merged summary names the result that was replaced, and merge.json keeps it
    earlier = tmp / "class" / "results" / f"{safe_name('alice')}.json"
    later = tmp / "regrade-alice" / "results" / f"{safe_name('alice')}.json"
    assert "1 result(s) replaced by a later folder's" in merged.stdout
    assert f"alice: {earlier} -> {later}" in merged.stdout
    record = json.loads((tmp / "final" / "merge.json").read_text())
    assert [(r["submission"], r["earlier"], r["later"]) for r in record["replaced"]] == [
        ("alice", str(earlier), str(later))
    ]


@pytest.mark.slow  # starts a sandbox
def test_results_of_another_rubric_or_another_labkit_version_are_refused(regraded):
    tmp, *_ = regraded
    later = tmp / "regrade-alice" / "results" / f"{safe_name('alice')}.json"
    data = json.loads(later.read_text())
    # the same result as `labkit grade --rubric OTHER` writes it: another rubric's points
    other = rubrics.from_dict({"title": "bilinear, 20 points", "required": [16], "points": {"16": 20}}, "other.toml")
    write_report(tmp / "other-rubric", [SubmissionGrade.from_dict(data, str(later), other)])
    run = _cli("merge", str(tmp / "class"), str(tmp / "other-rubric"), "--out", str(tmp / "m1"))
    assert run.returncode == 2 and "results of different rubrics" in run.stderr
    assert "'bilinear, 20 points'" in run.stderr and "'bilinear, with a deadline'" in run.stderr
    # written by another labkit
    shutil.copytree(tmp / "regrade-alice", tmp / "old-labkit")
    data["labkit"] = "0.0.9"
    (tmp / "old-labkit" / "results" / later.name).write_text(json.dumps(data))
    run = _cli("merge", str(tmp / "class"), str(tmp / "old-labkit"), "--out", str(tmp / "m2"))
    assert run.returncode == 1 and "not read" in run.stderr and "changed since the run wrote it" in run.stderr
    (tmp / "m2").rename(tmp / "m2-refused")
    record_file = tmp / "old-labkit" / "record.json"
    record_file.write_text(json.dumps({**json.loads(record_file.read_text()), "labkit": "0.0.9"}))
    run = _cli("merge", str(tmp / "class"), str(tmp / "old-labkit"), "--out", str(tmp / "m2"))
    assert run.returncode == 2 and "was graded by labkit 0.0.9, and this is labkit" in run.stderr
    assert not (tmp / "m1").exists() and not (tmp / "m2").exists()
