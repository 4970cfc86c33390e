"""No sandbox of labkit's own: for when each submission is already isolated outside labkit, e.g. one
``labkit grade`` per submission in a throw-away container (then ``labkit merge``). The worker keeps a private home,
the rlimits, a memory cgroup where one can be made, the seccomp filter and the watch; everything else is open, so
every run starts with :data:`WARNING` on stderr.
"""

import os
import tempfile

from ..protocol import COURSE_PATH
from . import register
from .base import Backend, Box, course_mounts, processes_of_this_user, remove_tree

WARNING = """\
!!! labkit grade --sandbox none (--no-sandbox): student code runs UNCONFINED, with your permissions.
!!! It can read, change or delete anything you can, reach the network and leave
!!! processes behind. Use this only for code you trust.
"""


@register
class Unconfined(Backend):
    """The worker as a plain process with a private folder: only where the submission is isolated already."""

    name = "none"
    summary = (
        "no sandbox of labkit's own, for when each submission already has a container of its own "
        "(a pod, a batch job's container); student code runs with your permissions"
    )

    def available(self):
        return None  # a process can always be started

    def warning(self):
        return WARNING

    def box(self, argv, limits):
        folder = tempfile.mkdtemp(prefix="labkit-grade-")
        env = {**os.environ, "HOME": folder, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"}
        courses = [str(origin.parent) for origin, _ in course_mounts()]  # -I ignores PYTHONPATH: the worker adds them
        if courses:
            env[COURSE_PATH] = os.pathsep.join(courses)
        return Box(
            argv,
            limits,
            cwd=folder,
            env=env,
            processes_base=processes_of_this_user(),
            cleanup=lambda: remove_tree(folder),
        )
