"""``labkit export DIR --canvas FILE ...``: the totals into the course's Canvas gradebook (or ``--moodle``)."""

import sys
from pathlib import Path

from ..errors import InputError
from . import options
from .common import refused


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "export",
        help="put the grades into the course's Canvas gradebook or a Moodle grade import file",
        description="Write each student's total under the rubric for the LMS to import: into the Canvas gradebook "
        "export GRADEBOOK.csv (one assignment column filled in or added, everything else kept), or a CSV for "
        "Moodle's 'Import grades from CSV'. A roster joins submissions to the LMS's students. Submissions that "
        "could not be graded, and students who do not match, are listed and get nothing (never a zero). Exit "
        "status: 0 when every submission and roster entry matched, 1 when the file was written with students "
        "listed, 2 for bad input (then nothing is written).",
    )
    options.run_folder(parser, "the --out folder of `labkit grade` (or of `labkit merge`)", dest="results")
    lms_choice = parser.add_mutually_exclusive_group(required=True)
    lms_choice.add_argument(
        "--canvas",
        type=Path,
        metavar="GRADEBOOK.csv",
        help="the course's gradebook as Canvas exports it (Grades > Export); it is read, never changed",
    )
    lms_choice.add_argument("--moodle", action="store_true", help="write a CSV for Moodle's 'Import grades from CSV'")
    lms_choice.add_argument(
        "--lms",
        metavar="NAME",
        help="write the grade import of another LMS: the name of its module added to labkit/grading/lms/",
    )
    options.roster(
        parser,
        "CSV with the columns submission (the names in grades.csv) and id (the student's id in the LMS)",
        required=True,
        metavar="ROSTER.csv",
    )
    _lms_options(parser)
    options.out(
        parser,
        "the file to write (default: OUT-canvas.csv or OUT-moodle.csv next to OUT); a summary CSV "
        "(FILE-summary.csv) goes beside it",
        required=False,
        metavar="FILE",
    )
    options.force(parser, "replace FILE and its summary if they exist (never an input file)")
    options.rubric(parser)
    parser.set_defaults(handler=handle)


def _lms_options(parser):
    """--key, --column, --new-column and --feedback: how the LMS's file is filled."""
    parser.add_argument(
        "--key",
        help="what the roster's ids are: for Canvas the gradebook column 'ID' (the default), 'SIS User ID' or "
        "'SIS Login ID'; for Moodle 'idnumber' (the default) or 'email'",
    )
    parser.add_argument(
        "--column",
        default="labkit",
        metavar="NAME",
        help="the assignment: Canvas's column of that title is filled (one the gradebook lacks is refused, "
        "unless --new-column); Moodle's grade item column (default %(default)s)",
    )
    parser.add_argument(
        "--new-column",
        action="store_true",
        help="Canvas: add --column as a new assignment column, worth the rubric's full credit (refused if the "
        "gradebook has that column already); without it a --column the gradebook lacks is refused, so a typo "
        "never creates an assignment",
    )
    parser.add_argument("--feedback", action="store_true", help="Moodle: add a Feedback column (the points in words)")


def handle(args):
    """Write the LMS's file and its summary; 1 when a submission or roster entry did not match."""
    from ..grading.store.record import rubric_for
    from ..grading.store.report import read_results

    if args.canvas is not None and args.feedback:
        raise InputError("--feedback is for --moodle; a Canvas gradebook has no feedback column to import.")
    if args.canvas is None and args.new_column:
        raise InputError("--new-column is for --canvas; Moodle's import maps a column to a new grade item itself.")
    # the run's recorded rubric (late rule included): what is exported is grades.csv's total
    grades = read_results([args.results], rubric_for([args.results], args.rubric, "labkit export"))
    refused(grades, "labkit export")
    if args.lms is not None:
        export = _to_other(args, grades)
    else:
        export = _to_canvas(args, grades) if args.canvas is not None else _to_moodle(args, grades)
    for line in export.problems():
        print(f"labkit export: {line}", file=sys.stderr)
    print(export.summary())
    return 1 if export.listed or grades.refused else 0


def _to_canvas(args, grades):
    from ..grading.lms import canvas, exports

    return canvas.to_canvas(
        grades,
        args.canvas,
        args.roster,
        args.out or exports.default_file(args.results, "canvas"),
        column=args.column,
        key=args.key or "ID",
        new_column=args.new_column,
        force=args.force,
    )


def _to_moodle(args, grades):
    from ..grading.lms import exports, moodle

    return moodle.to_moodle(
        grades,
        args.roster,
        args.out or exports.default_file(args.results, "moodle"),
        key=args.key or "idnumber",
        column=args.column,
        feedback=args.feedback,
        force=args.force,
    )


def _to_other(args, grades):
    from ..grading.lms import exports, named

    out = args.out or exports.default_file(args.results, args.lms)
    return named(args.lms).export(grades, args.roster, out, force=args.force)
