"""Grading a class on a Dask cluster: :class:`DaskEngine`, ``labkit grade --dask ADDRESS`` (or ``--dask local``).

One task per submission (:func:`_task`), graded in a Dask worker as ``--jobs`` grades it here. The workers need
the same labkit version, the course's exercises module, the sandbox's tool and the submissions at the client's
path (a shared file system); the rubric is sent, the refusals computed once per worker. A task whose worker dies
goes to another (the scheduler's ``allowed-failures``), one that raises runs once more (``retries=1``), then it is
"could not be graded", which a resumed run grades again. A second arrival for a name is ignored and counted in
``run.json``. Dask is imported here only, when a run asks for it (the ``labkit[dask]`` extra).
"""

import atexit
import functools
import json
import logging
import os
import secrets
import shutil
import tempfile
import threading
import time
from collections.abc import Generator
from dataclasses import asdict, replace
from pathlib import Path

from ...errors import InputError
from ..options import GradeOptions
from ..store.report import one_line, safe_name
from ..submission import refusals
from .engines import Batch, Engine, Outcome, start_warm, stop_warm
from .processes import Job, low_space, peak_bytes, sandbox_problem

LOCAL = "local"  # --dask local: a LocalCluster on this machine
CONNECT_TIMEOUT = "30s"  # to reach a scheduler


def _dask():
    """The distributed module, or a ValueError saying how to install it."""
    try:
        import distributed
    except ImportError:
        raise InputError(
            "--dask needs dask.distributed, which comes with the dask extra: pip install 'labkit[dask]' "
            "(on the client and on every worker)."
        ) from None
    return distributed


def connect(address, workers=2):
    """(client, close) of the scheduler at `address`, or of a new LocalCluster of `workers` one-thread worker
    processes when it is ``"local"``; ``close()`` closes both. ValueError when it cannot be reached."""
    distributed = _dask()
    if address == LOCAL:
        if int(workers) < 1:
            raise InputError(f"--dask-workers must be at least 1; got {workers}.")
        cluster = distributed.LocalCluster(
            n_workers=int(workers),
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=logging.ERROR,
        )
        client = distributed.Client(cluster)
        return client, lambda: (client.close(), cluster.close())
    try:
        client = distributed.Client(address, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            f"cannot reach the Dask scheduler at {one_line(address, 100)} ({one_line(exc, 200)}): start one "
            "(`dask scheduler`, and `dask worker ADDRESS --nthreads 1` on each machine), or give --dask local."
        ) from None
    return client, client.close


class DaskEngine(Engine):
    """Grade on the Dask cluster at `address` (``"local"``: a LocalCluster of `workers` processes), one task per
    submission; connected while :meth:`grade` runs."""

    name = "dask"

    def __init__(self, address: str, workers: int = 2):
        if not isinstance(address, str) or not address.strip():
            raise InputError(f"--dask takes a scheduler's address (tcp://host:8786) or 'local'; got {address!r}.")
        self.address, self.workers = address, workers
        self._record: dict = {"engine": self.name}

    def record(self) -> dict:
        """The engine, its scheduler, how many each worker graded, the duplicates ignored, the workers' peak."""
        return dict(self._record)

    def grade(self, batch: Batch) -> Generator[Outcome, None, None]:
        distributed = _dask()
        options = batch.options
        client, close = connect(self.address, self.workers)
        token = secrets.token_hex(4)
        rubric = None if options.rubric is None else Path(options.rubric).read_text(encoding="utf-8")
        payload = {"options": asdict(options), "rubric": rubric}
        seen: set[str] = set()
        by_worker: dict[str, int] = {}
        duplicates, stopped = 0, None
        self._record = {"engine": self.name, "dask scheduler": client.scheduler.address}
        try:
            futures = {}
            for path, name in batch.todo:
                key = f"labkit-grade-{safe_name(name)}-{token}"
                future = client.submit(
                    _task, os.path.abspath(path), name, payload, key=key, pure=False, retries=1
                )  # abspath, not resolve: a submission that is a link stays one (and is refused)
                futures[future] = name
            for future in distributed.as_completed(list(futures)):
                name = futures[future]
                try:
                    message = future.result()
                except Exception as exc:  # noqa: BLE001 - KilledWorker, or what the task raised twice
                    died = isinstance(exc, distributed.KilledWorker)
                    why = "the Dask workers grading it died" if died else "its Dask task failed"
                    message = {
                        "name": name, "result": None, "failure": f"{why} ({type(exc).__name__}: {one_line(exc)})"
                    }  # fmt: skip
                future.release()
                if name in seen:  # a submission is recorded once
                    duplicates += 1
                    continue
                seen.add(name)
                message["name"] = name  # the name is the client's, whatever came back
                worker = message.get("worker")
                if worker:
                    by_worker[worker] = by_worker.get(worker, 0) + 1
                yield batch.outcome(message)
                stopped = low_space(batch.out)
                if stopped is not None:
                    break
            if stopped is not None:  # as the local engine does: the rest are reported, and a resumed run grades them
                left = [future for future, name in futures.items() if name not in seen]
                client.cancel(left)
                for future in left:
                    yield Outcome(batch.not_graded(futures[future], stopped))
            try:
                worker_peaks = client.run(peak_bytes)
            except Exception:  # noqa: BLE001 - a worker that went away while asked
                worker_peaks = {}
        finally:
            close()
        self._record.update(
            {
                "dask workers": dict(sorted(by_worker.items())),
                "dask duplicates ignored": duplicates,
                "dask worker peak bytes": max(worker_peaks.values(), default=None),
            }
        )


@functools.cache
def _profiles_text(exercises):
    """The refusals of the exercises' registry as JSON, computed once per worker (250 kB: not sent per task)."""
    from ...exercises.registry import load as load_registry

    return json.dumps(refusals.wire(load_registry(exercises).refusals))


_sandbox_problem = functools.cache(sandbox_problem)  # looked at once per worker process


def _task(path, name, payload):
    """In a Dask worker: grade one submission in a grading process of its own (started once more if it breaks,
    with :mod:`subprocess`: a worker is a daemonic process that multiprocessing refuses children); its
    outcome as plain data (:meth:`.processes.Job.message`), with the worker's address."""
    from distributed import get_worker

    here = get_worker().address
    options = GradeOptions.from_dict(payload["options"])
    outcome = {"name": name, "result": None, "attempts": 0, "peak": None, "worker": here}
    if not os.path.lexists(path):
        outcome["failure"] = (
            f"{one_line(path, 200)} is not on the Dask worker {here}: workers read the submissions from a file "
            "system shared with the client, at the same path"
        )
        return outcome
    problem = _sandbox_problem(options.backend)
    if problem is not None:
        outcome["failure"] = f"the sandbox cannot run on the Dask worker {here}: {one_line(problem, 300)}"
        return outcome
    work = Path(tempfile.mkdtemp(prefix="labkit-run-"))
    try:
        profiles_file = work / "profiles.json"
        profiles_file.write_text(_profiles_text(options.exercises), encoding="utf-8")
        if payload.get("rubric") is not None:
            (work / "rubric.toml").write_text(payload["rubric"], encoding="utf-8")
            options = replace(options, rubric=str(work / "rubric.toml"))
        job = Job(path, name, work, options, profiles_file, *_kept(options))
        while True:
            job.start()
            while not job.poll():
                time.sleep(0.05)
            if job.conclude():
                break
        outcome.update(job.message())
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return outcome


_KEPT: dict = {}  # (backend, limits, exercises, thread) -> (fork server, launcher) kept
_KEPT_LOCK = threading.Lock()


def _kept(options):
    """The fork server and launcher this worker keeps (:func:`.engines.start_warm`), as it grades one submission per
    task: started on first use, started again if they died, stopped when the process ends."""
    if not options.fork_server:
        return None, None
    # one pair per thread: a worker's threads never stop each other's, and the pair dies with its thread
    # (the sandbox and the launcher are set to die with the thread that started them)
    key = (options.backend, options.limits, options.exercises, options.solutions, threading.get_ident())
    with _KEPT_LOCK:
        found = _KEPT.get(key)
        server, launcher = found or (None, None)
        died = (server is not None and server.box.process.poll() is not None) or (
            launcher is not None and launcher.process.poll() is not None
        )
        if found is None or died:  # none started yet (or none could be: then none is tried again), or one died
            stop_warm(server, launcher)
            if key not in _KEPT:
                atexit.register(lambda: stop_warm(*_KEPT.pop(key, (None, None))))
            _KEPT[key] = start_warm(options)
        return _KEPT[key]
