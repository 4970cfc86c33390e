"""Grade the catalog class of tests/catalog.py (15 correct variations, the typical mistakes, one MATLAB-style
solution set) with one seed, as tests/exercises/test_catalog.py does, and write grades.csv into OUT.

Run it from any checkout of labkit to compare two versions' grades, e.g. before and after a refactoring:

    PYTHONPATH=/path/to/old/checkout python benchmarks/grade_catalog.py /tmp/old
    python benchmarks/grade_catalog.py /tmp/new
    cmp /tmp/old/out/grades.csv /tmp/new/out/grades.csv

tests/data/catalog_grades_seed20261201.csv was written this way by commit 646d67a (before the exercises were
declared once); test_catalog.py compares every run with it.
"""

import shutil
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from catalog import plant_class

from labkit import grading

SEED = 20261201


def main(out):
    out = Path(out)
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    folders = plant_class(out)
    start = time.perf_counter()
    grading.grade(list(folders.values()), out / "out", grading.GradeOptions(seed=SEED, jobs=2), progress=False)
    print(f"{len(folders)} submissions graded in {time.perf_counter() - start:.0f} s: {out / 'out' / 'grades.csv'}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "catalog-grades")
