"""Time a class-sized `labkit grade` three ways: --jobs 2, --dask local (2 workers), and 4 shards merged.

Run: ``.venv/bin/python benchmarks/bench_class.py [--count 300] [--keep DIR]``.
The class is a mix of solved submissions (all six notebooks), half-solved
ones (the first three notebooks solved, the others as released), the bare
release, and a few hostile ones from the test suite (tests/grading/test_hostile.py's
attacks that end by themselves, and a notebook that is not JSON). Each way is
run as an instructor runs it, ``labkit grade`` in a process of its own, with
one seed; the shards one after another, each with --jobs 2 (as the tasks of a
Slurm array would run side by side on other machines), then ``labkit merge``.
Reported: the total time, seconds per submission, the peak memory of the
grader (the `labkit grade` process, and one submission's grading process, from
``run.json``) and of a Dask worker, and whether the three grades.csv are
identical (they must be: the script exits with status 1 otherwise).
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
sys.path.insert(0, str(ROOT / "tests"))
from test_hostile import ATTACKS  # the attacks' cells, as the hostile test plants them

from labkit import grading

SEED = "20261122"
# attacks that end by themselves within the default limits (no placeholder to fill, no loop to wait out)
HOSTILE = (
    "patched_check",
    "patched_numpy",
    "always_equal",
    "always_equal_array",
    "fake_result_line",
    "memory_grab",
    "fork_loop",
    "sys_exit",
    "os_exit",
    "memfd",
)
SHARDS = 4


def _class(tmp, count):
    """`count` submission folders in tmp/class, in name order: solved, half-solved and bare release in turn,
    and a few hostile ones."""
    release = tmp / "release"
    grading.release(NOTEBOOKS, release)
    notebooks = sorted(path.name for path in NOTEBOOKS.glob("*.ipynb"))
    hostile = [name for name in HOSTILE if all("<" not in cell for cell in ATTACKS[name])]
    hostile = hostile[: min(len(hostile), max(2, count // 30))]
    folder = tmp / "class"
    folder.mkdir()
    for i in range(count - len(hostile)):
        target = folder / f"student{i:04d}"
        target.mkdir()
        kind = i % 3  # 0 solved, 1 half-solved, 2 the bare release
        for index, name in enumerate(notebooks):
            solved = kind == 0 or (kind == 1 and index < len(notebooks) // 2)
            shutil.copy((NOTEBOOKS if solved else release) / name, target / name)
    for name in hostile[:-1]:
        target = folder / f"hostile_{name}"
        target.mkdir()
        nb = nbformat.read(release / "02_convergence.ipynb", as_version=4)
        nb.cells += [nbformat.v4.new_code_cell(cell) for cell in ATTACKS[name]]
        nbformat.write(nb, target / "02_convergence.ipynb")
    if hostile:
        (folder / "hostile_not_json.ipynb").write_text('{"cells": [ this is not json')
    return sorted(folder.iterdir(), key=grading.submission.scoring.submission_name)


def _grade(*args, command="grade"):
    """`labkit grade ARGS` (or another `command`) in a process of its own; its wall time. It must succeed: no
    submission of this class makes grading fail, hostile ones included."""
    start = time.perf_counter()
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", command, *map(str, args), "--quiet"], capture_output=True, text=True
    )
    elapsed = time.perf_counter() - start
    if run.returncode != 0:
        sys.exit(f"labkit grade {' '.join(map(str, args[-6:]))} failed ({run.returncode}):\n{run.stderr[-3000:]}")
    return elapsed


def _mib(value):
    return "n/a" if not value else f"{value / 1024**2:.0f} MiB"


def _load():
    return " ".join(f"{x:.1f}" for x in os.getloadavg())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=300, help="submissions in the class (default 300)")
    parser.add_argument("--keep", type=Path, help="grade in this folder and keep it (default: a temporary one)")
    args = parser.parse_args()
    if args.count < 1:
        parser.error("--count must be at least 1")
    tmp = Path(tempfile.mkdtemp(prefix="bench-class-")) if args.keep is None else args.keep
    tmp.mkdir(parents=True, exist_ok=True)
    try:
        submissions = _class(tmp, args.count)
        print(f"a class of {len(submissions)} submissions in {tmp / 'class'} (seed {SEED})", flush=True)
        print(f"load average before: {_load()} ({os.cpu_count()} cores)", flush=True)
        parts = [tmp / f"shard{index}" for index in range(1, SHARDS + 1)]
        figures = {}  # label: (seconds, output folder, the run folders whose run.json count)
        seconds = _grade(*submissions, "--out", tmp / "jobs2", "--seed", SEED, "--jobs", 2)
        figures["--jobs 2"] = (seconds, tmp / "jobs2", [tmp / "jobs2"])
        seconds = _grade(*submissions, "--out", tmp / "dask", "--seed", SEED, "--dask", "local", "--dask-workers", 2)
        figures["--dask local, 2 workers"] = (seconds, tmp / "dask", [tmp / "dask"])
        seconds = sum(
            _grade(*submissions, "--out", part, "--seed", SEED, "--jobs", 2, "--shard", f"{index}/{SHARDS}")
            for index, part in enumerate(parts, start=1)
        )
        seconds += _grade(*parts, "--out", tmp / "merged", command="merge")
        figures[f"{SHARDS} shards merged"] = (seconds, tmp / "merged", parts)
        print(f"{'':<24} {'total':>8} {'s/submission':>13} {'grader':>9} {'one grading':>12} {'Dask worker':>12}")
        for label, (seconds, _, runs) in figures.items():
            records = [json.loads((run / "run.json").read_text()) for run in runs]
            grader = max((r.get("grader process peak bytes") or 0 for r in records), default=0)
            one = max((r.get("grader peak bytes") or 0 for r in records), default=0)
            worker = max((r.get("dask worker peak bytes") or 0 for r in records), default=0)
            print(
                f"{label:<24} {seconds:>7.1f}s {seconds / len(submissions):>12.2f}s {_mib(grader):>9} "
                f"{_mib(one):>12} {_mib(worker):>12}"
            )
        print(f"load average after: {_load()}")
        print(
            f"shards: {SHARDS} runs of --jobs 2 one after another (an array's tasks would run side by side), "
            "then labkit merge"
        )
        print(
            "peak memory: grader = the `labkit grade` process; one grading = one submission's grading process "
            "(its memory cgroup); Dask worker = a worker process (its grading processes apart)"
        )
        csvs = {label: (out / "grades.csv").read_bytes() for label, (_, out, _) in figures.items()}
        same = len(set(csvs.values())) == 1
        print(f"the three grades.csv are {'identical' if same else 'DIFFERENT'} ({len(submissions)} rows each)")
        return 0 if same else 1
    finally:
        if args.keep is None:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
