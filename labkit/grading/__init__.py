"""Releasing the lab to students and grading what comes back.

One module per concern:

* :mod:`~labkit.grading.release` - the student version of the instructor notebooks;
* :mod:`~labkit.grading.sandbox` - the bubblewrap box and resource limits a notebook runs in;
* :mod:`~labkit.grading.protocol` - the plain-number messages between grader and sandbox;
* :mod:`~labkit.grading.worker` - the sandboxed side: runs the cells, answers calls;
* :mod:`~labkit.grading.remote` - the grader's handle on a sandbox and its proxies;
* :mod:`~labkit.grading.refusals` - reference implementations a graded function may not use;
* :mod:`~labkit.grading.scoring` - grading one notebook and one submission;
* :mod:`~labkit.grading.rubric` - how exercise results become a grade (``rubric.toml``: the lab's);
* :mod:`~labkit.grading.batch` - grading a class in parallel;
* :mod:`~labkit.grading.report` - grades.csv, feedback, per-submission JSON, merging.

Student code never runs in the grading process: see the README's "For instructors".
"""
from .batch import grade
from .release import release, release_notebook, strip_solutions
from .report import SubmissionGrade, merge
from .rubric import Rubric, load as load_rubric
from .scoring import exercises_in, grade_notebook, grade_submission, submission_notebooks

__all__ = ["Rubric", "SubmissionGrade", "load_rubric", "exercises_in", "grade", "grade_notebook", "grade_submission", "merge", "release",
           "release_notebook", "strip_solutions", "submission_notebooks"]
