"""``labkit report OUT``: write OUT/report.html, the class at a glance, from a grading run."""

import time

from ..errors import InputError
from ..grading.reports import similarity
from . import options
from .common import refused


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "report",
        help="write OUT/report.html: totals, pass rates, slips, problems and similar code of a grading run",
        description="Read the results/ of a `labkit grade` run (or of `labkit merge`) in OUT and write "
        "OUT/report.html, one self-contained page: the distribution of totals, each exercise's and part's "
        "pass rate, the slips the checks named with who made them, the problems (time limits, crashes, "
        "errors, refused references), the students with the most failed parts, and similar code side by "
        "side. Nothing else in OUT is changed.",
    )
    options.run_folder(parser)
    options.rubric(parser)
    parser.add_argument(
        "--similarity-threshold",
        type=float,
        default=similarity.DEFAULT_THRESHOLD,
        metavar="X",
        help="show pairs of similar code from this similarity (0 to 1) up (default %(default)s); "
        "similarity never changes a grade",
    )
    options.quiet(parser, "print nothing when all goes well")
    parser.set_defaults(handler=handle)


def handle(args):
    """Write the report; 1 when a result file was not read."""
    from ..grading.progress import Progress
    from ..grading.reports import class_report

    start = time.perf_counter()
    threshold = args.similarity_threshold
    if not 0.0 < threshold <= 1.0:
        raise InputError(f"--similarity-threshold is a similarity above 0 and at most 1; got {threshold}.")
    grades = class_report.read(args.out, args.rubric)  # the run's recorded rubric; a different one is refused
    refused(grades, "labkit report")
    functions = {function for grade in grades for function in grade.sources}
    with Progress(len(functions), "comparing code", enabled=not args.quiet) as bar:
        pairs = similarity.similar_pairs(grades, threshold, progress=bar)
    path = class_report.write(args.out, grades, pairs, threshold=threshold)
    if not args.quiet:
        similar = "similar code not computed" if pairs is None else f"{len(pairs)} similar pair(s)"
        print(
            f"wrote {path}: {len(grades)} submission(s), {similar}, in {time.perf_counter() - start:.1f} s "
            "(open it in a browser; it needs no network)"
        )
    return 1 if grades.refused else 0
