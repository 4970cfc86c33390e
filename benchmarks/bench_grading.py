"""Seconds per submission of `labkit grade`: the fork server, the unforked path, and a plain-python floor.

Run: ``.venv/bin/python benchmarks/bench_grading.py [--count 8] [--jobs 1] [--limit 3]``.

One run measures, on the same class of `count` solved submissions (all six
notebooks each, every part of the lab graded):

* **forked**: ``labkit grade`` as it runs by default, every notebook's worker
  forked from the run's fork server and every submission's grading process
  from its launcher (:mod:`labkit.grading.sandbox.forkserver`);
* **unforked**: ``labkit grade --no-fork-server``, a new sandbox with a new
  Python for every notebook and a new Python for every submission;
* **floor**: the notebooks' code cells run as six plain ``python`` processes
  per submission, one per notebook: no sandbox, no checks, no grader, only
  the start-up and imports a kernel pays and the lab's computations.

It prints the three figures and the ratio unforked / forked, and fails (exit
status 1) when the ratio is below `--limit` (3 by default: `make bench`).
"""

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
LABKIT = [sys.executable, "-m", "labkit.cli"]

FLOOR = """
import json, sys
import matplotlib
matplotlib.use("Agg")
from IPython.core.interactiveshell import InteractiveShell
shell = InteractiveShell.instance()
shell.register_magic_function(lambda line: None, "line", "matplotlib")
for cell in json.load(open(sys.argv[1]))["cells"]:
    if cell["cell_type"] == "code":
        shell.run_cell("".join(cell["source"]), silent=True)
"""


def _class(tmp, count):
    submissions = []
    for i in range(count):
        target = tmp / f"student{i:02d}"
        shutil.copytree(NOTEBOOKS, target, ignore=shutil.ignore_patterns("*.vtu", ".ipynb_checkpoints"))
        submissions.append(target)
    return submissions


def _grade(submissions, out, jobs, *extra):
    start = time.perf_counter()
    subprocess.run(
        [*LABKIT, "grade", *map(str, submissions), "--out", str(out), "--jobs", str(jobs), "--seed", "1", "--quiet"]
        + list(extra),
        check=True,
        stdout=subprocess.DEVNULL,
    )
    elapsed = time.perf_counter() - start
    return elapsed, json.loads((out / "run.json").read_text())


def _floor(submissions, tmp):
    script = tmp / "floor.py"
    script.write_text(FLOOR)
    start = time.perf_counter()
    for submission in submissions:
        for notebook in sorted(submission.glob("*.ipynb")):
            subprocess.run(
                [sys.executable, str(script), str(notebook)],
                check=True,
                cwd=tmp,
                stdout=subprocess.DEVNULL,
                env={"MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"},
            )
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=8, help="solved submissions in the class (default 8)")
    parser.add_argument("--jobs", type=int, default=1, help="submissions graded at once (default 1)")
    parser.add_argument("--limit", type=float, default=3.0, help="least unforked / forked ratio (default 3)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        submissions = _class(tmp, args.count)
        forked, run = _grade(submissions, tmp / "forked", args.jobs)
        unforked, plain_run = _grade(submissions, tmp / "unforked", args.jobs, "--no-fork-server")
        floor = _floor(submissions, tmp)
        same = (tmp / "forked" / "grades.csv").read_bytes() == (tmp / "unforked" / "grades.csv").read_bytes()
    n = args.count
    print(f"class of {n} solved submissions (six notebooks each), --jobs {args.jobs}, one run:")
    print(f"  forked (default)           {forked:7.1f} s   {forked / n:5.2f} s per submission", end="")
    print(f"   fork server: {run['fork server']}, forked grading processes: {run['forked grading processes']}")
    print(f"  unforked (--no-fork-server) {unforked:6.1f} s   {unforked / n:5.2f} s per submission")
    print(f"  plain-python floor          {floor:6.1f} s   {floor / n:5.2f} s per submission (no sandbox, no checks)")
    ratio = unforked / forked
    print(f"  unforked / forked: {ratio:.2f}x; forked / floor: {forked / floor:.2f}; identical grades.csv: {same}")
    if not same or not run["fork server"] or plain_run["fork server"]:
        print("FAILED: the two ways must grade alike, the default way through the fork server")
        return 1
    if ratio < args.limit:
        print(f"FAILED: the fork server must save at least {args.limit}x (got {ratio:.2f}x)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
