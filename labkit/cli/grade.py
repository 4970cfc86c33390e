"""``labkit grade SUBMISSION... --out DIR``: grade submitted notebooks (or folders of them) in a sandbox.

The arguments become a :class:`~labkit.grading.options.GradeOptions`, an engine and the chosen submissions;
:func:`labkit.grading.grade` does the grading, and :mod:`labkit.grading.reports.notes` says what the
instructor should know about the run.
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

from ..errors import InputError
from ..grading.options import DEFAULTS, MIB
from ..grading.sandbox import backends
from . import options
from .common import refused, roster_and_variants, summary, warn
from .submissions import chosen


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "grade",
        help="grade submitted notebooks",
        description="Run each submission (a notebook, or a folder with a student's notebooks) in a sandbox, "
        "check every exercise from outside it, and write grades.csv, feedback/<submission>.txt, "
        "results/<submission>.json and seed.txt. `labkit merge` combines earlier runs' results.",
        epilog="Each submission's result is written as soon as it is graded. Resuming is automatic: when --out "
        "already holds results of an earlier run (same rubric and labkit version), only the submissions without "
        "one are graded, with that run's seed from seed.txt (a different --seed is refused), and a submission that "
        "could not be graded is graded again; grades.csv then covers them all. --fresh starts over instead.",
    )
    parser.add_argument(
        "submissions",
        nargs="*",
        type=Path,
        help="the class as the LMS gives it (one folder or zip: a folder per student, nbgrader's submitted/, "
        "Canvas's or Moodle's download), or the submissions one by one (notebooks or folders of notebooks); put "
        "`--` before them when a name could start with '-'",
    )
    options.out(parser, "folder for grades.csv, feedback/ and results/")
    parser.add_argument("--merge", nargs="*", help=argparse.SUPPRESS)  # now `labkit merge`: refused, saying so
    _where_options(parser)
    _limit_options(parser)
    _class_options(parser)
    _time_options(parser)
    _variant_options(parser)
    parser.set_defaults(handler=handle)


def _where_options(parser):
    """Where and how much at once: --jobs, --shard, --fresh, --dask, --dask-workers."""
    parser.add_argument(
        "--jobs", type=int, default=2, help="submissions graded at once on this machine (default 2; not with --dask)"
    )
    parser.add_argument(
        "--shard",
        metavar="I/N",
        help="grade only the I-th of N equal parts of the submissions (in name order, I from 1): one task of a "
        "batch array each (give every part the same --seed), then `labkit merge` the parts",
    )
    parser.add_argument(
        "--fresh",
        action="store_true",
        help="delete the results and feedback already in --out and grade every submission (by default a run "
        "into a folder with results resumes it)",
    )
    parser.add_argument(
        "--dask",
        metavar="ADDRESS",
        help="grade on a Dask cluster, one task per submission: the scheduler's address (tcp://host:8786), or "
        "'local' for a LocalCluster here; workers need the submissions at the same path (a shared file system), "
        "labkit of this version and the sandbox (pip install 'labkit[dask]')",
    )
    parser.add_argument(
        "--dask-workers",
        type=int,
        metavar="N",
        help="worker processes of --dask local, one submission each at a time (default 2)",
    )


def _limit_options(parser):
    """The limits of each submission, the seed and the sandbox (their defaults are labkit.grading.options')."""
    for flag, default, text in (
        ("--cell-timeout", DEFAULTS.cell_timeout, "seconds per cell, and per call of a graded function"),
        ("--total-timeout", DEFAULTS.total_timeout, "seconds per submission in all, every notebook of it together"),
        (
            "--memory",
            DEFAULTS.limits.memory // MIB,
            "MiB of memory for a notebook's sandbox, and of address space per process",
        ),
        ("--grader-memory", DEFAULTS.grader_memory // MIB, "MiB of memory for the grader's own work on one submission"),
    ):
        parser.add_argument(flag, type=int, default=default, help=f"{text} (default %(default)s)")
    parser.add_argument(
        "--seed",
        type=int,
        default=DEFAULTS.seed,
        help="seed of the random test data (default: a fresh one, saved in seed.txt)",
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--sandbox",
        choices=backends.names(),
        default=DEFAULTS.backend,
        metavar="NAME",
        help="where student code runs: "
        + "; ".join(
            f"{name}{' (the default)' if name == DEFAULTS.backend else ''}: {backends.backend_class(name).summary}"
            for name in backends.names()
        ),
    )
    where.add_argument(
        "--no-sandbox",
        dest="sandbox",
        action="store_const",
        const=backends.UNCONFINED,
        help=f"the old name of --sandbox {backends.UNCONFINED}: student code runs UNCONFINED, with "
        "your permissions (only for code you trust, or where each submission is already "
        "isolated)",
    )


def _class_options(parser):
    """The rubric, and which of the class to grade: --student, --assignment."""
    options.rubric(
        parser,
        "TOML rubric: points, required exercises, branches, extra credit, a deadline ([late]) "
        "(default: the one recorded in --out by an earlier run, else the lab's; `labkit rubric` prints it)",
    )
    parser.add_argument(
        "--student",
        action="append",
        metavar="NAME",
        help="grade only this student of the class folder (its name in grades.csv; repeat for more): a regrade, "
        "merged over the class's run with `labkit merge`",
    )
    parser.add_argument(
        "--assignment",
        metavar="NAME",
        help="the assignment to grade in an nbgrader class folder (submitted/STUDENT/NAME/) holding several, and "
        "in the exchange of --times-from-exchange",
    )


def _time_options(parser):
    """Where the submission times come from: --times and the --times-from-* sources."""
    options.times(
        parser,
        ", as the LMS exports them: a CSV with the columns submission and time (ISO 8601 with a UTC offset); "
        "trusted, and it comes before every other source",
    )
    parser.add_argument(
        "--times-from-exchange",
        type=Path,
        metavar="COURSE",
        help="read the submission times from nbgrader's exchange itself (COURSE: the course's folder there, which "
        "holds inbound/; with --assignment): each student's newest submission",
    )
    parser.add_argument(
        "--times-from-submission",
        action="store_true",
        help="a submission with no other time gets the time in the timestamp.txt inside it (never without this "
        "option: the student's own process writes that file; marked student-supplied)",
    )
    parser.add_argument(
        "--times-from-mtime",
        action="store_true",
        help="a submission with no other time gets its notebooks' newest modification time (never without "
        "this option: copying or unpacking a file changes it, and the student sets it; marked student-supplied)",
    )


def _variant_options(parser):
    """Known code, each student's own data, the fork server and the progress bar."""
    parser.add_argument(
        "--solutions",
        type=Path,
        metavar="DIR",
        help="the instructor notebooks (the course repository's notebooks/): a graded part whose code is mostly "
        "theirs, names aside, is held for you like one that is labkit's or scipy's own (see "
        "docs/grading-security.md); recorded, and used again when the run resumes",
    )
    options.roster(parser, f"{options.ROSTER}: with --variants, each student is graded against their own data")
    options.variants(
        parser, f"{options.VARIANTS} (labkit variants --new), as given to labkit release; recorded by its digest"
    )
    parser.add_argument(
        "--no-fork-server",
        action="store_true",
        help="start every notebook's sandbox with a fresh Python that imports everything again (slower; the way "
        "before the fork server, which forks each notebook's isolated worker from one warm process per run)",
    )
    options.quiet(parser)


def grade_options(args):
    """The :class:`~labkit.grading.options.GradeOptions` of `labkit grade`'s arguments; ValueError for a bad one."""
    from ..grading.options import CPU_GRACE, GradeOptions
    from ..grading.sandbox.backends.base import Limits

    for name in ("jobs", "cell_timeout", "total_timeout", "memory", "grader_memory"):
        if getattr(args, name) < 1:
            raise InputError(f"--{name.replace('_', '-')} must be at least 1; got {getattr(args, name)}.")
    return GradeOptions(
        cell_timeout=args.cell_timeout,
        total_timeout=args.total_timeout,
        seed=args.seed,
        backend=args.sandbox,
        rubric=args.rubric,
        grader_memory=args.grader_memory * MIB,
        limits=Limits(memory=args.memory * MIB, cpu_seconds=args.total_timeout + CPU_GRACE),
        fork_server=not args.no_fork_server,
        solutions=args.solutions,
        jobs=args.jobs,
        shard=args.shard,
        fresh=args.fresh,
        times_from_submission=args.times_from_submission,
        times_from_mtime=args.times_from_mtime,
    )


def _engine(args):
    """The engine of `labkit grade`'s arguments (labkit.grading.run.engines): ``--dask``'s, else ``--jobs``
    grading processes here."""
    if args.dask is None:
        from ..grading.run.engines import LocalEngine

        return LocalEngine(args.jobs)
    from ..grading.run.dask import DaskEngine

    return DaskEngine(args.dask, 2 if args.dask_workers is None else args.dask_workers)


def _refuse_misuse(args):
    """Refuse ``--merge``: merging is `labkit merge` now."""
    if args.merge is not None:
        raise InputError(
            "`labkit grade --merge` is now a command of its own: labkit merge DIR... --out DIR [--rubric R] "
            "[--times T]."
        )


def _exchange_times(args):
    """The times read from nbgrader's exchange (``--times-from-exchange``), else None."""
    if args.times_from_exchange is None:
        return None
    if not args.assignment:
        raise InputError("--times-from-exchange needs --assignment NAME: the assignment's name in nbgrader.")
    from ..grading.run.times import read_exchange

    return read_exchange(args.times_from_exchange, args.assignment)


def _check_out(args):
    """Refuse an --out inside a submission folder, where it would read as part of the submission."""
    for given in args.submissions:
        if given.is_dir() and args.out.resolve().is_relative_to(given.resolve()):
            raise InputError(
                f"--out {args.out} is inside {given}, where it would read as part of a submission: give an --out "
                "outside it."
            )


def handle(args):
    """Grade the submissions into --out and print each total and what the instructor should know; 1 when a
    submission could not be graded or a time could not be read."""
    from ..grading import Submissions, grade
    from ..grading.run.times import read_times

    _refuse_misuse(args)
    start = time.perf_counter()
    times = read_times(args.times) if args.times else None
    if not args.submissions:
        raise InputError(
            "give the submissions: the class folder (or zip) the LMS gave you, or each submission (notebooks or "
            "folders); `labkit merge DIR...` combines runs."
        )
    if args.dask_workers is not None and args.dask != "local":
        raise InputError("--dask-workers is the size of --dask local; a cluster's workers are started on its machines.")
    options = grade_options(args)
    engine = _engine(args)
    roster, variants = roster_and_variants(args, "to grade each student against their own data")
    if args.shard is not None:
        from ..grading.run.resume import parse_shard

        parse_shard(args.shard)  # a bad one is refused before anything is read
    exchange = _exchange_times(args)
    _check_out(args)
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=".labkit-unpacked-", dir=args.out) as workspace:
        found = chosen(args, Path(workspace))
        given = Submissions(found.paths, found.names, found.ungradable, times, exchange, roster, variants)
        grades = grade(given, args.out, options, engine=engine, progress=not args.quiet)
    if found.intake is not None:
        from ..grading.lms.delivery import remember

        remember(args.out, found.intake)
    return _told(args, grades, found, times, start, variants)


def _told(args, grades, found, times, start, variants):
    """Print what the run did and what the instructor should know; the command's exit status."""
    from ..grading.reports import notes
    from ..grading.run.classrun import report_failures

    summary(grades, args.out, start, "listed")
    for line in notes.resumed_notes(args.out):
        print(line)
    refused(grades.earlier, "the resumed run")
    print(f"random test data from seed {(args.out / 'seed.txt').read_text().strip()} (repeat the run with --seed)")
    warn(f"labkit grade: {line}" for line in found.notes)
    if variants is not None:
        print(
            f"each student graded against their own data; {notes.holding_another_variant(grades)} submission(s) "
            f"hold another's: see {args.out / 'variants.csv'}"
        )
    warn(notes.late_mark_notes(grades, found.marked_late))
    lines, unreadable = notes.time_notes(grades, grades.earlier.rubric, times)
    warn(lines)
    failed = report_failures(grades)
    if unreadable and not failed:
        return 1
    if failed:
        print(
            f"labkit grade: {failed} submission(s) could not be graded (see above and their feedback); "
            "every other submission is in grades.csv.",
            file=sys.stderr,
        )
        return 1
    return 0
