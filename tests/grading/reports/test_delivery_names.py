"""The names labkit feedback gives each student's page, per LMS, read back as each importer reads them (no
sandbox: the run is written by hand)."""

import zipfile

import pytest

from labkit.grading.lms import canvas, delivery, folders, moodle, nbgrader
from labkit.grading.store import record as records
from labkit.grading.store.report import SubmissionGrade, write_report


def test_canvas_names_carry_the_downloads_user_and_file_ids():
    assert canvas.LMS.feedback_names("lovelaceada", {"file": "lovelaceada_LATE_101_9001"}) == [
        "lovelaceada_LATE_101_9001_feedback.html"
    ]
    for bad in ({}, {"file": "../x_1_2"}, {"file": "lovelaceada_101"}):
        with pytest.raises(ValueError, match="no Canvas file"):
            canvas.LMS.feedback_names("lovelaceada", bad)


def test_moodle_names_are_the_participant_id_and_the_feedback_file_plugin():
    assert moodle.LMS.feedback_names("Ada Lovelace_201", {"lms id": "201"}) == [
        "Ada Lovelace_201_assignfeedback_file_/feedback.html"
    ]
    # a name that would add pieces at "_" or a folder keeps the participant id second
    name = moodle.LMS.feedback_names("a_b/../c_7", {"lms id": "7"})[0]
    assert name.split("/")[0].split("_", 4)[1:4] == ["7", "assignfeedback", "file"] and ".." not in name.split("/")
    with pytest.raises(ValueError, match="participant id"):
        moodle.LMS.feedback_names("Ada", {"lms id": None})


def test_folder_and_nbgrader_names_stay_inside_the_zip():
    assert folders.LMS.feedback_names("alice", {}) == ["alice/feedback.html"]
    assert (
        folders.LMS.feedback_names("..", {})[0].startswith("submission-")
        or ".." not in folders.LMS.feedback_names("..", {})[0]
    )
    entry = {"assignment": "lab8", "notebooks": ["01_limacon", "02_convergence"]}
    assert nbgrader.LMS.feedback_names("alice", entry) == [
        "alice/feedback.html",
        "feedback/alice/lab8/01_limacon.html",
        "feedback/alice/lab8/02_convergence.html",
    ]
    assert nbgrader.LMS.feedback_names("alice", {**entry, "assignment": "../x"}) == ["alice/feedback.html"]


def test_an_nbgrader_run_writes_its_feedback_folder_with_the_timestamp_and_secret(tmp_path):
    out = tmp_path / "grades"
    write_report(out, [SubmissionGrade("alice", {2: {"fraction": 1.0, "passed": True, "checks": []}})])
    record = records.read(out)
    record.delivery = {"layout": "nbgrader", "students": {"alice": {
        "assignment": "lab8", "notebooks": ["02_convergence"], "timestamp.txt": "2026-12-01 10:00:00",
        "submission_secret.txt": "s3cret"}}}  # fmt: skip
    records.write(out, record)
    path, members, notes = delivery.write_upload(out)
    assert notes == [] and path == out / "feedback-upload.zip"
    with zipfile.ZipFile(path) as archive:
        assert (
            sorted(archive.namelist())
            == sorted(members)
            == [
                "alice/feedback.html",
                "feedback/alice/lab8/02_convergence.html",
                "feedback/alice/lab8/submission_secret.txt",
                "feedback/alice/lab8/timestamp.txt",
            ]
        )
        assert archive.read("feedback/alice/lab8/timestamp.txt") == b"2026-12-01 10:00:00"
        assert b"Total: 10 / 100 points" in archive.read("alice/feedback.html")


def test_a_student_the_lms_cannot_name_is_left_out_and_said(tmp_path):
    out = tmp_path / "grades"
    write_report(out, [SubmissionGrade(n, {2: {"fraction": 1.0, "passed": True, "checks": []}}) for n in ("a", "b")])
    record = records.read(out)
    record.delivery = {"layout": "canvas", "students": {"a": {"file": "a_1_2"}}}
    records.write(out, record)
    _, members, notes = delivery.write_upload(out)
    assert members == ["a_1_2_feedback.html"] and len(notes) == 1 and notes[0].startswith("b left out")
