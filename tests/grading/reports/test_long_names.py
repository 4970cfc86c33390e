"""Names are keys, never cut (issue 44): two 230-character names sharing 199 characters go through the marking
page, its marks.csv, grades.csv, `labkit merge`, the report and the export as themselves, and apart."""

import csv
import json
import re

from test_marking import _passed, _rubric

from labkit.cli import main
from labkit.grading.lms import moodle
from labkit.grading.reports import marking
from labkit.grading.store import marks as store_marks
from labkit.grading.store import report
from labkit.grading.store.names import name_from_cell, shown_name
from labkit.grading.store.report import read_results

COMMON = "ada lovelace, " + "x" * 185  # 199 characters
FIRST, SECOND = COMMON + "1" + "a" * 30, COMMON + "2" + "b" * 30  # 230 each
ODD = "=tab\there, 'quote\" and a newline\nin it"


def _run(tmp_path, rubric_object, name="run"):
    grades = [
        report.SubmissionGrade(
            student,
            {3: _passed(3), 4: _passed(4)},
            [],
            7,
            rubric_object,
            answers={"exercise3-answer-1": f"answer of {student[-3:]}"},
        )
        for student in (FIRST, SECOND, ODD)
    ]
    report.write_report(tmp_path / name, grades)
    return tmp_path / name


def _page_data(out):
    page = (out / marking.PAGE).read_text(encoding="utf-8")
    text = re.search(r"var DATA = (\{.*?\});\n", page, re.DOTALL).group(1)
    return json.loads(text.replace("\\u003c", "<").replace("\\u003e", ">").replace("\\u0026", "&"))


def test_long_names_are_shown_apart_and_keyed_whole(tmp_path):
    out = _run(tmp_path, _rubric(tmp_path))
    marking.write_page(out)
    answers = [a for task in _page_data(out)["tasks"] for a in task["answers"] if task["kind"] == "answer"]
    assert {a["submission"] for a in answers} == {FIRST, SECOND, ODD}
    shown = {a["submission"]: a["shown"] for a in answers}
    assert shown[FIRST] != shown[SECOND] and all(len(s) <= 200 for s in shown.values())
    assert shown_name(FIRST, 200) == shown[FIRST]


def test_marks_csv_grades_csv_merge_and_export_keep_every_name(tmp_path):
    marked = _rubric(tmp_path)
    out = _run(tmp_path, marked)
    path = tmp_path / "marks.csv"
    with open(path, "w", newline="", encoding="utf-8") as handle:  # as the page writes it (see templates/marking.js)
        writer = csv.writer(handle)
        writer.writerow(store_marks.HEADER)
        writer.writerows([[FIRST, "exercise3-answer-1", "5", ""], [SECOND, "exercise3-answer-1", "1", ""]])
        writer.writerow(["'" + ODD, "exercise3-answer-1", "3", ""])
    assert main(["mark", str(out), "--import", str(path), "--quiet"]) == 0
    totals = {g.name: g.total for g in read_results([out])}
    assert totals[FIRST] - totals[SECOND] == 4 and totals[ODD] - totals[SECOND] == 2
    with open(out / "grades.csv", newline="", encoding="utf-8") as handle:
        cells = [row[0] for row in list(csv.reader(handle))[1:]]
    assert sorted(name_from_cell(cell, totals) for cell in cells) == sorted(totals)
    again = tmp_path / "again.csv"
    again.write_text(store_marks.marks_csv(read_results([out])), encoding="utf-8")
    assert store_marks.import_marks(out, again) == 0  # labkit's own marks.csv reads back as the same marks
    merged = tmp_path / "merged"
    assert main(["merge", str(out), "--out", str(merged), "--quiet"]) in (0, 1)
    assert {g.name: g.total for g in read_results([merged])} == totals
    assert main(["report", str(merged), "--quiet"]) == 0
    roster = tmp_path / "roster.csv"
    with open(roster, "w", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerows([["submission", "id"], [FIRST, "S1"], [SECOND, "S2"], [ODD, "S3"]])
    moodle.to_moodle(read_results([merged]), roster, tmp_path / "moodle.csv", key="idnumber", column="Lab 8")
    with open(tmp_path / "moodle.csv", newline="", encoding="utf-8") as handle:
        exported = {row[0]: float(row[1]) for row in list(csv.reader(handle))[1:]}
    assert exported == {"S1": totals[FIRST], "S2": totals[SECOND], "S3": totals[ODD]}
