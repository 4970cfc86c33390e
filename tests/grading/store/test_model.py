"""The store's typed results: what a grading process gives reads into classes and writes back as it came."""

import json

import pytest

from labkit.exercises.registry import LAB
from labkit.grading.store.grade import SubmissionGrade
from labkit.grading.store.model import ExerciseResult, ItemKey, Mark, PartResult, Step


def test_a_checked_exercise_reads_into_classes_and_writes_back_unchanged():
    verdict = LAB.check(2, {}, seed=1)  # nothing defined: every part fails, each step with its kind
    typed = ExerciseResult.from_dict(json.loads(json.dumps(verdict)), 2)
    assert typed.as_dict() == json.loads(json.dumps(verdict))
    assert [part.name for part in typed.parts] == [check["name"] for check in verdict["checks"]]
    assert all(isinstance(step, Step) and not step.passed for part in typed.parts for step in part.failed)
    assert typed.fraction == 0.0 and not typed.passed


def test_a_result_without_its_checks_is_refused_naming_the_submission():
    with pytest.raises(ValueError, match="'ada' for exercise 2 has no list of checks"):
        SubmissionGrade("ada", {2: {"fraction": 1.0, "checks": [1, 2]}})
    for weight in ("ten", float("nan"), float("inf"), 10**400):
        with pytest.raises(ValueError, match="weight of part 'p' is not a finite number"):
            PartResult.from_dict({"name": "p", "passed": True, "weight": weight})


def test_item_keys_are_values_and_their_text_round_trips():
    keys = [ItemKey.exercise(12), ItemKey.held(2, "eval_pherm"), ItemKey.of_answer("exercise12-answer-1")]
    assert [key.kind for key in keys] == ["exercise", "held", "answer"]
    assert [ItemKey.of(str(key)) for key in keys] == keys
    assert ItemKey.of("exercise2/a/b") == ItemKey.held(2, "a/b")  # a part's name is kept whole


def test_marks_read_from_a_result_file_are_typed_and_excuse_by_value():
    grade = SubmissionGrade("ada", marks={"exercise5": {"points": "excused", "comment": "ill", "time": ""}})
    assert grade.marks == {ItemKey.exercise(5): Mark("excused", "ill")}
    assert grade.excused == frozenset({5})
    assert grade.as_dict()["marks"] == {"exercise5": {"points": "excused", "comment": "ill", "time": ""}}
