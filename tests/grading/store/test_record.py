"""The run's record (labkit.grading.store.record): what it vouches for, and a record that is not one."""

import json
import os

import pytest

from labkit.grading.store import record
from labkit.grading.store.report import SubmissionGrade, read_results, write_report
from labkit.grading.store.rubric import DEFAULT, default


def _run(folder, names=("ada", "bob")):
    write_report(folder, [SubmissionGrade(name, {}, [], 7, default()) for name in names])
    return folder


def _edit_record(folder, **changes):
    path = folder / record.RECORD
    path.write_text(json.dumps({**json.loads(path.read_text()), **changes}))


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"seed": [1, 2]}, "its seed is not a number"),
        ({"seed": "abc"}, "its seed is not a number"),
        ({"times": {"csv": {"ada": "2026-12-03T10:00:00"}}}, "not times with a UTC offset"),
        ({"times": {"csv": {"ada": "yesterday"}}}, "not times with a UTC offset"),
        ({"format": "labkit-run/0"}, "its format is not"),
        ({"submissions": {"ada": {"result": "../../etc/passwd.json", "sha256": "0"}}}, "outside results/"),
        ({"flags": {"times from mtime": "yes"}}, "its flags are not true or false"),
    ],
)
def test_a_record_that_is_not_one_is_refused_with_a_message(tmp_path, changes, message):
    out = _run(tmp_path / "out")
    _edit_record(out, **changes)
    with pytest.raises(ValueError, match=f"is not a labkit run record .*{message}"):
        read_results([out])


def test_the_record_vouches_for_what_the_grader_wrote_not_what_the_folder_holds_later(tmp_path):
    out = _run(tmp_path / "out")
    entry = json.loads((out / record.RECORD).read_text())["submissions"]["ada"]
    path = out / "results" / entry["result"]
    data = json.loads(path.read_text())
    path.write_text(json.dumps({**data, "problems": ["written later"]}))
    found = read_results([out])
    assert [g.name for g in found] == ["bob"] and "changed since the run wrote it" in found.refused[0][1]


def test_another_rubric_is_refused_with_a_command_that_runs(tmp_path):
    out = _run(tmp_path / "out")
    other = tmp_path / "other.toml"
    other.write_text(
        DEFAULT.read_text() + '\n[late]\ndeadline = "2026-12-01T23:59Z"\nper = "day"\npercent = 5\ncap = 9\n'
    )
    with pytest.raises(ValueError, match=f"labkit merge {out} --rubric {other} --out NEW"):
        record.rubric_for([out], other, "labkit report")
    assert not record.rubric_for([out], DEFAULT, "labkit report").differences(default())  # the same rubric, named again
    assert record.rubric_for([out], None, "labkit report").text == DEFAULT.read_text()


def test_a_replaced_file_gets_the_mode_asked_for_and_a_failed_write_leaves_the_earlier_file(tmp_path):
    target = tmp_path / "report.html"
    old = os.umask(0o077)
    try:
        record.replace_text(target, "first", mode=0o644)
    finally:
        os.umask(old)
    assert target.stat().st_mode & 0o777 == 0o644  # readable as before, even under a strict umask
    with pytest.raises(UnicodeEncodeError):
        record.replace_text(target, "half \ud800 written", mode=0o644)
    assert target.read_text() == "first"
    assert [p.name for p in tmp_path.iterdir()] == ["report.html"]  # no partial file left beside it
