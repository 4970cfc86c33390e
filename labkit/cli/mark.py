"""``labkit mark OUT``: a page to mark answers in words and held parts by keyboard; ``--import`` its marks."""

from pathlib import Path

from . import options


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "mark",
        help="write OUT/marking.html to mark answers in words and held parts by keyboard; --import its marks.csv",
        description="--import marks.csv (submission,item,points,comment) puts the marks into the run in OUT: "
        "grades.csv, the feedback, the results that `labkit report` and `labkit export` read. Every row is "
        "checked first; one bad row and nothing changes. A later mark of an item replaces the earlier one.",
    )
    options.run_folder(parser)
    parser.add_argument("--import", dest="import_", type=Path, metavar="MARKS.csv", help="the marks to import")
    options.rubric(parser)
    parser.add_argument(
        "--marker",
        default="instructor",
        help="whose marking order: each marker's page shuffles the students of each item in its own order",
    )
    options.quiet(parser, "print nothing when all goes well")
    parser.set_defaults(handler=handle)


def handle(args):
    """Write the marking page, or import the marks it gave."""
    from ..grading.reports import marking
    from ..grading.store.marks import import_marks
    from ..grading.store.rubric import load

    rubric = None if args.rubric is None else load(args.rubric)
    if args.import_ is None:
        path = marking.write_page(args.out, args.marker, rubric)
        if not args.quiet:
            print(
                f"wrote {path} (open it in a browser; it needs no network; marks stay in that browser until "
                "you download marks.csv and import it with --import)"
            )
        return 0
    changed = import_marks(args.out, args.import_, rubric)
    if not args.quiet:
        print(f"{changed} mark(s) changed in {args.out} (grades.csv, feedback/, results/ and record.json)")
    return 0
