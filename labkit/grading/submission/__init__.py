"""One submission's grading process: reading its notebooks, the source scan, the refusals, scoring.

Runs in one process per submission, started by :mod:`labkit.grading.run.processes`; student code runs in the
sandbox it opens (:mod:`labkit.grading.sandbox`), never here.
"""
