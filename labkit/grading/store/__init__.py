"""What a grading run writes and reads back: the results' schema, the run's record, the rubric and the late policy.

Plain data and text, run in whichever process reads or writes a run's folder; no student code comes near it.
"""
