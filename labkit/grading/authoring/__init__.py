"""Handing the lab out, in the instructor's process: the student release, nbgrader's markup, every draw checked."""
