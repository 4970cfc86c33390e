"""What a person marks (issue 32): answer points in the rubric, and `labkit mark OUT --import marks.csv`."""

import csv
import json
from datetime import UTC, datetime

import pytest

from labkit.cli import main
from labkit.exercises.registry import LAB
from labkit.grading.reports import marking
from labkit.grading.reports.class_report import read as read_class
from labkit.grading.store import marks as store_marks
from labkit.grading.store import report, rubric
from labkit.grading.store.report import SubmissionGrade, file_stem
from labkit.grading.store.rubric import DEFAULT

# the answers of both branches and of exercise 3 weighed: the branches stay worth the same (3 + 3)
ANSWERS = """
[answers]
exercise3-answer-1 = 5
exercise7-answer-1 = 3
exercise11-answer-1 = 3
"""


def _rubric(tmp_path, extra=ANSWERS):
    path = tmp_path / "marked.toml"
    path.write_text(rubric.DEFAULT.read_text() + extra)
    return rubric.load(path)


def _passed(number, name="part", weight=10, held=None):
    check = {"name": name, "passed": True, "hint": "", "weight": weight, "steps": []}
    if held is not None:
        check["held"] = held
    return {"exercise": number, "defined": True, "checks": [check], "points": 0, "passed": held is None,
            "fraction": 0.0 if held else 1.0}  # fmt: skip


HELD = {"definition": "eval_pherm", "source": "labkit.piecewise.eval_pherm", "share": 0.93,
        "lines": [["q1 = np.diff(q0)", "h = np.diff(x)"]]}  # fmt: skip


def _run(tmp_path, rubric_object):
    """A run of two submissions: ada passed 2, 3 and 4 (2 held); =bob passed 3 only, and wrote answers."""
    ada = report.SubmissionGrade(
        "ada",
        {2: _passed(2, "eval_pherm", held=HELD), 3: _passed(3), 4: _passed(4)},
        [],
        7,
        rubric_object,
        answers={"exercise3-answer-1": "Order $h^4$ <script>alert(1)</script>"},
    )
    bob = report.SubmissionGrade("=bob", {3: _passed(3)}, [], 7, rubric_object)
    out = tmp_path / "run"
    report.write_report(out, [ada, bob])
    return out


def _marks(tmp_path, rows, name="marks.csv"):
    path = tmp_path / name
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(store_marks.HEADER)
        writer.writerows(rows)
    return path


def _grades_csv(out):
    with open(out / "grades.csv", newline="", encoding="utf-8") as handle:
        return {row["submission"]: row for row in csv.DictReader(handle)}


def _snapshot(out):
    return {p.relative_to(out): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


# -- the rubric's [answers] table ----------------------------------------------------------------------------------


def test_the_lab_rubric_gives_answers_no_points_and_keeps_its_totals():
    lab = rubric.default()
    assert lab.answers == {} and lab.full_credit == 100 and lab.maximum == 118
    assert "answers" not in json.dumps(lab.data)  # nor in the digest: earlier runs' digests stand


def test_answer_points_add_to_their_exercise_full_credit_and_maximum(tmp_path):
    marked = _rubric(tmp_path)
    assert marked.worth(3) == 15 + 5 and marked.worth(7) == 10 + 3 and marked.worth(2) == 10
    assert marked.full_credit == 100 + 5 + 3 and marked.maximum == 118 + 5 + 3
    assert marked.digest != rubric.default().digest
    assert "exercise3-answer-1 (5)" in marked.describe()


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("[answers]\nexercise3-answer-9 = 2\n", "no answer in words"),
        ("[answers]\nexercise3-answer-1 = -1\n", "at least 0"),
        ('[answers]\nexercise3-answer-1 = "two"\n', "must be a finite number"),
        ("[answers]\nexercise3-answer-1 = nan\n", "must be a finite number"),
        ("[answers]\nexercise7-answer-1 = 3\n", "branches must be worth the same"),
    ],
)
def test_a_bad_answers_table_is_refused_with_what_to_write(tmp_path, table, message):
    with pytest.raises(ValueError, match=message):
        _rubric(tmp_path, "\n" + table)


def test_answers_that_are_no_table_are_refused(tmp_path):
    path = tmp_path / "marked.toml"
    path.write_text("answers = 3\n" + rubric.DEFAULT.read_text())
    with pytest.raises(ValueError, match=r"\[answers\] must be a table"):
        rubric.load(path)


# -- importing marks -----------------------------------------------------------------------------------------------


def test_marks_reach_grades_csv_the_feedback_the_report_and_the_export(tmp_path):
    marked = _rubric(tmp_path)
    out = _run(tmp_path, marked)
    before = _grades_csv(out)
    assert before["ada"]["total"] == "30" and before["ada"]["full credit"] == "108"  # 2 is held
    path = _marks(
        tmp_path,
        [
            ["ada", "exercise3-answer-1", "4.5", "Right order; say why."],
            ["ada", "exercise2/eval_pherm", "release", "Compared: her own."],
            ["'=bob", "exercise4", "excused", "ill"],
        ],
    )
    assert main(["mark", str(out), "--import", str(path), "--quiet"]) == 0
    rows = _grades_csv(out)
    assert rows["ada"]["exercise 3"] == "19.5" and rows["ada"]["exercise 2"] == "10"
    assert rows["ada"]["total"] == "44.5"  # 10 + 19.5 + 15
    assert rows["ada"]["to read: exercise 3, the order the table shows, against piecewise linear"] == "4.5"
    assert rows["'=bob"]["full credit"] == "93" and rows["'=bob"]["total"] == "15"  # 108 less exercise 4's 15
    feedback = (out / "feedback" / f"{file_stem('ada')}.txt").read_text()
    assert "4.5 / 5 points" in feedback and "Right order; say why." in feedback and "Compared: her own." in feedback
    assert "excused" in (out / "feedback" / f"{file_stem('=bob')}.txt").read_text()
    grades = read_class(out, None)  # what `labkit report` and `labkit export` read
    assert {g.name: g.total for g in grades} == {"ada": 44.5, "=bob": 15}
    assert main(["report", str(out), "--quiet"]) == 0
    assert "44.5" in (out / "report.html").read_text(encoding="utf-8")
    from labkit.grading.lms import moodle
    from labkit.grading.store.report import read_results

    roster = tmp_path / "roster.csv"
    roster.write_text("submission,id\nada,S1\n=bob,S2\n", encoding="utf-8")
    moodle.to_moodle(read_results([out]), roster, tmp_path / "moodle.csv", key="idnumber", column="Lab 8")
    with open(tmp_path / "moodle.csv", newline="", encoding="utf-8") as handle:
        exported = {row[0]: row[1] for row in list(csv.reader(handle))[1:]}
    assert exported == {"S1": "44.5", "S2": "15"}


def test_importing_twice_changes_nothing_and_a_later_mark_replaces_the_earlier(tmp_path):
    out = _run(tmp_path, _rubric(tmp_path))
    first = _marks(tmp_path, [["ada", "exercise3-answer-1", "2", "thin"]])
    assert store_marks.import_marks(out, first, now=datetime(2026, 12, 1, tzinfo=UTC)) == 1
    snapshot = _snapshot(out)
    assert store_marks.import_marks(out, first, now=datetime(2026, 12, 2, tzinfo=UTC)) == 0
    assert _snapshot(out) == snapshot
    later = _marks(tmp_path, [["ada", "exercise3-answer-1", "5", "better on a second read"]], "later.csv")
    assert store_marks.import_marks(out, later, now=datetime(2026, 12, 3, tzinfo=UTC)) == 1
    data = json.loads((out / "results" / f"{report.safe_name('ada')}.json").read_text())
    assert data["marks"]["exercise3-answer-1"] == {
        "points": 5.0,
        "comment": "better on a second read",
        "time": "2026-12-03T00:00:00+00:00",
    }
    assert _grades_csv(out)["ada"]["total"] == "35"  # 0 (2 held) + 15 + 5 + 15
    assert main(["report", str(out), "--quiet"]) == 0  # the record vouches for the rewritten results


@pytest.mark.parametrize(
    ("row", "message"),
    [
        (["carol", "exercise3-answer-1", "1", ""], "no submission 'carol'"),
        (["ada", "exercise99", "excused", ""], "nothing to mark"),
        (["ada", "exercise3-answer-1", "6", ""], "outside 0 to 5"),
        (["ada", "exercise3-answer-1", "-1", ""], "outside 0 to 5"),
        (["ada", "exercise3-answer-1", "nan", ""], "outside 0 to 5"),
        (["ada", "exercise3-answer-1", "lots", ""], "not a number"),
        (["ada", "exercise12-answer-1", "1", ""], "gives this answer no points"),
        (["ada", "exercise2/eval_pherm", "3", ""], "release or keep"),
        (["ada", "exercise4", "0", ""], "excused or counted"),
        (["=bob", "exercise2/eval_pherm", "release", ""], "nothing to mark"),  # bob has nothing held
        (["=bob", "exercise3-answer-1", "2", ""], "wrote no answer"),  # bob's answer is blank
    ],
)
def test_a_bad_mark_is_refused_and_nothing_changes(tmp_path, row, message, capsys):
    out = _run(tmp_path, _rubric(tmp_path))
    snapshot = _snapshot(out)
    good = ["ada", "exercise3-answer-1", "1", ""]
    path = _marks(tmp_path, [good, row])
    with pytest.raises(ValueError, match=message):
        store_marks.import_marks(out, path)
    assert _snapshot(out) == snapshot
    assert main(["mark", str(out), "--import", str(path)]) == 2
    assert "nothing changed" in capsys.readouterr().err
    assert _snapshot(out) == snapshot


def test_marks_under_another_rubric_are_refused(tmp_path):
    out = _run(tmp_path, _rubric(tmp_path))
    path = _marks(tmp_path, [["ada", "exercise3-answer-1", "1", ""]])
    snapshot = _snapshot(out)
    with pytest.raises(ValueError, match="graded under the rubric"):
        store_marks.import_marks(out, path, rubric.default())
    assert _snapshot(out) == snapshot


def test_a_held_part_can_be_kept_against_the_rubric_release_and_released_again(tmp_path):
    out = _run(tmp_path, _rubric(tmp_path, ANSWERS + '\n[held]\nrelease = {"ada" = [2]}\n'))
    assert _grades_csv(out)["ada"]["exercise 2"] == "10"
    store_marks.import_marks(out, _marks(tmp_path, [["ada", "exercise2/eval_pherm", "keep", ""]]))
    assert _grades_csv(out)["ada"]["exercise 2"] == "0"
    store_marks.import_marks(out, _marks(tmp_path, [["ada", "exercise2/eval_pherm", "release", ""]]))
    assert _grades_csv(out)["ada"]["exercise 2"] == "10"


def test_a_bad_header_or_a_missing_file_is_a_clear_error(tmp_path):
    out = _run(tmp_path, _rubric(tmp_path))
    bad = tmp_path / "bad.csv"
    bad.write_text("name,score\nada,3\n")
    with pytest.raises(ValueError, match="must start with the header submission,item,points,comment"):
        store_marks.import_marks(out, bad)
    with pytest.raises(ValueError, match="cannot read the marks"):
        store_marks.import_marks(out, tmp_path / "missing.csv")


def test_student_text_in_a_comment_is_data_in_grades_csv_and_the_feedback(tmp_path):
    out = _run(tmp_path, _rubric(tmp_path))
    path = _marks(tmp_path, [["ada", "exercise3-answer-1", "1", "=HYPERLINK(x)\x1b[31m red"]])
    store_marks.import_marks(out, path)
    feedback = (out / "feedback" / f"{file_stem('ada')}.txt").read_text()
    assert "\x1b" not in feedback
    text = store_marks.marks_csv(read_class(out, None))
    assert "'=HYPERLINK" in text and "\x1b" not in text


# -- the marking page ----------------------------------------------------------------------------------------------


def test_a_student_answer_is_escaped_before_its_markdown_is_rendered():
    rendered = marking.render_markdown("<script>alert(1)</script> **b** $h^4$ `x<y`\n\n- one\n- <img onerror=x>")
    assert "<script" not in rendered and "<img" not in rendered and "&lt;script&gt;" in rendered
    assert "<strong>b</strong>" in rendered and "<msup><mi>h</mi><mn>4</mn></msup>" in rendered  # typeset
    assert "<code>x&lt;y</code>" in rendered and rendered.count("<li>") == 2
    assert marking.render_markdown("") == "<p><em>(no answer)</em></p>"


def test_an_answers_maths_is_typeset_and_can_carry_nothing_that_runs():
    rendered = marking.render_markdown(r"$$\frac{a*b}{c*d}$$ is *small*, and $\text{<img src=x onerror=alert(1)>}$")
    assert "<mfrac>" in rendered and 'display="block"' in rendered and "<em>small</em>" in rendered
    assert "<img" not in rendered and "&lt;img" in rendered
    assert "<em>" not in rendered.split("<mfrac>")[1].split("</math>")[0]  # no emphasis inside the maths
    assert marking.math_html("\\frac{").startswith('<span class="math">')  # TeX it cannot read, as written


def test_the_model_answers_come_from_the_instructor_notebooks():
    models = marking.model_answers()
    assert set(models) == set(rubric.default().registry.answers)
    question, model = models["exercise3-answer-1"]
    assert "order" in question.lower() and model and "BEGIN SOLUTION" not in model


def test_each_item_is_shuffled_per_marker_and_the_page_runs_only_its_own_script(tmp_path):
    import base64
    import hashlib
    import re

    grades = [
        report.SubmissionGrade(f"s{k:02d}", {3: _passed(3)}, [], 7, _rubric(tmp_path), answers=answer)
        for k in range(20)
        for answer in [{"exercise3-answer-1": f"order {k}"}]
    ]
    one, again, other = (marking.tasks(grades, m)[0] for m in ("ada", "ada", "bob"))
    names = [a["submission"] for a in one["answers"]]
    assert names == [a["submission"] for a in again["answers"]] != [a["submission"] for a in other["answers"]]
    assert sorted(names) == [g.name for g in grades] and one["max"] == 5
    out = _run(tmp_path, _rubric(tmp_path))
    assert main(["mark", str(out), "--quiet"]) == 0
    page = (out / marking.PAGE).read_text()
    policy = re.search(r"script-src 'sha256-([^']+)'", page).group(1)
    scripts = re.findall(r"<script>(.*?)</script>", page, re.S)
    assert len(scripts) == 1 and base64.b64encode(hashlib.sha256(scripts[0].encode()).digest()).decode() == policy
    assert "alert(1)" in scripts[0] and "<script>alert" not in scripts[0]  # the answer is data inside it
    held = [t for t in marking.tasks(report.read_results([out]), "ada") if t["kind"] == "held"]
    assert [t["item"] for t in held] == ["exercise2/eval_pherm"] and "h = np.diff(x)" in held[0]["answers"][0]["html"]


def test_only_answers_worth_points_and_written_by_the_student_are_queued(tmp_path):
    marked = _rubric(tmp_path)
    written = {"exercise3-answer-1": "order 4", "exercise7-answer-1": "YOUR ANSWER HERE", "exercise12-answer-1": "x"}
    grades = [
        report.SubmissionGrade("ada", {3: _passed(3)}, [], 7, marked, answers=written),
        report.SubmissionGrade("bob", {3: _passed(3)}, [], 7, marked, answers={"exercise3-answer-1": "  "}),
    ]
    queued = {task["item"]: [a["submission"] for a in task["answers"]] for task in marking.tasks(grades, "me")}
    # exercise 12's answer is worth nothing: not queued; the blank and untouched answers are not either
    assert queued == {"exercise3-answer-1": ["ada"]}
    feedback = grades[1].feedback()
    assert "Exercise 3, the order the table shows, against piecewise linear: no answer, 0 / 5 points" in feedback


def test_an_answer_can_carry_rubric_lines_that_the_page_shows_beside_the_model_answer(tmp_path):
    path = tmp_path / "rubric.toml"
    grade_id = next(iter(LAB.answers))
    path.write_text(
        DEFAULT.read_text() + f'\n[answers]\n{grade_id} = {{points = 2, rubric = ["names the order", "a < b"]}}\n'
    )
    loaded = rubric.load(path)
    assert loaded.answers[grade_id] == 2 and loaded.answer_lines[grade_id] == ("names the order", "a < b")
    grade = SubmissionGrade("ada", results={}, rubric=loaded, answers={grade_id: "an answer"})
    task = next(t for t in marking.tasks([grade]) if t["item"] == grade_id)
    assert "<li>names the order</li>" in task["model"] and "<li>a &lt; b</li>" in task["model"]
    path.write_text(DEFAULT.read_text() + f'\n[answers]\n{grade_id} = {{points = 2, lines = "x"}}\n')
    with pytest.raises(ValueError, match="a table of points and rubric lines"):
        rubric.load(path)


def test_a_regraded_submission_keeps_the_marks_that_still_apply():
    from labkit.grading.run.resume import carried_marks

    answer, other = list(LAB.answers)[:2]
    mark = {"points": 1.0, "comment": "", "time": "2026-12-01T10:00:00+00:00"}
    held = {"definition": "eval_pherm", "source": "labkit.piecewise.eval_pherm", "share": 0.9, "lines": []}
    checks = [{"name": "eval_pherm", "passed": True, "hint": "", "weight": 10, "steps": [], "held": held}]
    marks = {answer: mark, other: mark, "exercise2/eval_pherm": mark, "exercise5": mark}
    earlier = SubmissionGrade("ada", answers={answer: "the same", other: "before"}, marks=marks)
    answers = {answer: "the same", other: "rewritten"}
    again = SubmissionGrade("ada", results={2: {"exercise": 2, "checks": checks}}, answers=answers)
    kept, dropped = carried_marks(earlier, again)
    assert set(map(str, kept)) == {answer, "exercise2/eval_pherm", "exercise5"} and dropped == 1
    checks[0].pop("held")  # rewritten: no longer held
    again = SubmissionGrade("ada", results={2: {"exercise": 2, "checks": checks}}, answers=answers)
    kept, dropped = carried_marks(earlier, again)
    assert set(map(str, kept)) == {answer, "exercise5"} and dropped == 2
