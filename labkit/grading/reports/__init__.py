"""What a person reads after a run, in the instructor's process: the class report, copies, marking by hand, notes."""
