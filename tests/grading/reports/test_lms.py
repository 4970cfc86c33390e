"""Grades into the LMS: a Canvas gradebook export filled in, a Moodle grade import file, and bad input refused."""

import csv
import dataclasses
import io
import subprocess
import sys

import pytest

from labkit.grading.lms import canvas, exports, moodle
from labkit.grading.store import late
from labkit.grading.store.report import SubmissionGrade, read_results, write_report
from labkit.grading.store.rubric import default

LAB = default()
SPLINES = (10, 11, 12, 13, 14, 15)
HOSTILE = '=HYPERLINK("http://evil.example","click")'
ESCAPE = "mal\x1b[2Jory"  # an escape sequence that would clear a terminal


def _results(fractions):
    return {
        n: {"exercise": n, "passed": f == 1.0, "points": LAB.points[n], "fraction": f, "defined": True, "checks": []}
        for n, f in fractions.items()
    }


def _grades():
    full = {n: 1.0 for n in (2, 3, 4, *SPLINES)}
    return [
        SubmissionGrade("ada", _results({**full, 16: 0.5}), rubric=LAB),  # 100 + 4 extra credit
        SubmissionGrade("bob", _results({2: 1.0, 3: 0.5}), rubric=LAB),  # 10 + 7.5
        SubmissionGrade("carl", rubric=LAB, failure="its grading crashed twice"),
        SubmissionGrade("dora", _results(full), rubric=LAB),  # 100, but not on the roster
        SubmissionGrade(HOSTILE, _results({2: 1.0}), rubric=LAB),  # 10
        SubmissionGrade(ESCAPE, _results({2: 0.5}), rubric=LAB),  # 5, not on the roster
    ]


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    """A grading run's output folder, written as `labkit grade` writes it (no sandbox needed)."""
    folder = tmp_path_factory.mktemp("run") / "grades"
    write_report(folder, _grades())
    return folder


ROSTER = f'''name,submission,id
Ada Lovelace,ada,1001
Bob Babbage,bob,1002
Carl Gauss,carl,1003
Eve Noether,eve,1005
"Mallory Formula","{HOSTILE.replace('"', '""')}",1006
Gus Riemann,gus,1007
'''

# Canvas's layout (see labkit/grading/lms/canvas.py): the student columns, closed by Section; assignments titled
# "Title (number)"; read-only totals; a Muted row, the Points Possible row, then the students. Exported with a
# byte-order mark. Frank has no roster entry; "Student, Test" is Canvas's test student.
CANVAS = (
    "\ufeffStudent,ID,SIS User ID,SIS Login ID,Section,Quiz 1 (501),Lab 8 (777),Current Score,Final Score\n"
    ",,,,,,Muted,,\n"
    "    Points Possible,,,,,10,100,(read only),(read only)\n"
    '"Lovelace, Ada",1001,S1001,ada@uni.example,Section A,9,,90,90\n'
    '"Babbage, Bob",1002,S1002,bob@uni.example,Section A,7.5,,75,75\n'
    '"Gauss, Carl",1003,S1003,carl@uni.example,Section B,8,55,80,80\n'
    '"Noether, Eve",1005,S1005,eve@uni.example,Section B,10,,100,100\n'
    "\"=cmd|' /C calc'!A0\",1006,S1006,mallory@uni.example,Section B,6,,60,60\n"
    '"Fourier, Frank",1004,S1004,frank@uni.example,Section A,,,,\n'
    '"Student, Test",9999,,,Section A,,,,\n'
)


def _write(path, text, encoding="utf-8"):
    path.write_bytes(text.encode(encoding))
    return path


@pytest.fixture
def inputs(tmp_path):
    return _write(tmp_path / "gradebook.csv", CANVAS), _write(tmp_path / "roster.csv", ROSTER)


def _rows(path, delimiter=","):
    return list(csv.reader(io.StringIO(path.read_bytes().decode("utf-8-sig"), newline=""), delimiter=delimiter))


def _snapshot(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def test_a_new_canvas_column_holds_the_totals_and_everything_else_is_kept(out, inputs, tmp_path):
    gradebook, roster = inputs
    target = tmp_path / "import.csv"
    export = canvas.to_canvas(
        read_results([out]), gradebook, roster, target, column="Interpolation lab", new_column=True
    )
    before, after = _rows(gradebook), _rows(target)
    # every row and column as exported, one column added at the end
    assert [row[:-1] for row in after] == before
    assert after[0][-1] == "Interpolation lab"
    column = {row[1] or row[0].strip(): row[-1] for row in after[1:]}
    assert column == {
        "": "",  # the Muted row
        "Points Possible": "100",  # the rubric's full credit: Canvas makes the new assignment worth it
        "1001": "104",  # ada: 100 + 4 extra credit
        "1002": "17.5",
        "1003": "",  # carl could not be graded: no number, never 0
        "1005": "",  # eve submitted nothing
        "1006": "10",  # the submission with the formula name, matched through the roster
        "1004": "",  # frank has no roster entry
        "9999": "",
    }
    # the file is Canvas's own encoding: the byte-order mark and line endings kept, the input untouched
    assert target.read_bytes().startswith(b"\xef\xbb\xbfStudent,ID,") and b"\r\n" not in target.read_bytes()
    assert gradebook.read_text(encoding="utf-8") == CANVAS
    assert export.exported == {"ada": ("1001", 104.0), "bob": ("1002", 17.5), HOSTILE: ("1006", 10.0)}


def test_canvas_lists_everyone_who_got_nothing(out, inputs, tmp_path):
    gradebook, roster = inputs
    export = canvas.to_canvas(read_results([out]), gradebook, roster, tmp_path / "import.csv", column="Lab 8")
    assert export.not_graded == {"carl": "its grading crashed twice"}
    assert sorted(export.not_in_roster) == sorted(["dora", ESCAPE])
    assert export.no_submission == [("eve", "1005"), ("gus", "1007")]
    assert export.not_in_lms == []  # gus has no submission, which is said first
    assert export.lms_only == [("Fourier, Frank", "1004")]  # Canvas's test student is no one to list
    assert export.listed == 6
    assert "note: Canvas's test student ('Student, Test') is in the gradebook; left as it is." in export.summary()
    lines = export.problems()
    assert "not graded, no points exported: carl (its grading crashed twice)" in lines
    assert "in the Canvas gradebook, not in the roster: Fourier, Frank (id 1004)" in lines
    assert all("\x1b" not in line for line in lines) and any("mal\ufffd[2Jory" in line for line in lines)


def test_the_summary_has_every_student_once_and_neutralises_formula_names(out, inputs, tmp_path):
    gradebook, roster = inputs
    export = canvas.to_canvas(read_results([out]), gradebook, roster, tmp_path / "import.csv", column="Lab 8")
    assert export.summary_path == tmp_path / "import-summary.csv"
    rows = _rows(export.summary_path)
    assert rows[0] == ["submission", "id", "points", "status"]
    status = {row[0] or row[1]: row[1:] for row in rows[1:]}
    assert status["ada"] == ["1001", "104", "exported"]
    assert status["carl"] == ["1003", "", "not graded: its grading crashed twice"]
    assert status["dora"] == ["", "100", "no roster entry"]  # the total, for entering by hand
    assert status["eve"] == ["1005", "", "no submission (in the roster)"]
    assert status["1004"] == ["1004", "", "in the Canvas gradebook (Fourier, Frank), not in the roster"]
    # a name that a spreadsheet would run as a formula is shown as text, and no control character is left
    assert "'" + HOSTILE in status and HOSTILE not in status
    assert all("\x1b" not in cell for row in rows for cell in row)
    assert (
        len(rows) == 1 + 6 + 2 + 1
    )  # six submissions, two roster entries without one, a Canvas row (not the test student)


def test_an_existing_canvas_column_is_filled_and_a_cell_without_a_grade_is_left_as_exported(out, inputs, tmp_path):
    gradebook, roster = inputs
    target = tmp_path / "import.csv"
    export = canvas.to_canvas(read_results([out]), gradebook, roster, target, column="Lab 8")
    before, after = _rows(gradebook), _rows(target)
    assert after[0] == before[0] and export.column == "Lab 8 (777)"
    at = before[0].index("Lab 8 (777)")
    for old, new in zip(before, after):
        assert old[:at] + old[at + 1 :] == new[:at] + new[at + 1 :]  # nothing else changed
    assert {row[1]: row[at] for row in after[3:]} == {
        "1001": "104",
        "1002": "17.5",
        "1003": "55",  # carl was not graded: the grade Canvas holds stays
        "1005": "",
        "1006": "10",
        "1004": "",
        "9999": "",
    }
    assert after[1][at] == "Muted" and after[2][at] == "100"
    # the full header, with Canvas's number, names the same column
    again = canvas.to_canvas(read_results([out]), gradebook, roster, tmp_path / "again.csv", column="Lab 8 (777)")
    assert _rows(tmp_path / "again.csv") == after and again.column == "Lab 8 (777)"


def test_a_column_the_gradebook_lacks_is_refused_with_its_assignments_unless_new_column_is_given(out, inputs, tmp_path):
    gradebook, roster = inputs
    grades = read_results([out])
    message = _refused(
        tmp_path,
        lambda: canvas.to_canvas(grades, gradebook, roster, tmp_path / "x.csv", column="Lab 9"),
        "has no assignment column named 'Lab 9'",
        "its assignment columns are 'Quiz 1 (501)', 'Lab 8 (777)'.",
        "--new-column",
    )
    # the totals are not assignments, and the student columns are not listed
    assert "Current Score" not in message and "Final Score" not in message and "Section" not in message
    # the default column is no exception: a gradebook without a 'labkit' column is not given one silently
    _refused(tmp_path, lambda: canvas.to_canvas(grades, gradebook, roster, tmp_path / "x.csv"), "named 'labkit'")
    # asked for on purpose, the column is added
    export = canvas.to_canvas(grades, gradebook, roster, tmp_path / "x.csv", column="Lab 9", new_column=True)
    assert _rows(tmp_path / "x.csv")[0][-1] == "Lab 9" and export.column == "Lab 9"


def test_new_column_refuses_a_column_the_gradebook_has(out, inputs, tmp_path):
    gradebook, roster = inputs
    grades = read_results([out])
    for column in ("Lab 8", "Lab 8 (777)", " lab 8 ".upper().title()):
        _refused(
            tmp_path,
            lambda c=column: canvas.to_canvas(grades, gradebook, roster, tmp_path / "x.csv", column=c, new_column=True),
            "already has the assignment column 'Lab 8 (777)'",
            "leave out --new-column to fill it",
        )


def test_the_assignments_listed_in_the_refusal_are_bounded_and_printable(out, tmp_path):
    names = [f"Quiz {i} \x1b[2J (50{i})" for i in range(canvas.MAX_LISTED + 7)] + ["Current Score"]
    header = "Student,ID,Section," + ",".join(names)
    points = "    Points Possible,,," + ",".join(["5"] * (len(names) - 1)) + ",(read only)"
    gradebook = _write(tmp_path / "gradebook.csv", f"{header}\n{points}\nAda,1001,A{',' * len(names)}\n")
    roster = _write(tmp_path / "roster.csv", "submission,id\nada,1001\n")
    message = _refused(
        tmp_path,
        lambda: canvas.to_canvas(read_results([out]), gradebook, roster, tmp_path / "x.csv", column="Exam"),
        "and 7 more",
    )
    assert "\x1b" not in message and message.count("'Quiz") == canvas.MAX_LISTED
    empty = _write(tmp_path / "empty.csv", "Student,ID,Section,Current Score\nAda,1001,A,\n")
    _refused(
        tmp_path,
        lambda: canvas.to_canvas(read_results([out]), empty, roster, tmp_path / "x.csv", column="Quiz"),
        "it has no assignment column yet",
    )


def test_the_roster_can_match_canvas_on_sis_ids(out, tmp_path):
    gradebook = _write(tmp_path / "gradebook.csv", CANVAS)
    roster = _write(
        tmp_path / "roster.csv", "submission,id\nada,ada@uni.example\nbob,bob@uni.example\ndora,dora@uni.example\n"
    )
    export = canvas.to_canvas(
        read_results([out]), gradebook, roster, tmp_path / "import.csv", key="SIS Login ID", new_column=True
    )
    rows = {row[1]: row[-1] for row in _rows(tmp_path / "import.csv")[3:]}
    assert rows["1001"] == "104" and rows["1002"] == "17.5" and rows["1003"] == ""
    # dora was graded, but no row of the gradebook has her login: listed, and her total is in the summary
    assert export.not_in_lms == [("dora", "dora@uni.example")] and "dora" not in export.exported
    assert "in the roster, not in the Canvas gradebook: dora (id dora@uni.example)" in export.problems()
    summary = {row[0]: row[1:] for row in _rows(export.summary_path)}
    assert summary["dora"] == ["dora@uni.example", "100", "not in the Canvas gradebook"]
    # the test student has no login: left alone all the same
    assert all(name != "Student, Test" for name, _ in export.lms_only)


def test_canvas_test_student_is_left_alone_and_the_export_exits_0(tmp_path):
    """Every Canvas gradebook has its test student, whom no roster holds: noted, never listed."""
    results = tmp_path / "grades"
    write_report(results, _grades()[:2])  # ada and bob
    book = CANVAS.split('"Gauss, Carl"')[0] + '"Student, Test",9999,,,Section A,,,,\n'
    gradebook = _write(tmp_path / "book.csv", book)
    roster = _write(tmp_path / "roster.csv", "submission,id\nada,1001\nbob,1002\n")
    run = _cli(results, "--canvas", gradebook, "--roster", roster, "--column", "Lab 8", "--out", tmp_path / "i.csv")
    assert run.returncode == 0, run.stderr
    assert "Canvas's test student ('Student, Test') is in the gradebook; left as it is." in run.stdout
    rows = {row[0]: row[6] for row in _rows(tmp_path / "i.csv")[3:]}
    assert rows == {"Lovelace, Ada": "104", "Babbage, Bob": "17.5", "Student, Test": ""}


def test_a_semicolon_export_keeps_its_separator_and_decimal_commas(out, tmp_path):
    text = (
        "Student;ID;SIS Login ID;Section;Quiz 1 (501)\r\n"
        "    Points Possible;;;;7,5\r\n"
        "Lovelace Ada;1001;ada;Section A;7,5\r\n"
        "Babbage Bob;1002;bob;Section A;6\r\n"
    )
    gradebook = _write(tmp_path / "gradebook.csv", text)
    roster = _write(tmp_path / "roster.csv", "submission;id\nada;1001\nbob;1002\n")
    canvas.to_canvas(read_results([out]), gradebook, roster, tmp_path / "import.csv", new_column=True)
    written = (tmp_path / "import.csv").read_bytes().decode("utf-8")
    assert not written.startswith("\ufeff")  # no byte-order mark where the export had none
    assert written == (
        "Student;ID;SIS Login ID;Section;Quiz 1 (501);labkit\r\n"
        "    Points Possible;;;;7,5;100\r\n"
        "Lovelace Ada;1001;ada;Section A;7,5;104\r\n"
        "Babbage Bob;1002;bob;Section A;6;17,5\r\n"
    )


@pytest.mark.parametrize(
    "key, roster, header",
    [
        ("idnumber", "submission,id\nada,S1001\nbob,S1002\ncarl,S1003\neve,S1005\n", "ID number"),
        ("email", "submission,id\nada,ada@uni.example\nbob,bob@uni.example\ncarl,carl@uni.example\n", "Email address"),
    ],
)
def test_moodle_gets_one_row_per_graded_student_keyed_as_asked(out, tmp_path, key, roster, header):
    path = _write(tmp_path / "roster.csv", roster)
    export = moodle.to_moodle(read_results([out]), path, tmp_path / "moodle.csv", key=key, column="Lab 8")
    ids = dict(line.split(",") for line in roster.splitlines()[1:])
    # carl could not be graded: left out, so Moodle keeps what it has (an empty cell would mean "no grade")
    assert _rows(tmp_path / "moodle.csv") == [[header, "Lab 8"], [ids["ada"], "104"], [ids["bob"], "17.5"]]
    assert export.not_graded == {"carl": "its grading crashed twice"}
    assert sorted(export.not_in_roster) == sorted(["dora", ESCAPE, HOSTILE])
    assert [name for name, _ in export.no_submission] == (["eve"] if key == "idnumber" else [])
    assert any("above full credit" in note and "104" in note for note in export.notes)


def test_moodle_feedback_says_the_points_in_words(out, tmp_path):
    path = _write(tmp_path / "roster.csv", "submission,id\nada,S1001\nbob,S1002\n")
    moodle.to_moodle(read_results([out]), path, tmp_path / "moodle.csv", feedback=True)
    rows = _rows(tmp_path / "moodle.csv")
    assert rows[0] == ["ID number", "labkit", "Feedback"]
    first, rest = rows[1][2].split("\n", 1)
    assert first == "104 points: 100 of 100 for full credit, and 4 of extra credit (labkit grade)"
    assert rest.startswith(
        "\nTotal: 104 / 100 points\n  including 4 extra credit\nFeedback for ada\n"
    )  # then the student's whole feedback, many lines
    assert rows[2][2].startswith(
        "17.5 points: 17.5 of 100 for full credit (labkit grade)\n\nTotal: 17.5 / 100 points\nFeedback for bob"
    )
    assert "Exercise 3, the order the table shows" in rows[2][2] and rows[2][2].count("\n") > 10


def _late_grades():
    """The lab's rubric with a [late] table (10% per started day, at most 50%), and four submissions."""
    rubric = dataclasses.replace(
        LAB, late=late.from_dict({"deadline": "2026-12-01T23:59:00+01:00", "per": "day", "percent": 10, "cap": 50})
    )
    full = {n: 1.0 for n in (2, 3, 4, *SPLINES)}

    def handed_in(text):
        return late.SubmissionTime(late.parse_deadline(text), late.FROM_CSV)

    return [
        # 104 points (100 + 4 extra credit), 1 day 8 h late: 2 started days, 20% off: 104 - 20.8 = 83.2
        SubmissionGrade("ada", _results({**full, 16: 0.5}), rubric=rubric, time=handed_in("2026-12-03T08:00+01:00")),
        # 17.5 points, on time
        SubmissionGrade("bob", _results({2: 1.0, 3: 0.5}), rubric=rubric, time=handed_in("2026-12-01T20:00+01:00")),
        # 100 points, 6 days 10 h late: 7 started days, 70% capped at 50%: 100 - 50 = 50
        SubmissionGrade("cy", _results(full), rubric=rubric, time=handed_in("2026-12-08T10:00+01:00")),
        # 10 points, no known time: not penalised
        SubmissionGrade("dee", _results({2: 1.0}), rubric=rubric),
    ]


def test_moodle_feedback_begins_with_the_grade_after_the_late_penalty_and_states_the_penalty(tmp_path):
    roster = _write(tmp_path / "roster.csv", "submission,id\nada,S1\nbob,S2\ncy,S3\ndee,S4\n")
    moodle.to_moodle(_late_grades(), roster, tmp_path / "moodle.csv", feedback=True)
    rows = {row[0]: row[1:] for row in _rows(tmp_path / "moodle.csv")[1:]}
    assert {key: grade for key, (grade, _) in rows.items()} == {"S1": "83.2", "S2": "17.5", "S3": "50", "S4": "10"}
    for grade, feedback in rows.values():
        assert feedback.split(" ")[0] == grade  # the first number is the grade beside it
    rows = {key: (grade, feedback.split("\n")[0]) for key, (grade, feedback) in rows.items()}  # its first line
    assert rows["S1"][1] == (
        "83.2 points: 104 (100 of 100 for full credit, and 4 of extra credit) less 20.8 for late work "
        "(2 started days, 20% off) (labkit grade)"
    )
    assert rows["S3"][1] == (
        "50 points: 100 (100 of 100 for full credit) less 50 for late work (7 started days, 50% off, the cap) "
        "(labkit grade)"
    )
    assert rows["S2"][1] == "17.5 points: 17.5 of 100 for full credit (labkit grade)"  # on time: nothing to say
    assert "late" not in rows["S4"][1]


def test_another_rubric_than_the_runs_is_refused_and_none_needed(out, inputs, tmp_path):
    rubric = tmp_path / "rubric.toml"
    rubric.write_text("required = [2, 3]\n[points]\n2 = 50\n3 = 50\n")
    gradebook, roster = inputs
    run = _cli(out, "--canvas", gradebook, "--roster", roster, "--rubric", rubric, "--out", tmp_path / "x.csv")
    assert run.returncode == 2 and "differs from it in its exercises, groups or points" in run.stderr, run.stderr
    assert not (tmp_path / "x.csv").exists()
    # without --rubric, the run's own: the column holds grades.csv's totals
    canvas.to_canvas(read_results([out]), gradebook, roster, tmp_path / "import.csv", new_column=True)
    with open(out / "grades.csv", newline="", encoding="utf-8") as handle:
        totals = {row["submission"]: row["total"] for row in csv.DictReader(handle)}
    exported = {row[1]: row[-1] for row in _rows(tmp_path / "import.csv")[1:]}
    assert (exported["1001"], exported["1002"]) == (totals["ada"], totals["bob"]) == ("104", "17.5")


# --- bad input: a clear error, and nothing written or changed ---------------------------------------------------


def _refused(tmp_path, call, *messages):
    before = _snapshot(tmp_path)
    with pytest.raises(ValueError) as caught:
        call()
    for message in messages:
        assert message in str(caught.value), str(caught.value)
    assert _snapshot(tmp_path) == before  # nothing written, no input changed
    return str(caught.value)


@pytest.mark.parametrize(
    "roster, messages",
    [
        ("submission,id\nada,1001\nbob,1001\n", ["gives the id '1001' to two submissions", "rows 2 and 3"]),
        ("submission,id\nada,1001\nada,1002\n", ["names the submission 'ada' twice", "rows 2 and 3"]),
        ("name,student\nada,1001\n", ["needs a header row with the columns 'submission'", "'name', 'student'"]),
        ("submission,id\nada,\n", ["row 2: the id is empty"]),
        ("submission,id\n\n", ["has a header but no student"]),
        ("submission,id,id\nada,1,2\n", ["has two 'id' columns"]),
    ],
)
def test_a_bad_roster_is_refused(out, tmp_path, roster, messages):
    gradebook = _write(tmp_path / "gradebook.csv", CANVAS)
    path = _write(tmp_path / "roster.csv", roster)
    _refused(tmp_path, lambda: canvas.to_canvas(read_results([out]), gradebook, path, tmp_path / "x.csv"), *messages)
    _refused(tmp_path, lambda: moodle.to_moodle(read_results([out]), path, tmp_path / "x.csv"), *messages)


@pytest.mark.parametrize(
    "content, messages",
    [
        ("Name,Points\nada,3\n", ["is not a Canvas gradebook export", "'Student' and 'ID'", "'Name', 'Points'"]),
        ("Student,ID,Quiz (1)\nAda,1001,3\n", ["no 'Section' column"]),
        ("Student,ID,Section,Quiz (1)\nAda,1001,A,3,4\n", ["row 2 has 5 cells but the header only 4"]),
        ('Student,ID,Section,Quiz (1)\n"Ada,1001,A,3\n', ["is not valid CSV"]),
    ],
)
def test_a_file_that_is_not_a_canvas_export_is_refused(out, tmp_path, content, messages):
    gradebook = _write(tmp_path / "gradebook.csv", content)
    roster = _write(tmp_path / "roster.csv", ROSTER)
    _refused(tmp_path, lambda: canvas.to_canvas(read_results([out]), gradebook, roster, tmp_path / "x.csv"), *messages)


def test_a_canvas_export_that_is_not_utf8_or_is_a_workbook_is_refused(out, tmp_path):
    roster = _write(tmp_path / "roster.csv", ROSTER)
    latin = _write(tmp_path / "latin.csv", CANVAS.replace("\ufeff", "").replace("Ada", "Adà"), "latin-1")
    _refused(
        tmp_path,
        lambda: canvas.to_canvas(read_results([out]), latin, roster, tmp_path / "x.csv"),
        "is not UTF-8 text",
        "CSV UTF-8",
    )
    workbook = tmp_path / "gradebook.xlsx"
    workbook.write_bytes(b"PK\x03\x04" + bytes(range(256)))
    _refused(
        tmp_path,
        lambda: canvas.to_canvas(read_results([out]), workbook, roster, tmp_path / "x.csv"),
        "is an Excel workbook, not CSV",
    )


def test_canvas_columns_and_ids_that_cannot_be_filled_are_refused(out, inputs, tmp_path):
    gradebook, roster = inputs
    grades = read_results([out])

    def refused(*messages, book=gradebook, **options):
        return _refused(
            tmp_path, lambda: canvas.to_canvas(grades, book, roster, tmp_path / "x.csv", **options), *messages
        )

    refused("as a student column or a total", column="Current Score")
    refused("as a student column or a total", column="Section")
    refused("starts like a spreadsheet formula", column="=1+1")
    refused("must be one line", column="Lab\n8")
    refused("--key for Canvas is one of", key="email")
    ambiguous = _write(tmp_path / "two.csv", CANVAS.replace("Quiz 1 (501)", "Lab 8 (778)"))
    refused("has 2 assignment columns named 'Lab 8'", "--column 'Lab 8 (778)'", book=ambiguous, column="Lab 8")
    readonly = _write(tmp_path / "ro.csv", CANVAS.replace(",10,100,", ",(read only),100,"))
    refused("is read-only in Canvas", book=readonly, column="Quiz 1")
    no_sis = _write(
        tmp_path / "nosis.csv", "Student,ID,SIS Login ID,Section,Quiz (1)\n    Points Possible,,,,5\nAda,1001,ada,A,3\n"
    )
    refused("has no 'SIS User ID' column", book=no_sis, key="SIS User ID")
    twice = _write(tmp_path / "twice.csv", CANVAS.replace('"Fourier, Frank",1004', '"Fourier, Frank",1001'))
    refused("has two rows with ID '1001' (rows 4 and 9)", book=twice, column="Lab 8")
    refused(
        "no submission of the results matched a row", key="SIS User ID", column="Lab 8"
    )  # the roster holds Canvas IDs


def test_an_output_is_never_an_input_nor_an_existing_file_unless_forced(out, inputs, tmp_path):
    gradebook, roster = inputs
    grades = read_results([out])
    for target in (gradebook, roster):
        message = _refused(tmp_path, lambda t=target: canvas.to_canvas(grades, gradebook, roster, t, force=True))
        assert "is an input of this export; it is never overwritten" in message
    target = _write(tmp_path / "import.csv", "my earlier export")
    _refused(tmp_path, lambda: canvas.to_canvas(grades, gradebook, roster, target), "already exists", "--force")
    _refused(tmp_path, lambda: canvas.to_canvas(grades, gradebook, roster, tmp_path / "no" / "x.csv"), "does not exist")
    canvas.to_canvas(grades, gradebook, roster, target, force=True, new_column=True)
    assert _rows(target)[0][-1] == "labkit" and gradebook.read_text(encoding="utf-8") == CANVAS
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "gradebook.csv",
        "import-summary.csv",
        "import.csv",
        "roster.csv",
    ]  # no temporary file left


def test_moodle_refuses_ids_that_are_not_what_the_key_says(out, tmp_path):
    grades = read_results([out])
    roster = _write(tmp_path / "roster.csv", "submission,id\nada,S1001\n")
    _refused(
        tmp_path, lambda: moodle.to_moodle(grades, roster, tmp_path / "m.csv", key="email"), "is not an email address"
    )
    formula = _write(tmp_path / "roster.csv", "submission,id\nada,=1+1\n")
    _refused(
        tmp_path, lambda: moodle.to_moodle(grades, formula, tmp_path / "m.csv"), "starts like a spreadsheet formula"
    )
    nobody = _write(tmp_path / "roster.csv", "submission,id\ncarl,S1003\n")  # only a student who was not graded
    _refused(tmp_path, lambda: moodle.to_moodle(grades, nobody, tmp_path / "m.csv"), "no graded submission")
    _refused(tmp_path, lambda: moodle.to_moodle(grades, nobody, tmp_path / "m.csv", key="ID"), "idnumber or email")


def test_moodle_refuses_email_addresses_under_the_id_number_key(out, tmp_path):
    grades = read_results([out])
    emails = _write(tmp_path / "roster.csv", "submission,id\nada,ada@uni.example\nbob,bob@uni.example\n")
    message = _refused(
        tmp_path,
        lambda: moodle.to_moodle(grades, emails, tmp_path / "m.csv"),  # key="idnumber", the default
        "holds email addresses (e.g. 'ada' ('ada@uni.example'), 'bob' ('bob@uni.example')), not ID numbers",
        "give --key email",
    )
    assert "ID number column" in message
    mixed = _write(
        tmp_path / "roster.csv",
        f"submission,id\nada,S1001\nbob,bob@uni.example\ncarl,S1003\n{ESCAPE},m\x1b[2J@uni.example\n",
    )
    message = _refused(
        tmp_path,
        lambda: moodle.to_moodle(grades, mixed, tmp_path / "m.csv", key="idnumber"),
        "mixes email addresses (2 of 4: 'bob' ('bob@uni.example'), 'mal\ufffd[2Jory' ('m\ufffd[2J@uni.example'))",
        "with other ids (e.g. 'ada' ('S1001'), 'carl' ('S1003'))",
        "correct those rows",
    )
    assert "\x1b" not in message
    # and under --key email, the ID numbers among the addresses are refused as before
    _refused(tmp_path, lambda: moodle.to_moodle(grades, mixed, tmp_path / "m.csv", key="email"), "not an email address")
    # the same roster of addresses, under the key that says so, is exported
    emails = _write(tmp_path / "roster.csv", "submission,id\nada,ada@uni.example\nbob,bob@uni.example\n")
    export = moodle.to_moodle(grades, emails, tmp_path / "m.csv", key="email")
    assert export.exported == {"ada": ("ada@uni.example", 104.0), "bob": ("bob@uni.example", 17.5)}


# --- the command ------------------------------------------------------------------------------------------------


def _cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "labkit.cli", "export", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=cwd,
    )


def test_labkit_export_canvas_writes_next_to_out_and_lists_on_stderr(out, tmp_path):
    run_dir = tmp_path / "grades"
    write_report(run_dir, _grades())
    gradebook = _write(tmp_path / "gradebook.csv", CANVAS)
    roster = _write(tmp_path / "roster.csv", ROSTER)
    run = _cli(run_dir, "--canvas", gradebook, "--roster", roster, "--column", "Lab 8")
    assert run.returncode == 1, run.stderr  # written, with students listed
    target = tmp_path / "grades-canvas.csv"
    assert _rows(target)[3][6] == "104" and (tmp_path / "grades-canvas-summary.csv").exists()
    assert f"wrote {target}" in run.stdout and "6 student(s) got nothing from this file" in run.stdout
    assert "labkit export: not graded, no points exported: carl (its grading crashed twice)" in run.stderr
    assert "labkit export: no roster entry, nothing exported: dora" in run.stderr
    assert "labkit export: in the roster, no submission: eve (id 1005)" in run.stderr
    assert "\x1b" not in run.stderr + run.stdout and "mal\ufffd[2Jory" in run.stderr
    # a second run refuses to replace the file
    again = _cli(run_dir, "--canvas", gradebook, "--roster", roster)
    assert again.returncode == 2 and "already exists" in again.stderr and again.stdout == ""


def test_labkit_export_adds_a_canvas_column_only_with_new_column(tmp_path):
    run_dir = tmp_path / "grades"
    write_report(run_dir, _grades())
    gradebook = _write(tmp_path / "gradebook.csv", CANVAS)
    roster = _write(tmp_path / "roster.csv", ROSTER)
    typo = _cli(run_dir, "--canvas", gradebook, "--roster", roster, "--column", "Lab 88")
    assert typo.returncode == 2 and "has no assignment column named 'Lab 88'" in typo.stderr
    assert "'Lab 8 (777)'" in typo.stderr and "--new-column" in typo.stderr
    assert not (tmp_path / "grades-canvas.csv").exists()
    run = _cli(run_dir, "--canvas", gradebook, "--roster", roster, "--column", "Lab 88", "--new-column")
    assert run.returncode == 1, run.stderr
    rows = _rows(tmp_path / "grades-canvas.csv")
    assert rows[0][-1] == "Lab 88" and rows[2][-1] == "100" and rows[3][-1] == "104"
    moodle = _cli(run_dir, "--moodle", "--roster", roster, "--new-column", "--out", tmp_path / "m.csv")
    assert moodle.returncode == 2 and "--new-column is for --canvas" in moodle.stderr


def test_labkit_export_moodle_exits_0_when_everyone_matched(tmp_path):
    run_dir = tmp_path / "grades"
    write_report(run_dir, _grades()[:2])
    roster = _write(tmp_path / "roster.csv", "submission,id\nada,ada@uni.example\nbob,bob@uni.example\n")
    target = tmp_path / "for-moodle.csv"
    run = _cli(run_dir, "--moodle", "--roster", roster, "--key", "email", "--out", target)
    assert run.returncode == 0, run.stderr
    assert run.stderr == "" and "every submission and roster entry matched" in run.stdout
    assert _rows(target) == [["Email address", "labkit"], ["ada@uni.example", "104"], ["bob@uni.example", "17.5"]]


def test_labkit_export_refuses_bad_input_with_status_2(tmp_path):
    roster = _write(tmp_path / "roster.csv", ROSTER)
    empty = tmp_path / "empty"
    empty.mkdir()
    run = _cli(empty, "--moodle", "--roster", roster)
    assert run.returncode == 2 and "has no run record (record.json)" in run.stderr
    run = _cli(empty, "--canvas", tmp_path / "gradebook.csv", "--roster", roster, "--feedback")
    assert run.returncode == 2 and "--feedback is for --moodle" in run.stderr
    run = _cli(empty, "--roster", roster)
    assert run.returncode == 2 and "one of the arguments --canvas --moodle --lms is required" in run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty", "roster.csv"]


def test_the_default_column_is_the_modules():
    from labkit.cli import build_parser

    args = build_parser().parse_args(["export", "grades", "--moodle", "--roster", "r.csv"])
    assert args.column == exports.DEFAULT_COLUMN
