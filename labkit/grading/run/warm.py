"""The warm helpers of a run: the fork server and the launcher, started once and kept per thread.

:func:`warm` starts both for a class run here (:class:`.engines.LocalEngine`)
and stops them at its end; :func:`kept` keeps one pair per thread for the
life of a process that grades one submission per call (a Dask worker:
:mod:`.dask`), starting them again when one died. Either may be None: it is
switched off (``fork_server=False``) or could not start, and grading goes the
plain way (a sandbox of its own for every notebook, a new Python for every
grading process), slower and as safe.
"""

import atexit
import contextlib
import threading

from ..sandbox import backends, forkserver
from .launcher import Launcher


def start_warm(backend, options):
    """(fork server, launcher) for grading with `options`, each None where it is switched off or cannot start (the
    plain way then: a sandbox of its own for every notebook, a new Python for every grading process, slower
    and as safe). The two import what they need at the same time."""
    if not options.fork_server:
        return None, None
    try:
        server = forkserver.ForkServer(backend, options.limits).start(wait=False)
    except forkserver.ForkServerError:
        server = None
    try:
        launcher = Launcher(options, server, wait=False)
    except (OSError, ValueError):
        launcher = None
    if server is not None:
        try:
            server.wait_ready()
        except forkserver.ForkServerError:
            server = None
    if launcher is not None:
        try:
            launcher.wait_ready()
        except OSError:
            launcher = None
    return server, launcher


def stop_warm(server, launcher):
    for thing in (launcher, server):
        if thing is not None:
            thing.stop()


@contextlib.contextmanager
def warm(backend, options):
    """The run's fork server and launcher (:func:`start_warm`), stopped at the end."""
    server, launcher = start_warm(backend, options)
    try:
        yield server, launcher
    finally:
        stop_warm(server, launcher)


_KEPT: dict = {}  # (backend, limits, exercises, thread) -> (fork server, launcher) kept (a Dask worker's)
_KEPT_LOCK = threading.Lock()


def kept(options):
    """The fork server and launcher this process keeps for :func:`.engines.grade_one` (a Dask worker grades one
    submission per task): started on first use, started again if they died, stopped when the process
    ends; (None, None) with ``fork_server`` off or where they cannot start."""
    if not options.fork_server:
        return None, None
    # one pair per thread: a worker's threads never stop each other's, and the pair dies with its thread
    # (the sandbox and the launcher are set to die with the thread that started them)
    key = (options.backend, options.limits, options.exercises, threading.get_ident())
    with _KEPT_LOCK:
        found = _KEPT.get(key)
        server, launcher = found or (None, None)
        died = (server is not None and server.box.process.poll() is not None) or (
            launcher is not None and launcher.process.poll() is not None
        )
        if found is None or died:  # none started yet (or none could be: then none is tried again), or one died
            stop_warm(server, launcher)
            server, launcher = start_warm(backends.get_backend(options.backend), options)
            if key not in _KEPT:
                atexit.register(_stop_kept, key)
            _KEPT[key] = (server, launcher)
        return server, launcher


def _stop_kept(key):
    stop_warm(*_KEPT.pop(key, (None, None)))
