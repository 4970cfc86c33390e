"""One submission's grading process (started by :mod:`labkit.grading.run.processes`): reading its notebooks, the
source scan, the refusals, scoring; student code runs in the sandbox it opens, never here."""
