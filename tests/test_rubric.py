"""The rubric: the lab's branch rule as data, its scoring, and clear errors for a bad file."""

import subprocess
import sys
import tomllib

import pytest

from labkit.check import EXERCISES
from labkit.grading.results import rubric as rubrics
from labkit.grading.results.report import SubmissionGrade

MESH, SPLINES = (5, 6, 7, 8, 9), (10, 11, 12, 13, 14, 15)


def _fractions(*groups, value=1.0):
    return {n: value for group in groups for n in group}


def test_the_lab_rubric_is_its_branch_rule():
    lab = rubrics.default()
    assert lab.required == (2, 3, 4) and lab.extra_credit == (16,)
    assert [b.exercises for b in lab.branches] == [MESH, SPLINES]
    assert lab.branch_extra == 10
    # the points are the declared parts' weights, kept nowhere else
    assert lab.points == {n: exercise.points for n, exercise in EXERCISES.items()}
    assert "[points]" not in "".join(
        line for line in rubrics.DEFAULT.read_text().splitlines() if not line.startswith("#")
    )
    assert lab.full_credit == sum(lab.points[n] for n in (2, 3, 4) + MESH)
    assert lab.maximum == lab.full_credit + 10 + lab.points[16]


P = {n: float(e.points) for n, e in EXERCISES.items()}  # the declared points: the totals below follow them
REQUIRED, BRANCH = sum(P[n] for n in (2, 3, 4)), sum(P[n] for n in MESH)
BONUS = 10  # the rubric's extra credit for a complete second branch


def test_the_lab_branches_are_worth_the_same():
    assert BRANCH == sum(P[n] for n in SPLINES)


@pytest.mark.parametrize(
    "done, total, branch, extra",
    [
        (((2, 3, 4), SPLINES), REQUIRED + BRANCH, "splines", {"exercise 16": 0, "branch mesh generation": 0}),
        (((2, 3, 4), MESH), REQUIRED + BRANCH, "mesh generation", {"exercise 16": 0, "branch splines": 0}),
        (
            ((2, 3, 4), MESH, SPLINES),
            REQUIRED + BRANCH + BONUS,
            "mesh generation",
            {"exercise 16": 0, "branch splines": BONUS},
        ),
        (
            ((2, 3, 4), SPLINES, (16,)),
            REQUIRED + BRANCH + P[16],
            "splines",
            {"exercise 16": P[16], "branch mesh generation": 0},
        ),
        (
            ((2, 3, 4), MESH, SPLINES, (16,)),
            REQUIRED + BRANCH + BONUS + P[16],
            "mesh generation",
            {"exercise 16": P[16], "branch splines": BONUS},
        ),
        ((SPLINES,), BRANCH, "splines", {"exercise 16": 0, "branch mesh generation": 0}),
        ((), 0, "none", {"exercise 16": 0, "branch splines": 0}),
    ],
)
def test_the_better_branch_counts_and_the_other_is_extra_credit(done, total, branch, extra):
    score = rubrics.default().score(_fractions(*done))
    assert (score.total, score.branch, score.extra) == (total, branch, extra)


def test_a_partly_done_second_branch_earns_its_share_of_the_extra_credit():
    lab = rubrics.default()
    fractions = {**_fractions((2, 3, 4), SPLINES), 5: 1.0, 9: 0.5}  # 12 + 8 of the mesh branch's 60 points
    score = lab.score(fractions)
    assert score.branch == "splines" and score.counted == 60
    assert score.extra["branch mesh generation"] == pytest.approx(10 * 20 / 60, abs=0.01)
    assert score.total == pytest.approx(100 + 10 * 20 / 60, abs=0.01)
    # the mesh branch ahead of the spline branch swaps the roles
    swapped = lab.score({**_fractions((2, 3, 4), MESH), 10: 1.0})
    assert swapped.branch == "mesh generation" and swapped.extra["branch splines"] == pytest.approx(2.5)


def test_parts_scale_with_the_points_an_edited_rubric_gives():
    data = tomllib.loads(rubrics.DEFAULT.read_text())
    data["points"] = {"11": 18, "5": 21}  # 11: twice the lab's 9
    edited = rubrics.from_dict(data, "edited")
    assert edited.score({11: 5 / 9}).points[11] == 10  # the driver part: 5 of 9, now of 18


def test_the_feedback_explains_the_rubric_and_where_the_points_came_from():
    lab = rubrics.default()
    results = {
        n: {
            "exercise": n,
            "passed": True,
            "points": EXERCISES[n].points,
            "fraction": 1.0,
            "defined": True,
            "checks": [],
        }
        for n in (2, 3, 4) + SPLINES
    }
    text = SubmissionGrade("ada", results, [], None, lab).feedback()
    assert "Feedback for ada: 100 points (100 / 100)" in text
    assert "plus one branch: mesh generation (5, 6, 7, 8, 9) or splines (10, 11, 12, 13, 14, 15)" in text
    assert "Branch that counts: splines, 60 / 60" in text and "Extra credit, branch mesh generation: 0" in text
    assert "Exercise 5: 0 / 12 - not found" in text


def _write(tmp_path, text):
    path = tmp_path / "rubric.toml"
    path.write_text(text)
    return path


GOOD = """
required = [2, 3]
[points]
2 = 10
3 = 10
"""


@pytest.mark.parametrize(
    "text, message",
    [
        ("[points]\n17 = 5\n", "names exercise '17', which labkit does not grade"),
        ("required = [1]\n[points]\n1 = 5\n", "exercise 1 is not graded"),
        ("required = [2]\n[points]\n2 = -5\n", "negative points"),
        ("required = [2]\n[points]\n2 = 'ten'\n", "points must be a number"),
        (
            "[points]\n2 = 5\n5 = 5\n10 = 5\n[branches]\nextra_credit = 1\n[[branches.choice]]\nname = 'a'\nexercises = [5, 2]\n"
            "[[branches.choice]]\nname = 'b'\nexercises = [10, 2]\n",
            "branches may not overlap",
        ),
        (
            "required = [2]\n[points]\n2 = 5\n5 = 5\n[branches]\n[[branches.choice]]\nname = 'a'\nexercises = [5]\n"
            "[[branches.choice]]\nname = 'b'\nexercises = [2]\n",
            "branches may not overlap",
        ),
        (
            "[points]\n5 = 5\n10 = 6\n[branches]\n[[branches.choice]]\nname = 'a'\nexercises = [5]\n"
            "[[branches.choice]]\nname = 'b'\nexercises = [10]\n",
            "must be worth the same points",
        ),
        ("[points]\n5 = 5\n[branches]\n[[branches.choice]]\nname = 'a'\nexercises = [5]\n", "at least two"),
        ("title = 'x'\n", "grades nothing"),
        ("exercises = 'no_such_module:REGISTRY'\nrequired = [2]\n", "cannot load the exercises"),
        ("exercises = 'labkit.exercises.model:Part'\nrequired = [2]\n", "not a labkit Registry"),
        ("points = 3\nrequired = [2]\n", "must be a table"),
        ("required = [2]\n[points]\n2 = 5\n3 = 5\n", "exercise 3 has points but is in no group"),
        ("required = [2]\nbonus = [3]\n[points]\n2 = 5\n", "unknown key(s) bonus"),
        ("required = 2\n[points]\n2 = 5\n", "must be a list of exercise numbers"),
        ("required = [2\n", "is not valid TOML"),
    ],
)
def test_rubric_errors_are_clear(tmp_path, text, message):
    with pytest.raises(
        ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[").replace("]", r"\]")
    ):
        rubrics.load(_write(tmp_path, text))


def test_an_exercise_without_points_in_the_rubric_is_worth_its_parts(tmp_path):
    small = rubrics.load(_write(tmp_path, "required = [2, 3]\n[points]\n2 = 5\n"))
    assert small.points == {2: 5.0, 3: float(EXERCISES[3].points)}


def test_a_small_rubric_without_branches_loads(tmp_path):
    small = rubrics.load(_write(tmp_path, GOOD))
    assert small.full_credit == 20 and small.maximum == 20 and small.score({2: 1.0, 3: 0.5}).total == 15
    assert small.score({2: 1.0}).branch == ""


def test_cli_prints_the_lab_rubric_and_checks_an_edited_one(tmp_path):
    run = subprocess.run([sys.executable, "-m", "labkit.cli", "rubric"], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0 and rubrics.from_dict(tomllib.loads(run.stdout)) == rubrics.default()
    path = _write(tmp_path, run.stdout.replace("[branches]", "[points]\n16 = -8\n\n[branches]"))
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "rubric", "--check", str(path)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 2 and "negative points" in run.stderr


def test_the_points_example_the_rubric_and_the_docs_give_is_one_a_rubric_accepts(tmp_path):
    import re
    from pathlib import Path

    docs = (Path(__file__).resolve().parents[1] / "docs" / "instructors.md").read_text(encoding="utf-8")
    comment = "\n".join(line.lstrip("# ") for line in rubrics.DEFAULT.read_text(encoding="utf-8").splitlines())
    examples = re.findall(r"\[points\]\s*\n\s*(\d+ = \d+)", comment) + re.findall(
        r"`\[points\]` table \(`(\d+ = \d+)`", docs
    )
    assert len(examples) == 2
    for example in examples:
        number, points = (int(v) for v in example.split(" = "))
        path = tmp_path / "edited.toml"
        path.write_text(rubrics.DEFAULT.read_text(encoding="utf-8") + f"\n[points]\n{example}\n", encoding="utf-8")
        assert rubrics.load(path).points[number] == points
