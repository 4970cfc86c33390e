"""What several commands do alike: read the course and the roster with its variants, and print a run's summary
and the result files that were not read."""

import sys
import time

from ..errors import InputError


def course(args):
    """The exercises of ``--rubric`` (a course's own, named in its rubric), else the lab's."""
    if getattr(args, "rubric", None) is None:
        from ..exercises.registry import LAB

        return LAB
    from ..grading.store.rubric import load

    return load(args.rubric).registry


def roster_and_variants(args, purpose):
    """(roster, variants file) of ``--roster`` and ``--variants``, both or neither (None, None)."""
    if args.roster is None and args.variants is None:
        return None, None
    if args.roster is None or args.variants is None:
        raise InputError(f"give both --roster and --variants {purpose}, or neither.")
    from ..exercises import variants
    from ..grading.lms.roster import read_roster

    return read_roster(args.roster), variants.read(args.variants)


def warn(lines):
    """Print each line on stderr."""
    for line in lines:
        print(line, file=sys.stderr)


def refused(found, what):
    """Name each result file that was not read (its run's record does not vouch for it)."""
    from ..grading.store.report import one_line

    warn(f"labkit: {what}: not read: {one_line(path, 200)}: {one_line(why, 300)}" for path, why in found.refused)


def summary(grades, out, start, what):
    """Print each submission's total and where the run's files are."""
    from ..grading.store.report import one_line
    from ..grading.store.text import points_text

    for g in grades:
        lateness = g.lateness
        late = f"  ({points_text(lateness.penalty)} off for late work)" if lateness and lateness.penalty else ""
        print(f"{one_line(g.name, 30):<30} {points_text(g.total) if g.graded else 'not graded':>10}{late}")
    print(
        f"{what} {len(grades)} submission(s) in {time.perf_counter() - start:.1f} s; "
        f"wrote {out / 'grades.csv'}, {out / 'feedback'}/ and {out / 'results'}/"
    )
