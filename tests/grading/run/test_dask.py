"""``labkit grade --dask``: a real ``dask scheduler`` and two ``dask worker`` processes grade the small class as
one machine does, and when a worker is killed in the middle of a run every submission is still graded once."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import processes_with
from small_class import SEED, cli, files, rows

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's"),
]  # slow: a Dask cluster
distributed = pytest.importorskip("distributed")  # the labkit[dask] extra, which the test extra installs
DASK = Path(sys.executable).with_name("dask")
WAIT = 120  # seconds for a process to come up or a run to reach a point (bounded waits, never asserted)


def _processes_with(marker):
    return [cmdline for _, cmdline in processes_with(marker)]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory, small_class):
    """A scheduler on a free port and two single-threaded workers without nannies (a killed worker stays dead),
    each with a temporary folder of its own; {"address", "workers": {name: (process, its temporary folder)}}."""
    tmp = tmp_path_factory.mktemp("dask")
    scheduler_file = tmp / "scheduler.json"
    started = []
    try:
        started.append(
            subprocess.Popen(
                [DASK, "scheduler", "--scheduler-file", scheduler_file, "--port", "0", "--no-dashboard"],
                stdout=subprocess.DEVNULL,
                stderr=open(tmp / "scheduler.log", "wb"),
                start_new_session=True,
            )  # fmt: skip
        )
        workers = {}
        for name in ("w1", "w2"):
            temporary = tmp / f"tmp-{name}"
            temporary.mkdir()
            process = subprocess.Popen(
                [DASK, "worker", "--scheduler-file", scheduler_file, "--nthreads", "1", "--no-nanny", "--name", name,
                 "--no-dashboard", "--local-directory", tmp / f"space-{name}"],
                stdout=subprocess.DEVNULL, stderr=open(tmp / f"{name}.log", "wb"), start_new_session=True,
                env={**os.environ, "TMPDIR": str(temporary)},
            )  # fmt: skip
            started.append(process)
            workers[name] = (process, temporary)
        deadline = time.monotonic() + WAIT
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        with distributed.Client(address, timeout="60s") as client:
            client.wait_for_workers(2, timeout=WAIT)
        yield {"address": address, "workers": workers, "tmp": tmp}
    finally:
        for process in reversed(started):
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
            process.wait(timeout=30)


def test_a_class_graded_on_a_dask_cluster_is_the_class_graded_on_one_machine(cluster, small_class, tmp_path):
    submissions, reference = small_class
    out = tmp_path / "grades"
    # the first half of the class (a shard, as a Slurm array task could send it): its first two in name order
    run = cli("grade", *submissions, "--out", out, "--dask", cluster["address"], "--shard", "1/2", "--seed", SEED)
    assert run.returncode == 0, run.stderr
    graded = submissions[:2]
    assert rows(out) == dict(list(rows(reference).items())[:2])  # the reference is in name order too
    assert files(out, "feedback") == {
        k: v for k, v in files(reference, "feedback").items() if k in files(out, "feedback")
    }
    assert files(out, "results") == {k: v for k, v in files(reference, "results").items() if k in files(out, "results")}
    assert len(files(out, "results")) == len(graded)
    record = json.loads((out / "run.json").read_text())
    assert record["engine"] == "dask" and record["dask scheduler"] == cluster["address"]
    assert sum(record["dask workers"].values()) == len(graded) and record["dask duplicates ignored"] == 0
    for _, temporary in cluster["workers"].values():  # each task's files are removed
        assert list(temporary.iterdir()) == []


def test_a_worker_killed_in_the_middle_of_a_run_loses_nothing_and_counts_nothing_twice(cluster, small_class, tmp_path):
    submissions, reference = small_class
    out = tmp_path / "grades"
    command = [sys.executable, "-m", "labkit.cli", "grade", *map(str, submissions), "--out", str(out)]
    grader = subprocess.Popen(
        [*command, "--dask", cluster["address"], "--seed", SEED, "--quiet"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        with distributed.Client(cluster["address"], timeout="60s") as client:
            deadline, busy = time.monotonic() + WAIT, None
            while busy is None and grader.poll() is None and time.monotonic() < deadline:
                time.sleep(0.1)
                if not list((out / "results").glob("*.json")):
                    continue  # the first result has not arrived yet
                names = {w["name"]: a for a, w in client.scheduler_info()["workers"].items()}
                processing = client.processing()
                busy = next((name for name, address in sorted(names.items()) if processing.get(address)), None)
            assert busy is not None, "no worker was grading when the first result arrived"
            killed, temporary = cluster["workers"][busy]
            killed.send_signal(signal.SIGKILL)  # the worker dies with a submission in its hands
            killed.wait(timeout=30)
        stdout, stderr = grader.communicate(timeout=600)
    finally:
        if grader.poll() is None:
            grader.kill()
    assert grader.returncode == 0, stderr
    # every submission once, graded as on one machine: nothing lost, nothing twice
    assert sorted(files(out, "results")) == sorted(files(reference, "results"))
    assert (out / "grades.csv").read_bytes() == (reference / "grades.csv").read_bytes()
    assert files(out, "feedback") == files(reference, "feedback")
    record = json.loads((out / "run.json").read_text())
    assert record["graded now"] == len(submissions) and record["dask duplicates ignored"] == 0
    assert sum(record["dask workers"].values()) == len(submissions)
    # the killed worker's grading process (and its sandbox) died with it (a bounded wait, never a timed assertion)
    deadline = time.monotonic() + 30
    while _processes_with(str(temporary)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _processes_with(str(temporary)) == []


def test_dask_bad_input_is_refused_saying_what_to_do(monkeypatch, tmp_path):
    from labkit.grading.run import dask as engine

    monkeypatch.setattr(engine, "CONNECT_TIMEOUT", "1s")
    with pytest.raises(ValueError, match="cannot reach the Dask scheduler at tcp://127.0.0.1:9 .*--dask local"):
        engine.connect("tcp://127.0.0.1:9")
    with pytest.raises(ValueError, match="--dask-workers must be at least 1"):
        engine.connect("local", 0)
    monkeypatch.setitem(sys.modules, "distributed", None)  # as where the extra is not installed
    with pytest.raises(ValueError, match=r"pip install 'labkit\[dask\]'"):
        engine.connect("local")
    run = cli("grade", tmp_path, "--out", tmp_path / "out", "--dask-workers", "3")
    assert run.returncode == 2 and "--dask-workers is the size of --dask local" in run.stderr


def test_the_core_never_imports_dask():
    code = "import sys, labkit.cli, labkit.grading.run.classrun, labkit.grading.run.dask, labkit.grading.store.report; print(sorted({'dask', 'distributed'} & set(sys.modules)))"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and run.stdout.strip() == "[]", run.stdout + run.stderr
