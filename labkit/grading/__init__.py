"""Releasing the lab to students and grading what comes back.

One subpackage per process and job (CONTRIBUTING.md draws the process tree):

* :mod:`~labkit.grading.authoring` - handing the lab out: the student release, nbgrader's markup;
* :mod:`~labkit.grading.run` - the grader's own process: the class as the LMS gives it, the class run, its
  engines (here or on Dask), each submission's grading process and the launcher, resume, shards, merge;
* :mod:`~labkit.grading.submission` - one submission's grading process: its notebooks, the source scan,
  the refusals, copied code, scoring;
* :mod:`~labkit.grading.sandbox` - isolation: backends, cgroup, seccomp, the protocol, the grader's handle,
  the fork server and, inside the sandbox, the zygote, the worker and its watch;
* :mod:`~labkit.grading.store` - what a run writes and reads back: results, the record, the rubric, lateness;
* :mod:`~labkit.grading.reports` - what a person reads afterwards: the class report, similarity, marking, LMS;
* :mod:`~labkit.grading.options` - the limits of a run, built once at its edge and passed to every process.

Student code never runs in the grading process: see docs/grading-security.md.
"""

import importlib

from .authoring.release import release, release_notebook, strip_solutions  # light: nbformat is imported when used

# Names are imported on first use (PEP 562), so that the sandboxed worker, started as
# ``python -m labkit.grading.sandbox.worker``, does not pay for nbformat and the grader's modules.
_EXPORTS = {
    "grade": "run.classrun",
    "SubmissionGrade": "store.report",
    "merge": "store.report",
    "Rubric": "store.rubric",
    "load_rubric": "store.rubric",
    "exercises_in": "submission.scoring",
    "grade_notebook": "submission.scoring",
    "grade_submission": "submission.scoring",
    "submission_notebooks": "submission.scoring",
    "GradeOptions": "options",
    "Submissions": "run.plan",
    "get_backend": "sandbox.backends",
}
_MODULES = {"authoring", "options", "reports", "run", "store", "sandbox", "submission"}

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
