"""Time `labkit grade`: one submission alone, sandboxed and unconfined, then a class with --jobs.

Run: ``.venv/bin/python benchmarks/bench_grading.py [--count 30] [--jobs 2]``.
Each submission is a folder with all six notebooks; half are the solved
notebooks, half the student release. The sandbox's cost is the difference
between the sandboxed and the unconfined single-submission times, measured
in the same run.
"""

import argparse
import contextlib
import io
import shutil
import tempfile
import time
from pathlib import Path

from labkit import grading

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
BEFORE = 8.1  # s per submission before the sandbox (nbclient kernels, two at a time), docs/instructors.md


def _class(tmp, count):
    grading.release(NOTEBOOKS, tmp / "release")
    submissions = []
    for i in range(count):
        source = NOTEBOOKS if i % 2 == 0 else tmp / "release"
        target = tmp / f"student{i:02d}"
        shutil.copytree(source, target, ignore=shutil.ignore_patterns("*.vtu", ".ipynb_checkpoints"))
        submissions.append(target)
    return submissions


def _single(submission, sandboxed, repeat=3):
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        with contextlib.redirect_stderr(io.StringIO()):  # the --no-sandbox warning
            grading.grade_submission(submission, seed=1, confined=sandboxed)
        best = min(best, time.perf_counter() - start)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=30)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        submissions = _class(tmp, args.count)
        boxed, free = _single(submissions[0], True), _single(submissions[0], False)
        print(
            f"one solved submission (6 notebooks), best of 3: sandboxed {boxed:.2f} s, unconfined {free:.2f} s, "
            f"sandbox cost {boxed - free:+.2f} s per submission ({(boxed - free) / 6:+.3f} s per notebook)"
        )
        start = time.perf_counter()
        grades = grading.grade(submissions, tmp / "out", jobs=args.jobs, progress=False, seed=1)
        elapsed = time.perf_counter() - start
    totals = sorted({g.total for g in grades})
    print(
        f"class of {len(grades)} submissions, --jobs {args.jobs}, sandboxed: {elapsed:.1f} s "
        f"({elapsed / len(grades):.2f} s each; before the sandbox: {BEFORE} s each); totals seen: {totals}"
    )


if __name__ == "__main__":
    main()
