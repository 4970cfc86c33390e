"""Releasing the lab to students and grading what comes back.

One module per concern:

* :mod:`~labkit.grading.release` - the student version of the instructor notebooks;
* :mod:`~labkit.grading.options` - the limits of a grading run, defaults defined once;
* :mod:`~labkit.grading.backends` - the sandbox a notebook runs in, one module per backend (``--sandbox NAME``);
* :mod:`~labkit.grading.seccomp` - the system calls a sandboxed notebook may not make;
* :mod:`~labkit.grading.cgroup` - a memory cgroup around each sandbox and grading process;
* :mod:`~labkit.grading.protocol` - the plain-number messages between grader and sandbox;
* :mod:`~labkit.grading.worker` - the sandboxed side: a pristine supervisor and the notebook's process;
* :mod:`~labkit.grading.guard` - the watch in the notebook's process: refusals, tampering, attestations;
* :mod:`~labkit.grading.remote` - the grader's handle on a sandbox and its proxies;
* :mod:`~labkit.grading.refusals` - what a graded function may not reach, as the watch recognises it;
* :mod:`~labkit.grading.scan` - reading a notebook's source for refused references;
* :mod:`~labkit.grading.intake` - the class as the LMS gives it (folders, nbgrader, Canvas, Moodle, a zip) as students;
* :mod:`~labkit.grading.scoring` - grading one notebook and one submission (one process per submission);
* :mod:`~labkit.grading.rubric` - how exercise results become a grade (``rubric.toml``: the lab's);
* :mod:`~labkit.grading.late` - the rubric's deadline, submission times, the late penalty;
* :mod:`~labkit.grading.forkserver` - the grader's side of the fork server: notebooks' workers forked warm;
* :mod:`~labkit.grading.zygote` - the fork server inside its sandbox, isolating each worker it forks;
* :mod:`~labkit.grading.run` - the grader's own process: grading a class (:mod:`~labkit.grading.run.classrun`),
  its engines here or on a Dask cluster (:mod:`~labkit.grading.run.engines`, :mod:`~labkit.grading.run.dask`),
  each submission's grading process and the launcher that forks it (:mod:`~labkit.grading.run.processes`,
  :mod:`~labkit.grading.run.launcher`, :mod:`~labkit.grading.run.warm`), resuming and shards
  (:mod:`~labkit.grading.run.resume`), the progress bar (:mod:`~labkit.grading.run.progress`);
* :mod:`~labkit.grading.report` - grades.csv, feedback, per-submission JSON, merging;
* :mod:`~labkit.grading.record` - a run's record: its rubric, seed, version, the hash of each result it wrote;
* :mod:`~labkit.grading.class_report` - ``report.html``: the class at a glance (``labkit report OUT``);
* :mod:`~labkit.grading.lms` - the grades into a Canvas gradebook or a Moodle grade import file.

Student code never runs in the grading process: see docs/instructors.md.
"""

import importlib

from .release import release, release_notebook, strip_solutions  # light: nbformat is imported when used

# Names are imported on first use (PEP 562), so that the sandboxed worker, started as
# ``python -m labkit.grading.worker``, does not pay for nbformat and the grader's modules.
_EXPORTS = {
    "grade": "run.classrun",
    "SubmissionGrade": "report",
    "merge": "report",
    "Rubric": "rubric",
    "load_rubric": "rubric",
    "exercises_in": "scoring",
    "grade_notebook": "scoring",
    "grade_submission": "scoring",
    "submission_notebooks": "scoring",
    "GradeOptions": "options",
    "get_backend": "backends",
}
_MODULES = {
    "backends",
    "cgroup",
    "class_report",
    "forkserver",
    "guard",
    "intake",
    "late",
    "lms",
    "nbgrader",
    "options",
    "protocol",
    "record",
    "refusals",
    "release",
    "remote",
    "report",
    "rubric",
    "run",
    "scan",
    "scoring",
    "seccomp",
    "worker",
    "zygote",
}

__all__ = sorted(_EXPORTS) + ["release", "release_notebook", "strip_solutions"]


def __getattr__(name):
    if name in _MODULES:
        return importlib.import_module(f".{name}", __name__)
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = importlib.import_module(f".{_EXPORTS[name]}", __name__)
    value = getattr(module, "load" if name == "load_rubric" else name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS) | _MODULES)
