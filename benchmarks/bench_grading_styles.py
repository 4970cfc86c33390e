"""Grading costs what the notebooks cost, whatever the student's style: `labkit grade` of one submission against
the same six notebooks run top to bottom by nbclient.

Run: ``.venv/bin/python benchmarks/bench_grading_styles.py [--repeat 2] [--limit 1.5]``.

Two complete, correct submissions (tests/data/independent): one vectorised
(``style_a``, numpy throughout) and one in plain Python (``plain_loops``:
loops, lists and the ``math`` module). In one run, side by side, for each
style and each round:

* **grade**: ``labkit grade SUBMISSION --jobs 1`` alone (a new grading run:
  its fork server, sandboxes, checks and recognition of known code), which
  must give full marks;
* **notebooks**: the six notebooks executed top to bottom by nbclient, each
  in a new kernel (its start included), as a student's Run All.

It prints the ratio grade / notebooks per style (the median over the rounds)
and the split of the grading time the run recorded (``timings.json`` in the
run's folder, :mod:`labkit.grading.sandbox.timings`): sandbox starts, the notebooks'
own cells, the checks' calls of student code, reads of student variables,
recognition of known code, the checks' own work and the grading process's
start. The watch's share is the same submission graded once more with the
watch switched off (the grader asks for no refusals, so no profile hook and
no switched-off functions), through a private switch of this benchmark only
(:data:`labkit.grading.sandbox.remote._UNWATCHED`, set in this process; no
option, variable or file reaches it). Similarity between classmates is
`labkit report`'s and is measured by bench_similarity.py.

It fails (exit status 1) when either style's grade takes more than `--limit`
(1.5 by default: `make bench`) times its notebooks, or grades below full marks.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STYLES = {
    "vectorised": ROOT / "tests/data/independent/style_a",
    "plain loops": ROOT / "tests/data/independent/plain_loops",
}
LABKIT = [sys.executable, "-m", "labkit.cli"]
SPLIT = ("sandbox start", "cells", "calls", "reads", "recognition")


def _grade(submission, out):
    """(seconds, the run's timings of this submission, its total, the full total) of `labkit grade` alone."""
    start = time.perf_counter()
    command = [*LABKIT, "grade", str(submission), "--out", str(out), "--jobs", "1", "--seed", "1", "--quiet"]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    seconds = time.perf_counter() - start
    (figures,) = json.loads((out / "timings.json").read_text()).values()
    results = json.loads(next((out / "results").glob("*.json")).read_text())
    return seconds, figures, _total(results)


def _total(results):
    from labkit.grading.store import rubric
    from labkit.grading.store.report import SubmissionGrade

    grade = SubmissionGrade.from_dict(results, "bench", rubric.default())
    return grade.total, rubric.default().maximum


def _notebooks(submission):
    """Seconds to run every notebook of `submission` top to bottom with nbclient, a new kernel each."""
    import nbformat
    from nbclient import NotebookClient

    start = time.perf_counter()
    for path in sorted(submission.glob("*.ipynb")):
        notebook = nbformat.read(path, as_version=4)
        client = NotebookClient(
            notebook, timeout=1200, kernel_name="python3", resources={"metadata": {"path": str(submission)}}
        )
        client.execute()
    return time.perf_counter() - start


def _unwatched(submission):
    """The timings of grading `submission` in this process with the watch switched off (this benchmark only)."""
    from labkit.grading.options import GradeOptions
    from labkit.grading.sandbox import remote, timings
    from labkit.grading.submission import scoring

    remote._UNWATCHED = True
    try:
        timings.reset()
        scoring.grade_submission(submission, GradeOptions(seed=1))
        return timings.taken()
    finally:
        remote._UNWATCHED = False


def _seconds(figures, name):
    return figures.get(name, {}).get("seconds", 0.0)


def _split(style, seconds, figures, unwatched):
    """The lines of one style's split of its grading time."""
    parts = {name: _seconds(figures, name) for name in SPLIT}
    checks = _seconds(figures, "notebooks") - sum(parts.values())
    watched = sum(_seconds(figures, n) for n in ("cells", "calls", "reads"))
    bare = sum(_seconds(unwatched, n) for n in ("cells", "calls", "reads"))
    lines = [f"  {style}: grade {seconds:.1f} s ="]
    for name, value in parts.items():
        count = figures.get(name, {}).get("count", 0)
        lines.append(
            f"    {name:<28}{value:7.1f} s  ({count} requests)"
            if name in ("calls", "reads")
            else f"    {name:<28}{value:7.1f} s"
        )
    lines.append(f"    {'checks own work':<28}{checks:7.1f} s")
    lines.append(f"    {'grading process, run':<28}{seconds - _seconds(figures, 'notebooks'):7.1f} s")
    lines.append(
        f"    watch's share (cells+calls+reads watched - unwatched): {watched - bare:.1f} s "
        f"({watched:.1f} s against {bare:.1f} s)"
    )
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1, help="rounds of every measurement (default 1)")
    parser.add_argument("--limit", type=float, default=1.5, help="most grade / notebooks ratio (default 1.5)")
    args = parser.parse_args()
    ratios, last, failed = {s: [] for s in STYLES}, {}, []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for round_ in range(args.repeat):
            for style, source in STYLES.items():
                submission = tmp / f"{round_}-{source.name}"
                shutil.copytree(source, submission)
                seconds, figures, (total, full) = _grade(submission, tmp / f"out-{round_}-{source.name}")
                ran = _notebooks(submission)
                ratios[style].append(seconds / ran)
                last[style] = (seconds, ran, figures)
                print(
                    f"round {round_ + 1}, {style}: grade {seconds:.1f} s, notebooks {ran:.1f} s, "
                    f"ratio {seconds / ran:.2f}, {total}/{full}",
                    flush=True,
                )
                if total != full:
                    failed.append(f"{style} graded {total}/{full}, not full marks")
        unwatched = {style: _unwatched(tmp / f"0-{source.name}") for style, source in STYLES.items()}
    print(f"one submission alone (--jobs 1), {args.repeat} round(s), load {os.getloadavg()[0]:.1f}:")
    for style in STYLES:
        seconds, ran, figures = last[style]
        ratio = statistics.median(ratios[style])
        print(f"  {style:<12} grade / notebooks: {ratio:.2f}x (rounds: {', '.join(f'{r:.2f}' for r in ratios[style])})")
        if ratio > args.limit:
            failed.append(f"{style} grades in {ratio:.2f}x its notebooks' time (at most {args.limit}x)")
    print("the split of the last round's grading time:")
    for style in STYLES:
        print("\n".join(_split(style, last[style][0], last[style][2], unwatched[style])))
    for why in failed:
        print("FAILED:", why)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
