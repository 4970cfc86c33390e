"""Handing the lab out: the student release of the instructor notebooks and nbgrader's markup.

Run in the instructor's process (``labkit release``, ``labkit execute``) and nbgrader's own commands.
"""
