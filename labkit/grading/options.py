"""How a grading run is bounded and run: one options object, its defaults defined once.

:class:`GradeOptions`, the run's choices that a flag of ``labkit grade`` sets, is built once at the edge (the command
line, whose defaults are read from here, or the caller of :func:`labkit.grading.grade`) and passed on frozen, down
to each submission's grading process and into the sandbox; no other module spells out a default of its own. What a
run grades (paths, names, times, roster, variants) is a :class:`labkit.grading.run.plan.Submissions` instead.
"""

import os
from dataclasses import dataclass, field, fields

from ..errors import InputError
from .sandbox import backends
from .sandbox.backends.base import Limits

MIB = 1024**2
CPU_GRACE = 30  # CPU seconds a notebook's process gets beyond the total time limit (`labkit grade`)


@dataclass(frozen=True)
class GradeOptions:
    """Time, memory, randomness, sandbox and rubric of one grading run."""

    cell_timeout: int = 60  # seconds per cell, and per call of a student's function
    total_timeout: int = 600  # seconds for one submission in all, every notebook of it together
    seed: int | None = None  # the random test data's seed (a fresh one per run when None)
    backend: str = backends.DEFAULT  # the sandbox backend's name (labkit.grading.sandbox.backends; `--sandbox NAME`)
    rubric: str | None = None  # the rubric's TOML file (None: the lab's own, labkit/grading/store/rubric.toml)
    limits: Limits = field(default_factory=Limits)  # the sandbox's resource limits
    grader_memory: int = 3 * 1024**3  # bytes of address space for the grader's own work on one submission
    grader_grace: int = 120  # seconds the grader's own work may take beyond the submission's time limit
    # the exercises' registry as module:attribute (the lab's when None; see labkit.exercises)
    exercises: str | None = None
    # notebooks' workers forked from one warm server per run (labkit.grading.sandbox.forkserver)
    fork_server: bool = True
    # the instructor notebooks' folder, a known source (labkit.grading.submission.known); None: left out
    solutions: str | None = None
    # each student's own data (labkit.exercises.variants), derived by the class run from the roster and the
    # variants file: {submission name: {exercise (text): {parameter: value}}}; None: the lab's data for all
    variants: dict | None = None
    jobs: int = 2  # submissions graded at once here (the local engine's; labkit.grading.run.engines.LocalEngine)
    shard: str | tuple | None = None  # "I/N": grade only the I-th of N parts of the class (labkit.grading.run.resume)
    fresh: bool = False  # delete an earlier run's results in the output folder and grade every submission
    times_from_submission: bool = False  # a time missing elsewhere is read from the submission's timestamp.txt
    times_from_mtime: bool = False  # ... else from its notebooks' modification time (both student-supplied)

    def __post_init__(self):
        for name in ("cell_timeout", "total_timeout"):
            if int(getattr(self, name)) < 1:
                raise InputError(f"{name.replace('_', '-')} must be at least 1 second; got {getattr(self, name)}.")
        backends.backend_class(self.backend)  # ValueError naming the choices
        if self.rubric is not None:
            if not isinstance(self.rubric, (str, os.PathLike)):
                raise InputError(
                    f"rubric must be the path of a TOML rubric (or None for the lab's own); got {self.rubric!r}."
                )
            object.__setattr__(self, "rubric", os.fspath(self.rubric))
        if self.solutions is not None:
            if not isinstance(self.solutions, (str, os.PathLike)):
                raise InputError(
                    f"solutions must be the folder of the instructor notebooks (or None); got {self.solutions!r}."
                )
            object.__setattr__(self, "solutions", os.path.abspath(os.fspath(self.solutions)))
        if self.variants is not None and not (
            isinstance(self.variants, dict) and all(isinstance(v, dict) for v in self.variants.values())
        ):
            raise InputError("variants must map each submission name to its data, {exercise: {parameter: value}}.")
        if not isinstance(self.limits, Limits):
            raise InputError(f"limits must be a labkit.grading.sandbox.backends.base.Limits; got {self.limits!r}.")

    @classmethod
    def from_dict(cls, data):
        """The options as plain data (``dataclasses.asdict``, how they travel to each submission's grading process),
        read back once at the receiving process's edge; ValueError for a field that is not an option."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise InputError(
                f"unknown grading option(s) {', '.join(unknown)}; the options are {', '.join(sorted(known))}."
            )
        return cls(**{**data, "limits": Limits(**data.get("limits", {}))})


DEFAULTS = GradeOptions()
