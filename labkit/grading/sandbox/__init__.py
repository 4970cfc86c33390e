"""Isolation: the sandbox a notebook runs in, and both ends of the line to it.

Runs in two processes: the grader's side (:mod:`.remote`, :mod:`.forkserver`, :mod:`.backends`) in a
submission's grading process, and the sandboxed side (:mod:`.zygote`, :mod:`.worker`, :mod:`.guard`)
inside the sandbox. Nothing here imports labkit's other grading subpackages.
"""
