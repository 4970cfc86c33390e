"""Resuming: ``labkit grade`` into an --out that holds an earlier run's results grades only the submissions
without one (and those that could not be graded), with that run's seed; grades.csv then covers the class."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import processes_with
from small_class import SEED, cli, files

from labkit.grading.run.resume import clear, resumed
from labkit.grading.store import record as records
from labkit.grading.store import rubric as rubrics
from labkit.grading.store.report import file_stem, safe_name
from labkit.grading.submission.scoring import submission_name

pytestmark = pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")


def _result(out, name):
    return Path(out) / "results" / f"{safe_name(name)}.json"


def _run(out):
    return json.loads((Path(out) / "run.json").read_text())


def _recorded(out):
    """The submissions the run's record lists as graded (what a resume takes as done); none while there is no
    record yet."""
    try:
        return records.read(out).submissions
    except (ValueError, OSError):
        return {}


def _processes_with(marker):
    return [cmdline for _, cmdline in processes_with(marker)]


@pytest.mark.slow  # starts a sandbox
def test_a_resumed_run_grades_only_the_missing_the_unreadable_and_the_not_graded(small_class, tmp_path):
    submissions, reference = small_class
    out = tmp_path / "grades"
    shutil.copytree(reference, out)
    _result(out, "bob").unlink()  # missing
    _result(out, "carol").write_text('{"format": "labkit-gr')  # half written when a run was killed
    failed = json.loads(_result(out, "dave").read_text())
    failed["failure"] = "its grading ran out of memory (the grader's limit of 3072 MiB) and was stopped"
    _result(out, "dave").write_text(json.dumps(failed))  # could not be graded: tried again
    forged = json.loads(_result(out, "alice").read_text())
    forged["problems"] = ["not what the run wrote"]  # a result changed after the run: never trusted, graded again
    _result(out, "alice").write_text(json.dumps(forged))
    run = cli("grade", *submissions, "--out", out, "--quiet")  # no --seed: the earlier run's
    assert run.returncode == 0, run.stderr
    assert "resumed" in run.stdout and "1 submission(s) were graded there already and kept, 4 graded now" in run.stdout
    assert (_run(out)["graded now"], _run(out)["already graded"], _run(out)["seed"]) == (4, 1, int(SEED))
    assert "changed since the run wrote it" in run.stderr and "missing (the result of 'bob')" in run.stderr
    assert (out / "grades.csv").read_bytes() == (reference / "grades.csv").read_bytes()
    assert "not what the run wrote" not in (out / "feedback" / f"{file_stem('alice')}.txt").read_text()
    regraded = {f"{file_stem(name)}.txt" for name in ("alice", "bob", "carol", "dave")}
    assert {k: v for k, v in files(out, "feedback").items() if k in regraded} == {
        k: v for k, v in files(reference, "feedback").items() if k in regraded
    }
    assert sorted(files(out, "results")) == sorted(files(reference, "results"))  # no partial file left


@pytest.mark.slow  # starts a sandbox
def test_an_interrupted_run_resumes_where_it_stopped(small_class, tmp_path):
    submissions, reference = small_class
    out, temporary = tmp_path / "grades", tmp_path / "tmp"
    temporary.mkdir()
    env = {**os.environ, "TMPDIR": str(temporary)}  # the grading processes' files, named in their command lines
    command = [sys.executable, "-m", "labkit.cli", "grade", *map(str, submissions), "--out", str(out), "--jobs", "1"]
    grader = subprocess.Popen([*command, "--seed", SEED, "--quiet"], env=env, stdout=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 240
        while not _recorded(out) and grader.poll() is None and time.monotonic() < deadline:
            time.sleep(0.1)
        assert grader.poll() is None, "the run ended before it could be interrupted"
        grader.send_signal(signal.SIGKILL)  # as a batch system ends a job that ran out of time
        grader.wait(timeout=60)
    finally:
        if grader.poll() is None:
            grader.kill()
    # read after the kill: a result written but not yet entered in the record when the kill came is graded again
    done = _recorded(out)
    assert 1 <= len(done) < len(submissions) and not (out / "grades.csv").exists()
    deadline = time.monotonic() + 30  # the grading process of the killed run dies with it (bounded wait)
    while _processes_with(str(temporary)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _processes_with(str(temporary)) == []
    again = subprocess.run([*command[:-2], "--quiet"], env=env, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    assert (_run(out)["already graded"], _run(out)["graded now"]) == (len(done), len(submissions) - len(done))
    assert (out / "grades.csv").read_bytes() == (reference / "grades.csv").read_bytes()
    assert files(out, "feedback") == files(reference, "feedback")


@pytest.mark.slow  # starts a sandbox
def test_resuming_refuses_another_seed_rubric_or_class_and_fresh_starts_over(small_class, tmp_path):
    submissions, reference = small_class
    out = tmp_path / "grades"
    shutil.copytree(reference, out)
    before = files(out, "results")
    names = [submission_name(path) for path in submissions]
    run = cli("grade", *submissions, "--out", out, "--seed", "1")
    assert run.returncode == 2 and f"holds results of a run with seed {SEED}, not --seed 1" in run.stderr
    assert "leave --seed out to resume it, give --fresh" in run.stderr
    other = rubrics.from_dict({"title": "bilinear only", "required": [16]})
    with pytest.raises(ValueError, match="differs from it in its exercises, groups or points: leave --rubric out"):
        resumed(out, names, None, other)
    late = rubrics.from_dict(
        {**rubrics.default().data, "late": {"deadline": "2026-12-01T23:59:00Z", "per": "day", "percent": 10, "cap": 50}}
    )
    with pytest.raises(ValueError, match="differs from it in a \\[late\\] table.*labkit merge"):
        resumed(out, names, None, late)  # a late rule added afterwards: the merge applies it, a resume never
    with pytest.raises(ValueError, match="which is not among the submissions of this run"):
        resumed(out, ["alice"], None, rubrics.default())  # the others' results would stay out of grades.csv
    assert files(out, "results") == before  # nothing refused was changed
    assert not resumed(out, names, None).rubric.differences(rubrics.default())  # no rubric given: the recorded one
    assert resumed(out, names, None, rubrics.default(), fresh=True).done == {}
    assert files(out, "results") == before  # working the run out reads; --fresh deletes as the run starts:
    clear(out)
    assert list((out / "results").iterdir()) == [] and list((out / "feedback").iterdir()) == []
    assert not (out / "record.json").exists()


def test_a_run_into_a_folder_without_results_draws_a_fresh_seed(tmp_path):
    (tmp_path / "seed.txt").write_text("123\n")  # a run stopped before its first result: nothing to keep
    first = resumed(tmp_path, ["alice"], None, rubrics.default())
    assert (first.done, first.seed, first.record) == ({}, None, None)
    assert resumed(tmp_path, ["alice"], 7, rubrics.default()).seed == 7
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "alice-0.json").write_text("{}")  # results without a record: an older labkit's
    with pytest.raises(ValueError, match="holds results but no run record"):
        resumed(tmp_path, ["alice"], None, rubrics.default())
