"""``labkit variants --new FILE``: a course's variants file, every student their own data; redraw a student,
show or check the draws."""

from pathlib import Path

from ..errors import InputError
from . import options
from .common import course


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "variants",
        help="every student their own data: make the variants file, redraw a student, show or check the draws",
        description="A variants file holds the course's secret; each student's data (the limaçon's r0, ...) is "
        "derived from it and the student's roster id, for `labkit release --roster --variants` and `labkit grade "
        "--roster --variants`. Keep it private.",
    )
    action = parser.add_mutually_exclusive_group(required=True)
    action.add_argument("--new", type=Path, metavar="FILE", help="write a new variants file with a random secret")
    action.add_argument(
        "--redraw", metavar="ID", help="give the student with this roster id a fresh draw of --exercise"
    )
    action.add_argument("--show", action="store_true", help="print each roster student's data (needs --roster)")
    action.add_argument(
        "--check",
        type=int,
        metavar="N",
        help="check N made-up students' draws (and the --roster's): the solutions earn full marks, the catalog's "
        "slips are caught and named, a copy is caught; exits 1 naming every draw that is not",
    )
    options.variants(parser)
    parser.add_argument("--exercise", type=int, help="the exercise to redraw (with --redraw)")
    options.roster(parser)
    parser.add_argument(
        "--solutions", type=Path, default=Path("notebooks"), help="the instructor notebooks (default %(default)s)"
    )
    parser.add_argument(
        "--catalog", type=Path, help="a Python file of CORRECT variations and MISTAKES (slips) to check"
    )
    options.rubric(parser, options.COURSE_RUBRIC)
    parser.set_defaults(handler=handle)


def handle(args):
    """Make a variants file, or redraw, show or check the draws of the one given."""
    from ..exercises import variants
    from ..grading.lms.roster import read_roster

    registry = course(args)
    if args.new is not None:
        variants.new(args.new)
        print(f"wrote {args.new}: keep it private; give it to `labkit release` and `labkit grade` as --variants")
        return 0
    if args.variants is None:
        raise InputError("give the course's variants file: --variants SECRET_FILE (make one with --new FILE).")
    found = variants.read(args.variants)
    roster = read_roster(args.roster) if args.roster is not None else None
    if args.redraw is not None:
        return _redraw(args, roster, registry)
    if args.show:
        return _show(found, roster, registry)
    return _check(args, found, roster, registry)


def _redraw(args, roster, registry):
    """Give the student ``--redraw`` a fresh draw of ``--exercise`` and print it."""
    from ..exercises import variants
    from ..grading.store.report import one_line

    if args.exercise is None or roster is None:
        raise InputError(
            "--redraw needs --exercise N (the exercise whose data the student gets afresh) and --roster (the "
            "roster the id is in)."
        )
    key = args.redraw.strip()
    if key not in roster.values():
        raise InputError(f"{one_line(key, 60)} is no id of the roster {args.roster}: give an id as it has it.")
    number = variants.redraw(args.variants, key, args.exercise, registry)
    values = variants.read(args.variants).values(registry, key)[args.exercise]
    print(f"{one_line(key, 60)} now has draw {number} of exercise {args.exercise}: {values}")
    return 0


def _show(found, roster, registry):
    """Print each roster student's data."""
    from ..grading.store.report import one_line

    if roster is None:
        raise InputError("--show needs --roster: the students whose data to print.")
    for name, key in roster.items():
        values = found.values(registry, key)
        shown = "; ".join(
            f"exercise {n}: " + ", ".join(f"{p} = {v}" for p, v in given.items()) for n, given in values.items()
        )
        print(f"{one_line(name, 40)} ({one_line(key, 30)}): {shown}")
    return 0


def _check(args, found, roster, registry):
    """Check the draws of ``--check`` made-up students and the roster's; 1 naming each that is not right."""
    from ..grading.authoring.draws import check
    from ..grading.store.report import one_line

    troubles = check(
        found,
        args.check,
        args.solutions,
        args.catalog,
        roster,
        registry=registry,
        progress=lambda line: print(line, flush=True),
    )
    for trouble in troubles:
        print(f"not as it should be: {one_line(str(trouble), 300)}")
    print(f"{len(troubles)} draw(s) not as they should be" if troubles else "every draw is as it should be")
    return 1 if troubles else 0
