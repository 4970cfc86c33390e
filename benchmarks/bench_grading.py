"""Time `labkit grade` on 20 full submissions (each a folder with all six notebooks).

Run: ``.venv/bin/python benchmarks/bench_grading.py [--jobs 2] [--count 20]``.
Half the submissions are the solved notebooks, half the student release.
"""
import argparse
import shutil
import tempfile
import time
from pathlib import Path

from labkit import grading

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=20)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        grading.release(NOTEBOOKS, tmp / "release")
        submissions = []
        for i in range(args.count):
            source = NOTEBOOKS if i % 2 == 0 else tmp / "release"
            target = tmp / f"student{i:02d}"
            shutil.copytree(source, target, ignore=shutil.ignore_patterns("*.vtu", ".ipynb_checkpoints"))
            submissions.append(target)
        start = time.perf_counter()
        grades = grading.grade(submissions, tmp / "out", jobs=args.jobs)
        elapsed = time.perf_counter() - start
    totals = sorted({g.total for g in grades})
    print(f"graded {len(grades)} submissions ({args.jobs} at a time) in {elapsed:.1f} s "
          f"({elapsed / len(grades):.1f} s each); totals seen: {totals}")


if __name__ == "__main__":
    main()
