"""Grading a class on a Dask cluster: :class:`DaskEngine`, ``labkit grade --dask ADDRESS`` (or ``--dask local``).

One task per submission. In a Dask worker the task grades the submission as
``labkit grade --jobs`` does on one machine (:func:`.engines.grade_one`):
in a grading process of its own, started with :mod:`subprocess`, under the same
memory and time limits, whose notebooks run in the sandbox of the worker's
machine. (A Dask worker is a daemonic process, and Python's multiprocessing
refuses such a process children: the process pool an earlier ``labkit grade``
used failed there with "daemonic processes are not allowed to have children".)
The task sends back the result file's data; the client scores it under the
rubric and writes ``results/<name>.json`` and the feedback as each arrives
(:mod:`.classrun`), so a run that stops is resumed by
running it again.

What the workers need: the same labkit version (a result written by another
one is refused, and its submission reported as not graded), the course's
exercises module when the rubric names one, the sandbox backend's tool, and the
submissions at the path the client gives: a file system shared with the
client (NFS, a cluster's home or scratch). The notebooks are not sent with
the tasks; the rubric is, and each worker computes the refusals once.

A task whose worker dies is given to another worker by the scheduler (up to
``distributed.scheduler.allowed-failures`` times, 3 by default), and a task
that raises is run once more (``retries=1``); one that still fails is
reported as "could not be graded", which a resumed run grades again. Every
submission is recorded once, by name: a second arrival for a name already
recorded is ignored and counted in ``run.json``.

Dask is imported here only, when a run asks for it (the ``labkit[dask]``
extra); the rest of labkit never imports it.
"""

import functools
import json
import logging
import os
import resource
import secrets
import shutil
import tempfile
from collections.abc import Generator
from dataclasses import replace
from pathlib import Path

from ...errors import InputError
from ..options import GradeOptions
from ..sandbox import backends
from ..sandbox.backends.base import SandboxUnavailable
from ..store.report import one_line, safe_name
from ..submission import refusals
from .engines import Batch, Engine, Outcome, grade_one
from .processes import low_space, settled

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
    """A ``distributed.Client`` of the scheduler at `address`, or of a new LocalCluster of `workers` worker
    processes of one thread each when `address` is ``"local"``; ValueError when it cannot be reached.

    Returns (client, close): call ``close()`` to close the client (and the LocalCluster)."""
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

        def close():
            client.close()
            cluster.close()

        return client, close
    if not isinstance(address, str) or not address.strip():
        raise InputError(f"--dask takes a scheduler's address (tcp://host:8786) or 'local'; got {address!r}.")
    try:
        client = distributed.Client(address, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            f"cannot reach the Dask scheduler at {one_line(address, 100)} ({one_line(exc, 200)}): start one "
            "(`dask scheduler`, and `dask worker ADDRESS --nthreads 1` on each machine), or give --dask local."
        ) from None
    return client, client.close


class DaskEngine(Engine):
    """Grade on the Dask cluster at `address` (``"local"``: a LocalCluster of `workers` worker processes), one
    task per submission: ``labkit grade --dask ADDRESS``. Connects when :meth:`grade` starts, and closes the
    client (and the LocalCluster) when it ends."""

    name = "dask"

    def __init__(self, address: str, workers: int = 2):
        if address != LOCAL and (not isinstance(address, str) or not address.strip()):
            raise InputError(f"--dask takes a scheduler's address (tcp://host:8786) or 'local'; got {address!r}.")
        self.address, self.workers = address, workers
        self._record: dict = {"engine": self.name}

    def record(self) -> dict:
        """The engine, its scheduler, the workers that graded and how many each, the duplicate arrivals ignored,
        the workers' peak memory."""
        return dict(self._record)

    def grade(self, batch: Batch) -> Generator[Outcome, None, None]:
        # each worker computes the refusals itself, once (they are 250 kB: not sent per task)
        distributed = _dask()
        options = batch.options
        client, close = connect(self.address, self.workers)
        token = secrets.token_hex(4)
        payload = {"options": options.as_dict(), "rubric": None}
        if options.rubric is not None:
            payload["rubric"] = Path(options.rubric).read_text(encoding="utf-8")
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
                futures[future.key] = (future, name)
            for future in distributed.as_completed([future for future, _ in futures.values()]):
                name = futures[future.key][1]
                try:
                    message = future.result()
                except Exception as exc:  # noqa: BLE001 - KilledWorker, or what the task raised twice
                    why = (
                        "the Dask workers grading it died"
                        if isinstance(exc, distributed.KilledWorker)
                        else "its Dask task failed"
                    )
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
                yield Outcome(settled(message, batch.rubric, options.seed), message.get("peak"))
                stopped = stopped or low_space(batch.out)
                if stopped is not None:
                    break
            if stopped is not None:  # as the local engine does: the rest are reported, and a resumed run grades them
                left = [(future, name) for future, name in futures.values() if name not in seen]
                client.cancel([future for future, _ in left])
                for _, name in left:
                    seen.add(name)
                    yield Outcome(batch.not_graded(name, stopped))
            try:
                worker_peaks = client.run(_peak_bytes)
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


def _peak_bytes():
    """A Dask worker's peak resident memory (its own, not its grading processes')."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


@functools.cache
def _profiles_text(exercises):
    """The refusals of the exercises' registry as JSON, computed once per worker process."""
    from ...exercises.registry import load as load_registry

    return json.dumps(refusals.wire(load_registry(exercises).refusals))


@functools.cache
def _sandbox_problem(backend):
    """Why the sandbox cannot run on this worker, or None."""
    try:
        backends.get_backend(backend).available()
    except SandboxUnavailable as exc:
        return str(exc)
    return None


def _task(path, name, payload):
    """In a Dask worker: grade one submission (:func:`.engines.grade_one`); its outcome as plain
    data, with the worker's address."""
    from distributed import get_worker

    try:
        here = get_worker().address
    except ValueError:
        here = "a Dask worker"
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
        outcome.update(grade_one(path, name, options, profiles_file, work))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return outcome
