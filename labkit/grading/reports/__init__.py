"""What a person reads after a run: the class report, code similarity, marking by hand, LMS exports.

Run in the instructor's process (``labkit report``, ``labkit mark``, ``labkit export``).
"""
