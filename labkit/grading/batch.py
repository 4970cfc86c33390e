"""Grading a class: many submissions in parallel, one seed, one output folder.

:func:`grade` checks the sandbox once, draws the run's seed (or takes the one
given), grades the submissions a few at a time in worker processes and
writes the output folder (:mod:`labkit.grading.report`). A course that
outgrows one machine grades one submission per batch job into folders of
its own and combines them with :func:`labkit.grading.report.merge`.
"""
import multiprocessing
import secrets
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from . import sandbox
from .rubric import default as default_rubric
from .report import SubmissionGrade, write_report
from .scoring import grade_submission, submission_notebooks

UNCONFINED_WARNING = """\
!!! labkit grade --no-sandbox: student code runs UNCONFINED, with your permissions.
!!! It can read, change or delete anything you can, reach the network and leave
!!! processes behind. Use this only for code you trust.
"""


def _progress(done, total, width=30):
    filled = int(width * done / total)
    sys.stderr.write(f"\rgrading [{'#' * filled}{'.' * (width - filled)}] {done}/{total}")
    if done == total:
        sys.stderr.write("\n")
    sys.stderr.flush()


def grade(submissions, out_dir, jobs=2, cell_timeout=60, total_timeout=600, progress=True, seed=None,
          sandboxed=True, limits=None, rubric=None):
    """Grade submissions in parallel; write grades.csv, feedback/, results/ and seed.txt into `out_dir`.

    `seed` fixes the random test data (a fresh one is drawn and written to
    ``seed.txt`` when it is None). `sandboxed=False` runs student code
    unconfined, after a warning on stderr. `rubric` turns the checks' results into
    grades (:mod:`labkit.grading.rubric`; the lab's own when None).
    """
    submissions = [Path(s) for s in submissions]
    for path in submissions:
        submission_notebooks(path)  # bad paths stop here, before any work
    names = [p.stem if p.is_file() else p.name for p in submissions]
    if len(set(names)) != len(names):
        raise ValueError("two submissions have the same name; their feedback files would collide.")
    if sandboxed:
        try:
            sandbox.available()
        except sandbox.SandboxUnavailable as exc:
            raise ValueError(f"cannot grade in a sandbox: {exc}") from None
    else:
        sys.stderr.write(UNCONFINED_WARNING)
    seed = secrets.randbits(63) if seed is None else int(seed)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "seed.txt").write_text(f"{seed}\n", encoding="utf-8")
    grades = {}
    # spawn, not fork: a forked process would inherit the parent's threads and locks
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=max(1, jobs), mp_context=context) as pool:
        futures = {pool.submit(grade_submission, p, cell_timeout, total_timeout, seed, sandboxed, limits, rubric): p
                   for p in submissions}
        for done, future in enumerate(as_completed(futures), start=1):
            path = futures[future]
            try:
                result = future.result()
            except Exception as exc:  # noqa: BLE001 - one broken submission must not stop the class
                result = SubmissionGrade(path.stem if path.is_file() else path.name, {}, [f"grading failed: {exc}"],
                                         seed, rubric or default_rubric())
            grades[path] = result
            if progress:
                _progress(done, len(submissions))
    ordered = [grades[p] for p in submissions]
    write_report(out, ordered)
    return ordered
