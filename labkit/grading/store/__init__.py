"""The typed store of a run: the one reader and writer of its folder, the results' classes, rubric and late rule.

What it keeps: results, feedback, grades.csv, seed.txt, run.json, the run's record and the marks. Plain data and
text, run in whichever process reads or writes a run's folder; no student code comes near it. It imports nothing of
the grader above it (only the sandbox's level, the options and the labkit library).
"""
