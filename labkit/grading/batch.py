"""Grading a class: every submission in a grading process of its own, a few at a time.

:func:`grade` checks the sandbox backend once (:mod:`labkit.grading.sandbox.backends`),
draws the run's seed (or takes the one given), computes what the sandbox
refuses once, and then starts one process
per submission (``python -m labkit.grading.submission.scoring``), at most `jobs` at a
time. Each has its own limits: address space and a memory cgroup for the
grader's own work, and the submission's time limit plus a grace for the
checks. So a submission that makes its grading crash, run out of memory or
hang costs only its own grade: its process is started once more, and if
that fails too the submission is reported as "could not be graded" with
the reason, while every other submission is graded as usual.

Before each submission the free space of the temporary and output folders
is checked; when it runs low the run stops starting new submissions and
says so, rather than grading students into zeros. The output folder
(:mod:`labkit.grading.results.report`) always gets a ``grades.csv`` with every
submission once, and ``run.json`` says how the run went (its seed, how many
could not be graded, its time, the grader's peak memory for one submission).

Each submission's time (for a rubric's ``[late]`` table) is read here, on the
grader's side (:func:`labkit.grading.results.late.submission_time`), and saved with
its result, so that ``--merge`` can apply a late rule later. A progress bar
with an ETA is drawn on a terminal (:mod:`labkit.grading.progress`).

Each submission's ``results/<name>.json`` and feedback are written as soon as
it is graded, so a run that stops can be resumed: grading into an output
folder that already holds results of the same rubric, labkit version and seed
grades only the submissions it lacks (:func:`resumed`; a submission that could
not be graded is graded again). :func:`shard` picks the I-th of N parts of a
class, for batch systems; :mod:`labkit.grading.distributed` sends the
submissions to a Dask cluster instead of grading them here. Both engines grade
a submission through :func:`grade_one`.
"""

import atexit
import contextlib
import ctypes
import json
import os
import resource
import secrets
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from .options import GradeOptions
from .progress import Progress
from .results import record as records
from .results.late import submission_time
from .results.report import FORMAT, SubmissionGrade, labkit_version, one_line, safe_name, write_report, write_result
from .results.rubric import DEFAULT as DEFAULT_RUBRIC
from .results.rubric import Rubric
from .results.rubric import default as default_rubric
from .results.rubric import load as load_rubric
from .sandbox import backends, cgroup, forkserver
from .sandbox.backends.base import SandboxUnavailable
from .submission import refusals
from .submission.scoring import known_sources, submission_name, submission_notebooks

MIN_FREE = 512 * 1024**2  # bytes free in the temporary and output folders before a submission starts
ATTEMPTS = 2  # a grading process that breaks is started once more
LAUNCH_TIMEOUT = 30  # seconds for the launcher to fork one grading process
LAUNCHER_READY = 120  # seconds for the launcher to import the grader


def _low_space(out):
    """Why grading cannot go on (a folder with too little free space), or None."""
    for folder in (Path(tempfile.gettempdir()), out):
        try:
            free = shutil.disk_usage(folder).free
        except OSError:
            continue
        if free < MIN_FREE:
            return (
                f"only {free / 1024**2:.0f} MiB free in {folder} (grading needs {MIN_FREE // 1024**2} MiB); "
                "free some space and grade these submissions again, then combine the runs with --merge"
            )
    return None


class _Job:
    """One submission's grading process."""

    def __init__(self, path, name, work, options, profiles_file, server=None, launcher=None):
        self.path, self.name, self.attempt = Path(path), name, 0
        self.work, self.options, self.profiles_file = work, options, profiles_file
        self.server = server  # the run's fork server (labkit.grading.sandbox.forkserver), or None
        self.launcher = launcher  # the run's Launcher of grading processes, or None (each one a new Python)
        self.process, self.cgroup, self.started = None, None, None

    def start(self):
        self.attempt += 1
        self.result = self.work / f"{safe_name(self.name)}-{self.attempt}.json"
        spec = self.work / f"{safe_name(self.name)}-{self.attempt}.spec.json"
        origin = None if self.options.backend in backends.BUILTIN else backends.origin(self.options.backend)
        spec.write_text(
            json.dumps(
                {
                    "submission": str(self.path),
                    "name": self.name,
                    "result": str(self.result),
                    "profiles": str(self.profiles_file),
                    "options": self.options.as_dict(),
                    "backend_origin": origin,
                }
            ),
            encoding="utf-8",
        )
        memory = self.options.grader_memory
        self.cgroup = cgroup.create(memory, label="labkit-grader", cores=None)
        group = self.cgroup

        parent = os.getpid()

        def prepare():
            if group is not None:
                group.join()
            resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
            _die_with(parent)

        environment = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
        environment.update(_process_environment())
        if group is not None:  # the sandboxes' cgroups go beside the grading process's, not inside its limit
            environment.update(group.sibling_environment())
        environment.pop(forkserver.ENV, None)
        if self.server is not None:
            environment.update(self.server.environment())
        self.log = self.work / f"{safe_name(self.name)}-{self.attempt}.log"
        if self.launcher is not None:
            folders = [group.path, group.cpu_path] if group is not None else []
            try:
                self.process = self.launcher.launch(
                    {
                        "spec": str(spec),
                        "log": str(self.log),
                        "memory": memory,
                        "cgroups": [str(folder / "cgroup.procs") for folder in folders if folder is not None],
                        "environment": environment,
                    }
                )
                self.started = time.monotonic()
                return
            except OSError:  # the launcher is gone: this submission and the next start the plain way
                self.launcher = None
        with open(self.log, "wb") as log:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "labkit.grading.submission.scoring", str(spec)],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=log,
                start_new_session=True,
                preexec_fn=prepare,
                env=environment,
                pass_fds=(self.server.fd,) if self.server is not None else (),
            )
        self.started = time.monotonic()

    @property
    def limit(self):
        return self.options.total_timeout + self.options.grader_grace

    def overdue(self):
        return time.monotonic() - self.started > self.limit

    def stop(self):
        """Kill the grading process and everything it started (its sandboxes die with it)."""
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        self.process.wait()
        self.finish()

    def last_words(self):
        """The last line the grading process wrote to stderr (a Python error's summary), as one printable line."""
        try:
            with open(self.log, "rb") as log:
                log.seek(max(0, os.path.getsize(self.log) - 4096))
                lines = log.read().decode("utf-8", "replace").strip().splitlines()
        except OSError:
            return ""
        return f": {one_line(lines[-1], 200)}" if lines else ""

    def finish(self):
        self.out_of_memory, self.peak = False, None
        if self.cgroup is not None:
            self.out_of_memory = self.cgroup.out_of_memory()
            self.peak = self.cgroup.peak()
            self.cgroup.remove()

    def poll(self):
        """Whether this attempt is over (its process ended, or it overran its limit and was stopped)."""
        if self.process.poll() is None:
            if not self.overdue():
                return False
            self.stop()
            self.timed_out = True
        else:
            self.finish()
            self.timed_out = False
        return True

    def wait(self):
        """Wait until this attempt is over (its process ends, or it overruns its limit and is stopped)."""
        try:
            self.process.wait(timeout=max(0.0, self.limit - (time.monotonic() - self.started)))
        except subprocess.TimeoutExpired:
            self.stop()
            self.timed_out = True
        else:
            self.finish()
            self.timed_out = False

    def conclude(self):
        """After an attempt: True when the submission is done (:meth:`message`), False when its grading
        process is to be started once more."""
        self.peaks = [*getattr(self, "peaks", []), self.peak]
        self.data, self.why = self.read(self.timed_out)
        return self.data is not None or self.attempt >= ATTEMPTS

    def message(self):
        """The submission's outcome as plain data (what a Dask task sends back): its result file's data, or
        why it could not be graded."""
        return {
            "name": self.name,
            "result": self.data,
            "failure": None if self.data is not None else f"{self.why} (tried {self.attempt} times)",
            "attempts": self.attempt,
            "peak": max((p for p in self.peaks if p), default=None),
        }

    def read(self, timed_out):
        """(the result file's data, None), or (None, why the grading process failed)."""
        code = self.process.returncode
        if timed_out:
            return None, (
                f"its grading took longer than {self.limit} s (the submission's time limit plus "
                f"{self.options.grader_grace} s for the checks) and was stopped"
            )
        if code != 0 or not self.result.exists():
            if getattr(self, "out_of_memory", False) or code in (-signal.SIGKILL, -signal.SIGSEGV):
                return None, (
                    "its grading ran out of memory (the grader's limit of "
                    f"{self.options.grader_memory // 1024**2} MiB) and was stopped"
                    if getattr(self, "out_of_memory", False) or code == -signal.SIGKILL
                    else f"its grading process crashed ({signal.Signals(-code).name})"
                )
            if code is not None and code < 0:
                name = signal.Signals(-code).name if -code in signal.Signals._value2member_map_ else str(-code)
                return None, f"its grading process was killed by {name}"
            return None, f"its grading process ended with status {code} without a result{self.last_words()}"
        try:
            if self.result.stat().st_size > records.MAX_RESULT:
                return None, "its result was larger than the grader accepts"
            data = json.loads(self.result.read_text(encoding="utf-8"))
            if not isinstance(data, dict) or data.get("format") != FORMAT:
                raise ValueError(f"format {data.get('format') if isinstance(data, dict) else data!r:.60}")
        except (OSError, ValueError) as exc:
            return None, f"its result could not be read ({str(exc)[:200]})"
        return data, None


def _process_environment():
    """What each grading process gets in its environment beyond the grader's own (nothing yet).

    Called in the process that starts the grading process: the grader with ``--jobs``, a Dask worker
    with ``--dask``; the place for whatever a grading process must be handed (the fork server's address)."""
    return {}


_LIBC = ctypes.CDLL(None, use_errno=True) if sys.platform.startswith("linux") else None


def _die_with(parent):
    """In a grading process before it runs: be killed when the thread that started it dies (the grader, or
    a Dask worker killed mid-task), so no grading outlives its grader; Linux only."""
    if _LIBC is not None:
        _LIBC.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # the grader died before the line above
            os._exit(1)


def grade_one(path, name, options, profiles_file, work):
    """Grade one submission in a grading process of its own (started once more if it breaks); blocks.

    The seam both engines share: :func:`_schedule` runs the same steps (:class:`_Job`) a few at a time,
    and a Dask task (:mod:`labkit.grading.distributed`) calls this. `options` is the run's
    :class:`GradeOptions` (its seed drawn), `profiles_file` the refusals as JSON
    (:func:`labkit.grading.submission.refusals.wire`), `work` a folder for the process's files. Returns plain data:
    ``{"name", "result": the result file's data or None, "failure": why it could not be graded or None,
    "attempts", "peak": the grading process's peak memory in bytes or None}``; :func:`settled` makes a
    :class:`SubmissionGrade` of it under a rubric."""
    server, launcher = _kept(options)
    job = _Job(path, name, Path(work), options, profiles_file, server, launcher)
    while True:
        job.start()
        job.wait()
        if job.conclude():
            return job.message()


_KEPT: dict = {}  # (backend, limits, exercises, thread) -> (fork server, launcher) kept (a Dask worker's)
_KEPT_LOCK = threading.Lock()


def _kept(options):
    """The fork server and launcher this process keeps for :func:`grade_one` (a Dask worker grades one
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
            _stop_warm(server, launcher)
            server, launcher = _start_warm(backends.get_backend(options.backend), options)
            if key not in _KEPT:
                atexit.register(_stop_kept, key)
            _KEPT[key] = (server, launcher)
        return server, launcher


def _stop_kept(key):
    _stop_warm(*_KEPT.pop(key, (None, None)))


def settled(message, rubric, seed):
    """The :class:`SubmissionGrade` of :func:`grade_one`'s outcome, scored with `rubric`; a result that cannot be
    read (another labkit version's, say) makes a submission that could not be graded, saying why."""
    name = message["name"]
    if message.get("result") is not None:
        try:
            grade = SubmissionGrade.from_dict(message["result"], one_line(name, 80), rubric)
        except ValueError as exc:
            return SubmissionGrade(name, seed=seed, rubric=rubric, failure=f"its result could not be read ({exc})")
        grade.name = name
        return grade
    return SubmissionGrade(name, seed=seed, rubric=rubric, failure=str(message.get("failure")))


def grade(
    submissions,
    out_dir,
    jobs=2,
    cell_timeout=None,
    total_timeout=None,
    progress=True,
    seed=None,
    sandboxed=None,
    limits=None,
    rubric=None,
    options=None,
    times=None,
    times_from_mtime=False,
    shard=None,
    fresh=False,
    engine=None,
    *,
    names=None,
    ungradable=None,
    times_from_submission=False,
    exchange_times=None,
):
    """Grade submissions; write grades.csv, feedback/, results/, seed.txt and the run's record into `out_dir`.

    `options` (a :class:`labkit.grading.options.GradeOptions`, the defaults
    when None) bound the run, with the single keywords that are given in
    place of its own; `seed` fixes the random test data (a fresh one is
    drawn and written to ``seed.txt`` when it is None); the options'
    backend is the sandbox (``sandboxed=False``, the old switch, means
    ``backend="none"``: student code runs unconfined, after a warning on
    stderr). `rubric` (a :class:`Rubric`, or a TOML file; else the options'
    rubric; else the rubric recorded in `out_dir` by an earlier run, else the
    lab's) turns the checks' results into grades. `names` gives each
    submission its name (by default its folder's or notebook's), and
    `ungradable` ({name: why}) adds students who handed in nothing to grade:
    they are reported as "could not be graded", never given a zero.

    Each submission's time comes from `times` ({name: datetime}, the LMS's
    times in the instructor's ``--times`` file), else from `exchange_times`
    (read by labkit from nbgrader's exchange), else, only with
    `times_from_submission`, from the ``timestamp.txt`` in its folder, else,
    only with `times_from_mtime`, from its notebooks' modification time
    (:func:`labkit.grading.results.late.submission_time`); the last two are written
    by the student and marked "student-supplied" wherever they are shown.
    `progress` draws a bar with an ETA on a terminal.

    Each submission's result and feedback are written as soon as it is
    graded, and entered in ``record.json`` (:mod:`labkit.grading.results.record`).
    When `out_dir` already holds a run's record, only the submissions without
    a result there, or whose notebooks changed since, are graded, with that
    run's seed and rubric (:func:`resumed`); `fresh` deletes those results
    first. `shard`, ``(I, N)`` or ``"I/N"``, grades only the I-th of N parts
    of the class (:func:`shard`). `engine` grades the submissions elsewhere,
    in place of `jobs` grading processes here: a callable ``engine(todo,
    options, profiles_file, rubric, out, bar, peaks, arrived)`` returning
    ({name: SubmissionGrade}, what ``run.json`` records of it), such as
    :func:`labkit.grading.distributed.engine`'s for a Dask cluster. Returns
    the grades in the order given (a shard's in name order; the ungradable
    last), those of an earlier run included; those with ``graded`` False
    could not be graded (their ``failure`` says why).
    """
    submissions = [Path(s) for s in submissions]
    for path in submissions:
        if not os.path.lexists(path):
            raise ValueError(f"{path} does not exist.")
        if not path.is_symlink() and path.is_file() and path.suffix != ".ipynb":
            raise ValueError(f"{path} is not a notebook: give .ipynb files or folders of them.")
    names = [submission_name(p) for p in submissions] if names is None else [str(n) for n in names]
    if len(names) != len(submissions):
        raise ValueError(f"{len(names)} names for {len(submissions)} submissions; give one name per submission.")
    ungradable = dict(ungradable or {})
    every = names + list(ungradable)
    if len(set(every)) != len(every):
        raise ValueError("two submissions have the same name; their feedback files would collide.")
    if shard is not None:
        shard = parse_shard(shard)
        chosen = set(shard_of(every, every, shard)[1])
        by_name = dict(zip(names, submissions))
        names = sorted(name for name in names if name in chosen)
        submissions = [by_name[name] for name in names]
        ungradable = {name: why for name, why in sorted(ungradable.items()) if name in chosen}
    options = GradeOptions.build(
        options, cell_timeout=cell_timeout, total_timeout=total_timeout, limits=limits, seed=seed, sandboxed=sandboxed
    )
    if rubric is not None and not isinstance(rubric, Rubric):
        options = GradeOptions.build(options, rubric=rubric)
    if not isinstance(rubric, Rubric):
        rubric = None if options.rubric is None else load_rubric(options.rubric)
    backend = backends.get_backend(options.backend)
    try:
        backend.available()
    except SandboxUnavailable as exc:
        raise ValueError(f"cannot grade in a sandbox: {exc}") from None
    warning = backend.warning()
    if warning:
        sys.stderr.write(warning)
    from dataclasses import replace

    out = Path(out_dir)
    # read before any student code runs, as collected
    contents = {name: _content(path) for path, name in zip(submissions, names)}
    earlier = resumed(out, [*names, *ungradable], options.seed, rubric, fresh, contents)
    done, rubric = earlier.done, earlier.rubric
    seed = secrets.randbits(63) if earlier.seed is None else int(earlier.seed)
    options = replace(options, seed=seed)
    if options.exercises not in (None, rubric.registry.source):
        raise ValueError(
            f"the options grade the exercises {options.exercises!r} but the rubric grades {rubric.registry.source!r}: "
            'name the course\'s exercises in its rubric (exercises = "module:attribute") and leave the option out.'
        )
    options = replace(options, exercises=rubric.registry.source)  # the workers load the rubric's exercises
    if earlier.record is not None:  # the times an earlier run was given count again, unless given anew
        times = {**earlier.record.given_times("csv"), **(times or {})}
        exchange_times = {**earlier.record.given_times("exchange"), **(exchange_times or {})}
        times_from_submission = times_from_submission or earlier.record.flags.get("times from submission", False)
        times_from_mtime = times_from_mtime or earlier.record.flags.get("times from mtime", False)
        if options.solutions is None and earlier.record.known.get("solutions"):  # compared with them again
            options = replace(options, solutions=earlier.record.known["solutions"])
    known = known_sources(rubric.registry, options.solutions)  # computed (or read from its cache) once, here
    recorded = earlier.record.known.get("digest") if earlier.record is not None else None
    if recorded and earlier.done and recorded != known.digest:
        raise ValueError(
            f"{out} was graded against other known sources ({recorded}; now {known.digest}): the solutions given "
            "to --solutions, labkit or scipy changed since, so its held parts would be judged otherwise. Grade "
            "into a new --out, or again with --fresh."
        )
    handed_in = [
        submission_time(
            path,
            name,
            times,
            _notebooks(path) if times_from_mtime else None,
            times_from_mtime,
            from_submission=times_from_submission,
            exchange=exchange_times,
        )
        for path, name in zip(submissions, names)
    ]
    for folder in ("results", "feedback"):
        (out / folder).mkdir(parents=True, exist_ok=True)  # an empty shard's folder is a run's too
    record = earlier.record or records.new("grade", labkit_version(), seed, rubric)
    record.times = {
        source: {name: when.isoformat() for name, when in sorted((given or {}).items())}
        for source, given in (("csv", times), ("exchange", exchange_times))
        if given
    }
    record.flags = {"times from submission": bool(times_from_submission), "times from mtime": bool(times_from_mtime)}
    record.known = {"digest": known.digest, "solutions": options.solutions}
    records.write(out, record)
    if rubric.text is not None:  # the grading processes read the run's rubric from its record's copy
        options = replace(options, rubric=str((out / records.RUBRIC_COPY).resolve()))
    (out / "seed.txt").write_text(f"{seed}\n", encoding="utf-8")
    when = dict(zip(names, handed_in))
    when.update({name: submission_time(None, name, times, exchange=exchange_times) for name in ungradable})
    todo = [(path, name) for path, name in zip(submissions, names) if name not in done]

    dropped = []

    def arrived(grade):
        """Write a submission's result and feedback as soon as it is graded (a stopped run resumes from them)."""
        grade.time = when[grade.name]
        if grade.name in earlier.earlier and grade.graded:
            grade.marks, lost = carried_marks(earlier.earlier[grade.name], grade)
            if lost:
                dropped.append((grade.name, lost))
        records.note(out, record, grade.name, write_result(out, grade), contents.get(grade.name))

    work = Path(tempfile.mkdtemp(prefix="labkit-run-"))
    start, peaks, run = time.monotonic(), [], {"engine": "local", "jobs": int(jobs)}
    try:
        profiles_file = work / "profiles.json"
        profiles_file.write_text(json.dumps(refusals.wire(rubric.registry.refusals)), encoding="utf-8")
        if engine is None:
            with _warm(backend, options) as (server, launcher), Progress(len(todo), "grading", enabled=progress) as bar:
                run.update({"fork server": server is not None, "forked grading processes": launcher is not None})
                graded = _schedule(
                    [p for p, _ in todo], [n for _, n in todo], work, options, profiles_file, rubric,
                    max(1, int(jobs)), out, bar, peaks, arrived, server, launcher,
                )  # fmt: skip
                graded = {grade.name: grade for grade in graded.values()}
        else:
            with Progress(len(todo), "grading", enabled=progress) as bar:
                graded, run = engine(todo, options, profiles_file, rubric, out, bar, peaks, arrived)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for name, why in ungradable.items():
        graded[name] = SubmissionGrade(name, seed=seed, rubric=rubric, failure=why)
    ordered = [graded[name] if name in graded else done[name] for name in [*names, *ungradable]]
    for grade in ordered:
        grade.time = when[grade.name]
    write_report(out, ordered, record)
    for name, lost in dropped:
        sys.stderr.write(
            f"labkit grade: {one_line(name, 80)}'s notebooks changed; {lost} of the marks given to it no longer "
            "apply (an answer rewritten, a part no longer held): mark them again (labkit mark OUT).\n"
        )
    (out / "run.json").write_text(
        json.dumps(
            {
                "seed": seed,
                "submissions": len(ordered),
                "graded now": len(graded) - len(ungradable),
                "already graded": len(done),
                "graded again, changed": len(earlier.changed),
                "handed in nothing to grade": len(ungradable),
                "shard": None if shard is None else f"{shard[0]}/{shard[1]}",
                "not graded": sum(not g.graded for g in ordered),
                "seconds": round(time.monotonic() - start, 1),
                **run,
                "grader peak bytes": max((p for p in peaks if p), default=None),
                "grader process peak bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
            },
            indent=1,
        ),
        encoding="utf-8",
    )
    return Graded(ordered, earlier)


class Graded(list):
    """The grades of a run (:func:`grade`), with what it resumed (:attr:`earlier`, a :class:`Resumed`)."""

    def __init__(self, grades, earlier):
        super().__init__(grades)
        self.earlier = earlier


def _content(path):
    """The digest of a submission's notebooks (:func:`labkit.grading.results.record.content_digest`)."""
    path = Path(path)
    return records.content_digest(_notebooks(path), path if path.is_dir() else path.parent)


def _notebooks(path):
    """The submission's notebooks, or none when it has none to offer."""
    try:
        return submission_notebooks(path)
    except ValueError:
        return []


def _start_warm(backend, options):
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


def _stop_warm(server, launcher):
    for thing in (launcher, server):
        if thing is not None:
            thing.stop()


@contextlib.contextmanager
def _warm(backend, options):
    """The run's fork server and launcher (:func:`_start_warm`), stopped at the end."""
    server, launcher = _start_warm(backend, options)
    try:
        yield server, launcher
    finally:
        _stop_warm(server, launcher)


class _Launched:
    """The part of a Popen that :class:`_Job` uses, for a grading process the :class:`Launcher` forked."""

    def __init__(self, launcher, pid, key):
        self.launcher, self.pid, self.key = launcher, pid, key  # `key`: its request's id, never used twice

    @property
    def returncode(self):
        return self.launcher.ended.get(self.key)

    def poll(self):
        self.launcher.pump(0)
        return self.returncode

    def wait(self, timeout=None):
        until = None if timeout is None else time.monotonic() + timeout
        while self.returncode is None:
            if until is not None and time.monotonic() > until:
                raise subprocess.TimeoutExpired("grading process", timeout)
            if not self.launcher.pump(0.05) and self.launcher.process.poll() is not None:
                self.launcher.ended.setdefault(self.key, -signal.SIGKILL)  # the launcher is gone, and its children
        return self.returncode


class Launcher:
    """One warm process that forks each submission's grading process (:mod:`labkit.grading.launcher`)."""

    def __init__(self, options, server=None, wait=True):
        self.ended, self._buffer, self._lock = {}, b"", threading.RLock()
        environment = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
        parent = os.getpid()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "labkit.grading.launcher", options.exercises or ""],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
            env=environment,
            pass_fds=(server.fd,) if server is not None else (),
            preexec_fn=lambda: _die_with(parent),
        )
        if wait:
            self.wait_ready()

    def wait_ready(self):
        """Wait until the launcher has imported the grader; OSError (and the launcher stopped) when it does not."""
        if self._next(time.monotonic() + LAUNCHER_READY) != {"ready": True}:
            self.stop()
            raise OSError("the launcher of grading processes did not start")

    def _next(self, until):
        """The launcher's next message, or None when `until` passes or it is gone."""
        try:
            fd = self.process.stdout.fileno()
        except ValueError:  # stopped
            return None
        while b"\n" not in self._buffer:
            remaining = until - time.monotonic()
            if not select.select([fd], [], [], max(0.0, remaining))[0]:
                return None
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                return None
            self._buffer += chunk
        line, _, self._buffer = self._buffer.partition(b"\n")
        return json.loads(line)

    def pump(self, wait):
        """File every ended process the launcher reported (waiting up to `wait` s for one); whether any."""
        with self._lock:
            message = self._next(time.monotonic() + wait)
            found = False
            while message is not None:
                if "ended" in message:
                    self.ended[message.get("id")] = int(message["code"])
                    found = True
                message = self._next(time.monotonic())
            return found

    def launch(self, request):
        """Fork a grading process for `request`; a :class:`_Launched` (OSError when the launcher is gone)."""
        with self._lock:
            key = request["id"] = secrets.token_hex(8)
            try:
                self.process.stdin.write((json.dumps(request) + "\n").encode())
                self.process.stdin.flush()
            except ValueError:  # closed: stopped
                raise OSError("the launcher of grading processes was stopped") from None
            while True:
                message = self._next(time.monotonic() + LAUNCH_TIMEOUT)
                if message is None:
                    raise OSError("the launcher of grading processes stopped answering")
                if "ended" in message:
                    self.ended[message.get("id")] = int(message["code"])
                elif "started" in message and message.get("id") == key:
                    return _Launched(self, int(message["started"]), key)

    def stop(self):
        try:
            self.process.stdin.close()  # it stops every grading process still running, then ends
        except OSError:
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.process.stdout.close()


def _schedule(
    submissions, names, work, options, profiles_file, rubric, jobs, out, bar, peaks, arrived=None, server=None,
    launcher=None,
):  # fmt: skip
    """Run the grading processes, `jobs` at a time; {path: SubmissionGrade} for every submission, each handed
    to `arrived` as soon as it is graded. `server` and `launcher` are the run's (None: the plain way)."""
    pending = [
        _Job(path, name, work, options, profiles_file, server, launcher) for path, name in zip(submissions, names)
    ]
    pending.reverse()
    running, grades, stopped = [], {}, None
    while pending or running:
        while pending and len(running) < jobs and stopped is None:
            stopped = _low_space(out)
            if stopped is None:
                job = pending.pop()
                job.start()
                running.append(job)
        if stopped is not None and not running:
            for job in pending:
                grades[job.path] = SubmissionGrade(job.name, seed=options.seed, rubric=rubric, failure=stopped)
                if arrived is not None:
                    arrived(grades[job.path])
                bar.advance()
            pending = []
            break
        time.sleep(0.05)
        for job in list(running):
            if not job.poll():
                continue
            running.remove(job)
            peaks.append(job.peak)
            if not job.conclude():
                pending.append(job)  # once more, in a fresh process
                continue
            grades[job.path] = settled(job.message(), rubric, options.seed)
            if arrived is not None:
                arrived(grades[job.path])
            bar.advance()
    return grades


def report_failures(grades, stream=sys.stderr):
    """Name every submission that could not be graded (printable, one line each); how many there were."""
    failed = [g for g in grades if not g.graded]
    for g in failed:
        stream.write(f"could not grade {one_line(g.name, 80)}: {one_line(g.failure, 300)}\n")
    return len(failed)


@dataclass
class Resumed:
    """What an earlier run into the same output folder leaves to this one (:func:`resumed`).

    Attributes
    ----------
    done : dict
        {name: SubmissionGrade} kept: graded there, and its notebooks unchanged since.
    seed : int or None
        The seed to grade with (the earlier run's).
    rubric : Rubric
        The rubric to grade with (the earlier run's, when none was given).
    record : RunRecord or None
        The earlier run's record, which this run goes on writing.
    changed : list
        The submissions graded there whose notebooks changed since: graded again.
    refused : list
        (path, why) of result files in the folder that its record does not vouch for: never read.
    """

    done: dict
    seed: object
    rubric: Rubric
    record: object = None
    changed: list = field(default_factory=list)
    refused: list = field(default_factory=list)
    # {name: its earlier grade} of the changed submissions: the marks a person gave them carry over where they apply
    earlier: dict = field(default_factory=dict)


def resumed(out, names, seed, rubric=None, fresh=False, contents=None):
    """What the earlier run in `out` leaves to this one: a :class:`Resumed`.

    An output folder with a run record (:mod:`labkit.grading.results.record`) is resumed: the submissions graded
    there are kept, unless their notebooks' digest differs from the recorded one (`contents`, {name:
    digest}: they changed since, and are graded again), and the run grades the others with the earlier
    run's seed, which `seed` may repeat but not change, and under the earlier run's rubric, which `rubric`
    (a Rubric, or None for the recorded one) may repeat but not change. A submission that could not be
    graded is graded again (such failures are the grader's: a crash, a stopped run, a lost worker). A
    folder of another labkit version, a merge's folder, results without a record, a different rubric or
    seed, or a submission graded there that is not in `names` are refused with a ValueError saying what to
    do, as nothing of them would fit this run's grades.csv. `fresh` deletes the earlier results, feedback
    and record instead: every submission is graded, with `seed` (a fresh one when None)."""
    out = Path(out)
    files = sorted((out / "results").glob("*.json")) if (out / "results").is_dir() else []
    if fresh:
        for path in [*files, *sorted((out / "feedback").glob("*.txt"))]:
            path.unlink()
        for name in (records.RECORD, records.RUBRIC_COPY):
            (out / name).unlink(missing_ok=True)
        return Resumed({}, seed, rubric if rubric is not None else default_rubric())
    if not (out / records.RECORD).exists():
        if files:
            raise ValueError(
                f"{out} holds results but no run record ({records.RECORD}; an older labkit wrote none): give "
                "--fresh to grade every submission again there, or choose a new --out."
            )
        return Resumed({}, seed, rubric if rubric is not None else default_rubric())
    how = "give --fresh to grade every submission again, or choose a new --out"
    record = records.read(out)
    if record.kind != "grade":
        raise ValueError(
            f"{out} holds a merge ({records.RECORD} says so), which is not resumed: grade into a new --out, or {how}."
        )
    if record.labkit != labkit_version():
        raise ValueError(
            f"{out} was graded by labkit {one_line(record.labkit, 40)}, and this is labkit {labkit_version()}: "
            f"{how} with this version."
        )
    recorded = record.rubric_object(out)
    if rubric is None:
        rubric = recorded
    elif not recorded.same_as(rubric):
        raise ValueError(
            f"{out} was graded under the rubric recorded there ({recorded.title!r}), and {rubric.source} differs "
            f"from it in {' and '.join(recorded.differences(rubric))}: leave --rubric out to resume that run. "
            f"To grade under {rubric.source}, {how}; to apply only another [late] or [held] table to these results, "
            f"`labkit grade --merge {out} --rubric {_file_of(rubric)} --out NEW`."
        )
    if seed is not None and record.seed is not None and int(seed) != int(record.seed):
        raise ValueError(
            f"{out} holds results of a run with seed {record.seed}, not --seed {seed}: leave --seed out to resume "
            f"it, {how}."
        )
    stray = sorted(set(record.submissions) - set(names))
    if stray:
        raise ValueError(
            f"{out} holds the result of {one_line(stray[0], 80)!r}, which is not among the submissions of this "
            "run: give the submissions (and --shard) of the run that wrote it to resume it, give --fresh to grade "
            "only these, or choose a new --out."
        )
    found, refused = records.results(out, record)
    done, changed, before = {}, [], {}
    for name, (path, data) in found.items():
        grade = SubmissionGrade.from_dict(data, str(path), rubric)  # ValueError: another labkit version's
        if not grade.graded:
            continue
        if contents is not None and record.submissions[name].get("content") != contents.get(name):
            changed.append(name)
            before[name] = grade
            continue
        done[name] = grade
    seed = record.seed if record.seed is not None else seed
    return Resumed(done, seed, rubric, record, sorted(changed), refused, earlier=before)


def carried_marks(earlier, grade):
    """The marks of `earlier` (a submission's grade before its notebooks changed) that still apply to its new
    `grade`: an answer's while its text is the same, a held part's while it is still held, an exercise's
    excuse always; and how many no longer apply."""
    kept, dropped = {}, 0
    held = {f"exercise{number}/{part}" for number, part, _, _ in grade.held()}
    for item, mark in earlier.marks.items():
        if item in grade.rubric.registry.answers:
            same = str(earlier.answers.get(item, "")) == str(grade.answers.get(item, ""))
        else:
            same = "/" not in item or item in held
        if same:
            kept[item] = mark
        else:
            dropped += 1
    return kept, dropped


def _file_of(rubric):
    """The TOML file a rubric was read from, for a command to show (the lab's own when it names none)."""
    source = Path(str(rubric.source))
    return source if source.suffix == ".toml" else DEFAULT_RUBRIC


def parse_shard(spec):
    """``(I, N)`` from ``"I/N"`` (or a pair): the I-th of N parts, counted from 1; ValueError says how to write it.

    >>> parse_shard("3/50")
    (3, 50)
    """
    how = "give --shard I/N with 1 <= I <= N, e.g. 3/50 for the third of 50 parts (a Slurm array: --array=1-50)"
    try:
        index, count = spec.split("/") if isinstance(spec, str) else spec
        index, count = int(index), int(count)
    except (TypeError, ValueError):
        raise ValueError(f"{how}; got {one_line(spec, 40)!r}.") from None
    if not 1 <= index <= count:
        raise ValueError(f"{how}; got {index}/{count}.")
    return index, count


def shard(names, index, count):
    """The `index`-th (from 1) of `count` parts of `names`, in name order: every name is in exactly one part,
    the parts' sizes differ by at most one, and with more parts than names some parts are empty.

    >>> [shard(["d", "a", "c", "b", "e"], i, 2) for i in (1, 2)]
    [['a', 'b'], ['c', 'd', 'e']]
    >>> shard(["a"], 2, 3)
    []
    """
    index, count = parse_shard((index, count))
    ordered = sorted(names)
    return ordered[(index - 1) * len(ordered) // count : index * len(ordered) // count]


def shard_of(submissions, names, part):
    """The submissions (and their names) of `part`, ``(I, N)``, in name order (:func:`shard`)."""
    by_name = dict(zip(names, submissions))
    chosen = shard(names, *part)
    return [by_name[name] for name in chosen], chosen
