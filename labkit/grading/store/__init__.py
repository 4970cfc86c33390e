"""The typed store of a run: the one reader and writer of a run's folder (results, feedback, grades.csv, seed,
run.json, the record and the marks), the results' classes, the rubric and the late rule.

Plain data and text, run in whichever process reads or writes a run's folder; no student code comes near it. It
imports nothing of the grader above it (only the sandbox's level, the options and the labkit library).
"""
