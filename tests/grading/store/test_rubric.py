"""The rubric: the lab's branch rule as data, its scoring, and clear errors for a bad file."""

import subprocess
import sys
import tomllib

import pytest

from labkit.check import EXERCISES
from labkit.grading.store import rubric as rubrics
from labkit.grading.store.report import SubmissionGrade

# The groups come from the lab's rubric file and the points from the exercises' declarations (the registry), so a
# new exercise in a group changes the expectations below with it; only the first test states the lab's own rule.
LAB_RUBRIC = rubrics.default()
REQUIRED_GROUP = tuple(LAB_RUBRIC.required)
FIRST, SECOND = (tuple(b.exercises) for b in LAB_RUBRIC.branches)
FIRST_NAME, SECOND_NAME = (b.name for b in LAB_RUBRIC.branches)
EXTRA_GROUP = tuple(LAB_RUBRIC.extra_credit)
P = {n: float(e.points) for n, e in EXERCISES.items()}  # the declared points
REQUIRED, BRANCH = sum(P[n] for n in REQUIRED_GROUP), sum(P[n] for n in FIRST)
EXTRA = sum(P[n] for n in EXTRA_GROUP)
BONUS = LAB_RUBRIC.branch_extra  # the rubric's extra credit for a complete second branch


def _fractions(*groups, value=1.0):
    return {n: value for group in groups for n in group}


def test_the_lab_rubric_is_its_branch_rule():
    """The lab's rule: exercises 2-4 for everyone, then the mesh (5-9) or the spline branch (10-15), the
    better counting and the other extra credit, and exercise 16 extra credit."""
    assert {2, 3, 4} <= set(REQUIRED_GROUP) and 16 in EXTRA_GROUP
    assert (FIRST_NAME, SECOND_NAME) == ("mesh generation", "splines")
    assert {5, 6, 7, 8, 9} <= set(FIRST) and {10, 11, 12, 13, 14, 15} <= set(SECOND)
    assert BONUS > 0
    groups = [REQUIRED_GROUP, FIRST, SECOND, EXTRA_GROUP]
    graded = [n for group in groups for n in group]
    assert sorted(graded) == sorted(set(graded)), "an exercise is in two groups"
    # every graded exercise of the registry is in a group, and the points are the declared parts' weights
    assert set(graded) == {n for n in EXERCISES if n != 1} == set(LAB_RUBRIC.points)
    assert LAB_RUBRIC.points == {n: exercise.points for n, exercise in EXERCISES.items() if n in LAB_RUBRIC.points}
    assert "[points]" not in "".join(
        line for line in rubrics.DEFAULT.read_text().splitlines() if not line.startswith("#")
    )
    assert LAB_RUBRIC.full_credit == REQUIRED + BRANCH
    assert LAB_RUBRIC.maximum == REQUIRED + BRANCH + BONUS + EXTRA


def test_the_lab_branches_are_worth_the_same():
    assert BRANCH == sum(P[n] for n in SECOND)


@pytest.mark.parametrize(
    "done, total, branch, other, bonus, extra",
    [
        (("required", "second"), REQUIRED + BRANCH, SECOND_NAME, FIRST_NAME, 0, False),
        (("required", "first"), REQUIRED + BRANCH, FIRST_NAME, SECOND_NAME, 0, False),
        (("required", "first", "second"), REQUIRED + BRANCH + BONUS, FIRST_NAME, SECOND_NAME, BONUS, False),
        (("required", "second", "extra"), REQUIRED + BRANCH + EXTRA, SECOND_NAME, FIRST_NAME, 0, True),
        (
            ("required", "first", "second", "extra"),
            REQUIRED + BRANCH + BONUS + EXTRA,
            FIRST_NAME,
            SECOND_NAME,
            BONUS,
            True,
        ),
        (("second",), BRANCH, SECOND_NAME, FIRST_NAME, 0, False),
        ((), 0, "none", SECOND_NAME, 0, False),
    ],
)
def test_the_better_branch_counts_and_the_other_is_extra_credit(done, total, branch, other, bonus, extra):
    named = {"required": REQUIRED_GROUP, "first": FIRST, "second": SECOND, "extra": EXTRA_GROUP}
    score = LAB_RUBRIC.score(_fractions(*(named[d] for d in done)))
    expected_extra = {f"exercise {n}": (P[n] if extra else 0) for n in EXTRA_GROUP}
    expected_extra[f"branch {other}"] = bonus
    assert (score.total, score.branch, score.extra) == (total, branch, expected_extra)


def test_a_partly_done_second_branch_earns_its_share_of_the_extra_credit():
    lab = LAB_RUBRIC
    a, b = FIRST[0], FIRST[-1]  # one exercise of the first branch done, another half done
    earned = P[a] + P[b] / 2
    score = lab.score({**_fractions(REQUIRED_GROUP, SECOND), a: 1.0, b: 0.5})
    assert score.branch == SECOND_NAME and score.counted == BRANCH
    assert score.extra[f"branch {FIRST_NAME}"] == pytest.approx(BONUS * earned / BRANCH, abs=0.01)
    assert score.total == pytest.approx(REQUIRED + BRANCH + BONUS * earned / BRANCH, abs=0.01)
    # the first branch ahead of the second swaps the roles
    c = SECOND[0]
    swapped = lab.score({**_fractions(REQUIRED_GROUP, FIRST), c: 1.0})
    assert swapped.branch == FIRST_NAME
    assert swapped.extra[f"branch {SECOND_NAME}"] == pytest.approx(BONUS * P[c] / BRANCH, abs=0.01)


def test_parts_scale_with_the_points_an_edited_rubric_gives():
    data = tomllib.loads(rubrics.DEFAULT.read_text())
    n, m = SECOND[1], FIRST[0]
    data["points"] = {str(n): 2 * P[n], str(m): P[m] + (2 * P[n] - P[n])}  # n doubled; m keeps the branches level
    edited = rubrics.from_dict(data, "edited")
    part = EXERCISES[n].parts[0].weight
    assert edited.score({n: part / P[n]}).points[n] == pytest.approx(2 * part)


def _text(points):
    return f"{points:g}"


def test_the_feedback_explains_the_rubric_and_where_the_points_came_from():
    lab = LAB_RUBRIC
    results = {
        n: {
            "exercise": n,
            "passed": True,
            "points": EXERCISES[n].points,
            "fraction": 1.0,
            "defined": True,
            "checks": [],
        }
        for n in REQUIRED_GROUP + SECOND
    }
    text = SubmissionGrade("ada", results, [], None, lab).feedback()
    full = _text(REQUIRED + BRANCH)
    assert f"Total: {full} / {full} points\nFeedback for ada\n" in text
    listed = lambda group: ", ".join(map(str, group))
    assert f"plus one branch: {FIRST_NAME} ({listed(FIRST)}) or {SECOND_NAME} ({listed(SECOND)})" in text
    assert f"Branch that counts: {SECOND_NAME}, {_text(BRANCH)} / {_text(BRANCH)}" in text
    assert f"Extra credit, branch {FIRST_NAME}: 0" in text
    row = f"\n{FIRST[0]:>8}  {'0 / ' + _text(P[FIRST[0]]):>13}  not done (the other branch)\n"
    assert row in text, text


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
        ("required = [2]\n[points]\n2 = 'ten'\n", "points must be a finite number"),
        ("required = [2]\n[points]\n2 = inf\n", "gives exercise 2 inf; points must be a finite number"),
        ("required = [2]\n[points]\n2 = nan\n", "gives exercise 2 nan; points must be a finite number"),
        ("required = [2]\n[points]\n2 = " + "9" * 400 + "\n", "points must be a finite number"),
        ("required = [12]\n[answers]\nexercise12-answer-1 = inf\n", "points must be a finite number, at least 0"),
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
        *[
            (
                f"[points]\n5 = 5\n10 = 5\n[branches]\nextra_credit = {given}\n[[branches.choice]]\nname = 'a'\n"
                "exercises = [5]\n[[branches.choice]]\nname = 'b'\nexercises = [10]\n",
                f"extra_credit must be a finite number of points, at least 0; got {given}",
            )
            for given in ("nan", "inf", "-1")
        ],
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

    docs = (Path(__file__).resolve().parents[3] / "docs" / "instructors.md").read_text(encoding="utf-8")
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
