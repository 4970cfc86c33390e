"""Late work: the rubric's [late] table, submission times (nbgrader's timestamp.txt, --times, modification times
only on request), the penalty, grades.csv and the feedback, and merging results with times and replacements.

The expected penalties are worked out by hand from the rule in the comments, never from labkit's output."""

import csv
import json
import os
import shutil
import subprocess
import sys
import tomllib
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

import pytest

from labkit.grading import merge
from labkit.grading.run import times
from labkit.grading.store import late
from labkit.grading.store import rubric as rubrics
from labkit.grading.store.report import CSV_TAIL, SubmissionGrade, safe_name, write_report

CET = timezone(timedelta(hours=1))
DEADLINE = datetime(2026, 12, 1, 23, 59, tzinfo=CET)
LATE = """
[late]
deadline = "2026-12-01T23:59:00+01:00"
per = "day"
percent = 10
cap = 50
grace = 15
"""
SMALL = 'title = "bilinear only"\nrequired = [16]\n[points]\n16 = 20\n'


def _rubric(text=SMALL + LATE, source="test.toml"):
    return rubrics.from_dict(tomllib.loads(text), source)


def _results(fraction):
    return {16: {"exercise": 16, "passed": fraction == 1, "points": 8 * fraction, "fraction": fraction, "checks": []}}


def _grade(name, rubric, when=None, fraction=1.0, source=late.FROM_CSV, seed=7):
    time = None if when is None else late.SubmissionTime(when, source)
    return SubmissionGrade(name, _results(fraction), [], seed, rubric, time=time)


def _error(text):
    """A regular expression matching `text` literally."""
    import re

    return re.escape(text)


# --- the [late] table ---------------------------------------------------------------------------------------------


def test_a_late_table_is_read_with_its_deadline_rule_and_extensions():
    rule = _rubric(SMALL + LATE + '[late.extensions]\nalice = 48\n"jane doe" = "2026-12-05T12:00:00Z"\n').late
    assert rule.deadline == DEADLINE and rule.per == "day" and (rule.percent, rule.cap, rule.grace) == (10, 50, 15)
    assert rule.deadline_for("alice") == (DEADLINE + timedelta(hours=48), True)
    assert rule.deadline_for("jane doe") == (datetime(2026, 12, 5, 12, tzinfo=UTC), True)
    assert rule.deadline_for("bob") == (DEADLINE, False)


def test_a_toml_offset_date_time_is_a_deadline_too():
    rule = _rubric(SMALL + LATE.replace('"2026-12-01T23:59:00+01:00"', "2026-12-01T23:59:00+01:00")).late
    assert rule.deadline == DEADLINE


def test_without_a_late_table_there_is_no_rule():
    assert _rubric(SMALL).late is None and rubrics.default().late is None


@pytest.mark.parametrize(
    "change, message",
    [
        (('"2026-12-01T23:59:00+01:00"', '"2026-12-01T23:59:00"'), "which has no UTC offset: write it as ISO 8601"),
        (('"2026-12-01T23:59:00+01:00"', "2026-12-01T23:59:00"), "has no UTC offset: write it as ISO 8601"),
        (('"2026-12-01T23:59:00+01:00"', '"01/12/2026 23:59"'), "which is not in that format: write it as ISO 8601"),
        (('"2026-12-01T23:59:00+01:00"', '"2026-02-30T10:00:00+01:00"'), "which is not a real time"),
        (('"2026-12-01T23:59:00+01:00"', "20261201"), "not a time: write it as ISO 8601"),
        (('per = "day"', 'per = "week"'), 'per must be "day" or "hour"'),
        (("percent = 10", "percent = -5"), "percent must be between 0 and 100"),
        (("percent = 10", "percent = 'ten'"), "percent must be a number"),
        (("percent = 10", "percent = true"), "percent must be a number"),
        (("percent = 10", "percent = nan"), "percent must be a number"),
        (("cap = 50", "cap = 150"), "cap must be between 0 and 100"),
        (("grace = 15", "grace = -1"), "grace must be at least 0"),
        (("cap = 50\n", ""), "[late] needs cap"),
        (("grace = 15", "penalty = 5"), "unknown key(s) penalty in [late]"),
        (("grace = 15", "grace = 15\nextensions = 3"), "[late.extensions] must be a table"),
        (("grace = 15", "grace = 15\n[late.extensions]\nalice = -2"), "an extension adds more than 0 hours"),
        (("grace = 15", "grace = 15\n[late.extensions]\nalice = true"), "give a new deadline"),
        (("grace = 15", "grace = 15\n[late.extensions]\nalice = [1]"), "give a new deadline"),
        (
            ("grace = 15", 'grace = 15\n[late.extensions]\nalice = "2026-11-30T10:00:00+01:00"'),
            "not after the deadline 2026-12-01T23:59:00+01:00; an extension gives more time",
        ),
        (("grace = 15", 'grace = 15\n[late.extensions]\nalice = "2026-12-03"'), "has no UTC offset"),
    ],
)
def test_late_table_errors_say_what_is_wrong_and_how_to_fix_it(change, message):
    old, new = change
    assert old in LATE
    with pytest.raises(ValueError, match=_error(message)) as caught:
        _rubric(SMALL + LATE.replace(old, new))
    assert str(caught.value).startswith("test.toml: ") and "[late" in str(caught.value)


def test_a_late_table_that_is_not_a_table_and_a_name_that_is_not_text_are_refused():
    with pytest.raises(ValueError, match=_error("[late] must be a table")):
        rubrics.from_dict({**tomllib.loads(SMALL), "late": 5}, "r")
    table = {**tomllib.loads(LATE)["late"], "extensions": {1: 5}}
    with pytest.raises(ValueError, match="a name is a submission's name, as text"):
        late.from_dict(table, "r")


def test_the_rubric_check_command_shows_the_rule_and_refuses_a_bad_deadline(tmp_path):
    path = tmp_path / "r.toml"
    path.write_text(SMALL + LATE + "[late.extensions]\nalice = 24\n")
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "rubric", "--check", str(path)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0, run.stderr
    assert "late work: due 2026-12-01T23:59:00+01:00, with 15 minutes of grace" in run.stdout
    assert "10% of the points off per started day late, at most 50%" in run.stdout
    assert "extensions: 1 student(s)" in run.stdout and "alice" not in run.stdout
    path.write_text(SMALL + LATE.replace("+01:00", ""))
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "rubric", "--check", str(path)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 2 and "has no UTC offset: write it as ISO 8601 with a UTC offset" in run.stderr


# --- nbgrader's timestamps ----------------------------------------------------------------------------------------

MOMENT = datetime(2026, 12, 1, 22, 59, 59, 123456, tzinfo=UTC)


@pytest.mark.parametrize(
    "text",
    [
        "2026-12-01 22:59:59.123456 UTC",  # nbgrader's format, "%Y-%m-%d %H:%M:%S.%f %Z"
        "2026-12-01 22:59:59.123456 UTC\n",
        "\ufeff 2026-12-01 22:59:59.123456 UTC  ",
        "2026-12-01 23:59:59.123456+01:00",  # zip_collect's isoformat(" ")
        "2026-12-01T22:59:59.123456Z",
        "2026-12-01 23:59:59.123456 +0100",
        "2026-12-01 17:59:59.123456 -05:00",
        "2026-12-01 22:59:59.123456789 GMT",  # more digits than microseconds: cut, not rounded
    ],
)
def test_nbgrader_timestamps_are_read_in_every_form_nbgrader_writes(text):
    assert times.parse_timestamp(text) == MOMENT


def test_an_older_nbgrader_timestamp_without_a_fraction_is_read():
    assert times.parse_timestamp("2026-12-01 22:59:59 UTC") == MOMENT.replace(microsecond=0)


@pytest.mark.parametrize(
    "text, message",
    [
        ("2026-12-01 22:59:59", "has no time zone"),
        ("2026-12-01 22:59:59 CET", "names the time zone 'CET', which labkit cannot place"),
        ("yesterday evening", "is not a time as nbgrader writes it"),
        ("2026-13-01 10:00:00 UTC", "is not a real time"),
        ("2026-12-01 10:00:00 +25:00", "which no time zone has"),
        ("", "is not a time as nbgrader writes it"),
    ],
)
def test_a_timestamp_that_cannot_be_placed_is_refused_with_the_reason(text, message):
    with pytest.raises(ValueError, match=message):
        times.parse_timestamp(text)


def test_a_submission_folders_timestamp_is_read_and_a_bad_one_is_a_problem_not_a_crash(tmp_path):
    folder = tmp_path / "alice"
    folder.mkdir()
    (folder / "work.ipynb").write_text("{}")
    assert times.read_timestamp(folder) is None and times.read_timestamp(folder / "work.ipynb") is None
    (folder / "timestamp.txt").write_text("2026-12-01 22:59:59.123456 UTC")
    assert times.read_timestamp(folder) == late.SubmissionTime(MOMENT, late.FROM_NBGRADER)
    cases = {
        b"\x1b[31mnot a time\x07": "is not a time as nbgrader writes it",
        b"\xff\xfe\x00": "timestamp.txt is not text",
        b"2026-12-01 22:59:59 UTC" + b" " * 1000: "more than the 256 it can be",
    }
    for raw, problem in cases.items():
        (folder / "timestamp.txt").write_bytes(raw)
        found = times.read_timestamp(folder)
        assert found.when is None and found.source == late.FROM_NBGRADER and problem in found.problem
    (folder / "timestamp.txt").unlink()
    (tmp_path / "elsewhere.txt").write_text("2026-12-01 22:59:59 UTC")
    (folder / "timestamp.txt").symlink_to(tmp_path / "elsewhere.txt")
    assert "is a symbolic link" in times.read_timestamp(folder).problem
    (folder / "timestamp.txt").unlink()
    os.mkfifo(folder / "timestamp.txt")  # opening a pipe for reading would wait for a writer forever
    assert "timestamp.txt is not a file" in times.read_timestamp(folder).problem
    (folder / "timestamp.txt").unlink()
    (folder / "timestamp.txt").mkdir()
    assert "timestamp.txt is not a file" in times.read_timestamp(folder).problem


def test_the_times_file_comes_first_and_modification_times_only_when_asked(tmp_path):
    folder = tmp_path / "alice"
    folder.mkdir()
    notebook = folder / "work.ipynb"
    notebook.write_text("{}")
    stamp = datetime(2026, 12, 3, 12, tzinfo=UTC).timestamp()
    os.utime(notebook, (stamp, stamp))
    # no timestamp.txt, no times file: the file's modification time is never used unless asked for
    assert times.submission_time(folder, "alice", notebooks=[notebook]) is None
    by_mtime = times.submission_time(folder, "alice", notebooks=[notebook], from_mtime=True)
    assert by_mtime == late.SubmissionTime(datetime(2026, 12, 3, 12, tzinfo=UTC), late.FROM_MTIME)
    (folder / "timestamp.txt").write_text("2026-12-01 22:59:59.123456 UTC")
    # the student's own timestamp.txt is never read unless asked for, and then it is marked student-supplied
    assert times.submission_time(folder, "alice") is None
    assert times.submission_time(folder, "alice", notebooks=[notebook], from_mtime=True).source == late.FROM_MTIME
    inside = times.submission_time(folder, "alice", from_submission=True)
    assert inside.when == MOMENT and inside.source in late.STUDENT_SUPPLIED and "student-supplied" in inside.source
    listed = {"alice": datetime(2026, 12, 2, tzinfo=UTC)}
    assert times.submission_time(folder, "alice", listed, from_submission=True) == late.SubmissionTime(
        listed["alice"], late.FROM_CSV
    )
    assert times.submission_time(folder, "bob", listed, from_submission=True).source == late.FROM_NBGRADER
    # labkit's own reading of nbgrader's exchange comes after the LMS's times, before anything inside
    exchange = {"alice": datetime(2026, 12, 2, 5, tzinfo=UTC)}
    assert times.submission_time(folder, "alice", None, exchange=exchange, from_submission=True).source == (
        late.FROM_EXCHANGE
    )
    assert times.submission_time(folder, "alice", listed, exchange=exchange).source == late.FROM_CSV


def test_the_exchange_is_read_from_its_folder_names_newest_first(tmp_path):
    inbound = tmp_path / "course101" / "inbound"
    for name in (
        "alice+lab8+2026-12-01 22:00:00.000000 UTC+abc123",
        "alice+lab8+2026-12-02 08:30:00.000000 UTC+def456",  # a second submission: the newest counts
        "bob+lab8+2026-12-01 20:00:00 UTC",  # nbgrader before the random part was added
        "carol+lab7+2026-12-09 20:00:00 UTC+x",  # another assignment
        "d+ave+lab8+2026-12-01 21:00:00.5 UTC+q",  # a student id with a plus
    ):
        folder = inbound / name
        folder.mkdir(parents=True)
        # what travels with the work is the student's: a forged timestamp.txt changes nothing
        (folder / "timestamp.txt").write_text("2026-11-01 00:00:00 UTC")
    found = times.read_exchange(tmp_path / "course101", "lab8")
    assert found == {
        "alice": datetime(2026, 12, 2, 8, 30, tzinfo=UTC),
        "bob": datetime(2026, 12, 1, 20, tzinfo=UTC),
        "d+ave": datetime(2026, 12, 1, 21, 0, 0, 500000, tzinfo=UTC),
    }
    assert times.read_exchange(inbound, "lab7") == {"carol": datetime(2026, 12, 9, 20, tzinfo=UTC)}
    (inbound / "eve+lab8+yesterday+r").mkdir()
    with pytest.raises(ValueError, match="no readable time"):
        times.read_exchange(inbound, "lab8")
    with pytest.raises(ValueError, match="no inbound"):
        times.read_exchange(tmp_path, "lab8")


def test_a_times_file_is_read_with_extra_columns_and_either_time_format(tmp_path):
    path = tmp_path / "times.csv"
    path.write_text(
        "\ufeffTime,Submission,email\n2026-12-01T23:10:00+01:00,alice,a@x\n\n2026-12-01 22:59:59.123456 UTC, bob ,\n",
        encoding="utf-8",
    )
    assert times.read_times(path) == {"alice": datetime(2026, 12, 1, 22, 10, tzinfo=UTC), "bob": MOMENT}


@pytest.mark.parametrize(
    "text, message",
    [
        ("name,when\nalice,2026-12-01T23:10:00+01:00\n", "needs a header row with the columns submission and time"),
        (
            "submission,time\nalice,2026-12-01T23:10:00+01:00\nalice,2026-12-02T23:10:00+01:00\n",
            "line 3: 'alice' is listed twice",
        ),
        (
            "submission,time\nalice,2026-12-01T23:10:00+01:00\nbob,2026-12-01 23:10\n",
            "line 3 ('bob'): '2026-12-01 23:10' has no time zone",
        ),
        ("submission,time\n,2026-12-01T23:10:00+01:00\n", "line 2: the submission's name is empty"),
        ("submission,time\nalice\n", "line 2: it has 1 cell(s)"),
    ],
)
def test_times_file_errors_name_the_line_and_the_fix(tmp_path, text, message):
    path = tmp_path / "times.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=_error(message)):
        times.read_times(path)


def test_a_missing_or_binary_times_file_is_refused(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        times.read_times(tmp_path / "missing.csv")
    (tmp_path / "bin.csv").write_bytes(b"\xff\xfe\xfa")
    with pytest.raises(ValueError, match="cannot read the times file"):
        times.read_times(tmp_path / "bin.csv")


# --- the penalty --------------------------------------------------------------------------------------------------


# deadline 2026-12-01 23:59 +01:00, 10% of the points per started day, at most 50%, 15 minutes of grace
@pytest.mark.parametrize(
    "handed_in, units, percent",
    [
        (DEADLINE - timedelta(hours=3), 0, 0),
        (DEADLINE, 0, 0),
        (DEADLINE + timedelta(minutes=15), 0, 0),  # within the grace
        (DEADLINE + timedelta(minutes=20), 1, 10),  # past the grace: counted from the deadline, one started day
        (DEADLINE + timedelta(hours=24), 1, 10),
        (DEADLINE + timedelta(hours=24, seconds=1), 2, 20),
        (datetime(2026, 12, 1, 23, 30, tzinfo=UTC), 1, 10),  # 00:30 +01:00: 31 minutes late
        (DEADLINE + timedelta(days=4, hours=1), 5, 50),
        (DEADLINE + timedelta(days=30), 30, 50),  # the cap
    ],
)
def test_the_penalty_is_a_share_of_the_points_per_started_day_up_to_the_cap(handed_in, units, percent):
    grade = _grade("ada", _rubric(), handed_in, fraction=0.75)  # 15 of 20 points
    lateness = grade.lateness
    assert (lateness.units, lateness.percent) == (units, percent)
    assert lateness.penalty == pytest.approx(15 * percent / 100) and grade.raw_total == 15
    assert grade.total == pytest.approx(15 - 15 * percent / 100)


def test_per_hour_counts_started_hours():
    rubric = _rubric(SMALL + LATE.replace('"day"', '"hour"').replace("grace = 15\n", ""))
    assert _grade("ada", rubric, DEADLINE + timedelta(minutes=61)).lateness.units == 2
    assert _grade("ada", rubric, DEADLINE + timedelta(seconds=1)).lateness.percent == 10
    assert _grade("ada", rubric, DEADLINE + timedelta(hours=7)).total == 10  # 70% capped at 50% of 20


def test_an_extension_moves_only_that_students_deadline_and_stays_private():
    rubric = _rubric(SMALL + LATE + "[late.extensions]\nalice = 48\n")
    handed_in = DEADLINE + timedelta(hours=47)
    alice, bob = _grade("alice", rubric, handed_in), _grade("bob", rubric, handed_in)
    assert alice.total == 20 and alice.lateness.extended and alice.lateness.deadline == DEADLINE + timedelta(hours=48)
    assert bob.total == 16 and bob.lateness.units == 2 and not bob.lateness.extended  # 47 h: two started days
    assert "your extension" in alice.feedback() and "2026-12-03T23:59:00+01:00" in alice.feedback()
    assert "alice" not in bob.feedback() and "extension" not in bob.feedback()
    assert "alice" not in rubric.describe()


def test_a_submission_without_a_time_is_listed_and_not_penalised():
    rubric = _rubric()
    unknown = _grade("ada", rubric)
    unreadable = SubmissionGrade(
        "bea", _results(1.0), [], 7, rubric, time=late.SubmissionTime(None, late.FROM_NBGRADER, "timestamp.txt: bad")
    )
    on_time = _grade("cy", rubric, DEADLINE)
    assert unknown.total == unreadable.total == 20
    assert unknown.lateness.note == "no submission time: not penalised"
    assert unreadable.lateness.note == "its submission time could not be read (timestamp.txt: bad): not penalised"
    assert "this submission's time is not known, so no late penalty was applied" in unknown.feedback()
    assert late.unknown_times([unknown, unreadable, on_time]) == [
        ("ada", "no submission time: not penalised", False),
        ("bea", unreadable.lateness.note, True),
    ]


def test_the_feedback_shows_the_raw_total_the_lateness_the_penalty_and_the_final_total():
    grade = _grade("ada", _rubric(), DEADLINE + timedelta(hours=30), fraction=0.5)  # 10 points, 2 days: 20%
    text = grade.feedback()
    assert text.startswith("Total: 8 / 20 points\n  2 off for late work (10 before the penalty)\nFeedback for ada\n")
    assert "handed in 2026-12-03T05:59:00+01:00 (the --times file): late by 1 day 6 h: 2 started days, 20% off" in text
    assert "2 of 10 points" in text
    assert "Total: 8 (10 less 2 for late work; full credit is 20)" in text
    assert "late work: due 2026-12-01T23:59:00+01:00" in text  # the rule, with the rubric


def test_without_a_late_table_the_feedback_and_total_are_as_before():
    rubric = _rubric(SMALL)
    grade = _grade("ada", rubric, DEADLINE + timedelta(days=3), fraction=0.5)
    assert grade.lateness is None and grade.total == 10
    assert "late" not in grade.feedback().lower()


# --- grades.csv ---------------------------------------------------------------------------------------------------


def _rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.reader(handle))


def test_without_a_late_table_grades_csv_has_exactly_the_old_columns(tmp_path):
    grade = _grade("ada", _rubric(SMALL), DEADLINE + timedelta(days=3))
    write_report(tmp_path, [grade])
    header, row = _rows(tmp_path / "grades.csv")[:2]
    assert CSV_TAIL == ["required", "branch", "branch points", "extra credit", "total", "full credit", "status"]
    assert header[:9] == ["submission", "exercise 16", *CSV_TAIL]
    assert row[:9] == ["ada", "20", "20", "", "0", "0", "20", "20", "graded"]


def test_with_a_late_table_grades_csv_shows_raw_total_time_lateness_penalty_and_total(tmp_path):
    rubric = _rubric()
    hostile = '=HYPERLINK("http://x")\x1b[2J'
    grades = [
        _grade("ada", rubric, DEADLINE + timedelta(hours=30), fraction=0.5),
        _grade(hostile, rubric, DEADLINE - timedelta(hours=1)),
        _grade("cy", rubric),
        SubmissionGrade("dee", {}, [], 7, rubric, failure="its grading crashed"),
    ]
    write_report(tmp_path, grades)
    header, *rows = _rows(tmp_path / "grades.csv")
    assert header[:16] == [
        "submission",
        "exercise 16",
        "required",
        "branch",
        "branch points",
        "extra credit",
        "raw total",
        "submitted",
        "time source",
        "deadline",
        "hours late",
        "lateness",
        "penalty",
        "total",
        "full credit",
        "status",
    ]
    assert all(len(row) == len(header) for row in rows)
    ada, evil, cy, dee = ({key: value for key, value in zip(header, row)} for row in rows)
    assert (ada["raw total"], ada["penalty"], ada["total"]) == ("10", "2", "8")
    assert ada["submitted"] == "2026-12-03T05:59:00+01:00" and ada["deadline"] == "2026-12-01T23:59:00+01:00"
    assert ada["time source"] == late.FROM_CSV and cy["time source"] == ""
    assert ada["hours late"] == "30.00" and ada["lateness"].startswith("late by 1 day 6 h: 2 started days, 20% off")
    assert evil["submission"].startswith("'=HYPERLINK") and "\x1b" not in evil["submission"]
    assert (evil["lateness"], evil["total"]) == ("on time", "20")
    assert cy["lateness"] == "no submission time: not penalised" and cy["submitted"] == "" and cy["total"] == "20"
    assert dee["status"] == "not graded: its grading crashed" and dee["total"] == dee["penalty"] == ""


# --- results and merging ------------------------------------------------------------------------------------------


def _run(folder, grades):
    write_report(folder, grades)
    return folder


def _result(folder, name):
    return Path(folder) / "results" / f"{safe_name(name)}.json"


def test_a_result_carries_the_submission_time_and_the_labkit_version(tmp_path):
    rubric = _rubric()
    grade = _grade("ada", rubric, DEADLINE + timedelta(hours=30))
    data = json.loads(json.dumps(grade.as_dict()))
    assert data["submitted"] == {"time": "2026-12-03T04:59:00+00:00", "source": late.FROM_CSV, "problem": None}
    back = SubmissionGrade.from_dict(data, "r.json", rubric)
    assert back.time == grade.time and back.total == grade.total == 16  # two started days: 20% of 20
    # rescored with a rubric without [late], the same result has no penalty
    assert SubmissionGrade.from_dict(data, "r.json", _rubric(SMALL)).total == 20
    for bad in ({"time": "yesterday"}, {"when": None}, "2026-12-01"):
        with pytest.raises(ValueError, match="is not a labkit grade result"):
            SubmissionGrade.from_dict({**data, "submitted": bad}, "r.json", rubric)


@pytest.mark.parametrize("version, written", [("0.0.1", "labkit 0.0.1"), (None, "a labkit that did not say")])
def test_a_result_of_another_labkit_version_is_refused(version, written):
    data = _grade("ada", _rubric()).as_dict()
    data["labkit"] = version
    with pytest.raises(ValueError, match=f"r.json was written by {written}, and this is labkit"):
        SubmissionGrade.from_dict(data, "r.json")


def test_a_later_folders_result_replaces_the_earlier_one_and_the_merge_says_so(tmp_path):
    rubric = _rubric()
    first = _run(
        tmp_path / "class",
        [_grade("alice", rubric, DEADLINE, fraction=0.5), _grade("bob", rubric, DEADLINE + timedelta(hours=2))],
    )
    regrade = _run(tmp_path / "regrade", [_grade("alice", rubric, None, fraction=1.0)])  # fixed, no time of its own
    merged = merge([first, regrade], tmp_path / "merged", rubric)
    assert [g.name for g in merged] == ["alice", "bob"]
    alice, bob = merged
    assert alice.raw_total == 20 and alice.time.when == DEADLINE  # the new result, the original submission time
    assert bob.total == 18  # 2 hours late: one started day, 10% of 20
    assert [(r.name, r.earlier, r.later, r.time_kept) for r in merged.replaced] == [
        ("alice", _result(first, "alice"), _result(regrade, "alice"), True)
    ]
    record = json.loads((tmp_path / "merged" / "merge.json").read_text())
    assert record["replaced"] == [
        {
            "submission": "alice",
            "earlier": str(_result(first, "alice")),
            "later": str(_result(regrade, "alice")),
            "time kept": True,
        }
    ]
    rows = {row[0]: row for row in _rows(tmp_path / "merged" / "grades.csv")}
    total = rows["submission"].index("total")
    assert rows["alice"][total] == "20" and rows["bob"][total] == "18"
    # the other order: the class's result is the later one and counts
    again = merge([regrade, first], tmp_path / "again", rubric)
    assert again[0].raw_total == 10 and again.replaced[0].later == _result(first, "alice")


def test_merge_refuses_mixed_rubrics_a_folder_twice_one_submission_twice_and_writing_over_its_input(tmp_path):
    rubric = _rubric()
    first = _run(tmp_path / "class", [_grade("alice", rubric), _grade("bob", rubric)])
    other = _run(tmp_path / "other", [_grade("alice", _rubric(SMALL.replace("16 = 20", "16 = 10") + LATE))])
    with pytest.raises(ValueError, match="results of different rubrics .* are not merged"):
        merge([first, other], tmp_path / "m1", rubric)
    # the [late] table is not part of the rubric's fingerprint: the merge applies the one it is given
    relaxed = _run(tmp_path / "relaxed", [_grade("alice", _rubric(SMALL + LATE.replace("cap = 50", "cap = 20")))])
    assert len(merge([first, relaxed], tmp_path / "m2", rubric)) == 2
    with pytest.raises(ValueError, match="is given twice"):
        merge([first, tmp_path / "class"], tmp_path / "m3", rubric)
    with pytest.raises(ValueError, match="is one of the folders merged"):
        merge([first, relaxed], first, rubric)
    # a result file the run's record does not name (a copy, or one a submission wrote) is never merged
    shutil.copy(_result(first, "alice"), first / "results" / "copy.json")
    merged = merge([first], tmp_path / "m4", rubric)
    assert [g.name for g in merged] == ["alice", "bob"] and [p.name for p, _ in merged.refused] == ["copy.json"]
    assert "copy.json" in (tmp_path / "m4" / "merge.json").read_text()
    assert not (tmp_path / "m1").exists()  # nothing written on a refusal


def test_times_given_to_a_merge_replace_the_stored_ones_for_the_submissions_they_list(tmp_path):
    rubric = _rubric()
    first = _run(tmp_path / "class", [_grade("alice", rubric), _grade("bob", rubric, DEADLINE)])
    times = {"alice": DEADLINE + timedelta(days=2, seconds=1)}  # two days and a second: three started days
    merged = merge([first], tmp_path / "m", rubric, times=times)
    assert merged[0].time == late.SubmissionTime(times["alice"], late.FROM_CSV) and merged[0].total == 14
    assert merged[1].total == 20 and merged[1].time.when == DEADLINE


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "labkit.cli", *args], capture_output=True, text=True, timeout=120)


def test_the_merge_command_lists_replacements_unknown_times_and_refuses_mtime(tmp_path):
    rubric_file = tmp_path / "r.toml"
    rubric_file.write_text(SMALL + LATE + "[late.extensions]\nzed = 5\n")
    rubric = rubrics.load(rubric_file)
    unreadable = late.SubmissionTime(None, late.FROM_NBGRADER, "timestamp.txt: '\x1b[31m' is not a time")
    first = _run(
        tmp_path / "class",
        [_grade("alice", rubric, DEADLINE), SubmissionGrade("bob", _results(1.0), [], 7, rubric, time=unreadable)],
    )
    regrade = _run(tmp_path / "regrade", [_grade("alice", rubric, DEADLINE + timedelta(hours=5))])
    times = tmp_path / "times.csv"
    times.write_text("submission,time\ncarl,2026-12-01T20:00:00Z\n")
    run = _cli(
        "merge", str(first), str(regrade), "--out", str(tmp_path / "m"), "--rubric", str(rubric_file),
        "--times", str(times),
    )  # fmt: skip
    assert run.returncode == 1, run.stderr  # a time could not be read
    assert "1 result(s) replaced by a later folder's" in run.stdout
    assert f"alice: {_result(first, 'alice')} -> {_result(regrade, 'alice')}" in run.stdout
    assert "alice                                  18  (2 off for late work)" in run.stdout
    assert "time unreadable for bob: its submission time could not be read" in run.stderr and "\x1b" not in run.stderr
    assert "the times file names submission(s) not in this run: 'carl'" in run.stderr
    assert "[late.extensions] name submission(s) not in this run: 'zed'" in run.stderr
    run = _cli("merge", str(first), "--out", str(tmp_path / "m2"), "--times-from-mtime")
    assert run.returncode == 2 and "--times-from-mtime reads the submissions' files" in run.stderr
    run = _cli("merge", str(first), "--out", str(tmp_path / "m3"), "--times", str(tmp_path / "no.csv"))
    assert run.returncode == 2 and "the times file" in run.stderr and "does not exist" in run.stderr


def test_the_late_tables_shown_in_the_docs_and_in_the_lab_rubric_are_valid():
    docs = (Path(__file__).resolve().parents[3] / "docs" / "instructors.md").read_text()
    block = next(b for b in docs.split("```toml\n")[1:] if b.startswith("[late]")).split("```")[0]
    commented = rubrics.DEFAULT.read_text().partition("# [late]\n")[2]
    example = "[late]\n" + "\n".join(line.removeprefix("# ").removeprefix("#") for line in commented.splitlines())
    for table in (block, example):
        rule = _rubric(SMALL + table).late
        assert rule.deadline == DEADLINE and (rule.per, rule.percent, rule.cap, rule.grace) == ("day", 10, 50, 15)
        assert rule.deadline_for("bob") == (DEADLINE + timedelta(hours=48), True)
        assert rule.deadline_for("alice") == (datetime(2026, 12, 3, 23, 59, tzinfo=CET), True)
