"""Releasing the lab to students and grading what comes back, in the rooms CONTRIBUTING.md maps: ``lms`` (the class
in, the grades out), ``run`` (the plan and its run), ``submission`` (one submission's grading process), ``sandbox``
(isolation), ``store`` (a run's folder), ``reports`` (what a person reads afterwards) and ``authoring`` (the
release); ``options`` holds the limits of a run. Student code never runs in the grading process: see
docs/grading-security.md.
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
