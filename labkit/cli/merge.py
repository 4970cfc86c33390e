"""``labkit merge DIR... --out DIR``: combine the results of several grading runs."""

import time
from pathlib import Path

from ..errors import InputError
from . import options
from .common import refused, summary, warn


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "merge",
        help="combine the results of several grading runs",
        description="Combine the results/ of earlier `labkit grade` --out folders (the shards of a class, a "
        "regrade after the class's run) into one grades.csv, feedback/ and results/ in --out; a later folder's "
        "result replaces an earlier one's for the same submission (a regrade goes last). Only results each "
        "folder's run record vouches for are read.",
    )
    parser.add_argument("folders", nargs="+", type=Path, metavar="DIR", help="the --out folders of earlier runs")
    options.out(parser, "folder for the merged grades.csv, feedback/ and results/")
    options.rubric(
        parser,
        "TOML rubric to score the results with (default: the one the runs recorded); it may differ from "
        "theirs only in its [late] and [held] tables",
    )
    options.times(
        parser,
        " (submission,time; ISO 8601 with a UTC offset), in place of those the results were graded with",
    )
    options.quiet(parser)
    # grading's, refused with a message saying so
    options.hidden(parser, "--shard", "--dask")
    options.hidden(parser, "--fresh", "--times-from-mtime", "--times-from-submission", action="store_true")
    options.hidden(parser, "--times-from-exchange", type=Path)
    parser.set_defaults(handler=handle)


def _refuse_grading_options(args):
    """Refuse the options of `labkit grade` that read or grade submissions."""
    given = [flag for flag, value in (("--shard", args.shard), ("--dask", args.dask), ("--fresh", args.fresh)) if value]
    if given:
        raise InputError(f"{', '.join(given)} grade(s) submissions, which `labkit merge` does not; merge without them.")
    for flag in ("times_from_mtime", "times_from_submission", "times_from_exchange"):
        if getattr(args, flag):
            raise InputError(
                f"--{flag.replace('_', '-')} reads the submissions' files or the exchange, which `labkit merge` does "
                "not: give the times in --times TIMES.csv (the results keep the times they were graded with)."
            )


def handle(args):
    """Merge the runs into --out and print the totals, the replaced results and the notes on times."""
    from ..grading import merge
    from ..grading.reports.notes import time_notes
    from ..grading.run.classrun import report_failures
    from ..grading.run.times import read_times

    start = time.perf_counter()
    _refuse_grading_options(args)
    times = read_times(args.times) if args.times else None
    grades = merge(args.folders, args.out, args.rubric, times=times, progress=not args.quiet)
    summary(grades, args.out, start, "merged")
    _replaced(grades.replaced)
    refused(grades, "the merge")
    lines, unreadable = time_notes(grades, grades.rubric, times)
    warn(lines)
    return 1 if report_failures(grades) or unreadable or grades.refused else 0


def _replaced(replaced):
    """Say which results a later folder's replaced in a merge."""
    from ..grading.store.report import one_line

    if not replaced:
        return
    print(f"{len(replaced)} result(s) replaced by a later folder's (the later one counts; see merge.json):")
    for r in replaced:
        kept = "; its submission time kept from the earlier result" if r.time_kept else ""
        print(f"  {one_line(r.name, 60)}: {one_line(r.earlier, 200)} -> {one_line(r.later, 200)}{kept}")
