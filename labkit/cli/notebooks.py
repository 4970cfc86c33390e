"""``labkit notebooks DIR``: write the student notebooks shipped with labkit into DIR."""

from pathlib import Path

from ..errors import InputError
from . import options


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "notebooks",
        help="write the student notebooks shipped with labkit into a folder",
        description="Write the lab's six student notebooks (exercises to do, with their "
        "self-checks) into DIR, e.g. for Colab, a JupyterHub or VS Code.",
    )
    parser.add_argument("out", type=Path, metavar="DIR", help="folder for the notebooks (created if needed)")
    options.force(parser, "overwrite notebooks of the same name in DIR")
    parser.set_defaults(handler=handle)


def handle(args):
    """Write the notebooks, never over a student's work without ``--force``."""
    from ..student_notebooks import paths

    out = args.out
    sources = paths()
    existing = [out / p.name for p in sources if (out / p.name).exists()]
    if existing and not args.force:
        raise InputError(
            f"{existing[0]} already exists (your work?); choose another folder, or --force to "
            "overwrite the notebooks there."
        )
    out.mkdir(parents=True, exist_ok=True)
    for source in sources:
        (out / source.name).write_bytes(source.read_bytes())
        print(f"wrote {out / source.name}")
    return 0
