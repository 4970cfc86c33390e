"""``labkit grade --shard I/N``: the I-th of N parts of a class, for a batch array; the parts merged with
``labkit merge`` are the class graded in one run."""

import json
import os

import pytest
from hypothesis import given
from hypothesis import strategies as st
from small_class import SEED, cli, files, rows

from labkit import grading
from labkit.grading import merge
from labkit.grading.run.resume import parse_shard, shard

pytestmark = pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")


@given(st.lists(st.text(min_size=1, max_size=12), unique=True, max_size=40), st.integers(1, 60), st.randoms())
def test_the_shards_cover_every_submission_exactly_once_for_any_count(names, count, random):
    parts = [shard(names, index, count) for index in range(1, count + 1)]
    together = [name for part in parts for name in part]
    assert sorted(together) == sorted(names)  # every name once: none missing, none twice
    assert together == sorted(names)  # the parts are consecutive runs of the name order
    assert max(map(len, parts)) - min(map(len, parts)) <= 1  # equal parts, as equal as they can be
    assert sum(not part for part in parts) == max(0, count - len(names))  # more parts than names: some are empty
    shuffled = list(names)
    random.shuffle(shuffled)  # every task of the array sees the same parts, whatever order its shell listed
    assert [shard(shuffled, index, count) for index in range(1, count + 1)] == parts


@pytest.mark.parametrize("spec", ["0/4", "5/4", "-1/4", "1/0", "3", "a/b", "1/2/3", "", None, (2, 1)])
def test_a_bad_shard_is_refused_saying_how_to_write_one(spec):
    with pytest.raises(ValueError, match=r"give --shard I/N with 1 <= I <= N, e\.g\. 3/50"):
        parse_shard(spec)


@pytest.mark.parametrize(("index", "count"), [(1, 0), (5, 4), (0, 4)])
def test_shard_itself_refuses_a_part_that_does_not_exist(index, count):
    with pytest.raises(ValueError, match=r"give --shard I/N with 1 <= I <= N"):
        shard(["a", "b"], index, count)


def test_the_cli_refuses_a_bad_shard_before_grading(tmp_path):
    (tmp_path / "class").mkdir()
    run = cli("grade", tmp_path / "class", "--out", tmp_path / "out", "--shard", "0/50")
    assert run.returncode == 2 and "give --shard I/N with 1 <= I <= N" in run.stderr and "got 0/50" in run.stderr
    assert not (tmp_path / "out").exists()
    run = cli("merge", tmp_path, "--out", tmp_path / "out", "--shard", "1/2")
    assert (
        run.returncode == 2
        and "labkit merge: --shard grade(s) submissions, which `labkit merge` does not" in run.stderr
    )


@pytest.fixture(scope="module")
def shards(small_class, tmp_path_factory):
    """The small class (five submissions) graded as four shards, and as the first of seven (an empty part)."""
    submissions, _ = small_class
    tmp = tmp_path_factory.mktemp("shards")
    for index in range(1, 5):  # each shard is given the whole class, in another order, as each array task is
        given = submissions[index % len(submissions) :] + submissions[: index % len(submissions)]
        grading.grade(
            given, tmp / f"part{index}", grading.GradeOptions(seed=int(SEED), shard=f"{index}/4"), progress=False
        )
    run = cli("grade", *submissions, "--out", tmp / "empty", "--shard", "1/7", "--seed", SEED, "--quiet")
    assert run.returncode == 0, run.stderr
    assert "shard 1/7: 0 submission(s)" in run.stdout
    return tmp


@pytest.mark.slow  # starts a sandbox
def test_four_shards_merged_are_the_class_graded_in_one_run(small_class, shards):
    submissions, reference = small_class
    sizes = [json.loads((shards / f"part{i}" / "run.json").read_text())["submissions"] for i in range(1, 5)]
    assert sizes == [1, 1, 1, 2]
    folders = [shards / f"part{i}" for i in (3, 1, 4, 2)] + [shards / "empty"]  # in any order, an empty part too
    run = cli("merge", *folders, "--out", shards / "merged", "--quiet")
    assert run.returncode == 0, run.stderr
    assert (shards / "merged" / "grades.csv").read_bytes() == (reference / "grades.csv").read_bytes()
    assert files(shards / "merged", "feedback") == files(reference, "feedback")
    assert len(rows(shards / "merged")) == len(submissions)


@pytest.mark.slow  # starts a sandbox
def test_an_empty_shard_writes_a_folder_that_merges_but_is_never_the_whole_merge(shards, tmp_path):
    empty = shards / "empty"
    assert sorted(p.name for p in empty.iterdir()) == [
        "feedback",
        "grades.csv",
        "record.json",
        "results",
        "rubric.toml",
        "run.json",
        "seed.txt",
    ]
    assert list((empty / "results").iterdir()) == [] and (empty / "seed.txt").read_text() == f"{SEED}\n"
    record = json.loads((empty / "run.json").read_text())
    assert (record["submissions"], record["shard"]) == (0, "1/7")
    assert rows(empty) == {}
    with pytest.raises(ValueError, match="hold no results"):
        merge([empty], tmp_path / "m")
    (tmp_path / "results").mkdir()  # an empty results/ without a run that says it had nothing to grade
    with pytest.raises(ValueError, match="has no run record"):
        merge([shards / "part1", tmp_path], tmp_path / "m")
