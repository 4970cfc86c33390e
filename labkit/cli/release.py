"""``labkit release DIR --out DIR``: write the student version of the instructor notebooks."""

import sys

from . import options
from .common import course, roster_and_variants


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "release",
        help="write the student version of the notebooks",
        description="Replace every '### BEGIN SOLUTION' ... '### END SOLUTION' region by a stub "
        "that raises NotImplementedError, remove hidden tests, clear outputs.",
    )
    options.instructor_notebooks(parser)
    options.out(parser, "folder for the student notebooks")
    options.roster(
        parser,
        f"{options.ROSTER} (as for labkit export): one folder per student, with --variants",
    )
    options.variants(
        parser, f"{options.VARIANTS} (labkit variants --new): each student's notebooks hold their own data"
    )
    options.rubric(parser, options.COURSE_RUBRIC)
    parser.set_defaults(handler=handle)


def handle(args):
    """Write the release (one folder per student with a roster and variants)."""
    from ..grading.authoring.release import release

    roster, variants = roster_and_variants(args, "for a release per student")
    registry = course(args)
    written = release(args.notebooks, args.out, roster, variants, registry)
    if roster is None:
        for path in written:
            print(f"wrote {path}")
        return 0
    print(f"wrote {len(written)} notebooks for {len(roster)} students into {args.out}, one folder each")
    _ties(variants, registry, roster)
    return 0


def _ties(variants, registry, roster):
    """Name, on stderr, the roster's students who drew the same data of an exercise."""
    from ..exercises.variants import ties
    from ..grading.store.report import one_line

    ids = {key: name for name, key in roster.items()}
    for number, tied in ties(variants, registry, roster.values()):
        names = ", ".join(one_line(ids[key], 40) for key in tied)
        print(
            f"labkit: {names} drew the same data of exercise {number}: a copy between them cannot be seen; give "
            f"all but one a fresh draw (labkit variants --redraw ID --exercise {number}) and release again",
            file=sys.stderr,
        )
