"""``labkit rubric``: print the lab's rubric (TOML) to copy and edit for ``--rubric``; ``--check`` one."""

from pathlib import Path


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "rubric",
        help="print the lab's rubric (TOML) to copy and edit",
        description="Print the lab's own rubric. Save it, edit it and pass it to "
        "`labkit grade --rubric FILE`; `--check FILE` validates an edited one.",
    )
    parser.add_argument("--check", type=Path, metavar="FILE", help="validate this rubric and summarise it instead")
    parser.set_defaults(handler=handle)


def handle(args):
    """Print the lab's rubric, or validate and summarise the one given."""
    from ..grading.store.rubric import DEFAULT, load
    from ..grading.store.text import points_text

    if args.check:
        rubric = load(args.check)
        print(rubric.describe())
        print("  points: " + ", ".join(f"exercise {n} {points_text(p)}" for n, p in rubric.points.items()))
        if rubric.late is not None and rubric.late.extensions:
            print(f"  extensions: {len(rubric.late.extensions)} student(s) have a deadline of their own")
        print(f"  digest: {rubric.digest} (results of runs with the same digest can be merged)")
    else:
        print(DEFAULT.read_text(encoding="utf-8"), end="")
    return 0
