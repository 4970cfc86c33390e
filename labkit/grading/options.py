"""How a grading run is bounded: one options object, its defaults defined once.

:class:`GradeOptions` travels from the command line (or :func:`labkit.grading.grade`)
to each submission's grading process and into the sandbox.
"""
from dataclasses import asdict, dataclass, field

from .sandbox import Limits


@dataclass(frozen=True)
class GradeOptions:
    """Time, memory and randomness of one grading run."""

    cell_timeout: int = 60  # seconds per cell, and per call of a student's function
    total_timeout: int = 600  # seconds for one submission in all, every notebook of it together
    seed: int = None  # the random test data's seed (a fresh one per run when None)
    confined: bool = True  # False runs student code without the sandbox (trusted code only)
    limits: Limits = field(default_factory=Limits)  # the sandbox's resource limits
    grader_memory: int = 3 * 1024**3  # bytes of address space for the grader's own work on one submission
    grader_grace: int = 120  # seconds the grader's own work may take beyond the submission's time limit
    exercises: str = None  # the exercises' registry as module:attribute (the lab's when None; see labkit.exercises)

    def __post_init__(self):
        for name in ("cell_timeout", "total_timeout"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name.replace('_', '-')} must be at least 1 second; got {getattr(self, name)}.")

    def as_dict(self):
        return asdict(self)

    @classmethod
    def from_dict(cls, data):
        data = dict(data)
        data["limits"] = Limits(**data.get("limits", {}))
        return cls(**data)
