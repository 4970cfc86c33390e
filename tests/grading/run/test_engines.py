"""The engines' one interface: a class run hands an engine its batch and writes whatever it yields, as it comes."""

import json
from pathlib import Path

import pytest

from labkit import grading
from labkit.grading.run.engines import Batch, Engine, LocalEngine, Outcome

NOTEBOOKS = Path(__file__).resolve().parents[3] / "notebooks"


class Declining(Engine):
    """An engine that grades nothing: each submission comes back not graded, with a peak it reports."""

    name = "declining"

    def __init__(self):
        self.batches: list[Batch] = []

    def grade(self, batch):
        self.batches.append(batch)
        for index, (_, name) in enumerate(reversed(batch.todo)):  # in an order of its own
            yield Outcome(batch.not_graded(name, f"{self.name} declined it"), peak=1000 + index)

    def record(self):
        return {"engine": self.name, "batches": len(self.batches)}


@pytest.mark.slow  # starts a sandbox
def test_a_class_run_writes_what_an_engine_yields_and_records_it(tmp_path):
    first, second = tmp_path / "ann.ipynb", tmp_path / "ben.ipynb"
    for path in (first, second):
        path.write_bytes((NOTEBOOKS / "06_bilinear.ipynb").read_bytes())
    engine = Declining()
    options = grading.GradeOptions(backend="none", seed=11)
    grades = grading.grade([second, first], tmp_path / "out", options, engine=engine, progress=False)
    assert [g.name for g in grades] == ["ben", "ann"]  # the order given, whatever the engine's
    assert [g.failure for g in grades] == ["declining declined it"] * 2 and not any(g.graded for g in grades)
    [batch] = engine.batches
    assert sorted(name for _, name in batch.todo) == ["ann", "ben"]
    assert batch.options.seed == 11 and batch.options.backend == "none"  # the run's options, passed as given
    assert batch.options.exercises == batch.rubric.registry.source  # settled once: the rubric's exercises
    run = json.loads((tmp_path / "out" / "run.json").read_text())
    assert run["engine"] == "declining" and run["batches"] == 1
    assert run["grader peak bytes"] == 1001 and run["not graded"] == 2
    saved = sorted((tmp_path / "out" / "results").glob("*.json"))
    assert [path.name.split("-")[0] for path in saved] == ["ann", "ben"]  # each written as it came
    assert all(json.loads(path.read_text())["failure"] == "declining declined it" for path in saved)
    again = grading.grade([second, first], tmp_path / "out", options, engine=Declining(), progress=False)
    assert [g.name for g in again] == ["ben", "ann"]  # not graded before: handed to the engine again


@pytest.mark.slow  # starts a sandbox
def test_an_engine_is_an_engine_and_the_local_one_has_jobs():
    with pytest.raises(TypeError, match="abstract"):
        Engine()  # type: ignore[abstract]
    with pytest.raises(ValueError, match="engine must be a labkit.grading.run.engines.Engine"):
        grading.grade([], "out", engine=lambda batch: iter(()))  # type: ignore[arg-type]
    for jobs in (0, 1.5, True):
        with pytest.raises(ValueError, match="jobs must be a whole number"):
            LocalEngine(jobs)  # type: ignore[arg-type]
    assert LocalEngine(3).record() == {"engine": "local", "jobs": 3}
