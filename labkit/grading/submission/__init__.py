"""One submission's grading process: reading its notebooks, the source scan, the refusals, scoring.

One process per submission (:mod:`labkit.grading.run.processes`); student code runs in its sandbox, never here.
"""
